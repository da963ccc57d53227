//! One DEM time step, read as the algorithm: neighbours → poses → contacts → forces and
//! integration. The packing protocol decides only which external forces apply (gravity and
//! buoyancy, the shaking of Eq. 14, the damping of Eq. 15).
//!
//! The simulation's state (bodies, contacts with their histories, time) is what a checkpoint
//! keeps; the step's working memory (pair forces, poses, the neighbour grid) is a separate
//! [`Pipeline`], filled afresh every step, so a restored simulation needs no repair.

use std::time::{Duration, Instant};

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::body::{Bodies, NewBody};
use super::contact;
use super::contact::{ContactPoint, Mode, PairCache};
use super::contact_law::{Calibration, ContactHistory, LinearSpringDashpot};
use super::domain::Domain;
use super::material::Material;
use super::neighbours::{BuildScratch, NeighbourList, Pair};
use super::shape::{Pose, Shape};
use crate::SolverError;
use crate::fluid::{self, Fluid, FluidResponse};

/// Time steps per collision below which the linear spring-dashpot is not resolved (the paper
/// uses T_c/Δt = 40, §4.2).
pub const MIN_STEPS_PER_COLLISION: f64 = 10.0;

/// Overlap, relative to the smaller grain's smallest half-extent, beyond which the simulation is
/// declared unstable rather than continued with a garbage result: past 2 the smaller grain lies
/// wholly inside the other across its thinnest extent, and the contact can no longer tell which
/// side it came in from. Deep overlaps short of that are the paper's law at work: its spring
/// (Eq. 11, k_n ∝ m_ij,eff) is soft for a light grain, so a coarse grain of mass M landing at
/// speed v on a fine one lying on the floor sinks in by about v·sqrt(M/(2 k_n))/2 (the dashpot
/// of e_n = 0.1 halves an undamped spring's reach): for U7's extremes, 31.5 and 2.8 mm grains of
/// the Rhine scans' form, 0.64 of the fine grain's half-thickness per m/s. A Table 7 U7
/// packing of those scans reached 0.80 at its first landing; a limit of 0.5 stopped all six.
pub const MAX_RELATIVE_OVERLAP: f64 = 2.0;

/// Steps of its motion at its velocity a fast body's share of the neighbour list's skin covers
/// (up to twice the skin): grains raining down at 1.5 m/s forced a rebuild every ~30 steps with
/// the skin's half alone.
const SKIN_HORIZON_STEPS: f64 = 100.0;

/// Material and numerical constants of a simulation (§4.2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    pub material: Material,
    pub time_step: f64,
    /// Verlet skin of the neighbour list (m).
    pub skin: f64,
    /// How k_n and d_n follow from e_n and T_c.
    pub calibration: Calibration,
    /// Where the force of a contact with a polyhedron acts. Absent in the cached states of
    /// earlier versions, which used the centre of pressure.
    #[serde(default)]
    pub contact_point: ContactPoint,
}

/// Horizontal shaking force m A_s sin(2πt/T_s) (2π/T_s)² x̂, Eq. 14.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Shaking {
    pub amplitude: f64,
    pub period: f64,
}

impl Shaking {
    /// Acceleration of Eq. 14 at time t.
    pub fn acceleration(&self, t: f64) -> f64 {
        let omega = 2.0 * std::f64::consts::PI / self.period;
        self.amplitude * (omega * t).sin() * omega * omega
    }
}

/// What one pair contact leaves for body j: the force on it and its torque (the opposite force
/// acts on body i at the same point, summed into i's [`Load`] where the pair is computed).
#[derive(Debug, Clone, Copy, Default)]
struct PairForce {
    force: Vector3<f64>,
    torque_j: Vector3<f64>,
}

/// Force and torque on a body from the pairs in which it is body i.
#[derive(Debug, Clone, Copy, Default)]
struct Load {
    force: Vector3<f64>,
    torque: Vector3<f64>,
}

/// What the pair stage reads: the bodies, their poses of this step, the contact law.
struct PairStage<'a> {
    bodies: &'a Bodies,
    /// Where each body's pairs as body i begin in the pair list.
    starts: &'a [u32],
    domain: Domain,
    poses: &'a [Pose],
    law: &'a LinearSpringDashpot,
    dt: f64,
    rule: ContactPoint,
}

