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

use std::collections::VecDeque;
use std::io::{BufRead, BufReader, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError, SyncSender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

/// The shortest time between two writes to one page (the page draws at most once per
/// animation frame, about 16 ms, anyway).
const BATCH: Duration = Duration::from_millis(10);

/// Lines of each stream the page can get on (re)connecting; older ones are only in the
/// verdict file (and the input log).
pub const HISTORY: usize = 100_000;

/// Lines queued for one connection that its thread has not yet written. A connection
/// whose browser stops reading (a laptop asleep, a frozen tab) fills its queue and is
/// dropped: the sidecar never waits for a browser, and no browser makes the sidecar's
/// memory grow. Its page reconnects with `Last-Event-ID` and gets what it missed from
/// the history. About 40 bytes a line, held from the start (`sync_channel` allocates its
/// buffer at once), so 8,192 lines are about 330 KiB per connection, and a page that
/// reads lets through 8,192 lines per batch (800k lines a second) before it is dropped.
pub const QUEUE: usize = 8_192;

/// How long a write to a page may wait for it to read, before its connection is closed
/// (its thread and queue then go too; the page reconnects when it reads again).
const WRITE_TIMEOUT: Duration = Duration::from_secs(30);

/// What a published line is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    /// A verdict line.
    Verdict = 0,
    /// An input record (`live::record::Input` as JSON).
    Input = 1,
}

impl Stream {
    fn key(self) -> &'static str {
        match self {
            Stream::Verdict => "verdict",
            Stream::Input => "input",
        }
    }
}

/// One published line: its sequence number (the event id), when it was published
/// (milliseconds since the Unix epoch, for the page's delay figure) and its stream.
#[derive(Clone, Debug)]
struct Published {
    id: u64,
    sent_ms: u64,
    stream: Stream,
    line: Arc<str>,
}

#[derive(Default)]
struct HubState {
    /// Verdict lines and input records, each its own history (inputs are many more).
    history: [VecDeque<Published>; 2],
    next_id: u64,
    subscribers: Vec<SyncSender<Published>>,
}

/// Where verdict lines meet the page's connections.
#[derive(Default)]
pub struct Hub {
    state: Mutex<HubState>,
}

impl Hub {
    /// Publishes one line of `stream` (without its newline) to every connection.
    pub fn publish(&self, stream: Stream, line: &str) {
        let Ok(mut s) = self.state.lock() else {
            return;
        };
        let p = Published {
            id: s.next_id,
            sent_ms: now_ms(),
            stream,
            line: line.into(),
        };
        s.next_id += 1;
        let history = &mut s.history[stream as usize];
        if history.len() == HISTORY {
            history.pop_front();
        }
        history.push_back(p.clone());
        // Never blocks: a connection that is gone drops its receiver, one whose queue is
        // full is behind by QUEUE lines; both are forgotten. Dropping the sender ends the
        // connection once its thread has written what is queued (`events`).
        // (`try_send` fails with `Full` or `Disconnected`.)
        s.subscribers.retain(|tx| tx.try_send(p.clone()).is_ok());
    }

    /// The lines after `last_id` (all with `None`) still held, how many lines after it
    /// are no longer held (older than the history), and a receiver of the later ones.
    fn subscribe(&self, last_id: Option<u64>) -> (Vec<Published>, u64, Receiver<Published>) {
        let (tx, rx) = sync_channel(QUEUE);
        let Ok(mut s) = self.state.lock() else {
            return (Vec::new(), 0, rx);
        };
        // Both histories, in the order they were published.
        let mut past: Vec<Published> = s
            .history
            .iter()
            .flatten()
            .filter(|p| last_id.is_none_or(|l| p.id > l))
            .cloned()
            .collect();
        past.sort_by_key(|p| p.id);
        let after = last_id.map_or(0, |l| l.saturating_add(1)).min(s.next_id);
        let skipped = (s.next_id - after).saturating_sub(past.len() as u64);
        s.subscribers.push(tx);
        (past, skipped, rx)
    }

    /// How many connections are subscribed (for the tests).
    #[cfg(test)]
    fn subscribers(&self) -> usize {
        self.state.lock().map_or(0, |s| s.subscribers.len())
    }

