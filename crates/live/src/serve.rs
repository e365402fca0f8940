//! The sidecar's live page (`hindsight monitor --serve ADDR`): a small HTTP/1.1 server on
//! its own threads that serves one self-contained page (the report's timeline script and
//! styles, `report/page.js` and `page.css`, inline) and streams to it, as server-sent
//! events in the order the sidecar writes them, every input record (the points: their
//! time and the variables they set, as `--record` writes them) and every verdict line.
//!
//! The outputs themselves are untouched: a [`Tee`] writes every byte to the verdict file
//! (or standard output), or to the input log, first and only then hands complete lines to
//! the [`Hub`], so a slow or absent browser can neither lose nor delay a verdict line, and
//! stopping the monitor flushes the files as before. Hand-written on `std::net` (two routes and an event
//! stream need no framework, and no async runtime beside the sidecar's loop).

use std::io::Write;
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

use super::http::{self, Hosts, Limits, Refusal};

mod hub;

pub use hub::{Hub, Stream, Tee, HISTORY};
use hub::{Published, Subscriber, BATCH};

/// The live page for `spec`: its properties in order (a row and a verdict lane each
/// before any verdict), its variables (a lane each: name, whether an event, initial
/// value), the unit that turns ticks into seconds, and `title` (e.g. the model's path).
pub fn page(title: &str, spec: &codegen::Compiled) -> String {
    let names: Vec<&str> = spec.property_names().collect();
    let vars: Vec<serde_json::Value> = spec
        .vars()
        .iter()
        .map(|v| {
            serde_json::json!({
                "name": v.name,
                "event": v.kind == monitor_core::VarKind::Event,
                "init": super::record::value_json(spec, v.init),
            })
        })
        .collect();
    let data = serde_json::json!({ "properties": names, "vars": vars, "unit_ns": spec.tick_ns() });
    // `<` escaped so no name can close the script element.
    let data = data.to_string().replace('<', "\\u003c");
    // The title last: nothing it holds is taken for a placeholder.
    include_str!("page.html")
        .replace("__CSS__", crate::report::PAGE_CSS)
        .replace("__LIVE_JS__", include_str!("page_live.js"))
        .replace("__JS__", crate::report::PAGE_JS)
        .replace("__SPEC__", &data)
        .replace("__VERSION__", env!("CARGO_PKG_VERSION"))
        .replace("__TITLE__", &crate::model::xml::escape(title))
}

/// Why `--serve ADDR` names no address: the text as given, and what the resolver said
/// (`None`: it resolved to no address).
#[derive(Debug)]
pub struct AddrError {
    /// The text as given.
    pub text: String,
    /// The resolver's error.
    pub error: Option<std::io::Error>,
}

impl std::fmt::Display for AddrError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.error {
            Some(e) => write!(
                f,
                "`{}`: {e} (expected PORT, :PORT or HOST:PORT)",
                self.text
            ),
            None => write!(f, "`{}`: no address", self.text),
        }
    }
}

impl std::error::Error for AddrError {}

/// Resolves `--serve ADDR`: a bare port (`8080`) or `:8080` means loopback, so the page
/// is not offered to the network unless an address says so (`0.0.0.0:8080`).
pub fn parse_addr(text: &str) -> Result<SocketAddr, AddrError> {
    let t = text.trim();
    let full = if t.parse::<u16>().is_ok() {
        format!("127.0.0.1:{t}")
    } else if let Some(port) = t.strip_prefix(':') {
        format!("127.0.0.1:{port}")
    } else {
        t.to_string()
    };
    let error = |error| AddrError {
        text: text.to_owned(),
        error,
    };
    full.to_socket_addrs()
        .map_err(|e| error(Some(e)))?
        .next()
        .ok_or_else(|| error(None))
}

