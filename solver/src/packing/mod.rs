//! The packing protocol of §4.3: grains created layer by layer on a hexahedral grid in the upper
//! part of the domain, shaken horizontally (Eq. 14) from the start until t_s after the last
//! creation, then damped (Eq. 15) until the mass-averaged height settles; finally the porosity of
//! §4.4. What a packing is, with the paper's defaults and rules, is `PackingSpec` (spec.rs).

mod spec;

pub use spec::{
    Derived, DomainKind, FLUID_COUPLING, FluidSpec, FormSpec, GrainSpec, Grid, Orientation, PackingSpec, Process,
    ShapeKind, SpecError, in_range,
};

use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;
use std::time::{Duration, Instant};

use nalgebra::{UnitQuaternion, Vector3};
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::SolverError;
use crate::dem::shape::{ConvexPolyhedron, Polyhedron};
use crate::dem::{NewBody, Settings, Shape, Simulation, uniform_rotation};
use crate::fabric::{Imbrication, imbrication};
use crate::fluid::Fluid;
use crate::grain::{
    DrawnClass, FormParameters, FormSampler, FormStatistic, MeshLibrary, SizeSampler, bonded_grain, form_statistics,
};
use crate::porosity::{self, Porosity, PorosityError, PorositySettings};

#[derive(Debug, Error, Clone, PartialEq)]
pub enum PackingError {
    #[error(transparent)]
    Spec(#[from] SpecError),
    #[error(transparent)]
    Solver(#[from] SolverError),
    #[error(transparent)]
    Porosity(#[from] PorosityError),
    #[error(
        "process.generation.spacing = {spacing} m leaves no grid position in the generation region \
         z ∈ [0.6, 1]·H of the domain (raise domain.height or lower the spacing)"
    )]
    NoGridPositions { spacing: f64 },
    #[error(
        "a grain of bounding radius {radius} m fits inside the domain at no position of the generation \
         grid (spacing {spacing} m) {turns}: widen the domain or narrow the grains"
    )]
    NoRoom { radius: f64, spacing: f64, turns: String },
    #[error("not converged after solver.max_time = {0} s of simulated time")]
    NotConverged(f64),
    #[error("the packing has not converged yet")]
    Unfinished,
    #[error("grains.meshes: {0}")]
    Meshes(String),
    #[error("grains.form: {0}")]
    Form(String),
}

/// The stage of the protocol.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Phase {
    Generation,
    Shaking,
    Damping,
    Converged,
}

impl Phase {
    pub fn name(self) -> &'static str {
        match self {
            Phase::Generation => "generation",
            Phase::Shaking => "shaking",
            Phase::Damping => "damping",
            Phase::Converged => "converged",
        }
    }
}

/// A snapshot for progress displays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    pub phase: Phase,
    pub time: f64,
    pub steps: u64,
    pub grains: usize,
    pub contacts: usize,
    /// Fraction of the target mass created so far.
    pub created: f64,
    /// While the packing shakes: the simulated time the shaking ends, t_s after the last set of
    /// grains was created (§4.3).
    pub shaking_until: Option<f64>,
}

/// One created grain as sampled: its sieve class, size D and form.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GrainRecord {
    pub class: usize,
    pub size: f64,
    pub form: FormParameters,
}

