//! The device bridge: a haptic device in another process (a driver for a Falcon, a Touch, a
//! Force Dimension device, a Python script, or `nanohaptics fake-device`) sends numbered
//! samples over UDP and gets a force and a local stiffness back for each.
//!
//! - [`protocol`]: the versioned wire format (`docs/device-bridge.md` has the byte layout);
//! - [`udp`]: the simulator's side, a [`HapticDevice`](haptic_types::device::HapticDevice) with a
//!   watchdog-friendly sample clock and fault counters;
//! - [`fake`]: a stand-in device process with injectable loss, jitter, latency and an outage;
//! - [`check`]: the simulator's side played against a lab's device adapter, rule by rule
//!   (`nanohaptics device-check`).

pub mod check;
pub mod fake;
pub mod fault;
pub mod protocol;
pub mod rule;
pub mod rxbuf;
pub mod udp;

pub use udp::{BridgeConfig, UdpDevice};

/// Parses `SCHEME:HOST:PORT`, or `SCHEME:PORT` for loopback (`127.0.0.1`), the form of the
/// `--device udp:…` and `--live ws:…` options; the error names the option and shows `example`.
pub fn parse_endpoint(
    spec: &str,
    scheme: &str,
    option: &str,
    example: &str,
) -> Result<std::net::SocketAddr, String> {
    let addr = spec
        .strip_prefix(scheme)
        .and_then(|a| a.strip_prefix(':'))
        .ok_or_else(|| format!("{option} `{spec}`: expected {scheme}:HOST:PORT, e.g. {example}"))?;
    let loopback = addr.parse::<u16>().ok().map(|p| format!("127.0.0.1:{p}"));
    let addr = loopback.as_deref().unwrap_or(addr);
    addr.parse().map_err(|_| {
        format!(
            "{option} `{spec}`: `{addr}` is not an IP address and port (e.g. {})",
            example.split_once(':').map_or(example, |x| x.1)
        )
    })
}
