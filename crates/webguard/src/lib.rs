//! # webguard: who may talk to a local web server
//!
//! The request head of an HTTP request read within bounds, and the two checks every request
//! and WebSocket upgrade of the project's servers passes (`Host` and `Origin`): the page
//! servers (`play`, `classroom`) and the live view (`run --live`). It is for small servers on
//! plain threads; it is no HTTP implementation (no bodies but a small form ([`form`]), no
//! chunking, no keep-alive) and no authentication.
//!
//! **Why the checks.** Loopback is no boundary against other pages in the same browser. A page
//! from any site can open `ws://127.0.0.1:8080/ws` (the browser sends its own `Origin`), and a
//! DNS-rebinding page reaches the server under its own host name (the browser sends that name
//! as `Host`). So the server answers only requests whose `Host` is one of its own addresses —
//! `localhost`, a loopback address, or, when it serves a network, an IP address — with its
//! port, and whose `Origin`, when a browser sends one, is that same `http://HOST:PORT`. A
//! rebinding page's host name and another site's origin are refused with `403`.

pub mod form;
pub mod gate;
pub mod serve;

use std::io::Read;
use std::net::{IpAddr, TcpStream};
use std::time::Duration;

/// Longest request head read, bytes (request line and headers).
pub const MAX_HEAD_BYTES: usize = 8 * 1024;
/// Most header lines in a request head.
pub const MAX_HEADERS: usize = 64;
/// How long a client may take to send its request head, s.
pub const HEAD_TIMEOUT_S: u64 = 5;

/// A request's head: method, target (path and query) and headers (names lower-cased).
#[derive(Clone, Debug, PartialEq)]
pub struct Head {
    /// `GET`, `POST`, …
    pub method: String,
    /// The request target as sent (`/ws?s=…`).
    pub target: String,
    /// Header lines (name lower-cased, value trimmed), in order.
    pub headers: Vec<(String, String)>,
}

impl Head {
    /// The first header `name` (lower-case).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// The target's path (before `?`).
    pub fn path(&self) -> &str {
        self.target.split('?').next().unwrap_or("/")
    }

    /// The query parameter `key`, percent-decoded (`+` is a space); `None` when absent or not
    /// valid UTF-8 once decoded.
    pub fn query(&self, key: &str) -> Option<String> {
        let q = self.target.split_once('?')?.1;
        q.split('&')
            .filter_map(|kv| kv.split_once('=').or(Some((kv, ""))))
            .find(|(k, _)| *k == key)
            .and_then(|(_, v)| percent_decode(v))
    }

    /// Whether this is a WebSocket upgrade (`Upgrade: websocket` with a key).
    pub fn is_upgrade(&self) -> bool {
        self.header("upgrade")
            .is_some_and(|u| u.eq_ignore_ascii_case("websocket"))
            && self.header("sec-websocket-key").is_some()
    }
}

/// Decodes `%XX` escapes and `+`; `None` on a bad escape or bytes that are not UTF-8.
pub fn percent_decode(s: &str) -> Option<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'%' => {
                let hex = s.get(i + 1..i + 3)?;
                out.push(u8::from_str_radix(hex, 16).ok()?);
                i += 3;
            }
            b'+' => {
                out.push(b' ');
                i += 1;
            }
            c => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8(out).ok()
}

/// Why a request head was not read.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HeadError {
    /// The head did not end within [`MAX_HEAD_BYTES`].
    #[error("the request head is longer than {limit} bytes")]
    TooLong {
        /// The limit, bytes.
        limit: usize,
    },
    /// More than [`MAX_HEADERS`] header lines.
    #[error("the request has more than {limit} header lines")]
    TooManyHeaders {
        /// The limit.
        limit: usize,
    },
    /// Not UTF-8.
    #[error("the request head is not UTF-8 text")]
    NotText,
    /// The request line is not `METHOD TARGET HTTP/1.x`.
    #[error("the request line is not `METHOD TARGET HTTP/1.1`")]
    RequestLine,
    /// A header line without `:`, or with a name that is not a token.
    #[error("header line {line} is not `Name: value`")]
    HeaderLine {
        /// Its number (1: the first header line).
        line: usize,
    },
    /// The connection closed or timed out before the head ended.
    #[error("the connection ended before the request head did")]
    Closed,
}