/// A drawn grain waiting for a grid position: its record and, for a mesh packing, its mesh.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct Draw {
    record: GrainRecord,
    mesh: Option<usize>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PackingResult {
    pub porosity: Porosity,
    pub particles: usize,
    pub simulated_time: f64,
    pub steps: u64,
    pub wall_time: Duration,
    /// Mean and (population) standard deviation of every Table 1 factor X and of X⁻¹ over the
    /// grains, where defined for every grain.
    pub statistics: Vec<FormStatistic>,
    /// The long axes' fabric against the flow (+x), for packings deposited with fluid forces on
    /// and grains that have a long axis.
    pub imbrication: Option<Imbrication>,
    /// Grains and mass created per sieve class, against the curve's mass fractions.
    pub size_classes: Vec<DrawnClass>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Packing {
    spec: PackingSpec,
    derived: Derived,
    pub simulation: Simulation,
    rng: ChaCha8Rng,
    phase: Phase,
    pub grains: Vec<GrainRecord>,
    created_mass: f64,
    /// Grains drawn but not placed yet, first in line for the next set.
    pending: Vec<Draw>,
    /// Bodies of the last generated set; a new set comes once all have left the region.
    set_start: usize,
    grid: Vec<Vector3<f64>>,
    shaking_until: f64,
    next_check: f64,
    last_height: Option<f64>,
    wall_time: Duration,
    /// The convex base shape of each mesh of the library, shared by the grains drawn from it.
    #[serde(skip)]
    bases: Vec<Arc<ConvexPolyhedron>>,
    /// The spec's fluid forces, handed to the simulation every step (it does not keep them).
    fluid: Option<Fluid>,
}

/// Random orientations a grain tries before it waits for the next set: in a cylinder, a long
/// grain near the axis fits when it stands steeply enough.
const ORIENTATIONS: usize = 32;

impl Orientation {
    /// Turns a new grain tries before it waits for the next set.
    fn tries(self) -> usize {
        match self {
            Orientation::Random => ORIENTATIONS,
            Orientation::Upright => 1,
        }
    }

    /// A new grain's turn.
    fn turn(self, rng: &mut ChaCha8Rng) -> UnitQuaternion<f64> {
        match self {
            Orientation::Random => uniform_rotation(rng),
            // A grain's L, I, S lie along its body's x, y, z: turn x up and z across.
            Orientation::Upright => UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -FRAC_PI_2),
        }
    }

    /// The turns tried, in words.
    fn tried(self) -> String {
        match self {
            Orientation::Random => format!("in any of {ORIENTATIONS} random orientations"),
            Orientation::Upright => "standing upright (process.generation.orientation)".into(),
        }
    }
}

/// Steps between checks of whether the last set has left the generation region.
const GENERATION_CHECK_STEPS: u64 = 100;

impl Packing {
    /// A packing of a checked spec, ready to generate its first grains.
    pub fn new(spec: PackingSpec) -> Result<Self, PackingError> {
        spec.check()?;
        let derived = spec.derived();
        let settings = Settings {
            material: spec.material,
            time_step: spec.time_step,
            skin: derived.skin,
            calibration: spec.calibration,
            contact_point: spec.contact_point,
        };
        let simulation = Simulation::new(spec.domain, settings)?;
        let grid = generation_grid(&spec, &derived);
        if grid.is_empty() {
            return Err(PackingError::NoGridPositions { spacing: derived.spacing });
        }
        if spec.grains.shape == ShapeKind::Mesh && spec.grains.meshes.as_ref().is_none_or(|m| m.meshes.is_empty()) {
            return Err(PackingError::Meshes("a mesh packing needs at least one mesh".into()));
        }
        Ok(Self {
            rng: ChaCha8Rng::seed_from_u64(spec.seed),
            simulation,
            phase: Phase::Generation,
            grains: Vec::new(),
            created_mass: 0.0,
            pending: Vec::new(),
            set_start: 0,
            grid,
            shaking_until: f64::INFINITY,
            next_check: 0.0,
            last_height: None,
            wall_time: Duration::ZERO,
            bases: Vec::new(),
            fluid: spec.fluid_forces(),
            spec,
            derived,
        })
    }

    pub fn spec(&self) -> &PackingSpec {
        &self.spec
    }

    pub fn derived(&self) -> &Derived {
        &self.derived
    }

    /// Gives a packing restored from a checkpoint its meshes back (a checkpoint keeps only their
    /// digest); they must be the ones it was started with.
    pub fn attach_meshes(&mut self, library: &MeshLibrary) -> Result<(), PackingError> {
        match &mut self.spec.grains.meshes {
            Some(own) if own == library => {
                own.meshes.clone_from(&library.meshes);
                Ok(())
            }
            _ => Err(PackingError::Meshes(format!("{}: not the meshes this packing was started with", library.source))),
        }
    }

    pub fn progress(&self) -> Progress {
        Progress {
            phase: self.phase,
            time: self.simulation.time,
            steps: self.simulation.steps,
            grains: self.simulation.bodies.len(),
            contacts: self.simulation.contacts,
            created: (self.created_mass / self.spec.grains.mass).min(1.0),
            shaking_until: (self.phase == Phase::Shaking).then_some(self.shaking_until),
        }
    }