impl PairStage<'_> {
    /// The pairs of bodies `first..first + loads.len()` as body i (listed by i), halved at a
    /// body until a task holds few pairs; the halves are the same whatever the threads, so
    /// every sum is too.
    fn run(
        &self,
        first: usize,
        pairs: &[Pair],
        history: &mut [ContactHistory],
        cache: &mut [PairCache],
        out: &mut [PairForce],
        loads: &mut [Load],
    ) -> (usize, f64) {
        if pairs.len() > PAIRS_PER_TASK && loads.len() > 1 {
            let half = loads.len() / 2;
            // An index, not a search of the pairs: the search's probes missed the cache.
            let cut = (self.starts[first + half] - self.starts[first]) as usize;
            let (pairs_a, pairs_b) = pairs.split_at(cut);
            let (history_a, history_b) = history.split_at_mut(cut);
            let (cache_a, cache_b) = cache.split_at_mut(cut);
            let (out_a, out_b) = out.split_at_mut(cut);
            let (loads_a, loads_b) = loads.split_at_mut(half);
            let (a, b) = rayon::join(
                || self.run(first, pairs_a, history_a, cache_a, out_a, loads_a),
                || self.run(first + half, pairs_b, history_b, cache_b, out_b, loads_b),
            );
            return (a.0 + b.0, a.1.max(b.1));
        }
        let (mut open, mut worst) = (0, 0.0f64);
        for (((pair, history), cache), out) in pairs.iter().zip(history).zip(cache).zip(out) {
            let Some(Touch { force, arm_i, arm_j, overlap }) = self.contact(pair, history, cache) else {
                history.tangential_displacement = Vector3::zeros();
                *out = PairForce::default();
                continue;
            };
            let load = &mut loads[pair.i as usize - first];
            load.force -= force;
            load.torque += force.cross(&arm_i);
            *out = PairForce { force, torque_j: arm_j.cross(&force) };
            open += 1;
            worst = worst.max(overlap);
        }
        (open, worst)
    }

    /// The pair's contact this step, if open.
    #[inline(always)]
    fn contact(&self, pair: &Pair, history: &mut ContactHistory, cache: &mut PairCache) -> Option<Touch> {
        let bodies = self.bodies;
        let (i, j) = (pair.i as usize, pair.j as usize);
        let xi = bodies.position[i];
        let xj = bodies.position[j] + self.domain.shift(pair.image);
        let (geometry, scale) = if pair.spheres {
            // Sphere beds spend most of their time here: no shape to load, no piece to build.
            let (ra, rb) = (bodies.bounding_radius[i], bodies.bounding_radius[j]);
            (contact::sphere::sphere_sphere(&xi, ra, &xj, rb)?, ra.min(rb))
        } else {
            let now = bodies.stance(i, j, xj - xi);
            if cache.still_apart(&now) {
                return None;
            }
            let [ka, kb] = pair.pieces.map(usize::from);
            let a = bodies.shape[i].piece(ka, xi, &bodies.orientation[i], &self.poses[i]);
            let b = bodies.shape[j].piece(kb, xj, &bodies.orientation[j], &self.poses[j]);
            let scale = a.smallest_half_extent().min(b.smallest_half_extent());
            (contact::between(&a, &b, cache, &now, Mode::Coherent, self.rule)?, scale)
        };
        let arm_i = geometry.point - xi;
        let arm_j = geometry.point - xj;
        let relative = bodies.point_velocity(j, &arm_j) - bodies.point_velocity(i, &arm_i);
        let force = self.law.force(pair.effective_mass, &geometry, &relative, history, self.dt);
        Some(Touch { force, arm_i, arm_j, overlap: geometry.depth / scale })
    }
}

/// An open pair contact: the force on body j (its opposite acts on i), the arms from i's and
/// j's centres to the contact point, and the overlap relative to the smaller half-extent.
struct Touch {
    force: Vector3<f64>,
    arm_i: Vector3<f64>,
    arm_j: Vector3<f64>,
    overlap: f64,
}

/// Pairs above which the pair stage splits a task in two: a task of sphere contacts then lasts
/// a few microseconds, long beside what splitting costs.
const PAIRS_PER_TASK: usize = 256;