/// The page's server: bound, accepting on its own thread.
pub struct Server {
    /// Where it listens (with the port the system chose for port 0).
    pub addr: SocketAddr,
    /// The verdict lines it streams.
    pub hub: Arc<Hub>,
    shared: Arc<Shared>,
}

impl Server {
    /// Connections being served now.
    pub fn connections(&self) -> usize {
        self.shared.active.load(Ordering::SeqCst)
    }
}

/// What every connection's thread shares.
struct Shared {
    hub: Arc<Hub>,
    page: Arc<str>,
    hosts: Hosts,
    limits: Limits,
    /// Connections being served.
    active: AtomicUsize,
    /// Connections reading the history at once (see [`Gate`]).
    gate: Gate,
}

/// How many connections may read and format the history at once. Pages that (re)connect
/// together, or a hundred streams opened by one client, would otherwise each copy out of
/// the hub as fast as they can: their threads would take both cores and the hub's lock
/// in turn, and the judging thread would wait for a core or for the lock (0.7 s measured
/// with 64 of them). Each holds the gate only to copy and format one piece, never while
/// writing it.
const READERS: usize = 2;

/// A counting semaphore of [`READERS`] permits.
#[derive(Default)]
struct Gate {
    taken: Mutex<usize>,
    free: Condvar,
}

/// A permit of the [`Gate`], given back when dropped.
struct Permit<'a>(&'a Gate);

impl Gate {
    fn enter(&self) -> Option<Permit<'_>> {
        let mut n = self.taken.lock().ok()?;
        while *n >= READERS {
            n = self.free.wait(n).ok()?;
        }
        *n += 1;
        Some(Permit(self))
    }
}

impl Drop for Permit<'_> {
    fn drop(&mut self) {
        if let Ok(mut n) = self.0.taken.lock() {
            *n -= 1;
        }
        self.0.free.notify_one();
    }
}

/// Counts a connection as served until it is dropped.
struct Slot(Arc<Shared>);

impl Drop for Slot {
    fn drop(&mut self) {
        self.0.active.fetch_sub(1, Ordering::SeqCst);
    }
}

/// How long the accepting thread pauses after `accept` fails (out of descriptors, say):
/// a failing `accept` fails again at once, and retrying in a loop would take a core.
const ACCEPT_PAUSE: Duration = Duration::from_millis(50);

/// Where a sidecar writes a stream of lines (verdicts, the input log).
pub type Output = Box<dyn Write + Send>;

/// A sidecar's outputs with `server`'s page beside them: the verdict lines go to
/// `verdicts` and to the page; the page's points are the input records, written to
/// `record` first when there is one (`--record`), else for the page alone.
pub fn attach(server: &Server, verdicts: Output, record: Option<Output>) -> (Output, Output) {
    let log = record.unwrap_or_else(|| Box::new(std::io::sink()));
    (
        Box::new(Tee::new(verdicts, server.hub.clone(), Stream::Verdict)),
        Box::new(Tee::new(log, server.hub.clone(), Stream::Input)),
    )
}

/// Binds `addr` and serves `page` at `/`, the event stream at `/events` and every line
/// held at `/verdicts.jsonl`, each connection on its own thread, within `limits`.
/// `public`: `addr` may be beyond loopback (`--serve-public`); without it such an address
/// is refused. Requests whose `Host` is not a name of this server are answered 421.
pub fn serve(
    addr: SocketAddr,
    page: String,
    public: bool,
    limits: Limits,
) -> std::io::Result<Server> {
    if !public && !addr.ip().is_loopback() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::PermissionDenied,
            "not a loopback address: the page would be offered to the network (add \
             --serve-public to mean it)",
        ));
    }
    let listener = TcpListener::bind(addr)?;
    let addr = listener.local_addr()?;
    let shared = Arc::new(Shared {
        hub: Arc::new(Hub::new(limits.queue_bytes)),
        page: page.into(),
        hosts: Hosts::new(addr, public),
        limits,
        active: AtomicUsize::new(0),
        gate: Gate::default(),
    });
    let hub = shared.hub.clone();
    let s = shared.clone();
    std::thread::Builder::new()
        .name("serve".into())
        .spawn(move || accept(listener, s))?;
    Ok(Server { addr, hub, shared })
}

