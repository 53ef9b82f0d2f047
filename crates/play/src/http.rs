//! The plain answers of the page servers (`play`, `classroom`) and the WebSocket upgrade; the
//! request head and its `Host`/`Origin` check are [`webguard`]'s.

use std::io::Write;
use std::net::TcpStream;
use webguard::Head;

/// Writes a complete response (`Connection: close`, never cached).
pub fn respond(stream: &mut TcpStream, status: &str, ctype: &str, extra: &str, body: &[u8]) {
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {ctype}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n{extra}Connection: close\r\n\r\n",
        body.len()
    );
    let _ = stream.write_all(head.as_bytes());
    let _ = stream.write_all(body);
    let _ = stream.flush();
}

/// Answers with a plain-text message.
pub fn respond_text(stream: &mut TcpStream, status: &str, message: &str) {
    respond(
        stream,
        status,
        "text/plain; charset=utf-8",
        "",
        format!("{message}\n").as_bytes(),
    );
}

/// Completes a WebSocket upgrade (the head was checked and [`Head::is_upgrade`]).
pub fn accept_upgrade(stream: &mut TcpStream, head: &Head) -> std::io::Result<()> {
    let key = head.header("sec-websocket-key").unwrap_or_default();
    let accept = tungstenite::handshake::derive_accept_key(key.as_bytes());
    let resp = format!(
        "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: {accept}\r\n\r\n"
    );
    stream.write_all(resp.as_bytes())
}
