//! Broad phase: linked cells (with periodic images) build a Verlet list of body pairs whose
//! bounding spheres come within the sum of their shares of the skin; the list is reused until
//! some body has moved more than its share, and each pair carries its contact history and
//! narrow-phase cache across rebuilds. A body's share is half the skin, or more for a fast one
//! (a grain raining down): the distance it covers in a fixed horizon, so that one falling grain
//! does not force a rebuild of the whole list every few dozen steps.
//!
//! The list is simulation state (a checkpoint keeps it); the cell grid and the previous list a
//! rebuild works with are scratch ([`BuildScratch`]), owned by the step pipeline.

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::body::Bodies;
use super::contact::PairCache;
use super::contact_law::ContactHistory;
use super::domain::Domain;
use super::shape::Shape;
use crate::SolverError;

/// A piece of body i and a piece of body j > i (with j moved by whole periods `image`, a
/// periodic image within reach of i) that are closer than the skin: one possible contact. Two
/// convex grains have one piece each; a bonded grain one per component sphere.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pair {
    pub i: u32,
    pub j: u32,
    pub image: [i16; 2],
    /// Piece of i and piece of j.
    pub pieces: [u16; 2],
    /// Both bodies are spheres (radius = bounding radius): the analytic contact needs no shape.
    pub spheres: bool,
    /// m_i m_j / (m_i + m_j), the mass of Eq. 11, kept here to spare a division per step.
    pub effective_mass: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct NeighbourList {
    skin: f64,
    /// The time ahead a body's share of the skin covers at its velocity at the build (s).
    horizon: f64,
    /// Sorted by (i, j, contact key, pieces): a body's pairs as i are contiguous.
    pub pairs: Vec<Pair>,
    /// The contact history of each pair.
    pub history: Vec<ContactHistory>,
    /// What the narrow phase keeps of each pair.
    pub cache: Vec<PairCache>,
    /// Positions at the last build; rebuilding is due once a body has moved its share from here.
    reference: Vec<Vector3<f64>>,
    /// Each body's share of the skin since the last build: between skin/2 and 2 skin.
    shares: Vec<f64>,
    /// Orientations at the last build: the pieces of a bonded grain also move by turning.
    reference_orientation: Vec<UnitQuaternion<f64>>,
    /// Whole periods each body has been moved back into the box by since the start; a pair's
    /// image corrected by them identifies the same contact across rebuilds.
    wraps: Vec<[i32; 2]>,
    /// Per body b, `as_j[first_as_j[b]..first_as_j[b + 1]]` are the pairs where it is j, and
    /// `pairs[first_as_i[b]..first_as_i[b + 1]]` those where it is i. Derived from `pairs`, so
    /// not kept in the state: [`NeighbourList::index`] builds them anew after a restore.
    #[serde(skip)]
    pub(crate) first_as_i: Vec<u32>,
    #[serde(skip)]
    first_as_j: Vec<u32>,
    #[serde(skip)]
    as_j: Vec<u32>,
    pub builds: u64,
}

/// What a rebuild works with and throws away: the cell grid and the previous list.
#[derive(Debug, Clone, Default)]
pub struct BuildScratch {
    cell_start: Vec<u32>,
    /// The bodies of each cell with what the pair search reads of them, cell after cell.
    cell_bodies: Vec<Member>,
    cell_of: Vec<usize>,
    /// The smallest and the largest bounding radius among each cell's bodies.
    cell_radii: Vec<[f64; 2]>,
    fill: Vec<u32>,
    old_pairs: Vec<Pair>,
    old_history: Vec<ContactHistory>,
    old_cache: Vec<PairCache>,
    old_keys: Vec<[i32; 2]>,
    radii: Vec<f64>,
}

/// A body as the pair search reads it from its cell: index, bounding radius and position.
#[derive(Debug, Clone, Copy, Default)]
struct Member {
    body: u32,
    radius: f64,
    share: f64,
    position: Vector3<f64>,
}