    /// Runs at most `max_steps` time steps; returns the phase reached.
    pub fn advance(&mut self, max_steps: u64) -> Result<Phase, PackingError> {
        let start = Instant::now();
        let result = self.run(max_steps);
        self.wall_time += start.elapsed();
        result
    }

    fn run(&mut self, max_steps: u64) -> Result<Phase, PackingError> {
        let p = self.spec.process;
        let dt = self.spec.time_step;
        for _ in 0..max_steps {
            match self.phase {
                Phase::Generation
                    if self.simulation.steps.is_multiple_of(GENERATION_CHECK_STEPS) && self.last_set_left() =>
                {
                    self.generate_set()?;
                    if self.created_mass >= self.spec.grains.mass && self.pending.is_empty() {
                        self.shaking_until = self.simulation.time + p.shaking_duration;
                        self.phase = Phase::Shaking;
                    }
                }
                Phase::Shaking if self.simulation.time >= self.shaking_until => {
                    self.phase = Phase::Damping;
                    self.next_check = self.simulation.time;
                }
                Phase::Damping if self.simulation.time >= self.next_check - 0.5 * dt => {
                    let height = self.simulation.mean_height();
                    if self.last_height.is_some_and(|last| (height - last).abs() < p.height_change) {
                        self.phase = Phase::Converged;
                        return Ok(self.phase);
                    }
                    self.last_height = Some(height);
                    self.next_check += p.interval;
                }
                Phase::Converged => return Ok(self.phase),
                _ => {}
            }
            if self.simulation.time > self.derived.max_time {
                return Err(PackingError::NotConverged(self.derived.max_time));
            }
            self.simulation.shaking = (self.phase != Phase::Damping).then_some(p.shaking);
            self.simulation.damping = (self.phase == Phase::Damping).then_some(p.damping);
            self.simulation.fluid = self.fluid;
            self.simulation.step()?;
        }
        Ok(self.phase)
    }

    /// Whether every grain of the last set lies wholly below the generation region.
    fn last_set_left(&self) -> bool {
        let floor = 0.6 * self.derived.height;
        let b = &self.simulation.bodies;
        (self.set_start..b.len()).all(|k| b.position[k].z + b.bounding_radius[k] < floor)
    }

