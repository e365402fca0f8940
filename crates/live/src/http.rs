//! The HTTP/1.1 plumbing of the live page (`monitor --serve`, `serve.rs`) with the limits
//! a web server has: a request head read against one deadline and capped in bytes (the
//! request line apart), every write against a deadline, a `Host` header checked against
//! the names the page may be reached by (a DNS-rebinding page's own name is refused), and
//! an error response closed without letting the client keep the connection.
//!
//! The statuses are those of RFC 9110 (400, 404, 405, 408, 414, 421, 503) and RFC 6585
//! (431 Request Header Fields Too Large); the `Host` check follows RFC 9110 section 7.2
//! (the authority the client meant) and is what servers that bind loopback do against DNS
//! rebinding (a page of `evil.example` whose name is made to resolve to 127.0.0.1 still
//! sends `Host: evil.example`).

use std::io::{ErrorKind, Read, Write};
use std::net::{Ipv4Addr, Ipv6Addr, Shutdown, SocketAddr, TcpStream};
use std::time::{Duration, Instant};

/// The limits of the live page's server; [`Limits::default`] is what `monitor --serve`
/// uses (tests shrink them).
#[derive(Clone, Debug)]
pub struct Limits {
    /// Connections served at once; one more is answered 503 and closed at once.
    pub connections: usize,
    /// Bytes of the request line (method, target, version); longer: 414.
    pub request_line: usize,
    /// Bytes of the whole request head (request line and headers); larger: 431.
    pub head: usize,
    /// Time to receive the whole request head, however it trickles in; later: 408.
    pub request_time: Duration,
    /// Bytes of events queued for one page and not yet written; one more and the page
    /// is dropped (it reconnects and resumes from the history).
    pub queue_bytes: usize,
    /// Bytes of one write to a page (history and queued events go out in pieces this size).
    pub chunk: usize,
    /// Time one write of at most `chunk` bytes may take; longer and the connection is
    /// closed (a page that stopped reading).
    pub stall: Duration,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            connections: 64,
            request_line: 8 * 1024,
            head: 16 * 1024,
            request_time: Duration::from_secs(5),
            queue_bytes: 256 * 1024,
            chunk: 64 * 1024,
            stall: Duration::from_secs(30),
        }
    }
}

/// The most header lines a request may have (beyond: 431).
const MAX_HEADERS: usize = 100;

/// A request's head, as far as the page needs it.
#[derive(Debug, PartialEq, Eq)]
pub struct Request {
    /// `GET`, `HEAD`, ...
    pub method: String,
    /// The target without its query.
    pub path: String,
    /// The `Last-Event-ID` header, when a number.
    pub last_id: Option<u64>,
    /// The `Host` header.
    pub host: Option<String>,
}

/// A refusal: the status line's code and reason, and a one-line body saying why.
#[derive(Debug, PartialEq, Eq)]
pub struct Refusal(pub &'static str, pub &'static str);

/// Reads one request head from `s` within `limits`: `Ok(None)` when the client closed
/// (or failed) before a whole head came, a [`Refusal`] for a head too long, too slow or
/// malformed. Reads in pieces into one buffer never larger than `limits.head` plus one
/// piece, against one deadline for the whole head (a byte now and then does not extend it).
pub(crate) fn read_request(s: &TcpStream, limits: &Limits) -> Result<Option<Request>, Refusal> {
    let deadline = Instant::now() + limits.request_time;
    let mut buf: Vec<u8> = Vec::with_capacity(1024);
    let mut piece = [0u8; 4096];
    loop {
        if let Some(end) = head_end(&buf) {
            return parse(&buf[..end], limits).map(Some);
        }
        let line_end = buf.iter().position(|&b| b == b'\n');
        if line_end.map_or(buf.len(), |e| e) > limits.request_line {
            return Err(Refusal("414 URI Too Long", "request line too long"));
        }
        if buf.len() > limits.head {
            return Err(Refusal(
                "431 Request Header Fields Too Large",
                "request head too large",
            ));
        }
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(Refusal(
                "408 Request Timeout",
                "request not received in time",
            ));
        }
        if s.set_read_timeout(Some(left)).is_err() {
            return Ok(None);
        }
        let room = (limits.head + 1 - buf.len().min(limits.head)).min(piece.len());
        match (&*s).read(&mut piece[..room]) {
            Ok(0) => return Ok(None),
            Ok(n) => buf.extend_from_slice(&piece[..n]),
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                return Err(Refusal(
                    "408 Request Timeout",
                    "request not received in time",
                ));
            }
            Err(_) => return Ok(None),
        }
    }
}

