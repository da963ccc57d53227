//! What a packing is: the paper's setup for a domain kind (§4.2 material, §4.3 process, §4.4
//! evaluation; the cylinder of §5.1 or the periodic square of §6.2; Table 3's U1 and Table 2's
//! Rhine forms) as a job changes it, the values the paper derives from the others, and the
//! checks that every value is one the protocol can run with. Errors name the job file's dotted
//! key, so a caller can point at the line.

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::dem::{Calibration, ContactPoint, Domain, MIN_STEPS_PER_COLLISION, Material, Shaking};
use crate::fluid::flow::Flow;
use crate::fluid::{Fluid, WATER};
use crate::grain::{FormDistribution, MeshLibrary, RHINE_FORMS, SieveCurve, TABLE3};

/// The two domains of §4.1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DomainKind {
    Periodic,
    Cylinder,
}

/// The shape family of the grains.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ShapeKind {
    Sphere,
    Ellipsoid,
    /// The bonded-sphere grain of Sun & Xiao (§2.4) built for each grain's L, I, S.
    BondedSpheres,
    /// A convex polyhedron: a mesh of the library rescaled to the grain's L, I, S (Fig. 5).
    Mesh,
}

/// How each grain's form is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum FormSpec {
    /// One flatness and elongation for every grain.
    Single { fl: f64, el: f64 },
    /// FL and EL drawn per grain (§7.1).
    Distribution(FormDistribution),
    /// Each mesh keeps its own form, scaled to the grain's size (§5.1).
    Own,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GrainSpec {
    pub shape: ShapeKind,
    pub size: SieveCurve,
    /// Total mass generated, m_tot (kg).
    pub mass: f64,
    pub form: FormSpec,
    /// The meshes of `ShapeKind::Mesh`, drawn from uniformly (§3.2).
    pub meshes: Option<MeshLibrary>,
}

/// Fluid drag and lift during the whole protocol (the second paper's §2.3), in a prescribed
/// flow; the fluid's density is the material's `fluid_density`, which buoyancy uses too.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FluidSpec {
    /// Dynamic viscosity μ (Pa·s).
    pub viscosity: f64,
    pub flow: Flow,
    /// Saffman lift (Eq. 8).
    pub lift: bool,
    /// Cell side of the fluid-fraction grid (m); None: three times the largest sieve in use.
    pub cell: Option<f64>,
    /// Simulated time between updates of the fluid forces (s), the fluid time step of a
    /// CFD–DEM code; None: [`FLUID_COUPLING`].
    pub coupling: Option<f64>,
}

/// The default time between updates of the fluid forces: 1e-4 s, 20 of the paper's time steps
/// of 5 µs. Over it a grain at 1 m/s moves 0.1 mm and its drag coefficient barely changes; in
/// between, each grain's drag follows its velocity every step (see [`crate::fluid`]).
pub const FLUID_COUPLING: f64 = 1e-4;

impl FluidSpec {
    /// Still water at 20 °C (viscosity), with lift, cells of three grain sizes.
    pub const STILL_WATER: Self =
        Self { viscosity: WATER.viscosity, flow: Flow::Quiescent, lift: true, cell: None, coupling: None };
}

/// How a grain lies when it is created; §4.3 does not say.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Orientation {
    /// Turned uniformly at random, each grain on its own (sedpack's).
    Random,
    /// Every grain alike, its longest axis L vertical and its shortest S along x: how the
    /// paper's software creates them (waLBerla's `ParticlePacking` keeps a scan as its file lies,
    /// long axis along z, and sorts a drawn form's axes so).
    Upright,
}

/// The grid new grains are created on, spacing h_g (§4.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Grid {
    /// The text's "hexahedral grid": cubic, centred in the domain (sedpack's).
    Cubic,
    /// Hexagonal close-packed, laid out from the domain's axis as the paper's software lays
    /// its grid (waLBerla's `HCPGrid`): nearest positions h_g apart as on the cubic grid, but
    /// rows √3/2 h_g and layers √(2/3) h_g apart, so more of them in the same region.
    Hcp,
}

