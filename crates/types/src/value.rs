//! The one form of a bad number, [`world_form::value`]: `field must be finite, got NaN` or
//! `field = value is out of range: allowed RANGE`, the value written by
//! [`world_form::fmt_num`]. It lives in `world-form`, the lowest crate, so that the worlds
//! (which do not depend on this crate) carry the same error; it is re-exported here for the
//! crates above.

pub use world_form::value::{ValueError, finite, finite3, out_of_range};