fn is_token(s: &str) -> bool {
    !s.is_empty()
        && s.bytes()
            .all(|c| c.is_ascii_alphanumeric() || b"!#$%&'*+-.^_`|~".contains(&c))
}

/// Parses a complete request head (up to and including the blank line, or without it).
pub fn parse_head(bytes: &[u8]) -> Result<Head, HeadError> {
    if bytes.len() > MAX_HEAD_BYTES {
        return Err(HeadError::TooLong {
            limit: MAX_HEAD_BYTES,
        });
    }
    let text = std::str::from_utf8(bytes).map_err(|_| HeadError::NotText)?;
    let text = text.strip_suffix("\r\n\r\n").unwrap_or(text);
    let mut lines = text.split("\r\n");
    let first = lines.next().ok_or(HeadError::RequestLine)?;
    let mut parts = first.split(' ');
    let (Some(method), Some(target), Some(version), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(HeadError::RequestLine);
    };
    if !is_token(method)
        || !target.starts_with('/')
        || target.bytes().any(|c| c <= b' ' || c == 0x7f)
        || !(version == "HTTP/1.1" || version == "HTTP/1.0")
    {
        return Err(HeadError::RequestLine);
    }
    let mut headers = Vec::new();
    for (k, l) in lines.enumerate() {
        if headers.len() == MAX_HEADERS {
            return Err(HeadError::TooManyHeaders { limit: MAX_HEADERS });
        }
        let (n, v) = l
            .split_once(':')
            .ok_or(HeadError::HeaderLine { line: k + 1 })?;
        if !is_token(n) || v.bytes().any(|c| c == b'\r' || c == b'\n' || c == 0) {
            return Err(HeadError::HeaderLine { line: k + 1 });
        }
        headers.push((n.to_ascii_lowercase(), v.trim().to_string()));
    }
    Ok(Head {
        method: method.to_string(),
        target: target.to_string(),
        headers,
    })
}

/// Reads a request head from `stream` (at most [`MAX_HEAD_BYTES`], within
/// [`HEAD_TIMEOUT_S`]) and parses it.
pub fn read_head(stream: &mut TcpStream) -> Result<Head, HeadError> {
    read_head_bytes(stream).map(|(_, h)| h)
}

/// As [`read_head`], with the head's bytes as read (to pass on unchanged).
pub fn read_head_bytes(stream: &mut TcpStream) -> Result<(Vec<u8>, Head), HeadError> {
    stream
        .set_read_timeout(Some(Duration::from_secs(HEAD_TIMEOUT_S)))
        .map_err(|_| HeadError::Closed)?;
    let mut buf = Vec::with_capacity(1024);
    let mut byte = [0u8; 1];
    while !buf.ends_with(b"\r\n\r\n") {
        if buf.len() >= MAX_HEAD_BYTES {
            return Err(HeadError::TooLong {
                limit: MAX_HEAD_BYTES,
            });
        }
        match stream.read(&mut byte) {
            Ok(1) => buf.push(byte[0]),
            _ => return Err(HeadError::Closed),
        }
    }
    let h = parse_head(&buf)?;
    Ok((buf, h))
}

/// Which host names a server answers to.
#[derive(Clone, Debug, PartialEq)]
pub struct Guard {
    /// The port served.
    pub port: u16,
    /// Loopback only (`localhost`, `127.0.0.0/8`, `[::1]`); otherwise any IP address too (a
    /// class network), never a DNS name other than `localhost`.
    pub loopback_only: bool,
    /// Origins allowed besides the page's own (`https://app.foxglove.dev` for the live view;
    /// none for the page servers).
    pub other_origins: Vec<String>,
}