/// Process parameters of §4.3 (generation, shaking, damping, convergence).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Process {
    /// Grid spacing h_g of the generation (m); None: Table 3's h_g for a named size case, else
    /// the largest sieve in use.
    pub spacing: Option<f64>,
    /// Initial speed u_p^init (m/s).
    pub velocity: f64,
    /// How each new grain is turned.
    pub orientation: Orientation,
    /// The grid of the generation region.
    pub grid: Grid,
    pub shaking: Shaking,
    /// Shaking continues this long after the last grain was created, t_s (s).
    pub shaking_duration: f64,
    /// Damping coefficient c_d of Eq. 15.
    pub damping: f64,
    /// Converged once ⟨z⟩ changes by less than this (m) …
    pub height_change: f64,
    /// … over this interval (s).
    pub interval: f64,
    /// The packing fails if not converged by this simulated time (s); None: the shaking
    /// duration plus 60 s.
    pub max_time: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PackingSpec {
    pub domain: Domain,
    /// Domain height H (m); grains are created in [0.6, 1]·H. None: the generation region
    /// clears the bed expected at porosity 0.4 by two grid spacings.
    pub height: Option<f64>,
    pub grains: GrainSpec,
    pub material: Material,
    pub time_step: f64,
    pub calibration: Calibration,
    /// Where the force of a contact with a polyhedron acts.
    pub contact_point: ContactPoint,
    pub process: Process,
    /// Slice height, cut-off porosity and trim of §4.4; a trim of None means the paper's
    /// choice: the largest sieve (periodic domain), 0 (cylinder).
    pub slice: f64,
    pub cutoff: f64,
    pub trim: Option<f64>,
    pub seed: u64,
    /// Fluid forces; None in the paper's protocol, whose grains settle "as if submerged", with
    /// buoyancy alone (§4.2).
    pub fluid: Option<FluidSpec>,
}

/// The values of a packing that the paper derives from the others, as the protocol uses them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Derived {
    /// h_g (m).
    pub spacing: f64,
    /// H (m).
    pub height: f64,
    /// s of simulated time.
    pub max_time: f64,
    /// m cut away at both ends of the bulk porosity's range.
    pub trim: f64,
    /// Verlet skin of the neighbour list (m).
    pub skin: f64,
    /// Cell side of the fluid-fraction grid (m).
    pub fluid_cell: f64,
    /// Simulated time between updates of the fluid forces (s).
    pub fluid_coupling: f64,
}

/// A value no packing can run with: the job file's dotted key and what was expected.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("{key}: {message}")]
pub struct SpecError {
    pub key: &'static str,
    pub message: String,
}

/// `value` if `ok` and finite, else an error saying it is out of range and what was expected.
pub fn in_range(key: &'static str, value: f64, ok: bool, expected: &str) -> Result<f64, SpecError> {
    if ok && value.is_finite() {
        Ok(value)
    } else {
        Err(SpecError { key, message: format!("{value} is out of range: expected {expected}") })
    }
}

fn positive(key: &'static str, value: f64) -> Result<f64, SpecError> {
    in_range(key, value, value > 0.0, "a number > 0")
}

impl PackingSpec {
    /// The paper's setup in a domain of this kind: U1 grains of the Rhine forms as ellipsoids,
    /// the material of §4.2, the protocol of §4.3 and the evaluation of §4.4, in the cylinder of
    /// §5.1 (L = 0.104 m, 3 kg, t_s = 1 s) or the periodic square of §6.2 (L = 0.2 m, 16 kg,
    /// t_s = 6 s), seed 1; height, spacing, time limit and trim follow the paper's rules.
    pub fn paper(kind: DomainKind) -> Self {
        let (domain, mass, shaking_duration) = match kind {
            DomainKind::Periodic => (Domain::Periodic { width: 0.2 }, 16.0, 6.0),
            DomainKind::Cylinder => (Domain::Cylinder { diameter: 0.104 }, 3.0, 1.0),
        };
        Self {
            domain,
            height: None,
            grains: GrainSpec {
                shape: ShapeKind::Ellipsoid,
                size: TABLE3[0].sieve_curve(),
                mass,
                form: FormSpec::Distribution(RHINE_FORMS),
                meshes: None,
            },
            material: Material::default(),
            time_step: 5e-6,
            calibration: Calibration::Discrete,
            contact_point: ContactPoint::CentreOfPressure,
            process: Process {
                spacing: None,
                velocity: 1.0,
                orientation: Orientation::Random,
                grid: Grid::Cubic,
                shaking: Shaking { amplitude: 3e-4, period: 0.025 },
                shaking_duration,
                damping: 1e-3,
                height_change: 1e-5,
                interval: 0.01,
                max_time: None,
            },
            slice: 1e-3,
            cutoff: 0.5,
            trim: None,
            seed: 1,
            fluid: None,
        }
    }

