//! Command clipping at the working envelope (paper §2.4, Fig. 1).

use crate::envelope::Envelope;
use crate::error::{EnvelopeError, Result, ValueError, finite_vec};
use crate::geometry::{contains, first_crossing, nearest_on_boundary};
use nalgebra::Vector2;

type V2 = Vector2<f64>;

/// How a command outside the envelope is cut back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ClipMode {
    /// Along the segment from the anchor (zero displacement, or the free
    /// drift when zero is unreachable) to the command, stop at the first
    /// envelope crossing: the paper's rule.
    #[default]
    Radial,
    /// The nearest point of the envelope boundary.
    Nearest,
}

impl ClipMode {
    /// Parse `"radial"` or `"nearest"`.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "radial" => Ok(Self::Radial),
            "nearest" => Ok(Self::Nearest),
            _ => Err(EnvelopeError::Value(ValueError::out_of_range(
                "mode (\"radial\" or \"nearest\")",
                f64::NAN,
                "\"radial\" | \"nearest\"",
            ))),
        }
    }
}

/// A clipped command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clipped {
    /// The displacement actually possible (m).
    pub allowed: V2,
    /// `command − allowed` (m): zero inside the envelope.
    pub excess: V2,
}

/// Clip `command` (displacement, m) to the envelope `we`.
pub fn clip_command(we: &Envelope, command: &V2, mode: ClipMode) -> Result<Clipped> {
    clip_to_polygon(&we.polygon, &we.free_displacement, command, mode)
}

/// [`clip_command`] on a bare polygon (m, counter-clockwise) with the free
/// drift `free` (m) as the second radial anchor. Allocates nothing.
pub fn clip_to_polygon(poly: &[V2], free: &V2, command: &V2, mode: ClipMode) -> Result<Clipped> {
    finite_vec("command [m]", command.as_slice())?;
    if poly.len() < 3 {
        return Err(EnvelopeError::Value(ValueError::out_of_range(
            "envelope.polygon (vertices)",
            poly.len() as f64,
            ">= 3",
        )));
    }
    if contains(poly, command) {
        return Ok(Clipped {
            allowed: *command,
            excess: V2::zeros(),
        });
    }
    let nearest = || nearest_on_boundary(poly, command).0;
    let allowed = match mode {
        ClipMode::Nearest => nearest(),
        ClipMode::Radial => {
            let anchor = [V2::zeros(), *free].into_iter().find(|a| contains(poly, a));
            match anchor
                .and_then(|a| first_crossing(poly, &a, command).map(|t| a + (command - a) * t))
            {
                Some(p) => p,
                None => nearest(),
            }
        }
    };
    Ok(Clipped {
        allowed,
        excess: command - allowed,
    })
}