/// A request refused by the [`Guard`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Refusal {
    /// No `Host` header (HTTP/1.1 requires one).
    #[error("the request has no Host header")]
    NoHost,
    /// `Host` is not one of this server's addresses (a DNS-rebinding page sends its own name).
    #[error(
        "Host `{got}` is not this server's address: allowed {allowed} with port {port} (a page \
         under another host name may not reach this server)"
    )]
    Host {
        /// The `Host` sent.
        got: String,
        /// What is allowed, in words.
        allowed: &'static str,
        /// The port served.
        port: u16,
    },
    /// `Origin` is another site than the page's own.
    #[error(
        "Origin `{got}` is not this page's own origin `{expected}`: a page from another site \
         may not use this server"
    )]
    Origin {
        /// The `Origin` sent.
        got: String,
        /// The page's own origin (`http://` and the request's `Host`).
        expected: String,
    },
}

impl Refusal {
    /// Short name for counters (`host`, `origin`).
    pub fn kind(&self) -> &'static str {
        match self {
            Refusal::NoHost | Refusal::Host { .. } => "host",
            Refusal::Origin { .. } => "origin",
        }
    }
}

/// Splits `host[:port]` (`[v6]:port` for IPv6) into the name and the port (`None`: absent).
fn split_host(h: &str) -> Option<(&str, Option<&str>)> {
    if let Some(rest) = h.strip_prefix('[') {
        let (addr, after) = rest.split_once(']')?;
        return match after {
            "" => Some((addr, None)),
            p => Some((addr, Some(p.strip_prefix(':')?))),
        };
    }
    match h.rsplit_once(':') {
        Some((n, p)) if !n.contains(':') => Some((n, Some(p))),
        Some(_) => None,
        None => Some((h, None)),
    }
}

