//! The bridge socket's kernel receive buffer, sized to hold a scheduling hiccup.
//!
//! A 10 kHz device sends a datagram every 100 µs. When the receiver thread is off the CPU (a
//! loaded machine with two cores), the kernel queues the device's datagrams in the socket's
//! receive buffer and drops what does not fit. Linux's default (`net.core.rmem_default`,
//! 208 KiB) holds about 20 ms of a 10 kHz device, since each small datagram is charged about a
//! kilobyte; [`RECEIVE_BUFFER_BYTES`] asks for ten times that. The kernel grants at most
//! `net.core.rmem_max` without privileges and never refuses the request, so what was granted
//! is read back and reported, not assumed.

use std::net::UdpSocket;

/// The receive buffer the bridge asks for, bytes (the kernel doubles it for its bookkeeping and
/// caps it at `net.core.rmem_max`).
pub const RECEIVE_BUFFER_BYTES: usize = 1 << 21;

/// Asks for a receive buffer of `bytes` and returns what the kernel granted, bytes, or `None`
/// where the system cannot say.
#[cfg(unix)]
#[allow(unsafe_code)] // two libc calls on a socket this bridge owns, with c_int values
pub fn enlarge(socket: &UdpSocket, bytes: usize) -> Option<usize> {
    use std::os::fd::AsRawFd;
    let fd = socket.as_raw_fd();
    let want = libc::c_int::try_from(bytes).unwrap_or(libc::c_int::MAX);
    let size = std::mem::size_of::<libc::c_int>() as libc::socklen_t;
    // SAFETY: a valid socket descriptor and a c_int option value of the stated size.
    let set = unsafe {
        libc::setsockopt(
            fd,
            libc::SOL_SOCKET,
            libc::SO_RCVBUF,
            (&want as *const libc::c_int).cast(),
            size,
        )
    };
    let mut got: libc::c_int = 0;
    let mut len = size;
    // SAFETY: as above; `got` and `len` are valid for writes of their sizes.
    let read = unsafe {
        libc::getsockopt(
            fd,
            libc::SOL_SOCKET,
            libc::SO_RCVBUF,
            (&mut got as *mut libc::c_int).cast(),
            &mut len,
        )
    };
    (set == 0 && read == 0)
        .then(|| usize::try_from(got).ok())
        .flatten()
}

/// Elsewhere the system's default buffer is kept.
#[cfg(not(unix))]
pub fn enlarge(_socket: &UdpSocket, _bytes: usize) -> Option<usize> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_buffer_grows_up_to_what_the_system_allows() {
        let s = UdpSocket::bind("127.0.0.1:0").unwrap();
        let got = enlarge(&s, RECEIVE_BUFFER_BYTES).unwrap();
        // Linux doubles the request, capped at rmem_max, for its bookkeeping.
        let max = std::fs::read_to_string("/proc/sys/net/core/rmem_max")
            .unwrap()
            .trim()
            .parse::<usize>()
            .unwrap();
        assert_eq!(got, 2 * RECEIVE_BUFFER_BYTES.min(max));
    }
}
