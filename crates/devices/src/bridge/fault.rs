//! The fake device's deliberate faults (`fake-device --fault`): each breaks one rule of
//! `docs/device-bridge.md` as a lab's adapter might, so `nanohaptics device-check` can be seen
//! failing by rule.

/// A deliberate fault of the fake device (`fake-device --fault`), each breaking one rule of
/// `docs/device-bridge.md` as a lab's adapter might, so that `nanohaptics device-check` can be
/// seen failing by rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// Numbers its samples from 1 after the welcome, not from 0.
    NumbersFrom1,
    /// Renders none of the local model's contact planes (the carried body's own surfaces
    /// still hold the body); a modelled device speaking protocol 2 only.
    IgnoresPlanes,
    /// Backs off when answers stop: after [`BACK_OFF_AFTER_S`] without one it sends only every
    /// tenth period's sample (numbered +1 per sample sent).
    BacksOffInSilence,
    /// Runs its servo, and so sends its samples, at half the welcome's rate.
    HalfRate,
}

/// How long without an answer before [`Fault::BacksOffInSilence`] backs off, s.
pub const BACK_OFF_AFTER_S: f64 = 0.1;

impl Fault {
    /// Every fault, in the order of [`Fault::names`].
    pub const ALL: [Fault; 4] = [
        Fault::NumbersFrom1,
        Fault::IgnoresPlanes,
        Fault::BacksOffInSilence,
        Fault::HalfRate,
    ];

    /// The fault's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Fault::NumbersFrom1 => "numbers-from-1",
            Fault::IgnoresPlanes => "ignores-planes",
            Fault::BacksOffInSilence => "backs-off-in-silence",
            Fault::HalfRate => "half-rate",
        }
    }

    /// The names, comma-separated (for messages).
    pub fn names() -> String {
        Fault::ALL.map(Fault::name).join(", ")
    }

    /// The fault named `name`, or an error listing the names.
    pub fn parse(name: &str) -> Result<Fault, String> {
        Fault::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| {
                format!(
                    "--fault `{name}` is not a fault (allowed: {})",
                    Fault::names()
                )
            })
    }
}

/// Whether `fault` can be played by a device that is modelled (`modelled`) and asks for
/// `protocol`: `ignores-planes` needs a modelled device speaking protocol 2, the only kind
/// that renders planes.
pub fn applies(
    fault: Option<Fault>,
    modelled: bool,
    protocol: crate::local::Protocol,
) -> Result<(), String> {
    if fault == Some(Fault::IgnoresPlanes) && (!modelled || !protocol.has_local_model()) {
        return Err(
            "--fault ignores-planes needs a modelled device speaking protocol 2 or 3 \
                    (--grip, --protocol 2): only such a device renders planes"
                .into(),
        );
    }
    Ok(())
}

/// The servo rate a device with `fault` runs at when welcomed at `welcome_hz` (Hz): half of
/// it with `half-rate`.
pub fn servo_rate_hz(fault: Option<Fault>, welcome_hz: u32) -> u32 {
    if fault == Some(Fault::HalfRate) {
        (welcome_hz / 2).max(1)
    } else {
        welcome_hz
    }
}