/// The narrow phase's shortcuts against the full query over one step's pairs
/// ([`Simulation::audit_next_step`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Audit {
    /// Non-spherical pairs looked at.
    pub pairs: usize,
    /// Pairs skipped as certainly apart, and of those the ones the full query finds touching.
    pub skipped: usize,
    pub wrongly_skipped: usize,
    /// Contacts both found, and pairs only one of the two found in contact.
    pub contacts: usize,
    pub mismatched: usize,
    /// Largest differences in depth and point relative to the pair's size (the sum of the
    /// pieces' bounding radii), and between the unit normals.
    pub depth: f64,
    pub point: f64,
    pub normal: f64,
    /// Contacts whose points differ by more than 1e-9 of the pair's size.
    pub points_beyond: usize,
}

impl Audit {
    /// The larger of each figure.
    pub fn merge(&mut self, other: &Audit) {
        self.pairs += other.pairs;
        self.skipped += other.skipped;
        self.wrongly_skipped += other.wrongly_skipped;
        self.contacts += other.contacts;
        self.mismatched += other.mismatched;
        self.points_beyond += other.points_beyond;
        self.depth = self.depth.max(other.depth);
        self.point = self.point.max(other.point);
        self.normal = self.normal.max(other.normal);
    }
}

/// What a body keeps of one point of its contact with a wall.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct WallPoint {
    /// The wall and the body's piece, and the key of the manifold point (its vertex or edge).
    pub key: (u32, u64),
    pub history: ContactHistory,
    /// Found open in the current step (points no longer open are dropped at its end).
    #[serde(skip)]
    open: bool,
}

impl WallPoint {
    fn key(wall: u32, piece: usize, feature: u64) -> (u32, u64) {
        (wall << 16 | piece as u32, feature)
    }
}

/// Memory held by a simulation ([`Simulation::memory`]), in bytes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Memory {
    /// Everything kept per body: its state, shape, wall histories, pose and neighbour index.
    pub bodies: usize,
    /// Everything kept per listed pair: the pair, its contact history, narrow-phase cache and
    /// force.
    pub pairs: usize,
    /// The base meshes of polyhedron grains, each counted once however many grains share it.
    pub shared_meshes: usize,
}

/// Wall-clock time spent in each stage since the simulation began.
#[derive(Debug, Clone, Copy, Default)]
pub struct StageTimes {
    pub neighbours: Duration,
    pub fluid: Duration,
    pub contacts: Duration,
    pub bodies: Duration,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Simulation {
    pub bodies: Bodies,
    pub domain: Domain,
    pub settings: Settings,
    law: LinearSpringDashpot,
    neighbours: NeighbourList,
    /// Per body, the points of its open contacts with the floor and the cylinder wall.
    walls: Vec<Vec<WallPoint>>,
    pub time: f64,
    pub steps: u64,
    /// Shaking force applied in the current phase, if any.
    pub shaking: Option<Shaking>,
    /// Damping coefficient c_d of Eq. 15 applied in the current phase, if any.
    pub damping: Option<f64>,
    /// Contacts (pair and wall) open in the last step.
    pub contacts: usize,
    /// Of those, the contacts between pieces of two bodies.
    #[serde(default)]
    pub pair_contacts: usize,
    /// Fluid drag and lift (off: buoyancy only, the first paper's protocol). Set by whoever
    /// drives the simulation, as the packing does every step from its spec; not kept in the
    /// state, so that states and cached beds keep their format.
    #[serde(skip)]
    pub fluid: Option<Fluid>,
    /// Each body's fluid force and torque as of the last update of the fluid forces, kept in
    /// the state so that a restored simulation goes on exactly as it would have; empty with
    /// fluid forces off.
    #[serde(default)]
    fluid_response: Vec<FluidResponse>,
    #[serde(skip)]
    pipeline: Pipeline,
}

/// The working memory of a step: overwritten every step, never part of the state.
#[derive(Debug, Clone, Default)]
struct Pipeline {
    /// What each listed pair leaves for its body j.
    pair_forces: Vec<PairForce>,
    /// Each body's load from the pairs in which it is body i.
    loads: Vec<Load>,
    /// What the narrow phase precomputes of each body for this step.
    poses: Vec<Pose>,
    /// The neighbour list's cell grid and previous list.
    build: BuildScratch,
    /// The fluid fraction grid and what the fluid stage keeps of each body's shape.
    fluid: fluid::Scratch,
    stage_times: StageTimes,
}

impl Simulation {
    pub fn new(domain: Domain, settings: Settings) -> Result<Self, SolverError> {
        if settings.material.collision_time / settings.time_step < MIN_STEPS_PER_COLLISION {
            return Err(SolverError::TimeStepTooLarge {
                time_step: settings.time_step,
                collision_time: settings.material.collision_time,
            });
        }
        Ok(Self {
            bodies: Bodies::default(),
            domain,
            settings,
            law: LinearSpringDashpot::new(&settings.material, settings.calibration, settings.time_step),
            neighbours: NeighbourList::new(settings.skin, SKIN_HORIZON_STEPS * settings.time_step),
            walls: Vec::new(),
            time: 0.0,
            steps: 0,
            shaking: None,
            damping: None,
            contacts: 0,
            pair_contacts: 0,
            fluid: None,
            fluid_response: Vec::new(),
            pipeline: Pipeline::default(),
        })
    }