/// The cell grid of one build, with cells as wide as a typical body's reach: a body looks for
/// partners no larger than itself in the cells its own reach spans.
struct Grid {
    n: [usize; 3],
    origin: Vector3<f64>,
    width: Vector3<f64>,
    periodic: bool,
}

impl Grid {
    fn new(domain: &Domain, cell: f64, z_range: (f64, f64)) -> Self {
        let l = domain.width();
        let nxy = (l / cell).floor().max(1.0) as usize;
        let height = (z_range.1 - z_range.0).max(cell);
        let nz = (height / cell).floor().max(1.0) as usize;
        Grid {
            n: [nxy, nxy, nz],
            origin: Vector3::new(0.0, 0.0, z_range.0),
            width: Vector3::new(l / nxy as f64, l / nxy as f64, height / nz as f64),
            periodic: domain.is_periodic(),
        }
    }

    fn coordinates(&self, p: &Vector3<f64>) -> [usize; 3] {
        let c = |k: usize| (((p[k] - self.origin[k]) / self.width[k]).floor().max(0.0) as usize).min(self.n[k] - 1);
        [c(0), c(1), c(2)]
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.n[1] + c[1]) * self.n[0] + c[0]
    }

    fn count(&self) -> usize {
        self.n.iter().product()
    }

    /// The cells along axis `k` within `reach` of a point at `p` in cell `c`, each once, with
    /// the squared gap from `p` to the cell's slab (to its nearest periodic image): a periodic
    /// axis wraps around (all its cells once the reach spans it), a bounded one stops at its ends.
    fn axis(&self, k: usize, p: f64, c: usize, reach: f64) -> impl Iterator<Item = (usize, f64)> + use<> {
        let (n, c, span) = (self.n[k] as i64, c as i64, (reach / self.width[k]).ceil() as i64);
        let wraps = self.periodic && k < 2;
        let (lo, hi) = match wraps {
            true if 2 * span + 1 >= n => (0, n - 1),
            true => (c - span, c + span),
            false => ((c - span).max(0), (c + span).min(n - 1)),
        };
        let (w, period) = (self.width[k], self.width[k] * n as f64);
        let local = p - self.origin[k];
        let slab_gap = move |start: f64| (start - local).max(local - start - w).max(0.0);
        // The wrapped range reaches less than one period past either end.
        (lo..=hi).map(move |v| {
            let start = v as f64 * w;
            let gap = match wraps {
                true => slab_gap(start).min(slab_gap(start - period)).min(slab_gap(start + period)),
                false => slab_gap(start),
            };
            // Shrunk by a rounding's worth: a member sits in its slab up to the rounding of `coordinates`.
            let gap = (gap - 1e-9 * w).max(0.0);
            let wrapped = if v < 0 {
                v + n
            } else if v >= n {
                v - n
            } else {
                v
            };
            (wrapped as usize, gap * gap)
        })
    }
}

impl NeighbourList {
    /// A list with Verlet skin `skin` whose fast bodies' shares cover `horizon` seconds of
    /// their motion (0: every share is skin/2, the classic list).
    pub fn new(skin: f64, horizon: f64) -> Self {
        Self {
            skin,
            horizon,
            pairs: Vec::new(),
            history: Vec::new(),
            cache: Vec::new(),
            reference: Vec::new(),
            shares: Vec::new(),
            reference_orientation: Vec::new(),
            wraps: Vec::new(),
            first_as_i: vec![0],
            first_as_j: vec![0],
            as_j: Vec::new(),
            builds: 0,
        }
    }

    pub fn skin(&self) -> f64 {
        self.skin
    }

