//! Resolution of a parsed job file into a checked job: the solver's paper setup for the file's
//! domain kind (`PackingSpec::paper`), changed section by section where the file says, then
//! checked as a whole. Errors name the file, the line and the dotted key.

use std::path::Path;

use analysis::Experiment;
use nalgebra::Vector3;
use solver::dem::{Calibration, ContactPoint, Domain, Material};
use solver::fluid::flow::Flow;
use solver::grain::simplify::DEFAULT_MAX_FACES;
use solver::grain::{FormDistribution, SieveCurve, Table3Case};
use solver::packing::{
    DomainKind, FluidSpec, FormSpec, Grid, Orientation, PackingSpec, Process, ShapeKind, SpecError, in_range,
};

use crate::job_file::{
    CalibrationFile, ContactPointFile, DomainFile, DomainKindFile, EvaluationFile, ExperimentFile, FlowFile,
    FlowKindFile, FluidFile, FormFile, GrainsFile, GridFile, JobFile, MaterialFile, OrientationFile, ProcessFile,
    ProcessFluidFile, ShapeFile, SizeFile, SolverFile, Source, read_job_file,
};
use crate::meshes;

/// A fully resolved job: every default applied and every value checked.
#[derive(Debug, Clone, PartialEq)]
pub struct JobSpec {
    pub name: String,
    pub packing: PackingSpec,
    /// A measured porosity printed beside the simulated one.
    pub experiment: Option<Experiment>,
}

impl JobSpec {
    /// Why the packing will likely end in "too thin for the trim", if it will: the bed expected
    /// from the mass is no higher than the two trims of the porosity evaluation (§4.4) together.
    pub fn thin_bed(&self) -> Option<String> {
        let p = &self.packing;
        let (bed, trim) = (p.expected_bed_height(), p.derived().trim);
        let whose = if p.trim.is_some() { "" } else { " (the largest sieve, the paper's trim of the periodic domain)" };
        (2.0 * trim >= bed).then(|| {
            format!(
                "{}: grains.mass makes a bed about {bed:.4} m high (at porosity 0.4), and the porosity is evaluated from evaluation.trim = {trim} m{whose} above the floor to as far below the surface: the packing will likely end with \"too thin for the trim\"; give more mass or a smaller evaluation.trim",
                self.name
            )
        })
    }
}

/// Reads, parses and resolves a job file.
pub fn read_job(path: &Path) -> anyhow::Result<JobSpec> {
    let (text, file) = read_job_file(path)?;
    resolve(file, &Source { path, text: &text })
}

/// The paper's setup for the file's domain kind, changed where the file says, every value checked.
pub fn resolve(file: JobFile, source: &Source) -> anyhow::Result<JobSpec> {
    let name = file.name.unwrap_or_else(|| {
        source.path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "job".into())
    });
    let d = file.domain.unwrap_or_default();
    let kind = match d.kind {
        None | Some(DomainKindFile::Periodic) => DomainKind::Periodic,
        Some(DomainKindFile::Cylinder) => DomainKind::Cylinder,
    };
    let mut packing = PackingSpec::paper(kind);
    domain(d, &mut packing);
    grains(file.grains.unwrap_or_default(), &mut packing, source)?;
    let m = file.material.unwrap_or_default();
    let fluid_density_given = m.fluid_density.is_some();
    material(m, &mut packing.material);
    solver(file.solver.unwrap_or_default(), &mut packing);
    let p = file.process.unwrap_or_default();
    let drag = p.fluid == Some(ProcessFluidFile::Drag);
    process(p, &mut packing.process);
    fluid(file.fluid.unwrap_or_default(), drag, fluid_density_given, &mut packing, source)?;
    evaluation(file.evaluation.unwrap_or_default(), &mut packing);
    packing.seed = file.seed.unwrap_or(packing.seed);
    packing.check().map_err(|e| spec_error(source, e))?;
    let experiment = experiment(file.experiment, &packing.grains.size, source)?;
    Ok(JobSpec { name, packing, experiment })
}

fn spec_error(source: &Source, error: SpecError) -> anyhow::Error {
    source.error(error.key, error.message)
}

fn set<T>(target: &mut T, value: Option<T>) {
    if let Some(v) = value {
        *target = v;
    }
}

fn domain(d: DomainFile, spec: &mut PackingSpec) {
    if let Some(width) = d.width {
        spec.domain = match spec.domain {
            Domain::Periodic { .. } => Domain::Periodic { width },
            Domain::Cylinder { .. } => Domain::Cylinder { diameter: width },
        };
    }
    spec.height = d.height.and_then(|h| h.given());
}

