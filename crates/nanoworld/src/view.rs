//! One flat view of every body, for renderers and recorders.

use nalgebra::Vector3;

use crate::world::{Target, TipContact, World};

/// What kind of body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyKind {
    /// The AFM tip apex (the cursor's body).
    Tip,
    /// A movable (orange) atom.
    Movable,
    /// A fixed (teal) substrate atom.
    Substrate,
}

/// A body's contact state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyContact {
    /// Tip: free. Substrate atom: not touched by the tip assembly.
    Free,
    /// Tip: held by a contact (the pull has not reached pull-off yet).
    Anchored,
    /// Movable atom riding on the tip.
    Carried,
    /// Uncarried movable atom: what holds it.
    Supported {
        /// Bonded to the substrate.
        on_substrate: bool,
        /// Number of movable atoms it is bonded to.
        bonds: usize,
    },
    /// Substrate atom or uncarried movable atom that the anchored tip assembly touches.
    Touched,
}

/// One body as a renderer or recorder sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyView {
    /// Kind of body.
    pub kind: BodyKind,
    /// Index within its kind (0 for the tip).
    pub index: usize,
    /// Centre (m).
    pub position_m: Vector3<f64>,
    /// Radius (m).
    pub radius_m: f64,
    /// Contact state.
    pub contact: BodyContact,
}

impl World {
    /// Every body: the tip, then movable atoms, then substrate atoms, each by index.
    /// (For large substrates, draw only nearby atoms with [`crate::Substrate::for_each_within`].)
    pub fn bodies(&self) -> impl Iterator<Item = BodyView> + '_ {
        let touched = match self.contact {
            TipContact::Anchored(a) => Some(a.target),
            TipContact::Free => None,
        };
        let tip = BodyView {
            kind: BodyKind::Tip,
            index: 0,
            position_m: self.tip,
            radius_m: self.params.tip.radius_m,
            contact: if touched.is_some() {
                BodyContact::Anchored
            } else {
                BodyContact::Free
            },
        };
        let ra = self.params.atoms.radius_m;
        let movable = self.atoms.iter().enumerate().map(move |(i, a)| BodyView {
            kind: BodyKind::Movable,
            index: i,
            position_m: a.position,
            radius_m: ra,
            contact: if a.is_carried() {
                BodyContact::Carried
            } else if touched == Some(Target::Atom(i)) {
                BodyContact::Touched
            } else {
                BodyContact::Supported {
                    on_substrate: a.on_substrate,
                    bonds: a.bonds.len(),
                }
            },
        });
        let rs = self.substrate.radius_m();
        let substrate = self
            .substrate
            .positions()
            .iter()
            .enumerate()
            .map(move |(j, q)| BodyView {
                kind: BodyKind::Substrate,
                index: j,
                position_m: *q,
                radius_m: rs,
                contact: if touched == Some(Target::SubstrateAtom(j)) {
                    BodyContact::Touched
                } else {
                    BodyContact::Free
                },
            });
        std::iter::once(tip).chain(movable).chain(substrate)
    }
}
