//! What stops a check before it can judge the device.

/// A check that could not run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CheckError {
    /// The address is not `udp:HOST:PORT` (the bridge's own message, naming the option).
    #[error("{0}")]
    Address(String),
    /// The address cannot be bound (in use, not this machine's).
    #[error("cannot bind udp:{addr}: {reason}")]
    Bind {
        /// The address asked for.
        addr: std::net::SocketAddr,
        /// The system's reason.
        reason: String,
    },
    /// No hello arrived within the wait: the bridge's message, with what arrived instead.
    #[error("{0}")]
    NoHello(String),
    /// The socket failed while the check ran.
    #[error("the check's socket failed: {0}")]
    Socket(String),
    /// A value of the check's configuration out of range.
    #[error("{0}")]
    Config(String),
}