/// The length of the head in `buf` (through its empty line), once it is complete.
fn head_end(buf: &[u8]) -> Option<usize> {
    let i = buf.windows(2).position(|w| w == b"\n\n");
    let j = buf.windows(3).position(|w| w == b"\n\r\n");
    match (i.map(|i| i + 2), j.map(|j| j + 3)) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

fn parse(head: &[u8], limits: &Limits) -> Result<Request, Refusal> {
    let bad = Refusal("400 Bad Request", "malformed request");
    let text = std::str::from_utf8(head).map_err(|_| Refusal("400 Bad Request", "not UTF-8"))?;
    let mut lines = text.split('\n').map(|l| l.strip_suffix('\r').unwrap_or(l));
    let first = lines.next().unwrap_or("");
    if first.len() > limits.request_line {
        return Err(Refusal("414 URI Too Long", "request line too long"));
    }
    let mut parts = first.split(' ');
    let (Some(method), Some(target), Some(version), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(bad);
    };
    if method.is_empty() || !version.starts_with("HTTP/1.") {
        return Err(bad);
    }
    let (mut last_id, mut host, mut count) = (None, None, 0);
    for line in lines.filter(|l| !l.is_empty()) {
        count += 1;
        if count > MAX_HEADERS {
            return Err(Refusal(
                "431 Request Header Fields Too Large",
                "too many header fields",
            ));
        }
        let Some((k, v)) = line.split_once(':') else {
            return Err(bad);
        };
        let (k, v) = (k.trim(), v.trim());
        if k.eq_ignore_ascii_case("last-event-id") {
            last_id = v.parse().ok();
        } else if k.eq_ignore_ascii_case("host") {
            // Two Host fields: RFC 9112 section 3.2 says answer 400.
            if host.replace(v.to_string()).is_some() {
                return Err(bad);
            }
        }
    }
    let (path, query) = target.split_once('?').unwrap_or((target, ""));
    // `?last=N`: the page's own reconnect after an error status (`page_live.js`), where
    // the browser sends no `Last-Event-ID`.
    if last_id.is_none() {
        last_id = query
            .split('&')
            .find_map(|kv| kv.strip_prefix("last=")?.parse().ok());
    }
    let path = path.to_string();
    Ok(Request {
        method: method.to_string(),
        path,
        last_id,
        host,
    })
}

/// The names the page may be reached by (the `Host` header without its port).
#[derive(Clone, Debug)]
pub struct Hosts {
    names: Vec<String>,
    /// Bound beyond loopback: any IP address written as such is the client's own choice
    /// of this machine (a rebinding page has a name, never an address, for its origin).
    any_address: bool,
}

impl Hosts {
    /// For a server bound to `bound`: `localhost`, `127.0.0.1`, `[::1]` and the bound
    /// address; with `public` (bound beyond loopback), also any address literal and this
    /// machine's host name (and that name under `.local`, mDNS).
    pub fn new(bound: SocketAddr, public: bool) -> Hosts {
        let mut names: Vec<String> = ["localhost", "127.0.0.1", "[::1]"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        if !bound.ip().is_unspecified() {
            names.push(match bound {
                SocketAddr::V4(a) => a.ip().to_string(),
                SocketAddr::V6(a) => format!("[{}]", a.ip()),
            });
        }
        if public {
            if let Ok(h) = std::fs::read_to_string("/proc/sys/kernel/hostname") {
                let h = h.trim().to_ascii_lowercase();
                if !h.is_empty() {
                    names.push(format!("{h}.local"));
                    names.push(h);
                }
            }
        }
        Hosts {
            names,
            any_address: public,
        }
    }

    /// Whether `host` (a `Host` header's value) names this server.
    pub fn allows(&self, host: &str) -> bool {
        let host = host.trim().to_ascii_lowercase();
        let name = if host.starts_with('[') {
            match host.find(']') {
                Some(i) if host[i + 1..].is_empty() || is_port(&host[i + 1..]) => &host[..=i],
                _ => return false,
            }
        } else {
            match host.rsplit_once(':') {
                Some((n, p)) if is_port(&format!(":{p}")) => n,
                Some(_) => return false,
                None => &host,
            }
        };
        let name = name.strip_suffix('.').unwrap_or(name);
        if self.names.iter().any(|n| n == name) {
            return true;
        }
        self.any_address
            && (name.parse::<Ipv4Addr>().is_ok()
                || name
                    .strip_prefix('[')
                    .and_then(|n| n.strip_suffix(']'))
                    .is_some_and(|n| n.parse::<Ipv6Addr>().is_ok()))
    }
}

/// `:` and a port number.
fn is_port(s: &str) -> bool {
    s.strip_prefix(':')
        .is_some_and(|p| !p.is_empty() && p.len() <= 5 && p.bytes().all(|b| b.is_ascii_digit()))
}

/// Writes all of `buf` to `s` by `deadline` (not per call: a reader that takes a byte now
/// and then does not extend it); `TimedOut` when it passes.
pub(crate) fn write_by(s: &TcpStream, mut buf: &[u8], deadline: Instant) -> std::io::Result<()> {
    while !buf.is_empty() {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(ErrorKind::TimedOut.into());
        }
        s.set_write_timeout(Some(left))?;
        match (&*s).write(buf) {
            Ok(0) => return Err(ErrorKind::WriteZero.into()),
            Ok(n) => buf = &buf[n..],
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) if e.kind() == ErrorKind::WouldBlock => {
                return Err(ErrorKind::TimedOut.into());
            }
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// Writes `buf` in pieces of at most `limits.chunk` bytes, each by its own deadline of
/// `limits.stall`: a connection makes progress or is closed.
pub(crate) fn write_chunks(s: &TcpStream, buf: &[u8], limits: &Limits) -> std::io::Result<()> {
    for piece in buf.chunks(limits.chunk.max(1)) {
        write_by(s, piece, Instant::now() + limits.stall)?;
    }
    Ok(())
}

/// The head of a response with `Connection: close`; with `length`, a `Content-Length`
/// (without it the body ends when the connection does).
pub fn head(status: &str, ty: &str, length: Option<usize>) -> String {
    let length = length.map_or_else(String::new, |n| format!("Content-Length: {n}\r\n"));
    format!(
        "HTTP/1.1 {status}\r\nContent-Type: {ty}\r\n{length}Cache-Control: no-store\r\n\
         Connection: close\r\n\r\n"
    )
}

/// Answers a refused request (`refusal`'s status, its reason as the body) and closes the
/// connection: writing takes at most a second, and what the client still sends is read
/// and thrown away for at most half a second (64 KiB at most) so that closing does not
/// reset the connection before the client reads the answer.
pub fn refuse(s: &TcpStream, refusal: &Refusal, extra: &str) {
    let body = format!("{}\n", refusal.1);
    let text = format!(
        "HTTP/1.1 {}\r\nContent-Type: text/plain\r\nContent-Length: {}\r\n{extra}\
         Connection: close\r\n\r\n{body}",
        refusal.0,
        body.len()
    );
    if write_by(s, text.as_bytes(), Instant::now() + Duration::from_secs(1)).is_err() {
        return;
    }
    let _ = s.shutdown(Shutdown::Write);
    let deadline = Instant::now() + Duration::from_millis(500);
    let (mut piece, mut left) = ([0u8; 4096], 64 * 1024usize);
    while left > 0 {
        let t = deadline.saturating_duration_since(Instant::now());
        if t.is_zero() || s.set_read_timeout(Some(t)).is_err() {
            return;
        }
        match (&*s).read(&mut piece) {
            Ok(0) | Err(_) => return,
            Ok(n) => left = left.saturating_sub(n),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::net::TcpListener;

    /// The server's end of a connection whose client sends `bytes` (then waits).
    fn pair() -> (TcpStream, TcpStream) {
        let l = TcpListener::bind("127.0.0.1:0").unwrap();
        let c = TcpStream::connect(l.local_addr().unwrap()).unwrap();
        (l.accept().unwrap().0, c)
    }

    fn small() -> Limits {
        Limits {
            request_line: 64,
            head: 256,
            request_time: Duration::from_millis(300),
            ..Limits::default()
        }
    }

    #[test]
    fn a_request_head_is_read_with_its_host_and_last_event_id() {
        let (s, mut c) = pair();
        c.write_all(b"GET /events?x=1 HTTP/1.1\r\nHost: localhost:80\r\nLast-Event-ID: 7\r\n\r\n")
            .unwrap();
        let r = read_request(&s, &small()).unwrap().unwrap();
        let (s2, mut c2) = pair();
        c2.write_all(b"GET /events?x=1&last=9 HTTP/1.1\r\nHost: localhost\r\n\r\n")
            .unwrap();
        let reconnect = read_request(&s2, &small()).unwrap().unwrap();
        assert_eq!(
            (reconnect.path.as_str(), reconnect.last_id),
            ("/events", Some(9))
        );
        assert_eq!(
            r,
            Request {
                method: "GET".into(),
                path: "/events".into(),
                last_id: Some(7),
                host: Some("localhost:80".into()),
            }
        );
    }

    #[test]
    fn a_long_request_line_is_414_and_a_large_head_431() {
        let (s, mut c) = pair();
        c.write_all(&[b'a'; 200]).unwrap();
        assert_eq!(
            read_request(&s, &small()).unwrap_err().0,
            "414 URI Too Long"
        );
        let (s, mut c) = pair();
        c.write_all(b"GET / HTTP/1.1\r\n").unwrap();
        c.write_all(&[b'a'; 300]).unwrap();
        assert_eq!(
            read_request(&s, &small()).unwrap_err().0,
            "431 Request Header Fields Too Large"
        );
        let (s, mut c) = pair();
        c.write_all(b"GET / HTTP/1.1\r\n").unwrap();
        for _ in 0..101 {
            c.write_all(b"a:\n").unwrap();
        }
        c.write_all(b"\n").unwrap();
        let big = Limits {
            head: 4096,
            ..small()
        };
        assert_eq!(
            read_request(&s, &big).unwrap_err().0,
            "431 Request Header Fields Too Large"
        );
        for bad in [
            &b"GET /\r\n\r\n"[..],
            b"GET / FTP/1\r\n\r\n",
            b"GET / HTTP/1.1\r\nnocolon\r\n\r\n",
        ] {
            let (s, mut c) = pair();
            c.write_all(bad).unwrap();
            assert_eq!(read_request(&s, &small()).unwrap_err().0, "400 Bad Request");
        }
    }

    #[test]
    fn a_trickling_request_meets_one_deadline_for_the_whole_head() {
        let (s, mut c) = pair();
        let t = std::thread::spawn(move || {
            // A byte every 50 ms: each read succeeds, the head never ends in 300 ms.
            for b in b"GET / HTTP/1.1\r\nHost: localhost\r\nX: "
                .iter()
                .cycle()
                .take(40)
            {
                if c.write_all(&[*b]).is_err() {
                    return;
                }
                std::thread::sleep(Duration::from_millis(50));
            }
        });
        assert_eq!(
            read_request(&s, &small()).unwrap_err().0,
            "408 Request Timeout"
        );
        drop(s);
        t.join().unwrap();
    }

    #[test]
    fn hosts_are_loopback_names_unless_public() {
        let local = Hosts::new("127.0.0.1:8080".parse().unwrap(), false);
        for ok in [
            "localhost",
            "localhost:8080",
            "127.0.0.1:8080",
            "[::1]:1",
            "LOCALHOST.",
            "127.0.0.1",
        ] {
            assert!(local.allows(ok), "{ok}");
        }
        for no in [
            "evil.example",
            "evil.example:8080",
            "192.168.1.5:8080",
            "localhost:x",
            "[::1",
            "",
            "localhost:80:80",
        ] {
            assert!(!local.allows(no), "{no}");
        }
        let public = Hosts::new("0.0.0.0:8080".parse().unwrap(), true);
        for ok in ["192.168.1.5:8080", "[fe80::1]:8080", "localhost"] {
            assert!(public.allows(ok), "{ok}");
        }
        assert!(!public.allows("evil.example:8080"));
        let own = Hosts::new("10.1.2.3:80".parse().unwrap(), true);
        assert!(own.allows("10.1.2.3"));
    }

    #[test]
    fn a_write_to_a_reader_that_stopped_ends_at_its_deadline() {
        let (s, _c) = pair();
        let big = vec![b'x'; 64 << 20];
        let t = Instant::now();
        let e = write_by(&s, &big, Instant::now() + Duration::from_millis(300)).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::TimedOut);
        assert!(t.elapsed() >= Duration::from_millis(300));
    }
}
