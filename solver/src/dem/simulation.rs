//! One DEM time step, read as the algorithm: neighbours → contacts → forces and integration.
//! The packing protocol decides only which external forces apply (gravity and buoyancy, the
//! shaking of Eq. 14, the damping of Eq. 15).

use std::time::{Duration, Instant};

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::body::{Bodies, NewBody};
use super::contact;
use super::contact::ellipsoid::EllipsoidPose;
use super::contact_law::{Calibration, ContactHistory, LinearSpringDashpot};
use super::domain::Domain;
use super::material::Material;
use super::neighbours::NeighbourList;
use crate::SolverError;

/// Time steps per collision below which the linear spring-dashpot is not resolved (the paper
/// uses T_c/Δt = 40, §4.2).
pub const MIN_STEPS_PER_COLLISION: f64 = 10.0;

/// Overlap, relative to the smaller grain's smallest half-extent, beyond which the simulation is
/// declared unstable rather than continued with a garbage result.
pub const MAX_RELATIVE_OVERLAP: f64 = 0.5;

/// Material and numerical constants of a simulation (§4.2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    pub material: Material,
    pub time_step: f64,
    /// Verlet skin of the neighbour list (m).
    pub skin: f64,
    /// How k_n and d_n follow from e_n and T_c.
    pub calibration: Calibration,
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

/// Force and torques of one pair contact: the force acts on body j, its opposite on body i,
/// both at the contact point.
#[derive(Debug, Clone, Copy, Default)]
struct PairForce {
    force: Vector3<f64>,
    torque_i: Vector3<f64>,
    torque_j: Vector3<f64>,
}