    /// A rebuild is due when bodies were added or a piece moved more than its body's share of
    /// the skin: two pieces unlisted were at least the sum of their shares apart, so neither
    /// moving further than its share, they cannot touch. A bonded grain's pieces move by at
    /// most |Δx| + r θ for a turn by θ.
    pub fn is_stale(&self, bodies: &Bodies) -> bool {
        if self.reference.len() != bodies.len() {
            return true;
        }
        (0..bodies.len()).any(|k| {
            let (shift2, share) = ((bodies.position[k] - self.reference[k]).norm_squared(), self.shares[k]);
            if bodies.shape[k].pieces() == 1 {
                return shift2 > share * share;
            }
            let turn = bodies.orientation[k].angle_to(&self.reference_orientation[k]);
            shift2.sqrt() + bodies.bounding_radius[k] * turn > share
        })
    }

    /// Bytes held per body: reference positions and orientations, wraps and the pair index.
    pub fn body_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.reference[..])
            + size_of_val(&self.shares[..])
            + size_of_val(&self.reference_orientation[..])
            + size_of_val(&self.wraps[..])
            + size_of_val(&self.first_as_i[..])
            + size_of_val(&self.first_as_j[..])
    }

    /// Bytes held per listed pair: the pair, its history and cache, and its index entry.
    pub fn pair_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.pairs[..])
            + size_of_val(&self.history[..])
            + size_of_val(&self.cache[..])
            + size_of_val(&self.as_j[..])
    }

    /// Pairs in which body `b` is body j.
    #[inline]
    pub fn pairs_as_j(&self, b: usize) -> &[u32] {
        &self.as_j[self.first_as_j[b] as usize..self.first_as_j[b + 1] as usize]
    }

    /// Builds the indices of pairs by body for `n` bodies if they are missing (a restored list).
    pub fn index(&mut self, n: usize, scratch: &mut BuildScratch) {
        if self.first_as_j.len() != n + 1 {
            self.index_by_body(n, &mut scratch.fill);
        }
    }

    /// Rebuilds the list, in stages: wrap positions into the periodic box, bin bodies into
    /// cells, list the pairs within reach, carry each surviving pair's history and cache over,
    /// index the pairs by body, and remember where the bodies were.
    pub fn rebuild(
        &mut self,
        bodies: &mut Bodies,
        domain: &Domain,
        scratch: &mut BuildScratch,
    ) -> Result<(), SolverError> {
        self.wraps.resize(bodies.len(), [0, 0]);
        scratch.old_keys.clear();
        scratch.old_keys.extend(self.pairs.iter().map(|p| contact_key(p, &self.wraps)));
        self.wrap(bodies, domain);
        let (least, most) = (0.5 * self.skin, 2.0 * self.skin);
        self.shares.clear();
        self.shares.extend(bodies.velocity.iter().map(|v| (v.norm() * self.horizon).clamp(least, most)));
        let most = self.shares.iter().cloned().fold(0.0, f64::max);
        let grid = self.grid(bodies, domain, most, &mut scratch.radii)?;
        scratch.bin(bodies, &self.shares, &grid);
        std::mem::swap(&mut self.pairs, &mut scratch.old_pairs);
        std::mem::swap(&mut self.history, &mut scratch.old_history);
        std::mem::swap(&mut self.cache, &mut scratch.old_cache);
        self.list_pairs(bodies, domain, &grid, most, scratch);
        self.carry_over(scratch);
        self.index_by_body(bodies.len(), &mut scratch.fill);
        self.reference.clear();
        self.reference.extend_from_slice(&bodies.position);
        self.reference_orientation.clear();
        self.reference_orientation.extend_from_slice(&bodies.orientation);
        self.builds += 1;
        Ok(())
    }

    /// Moves every body back into the periodic box, counting the periods per body.
    fn wrap(&mut self, bodies: &mut Bodies, domain: &Domain) {
        for (p, w) in bodies.position.iter_mut().zip(&mut self.wraps) {
            let moved = domain.wrap(p);
            w[0] += moved[0];
            w[1] += moved[1];
        }
    }

    /// The cell grid for the bodies' current extent, with cells as wide as the median body's
    /// reach (twice its bounding radius plus the skin), but no more than a few cells per body.
    /// `most` is the largest share of the skin.
    fn grid(&self, bodies: &Bodies, domain: &Domain, most: f64, radii: &mut Vec<f64>) -> Result<Grid, SolverError> {
        let r_max = bodies.bounding_radius.iter().cloned().fold(0.0, f64::max);
        let cutoff = 2.0 * (r_max + most);
        // A grain must not reach its own periodic image; up to that, a pair may touch through
        // two images at once and both are listed.
        if domain.is_periodic() && cutoff >= domain.width() {
            return Err(SolverError::DomainTooNarrow { width: domain.width(), reach: cutoff });
        }
        let (z_lo, z_hi) =
            bodies.position.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.z), hi.max(p.z)));
        let z_range = if bodies.is_empty() { (0.0, cutoff) } else { (z_lo, z_hi) };
        radii.clear();
        radii.extend_from_slice(&bodies.bounding_radius);
        let half = radii.len() / 2;
        let median = if radii.is_empty() { r_max } else { *radii.select_nth_unstable_by(half, f64::total_cmp).1 };
        // Bodies spread thin (grains raining down a tall column) would leave most cells empty.
        let volume = domain.width().powi(2) * (z_range.1 - z_range.0);
        let sparse = (volume / (4.0 * bodies.len().max(1) as f64)).cbrt();
        Ok(Grid::new(domain, (2.0 * median + self.skin).max(sparse), z_range))
    }

    /// Every pair of pieces within reach, in the order (i, j, contact key, pieces). Each body
    /// looks for the partners no larger than itself (ties to the lower index) in the cells its
    /// reach spans, so that a few large grains do not make every small one search their range.
    /// `most` is the largest share of the skin.
    fn list_pairs(&mut self, bodies: &Bodies, domain: &Domain, grid: &Grid, most: f64, s: &BuildScratch) {
        self.pairs.clear();
        let radius = &bodies.bounding_radius;
        for (i, (&xi, &ri)) in bodies.position.iter().zip(radius).enumerate() {
            let ci = grid.coordinates(&xi);
            let si = self.shares[i];
            let search = 2.0 * ri + si + most;
            for (cz, gz) in grid.axis(2, xi.z, ci[2], search) {
                for (cy, gy) in grid.axis(1, xi.y, ci[1], search) {
                    for (cx, gx) in grid.axis(0, xi.x, ci[0], search) {
                        let c = grid.index([cx, cy, cz]);
                        // Skip a cell none of whose members is both no larger than i and within
                        // reach of it: a large grain's search spans many cells of small ones.
                        let [smallest, largest] = s.cell_radii[c];
                        let cell_reach = ri + largest + si + most;
                        if smallest > ri || gx + gy + gz >= cell_reach * cell_reach {
                            continue;
                        }
                        for m in &s.cell_bodies[s.cell_start[c] as usize..s.cell_start[c + 1] as usize] {
                            let other = m.body as usize;
                            if m.radius > ri || (m.radius == ri && other <= i) {
                                continue;
                            }
                            // Positions are wrapped into the box; beyond reach of the nearest
                            // image, every image is.
                            let reach = ri + m.radius + si + m.share;
                            if domain.nearest_distance2(&xi, &m.position) < reach * reach {
                                self.list_pair(bodies, domain, i.min(other), i.max(other));
                            }
                        }
                    }
                }
            }
        }
        let wraps = &self.wraps;
        self.pairs.sort_unstable_by_key(|p| (p.i, p.j, contact_key(p, wraps), p.pieces));
    }

    /// Lists bodies i < j for every periodic image of j within reach of i.
    fn list_pair(&mut self, bodies: &Bodies, domain: &Domain, i: usize, j: usize) {
        let xi = bodies.position[i];
        let shares = self.shares[i] + self.shares[j];
        let reach = bodies.bounding_radius[i] + bodies.bounding_radius[j] + shares;
        let (mi, mj) = (bodies.mass[i], bodies.mass[j]);
        let effective_mass = mi * mj / (mi + mj);
        for image in domain.images_within(&xi, &bodies.position[j], reach) {
            let xj = bodies.position[j] + domain.shift(image);
            if (xj - xi).norm_squared() < reach * reach {
                let spheres =
                    matches!((&bodies.shape[i], &bodies.shape[j]), (Shape::Sphere { .. }, Shape::Sphere { .. }));
                let body_pair = Pair { i: i as u32, j: j as u32, image, pieces: [0, 0], spheres, effective_mass };
                push_piece_pairs(&mut self.pairs, body_pair, bodies, xj, shares);
            }
        }
    }

    /// Gives each listed pair the history and cache it had in the previous list, if it was
    /// there: both lists are sorted by (i, j, contact key, pieces), so one merge pass does it.
    fn carry_over(&mut self, s: &BuildScratch) {
        self.history.clear();
        self.cache.clear();
        let mut k = 0;
        for p in &self.pairs {
            let key = (p.i, p.j, contact_key(p, &self.wraps), p.pieces);
            let old = |k: usize| (s.old_pairs[k].i, s.old_pairs[k].j, s.old_keys[k], s.old_pairs[k].pieces);
            while k < s.old_pairs.len() && old(k) < key {
                k += 1;
            }
            if k < s.old_pairs.len() && old(k) == key {
                self.history.push(s.old_history[k]);
                self.cache.push(s.old_cache[k]);
            } else {
                self.history.push(ContactHistory::default());
                self.cache.push(PairCache::default());
            }
        }
    }

    /// Lists where each body's pairs as body i begin, and its pairs as body j by a counting
    /// sort on j.
    fn index_by_body(&mut self, n: usize, cursor: &mut Vec<u32>) {
        self.first_as_i.clear();
        self.first_as_i.resize(n + 1, 0);
        self.first_as_j.clear();
        self.first_as_j.resize(n + 1, 0);
        for p in &self.pairs {
            self.first_as_i[p.i as usize + 1] += 1;
            self.first_as_j[p.j as usize + 1] += 1;
        }
        for b in 0..n {
            self.first_as_i[b + 1] += self.first_as_i[b];
            self.first_as_j[b + 1] += self.first_as_j[b];
        }
        self.as_j.clear();
        self.as_j.resize(self.pairs.len(), 0);
        cursor.clear();
        cursor.extend_from_slice(&self.first_as_j[..n]);
        for (k, p) in self.pairs.iter().enumerate() {
            self.as_j[cursor[p.j as usize] as usize] = k as u32;
            cursor[p.j as usize] += 1;
        }
    }
}