    /// Fills the generation grid with the next set of grains. Grains drawn earlier that found
    /// no room wait in `pending` and come first; new ones are drawn until the drawn mass reaches
    /// the target. The set is placed largest grain first, each at the first free position (in
    /// a random order) where its bounding sphere overlaps nothing, and a grain that finds none
    /// waits for the next set. No drawn grain is thrown away, so the packing holds the sampled
    /// size and form distributions: discarding the grains that do not fit, as sedpack 0.1.0 did,
    /// drops the coarse classes of a wide sieve curve (U7 lost every grain above 16 mm).
    fn generate_set(&mut self) -> Result<(), PackingError> {
        let spec = &self.spec;
        let sizes: SizeSampler = spec.grains.size.sampler();
        let forms: Option<FormSampler> = match spec.grains.form {
            FormSpec::Distribution(d) => Some(d.sampler().map_err(|e| PackingError::Form(e.to_string()))?),
            FormSpec::Single { .. } | FormSpec::Own => None,
        };
        let meshes = spec.grains.meshes.as_ref().map_or(&[][..], |m| &m.meshes[..]);
        if self.bases.len() != meshes.len() {
            self.bases = meshes
                .iter()
                .map(|m| ConvexPolyhedron::new(m.mesh()).map(Arc::new))
                .collect::<Result<_, _>>()
                .map_err(|e| PackingError::Meshes(e.to_string()))?;
        }
        let (density, target) = (spec.material.density, spec.grains.mass);
        let mut set: Vec<(Draw, Shape)> = Vec::with_capacity(self.grid.len());
        for draw in std::mem::take(&mut self.pending) {
            set.push((draw, self.shape(&draw)?));
        }
        let mut drawn_mass = self.created_mass + set.iter().map(|(_, s)| density * s.volume()).sum::<f64>();
        while drawn_mass < target && set.len() < self.grid.len() {
            let draw = self.draw(&sizes, forms.as_ref())?;
            let shape = self.shape(&draw)?;
            drawn_mass += density * shape.volume();
            set.push((draw, shape));
        }
        // Largest first: a coarse grain needs an empty neighbourhood, fine ones fill the gaps.
        set.sort_by(|a, b| b.1.bounding_radius().total_cmp(&a.1.bounding_radius()));
        let mut free: Vec<usize> = (0..self.grid.len()).collect();
        free.shuffle(&mut self.rng);
        let domain = self.spec.domain;
        let reach = set.first().map_or(0.0, |(_, s)| s.bounding_radius());
        let floor = 0.6 * self.derived.height - reach;
        let b = &self.simulation.bodies;
        // Grains of earlier sets that a grain of the lowest grid layer could still touch.
        let mut occupied: Vec<(Vector3<f64>, f64)> = (0..b.len())
            .filter(|&k| b.position[k].z + b.bounding_radius[k] > floor)
            .map(|k| (b.position[k], b.bounding_radius[k]))
            .collect();
        let (u, rule) = (self.spec.process.velocity, self.spec.process.orientation);
        self.set_start = self.simulation.bodies.len();
        for (draw, shape) in set {
            let r = shape.bounding_radius();
            // Free positions where the grain's bounding sphere touches no other, whatever its turn.
            let clear: Vec<usize> = (0..free.len())
                .filter(|&k| {
                    let p = &self.grid[free[k]];
                    occupied.iter().all(|(q, rq)| domain.nearest_distance2(p, q) >= (r + rq).powi(2))
                })
                .collect();
            let mut placement = None;
            for _ in 0..rule.tries() {
                let orientation = rule.turn(&mut self.rng);
                let reach = shape.horizontal_reach(&orientation);
                if let Some(&k) =
                    clear.iter().find(|&&k| domain.holds(self.grid[free[k]].x, self.grid[free[k]].y, reach))
                {
                    placement = Some((k, orientation));
                    break;
                }
                if clear.is_empty() || domain.is_periodic() {
                    break;
                }
            }
            let Some((slot, orientation)) = placement else {
                if self.simulation.bodies.len() == self.set_start {
                    return Err(PackingError::NoRoom { radius: r, spacing: self.derived.spacing, turns: rule.tried() });
                }
                self.pending.push(draw);
                continue;
            };
            let position = self.grid[free.remove(slot)];
            let mut spin = || self.rng.random_range(-0.1..0.1) * u;
            let velocity = Vector3::new(spin(), spin(), -u);
            let angular_velocity = Vector3::new(spin(), spin(), spin()) / draw.record.size;
            let volume = shape.volume();
            self.simulation.add_body(NewBody { shape, position, orientation, velocity, angular_velocity });
            occupied.push((position, r));
            self.created_mass += density * volume;
            self.grains.push(draw.record);
        }
        Ok(())
    }

    /// A new grain from the size distribution, the mesh library and the form rule of the spec.
    fn draw(&mut self, sizes: &SizeSampler, forms: Option<&FormSampler>) -> Result<Draw, PackingError> {
        let spec = &self.spec;
        let (class, size) = sizes.sample(&mut self.rng);
        let meshes = spec.grains.meshes.as_ref().map_or(&[][..], |m| &m.meshes[..]);
        let mesh = (spec.grains.shape == ShapeKind::Mesh).then(|| self.rng.random_range(0..meshes.len()));
        let form = match (spec.grains.shape, spec.grains.form, forms) {
            (ShapeKind::Sphere, ..) => FormParameters { l: size, i: size, s: size },
            (_, FormSpec::Single { fl, el }, _) => FormParameters::from_flatness_elongation(fl, el, size),
            (_, FormSpec::Own, _) => match mesh {
                Some(k) => meshes[k].original_form().scaled_to_size(size),
                None => return Err(PackingError::Meshes("a mesh's own form needs grains.shape: mesh".into())),
            },
            (_, _, Some(sampler)) => sampler.sample(size, &mut self.rng),
            (_, FormSpec::Distribution(_), None) => unreachable!("a distribution always has a sampler"),
        };
        Ok(Draw { record: GrainRecord { class, size, form }, mesh })
    }