/// Wall-clock time spent in each stage since the simulation began.
#[derive(Debug, Clone, Copy, Default)]
pub struct StageTimes {
    pub neighbours: Duration,
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
    /// Per body, the history of each piece's contact with the floor and with the cylinder wall.
    floor_history: Vec<Vec<ContactHistory>>,
    wall_history: Vec<Vec<ContactHistory>>,
    pub time: f64,
    pub steps: u64,
    /// Shaking force applied in the current phase, if any.
    pub shaking: Option<Shaking>,
    /// Damping coefficient c_d of Eq. 15 applied in the current phase, if any.
    pub damping: Option<f64>,
    /// Contacts (pair and wall) open in the last step.
    pub contacts: usize,
    #[serde(skip)]
    pair_forces: Vec<PairForce>,
    /// Narrow-phase ellipsoid of every non-spherical body at the current orientation.
    #[serde(skip)]
    poses: Vec<Option<EllipsoidPose>>,
    #[serde(skip)]
    pub stage_times: StageTimes,
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
            neighbours: NeighbourList::new(settings.skin),
            floor_history: Vec::new(),
            wall_history: Vec::new(),
            time: 0.0,
            steps: 0,
            shaking: None,
            damping: None,
            contacts: 0,
            pair_forces: Vec::new(),
            poses: Vec::new(),
            stage_times: StageTimes::default(),
        })
    }

    pub fn law(&self) -> &LinearSpringDashpot {
        &self.law
    }

    pub fn add_body(&mut self, body: NewBody) -> usize {
        self.floor_history.push(vec![ContactHistory::default(); body.shape.pieces()]);
        self.wall_history.push(vec![ContactHistory::default(); body.shape.pieces()]);
        self.refresh_poses();
        self.poses.push(body.shape.pose(body.position, &body.orientation));
        self.bodies.push(body, self.settings.material.density)
    }

    /// Recomputes every pose when they are missing (a simulation restored from a checkpoint).
    fn refresh_poses(&mut self) {
        if self.poses.len() != self.bodies.len() {
            let b = &self.bodies;
            self.poses = (0..b.len()).map(|k| b.shape[k].pose(b.position[k], &b.orientation[k])).collect();
        }
    }

    /// Advances the simulation by one time step Δt.
    pub fn step(&mut self) -> Result<(), SolverError> {
        let start = Instant::now();
        self.refresh_poses();
        if self.neighbours.is_stale(&self.bodies) {
            self.neighbours.rebuild(&mut self.bodies, &self.domain)?;
        }
        let after_neighbours = Instant::now();
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
        self.time += self.settings.time_step;
        self.steps += 1;
        self.stage_times.neighbours += after_neighbours - start;
        self.stage_times.contacts += after_contacts - after_neighbours;
        self.stage_times.bodies += end - after_contacts;
        Ok(())
    }

    /// Narrow phase and contact law for every listed pair; returns the number of open contacts
    /// and the largest overlap relative to the pair's smaller half-extent.
    fn pair_contacts(&mut self) -> (usize, f64) {
        let bodies = &self.bodies;
        let domain = self.domain;
        let poses = &self.poses;
        let law = &self.law;
        let dt = self.settings.time_step;
        self.pair_forces.resize(self.neighbours.pairs.len(), PairForce::default());
        let pairs = &self.neighbours.pairs;
        pairs
            .par_iter()
            .zip(self.neighbours.history.par_iter_mut())
            .zip(self.pair_forces.par_iter_mut())
            .map(|((pair, history), out)| {
                let (i, j) = (pair.i as usize, pair.j as usize);
                let xi = bodies.position[i];
                let xj = bodies.position[j] + domain.shift(pair.image);
                let (geometry, scale) = if pair.spheres {
                    // Sphere beds spend most of their time here: no shape to load, no piece to build.
                    let (ra, rb) = (bodies.bounding_radius[i], bodies.bounding_radius[j]);
                    (contact::sphere::sphere_sphere(&xi, ra, &xj, rb), ra.min(rb))
                } else {
                    let [ka, kb] = pair.pieces.map(usize::from);
                    let a = bodies.shape[i].piece(ka, xi, &bodies.orientation[i], poses[i].as_ref());
                    let b = bodies.shape[j].piece(kb, xj, &bodies.orientation[j], poses[j].as_ref());
                    let scale = a.smallest_half_extent().min(b.smallest_half_extent());
                    (contact::between(&a, &b, &mut history.normal), scale)
                };
                let Some(geometry) = geometry else {
                    history.tangential_displacement = Vector3::zeros();
                    *out = PairForce::default();
                    return (0, 0.0);
                };
                let arm_i = geometry.point - xi;
                let arm_j = geometry.point - xj;
                let relative = bodies.point_velocity(j, &arm_j) - bodies.point_velocity(i, &arm_i);
                let force = law.force(pair.effective_mass, &geometry, &relative, history, dt);
                *out = PairForce { force, torque_i: force.cross(&arm_i), torque_j: arm_j.cross(&force) };
                (1, geometry.depth / scale)
            })
            .reduce(|| (0, 0.0), |a, b| (a.0 + b.0, a.1.max(b.1)))
    }

    /// Per body: wall contacts, the sum of its pair forces, external forces, then the
    /// semi-implicit Euler update of §3.1 (velocities first, then position and rotation).
    /// Returns the number of wall contacts and whether every state stayed finite.
    fn forces_and_integration(&mut self) -> (usize, bool) {
        let settings = &self.settings;
        let law = &self.law;
        let domain = self.domain;
        let neighbours = &self.neighbours;
        let pair_forces = &self.pair_forces;
        let dt = settings.time_step;
        let weight_per_volume = settings.material.weight_per_volume();
        let shaking = self.shaking.map_or(0.0, |s| s.acceleration(self.time));
        let damping = self.damping.map(|c| c.powf(dt));
        let b = &mut self.bodies;
        (
            b.position.par_iter_mut(),
            b.orientation.par_iter_mut(),
            b.velocity.par_iter_mut(),
            b.angular_velocity.par_iter_mut(),
            self.floor_history.par_iter_mut(),
            self.wall_history.par_iter_mut(),
            self.poses.par_iter_mut(),
        )
            .into_par_iter()
            .enumerate()
            .map(|(k, (x, q, v, w, floor, wall, pose))| {
                let shape = &b.shape[k];
                let mass = b.mass[k];
                let mut force = weight_per_volume * b.volume[k] + Vector3::new(mass * shaking, 0.0, 0.0);
                let mut torque = Vector3::zeros();
                let (as_i, as_j) = neighbours.pairs_of(k);
                for &pair in as_i {
                    let pf = &pair_forces[pair as usize];
                    force -= pf.force;
                    torque += pf.torque_i;
                }
                for &pair in as_j {
                    let pf = &pair_forces[pair as usize];
                    force += pf.force;
                    torque += pf.torque_j;
                }
                let mut wall_contacts = 0;
                for (k, (floor, wall)) in floor.iter_mut().zip(wall.iter_mut()).enumerate() {
                    let piece = shape.piece(k, *x, q, pose.as_ref());
                    for (geometry, history) in
                        [(contact::with_floor(&piece), &mut *floor), (contact::with_wall(&piece, &domain), &mut *wall)]
                    {
                        let Some(g) = geometry else {
                            *history = ContactHistory::default();
                            continue;
                        };
                        // The wall is body B, immovable: m_eff = m and its velocity is zero.
                        let arm = g.point - *x;
                        let relative = -(*v + w.cross(&arm));
                        let f = -law.force(mass, &g, &relative, history, dt);
                        force += f;
                        torque += arm.cross(&f);
                        wall_contacts += 1;
                    }
                }

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
                // q ← q + ½ Δt (0, ω) q, exact to O((|ω|Δt)³) per step, then renormalised by one
                // Newton step for 1/|q| about 1: |q|² − 1 is O((|ω|Δt)²), so the error is of
                // its square, below round-off, and no square root or division is needed.
                let p = q.quaternion() + Quaternion::from_imag(*w * (0.5 * dt)) * q.quaternion();
                *q = UnitQuaternion::new_unchecked(p * (0.5 * (3.0 - p.norm_squared())));
                if let Some(c) = damping {
                    *v *= c;
                    *w *= c;
                }
                if pose.is_some() {
                    *pose = shape.pose(*x, q);
                }
                // The sum is finite exactly when every component is (NaN and ±∞ propagate).
                (wall_contacts, (x.sum() + v.sum() + w.sum()).is_finite())
            })
            .reduce(|| (0, true), |a, b| (a.0 + b.0, a.1 && b.1))
    }

    /// Mass-averaged height ⟨z⟩ = Σ m z / Σ m (§4.3).
    pub fn mean_height(&self) -> f64 {
        let b = &self.bodies;
        let total: f64 = b.mass.iter().sum();
        b.mass.iter().zip(&b.position).map(|(m, x)| m * x.z).sum::<f64>() / total
    }
}