/// The accepting thread: a thread per connection up to `limits.connections`, beyond them
/// a 503 written without waiting and the connection closed (no thread, no wait).
fn accept(listener: TcpListener, shared: Arc<Shared>) {
    loop {
        let stream = match listener.accept() {
            Ok((s, _)) => s,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(_) => {
                std::thread::sleep(ACCEPT_PAUSE);
                continue;
            }
        };
        if shared.active.fetch_add(1, Ordering::SeqCst) >= shared.limits.connections {
            shared.active.fetch_sub(1, Ordering::SeqCst);
            busy(stream);
            continue;
        }
        let slot = Slot(shared.clone());
        // A thread that cannot be started drops its slot and its connection.
        let _ = std::thread::Builder::new()
            .name("serve-conn".into())
            .stack_size(256 * 1024)
            .spawn(move || {
                let _ = connection(&stream, &slot.0);
                drop(slot);
            });
    }
}

/// Answers 503 to a connection beyond the limit, without blocking the accepting thread.
fn busy(stream: TcpStream) {
    let body = "too many connections\n";
    let text = format!(
        "HTTP/1.1 503 Service Unavailable\r\nContent-Type: text/plain\r\nContent-Length: {}\r\n\
         Retry-After: 1\r\nConnection: close\r\n\r\n{body}",
        body.len()
    );
    if stream.set_nonblocking(true).is_ok() {
        let _ = (&stream).write(text.as_bytes());
        let _ = stream.shutdown(std::net::Shutdown::Write);
    }
}

fn connection(stream: &TcpStream, shared: &Shared) -> std::io::Result<()> {
    let limits = &shared.limits;
    let req = match http::read_request(stream, limits) {
        Ok(Some(r)) => r,
        Ok(None) => return Ok(()),
        Err(refusal) => {
            http::refuse(stream, &refusal, "");
            return Ok(());
        }
    };
    let Some(host) = req.host.as_deref() else {
        http::refuse(stream, &Refusal("400 Bad Request", "no Host header"), "");
        return Ok(());
    };
    if !shared.hosts.allows(host) {
        // A page of another site whose name was made to resolve to this address (DNS
        // rebinding) names that site here.
        http::refuse(
            stream,
            &Refusal("421 Misdirected Request", "not a name of this server"),
            "",
        );
        return Ok(());
    }
    let head_only = match req.method.as_str() {
        "GET" => false,
        "HEAD" => true,
        _ => {
            http::refuse(
                stream,
                &Refusal("405 Method Not Allowed", "GET or HEAD only"),
                "Allow: GET, HEAD\r\n",
            );
            return Ok(());
        }
    };
    match req.path.as_str() {
        "/" | "/index.html" => respond(
            stream,
            "200 OK",
            "text/html; charset=utf-8",
            shared.page.as_bytes(),
            head_only,
            limits,
        ),
        "/verdicts.jsonl" => verdicts(stream, shared, head_only),
        "/events" => events(stream, shared, req.last_id, head_only),
        _ => respond(
            stream,
            "404 Not Found",
            "text/plain",
            b"not found\n",
            head_only,
            limits,
        ),
    }
}

fn respond(
    s: &TcpStream,
    status: &str,
    ty: &str,
    body: &[u8],
    head_only: bool,
    limits: &Limits,
) -> std::io::Result<()> {
    http::write_chunks(
        s,
        http::head(status, ty, Some(body.len())).as_bytes(),
        limits,
    )?;
    if !head_only {
        http::write_chunks(s, body, limits)?;
    }
    Ok(())
}

