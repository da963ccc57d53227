//! Standard settled beds, the yardstick of the engine's speed (`sedpack bench`, the criterion
//! benchmarks): grains poured from a lattice into a horizontally periodic box and left to settle.
//!
//! * spheres: the LAMMPS comparison bed of `peers/lammps/pour_settle.in`: d = 6.7 mm on a
//!   lattice of 7 × 7 per 0.05 m and 10 mm between layers (2,450 spheres in 50 layers by
//!   default), velocities uniform in ±0.2 m/s with zero net momentum, poured for 0.5 s, then
//!   left until the translational v_rms falls below 1e-4 m/s (checked every 0.05 s), with a 1 mm
//!   skin, as LAMMPS does;
//! * ellipsoids and bonded spheres of the Rhine form distribution (Table 2), polyhedra of the two
//!   Rhine scans with their own forms (§5.1), all in the 5.6–8 mm sieve class: dropped at 1 m/s
//!   (as the generation of §4.3) from a lattice whose layers are spaced for the longest grain
//!   they hold, in a box 8 to 10 typical grains wide, poured until every grain has landed (none moves
//!   faster than 0.1 m/s), then damped (Eq. 15) until ⟨z⟩ changes by less than 1e-5 m over 0.01 s (§4.3).
//!
//! [`rain`] adds to a bed one lattice layer of new grains of its kind, falling at 1 m/s onto it
//! from just above: the raining state of `sedpack bench`, in which a packing spends most of its
//! generation.
//!
//! The material and time step are the paper's (§4.2).

use std::iter::Peekable;
use std::sync::Arc;

use nalgebra::{UnitQuaternion, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::SolverError;
use crate::dem::shape::{ConvexPolyhedron, Polyhedron};
use crate::dem::{Calibration, ContactPoint, Domain, Material, NewBody, Settings, Shape, Simulation, uniform_rotation};
use crate::grain::{
    FormParameters, FormSampler, RHINE_FORMS, SieveCurve, SizeSampler, UnitMesh, bonded_grain, rhine_meshes, simplify,
};
use crate::packing::ShapeKind;

/// Diameter of the LAMMPS bed's spheres (m).
pub const SPHERE_DIAMETER: f64 = 6.7e-3;
/// Lattice of the LAMMPS bed: 7 sites per 0.05 m row, layers 10 mm apart.
const SPHERE_ROW: usize = 7;
const SPHERE_SITE: f64 = 0.05 / 7.0;
const SPHERE_LAYER: f64 = 0.010;
/// The sieve class of the other beds (m).
const CLASS: [f64; 2] = [5.6e-3, 8e-3];

/// Which bed: its grains' shape, how many, and the seed of the random draws.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BedSpec {
    pub shape: ShapeKind,
    pub grains: usize,
    pub seed: u64,
}

impl BedSpec {
    /// The standard bed of a shape: the LAMMPS bed for spheres, 2,000 grains otherwise.
    pub fn standard(shape: ShapeKind) -> Self {
        let grains = if shape == ShapeKind::Sphere { SPHERE_ROW * SPHERE_ROW * 50 } else { 2000 };
        Self { shape, grains, seed: 12345 }
    }

    /// A name for files and tables.
    pub fn name(&self) -> String {
        let shape = match self.shape {
            ShapeKind::Sphere => "spheres",
            ShapeKind::Ellipsoid => "ellipsoids",
            ShapeKind::Mesh => "polyhedra",
            ShapeKind::BondedSpheres => "bonded-spheres",
        };
        format!("{shape}-{}-seed{}", self.grains, self.seed)
    }
}

/// The paper's material and time step (§4.2) with the given skin.
pub fn settings(skin: f64) -> Settings {
    Settings {
        material: Material::default(),
        time_step: 5e-6,
        skin,
        calibration: Calibration::Discrete,
        contact_point: ContactPoint::CentreOfPressure,
    }
}