    /// Every verdict line still held, newline-terminated.
    fn all_lines(&self) -> String {
        let Ok(s) = self.state.lock() else {
            return String::new();
        };
        let mut out = String::new();
        for p in &s.history[Stream::Verdict as usize] {
            out.push_str(&p.line);
            out.push('\n');
        }
        out
    }
}

fn now_ms() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as u64)
}

/// A writer that passes every byte to `inner` and then each complete line to a [`Hub`].
pub struct Tee {
    inner: Box<dyn Write + Send>,
    hub: Arc<Hub>,
    stream: Stream,
    partial: Vec<u8>,
}

impl Tee {
    /// Writes to `inner`, publishing its lines to `hub` as lines of `stream`.
    pub fn new(inner: Box<dyn Write + Send>, hub: Arc<Hub>, stream: Stream) -> Tee {
        Tee {
            inner,
            hub,
            stream,
            partial: Vec::new(),
        }
    }
}

impl Write for Tee {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        // The file first: what reaches the page is always already in the output.
        let n = self.inner.write(buf)?;
        let mut rest = &buf[..n];
        while let Some(i) = rest.iter().position(|&b| b == b'\n') {
            self.partial.extend_from_slice(&rest[..i]);
            self.hub
                .publish(self.stream, &String::from_utf8_lossy(&self.partial));
            self.partial.clear();
            rest = &rest[i + 1..];
        }
        self.partial.extend_from_slice(rest);
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

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
        .replace("__CSS__", include_str!("../report/page.css"))
        .replace("__LIVE_JS__", include_str!("page_live.js"))
        .replace("__JS__", include_str!("../report/page.js"))
        .replace("__SPEC__", &data)
        .replace("__VERSION__", env!("CARGO_PKG_VERSION"))
        .replace("__TITLE__", &crate::report::html::esc(title))
}

/// Resolves `--serve ADDR`: a bare port (`8080`) or `:8080` means loopback, so the page
/// is not offered to the network unless an address says so (`0.0.0.0:8080`).
pub fn parse_addr(text: &str) -> Result<SocketAddr, String> {
    let t = text.trim();
    let full = if t.parse::<u16>().is_ok() {
        format!("127.0.0.1:{t}")
    } else if let Some(port) = t.strip_prefix(':') {
        format!("127.0.0.1:{port}")
    } else {
        t.to_string()
    };
    full.to_socket_addrs()
        .map_err(|e| format!("`{text}`: {e} (expected PORT, :PORT or HOST:PORT)"))?
        .next()
        .ok_or_else(|| format!("`{text}`: no address"))
}

/// The page's server: bound, accepting on its own thread.
pub struct Server {
    /// Where it listens (with the port the system chose for port 0).
    pub addr: SocketAddr,
    /// The verdict lines it streams.
    pub hub: Arc<Hub>,
}

/// Binds `addr` and serves `page` at `/`, the event stream at `/events` and every line
/// held at `/verdicts.jsonl`, each connection on its own thread.
pub fn serve(addr: SocketAddr, page: String) -> std::io::Result<Server> {
    let listener = TcpListener::bind(addr)?;
    let addr = listener.local_addr()?;
    let hub = Arc::new(Hub::default());
    let page: Arc<str> = page.into();
    let h = hub.clone();
    std::thread::Builder::new()
        .name("serve".into())
        .spawn(move || {
            for stream in listener.incoming().flatten() {
                let (hub, page) = (h.clone(), page.clone());
                let _ = std::thread::Builder::new()
                    .name("serve-conn".into())
                    .spawn(move || {
                        let _ = connection(stream, &hub, &page);
                    });
            }
        })?;
    Ok(Server { addr, hub })
}