impl Guard {
    /// What [`Guard::check`] allows, in words.
    pub fn allowed(&self) -> &'static str {
        if self.loopback_only {
            "localhost, 127.0.0.1 or [::1]"
        } else {
            "localhost or an IP address of this machine"
        }
    }

    /// Whether `host` (a `Host` header value) names this server.
    pub fn host_ok(&self, host: &str) -> bool {
        let Some((name, port)) = split_host(host) else {
            return false;
        };
        let port_ok = match port {
            None => self.port == 80,
            Some(p) => p.parse::<u16>().is_ok_and(|p| p == self.port) && !p.starts_with('+'),
        };
        if !port_ok {
            return false;
        }
        if name.eq_ignore_ascii_case("localhost") {
            return true;
        }
        match name.parse::<IpAddr>() {
            Ok(ip) => ip.is_loopback() || !self.loopback_only,
            Err(_) => false,
        }
    }

    /// Checks a request's `Host` and, when present, its `Origin` (which must be
    /// `http://` followed by the `Host`).
    pub fn check(&self, head: &Head) -> Result<(), Refusal> {
        let host = head.header("host").ok_or(Refusal::NoHost)?;
        if !self.host_ok(host) {
            return Err(Refusal::Host {
                got: host.to_string(),
                allowed: self.allowed(),
                port: self.port,
            });
        }
        if let Some(origin) = head.header("origin") {
            let expected = format!("http://{host}");
            let other = self
                .other_origins
                .iter()
                .any(|o| o.eq_ignore_ascii_case(origin));
            if !origin.eq_ignore_ascii_case(&expected) && !other {
                return Err(Refusal::Origin {
                    got: origin.to_string(),
                    expected,
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn head(text: &str) -> Head {
        parse_head(text.replace('\n', "\r\n").as_bytes()).unwrap()
    }

    #[test]
    fn a_head_is_parsed_with_its_query() {
        let h = head("GET /join?name=Ada+L%C3%B6w&code=12 HTTP/1.1\nHost: 127.0.0.1:8080\n\n");
        assert_eq!(h.path(), "/join");
        assert_eq!(h.query("name").as_deref(), Some("Ada Löw"));
        assert_eq!(h.query("code").as_deref(), Some("12"));
        assert_eq!(h.query("x"), None);
        assert_eq!(h.header("host"), Some("127.0.0.1:8080"));
    }

    #[test]
    fn bad_heads_are_refused_with_their_reason() {
        let e = |t: &str| parse_head(t.as_bytes()).unwrap_err().to_string();
        assert_eq!(
            e("GET / HTTP/1.1 extra\r\n\r\n"),
            "the request line is not `METHOD TARGET HTTP/1.1`"
        );
        assert_eq!(
            e("GET http://x/ HTTP/1.1\r\n\r\n"),
            "the request line is not `METHOD TARGET HTTP/1.1`"
        );
        assert_eq!(
            e("GET / HTTP/1.1\r\nHost 1\r\n\r\n"),
            "header line 1 is not `Name: value`"
        );
        let many: String = (0..=MAX_HEADERS).map(|k| format!("X-{k}: 1\r\n")).collect();
        assert_eq!(
            e(&format!("GET / HTTP/1.1\r\n{many}\r\n")),
            "the request has more than 64 header lines"
        );
        let long = format!("GET /{} HTTP/1.1\r\n\r\n", "a".repeat(MAX_HEAD_BYTES));
        assert_eq!(e(&long), "the request head is longer than 8192 bytes");
        assert_eq!(
            parse_head(b"GET / HTTP/1.1\r\nX: \xff\r\n\r\n").unwrap_err(),
            HeadError::NotText
        );
    }

    #[test]
    fn only_this_servers_host_and_own_origin_pass() {
        let g = Guard {
            port: 8080,
            loopback_only: true,
            other_origins: Vec::new(),
        };
        let req = |host: &str, origin: Option<&str>| {
            let o = origin.map(|o| format!("Origin: {o}\n")).unwrap_or_default();
            g.check(&head(&format!("GET /ws HTTP/1.1\nHost: {host}\n{o}\n")))
        };
        for ok in [
            "127.0.0.1:8080",
            "localhost:8080",
            "[::1]:8080",
            "127.0.0.2:8080",
        ] {
            assert_eq!(req(ok, None), Ok(()), "{ok}");
            assert_eq!(req(ok, Some(&format!("http://{ok}"))), Ok(()), "{ok}");
        }
        // DNS rebinding: the attacker's name with our port.
        assert_eq!(
            req("evil.example:8080", None).unwrap_err().to_string(),
            "Host `evil.example:8080` is not this server's address: allowed localhost, \
             127.0.0.1 or [::1] with port 8080 (a page under another host name may not reach \
             this server)"
        );
        for bad in [
            "127.0.0.1",
            "127.0.0.1:80",
            "127.0.0.1:+8080",
            "192.168.1.4:8080",
            "localhost.evil.example:8080",
            "[::1]x:8080",
        ] {
            assert_eq!(req(bad, None).unwrap_err().kind(), "host", "{bad}");
        }
        // Cross-site WebSocket hijacking: another page's origin.
        assert_eq!(
            req("127.0.0.1:8080", Some("https://evil.example"))
                .unwrap_err()
                .to_string(),
            "Origin `https://evil.example` is not this page's own origin \
             `http://127.0.0.1:8080`: a page from another site may not use this server"
        );
        for bad in ["null", "http://localhost:8080", "http://127.0.0.1:8081"] {
            assert_eq!(
                req("127.0.0.1:8080", Some(bad)).unwrap_err().kind(),
                "origin",
                "{bad}"
            );
        }
        assert_eq!(g.check(&head("GET / HTTP/1.1\n\n")), Err(Refusal::NoHost));
        // A class network: IP addresses too, never a DNS name.
        let net = Guard {
            port: 8080,
            loopback_only: false,
            other_origins: vec!["https://app.foxglove.dev".into()],
        };
        assert_eq!(
            net.check(&head(
                "GET / HTTP/1.1\nHost: 10.0.0.2:8080\nOrigin: https://app.foxglove.dev\n\n"
            )),
            Ok(())
        );
        assert!(net.host_ok("192.168.1.4:8080"));
        assert!(net.host_ok("[fe80::1]:8080"));
        assert!(!net.host_ok("school.example:8080"));
    }
}