/// Where a bed's preparation stands, for progress displays.
#[derive(Debug, Clone, Copy)]
pub struct BedProgress {
    pub phase: &'static str,
    pub time: f64,
    pub grains: usize,
    pub contacts: usize,
}

/// Builds the settled bed of `spec`, reporting progress every 2,000 steps. The result is at
/// rest, with neither shaking nor damping on.
pub fn build(spec: &BedSpec, progress: &mut dyn FnMut(BedProgress)) -> Result<Simulation, SolverError> {
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let mut sim = match spec.shape {
        ShapeKind::Sphere => sphere_lattice(spec.grains, &mut rng)?,
        _ => grain_lattice(spec, &mut rng)?,
    };
    let report = |sim: &Simulation, phase| BedProgress {
        phase,
        time: sim.time,
        grains: sim.bodies.len(),
        contacts: sim.contacts,
    };
    if spec.shape == ShapeKind::Sphere {
        // pour_settle.in: 0.5 s of pouring, then 0.05 s runs until v_rms < 1e-4 m/s (at most 3 s).
        advance(&mut sim, 0.5, "pouring", progress, &report)?;
        for _ in 0..60 {
            advance(&mut sim, 0.05, "settling", progress, &report)?;
            if translational_rms(&sim) < 1e-4 {
                break;
            }
        }
    } else {
        // Pour until every grain has landed (none moves faster than 0.1 m/s), then damp
        // (Eq. 15) until ⟨z⟩ settles (§4.3).
        while sim.bodies.velocity.iter().any(|v| v.norm() > 0.1) {
            advance(&mut sim, 0.01, "pouring", progress, &report)?;
        }
        sim.damping = Some(1e-3);
        let mut last = sim.mean_height();
        loop {
            advance(&mut sim, 0.01, "settling", progress, &report)?;
            let height = sim.mean_height();
            if (height - last).abs() < 1e-5 {
                break;
            }
            last = height;
        }
        sim.damping = None;
    }
    for (v, w) in sim.bodies.velocity.iter_mut().zip(sim.bodies.angular_velocity.iter_mut()) {
        *v = Vector3::zeros();
        *w = Vector3::zeros();
    }
    Ok(sim)
}