    /// Wall-clock time spent in each stage of the step since this simulation was created or
    /// restored.
    pub fn stage_times(&self) -> StageTimes {
        self.pipeline.stage_times
    }

    /// The neighbour list: listed pairs, their contact histories and narrow-phase caches.
    pub fn neighbours(&self) -> &NeighbourList {
        &self.neighbours
    }

    pub fn law(&self) -> &LinearSpringDashpot {
        &self.law
    }

    pub fn add_body(&mut self, body: NewBody) -> usize {
        self.walls.push(Vec::new());
        self.bodies.push(body, self.settings.material.density)
    }

    /// Advances the simulation by one time step Δt.
    pub fn step(&mut self) -> Result<(), SolverError> {
        let start = Instant::now();
        if self.neighbours.is_stale(&self.bodies) {
            self.neighbours.rebuild(&mut self.bodies, &self.domain, &mut self.pipeline.build)?;
        } else {
            self.neighbours.index(self.bodies.len(), &mut self.pipeline.build);
        }
        self.pose_bodies();
        let after_neighbours = Instant::now();
        match &self.fluid {
            // Due every `coupling` steps, and whenever bodies came or fluid forces were just on.
            Some(fluid)
                if self.steps.is_multiple_of(u64::from(fluid.coupling.max(1)))
                    || self.fluid_response.len() != self.bodies.len() =>
            {
                let density = self.settings.material.fluid_density;
                fluid.update(&self.bodies, &self.domain, density, &mut self.pipeline.fluid, &mut self.fluid_response);
            }
            Some(_) => {}
            None => self.fluid_response.clear(),
        }
        let after_fluid = Instant::now();
        let (pair_contacts, worst_overlap) = self.pair_contacts();
        let after_contacts = Instant::now();
        if worst_overlap > MAX_RELATIVE_OVERLAP {
            return Err(SolverError::Overlap { time: self.time, relative: worst_overlap });
        }
        let (wall_contacts, finite) = self.forces_and_integration();
        let end = Instant::now();
        if !finite {
            return Err(SolverError::NotFinite { time: self.time });
        }
        self.contacts = pair_contacts + wall_contacts;
        self.pair_contacts = pair_contacts;
        self.time += self.settings.time_step;
        self.steps += 1;
        let times = &mut self.pipeline.stage_times;
        times.neighbours += after_neighbours - start;
        times.fluid += after_fluid - after_neighbours;
        times.contacts += after_contacts - after_fluid;
        times.bodies += end - after_contacts;
        Ok(())
    }