    /// Height of the finished bed (m) if its porosity is 0.4: the grains' volume over
    /// (1 − 0.4) times the cross-section.
    pub fn expected_bed_height(&self) -> f64 {
        self.grains.mass / (self.material.density * self.domain.cross_section() * 0.6)
    }

    /// The values this spec leaves to the paper's rules, worked out from the others.
    pub fn derived(&self) -> Derived {
        let size = &self.grains.size;
        let spacing = self.process.spacing.unwrap_or_else(|| size.case().map_or(size.largest_in_use(), |c| c.spacing));
        // The generation region [0.6, 1]·H must clear the finished bed by two grid spacings, so
        // that sets can always leave it.
        let bed = self.expected_bed_height();
        let height = self.height.unwrap_or_else(|| ((bed + 2.0 * spacing) / 0.6 * 100.0).ceil() / 100.0);
        // Generation plus settling rarely takes more than a minute of simulated time.
        let max_time = self.process.max_time.unwrap_or(self.process.shaking_duration + 60.0);
        let trim = self.trim.unwrap_or(match self.domain {
            Domain::Periodic { .. } => size.largest_sieve(),
            Domain::Cylinder { .. } => 0.0,
        });
        // A skin of 15 % of the smallest grain keeps neighbour lists for ~100 steps at 1 m/s.
        let skin = 0.15 * size.smallest_in_use();
        // CFD–DEM averages over cells of a few grains (Sun & Xiao's sediment-transport runs: 1.2
        // nominal diameters across, their settling runs one).
        let fluid_cell = self.fluid.and_then(|f| f.cell).unwrap_or(3.0 * size.largest_in_use());
        let fluid_coupling = self.fluid.and_then(|f| f.coupling).unwrap_or(FLUID_COUPLING);
        Derived { spacing, height, max_time, trim, skin, fluid_cell, fluid_coupling }
    }

    /// The fluid forces of the engine for this spec, if on.
    pub fn fluid_forces(&self) -> Option<Fluid> {
        let fluid = self.fluid?;
        let derived = self.derived();
        Some(Fluid {
            viscosity: fluid.viscosity,
            flow: fluid.flow,
            lift: fluid.lift,
            cell: derived.fluid_cell,
            slice: self.slice,
            cutoff: self.cutoff,
            coupling: (derived.fluid_coupling / self.time_step).round().max(1.0) as u32,
        })
    }

    /// Checks every value, in the order of the job file's sections.
    pub fn check(&self) -> Result<(), SpecError> {
        positive("domain.width", self.domain.width())?;
        self.check_grains()?;
        self.check_material()?;
        let dt = positive("solver.time_step", self.time_step)?;
        in_range(
            "solver.time_step",
            dt,
            self.material.collision_time / dt >= MIN_STEPS_PER_COLLISION,
            "at most material.collision_time / 10 (the paper resolves a collision in 40 steps)",
        )?;
        self.check_process()?;
        if let Some(h) = self.height {
            positive("domain.height", h)?;
        }
        if let Some(t) = self.process.max_time {
            positive("solver.max_time", t)?;
        }
        positive("evaluation.slice", self.slice)?;
        in_range("evaluation.cutoff", self.cutoff, self.cutoff > 0.0 && self.cutoff < 1.0, "a porosity in (0, 1)")?;
        if let Some(t) = self.trim {
            in_range("evaluation.trim", t, t >= 0.0, "a height ≥ 0")?;
        }
        if let Some(fluid) = &self.fluid {
            self.check_fluid(fluid)?;
        }
        Ok(())
    }