impl BuildScratch {
    /// Counting sort of the bodies into the grid's cells.
    fn bin(&mut self, bodies: &Bodies, shares: &[f64], grid: &Grid) {
        self.cell_of.clear();
        self.cell_of.extend(bodies.position.iter().map(|p| grid.index(grid.coordinates(p))));
        self.cell_start.clear();
        self.cell_start.resize(grid.count() + 1, 0);
        self.cell_radii.clear();
        self.cell_radii.resize(grid.count(), [f64::INFINITY, f64::NEG_INFINITY]);
        for (&c, &r) in self.cell_of.iter().zip(&bodies.bounding_radius) {
            self.cell_start[c + 1] += 1;
            let radii = &mut self.cell_radii[c];
            *radii = [radii[0].min(r), radii[1].max(r)];
        }
        for c in 0..grid.count() {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        self.cell_bodies.clear();
        self.cell_bodies.resize(bodies.len(), Member::default());
        self.fill.clone_from(&self.cell_start);
        for (b, &c) in self.cell_of.iter().enumerate() {
            let (radius, share, position) = (bodies.bounding_radius[b], shares[b], bodies.position[b]);
            self.cell_bodies[self.fill[c] as usize] = Member { body: b as u32, radius, share, position };
            self.fill[c] += 1;
        }
    }
}

/// The piece pairs of a body pair whose pieces come within `shares` (the bodies' shares of the
/// skin): the one pair of two convex grains, those of nearby component spheres when a grain is
/// bonded.
fn push_piece_pairs(pairs: &mut Vec<Pair>, body_pair: Pair, bodies: &Bodies, xj: Vector3<f64>, shares: f64) {
    let (i, j) = (body_pair.i as usize, body_pair.j as usize);
    let (si, sj) = (&bodies.shape[i], &bodies.shape[j]);
    if si.pieces() == 1 && sj.pieces() == 1 {
        pairs.push(body_pair);
        return;
    }
    for ka in 0..si.pieces() {
        let (ca, ra) = si.piece_bounds(ka);
        let ca = bodies.position[i] + bodies.orientation[i] * ca;
        for kb in 0..sj.pieces() {
            let (cb, rb) = sj.piece_bounds(kb);
            let reach = ra + rb + shares;
            if (xj + bodies.orientation[j] * cb - ca).norm_squared() < reach * reach {
                pairs.push(Pair { pieces: [ka as u16, kb as u16], ..body_pair });
            }
        }
    }
}

/// The image of a pair in unwrapped coordinates, image − W_j + W_i: unchanged by wrapping either
/// body back into the box, so it names the same contact from one build to the next.
fn contact_key(p: &Pair, wraps: &[[i32; 2]]) -> [i32; 2] {
    let (wi, wj) = (wraps[p.i as usize], wraps[p.j as usize]);
    [p.image[0] as i32 - wj[0] + wi[0], p.image[1] as i32 - wj[1] + wi[1]]
}

#[cfg(test)]
mod tests {
    use nalgebra::{UnitQuaternion, Vector3};