/// The request line's path and the `Last-Event-ID` header, if any.
fn read_request(stream: &TcpStream) -> std::io::Result<Option<(String, String, Option<u64>)>> {
    stream.set_read_timeout(Some(Duration::from_secs(5)))?;
    let mut r = BufReader::new(stream.try_clone()?);
    let mut first = String::new();
    if r.read_line(&mut first)? == 0 {
        return Ok(None);
    }
    let mut parts = first.split_whitespace();
    let (Some(method), Some(target)) = (parts.next(), parts.next()) else {
        return Ok(None);
    };
    let mut last_id = None;
    // Headers until the empty line; at most 100 of them.
    for _ in 0..100 {
        let mut h = String::new();
        if r.read_line(&mut h)? == 0 || h.trim().is_empty() {
            break;
        }
        if let Some((k, v)) = h.split_once(':') {
            if k.trim().eq_ignore_ascii_case("last-event-id") {
                last_id = v.trim().parse().ok();
            }
        }
    }
    let path = target.split('?').next().unwrap_or("/").to_string();
    Ok(Some((method.to_string(), path, last_id)))
}

fn respond(mut s: &TcpStream, status: &str, ty: &str, body: &[u8]) -> std::io::Result<()> {
    write!(
        s,
        "HTTP/1.1 {status}\r\nContent-Type: {ty}\r\nContent-Length: {}\r\n\
         Cache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len()
    )?;
    s.write_all(body)?;
    s.flush()
}

