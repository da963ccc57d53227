//! The packing protocol of §4.3: grains created layer by layer on a hexahedral grid in the upper
//! part of the domain, shaken horizontally (Eq. 14) from the start until t_s after the last
//! creation, then damped (Eq. 15) until the mass-averaged height settles; finally the porosity of
//! §4.4. What a packing is, with the paper's defaults and rules, is `PackingSpec` (spec.rs).

mod spec;

pub use spec::{
    Derived, DomainKind, FLUID_COUPLING, FluidSpec, FormSpec, GrainSpec, PackingSpec, Process, ShapeKind, SpecError,
    in_range,
};

use std::sync::Arc;
use std::time::{Duration, Instant};

use nalgebra::Vector3;
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
    FormParameters, FormSampler, FormStatistic, MeshLibrary, SizeSampler, bonded_grain, form_statistics,
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
}

/// One created grain as sampled: its sieve class, size D and form.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GrainRecord {
    pub class: usize,
    pub size: f64,
    pub form: FormParameters,
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
                    if self.created_mass >= self.spec.grains.mass {
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

    /// Fills the generation grid with new grains until the target mass is reached. A position
    /// where the new grain would overlap one created before is left empty for this set.
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
        let u = spec.process.velocity;
        self.set_start = self.simulation.bodies.len();
        for &position in &self.grid {
            if self.created_mass >= spec.grains.mass {
                break;
            }
            let (class, size) = sizes.sample(&mut self.rng);
            let drawn = (spec.grains.shape == ShapeKind::Mesh).then(|| self.rng.random_range(0..meshes.len()));
            let mesh = drawn.map(|k| &meshes[k]);
            let form = match (spec.grains.shape, spec.grains.form, &forms) {
                (ShapeKind::Sphere, ..) => FormParameters { l: size, i: size, s: size },
                (_, FormSpec::Single { fl, el }, _) => FormParameters::from_flatness_elongation(fl, el, size),
                (_, FormSpec::Own, _) => match mesh {
                    Some(unit) => unit.original_form().scaled_to_size(size),
                    None => return Err(PackingError::Meshes("a mesh's own form needs grains.shape: mesh".into())),
                },
                (_, _, Some(sampler)) => sampler.sample(size, &mut self.rng),
                (_, FormSpec::Distribution(_), None) => unreachable!("a distribution always has a sampler"),
            };
            let shape = match (spec.grains.shape, mesh) {
                (ShapeKind::Sphere, _) => Shape::Sphere { radius: size / 2.0 },
                (ShapeKind::Ellipsoid, _) => Shape::Ellipsoid { semi_axes: Vector3::new(form.l, form.i, form.s) / 2.0 },
                (ShapeKind::BondedSpheres, _) => {
                    Shape::from(&bonded_grain(&form).map_err(|e| PackingError::Form(e.to_string()))?)
                }
                (ShapeKind::Mesh, Some(_)) => {
                    let base = self.bases[drawn.expect("a mesh was drawn")].clone();
                    let grain = Polyhedron::with_form(base, &form).map_err(|e| PackingError::Meshes(e.to_string()))?;
                    Shape::Polyhedron(Box::new(grain))
                }
                (ShapeKind::Mesh, None) => unreachable!("a mesh was drawn for a mesh packing"),
            };
            let orientation = uniform_rotation(&mut self.rng);
            let mut spin = || self.rng.random_range(-0.1..0.1) * u;
            let velocity = Vector3::new(spin(), spin(), -u);
            let angular_velocity = Vector3::new(spin(), spin(), spin()) / size;
            if !spec.domain.holds(position.x, position.y, shape.bounding_radius()) {
                continue;
            }
            let body = NewBody { shape, position, orientation, velocity, angular_velocity };
            if self.overlaps_existing(&body) {
                continue;
            }
            let volume = body.shape.volume();
            self.simulation.add_body(body);
            self.created_mass += spec.material.density * volume;
            self.grains.push(GrainRecord { class, size, form });
        }
        Ok(())
    }

    fn overlaps_existing(&self, body: &NewBody) -> bool {
        let b = &self.simulation.bodies;
        let r = body.shape.bounding_radius();
        (0..b.len()).any(|k| {
            let shift = self.spec.domain.shift(self.spec.domain.nearest_image(&body.position, &b.position[k]));
            let other = b.position[k] + shift;
            (other - body.position).norm() < r + b.bounding_radius[k]
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
        })
    }
}

/// Grid positions of the generation region z ∈ [0.6, 1]·H, spacing h_g, centred horizontally.
fn generation_grid(spec: &PackingSpec, derived: &Derived) -> Vec<Vector3<f64>> {
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