/// Size first, since the shape decides what the form and mesh keys may say.
fn grains(g: GrainsFile, spec: &mut PackingSpec, source: &Source) -> anyhow::Result<()> {
    let grains = &mut spec.grains;
    match g.size {
        None => {}
        Some(SizeFile::Case(name)) => {
            let case = Table3Case::find(&name).ok_or_else(|| {
                source.error("grains.size", format!("unknown size case '{name}': expected U1, U3, U5, U7, B30, B50, B70 or {{sieves: [m, …], fractions: […]}}"))
            })?;
            grains.size = case.sieve_curve();
        }
        Some(SizeFile::Curve { sieves, fractions }) => {
            grains.size = SieveCurve::new(sieves, fractions).map_err(|err| source.error("grains.size", err))?;
        }
    }
    set(&mut grains.mass, g.mass);
    grains.shape = match g.shape {
        None => grains.shape,
        Some(ShapeFile::Sphere) => ShapeKind::Sphere,
        Some(ShapeFile::Ellipsoid) => ShapeKind::Ellipsoid,
        Some(ShapeFile::BondedSpheres) => ShapeKind::BondedSpheres,
        Some(ShapeFile::Mesh) => ShapeKind::Mesh,
    };
    grains.meshes = match (grains.shape, g.meshes, g.faces) {
        (ShapeKind::Mesh, library, faces) => {
            let faces = faces.unwrap_or(DEFAULT_MAX_FACES);
            if faces < 4 {
                return Err(source
                    .error("grains.faces", format!("{faces} is out of range: a closed mesh has at least 4 faces")));
            }
            let base = source.path.parent().unwrap_or(Path::new("."));
            let library = meshes::load(library.as_deref().unwrap_or(meshes::RHINE), faces, base)
                .map_err(|e| source.error("grains.meshes", format!("{e:#}")))?;
            Some(library)
        }
        (_, Some(_), _) => return Err(source.error("grains.meshes", "applies to grains.shape: mesh only")),
        (_, _, Some(_)) => return Err(source.error("grains.faces", "applies to grains.shape: mesh only")),
        _ => None,
    };
    grains.form = match (grains.shape, g.form) {
        (ShapeKind::Sphere, Some(_)) => return Err(source.error("grains.form", "has no meaning for spheres")),
        (ShapeKind::Sphere, None) => FormSpec::Single { fl: 1.0, el: 1.0 },
        // Meshes keep their own forms unless told otherwise, the paper's default (§3.2).
        (ShapeKind::Mesh, None) | (_, Some(FormFile::Own)) => FormSpec::Own,
        (_, None) => grains.form,
        (_, Some(FormFile::Single { fl, el })) => FormSpec::Single { fl, el },
        (_, Some(FormFile::Distribution { mu_fl, sigma_fl, mu_el, sigma_el })) => {
            FormSpec::Distribution(FormDistribution { mu_fl, sigma_fl, mu_el, sigma_el })
        }
    };
    Ok(())
}

fn material(m: MaterialFile, material: &mut Material) {
    set(&mut material.density, m.density);
    set(&mut material.fluid_density, m.fluid_density);
    set(&mut material.gravity, m.gravity.map(|g| Vector3::new(0.0, 0.0, -g)));
    set(&mut material.restitution, m.restitution);
    set(&mut material.collision_time, m.collision_time);
    set(&mut material.poisson_ratio, m.poisson_ratio);
    set(&mut material.friction, m.friction);
}

fn solver(s: SolverFile, spec: &mut PackingSpec) {
    set(&mut spec.time_step, s.time_step);
    set(
        &mut spec.calibration,
        s.calibration.map(|c| match c {
            CalibrationFile::Discrete => Calibration::Discrete,
            CalibrationFile::Eq11 => Calibration::Continuous,
        }),
    );
    set(
        &mut spec.contact_point,
        s.contact_point.map(|c| match c {
            ContactPointFile::CentreOfPressure => ContactPoint::CentreOfPressure,
            ContactPointFile::Witness => ContactPoint::Witness,
        }),
    );
    spec.process.max_time = s.max_time.and_then(|t| t.given());
}

fn process(p: ProcessFile, process: &mut Process) {
    let generation = p.generation.unwrap_or_default();
    process.spacing = generation.spacing.and_then(|h| h.given());
    set(&mut process.velocity, generation.velocity);
    set(
        &mut process.orientation,
        generation.orientation.map(|o| match o {
            OrientationFile::Random => Orientation::Random,
            OrientationFile::Upright => Orientation::Upright,
        }),
    );
    set(
        &mut process.grid,
        generation.grid.map(|g| match g {
            GridFile::Cubic => Grid::Cubic,
            GridFile::Hcp => Grid::Hcp,
        }),
    );
    let shaking = p.shaking.unwrap_or_default();
    set(&mut process.shaking.amplitude, shaking.amplitude);
    set(&mut process.shaking.period, shaking.period);
    set(&mut process.shaking_duration, shaking.duration);
    set(&mut process.damping, p.damping);
    let convergence = p.convergence.unwrap_or_default();
    set(&mut process.height_change, convergence.height_change);
    set(&mut process.interval, convergence.interval);
}