    /// Compares the narrow phase's shortcuts (pairs skipped as apart, polyhedron contacts from
    /// last step's features, closed-form centres of pressure) with the full query, cold, on
    /// every non-spherical pair of the coming step, leaving the state as it was (but for a
    /// neighbour list rebuilt if one was due, as the step would).
    pub fn audit_next_step(&mut self) -> Result<Audit, SolverError> {
        if self.neighbours.is_stale(&self.bodies) {
            self.neighbours.rebuild(&mut self.bodies, &self.domain, &mut self.pipeline.build)?;
        }
        self.pose_bodies();
        let (bodies, poses) = (&self.bodies, &self.pipeline.poses);
        let rule = self.settings.contact_point;
        let mut audit = Audit::default();
        for (k, pair) in self.neighbours.pairs.iter().enumerate().filter(|(_, p)| !p.spheres) {
            let (i, j) = (pair.i as usize, pair.j as usize);
            let xi = bodies.position[i];
            let xj = bodies.position[j] + self.domain.shift(pair.image);
            let [ka, kb] = pair.pieces.map(usize::from);
            let a = bodies.shape[i].piece(ka, xi, &bodies.orientation[i], &poses[i]);
            let b = bodies.shape[j].piece(kb, xj, &bodies.orientation[j], &poses[j]);
            let now = bodies.stance(i, j, xj - xi);
            let full = contact::between(&a, &b, &mut PairCache::default(), &now, Mode::Full, rule);
            audit.pairs += 1;
            let cache = self.neighbours.cache[k];
            if cache.still_apart(&now) {
                audit.skipped += 1;
                audit.wrongly_skipped += usize::from(full.is_some());
                continue;
            }
            let fast = contact::between(&a, &b, &mut cache.clone(), &now, Mode::Coherent, rule);
            let size = a.bounding_radius() + b.bounding_radius();
            match (full, fast) {
                (Some(f), Some(c)) => {
                    audit.contacts += 1;
                    let point = (f.point - c.point).norm() / size;
                    audit.depth = audit.depth.max((f.depth - c.depth).abs() / size);
                    audit.point = audit.point.max(point);
                    audit.points_beyond += usize::from(point > 1e-9);
                    audit.normal = audit.normal.max((f.normal - c.normal).norm());
                }
                (None, None) => {}
                _ => audit.mismatched += 1,
            }
        }
        Ok(audit)
    }

    /// The poses of this step for the bodies whose shapes need one (ellipsoids, polyhedra).
    fn pose_bodies(&mut self) {
        let b = &self.bodies;
        let poses = &mut self.pipeline.poses;
        poses.resize(b.len(), Pose::None);
        poses.par_iter_mut().enumerate().for_each(|(k, pose)| {
            if matches!(b.shape[k], Shape::Ellipsoid { .. } | Shape::Polyhedron(_)) {
                *pose = b.shape[k].pose(b.position[k], &b.orientation[k]);
            }
        });
    }

    /// Narrow phase and contact law for every listed pair; returns the number of open contacts
    /// and the largest overlap relative to the pair's smaller half-extent. Each body's load as
    /// body i is summed where its pairs are computed (they are listed by i); only body j's share
    /// of a pair waits in `pair_forces` for the next stage.
    fn pair_contacts(&mut self) -> (usize, f64) {
        let Pipeline { pair_forces, loads, poses, .. } = &mut self.pipeline;
        pair_forces.resize(self.neighbours.pairs.len(), PairForce::default());
        loads.clear();
        loads.resize(self.bodies.len(), Load::default());
        let list = &mut self.neighbours;
        let stage = PairStage {
            bodies: &self.bodies,
            starts: &list.first_as_i,
            domain: self.domain,
            poses,
            law: &self.law,
            dt: self.settings.time_step,
            rule: self.settings.contact_point,
        };
        stage.run(0, &list.pairs, &mut list.history, &mut list.cache, pair_forces, loads)
    }

