//! What a page server accepts: its limits (connections in all and per address, message size
//! and rate) and the count of everything it refused, by reason. One [`Gate`] per listening
//! server; every connection passes it before its request is read.

use crate::Guard;
use std::collections::HashMap;
use std::net::IpAddr;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// A server's limits.
#[derive(Clone, Debug, PartialEq)]
pub struct Limits {
    /// Connections open at once (HTTP and WebSocket).
    pub max_connections: usize,
    /// Connections open at once from one address.
    pub max_per_address: usize,
    /// Largest WebSocket message a page may send, bytes.
    pub max_message_bytes: usize,
    /// Messages a page may send per second (sustained; a burst of as many is allowed).
    pub messages_per_s: u32,
    /// Bytes written to a page but not yet taken by its socket, kept at most: beyond, the
    /// messages for that page are dropped (counted) until it reads again.
    pub max_write_buffer_bytes: usize,
    /// The kernel's send buffer of each connection, bytes (`None`: the system's own, which
    /// grows to a few MiB).
    pub send_buffer_bytes: Option<usize>,
}

impl Default for Limits {
    /// One player: 64 connections, 16 per address, 4 KiB messages, 500 messages/s, 256 KiB
    /// waiting to be written per page, the system's send buffers.
    fn default() -> Self {
        Limits {
            max_connections: 64,
            max_per_address: 16,
            max_message_bytes: 4096,
            messages_per_s: 500,
            max_write_buffer_bytes: 256 * 1024,
            send_buffer_bytes: None,
        }
    }
}

/// Requests and messages refused, by reason (each answered with its reason).
#[derive(Debug, Default)]
pub struct Refused {
    /// A `Host` that is not the server's (DNS rebinding) or none.
    pub host: AtomicU64,
    /// An `Origin` of another site (cross-site WebSocket hijacking).
    pub origin: AtomicU64,
    /// A request head that was too long, malformed or never finished.
    pub head: AtomicU64,
    /// Over the connection limits (in all or per address).
    pub connections: AtomicU64,
    /// A WebSocket message over the size limit.
    pub size: AtomicU64,
    /// Page messages over the rate limit.
    pub rate: AtomicU64,
    /// A student name refused (length or characters), or a class already full.
    pub join: AtomicU64,
    /// A wrong join or teacher code.
    pub code: AtomicU64,
}

/// A snapshot of [`Refused`].
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct RefusedCounts {
    /// See [`Refused::host`].
    pub host: u64,
    /// See [`Refused::origin`].
    pub origin: u64,
    /// See [`Refused::head`].
    pub head: u64,
    /// See [`Refused::connections`].
    pub connections: u64,
    /// See [`Refused::size`].
    pub size: u64,
    /// See [`Refused::rate`].
    pub rate: u64,
    /// See [`Refused::join`].
    pub join: u64,
    /// See [`Refused::code`].
    pub code: u64,
}

impl RefusedCounts {
    /// All refusals.
    pub fn total(&self) -> u64 {
        self.host
            + self.origin
            + self.head
            + self.connections
            + self.size
            + self.rate
            + self.join
            + self.code
    }
}

impl Refused {
    /// Counts one refusal of `kind` (a [`RefusedCounts`] field name).
    pub fn count(&self, kind: &str) {
        let c = match kind {
            "host" => &self.host,
            "origin" => &self.origin,
            "connections" => &self.connections,
            "size" => &self.size,
            "rate" => &self.rate,
            "join" => &self.join,
            "code" => &self.code,
            _ => &self.head,
        };
        c.fetch_add(1, Ordering::Relaxed);
    }

    /// The counts now.
    pub fn snapshot(&self) -> RefusedCounts {
        let l = |a: &AtomicU64| a.load(Ordering::Relaxed);
        RefusedCounts {
            host: l(&self.host),
            origin: l(&self.origin),
            head: l(&self.head),
            connections: l(&self.connections),
            size: l(&self.size),
            rate: l(&self.rate),
            join: l(&self.join),
            code: l(&self.code),
        }
    }
}

/// A listening server's checks, limits and counts.
#[derive(Debug)]
pub struct Gate {
    /// The `Host`/`Origin` check.
    pub guard: Guard,
    /// The limits.
    pub limits: Limits,
    /// What was refused.
    pub refused: Refused,
    open: Mutex<HashMap<IpAddr, usize>>,
    total: AtomicUsize,
}

/// An admitted connection; its place is freed when dropped.
pub struct Ticket {
    gate: Arc<Gate>,
    peer: IpAddr,
}

impl Drop for Ticket {
    fn drop(&mut self) {
        self.gate.total.fetch_sub(1, Ordering::Relaxed);
        if let Ok(mut m) = self.gate.open.lock()
            && let Some(n) = m.get_mut(&self.peer)
        {
            *n -= 1;
            if *n == 0 {
                m.remove(&self.peer);
            }
        }
    }
}