fn connection(stream: TcpStream, hub: &Hub, page: &str) -> std::io::Result<()> {
    let Some((method, path, last_id)) = read_request(&stream)? else {
        return Ok(());
    };
    if method != "GET" && method != "HEAD" {
        return respond(
            &stream,
            "405 Method Not Allowed",
            "text/plain",
            b"GET only\n",
        );
    }
    match path.as_str() {
        "/" | "/index.html" => respond(
            &stream,
            "200 OK",
            "text/html; charset=utf-8",
            page.as_bytes(),
        ),
        "/verdicts.jsonl" => respond(
            &stream,
            "200 OK",
            "application/x-ndjson",
            hub.all_lines().as_bytes(),
        ),
        "/events" => events(stream, hub, last_id),
        _ => respond(&stream, "404 Not Found", "text/plain", b"not found\n"),
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

fn events(mut stream: TcpStream, hub: &Hub, last_id: Option<u64>) -> std::io::Result<()> {
    stream.set_read_timeout(None)?;
    stream.set_write_timeout(Some(WRITE_TIMEOUT))?;
    write!(
        stream,
        "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\n\
         Connection: keep-alive\r\n\r\nretry: 1000\n\n"
    )?;
    let (past, skipped, rx) = hub.subscribe(last_id);
    let mut batch = String::new();
    if skipped > 0 {
        batch.push_str(&skipped_event(skipped));
    }
    for p in &past {
        batch.push_str(&event(p));
    }
    stream.write_all(batch.as_bytes())?;
    stream.flush()?;
    loop {
        match rx.recv_timeout(Duration::from_secs(15)) {
            Ok(p) => {
                let mut text = event(&p);
                // Whatever else is queued goes in the same write.
                while let Ok(more) = rx.try_recv() {
                    text.push_str(&event(&more));
                }
                stream.write_all(text.as_bytes())?;
                stream.flush()?;
                // At most one write per BATCH: a line after a quiet spell goes out at
                // once, a flood of input records in batches, so this thread does not
                // wake per sample and take the sidecar's core.
                std::thread::sleep(BATCH);
            }
            // A comment keeps proxies from closing an idle stream, and finds a gone peer.
            Err(RecvTimeoutError::Timeout) => {
                stream.write_all(b": idle\n\n")?;
                stream.flush()?;
            }
            // The hub dropped this connection (its queue was full): it ends here, and the
            // page reconnects after the last line written.
            Err(RecvTimeoutError::Disconnected) => return Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses_default_to_loopback() {
        assert_eq!(parse_addr("8080").unwrap().to_string(), "127.0.0.1:8080");
        assert_eq!(parse_addr(":0").unwrap().to_string(), "127.0.0.1:0");
        assert_eq!(parse_addr("0.0.0.0:9").unwrap().to_string(), "0.0.0.0:9");
        assert!(parse_addr("nowhere").unwrap_err().contains("expected PORT"));
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
        let (_, _, rx) = hub.subscribe(None);
        tee.write_all(b"{\"a\":1}\n{\"b\"").unwrap();
        assert_eq!(hub.all_lines(), "{\"a\":1}\n");
        tee.write_all(b":2}\n").unwrap();
        assert_eq!(hub.all_lines(), "{\"a\":1}\n{\"b\":2}\n");
        assert_eq!(&*file.lock().unwrap(), b"{\"a\":1}\n{\"b\":2}\n");
        let got: Vec<u64> = rx.try_iter().map(|p| p.id).collect();
        assert_eq!(got, vec![0, 1]);
        // A reconnect after id 0 gets only what followed.
        let (past, _, _) = hub.subscribe(Some(0));
        assert_eq!(past.len(), 1);
        assert!(event(&past[0]).starts_with("id: 1\ndata: {\"sent_ms\":"));
        assert!(event(&past[0]).ends_with(",\"verdict\":{\"b\":2}}\n\n"));
        // Input records go to the page in the same order, but not into the verdict lines.
        let mut inputs = Tee::new(Box::new(std::io::sink()), hub.clone(), Stream::Input);
        inputs
            .write_all(b"{\"kind\":\"tick\",\"time\":3}\n")
            .unwrap();
        tee.write_all(b"{\"c\":3}\n").unwrap();
        assert_eq!(hub.all_lines(), "{\"a\":1}\n{\"b\":2}\n{\"c\":3}\n");
        let (past, _, _) = hub.subscribe(Some(1));
        let texts: Vec<String> = past.iter().map(event).collect();
        assert!(texts[0].starts_with("id: 2\n"), "{texts:?}");
        assert!(texts[0].ends_with(",\"input\":{\"kind\":\"tick\",\"time\":3}}\n\n"));
        assert!(
            texts[1].ends_with(",\"verdict\":{\"c\":3}}\n\n"),
            "{texts:?}"
        );
    }

    #[test]
    fn a_connection_that_stops_reading_is_dropped_and_publishing_goes_on() {
        let hub = Hub::default();
        let (_, _, stalled) = hub.subscribe(None);
        let (_, _, reading) = hub.subscribe(None);
        let mut read = 0;
        for i in 0..QUEUE + 10 {
            hub.publish(Stream::Input, &format!("{{\"time\":{i}}}"));
            read += reading.try_iter().count();
        }
        // The stalled one was dropped when its queue was full; the reading one stays.
        assert_eq!(hub.subscribers(), 1);
        assert_eq!(read, QUEUE + 10);
        // What was queued before the drop is still there for its thread to write, then
        // the connection ends.
        let queued: Vec<u64> = stalled.try_iter().map(|p| p.id).collect();
        assert_eq!(queued, (0..QUEUE as u64).collect::<Vec<_>>());
        assert!(matches!(
            stalled.recv_timeout(Duration::from_millis(1)),
            Err(RecvTimeoutError::Disconnected)
        ));
        // Publishing goes on, and the page's reconnect gets the rest from the history.
        hub.publish(Stream::Verdict, "{\"v\":1}");
        assert_eq!(reading.try_iter().count(), 1);
        let (past, skipped, _) = hub.subscribe(Some(QUEUE as u64 - 1));
        assert_eq!(skipped, 0);
        assert_eq!(past.len(), 11);
        assert_eq!(past[0].id, QUEUE as u64);
    }

    #[test]
    fn a_reconnect_older_than_the_history_is_told_how_much_it_missed() {
        let hub = Hub::default();
        for i in 0..HISTORY + 5 {
            hub.publish(Stream::Input, &format!("{i}"));
        }
        hub.publish(Stream::Verdict, "v");
        // Inputs 0..5 are gone; the verdict line (id HISTORY + 5) is held.
        let (past, skipped, _) = hub.subscribe(Some(2));
        assert_eq!(skipped, 2);
        assert_eq!(past.len(), HISTORY + 1);
        assert_eq!(past[0].id, 5);
        let (past, skipped, _) = hub.subscribe(None);
        assert_eq!((past.len(), skipped), (HISTORY + 1, 5));
        assert_eq!(skipped_event(5), "data: {\"skipped\":5}\n\n");
        // Up to date: nothing missed.
        let (past, skipped, _) = hub.subscribe(Some(HISTORY as u64 + 5));
        assert_eq!((past.len(), skipped), (0, 0));
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
        assert!(page.contains(include_str!("../report/page.js")));
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