    /// Per body: wall contacts, the sum of its pair forces, external forces, then the
    /// semi-implicit Euler update of §3.1 (velocities first, then position and rotation).
    /// Returns the number of wall contacts and whether every state stayed finite.
    fn forces_and_integration(&mut self) -> (usize, bool) {
        let settings = &self.settings;
        let law = &self.law;
        let domain = self.domain;
        let neighbours = &self.neighbours;
        let pair_forces = &self.pipeline.pair_forces;
        let loads = &self.pipeline.loads;
        let poses = &self.pipeline.poses;
        let dt = settings.time_step;
        let weight_per_volume = settings.material.weight_per_volume();
        let shaking = self.shaking.map_or(0.0, |s| s.acceleration(self.time));
        let damping = self.damping.map(|c| c.powf(dt));
        let fluid = self.fluid.is_some().then_some(&self.fluid_response[..]);
        let b = &mut self.bodies;
        (
            b.position.par_iter_mut(),
            b.orientation.par_iter_mut(),
            b.velocity.par_iter_mut(),
            b.angular_velocity.par_iter_mut(),
            b.turn.par_iter_mut(),
            self.walls.par_iter_mut(),
        )
            .into_par_iter()
            .enumerate()
            .map(|(k, (x, q, v, w, turn, walls))| {
                let shape = &b.shape[k];
                let pose = &poses[k];
                let mass = b.mass[k];
                let mut force =
                    weight_per_volume * b.volume[k] + Vector3::new(mass * shaking, 0.0, 0.0) + loads[k].force;
                let mut torque = loads[k].torque;
                if let Some(responses) = fluid {
                    let (f, t) = responses[k].load(v, w);
                    force += f;
                    torque += t;
                }
                for &pair in neighbours.pairs_as_j(k) {
                    let pf = &pair_forces[pair as usize];
                    force += pf.force;
                    torque += pf.torque_j;
                }
                // Each wall contact is one point or a face's manifold; every point keeps its
                // tangential history under its key (wall, piece, vertex) while it stays open.
                for e in walls.iter_mut() {
                    e.open = false;
                }
                for piece in 0..shape.pieces() {
                    let p = shape.piece(piece, *x, q, pose);
                    contact::with_walls(&p, &domain, settings.contact_point, |wall, feature, g, weight| {
                        let key = WallPoint::key(wall, piece, feature);
                        let entry = match walls.iter().position(|e| e.key == key) {
                            Some(found) => &mut walls[found],
                            None => {
                                walls.push(WallPoint { key, history: ContactHistory::default(), open: false });
                                walls.last_mut().expect("just pushed")
                            }
                        };
                        entry.open = true;
                        // The wall is body B, immovable: m_eff = m and its velocity is zero.
                        let arm = g.point - *x;
                        let relative = -(*v + w.cross(&arm));
                        let f = -law.force(mass * weight, g, &relative, &mut entry.history, dt);
                        force += f;
                        torque += arm.cross(&f);
                    });
                }
                walls.retain(|e| e.open);
                let wall_contacts = walls.len();

                *v += force * (dt / mass);
                let inertia = b.inertia[k];
                if inertia.x == inertia.y && inertia.y == inertia.z {
                    *w += torque * (dt / inertia.x);
                } else {
                    // Euler's equations I ω̇ = T − ω × I ω in the body frame of the current
                    // orientation, i.e. with the world-frame inertia R diag(I) Rᵀ.
                    let body_w = q.inverse_transform_vector(w);
                    let body_t = q.inverse_transform_vector(&torque);
                    let body_wdot = (body_t - body_w.cross(&body_w.component_mul(&inertia))).component_div(&inertia);
                    *w += q.transform_vector(&body_wdot) * dt;
                }
                *x += *v * dt;
                // The body turns by at most |ω| Δt (below); its centre's motion is in each pair's offset.
                *turn += w.norm() * b.bounding_radius[k] * dt;
                // q ← q + ½ Δt (0, ω) q, exact to O((|ω|Δt)³) per step, then renormalised by one
                // Newton step for 1/|q| about 1: |q|² − 1 is O((|ω|Δt)²), so the error is of
                // its square, below round-off, and no square root or division is needed.
                let p = q.quaternion() + Quaternion::from_imag(*w * (0.5 * dt)) * q.quaternion();
                *q = UnitQuaternion::new_unchecked(p * (0.5 * (3.0 - p.norm_squared())));
                if let Some(c) = damping {
                    *v *= c;
                    *w *= c;
                }
                // The sum is finite exactly when every component is (NaN and ±∞ propagate).
                (wall_contacts, (x.sum() + v.sum() + w.sum()).is_finite())
            })
            .reduce(|| (0, true), |a, b| (a.0 + b.0, a.1 && b.1))
    }