    /// The shape of a drawn grain.
    fn shape(&self, draw: &Draw) -> Result<Shape, PackingError> {
        let form = &draw.record.form;
        Ok(match (self.spec.grains.shape, draw.mesh) {
            (ShapeKind::Sphere, _) => Shape::Sphere { radius: draw.record.size / 2.0 },
            (ShapeKind::Ellipsoid, _) => Shape::Ellipsoid { semi_axes: Vector3::new(form.l, form.i, form.s) / 2.0 },
            (ShapeKind::BondedSpheres, _) => {
                Shape::from(&bonded_grain(form).map_err(|e| PackingError::Form(e.to_string()))?)
            }
            (ShapeKind::Mesh, Some(k)) => {
                let grain = Polyhedron::with_form(self.bases[k].clone(), form)
                    .map_err(|e| PackingError::Meshes(e.to_string()))?;
                Shape::Polyhedron(Box::new(grain))
            }
            (ShapeKind::Mesh, None) => unreachable!("a mesh was drawn for a mesh packing"),
        })
    }

    /// Porosity (§4.4) and grain statistics of the converged packing.
    pub fn result(&self) -> Result<PackingResult, PackingError> {
        if self.phase != Phase::Converged {
            return Err(PackingError::Unfinished);
        }
        let b = &self.simulation.bodies;
        let spheres: Vec<(f64, f64)> =
            (0..b.len()).map(|k| (b.position[k].z, b.shape[k].equivalent_radius())).collect();
        let settings = PorositySettings { slice: self.spec.slice, cutoff: self.spec.cutoff, trim: self.derived.trim };
        let porosity = porosity::evaluate(&spheres, self.spec.domain.cross_section(), &settings)?;
        Ok(PackingResult {
            porosity,
            particles: b.len(),
            simulated_time: self.simulation.time,
            steps: self.simulation.steps,
            wall_time: self.wall_time,
            statistics: form_statistics(&self.grains.iter().map(|g| g.form).collect::<Vec<_>>()),
            imbrication: self.fluid.and_then(|_| imbrication(&b.shape, &b.orientation)),
            size_classes: self.drawn_classes(),
        })
    }

    /// The grains created so far per sieve class; body k is grain k, as no body is ever removed.
    fn drawn_classes(&self) -> Vec<DrawnClass> {
        let density = self.spec.material.density;
        let masses = self.simulation.bodies.volume.iter().map(|v| density * v);
        self.spec.grains.size.drawn(self.grains.iter().map(|g| g.class).zip(masses))
    }
}

/// Grid positions of the generation region z ∈ [0.6, 1]·H, spacing h_g, each at least h_g/2
/// inside the domain's side (within R − h_g/2 of a cylinder's axis).
fn generation_grid(spec: &PackingSpec, derived: &Derived) -> Vec<Vector3<f64>> {
    match spec.process.grid {
        Grid::Cubic => cubic_grid(spec, derived),
        Grid::Hcp => hcp_grid(spec, derived),
    }
}

/// The cubic grid, centred horizontally.
fn cubic_grid(spec: &PackingSpec, derived: &Derived) -> Vec<Vector3<f64>> {
    let (h, height) = (derived.spacing, derived.height);
    let l = spec.domain.width();
    let per_row = (l / h).floor() as usize;
    let layers = (0.4 * height / h).floor() as usize;
    let offset = (l - (per_row.max(1) - 1) as f64 * h) / 2.0;
    let mut grid = Vec::with_capacity(per_row * per_row * layers);
    for k in 0..layers {
        for j in 0..per_row {
            for i in 0..per_row {
                let p = Vector3::new(offset + i as f64 * h, offset + j as f64 * h, 0.6 * height + (k as f64 + 0.5) * h);
                if spec.domain.holds(p.x, p.y, h / 2.0) {
                    grid.push(p);
                }
            }
        }
    }
    grid
}