/// Every verdict line held when the request came, in pieces of `limits.chunk` bytes read
/// from the history one at a time (the body ends with the connection: lines that leave
/// the history while a slow client reads are not sent).
fn verdicts(s: &TcpStream, shared: &Shared, head_only: bool) -> std::io::Result<()> {
    let (hub, limits) = (&shared.hub, &shared.limits);
    http::write_chunks(
        s,
        http::head("200 OK", "application/x-ndjson", None).as_bytes(),
        limits,
    )?;
    if head_only {
        return Ok(());
    }
    let end = hub.next_id();
    let mut after = None;
    loop {
        let permit = shared.gate.enter();
        let piece = hub.verdicts(after, end, limits.chunk);
        let Some(last) = piece.last() else {
            return Ok(());
        };
        after = Some(last.id);
        let mut text = String::with_capacity(limits.chunk + 256);
        for p in &piece {
            text.push_str(&p.line);
            text.push('\n');
        }
        drop(permit);
        http::write_chunks(s, text.as_bytes(), limits)?;
    }
}

/// The event that says `n` lines are no longer held (published before the oldest line
/// of the history): data `{"skipped":N}`, no `id`, so a reconnect resumes after the last
/// line the page had.
fn skipped_event(n: u64) -> String {
    format!("data: {{\"skipped\":{n}}}\n\n")
}

/// One event: `id` for a reconnect's `Last-Event-ID`, data `{"sent_ms":..,"verdict":LINE}`
/// or `{"sent_ms":..,"input":RECORD}`.
fn event(p: &Published) -> String {
    format!(
        "id: {}\ndata: {{\"sent_ms\":{},\"{}\":{}}}\n\n",
        p.id,
        p.sent_ms,
        p.stream.key(),
        p.line
    )
}

/// Ends a subscription when its connection's thread leaves, however it leaves.
struct Subscribed(Arc<Subscriber>);

impl Drop for Subscribed {
    fn drop(&mut self) {
        self.0.close();
    }
}

/// The event stream: the history after `last_id` in pieces of `limits.chunk` bytes, then
/// each event as it is published, at most one write per [`BATCH`]. Every write has
/// `limits.stall` to finish; a page whose queue passes `limits.queue_bytes` is dropped
/// by the hub; either way the connection closes and the page reconnects after the last
/// event it had.
fn events(
    s: &TcpStream,
    shared: &Shared,
    last_id: Option<u64>,
    head_only: bool,
) -> std::io::Result<()> {
    let (hub, limits) = (&shared.hub, &shared.limits);
    http::write_chunks(
        s,
        b"HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\n\
          Connection: keep-alive\r\n\r\n",
        limits,
    )?;
    if head_only {
        return Ok(());
    }
    http::write_chunks(s, b"retry: 1000\n\n", limits)?;
    let mut after = last_id;
    let sub = loop {
        let permit = shared.gate.enter();
        let Some((piece, sub)) = hub.catch_up(after, limits.chunk) else {
            return Ok(());
        };
        // Subscribed now: ended whatever happens to the writes below.
        let sub = sub.map(Subscribed);
        let mut text = String::with_capacity(limits.chunk + 256);
        if piece.skipped > 0 {
            text.push_str(&skipped_event(piece.skipped));
        }
        for p in &piece.events {
            text.push_str(&event(p));
        }
        if let Some(p) = piece.events.last() {
            after = Some(p.id);
        }
        drop(permit);
        http::write_chunks(s, text.as_bytes(), limits)?;
        if let Some(sub) = sub {
            break sub;
        }
    };
    loop {
        let items = {
            let Ok(mut q) = sub.0.queue.lock() else {
                return Ok(());
            };
            if q.items.is_empty() && !q.closed {
                q.waiting = true;
                let (guard, _) = sub
                    .0
                    .ready
                    .wait_timeout(q, Duration::from_secs(15))
                    .map_err(|_| std::io::Error::other("poisoned"))?;
                q = guard;
                q.waiting = false;
            }
            if q.closed {
                // Dropped: the page reconnects and resumes from the history.
                return Ok(());
            }
            q.bytes = 0;
            std::mem::take(&mut q.items)
        };
        if items.is_empty() {
            // A comment keeps proxies from closing an idle stream, and finds a gone peer.
            http::write_chunks(s, b": idle\n\n", limits)?;
            continue;
        }
        // Written in pieces, so the text held is one piece, not the whole queue.
        let mut text = String::with_capacity(limits.chunk + 256);
        for p in &items {
            text.push_str(&event(p));
            if text.len() >= limits.chunk {
                http::write_chunks(s, text.as_bytes(), limits)?;
                text.clear();
            }
        }
        http::write_chunks(s, text.as_bytes(), limits)?;
        // At most one write per BATCH: a line after a quiet spell goes out at once, a
        // flood of input records in batches, so this thread does not wake per sample
        // and take the sidecar's core.
        std::thread::sleep(BATCH);
    }
}

