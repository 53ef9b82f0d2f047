//! The plain answers of the page servers (`play`, `classroom`) and the WebSocket upgrade; the
//! request head and its `Host`/`Origin` check are [`webguard`]'s.

use std::io::Write;
use std::net::TcpStream;
use webguard::Head;

pub use webguard::serve::{respond, respond_text};

/// Completes a WebSocket upgrade (the head was checked and [`Head::is_upgrade`]).
pub fn accept_upgrade(stream: &mut TcpStream, head: &Head) -> std::io::Result<()> {
    let key = head.header("sec-websocket-key").unwrap_or_default();
    let accept = tungstenite::handshake::derive_accept_key(key.as_bytes());
    let resp = format!(
        "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: {accept}\r\n\r\n"
    );
    stream.write_all(resp.as_bytes())
}
