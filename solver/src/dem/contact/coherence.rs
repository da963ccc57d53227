//! Frame coherence: what a pair of pieces keeps from one time step to the next so that the
//! narrow phase mostly confirms last step's answer instead of finding it again.
//!
//! * Apart: a lower bound g on the pieces' distance, with the sum T of the two bodies' travel
//!   bounds when it was found (each body's travel bound grows every step by the most any of its
//!   points can have moved, (|v| + |ω| r) Δt). While the travel sum has grown by less than g since,
//!   the pieces cannot have met, and the pair is skipped without a query (as Bullet's
//!   separating-distance utility does).
//! * Touching polyhedra: the vertices of EPA's last face of K = A − B and of a point of K on the
//!   far side. Next step the same vertex pairs, at the new poses, make a tetrahedron of K; if it
//!   still holds the origin EPA starts from it and, when the contact's features have not
//!   changed, ends after one support query. The answer is EPA's exact one either way.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// What the narrow phase keeps for one pair of pieces.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct PairCache {
    /// The last contact normal, or while apart the last separating direction found: where the
    /// next query starts (zero when unknown).
    pub warm: Vector3<f64>,
    /// A lower bound on the pieces' distance when it was last computed; 0 when unknown or in
    /// contact.
    pub gap: f64,
    /// The two bodies' travel sum then.
    pub travel: f64,
    pub features: Features,
}

impl PairCache {
    /// Whether the pieces are still certainly apart now that the bodies' travel sum is `travel`.
    #[inline(always)]
    pub fn still_apart(&self, travel: f64) -> bool {
        travel - self.travel < self.gap
    }

    /// Records a lower bound on the distance of two pieces of combined size `scale` (the sum of
    /// their bounding radii) at travel sum `travel`, less a margin for the rounding of the bound
    /// (relative to the coordinates, i.e. to `scale`) and of the travel sums.
    #[inline]
    pub fn set_gap(&mut self, gap: f64, travel: f64, scale: f64) {
        self.gap = (gap * (1.0 - 1e-9) - 1e-12 * scale).max(0.0);
        self.travel = travel;
    }
}

/// The features of a polyhedron pair's last contact: vertices of A and of B at the three
/// corners of EPA's last face and at a far point of K, in the canonical order of the pair at
/// that time.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Features {
    pub a: [u16; 4],
    pub b: [u16; 4],
    pub order: Order,
}

/// Which body was A when the features were recorded.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Order {
    #[default]
    None,
    /// The first body of the query was A.
    Forward,
    /// The second body was A.
    Swapped,
}