    use super::*;
    use crate::dem::body::NewBody;
    use crate::dem::shape::Shape;

    fn bodies(positions: &[Vector3<f64>], shape: Shape) -> Bodies {
        let mut b = Bodies::default();
        for &position in positions {
            let body = NewBody {
                shape: shape.clone(),
                position,
                orientation: UnitQuaternion::identity(),
                velocity: Vector3::zeros(),
                angular_velocity: Vector3::zeros(),
            };
            b.push(body, 2650.0);
        }
        b
    }

    /// Every pair within reach by brute force: each pair of bodies, each periodic image; a
    /// body's share of the skin is what its speed covers in `horizon`, from skin/2 to 2 skin.
    fn all_pairs_within_reach(b: &Bodies, domain: &Domain, skin: f64, horizon: f64) -> Vec<(u32, u32, [i16; 2])> {
        let share = |k: usize| (b.velocity[k].norm() * horizon).max(0.5 * skin).min(2.0 * skin);
        let mut expected = Vec::new();
        for i in 0..b.len() {
            for j in i + 1..b.len() {
                let reach = b.bounding_radius[i] + b.bounding_radius[j] + share(i) + share(j);
                for image in [-1i16, 0, 1].iter().flat_map(|&x| [-1i16, 0, 1].map(|y| [x, y])) {
                    let shift = if domain.is_periodic() { domain.shift(image) } else { Vector3::zeros() };
                    if (domain.is_periodic() || image == [0, 0])
                        && (b.position[j] + shift - b.position[i]).norm() < reach
                    {
                        expected.push((i as u32, j as u32, image));
                    }
                }
            }
        }
        expected.sort();
        expected
    }

