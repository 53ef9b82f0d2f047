//! The `page` target: what a browser (or anything else on the network) sends the page servers
//! (`play`, `classroom`) — the HTTP request head, a page's WebSocket message, a student's name.
//! The first byte picks which; nothing may panic, and what is accepted must read back the same.

use crate::outcome::Outcome;
use webguard::{Guard, HeadError, MAX_HEAD_BYTES, parse_head, percent_decode};

/// One input: byte 0 selects the reader (even: an HTTP head, 1 mod 4: a page message, 3 mod 4:
/// a student's name), the rest is its text.
pub fn run_page(input: &[u8]) -> Outcome {
    let Some((&mode, rest)) = input.split_first() else {
        return Outcome::Refused;
    };
    match mode % 4 {
        0 | 2 => head(rest),
        1 => message(rest),
        _ => name(rest),
    }
}

fn finding(kind: &'static str, what: String) -> Outcome {
    Outcome::Finding(kind, what)
}

fn head(bytes: &[u8]) -> Outcome {
    let Ok(h) = parse_head(bytes) else {
        return Outcome::Refused;
    };
    // Written back in its own form, it reads back the same.
    let mut text = format!("{} {} HTTP/1.1\r\n", h.method, h.target);
    for (n, v) in &h.headers {
        text.push_str(&format!("{n}: {v}\r\n"));
    }
    text.push_str("\r\n");
    // The canonical form may be longer than what was read (`name:value` gains a space, a head
    // without its blank line gains one); past the limit the one right answer is `TooLong`.
    match parse_head(text.as_bytes()) {
        Ok(again) if again == h => {}
        Err(HeadError::TooLong { limit }) if text.len() > limit && limit == MAX_HEAD_BYTES => {}
        other => {
            return finding(
                "not-idempotent",
                format!("a head read back differently: {h:?} then {other:?}"),
            );
        }
    }
    // Both guards answer without panicking; loopback never allows what a network guard refuses.
    for port in [80, 8080] {
        let lo = Guard {
            port,
            loopback_only: true,
            other_origins: Vec::new(),
        };
        let net = Guard {
            port,
            loopback_only: false,
            other_origins: Vec::new(),
        };
        if lo.check(&h).is_ok() && net.check(&h).is_err() {
            return finding(
                "guard",
                format!("loopback allowed a head the network guard refused: {h:?}"),
            );
        }
    }
    let _ = h.query("s").map(|s| s.len());
    let _ = percent_decode(&h.target);
    Outcome::Accepted
}

fn message(bytes: &[u8]) -> Outcome {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return Outcome::Refused;
    };
    match play::protocol::parse(text, 0b1111) {
        Ok(m) => match play::protocol::parse(&m.to_json(), 0b1111) {
            Ok(again) if again == m => Outcome::Accepted,
            other => finding(
                "not-idempotent",
                format!("a page message read back differently: {m:?} then {other:?}"),
            ),
        },
        Err(e) => {
            // Every refusal names its field.
            if e.field().is_empty() {
                return finding("unnamed", format!("a refusal without its field: {e}"));
            }
            Outcome::Refused
        }
    }
}

fn name(bytes: &[u8]) -> Outcome {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return Outcome::Refused;
    };
    let Ok(n) = play::classroom::names::check_name(text) else {
        return Outcome::Refused;
    };
    let dir = std::path::Path::new("/class");
    let p = play::classroom::names::recording_path(dir, &n, 1, &[]);
    let file = p.file_name().map(|f| f.to_string_lossy().to_string());
    let ok = p.parent() == Some(dir)
        && file.as_deref().is_some_and(|f| {
            !f.starts_with('.')
                && f.bytes()
                    .all(|c| c.is_ascii_alphanumeric() || c == b'_' || c == b'-' || c == b'.')
        });
    if ok {
        Outcome::Accepted
    } else {
        finding(
            "path",
            format!("the name `{n}` made the recording path {}", p.display()),
        )
    }
}

/// Seeds: heads, page messages and names, each with its selector byte.
pub fn seeds() -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    let mut push = |mode: u8, text: &str| {
        let mut v = vec![mode];
        v.extend_from_slice(text.as_bytes());
        out.push(v);
    };
    push(
        0,
        "GET /ws?s=abc HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nOrigin: http://127.0.0.1:8080\r\nUpgrade: websocket\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n",
    );
    push(
        0,
        "GET /join?name=Ada+L%C3%B6w&code=123456 HTTP/1.1\r\nHost: [::1]:8080\r\n\r\n",
    );
    push(
        2,
        "GET / HTTP/1.0\r\nHost: evil.example:8080\r\nOrigin: null\r\n\r\n",
    );
    for m in play::protocol::PageMsg::examples() {
        push(1, &m.to_json());
    }
    push(
        1,
        r#"{"type":"input","seq":1e300,"pos":[null,{},[]],"buttons":1.5,"t_ms":-1}"#,
    );
    push(3, "Zoë O'Brien-2");
    push(3, "../etc/passwd");
    out
}