/// The fluid: its density is buoyancy's whether or not drag is on (`material.fluid_density`
/// names the same value, so only one of the two may be given); the rest applies with
/// `process.fluid: drag`, which turns on drag and lift in still water at 20 °C unless the block
/// says otherwise.
fn fluid(f: FluidFile, drag: bool, density_given: bool, spec: &mut PackingSpec, source: &Source) -> anyhow::Result<()> {
    if let Some(density) = f.density {
        if density_given {
            return Err(source.error(
                "fluid.density",
                "the fluid's density is given twice: keep fluid.density or material.fluid_density",
            ));
        }
        let grain = spec.material.density;
        in_range(
            "fluid.density",
            density,
            density >= 0.0 && density < grain,
            "≥ 0 and below material.density (grains must sink)",
        )
        .map_err(|e| spec_error(source, e))?;
        spec.material.fluid_density = density;
    }
    if !drag {
        let given = [
            ("fluid.viscosity", f.viscosity.is_some()),
            ("fluid.flow", f.flow.is_some()),
            ("fluid.lift", f.lift.is_some()),
            ("fluid.cell", f.cell.is_some()),
            ("fluid.coupling", f.coupling.is_some()),
        ];
        return match given.iter().find(|(_, given)| *given) {
            Some((key, _)) => Err(source.error(key, "applies with process.fluid: drag only")),
            None => Ok(()),
        };
    }
    let mut fluid = FluidSpec::STILL_WATER;
    set(&mut fluid.viscosity, f.viscosity);
    set(&mut fluid.lift, f.lift);
    fluid.cell = f.cell.and_then(|c| c.given());
    fluid.coupling = f.coupling.and_then(|c| c.given());
    if let Some(flow) = f.flow {
        fluid.flow = flow_of(flow, source)?;
    }
    spec.fluid = Some(fluid);
    Ok(())
}

/// A flow of the kind the file names, with the keys that kind takes and no other.
fn flow_of(f: FlowFile, source: &Source) -> anyhow::Result<Flow> {
    let kind = f
        .kind
        .ok_or_else(|| source.error("fluid.flow.kind", "required: quiescent, uniform, laminar or logarithmic"))?;
    let (name, takes): (&str, &[&str]) = match kind {
        FlowKindFile::Quiescent => ("quiescent", &[]),
        FlowKindFile::Uniform => ("uniform", &["velocity"]),
        FlowKindFile::Laminar => ("laminar", &["shear_velocity", "depth"]),
        FlowKindFile::Logarithmic => ("logarithmic", &["shear_velocity", "roughness"]),
    };
    let keys = [
        ("velocity", f.velocity.is_some()),
        ("shear_velocity", f.shear_velocity.is_some()),
        ("depth", f.depth.is_some()),
        ("roughness", f.roughness.is_some()),
    ];
    for (key, given) in keys {
        let wanted = takes.contains(&key);
        if given && !wanted {
            return Err(source.error(&format!("fluid.flow.{key}"), format!("does not apply to kind {name}")));
        }
        if wanted && !given {
            return Err(source.error(&format!("fluid.flow.{key}"), format!("required for kind {name}")));
        }
    }
    let value = |v: Option<f64>| v.expect("checked above");
    Ok(match kind {
        FlowKindFile::Quiescent => Flow::Quiescent,
        FlowKindFile::Uniform => Flow::Uniform { velocity: Vector3::from(f.velocity.expect("checked above")) },
        FlowKindFile::Laminar => Flow::Laminar { shear_velocity: value(f.shear_velocity), depth: value(f.depth) },
        FlowKindFile::Logarithmic => {
            Flow::Logarithmic { shear_velocity: value(f.shear_velocity), roughness: value(f.roughness) }
        }
    })
}

fn evaluation(e: EvaluationFile, spec: &mut PackingSpec) {
    set(&mut spec.slice, e.slice);
    set(&mut spec.cutoff, e.cutoff);
    spec.trim = e.trim.and_then(|t| t.given());
}

/// A measured porosity, or Table 3's for the size case.
fn experiment(file: Option<ExperimentFile>, size: &SieveCurve, source: &Source) -> anyhow::Result<Option<Experiment>> {
    let checked = |key, value, ok, expected| in_range(key, value, ok, expected).map_err(|e| spec_error(source, e));
    match file {
        None => Ok(None),
        Some(ExperimentFile::Measured(x)) => {
            checked("experiment.porosity", x.porosity, (0.0..1.0).contains(&x.porosity), "a porosity in [0, 1)")?;
            if let Some(std) = x.std {
                checked("experiment.std", std, std >= 0.0, "a standard deviation ≥ 0")?;
            }
            Ok(Some(Experiment { porosity: x.porosity, std: x.std }))
        }
        Some(ExperimentFile::Table3) => match size.case() {
            Some(case) => Ok(Some(Experiment { porosity: case.porosity, std: Some(case.porosity_std) })),
            None => Err(source.error("experiment", "`table3` needs grains.size to be a case of Table 3")),
        },
    }
}