    fn check_fluid(&self, fluid: &FluidSpec) -> Result<(), SpecError> {
        positive("fluid.viscosity", fluid.viscosity)?;
        if let Some(h) = fluid.cell {
            let largest = self.grains.size.largest_in_use();
            in_range(
                "fluid.cell",
                h,
                h >= largest,
                &format!("at least the largest sieve in use, {largest} m (cells average over several grains)"),
            )?;
        }
        if let Some(t) = fluid.coupling {
            in_range("fluid.coupling", t, t >= self.time_step, "a time ≥ solver.time_step (s)")?;
        }
        match fluid.flow {
            Flow::Quiescent => {}
            Flow::Uniform { velocity } => {
                in_range("fluid.flow.velocity", velocity.norm(), true, "finite components (m/s)")?;
            }
            Flow::Laminar { shear_velocity, depth } => {
                in_range("fluid.flow.shear_velocity", shear_velocity, shear_velocity >= 0.0, "a speed ≥ 0")?;
                positive("fluid.flow.depth", depth)?;
            }
            Flow::Logarithmic { shear_velocity, roughness } => {
                in_range("fluid.flow.shear_velocity", shear_velocity, shear_velocity >= 0.0, "a speed ≥ 0")?;
                positive("fluid.flow.roughness", roughness)?;
            }
        }
        Ok(())
    }

    fn check_grains(&self) -> Result<(), SpecError> {
        let g = &self.grains;
        positive("grains.mass", g.mass)?;
        match (g.shape, &g.meshes) {
            (ShapeKind::Mesh, None) => {
                return Err(SpecError { key: "grains.meshes", message: "a mesh packing needs a mesh library".into() });
            }
            (ShapeKind::Mesh, Some(_)) | (_, None) => {}
            (_, Some(_)) => {
                return Err(SpecError { key: "grains.meshes", message: "applies to grains.shape: mesh only".into() });
            }
        }
        match g.form {
            FormSpec::Single { fl, el } => {
                in_range("grains.form.fl", fl, fl > 0.0 && fl <= 1.0, "a flatness in (0, 1]")?;
                in_range("grains.form.el", el, el > 0.0 && el <= 1.0, "an elongation in (0, 1]")?;
            }
            FormSpec::Distribution(d) => {
                d.sampler().map_err(|e| SpecError { key: "grains.form", message: e.to_string() })?;
            }
            FormSpec::Own if g.shape != ShapeKind::Mesh => {
                return Err(SpecError {
                    key: "grains.form",
                    message: "`mesh` (each mesh's own form) needs grains.shape: mesh".into(),
                });
            }
            FormSpec::Own => {}
        }
        Ok(())
    }

    fn check_material(&self) -> Result<(), SpecError> {
        let m = &self.material;
        positive("material.density", m.density)?;
        let g = m.gravity;
        in_range("material.gravity", -g.z, g.x == 0.0 && g.y == 0.0, "gravity along −z, (0, 0, −g)")?;
        positive("material.gravity", -g.z)?;
        positive("material.collision_time", m.collision_time)?;
        let f = m.fluid_density;
        in_range(
            "material.fluid_density",
            f,
            f >= 0.0 && f < m.density,
            "≥ 0 and below material.density (grains must sink)",
        )?;
        let e = m.restitution;
        in_range("material.restitution", e, e > 0.0 && e <= 1.0, "a coefficient in (0, 1]")?;
        let nu = m.poisson_ratio;
        in_range("material.poisson_ratio", nu, (0.0..=0.5).contains(&nu), "a ratio in [0, 0.5]")?;
        in_range("material.friction", m.friction, m.friction >= 0.0, "a coefficient ≥ 0")?;
        Ok(())
    }

    fn check_process(&self) -> Result<(), SpecError> {
        let p = &self.process;
        if let Some(h) = p.spacing {
            let smallest = self.grains.size.smallest_in_use();
            in_range(
                "process.generation.spacing",
                h,
                h >= smallest,
                &format!("at least the smallest sieve in use, {smallest} m (a grid slot holds a grain)"),
            )?;
        }
        in_range("process.generation.velocity", p.velocity, p.velocity >= 0.0, "a speed ≥ 0")?;
        let a = p.shaking.amplitude;
        in_range("process.shaking.amplitude", a, a >= 0.0, "an amplitude ≥ 0")?;
        positive("process.shaking.period", p.shaking.period)?;
        let t = p.shaking_duration;
        in_range("process.shaking.duration", t, t >= 0.0, "a duration ≥ 0")?;
        let c = p.damping;
        in_range("process.damping", c, c > 0.0 && c <= 1.0, "a factor c_d in (0, 1]")?;
        positive("process.convergence.height_change", p.height_change)?;
        in_range(
            "process.convergence.interval",
            p.interval,
            p.interval >= self.time_step,
            "an interval ≥ solver.time_step",
        )?;
        Ok(())
    }
}