    /// Bytes of memory the simulation holds: per body and per listed pair (state and the step's
    /// working memory), and the base meshes that polyhedron grains share.
    pub fn memory(&self) -> Memory {
        use std::mem::size_of_val;
        let b = &self.bodies;
        let arrays = size_of_val(&b.position[..])
            + size_of_val(&b.orientation[..])
            + size_of_val(&b.velocity[..])
            + size_of_val(&b.angular_velocity[..])
            + size_of_val(&b.mass[..])
            + size_of_val(&b.inertia[..])
            + size_of_val(&b.volume[..])
            + size_of_val(&b.shape[..])
            + size_of_val(&b.bounding_radius[..])
            + size_of_val(&b.turn[..]);
        let shapes: usize = b.shape.iter().map(Shape::heap_bytes).sum();
        let walls: usize =
            self.walls.iter().map(|h| size_of_val(h) + h.capacity() * std::mem::size_of::<WallPoint>()).sum();
        let mut meshes: Vec<&std::sync::Arc<super::shape::ConvexPolyhedron>> = Vec::new();
        for shape in &b.shape {
            if let Shape::Polyhedron(p) = shape
                && !meshes.iter().any(|m| std::sync::Arc::ptr_eq(m, &p.base))
            {
                meshes.push(&p.base);
            }
        }
        let pipeline = &self.pipeline;
        Memory {
            bodies: arrays
                + shapes
                + walls
                + self.neighbours.body_bytes()
                + size_of_val(&pipeline.poses[..])
                + size_of_val(&pipeline.loads[..]),
            pairs: self.neighbours.pair_bytes() + size_of_val(&pipeline.pair_forces[..]),
            shared_meshes: meshes.iter().map(|m| m.heap_bytes()).sum(),
        }
    }

    /// Mass-averaged height ⟨z⟩ = Σ m z / Σ m (§4.3).
    pub fn mean_height(&self) -> f64 {
        let b = &self.bodies;
        let total: f64 = b.mass.iter().sum();
        b.mass.iter().zip(&b.position).map(|(m, x)| m * x.z).sum::<f64>() / total
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{UnitQuaternion, Vector3};

    use super::*;

    /// A bed of spheres (2–4 mm) starting at rest with a layer raining onto it at 1.5 m/s, as
    /// new grains arrive in a packing's generation.
    fn bed_and_rain() -> Simulation {
        let material = Material { restitution: 0.1, friction: 0.5, ..Material::default() };
        let settings = Settings {
            material,
            time_step: 5e-6,
            skin: 3e-4,
            calibration: Calibration::Discrete,
            contact_point: ContactPoint::CentreOfPressure,
        };
        let mut sim = Simulation::new(Domain::Periodic { width: 0.054 }, settings).unwrap();
        for k in 0..6 * 6 * 5 {
            let (x, y, layer) = (k % 6, (k / 6) % 6, k / 36);
            let radius = 2e-3 + 2e-3 * ((k * 7919) % 13) as f64 / 12.0;
            let falling = layer == 4;
            sim.add_body(NewBody {
                shape: Shape::Sphere { radius },
                position: Vector3::new(
                    0.0045 + 0.009 * x as f64,
                    0.0045 + 0.009 * y as f64,
                    if falling { 0.058 } else { 0.0045 + 0.009 * layer as f64 },
                ),
                orientation: UnitQuaternion::identity(),
                velocity: Vector3::new(0.0, 0.0, if falling { -1.5 } else { 0.0 }),
                angular_velocity: Vector3::zeros(),
            });
        }
        sim
    }

    #[test]
    fn fast_grains_take_a_larger_share_of_the_skin_and_the_motion_is_the_same_bit_for_bit() {
        // The list only decides which pairs the narrow phase looks at; spheres have no narrow-phase
        // cache, so every listing that misses no contact gives the same forces in the same order.
        let mut classic = bed_and_rain();
        classic.neighbours = NeighbourList::new(classic.settings.skin, 0.0);
        let mut ahead = bed_and_rain();
        let mut landed = false;
        for _ in 0..4000 {
            classic.step().unwrap();
            ahead.step().unwrap();
            landed |= ahead.bodies.velocity[150..].iter().any(|v| v.z > -1.0);
        }
        assert!(landed, "the rain reached the bed");
        assert_eq!(classic.bodies.position, ahead.bodies.position);
        assert_eq!(classic.bodies.velocity, ahead.bodies.velocity);
        assert_eq!(classic.bodies.angular_velocity, ahead.bodies.angular_velocity);
        // At 1.5 m/s half the skin (0.15 mm) lasts 20 steps, the horizon's share (0.6 mm, at
        // twice the skin) 80; the bed's own motion sets the pace once the rain has landed.
        let (slow, fast) = (classic.neighbours.builds, ahead.neighbours.builds);
        assert!(fast * 3 < slow, "{fast} builds against {slow}");
    }
}
