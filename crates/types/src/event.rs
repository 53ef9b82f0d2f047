//! What happened during a tick, as a name and a detail.

/// An event raised during a tick (logged, shown in Foxglove as a log line).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Event {
    /// Dotted event name, e.g. `wall.contact_begin`.
    pub name: String,
    /// Human-readable detail (may be empty).
    pub detail: String,
}

impl Event {
    /// A new event.
    pub fn new(name: impl Into<String>, detail: impl Into<String>) -> Self {
        Event {
            name: name.into(),
            detail: detail.into(),
        }
    }
}
