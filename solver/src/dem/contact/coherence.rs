//! Frame coherence: what a pair of pieces keeps from one time step to the next so that the
//! narrow phase mostly confirms last step's answer instead of finding it again.
//!
//! * Apart: a lower bound g on the pieces' distance, with where the pair stood when it was
//!   found ([`Stance`]): the offset d = x_B − x_A of the two bodies' centres and the sum of their
//!   turns (each body's turn grows every step by the most any of its points can have moved about
//!   its centre, |ω| r Δt). Moving B's centre relative to A's by Δd brings the pieces at most |Δd|
//!   closer, and turning moves no point farther than the turn, so while |Δd| + Δturn < g the
//!   pieces cannot have met and the pair is skipped without a query (Bullet's separating-distance
//!   utility bounds the motion the same way). Only the relative motion counts: grains falling or
//!   shaken together keep their bound however fast they go. Once it is used up, the pair of
//!   polyhedra is first tried along its last separating direction n: −h_K(n) is a new bound for
//!   one support query, kept if it is at least half the last one (most near contacts of a bed,
//!   requeried every few steps, end there); otherwise GJK finds the distance again, starting
//!   from the points of K its last distance query ended on (the vertex pairs of the feature of K
//!   nearest the origin, taken at the new poses), which a step mostly leaves the nearest. Either
//!   query climbs each body from a vertex of that feature rather than from the start table.
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
    /// Where the pair stood then.
    pub stance: Stance,
    pub features: Features,
}

/// Where a pair of bodies stands, as far as its distance bound needs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Stance {
    /// x_B − x_A, with B's periodic image.
    pub offset: Vector3<f64>,
    /// The sum of the two bodies' turns ([`crate::dem::Bodies::turn`]).
    pub turn: f64,
}

impl PairCache {
    /// Whether the pieces are still certainly apart, the pair standing as `now`.
    #[inline(always)]
    pub fn still_apart(&self, now: &Stance) -> bool {
        let slack = self.gap - (now.turn - self.stance.turn);
        slack > 0.0 && (now.offset - self.stance.offset).norm_squared() < slack * slack
    }

    /// Records a lower bound on the distance of two pieces of combined size `scale` (the sum of
    /// their bounding radii), the pair standing as `now`, less a margin for rounding: 1e-12 of
    /// `scale` holds the bound's (found relative to A's centre) and that of the offsets and turns
    /// while they stay below a few hundred times `scale` (metres, for grains of millimetres).
    #[inline]
    pub fn set_gap(&mut self, gap: f64, now: &Stance, scale: f64) {
        self.gap = (gap * (1.0 - 1e-9) - 1e-12 * scale).max(0.0);
        self.stance = *now;
    }
}

/// What a polyhedron pair keeps of its last query, in the canonical order of the pair at that
/// time.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Features {
    pub kept: Kept,
    pub order: Order,
}

/// The vertices a pair of polyhedra keeps.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub enum Kept {
    #[default]
    None,
    /// Touching: the vertices of A and of B at the three corners of EPA's last face and at a far
    /// point of K.
    Contact { a: [u16; 4], b: [u16; 4] },
    /// Apart: the vertices of A and of B of the points of K (`len`, 1 to 3) that the last
    /// distance query ended on, the feature of K nearest the origin. The next distance query
    /// starts GJK from them at the new poses, and its climbs from the first.
    Apart { a: [u16; 3], b: [u16; 3], len: u8 },
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