#[cfg(test)]
mod tests {
    use super::hub::EVENT_OVERHEAD;
    use super::*;
    use std::io::Read;
    use std::time::Instant;

    /// Every verdict line held, newline-terminated.
    fn all_lines(hub: &Hub) -> String {
        hub.verdicts(None, hub.next_id(), usize::MAX)
            .iter()
            .map(|p| format!("{}\n", p.line))
            .collect()
    }

    /// Subscribes after `last_id` in one piece: what was held, how much was skipped, the
    /// subscriber.
    fn subscribe(hub: &Hub, last_id: Option<u64>) -> (Vec<Published>, u64, Arc<Subscriber>) {
        let (piece, sub) = hub.catch_up(last_id, usize::MAX).unwrap();
        (piece.events, piece.skipped, sub.unwrap())
    }

    /// The ids queued for `sub`, taken.
    fn take(sub: &Subscriber) -> Vec<u64> {
        let mut q = sub.queue.lock().unwrap();
        q.bytes = 0;
        std::mem::take(&mut q.items).iter().map(|p| p.id).collect()
    }

    #[test]
    fn addresses_default_to_loopback() {
        assert_eq!(parse_addr("8080").unwrap().to_string(), "127.0.0.1:8080");
        assert_eq!(parse_addr(":0").unwrap().to_string(), "127.0.0.1:0");
        assert_eq!(parse_addr("0.0.0.0:9").unwrap().to_string(), "0.0.0.0:9");
        assert!(parse_addr("nowhere")
            .unwrap_err()
            .to_string()
            .contains("expected PORT"));
    }