/// The hexagonal close-packed grid of the paper's software, laid out from the domain's axis:
/// rows of positions h_g apart, rows √3/2 h_g apart and shifted by h_g/2 in turn, layers
/// √(2/3) h_g apart and shifted by a third of a row spacing in turn (waLBerla's `HCPGrid`),
/// so that every position has its nearest neighbours h_g away. Its positions reach, as the
/// cubic grid's do, to h_g/2 inside the domain's side.
fn hcp_grid(spec: &PackingSpec, derived: &Derived) -> Vec<Vector3<f64>> {
    let (h, height) = (derived.spacing, derived.height);
    let l = spec.domain.width();
    let c = l / 2.0;
    let (dy, dz) = (h * 3f64.sqrt() / 2.0, h * (2.0f64 / 3.0).sqrt());
    let layers = (0.4 * height / dz).floor() as usize;
    let (rows, columns) = ((c / dy).ceil() as i64 + 1, (c / h).ceil() as i64 + 1);
    let inside = |u: f64| (h / 2.0..=l - h / 2.0).contains(&u);
    let mut grid = Vec::new();
    for k in 0..layers {
        let z = 0.6 * height + (k as f64 + 0.5) * dz;
        for j in -rows..=rows {
            let y = c + dy * (j as f64 + (k % 2) as f64 / 3.0);
            for i in -columns..=columns {
                let x = c + h * (i as f64 + (j + k as i64).rem_euclid(2) as f64 / 2.0);
                if inside(x) && inside(y) && spec.domain.holds(x, y, h / 2.0) {
                    grid.push(Vector3::new(x, y, z));
                }
            }
        }
    }
    grid
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grain::Table3Case;

    /// Generates every set of a U7 packing of ellipsoids of FL 0.65 and EL `el` without the
    /// dynamics: a placed set is moved far below the generation region, as if it had fallen.
    /// Checks on the way that no two grains of a set overlap and that every grain lies inside
    /// the domain; returns the packing and how many grains fit the cylinder only by their turn.
    fn generate_without_falling(kind: DomainKind, el: f64) -> (Packing, usize) {
        let mut spec = PackingSpec::paper(kind);
        spec.grains.size = Table3Case::find("U7").unwrap().sieve_curve();
        spec.grains.form = FormSpec::Single { fl: 0.65, el };
        if kind == DomainKind::Periodic {
            (spec.domain, spec.grains.mass) = (crate::dem::Domain::Periodic { width: 0.1 }, 4.0);
        }
        let mut packing = Packing::new(spec).unwrap();
        let domain = packing.spec.domain;
        let mut turned = 0;
        while packing.created_mass < packing.spec.grains.mass || !packing.pending.is_empty() {
            let start = packing.simulation.bodies.len();
            packing.generate_set().unwrap();
            let b = &mut packing.simulation.bodies;
            assert!(b.len() > start, "a set placed no grain");
            for i in start..b.len() {
                let (x, y) = (b.position[i].x, b.position[i].y);
                assert!(domain.holds(x, y, b.shape[i].horizontal_reach(&b.orientation[i])));
                turned += usize::from(!domain.holds(x, y, b.bounding_radius[i]));
                for j in start..i {
                    let d2 = domain.nearest_distance2(&b.position[i], &b.position[j]);
                    assert!(d2 >= (b.bounding_radius[i] + b.bounding_radius[j]).powi(2), "grains {i} and {j} overlap");
                }
            }
            for z in &mut b.position[start..] {
                z.z -= 10.0;
            }
        }
        (packing, turned)
    }

    /// Every drawn grain is placed, so the grains per sieve class follow the number weights of
    /// Eq. 9 as a multinomial sample: each count within 4 standard deviations (+1 for the
    /// rounding of the rare classes) of N w_i, for any seed. sedpack 0.1.0 threw away the grains
    /// that found no room: its Table 6 U7 packing of the Rhine scans held none of the ~15 grains
    /// above 16 mm expected among its first 2,731 (here: ~24 of ~4,250 and ~19 of ~3,260).
    /// In the cylinder the grains are longer (EL 0.45: a 31.5 mm grain is 83 mm long), so that
    /// the coarsest fit the 0.104 m cylinder from the grid positions nearest its axis (15.6 mm
    /// off it) only standing steeply: its bounding sphere would cross the wall.
    #[test]
    fn generation_keeps_the_drawn_sieve_curve_of_a_wide_distribution() {
        for (kind, el) in [(DomainKind::Periodic, 0.53), (DomainKind::Cylinder, 0.45)] {
            let (packing, turned) = generate_without_falling(kind, el);
            if kind == DomainKind::Cylinder {
                assert!(turned > 0, "no grain needed its turn to fit the cylinder");
            }
            let weights = packing.spec.grains.size.number_weights();
            let n = packing.grains.len() as f64;
            let mut counts = vec![0usize; weights.len()];
            for g in &packing.grains {
                counts[g.class] += 1;
            }
            for (class, (&count, &w)) in counts.iter().zip(&weights).enumerate() {
                let sigma = (n * w * (1.0 - w)).sqrt();
                assert!(
                    (count as f64 - n * w).abs() <= 4.0 * sigma + 1.0,
                    "{kind:?}: class {class} holds {count} of {n} grains, expected {:.1} ± {sigma:.1}",
                    n * w
                );
            }
            assert!(counts[5] + counts[6] > 0, "{kind:?}: no grain above 16 mm");
            // The target mass is reached and overshot by less than the heaviest grain.
            let b = &packing.simulation.bodies;
            let density = packing.spec.material.density;
            let heaviest = b.volume.iter().fold(0.0_f64, |m, &v| m.max(v)) * density;
            let mass: f64 = b.volume.iter().sum::<f64>() * density;
            let target = packing.spec.grains.mass;
            assert!(mass >= target && mass < target + heaviest, "{kind:?}: {mass} kg for {target} kg");
            assert_eq!(packing.grains.len(), b.len());
        }
    }

    /// The first set of a U1 packing of elongated ellipsoids in the cylinder, created by `orientation`:
    /// each grain's long axis (body x) and short axis (body z) in the world frame.
    fn first_set_axes(orientation: Orientation) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        let mut spec = PackingSpec::paper(DomainKind::Cylinder);
        spec.grains.form = FormSpec::Single { fl: 0.65, el: 0.5 };
        spec.process.orientation = orientation;
        let mut packing = Packing::new(spec).unwrap();
        packing.generate_set().unwrap();
        let b = &packing.simulation.bodies;
        b.orientation.iter().map(|q| (q.transform_vector(&Vector3::x()), q.transform_vector(&Vector3::z()))).collect()
    }

    #[test]
    fn upright_grains_stand_on_their_long_axis_with_the_short_one_across_x() {
        let upright = first_set_axes(Orientation::Upright);
        assert!(upright.len() > 100, "{} grains", upright.len());
        for (long, short) in &upright {
            assert!((long - Vector3::z()).norm() < 1e-12, "{long}");
            assert!((short.x.abs() - 1.0).abs() < 1e-12, "{short}");
        }
        // Turned at random, |cos| of the long axis with the vertical is uniform on [0, 1]: mean
        // 1/2, std 1/√12 per grain, so within 4 standard errors of 1/2 over the set.
        let random = first_set_axes(Orientation::Random);
        let mean = random.iter().map(|(long, _)| long.z.abs()).sum::<f64>() / random.len() as f64;
        let tolerance = 4.0 / (12.0 * random.len() as f64).sqrt();
        assert!((mean - 0.5).abs() < tolerance, "mean |cos| {mean} over {} grains", random.len());
    }

    fn grid_of(domain: crate::dem::Domain, height: f64, spacing: f64, grid: Grid) -> Vec<Vector3<f64>> {
        let mut spec = PackingSpec::paper(DomainKind::Cylinder);
        (spec.domain, spec.height, spec.process.spacing, spec.process.grid) =
            (domain, Some(height), Some(spacing), grid);
        generation_grid(&spec, &spec.derived())
    }

    /// Table 6's U5 (h_g = 26 mm) in the 0.104 m cylinder, H = 1 m, positions within R − h_g/2
    /// = 39 mm of the axis, counted by hand. Cubic: positions ±13 and ±39 mm off the axis in x
    /// and y, of which only the four at (±13, ±13) mm lie within 39 mm ((39, 13) is 41.1 mm
    /// out), in floor(0.4 m / 26 mm) = 15 layers: 60. Close-packed: layers √(2/3)·26 = 21.2 mm
    /// apart, 18 in 0.4 m; rows 22.5 mm apart; a layer through the axis holds it, two at 26 mm
    /// on its row and two on each next row (13, ±22.5) mm: 7; the layers between are shifted
    /// by a third of a row: (±13, 7.5), (0 and ±26, −15) and (0, 30) mm, 15.0–30.0 mm out: 6.
    /// 9 × 7 + 9 × 6 = 117, the rain of new grains almost twice as dense.
    #[test]
    fn the_generation_grids_of_u5_in_the_cylinder_hold_the_positions_counted_by_hand() {
        let cylinder = crate::dem::Domain::Cylinder { diameter: 0.104 };
        let cubic = grid_of(cylinder, 1.0, 0.026, Grid::Cubic);
        let hcp = grid_of(cylinder, 1.0, 0.026, Grid::Hcp);
        assert_eq!((cubic.len(), hcp.len()), (60, 117));
        let layer = |z: f64| ((z - 0.6) / (0.026 * (2.0f64 / 3.0).sqrt()) - 0.5).round() as usize;
        for k in 0..18 {
            let count = hcp.iter().filter(|p| layer(p.z) == k).count();
            assert_eq!(count, if k % 2 == 0 { 7 } else { 6 }, "layer {k}");
        }
        for p in cubic.iter().chain(&hcp) {
            assert!((p.x - 0.052).hypot(p.y - 0.052) <= 0.039 + 1e-12 && (0.6..=1.0).contains(&p.z), "{p}");
        }
    }

    /// The close-packed grid is HCP: in a periodic box no two positions (or periodic images)
    /// are nearer than h_g, and a position away from the box's sides, bottom and top has its
    /// twelve nearest neighbours exactly h_g away (six in its layer, three above, three below).
    #[test]
    fn the_close_packed_grid_has_twelve_nearest_neighbours_at_the_spacing() {
        let (l, h) = (0.1, 0.01);
        let domain = crate::dem::Domain::Periodic { width: l };
        let grid = grid_of(domain, 0.5, h, Grid::Hcp);
        let (bottom, top) = (0.6 * 0.5, 0.5);
        let mut interior = 0;
        for (a, p) in grid.iter().enumerate() {
            let distances: Vec<f64> = grid
                .iter()
                .enumerate()
                .filter(|&(b, _)| b != a)
                .map(|(_, q)| domain.nearest_distance2(p, q).sqrt())
                .collect();
            let nearest = distances.iter().fold(f64::INFINITY, |m, &d| m.min(d));
            assert!(nearest >= h * (1.0 - 1e-12), "{p}: a position {nearest} m away");
            let away = |u: f64| (2.0 * h..=l - 2.0 * h).contains(&u);
            if away(p.x) && away(p.y) && p.z > bottom + 2.0 * h && p.z < top - 2.0 * h {
                interior += 1;
                let at_h = distances.iter().filter(|&&d| (d - h).abs() < 1e-12).count();
                assert_eq!(at_h, 12, "{p}");
            }
        }
        assert!(interior > 100, "{interior} interior positions");
    }

    /// A grain that no turn fits into the domain is an error naming the grain, not a set that
    /// waits for it forever: ellipsoids of 0.1–0.11 m with FL = EL = 0.9 need at least I/2 ≥
    /// 52.6 mm around their centre, more than the 52 mm radius of the 0.104 m cylinder, even on
    /// its axis (the one position of a grid of spacing 0.1 m).
    #[test]
    fn a_grain_too_wide_for_the_cylinder_in_any_turn_is_an_error() {
        let mut spec = PackingSpec::paper(DomainKind::Cylinder);
        spec.grains.size = crate::grain::SieveCurve::new(vec![0.1, 0.11], vec![1.0]).unwrap();
        spec.process.spacing = Some(0.1);
        spec.grains.form = FormSpec::Single { fl: 0.9, el: 0.9 };
        let mut packing = Packing::new(spec).unwrap();
        let error = packing.generate_set().unwrap_err();
        assert!(matches!(error, PackingError::NoRoom { radius, .. } if radius > 0.052), "{error}");
        assert!(error.to_string().contains("in any of 32 random orientations"), "{error}");
    }
}