    #[test]
    fn grains_of_widely_different_sizes_get_every_pair_within_reach_once() {
        // Spheres of 0.5 to 8 mm radius (the range of Table 3's U7 and B50 sieves), the largest
        // reaching across the whole 5 cm box, where the search wraps around every cell once; at
        // rest (every share skin/2), and at speeds up to 0.5 m/s with a 10 ms horizon and a
        // skin of 1 mm (shares of 0.5 to 2 mm, three fifths of them clamped at either end).
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let at_rest = [(2e-4, 0.0, Domain::Periodic { width: 0.05 }), (2e-4, 0.0, Domain::Cylinder { diameter: 0.05 })];
        let moving =
            [(1e-3, 1e-2, Domain::Periodic { width: 0.05 }), (1e-3, 1e-2, Domain::Cylinder { diameter: 0.05 })];
        for (skin, horizon, domain) in at_rest.into_iter().chain(moving) {
            let mut b = Bodies::default();
            for _ in 0..600 {
                let radius = 5e-4 * 16f64.powf(rng.random::<f64>().powi(3));
                let (x, y) = (rng.random::<f64>() * 0.05, rng.random::<f64>() * 0.05);
                let speed = if horizon > 0.0 { 0.5 * rng.random::<f64>() } else { 0.0 };
                let body = NewBody {
                    shape: Shape::Sphere { radius },
                    position: Vector3::new(x, y, rng.random::<f64>() * 0.03),
                    orientation: UnitQuaternion::identity(),
                    velocity: Vector3::new(0.0, 0.0, -speed),
                    angular_velocity: Vector3::zeros(),
                };
                b.push(body, 2650.0);
            }
            let mut list = NeighbourList::new(skin, horizon);
            list.rebuild(&mut b, &domain, &mut BuildScratch::default()).unwrap();
            let listed: Vec<(u32, u32, [i16; 2])> = list.pairs.iter().map(|p| (p.i, p.j, p.image)).collect();
            let expected = all_pairs_within_reach(&b, &domain, skin, horizon);
            assert!(expected.len() > 500, "{domain:?}: {} pairs", expected.len());
            assert_eq!(listed, expected, "{domain:?}, horizon {horizon} s");
        }
    }

