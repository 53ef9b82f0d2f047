//! The decoder's byte reader: bounds-checked little-endian fields, strings and the version-2
//! local model, each failure an error naming the packet.

use super::ProtocolError;
use haptic_types::local::{
    Body, Bond, Follower, LocalModel, MAX_PLANES, MAX_REACH_VERTICES, Plane,
};

/// A bounds-checked little-endian reader over one datagram.
pub(super) struct Reader<'a> {
    /// The datagram.
    b: &'a [u8],
    /// Where the next read starts, bytes.
    at: usize,
}

impl<'a> Reader<'a> {
    /// A reader of `b` from byte `at` on.
    pub(super) fn new(b: &'a [u8], at: usize) -> Reader<'a> {
        Reader { b, at }
    }

    pub(super) fn f64s<const N: usize>(
        &mut self,
        kind: &'static str,
    ) -> Result<[f64; N], ProtocolError> {
        let mut out = [0.0; N];
        for x in &mut out {
            *x = self.f64(kind)?;
        }
        Ok(out)
    }

    fn planes(&mut self, kind: &'static str) -> Result<Vec<Plane>, ProtocolError> {
        let n = usize::from(self.u8(kind)?);
        if n > MAX_PLANES {
            return Err(ProtocolError::Local(format!(
                "{kind}: {n} planes, allowed at most {MAX_PLANES}"
            )));
        }
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let normal = self.f64s::<3>(kind)?;
            let [offset_m, stiffness_n_per_m] = self.f64s::<2>(kind)?;
            out.push(Plane {
                normal,
                offset_m,
                stiffness_n_per_m,
            });
        }
        Ok(out)
    }

    /// The local model after a version-2 force packet's version-1 fields.
    pub(super) fn local(&mut self) -> Result<LocalModel, ProtocolError> {
        let kind = "force (version 2)";
        let residual_force_n = self.f64s::<3>(kind)?;
        let residual_stiffness_n_per_m = self.f64s::<9>(kind)?;
        let [world_energy_j] = self.f64s::<1>(kind)?;
        let planes = self.planes(kind)?;
        let body = match self.u8(kind)? {
            0 => None,
            1 => {
                let position_m = self.f64s::<3>(kind)?;
                let velocity_m_per_s = self.f64s::<3>(kind)?;
                let [
                    mass_kg,
                    stiffness_n_per_m,
                    series_stiffness_n_per_m,
                    damping_n_s_per_m,
                ] = self.f64s::<4>(kind)?;
                let damper_m = self.f64s::<3>(kind)?;
                let external_force_n = self.f64s::<3>(kind)?;
                let substeps = self.u32(kind)?;
                let [restitution] = self.f64s::<1>(kind)?;
                Some(Body {
                    position_m,
                    velocity_m_per_s,
                    mass_kg,
                    stiffness_n_per_m,
                    series_stiffness_n_per_m,
                    damping_n_s_per_m,
                    damper_m,
                    external_force_n,
                    substeps,
                    restitution,
                })
            }
            other => {
                return Err(ProtocolError::Local(format!(
                    "body flag {other}: allowed 0 (none) or 1"
                )));
            }
        };
        let body_planes = self.planes(kind)?;
        let m = LocalModel {
            residual_force_n,
            residual_stiffness_n_per_m,
            planes,
            body,
            body_planes,
            world_energy_j,
            ..LocalModel::default()
        };
        // Finite, unit normals, masses and stiffnesses non-negative; the stiffnesses' cap is the
        // simulator's (it sends only what the device announced it renders).
        m.check(f64::INFINITY).map_err(ProtocolError::Local)?;
        Ok(m)
    }

    /// The bond after a version-3 force packet's local model (or a version-4 one's bond flag):
    /// anchor, normal, stiffness and breaking stretch (checked with the model); `kind` names
    /// the packet in a refusal.
    pub(super) fn bond(&mut self, kind: &'static str) -> Result<Bond, ProtocolError> {
        let anchor_m = self.f64s::<3>(kind)?;
        let normal = self.f64s::<3>(kind)?;
        let [stiffness_n_per_m, break_m] = self.f64s::<2>(kind)?;
        Ok(Bond {
            anchor_m,
            normal,
            stiffness_n_per_m,
            break_m,
        })
    }

    /// The follower after a version-4 force packet's bond: position, drift, retain,
    /// stiffness and the envelope's vertices (checked with the model).
    pub(super) fn follower(&mut self) -> Result<Follower, ProtocolError> {
        let kind = "force (version 4)";
        let position_m = self.f64s::<2>(kind)?;
        let drift_m = self.f64s::<2>(kind)?;
        let [retain, stiffness_n_per_m] = self.f64s::<2>(kind)?;
        // The count is checked with the model (at most MAX_REACH_VERTICES).
        let n = usize::from(self.u8(kind)?);
        let mut reach_m = Vec::with_capacity(n.min(MAX_REACH_VERTICES));
        for _ in 0..n {
            reach_m.push(self.f64s::<2>(kind)?);
        }
        Ok(Follower {
            position_m,
            drift_m,
            reach_m,
            retain,
            stiffness_n_per_m,
        })
    }

    fn take(&mut self, n: usize, kind: &'static str) -> Result<&[u8], ProtocolError> {
        let end = self.at + n;
        if end > self.b.len() {
            return Err(ProtocolError::TooShort {
                kind,
                got: self.b.len(),
                need: end,
            });
        }
        let s = &self.b[self.at..end];
        self.at = end;
        Ok(s)
    }
    pub(super) fn u8(&mut self, kind: &'static str) -> Result<u8, ProtocolError> {
        Ok(self.take(1, kind)?[0])
    }
    pub(super) fn u32(&mut self, kind: &'static str) -> Result<u32, ProtocolError> {
        let mut a = [0; 4];
        a.copy_from_slice(self.take(4, kind)?);
        Ok(u32::from_le_bytes(a))
    }
    pub(super) fn u64(&mut self, kind: &'static str) -> Result<u64, ProtocolError> {
        let mut a = [0; 8];
        a.copy_from_slice(self.take(8, kind)?);
        Ok(u64::from_le_bytes(a))
    }
    pub(super) fn f64(&mut self, kind: &'static str) -> Result<f64, ProtocolError> {
        Ok(f64::from_bits(self.u64(kind)?))
    }
    pub(super) fn string(&mut self, kind: &'static str) -> Result<String, ProtocolError> {
        let n = usize::from(self.u8(kind)?);
        let b = self.take(n, kind)?;
        String::from_utf8(b.to_vec()).map_err(|_| ProtocolError::Text(kind))
    }
    pub(super) fn remaining(&self) -> usize {
        self.b.len().saturating_sub(self.at)
    }
    pub(super) fn end(&self, kind: &'static str) -> Result<(), ProtocolError> {
        if self.at == self.b.len() {
            Ok(())
        } else {
            Err(ProtocolError::TooLong {
                kind,
                got: self.b.len(),
                expected: self.at,
            })
        }
    }
}