impl Gate {
    /// A gate with `guard` and `limits`.
    pub fn new(guard: Guard, limits: Limits) -> Self {
        Gate {
            guard,
            limits,
            refused: Refused::default(),
            open: Mutex::new(HashMap::new()),
            total: AtomicUsize::new(0),
        }
    }

    /// Admits a connection from `peer`, or says which limit it is over (counted).
    pub fn admit(self: &Arc<Self>, peer: IpAddr) -> Result<Ticket, String> {
        let mut m = self
            .open
            .lock()
            .map_err(|_| "the server is shutting down".to_string())?;
        let n = m.get(&peer).copied().unwrap_or(0);
        let total = self.total.load(Ordering::Relaxed);
        let over = if total >= self.limits.max_connections {
            Some(format!(
                "the server has {} connections open, its limit: try again shortly",
                self.limits.max_connections
            ))
        } else if n >= self.limits.max_per_address {
            Some(format!(
                "{peer} has {} connections open, the limit per address: close a tab or try \
                 again shortly",
                self.limits.max_per_address
            ))
        } else {
            None
        };
        if let Some(msg) = over {
            self.refused.count("connections");
            return Err(msg);
        }
        m.insert(peer, n + 1);
        self.total.fetch_add(1, Ordering::Relaxed);
        Ok(Ticket {
            gate: self.clone(),
            peer,
        })
    }
}

/// Sets the kernel's send buffer of `stream` to `bytes` (best effort).
#[allow(unsafe_code)] // one setsockopt on a socket this server owns
pub fn set_send_buffer(stream: &std::net::TcpStream, bytes: usize) {
    #[cfg(unix)]
    {
        use std::os::fd::AsRawFd;
        let v = libc::c_int::try_from(bytes).unwrap_or(libc::c_int::MAX);
        // SAFETY: a valid socket descriptor and a c_int option value of the right size.
        unsafe {
            let _ = libc::setsockopt(
                stream.as_raw_fd(),
                libc::SOL_SOCKET,
                libc::SO_SNDBUF,
                (&v as *const libc::c_int).cast(),
                std::mem::size_of::<libc::c_int>() as libc::socklen_t,
            );
        }
    }
}

/// A page's message allowance: [`Limits::messages_per_s`] per second, in bursts of as many.
#[derive(Debug)]
pub struct RateLimit {
    per_s: f64,
    tokens: f64,
    at: Instant,
}

impl RateLimit {
    /// A full allowance of `per_s` messages per second.
    pub fn new(per_s: u32) -> Self {
        RateLimit {
            per_s: f64::from(per_s.max(1)),
            tokens: f64::from(per_s.max(1)),
            at: Instant::now(),
        }
    }

    /// Takes one message at `now`; false when over the rate (the message is refused).
    pub fn take(&mut self, now: Instant) -> bool {
        let dt = now.saturating_duration_since(self.at).as_secs_f64();
        self.at = now;
        self.tokens = (self.tokens + dt * self.per_s).min(self.per_s);
        if self.tokens >= 1.0 {
            self.tokens -= 1.0;
            true
        } else {
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn gate(max: usize, per: usize) -> Arc<Gate> {
        Arc::new(Gate::new(
            Guard {
                port: 1,
                loopback_only: true,
                other_origins: Vec::new(),
            },
            Limits {
                max_connections: max,
                max_per_address: per,
                ..Limits::default()
            },
        ))
    }

    #[test]
    fn connections_are_limited_per_address_and_in_all() {
        let g = gate(3, 2);
        let a: IpAddr = "127.0.0.1".parse().unwrap();
        let b: IpAddr = "127.0.0.2".parse().unwrap();
        let t1 = g.admit(a).unwrap();
        let _t2 = g.admit(a).unwrap();
        assert_eq!(
            g.admit(a).err().unwrap(),
            "127.0.0.1 has 2 connections open, the limit per address: close a tab or try \
             again shortly"
        );
        let _t3 = g.admit(b).unwrap();
        assert_eq!(
            g.admit(b).err().unwrap(),
            "the server has 3 connections open, its limit: try again shortly"
        );
        drop(t1);
        assert!(g.admit(a).is_ok());
        assert_eq!(g.refused.snapshot().connections, 2);
        assert_eq!(g.refused.snapshot().total(), 2);
    }

    #[test]
    fn the_rate_limit_allows_its_rate_and_refuses_beyond() {
        let mut r = RateLimit::new(100);
        let t0 = Instant::now();
        // A burst of 100, then nothing more in the same instant.
        assert_eq!((0..150).filter(|_| r.take(t0)).count(), 100);
        // One second later, 100 more.
        let t1 = t0 + Duration::from_secs(1);
        assert_eq!((0..150).filter(|_| r.take(t1)).count(), 100);
        // 10 ms later: one per 10 ms.
        let t2 = t1 + Duration::from_millis(10);
        assert_eq!((0..5).filter(|_| r.take(t2)).count(), 1);
    }
}