fn advance(
    sim: &mut Simulation,
    duration: f64,
    phase: &'static str,
    progress: &mut dyn FnMut(BedProgress),
    report: &dyn Fn(&Simulation, &'static str) -> BedProgress,
) -> Result<(), SolverError> {
    let steps = (duration / sim.settings.time_step).round() as u64;
    for k in 0..steps {
        sim.step()?;
        if k % 2000 == 0 {
            progress(report(sim, phase));
        }
    }
    Ok(())
}

fn translational_rms(sim: &Simulation) -> f64 {
    let b = &sim.bodies;
    (b.velocity.iter().map(|v| v.norm_squared()).sum::<f64>() / b.len() as f64).sqrt()
}

/// The LAMMPS lattice: `grains` spheres in rows of 7 per 0.05 m (more rows for larger beds, so
/// that the column stays 50 layers high), velocities in ±0.2 m/s without net momentum.
fn sphere_lattice(grains: usize, rng: &mut ChaCha8Rng) -> Result<Simulation, SolverError> {
    let per_row = ((grains as f64 / 50.0).sqrt().round() as usize).max(3);
    let width = per_row as f64 * SPHERE_SITE;
    let mut sim = Simulation::new(Domain::Periodic { width }, settings(1e-3))?;
    let mut velocities = Vec::with_capacity(grains);
    for k in 0..grains {
        let (i, j, layer) = (k % per_row, k / per_row % per_row, k / (per_row * per_row));
        let mut v = || rng.random_range(-0.2..0.2);
        velocities.push(Vector3::new(v(), v(), v()));
        let position = Vector3::new(
            (i as f64 + 0.5) * SPHERE_SITE,
            (j as f64 + 0.5) * SPHERE_SITE,
            (layer as f64 + 0.5) * SPHERE_LAYER,
        );
        sim.add_body(NewBody {
            shape: Shape::Sphere { radius: SPHERE_DIAMETER / 2.0 },
            position,
            orientation: UnitQuaternion::identity(),
            velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
        });
    }
    // `velocity all zero linear`: equal masses, so subtract the mean.
    let mean = velocities.iter().sum::<Vector3<f64>>() / grains as f64;
    for (body, v) in sim.bodies.velocity.iter_mut().zip(&velocities) {
        *body = v - mean;
    }
    Ok(sim)
}

/// Draws grains of a bed's kind, as its lattice drew them: spheres of the LAMMPS bed, the others
/// of the 5.6–8 mm class.
struct GrainDraw {
    kind: ShapeKind,
    sizes: SizeSampler,
    forms: FormSampler,
    /// The Rhine scans simplified to ≤ 300 faces, and their own forms.
    bases: Vec<Arc<ConvexPolyhedron>>,
    own: Vec<FormParameters>,
}

impl GrainDraw {
    fn new(kind: ShapeKind) -> Self {
        let bases = match kind {
            ShapeKind::Mesh => rhine_meshes()
                .iter()
                .map(|(_, m)| {
                    let unit =
                        UnitMesh::new(&simplify(m, 300).expect("the Rhine scans simplify").mesh).expect("unit form");
                    Arc::new(ConvexPolyhedron::new(unit.mesh()).expect("the Rhine scans are convex"))
                })
                .collect(),
            _ => Vec::new(),
        };
        Self {
            kind,
            sizes: SieveCurve::new(CLASS.to_vec(), vec![1.0]).expect("one class").sampler(),
            forms: RHINE_FORMS.sampler().expect("Table 2's distribution lies in the admissible ranges"),
            bases,
            own: rhine_meshes().iter().map(|(_, m)| UnitMesh::new(m).expect("unit form").original_form()).collect(),
        }
    }

    fn draw(&self, rng: &mut ChaCha8Rng) -> Shape {
        let (_, size) = self.sizes.sample(rng);
        match self.kind {
            ShapeKind::Mesh => {
                let k = rng.random_range(0..self.bases.len());
                let form = self.own[k].scaled_to_size(size);
                Shape::Polyhedron(Box::new(
                    Polyhedron::with_form(self.bases[k].clone(), &form).expect("a valid stretch"),
                ))
            }
            ShapeKind::Ellipsoid => {
                let form = self.forms.sample(size, rng);
                Shape::Ellipsoid { semi_axes: Vector3::new(form.l, form.i, form.s) / 2.0 }
            }
            ShapeKind::BondedSpheres => {
                Shape::from(&bonded_grain(&self.forms.sample(size, rng)).expect("sampled forms are valid"))
            }
            ShapeKind::Sphere => Shape::Sphere { radius: SPHERE_DIAMETER / 2.0 },
        }
    }
}

/// Takes the grains of one lattice layer from `shapes`: as many as its sites hold, spaced for
/// the longest grain taken, so that a few long grains of the distribution's tail do not spread a
/// whole bed thin. Returns them with the spacing.
fn next_layer(shapes: &mut Peekable<impl Iterator<Item = Shape>>, width: f64) -> (Vec<Shape>, f64) {
    let mut layer: Vec<Shape> = Vec::new();
    let mut spacing = 0.0f64;
    while let Some(next) = shapes.peek() {
        let wider = spacing.max(2.1 * next.bounding_radius());
        let sites = ((width / wider).floor() as usize).max(1).pow(2);
        if layer.len() >= sites {
            break;
        }
        spacing = wider;
        layer.push(shapes.next().expect("peeked"));
    }
    (layer, spacing)
}

/// Places a layer on its sites, each at the height `height` gives for it (at its site, as turned),
/// turned at random and falling at 1 m/s (the generation's speed of new grains, §4.3), with
/// a little sideways speed and spin.
fn place_layer(
    sim: &mut Simulation,
    layer: Vec<Shape>,
    spacing: f64,
    height: &dyn Fn(&Simulation, &NewBody) -> f64,
    rng: &mut ChaCha8Rng,
) {
    let row = ((sim.domain.width() / spacing).floor() as usize).max(1);
    for (k, shape) in layer.into_iter().enumerate() {
        let (x, y) = ((k % row) as f64 * spacing + spacing / 2.0, (k / row) as f64 * spacing + spacing / 2.0);
        let mut spin = || rng.random_range(-0.1..0.1);
        let velocity = Vector3::new(spin(), spin(), -1.0);
        let angular_velocity = Vector3::new(spin(), spin(), spin()) / spacing;
        let orientation = uniform_rotation(rng);
        let mut body = NewBody { shape, position: Vector3::new(x, y, 0.0), orientation, velocity, angular_velocity };
        body.position.z = height(sim, &body);
        sim.add_body(body);
    }
}

/// Grains of the 5.6–8 mm class on a lattice as wide as their largest reach, falling at 1 m/s.
fn grain_lattice(spec: &BedSpec, rng: &mut ChaCha8Rng) -> Result<Simulation, SolverError> {
    let draw = GrainDraw::new(spec.shape);
    let shapes: Vec<Shape> = (0..spec.grains).map(|_| draw.draw(rng)).collect();
    // The box is as wide as 8 to 10 typical grains (each row of sites 2.1 median reaches
    // apart), or wider if a long grain needs it.
    let mut reaches: Vec<f64> = shapes.iter().map(Shape::bounding_radius).collect();
    let longest = reaches.iter().cloned().fold(0.0, f64::max);
    reaches.sort_by(f64::total_cmp);
    let typical = 2.1 * reaches[reaches.len() / 2];
    let per_row = ((spec.grains as f64 / 30.0).sqrt().round() as usize).max(3);
    let skin = 0.15 * CLASS[0];
    let width = (per_row as f64 * typical).max(2.2 * longest + skin);
    let mut sim = Simulation::new(Domain::Periodic { width }, settings(skin))?;
    let mut shapes = shapes.into_iter().peekable();
    let mut z = 0.0;
    while shapes.peek().is_some() {
        let (layer, spacing) = next_layer(&mut shapes, width);
        z += spacing / 2.0;
        place_layer(&mut sim, layer, spacing, &|_, _| z, rng);
        z += spacing / 2.0;
    }
    Ok(sim)
}

/// Gap between a grain [`rain`] adds and the highest grain of the bed below it (m).
pub const RAIN_GAP: f64 = 2e-3;

/// Adds one lattice layer of new grains of `spec`'s kind above `bed`, the state a packing spends
/// most of its generation in (§4.3): drawn as the bed's grains were (from a stream of their own),
/// on sites spaced for the longest of them, turned at random and falling at 1 m/s, each with its
/// lowest point [`RAIN_GAP`] above the highest point of the bed's grains whose bounding spheres
/// its own could meet on the way down, so that they land within the first few milliseconds.
/// Returns how many were added.
pub fn rain(spec: &BedSpec, bed: &mut Simulation) -> usize {
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    rng.set_stream(1);
    let draw = GrainDraw::new(spec.shape);
    let old = bed.bodies.len();
    let (layer, spacing) =
        next_layer(&mut std::iter::repeat_with(|| draw.draw(&mut rng)).peekable(), bed.domain.width());
    let added = layer.len();
    let height = |sim: &Simulation, new: &NewBody| {
        let (b, domain) = (&sim.bodies, &sim.domain);
        let below = (0..old)
            .filter(|&k| {
                let image = b.position[k] + domain.shift(domain.nearest_image(&new.position, &b.position[k]));
                let apart = image - new.position;
                apart.x.hypot(apart.y) < b.bounding_radius[k] + new.shape.bounding_radius()
            })
            .map(|k| b.position[k].z + b.shape[k].reach_along(&b.orientation[k], &Vector3::z()))
            .fold(0.0, f64::max);
        below + RAIN_GAP + new.shape.reach_along(&new.orientation, &-Vector3::z())
    };
    place_layer(bed, layer, spacing, &height, &mut rng);
    added
}