    #[test]
    fn a_contact_keeps_its_history_when_a_body_is_wrapped_into_the_box() {
        let domain = Domain::Periodic { width: 0.05 };
        let sphere = Shape::Sphere { radius: 3e-3 };
        let mut b = bodies(&[Vector3::new(0.002, 0.02, 0.02), Vector3::new(0.0475, 0.02, 0.02)], sphere);
        let mut list = NeighbourList::new(1e-3, 0.0);
        list.rebuild(&mut b, &domain, &mut BuildScratch::default()).unwrap();
        assert_eq!(list.pairs.len(), 1, "one pair, through the boundary");
        list.history[0].tangential_displacement = Vector3::new(0.0, 1e-6, 0.0);
        // Both drift by −3 mm: body 0 leaves through x = 0 and is wrapped to the far side.
        for p in &mut b.position {
            p.x -= 0.003;
        }
        list.rebuild(&mut b, &domain, &mut BuildScratch::default()).unwrap();
        assert!(b.position[0].x > 0.04, "body 0 was wrapped");
        assert_eq!(list.pairs.len(), 1);
        assert_eq!(list.history[0].tangential_displacement, Vector3::new(0.0, 1e-6, 0.0));
    }

    #[test]
    fn a_long_grain_in_a_narrow_box_touches_a_neighbour_through_two_images() {
        // Semi-axis 7 mm along x in a 20 mm box: grains 10 mm apart overlap directly and through
        // the boundary; both contacts are listed, each once.
        let domain = Domain::Periodic { width: 0.02 };
        let needle = Shape::Ellipsoid { semi_axes: Vector3::new(7e-3, 2e-3, 2e-3) };
        let mut b = bodies(&[Vector3::new(0.005, 0.01, 0.01), Vector3::new(0.015, 0.01, 0.01)], needle.clone());
        let mut list = NeighbourList::new(5e-4, 0.0);
        list.rebuild(&mut b, &domain, &mut BuildScratch::default()).unwrap();
        let images: Vec<[i16; 2]> = list.pairs.iter().map(|p| p.image).collect();
        assert_eq!(images, vec![[-1, 0], [0, 0]]);
        // A grain reaching its own image is refused.
        let mut long =
            bodies(&[Vector3::new(0.01, 0.01, 0.01)], Shape::Ellipsoid { semi_axes: Vector3::new(0.0101, 2e-3, 2e-3) });
        assert!(matches!(
            NeighbourList::new(5e-4, 0.0).rebuild(&mut long, &domain, &mut BuildScratch::default()),
            Err(SolverError::DomainTooNarrow { .. })
        ));
    }
}