    #[test]
    fn the_tee_writes_through_and_publishes_whole_lines() {
        let hub = Arc::new(Hub::default());
        let file = Arc::new(Mutex::new(Vec::new()));
        struct Shared(Arc<Mutex<Vec<u8>>>);
        impl Write for Shared {
            fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
                self.0.lock().unwrap().extend_from_slice(b);
                Ok(b.len())
            }
            fn flush(&mut self) -> std::io::Result<()> {
                Ok(())
            }
        }
        let mut tee = Tee::new(Box::new(Shared(file.clone())), hub.clone(), Stream::Verdict);
        let (_, _, sub) = subscribe(&hub, None);
        tee.write_all(b"{\"a\":1}\n{\"b\"").unwrap();
        assert_eq!(all_lines(&hub), "{\"a\":1}\n");
        tee.write_all(b":2}\n").unwrap();
        assert_eq!(all_lines(&hub), "{\"a\":1}\n{\"b\":2}\n");
        assert_eq!(&*file.lock().unwrap(), b"{\"a\":1}\n{\"b\":2}\n");
        assert_eq!(take(&sub), vec![0, 1]);
        // A reconnect after id 0 gets only what followed.
        let (past, _, _) = subscribe(&hub, Some(0));
        assert_eq!(past.len(), 1);
        assert!(event(&past[0]).starts_with("id: 1\ndata: {\"sent_ms\":"));
        assert!(event(&past[0]).ends_with(",\"verdict\":{\"b\":2}}\n\n"));
        // Input records go to the page in the same order, but not into the verdict lines.
        let mut inputs = Tee::new(Box::new(std::io::sink()), hub.clone(), Stream::Input);
        inputs
            .write_all(b"{\"kind\":\"tick\",\"time\":3}\n")
            .unwrap();
        tee.write_all(b"{\"c\":3}\n").unwrap();
        assert_eq!(all_lines(&hub), "{\"a\":1}\n{\"b\":2}\n{\"c\":3}\n");
        let (past, _, _) = subscribe(&hub, Some(1));
        let texts: Vec<String> = past.iter().map(event).collect();
        assert!(texts[0].starts_with("id: 2\n"), "{texts:?}");
        assert!(texts[0].ends_with(",\"input\":{\"kind\":\"tick\",\"time\":3}}\n\n"));
        assert!(
            texts[1].ends_with(",\"verdict\":{\"c\":3}}\n\n"),
            "{texts:?}"
        );
    }

    #[test]
    fn a_connection_whose_queue_passes_its_bytes_is_dropped_and_publishing_goes_on() {
        // Room for 10 events of 10-byte lines.
        let hub = Hub::new(10 * (10 + EVENT_OVERHEAD));
        let (_, _, stalled) = subscribe(&hub, None);
        let (_, _, reading) = subscribe(&hub, None);
        let mut read = 0;
        for i in 0..30 {
            hub.publish(Stream::Input, &format!("{i:010}"));
            read += take(&reading).len();
        }
        // The stalled one was dropped when its queue would have passed its bound, and its
        // queue emptied at once (its memory goes before its thread does); the reading one
        // stays.
        assert_eq!(hub.subscribers(), 1);
        assert_eq!(read, 30);
        let q = stalled.queue.lock().unwrap();
        assert!(q.closed && q.items.is_empty() && q.bytes == 0);
        drop(q);
        // The page's reconnect gets the rest from the history.
        let (past, skipped, _) = subscribe(&hub, Some(9));
        assert_eq!(skipped, 0);
        assert_eq!(past.len(), 20);
        assert_eq!(past[0].id, 10);
        // A connection whose thread ended is forgotten at the next line.
        let (_, _, gone) = subscribe(&hub, None);
        gone.close();
        hub.publish(Stream::Verdict, "{}");
        assert_eq!(hub.subscribers(), 2);
    }

    #[test]
    fn the_history_goes_out_in_pieces_and_subscribing_misses_nothing() {
        let hub = Hub::default();
        for i in 0..1000 {
            hub.publish(Stream::Input, &format!("{i:036}"));
        }
        // 100-event pieces (36 + 64 bytes each): never the whole history at once.
        let (mut after, mut pieces, mut got) = (None, 0, Vec::new());
        let sub = loop {
            let (piece, sub) = hub.catch_up(after, 100 * 100).unwrap();
            assert!(piece.events.len() <= 100);
            got.extend(piece.events.iter().map(|p| p.id));
            after = piece.events.last().map(|p| p.id).or(after);
            pieces += 1;
            // Published between two pieces: part of a later piece.
            hub.publish(Stream::Verdict, "{}");
            if let Some(sub) = sub {
                break sub;
            }
        };
        assert!(pieces >= 10, "{pieces}");
        let last = *got.last().unwrap();
        got.extend(take(&sub));
        assert_eq!(got, (0..=last + 1).collect::<Vec<_>>());
        // /verdicts.jsonl in pieces too, up to the end given.
        let end = hub.next_id();
        let first = hub.verdicts(None, end, 3 * (2 + EVENT_OVERHEAD));
        assert_eq!(first.len(), 3);
        let rest = hub.verdicts(Some(first[2].id), end, usize::MAX);
        assert_eq!(first.len() + rest.len(), pieces);
    }

    #[test]
    fn a_reconnect_older_than_the_history_is_told_how_much_it_missed() {
        let hub = Hub::default();
        for i in 0..HISTORY + 5 {
            hub.publish(Stream::Input, &format!("{i}"));
        }
        hub.publish(Stream::Verdict, "v");
        // Inputs 0..5 are gone; the verdict line (id HISTORY + 5) is held.
        let (past, skipped, _) = subscribe(&hub, Some(2));
        assert_eq!(skipped, 2);
        assert_eq!(past.len(), HISTORY + 1);
        assert_eq!(past[0].id, 5);
        let (past, skipped, _) = subscribe(&hub, None);
        assert_eq!((past.len(), skipped), (HISTORY + 1, 5));
        assert_eq!(skipped_event(5), "data: {\"skipped\":5}\n\n");
        // Up to date: nothing missed.
        let (past, skipped, _) = subscribe(&hub, Some(HISTORY as u64 + 5));
        assert_eq!((past.len(), skipped), (0, 0));
    }

    /// A server on a free loopback port with `limits`.
    fn server(limits: Limits) -> Server {
        serve(
            "127.0.0.1:0".parse().unwrap(),
            "<p>page</p>".into(),
            false,
            limits,
        )
        .unwrap()
    }

    /// Sends `request` and reads the answer to the end.
    fn ask(addr: SocketAddr, request: &str) -> String {
        let mut s = TcpStream::connect(addr).unwrap();
        s.write_all(request.as_bytes()).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
        let mut text = String::new();
        let _ = s.read_to_string(&mut text);
        text
    }

    #[test]
    fn head_has_no_body_and_hosts_other_than_this_server_s_are_refused() {
        let srv = server(Limits::default());
        let get = ask(srv.addr, "GET / HTTP/1.1\r\nHost: localhost\r\n\r\n");
        assert!(
            get.starts_with("HTTP/1.1 200 OK") && get.ends_with("<p>page</p>"),
            "{get}"
        );
        let head = ask(srv.addr, "HEAD / HTTP/1.1\r\nHost: localhost\r\n\r\n");
        assert!(head.starts_with("HTTP/1.1 200 OK"), "{head}");
        assert!(
            head.contains("Content-Length: 11\r\n") && head.ends_with("\r\n\r\n"),
            "{head}"
        );
        let head = ask(srv.addr, "HEAD /events HTTP/1.1\r\nHost: localhost\r\n\r\n");
        assert!(
            head.starts_with("HTTP/1.1 200 OK") && head.ends_with("\r\n\r\n"),
            "{head}"
        );
        let rebound = ask(
            srv.addr,
            "GET / HTTP/1.1\r\nHost: evil.example:8080\r\n\r\n",
        );
        assert!(rebound.starts_with("HTTP/1.1 421 "), "{rebound}");
        assert!(!rebound.contains("page"));
        let no_host = ask(srv.addr, "GET / HTTP/1.0\r\n\r\n");
        assert!(no_host.starts_with("HTTP/1.1 400 "), "{no_host}");
        let post = ask(srv.addr, "POST / HTTP/1.1\r\nHost: localhost\r\n\r\n");
        assert!(post.starts_with("HTTP/1.1 405 "), "{post}");
        let long = ask(srv.addr, &format!("GET /{} HTTP/1.1\r\n", "a".repeat(9000)));
        assert!(long.starts_with("HTTP/1.1 414 "), "{long}");
    }

    #[test]
    fn a_public_address_needs_public() {
        let e = serve(
            "0.0.0.0:0".parse().unwrap(),
            String::new(),
            false,
            Limits::default(),
        )
        .err()
        .unwrap();
        assert!(e.to_string().contains("--serve-public"), "{e}");
        assert!(serve(
            "0.0.0.0:0".parse().unwrap(),
            String::new(),
            true,
            Limits::default()
        )
        .is_ok());
    }

    #[test]
    fn connections_beyond_the_limit_get_503_and_slow_ones_are_closed_at_the_deadline() {
        let srv = server(Limits {
            connections: 2,
            request_time: Duration::from_millis(500),
            ..Limits::default()
        });
        // Two clients that send half a request and then nothing.
        let slow: Vec<TcpStream> = (0..2)
            .map(|_| {
                let mut s = TcpStream::connect(srv.addr).unwrap();
                s.write_all(b"GET / HTTP/1.1\r\n").unwrap();
                s
            })
            .collect();
        std::thread::sleep(Duration::from_millis(100));
        let third = ask(srv.addr, "GET / HTTP/1.1\r\nHost: localhost\r\n\r\n");
        assert!(third.starts_with("HTTP/1.1 503 "), "{third}");
        // Each slow one is answered 408 at its deadline, and its slot is free again.
        for mut s in slow {
            s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
            let mut text = String::new();
            let _ = s.read_to_string(&mut text);
            assert!(text.starts_with("HTTP/1.1 408 "), "{text}");
        }
        let t = Instant::now();
        loop {
            let again = ask(srv.addr, "GET / HTTP/1.1\r\nHost: localhost\r\n\r\n");
            if again.starts_with("HTTP/1.1 200") {
                break;
            }
            assert!(t.elapsed() < Duration::from_secs(10), "{again}");
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    #[test]
    fn an_events_client_that_stops_reading_is_closed_after_the_stall_time() {
        let srv = server(Limits {
            stall: Duration::from_millis(300),
            ..Limits::default()
        });
        // More history than the socket buffers hold (80 MB of events).
        let line = "x".repeat(800);
        for _ in 0..HISTORY {
            srv.hub.publish(Stream::Input, &line);
        }
        let mut s = TcpStream::connect(srv.addr).unwrap();
        s.write_all(b"GET /events HTTP/1.1\r\nHost: localhost\r\n\r\n")
            .unwrap();
        // Not read until the server gave up on it (once it took it).
        let t = Instant::now();
        while srv.connections() == 0 {
            assert!(t.elapsed() < Duration::from_secs(20), "never accepted");
            std::thread::sleep(Duration::from_millis(5));
        }
        while srv.connections() > 0 {
            assert!(t.elapsed() < Duration::from_secs(20), "never closed");
            std::thread::sleep(Duration::from_millis(20));
        }
        // What was sent ends early: the connection was closed, not finished.
        let mut got = Vec::new();
        s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
        let _ = s.read_to_end(&mut got);
        assert!(got.len() < HISTORY * 800, "{}", got.len());
        srv.hub.publish(Stream::Verdict, "{}");
        assert_eq!(srv.hub.subscribers(), 0);
    }

    #[test]
    fn the_page_inlines_the_report_script_and_the_spec() {
        let spec = codegen::compile_spec(
            "unit 10ms;\nstate level: int = 100;\nevent alarm;\n\
             property low = H({alarm} -> {level < 30});\n",
            "t.hspec",
        )
        .unwrap();
        let page = page("museum <guide>", &spec);
        assert!(page.contains(crate::report::PAGE_JS));
        assert!(page.contains(include_str!("page_live.js")));
        assert!(page.contains("hindsight monitor: museum &lt;guide&gt;"));
        assert!(page.contains(
            "{\"properties\":[\"low\"],\"unit_ns\":10000000,\"vars\":[{\"event\":false,\
             \"init\":100,\"name\":\"level\"},{\"event\":true,\"init\":false,\"name\":\"alarm\"}]}"
        ));
        for placeholder in [
            "__CSS__",
            "__JS__",
            "__LIVE_JS__",
            "__SPEC__",
            "__TITLE__",
            "__VERSION__",
        ] {
            assert!(!page.contains(placeholder), "{placeholder}");
        }
        assert!(!page.contains("http://") && !page.contains("https://"));
    }
}
