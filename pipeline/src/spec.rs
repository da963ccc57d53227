//! Job and campaign files: YAML with the paper's default for every key, so a file names only
//! what it changes. Unknown keys, wrong types and out-of-range values are errors that name the
//! file, the line and the dotted key.

use std::fmt;
use std::path::Path;

use anyhow::{Context, anyhow};
use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::{Deserialize, Serialize};
use solver::dem::{Calibration, Domain, Shaking};
use solver::grain::{FormDistribution, SieveCurve, Table3Case};
use solver::packing::{FormSpec, GrainSpec, Material, PackingSpec, Process, ShapeKind};

use crate::meshes;

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JobFile {
    pub name: Option<String>,
    pub domain: Option<DomainFile>,
    pub grains: Option<GrainsFile>,
    pub material: Option<MaterialFile>,
    pub solver: Option<SolverFile>,
    pub process: Option<ProcessFile>,
    pub evaluation: Option<EvaluationFile>,
    pub experiment: Option<ExperimentFile>,
    pub seed: Option<u64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DomainKind {
    Periodic,
    Cylinder,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DomainFile {
    pub kind: Option<DomainKind>,
    pub width: Option<f64>,
    pub height: Option<Auto>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShapeFile {
    Sphere,
    Ellipsoid,
    BondedSpheres,
    Mesh,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GrainsFile {
    pub shape: Option<ShapeFile>,
    pub size: Option<SizeFile>,
    pub mass: Option<f64>,
    pub form: Option<FormFile>,
    pub meshes: Option<String>,
    pub faces: Option<usize>,
}

/// A Table 3 case by name, or a sieve curve.
#[derive(Debug)]
pub enum SizeFile {
    Case(String),
    Curve { sieves: Vec<f64>, fractions: Vec<f64> },
}

/// One form for all grains, a §7.1 distribution, or each mesh's own form (`mesh`).
#[derive(Debug)]
pub enum FormFile {
    Single { fl: f64, el: f64 },
    Distribution { mu_fl: f64, sigma_fl: f64, mu_el: f64, sigma_el: f64 },
    Own,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialFile {
    pub density: Option<f64>,
    pub fluid_density: Option<f64>,
    pub gravity: Option<f64>,
    pub restitution: Option<f64>,
    pub collision_time: Option<f64>,
    pub poisson_ratio: Option<f64>,
    pub friction: Option<f64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CalibrationFile {
    /// k_n, d_n chosen so that the simulated collision has e_n and T_c (default).
    Discrete,
    /// Eq. 11 as printed.
    Eq11,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverFile {
    pub time_step: Option<f64>,
    pub calibration: Option<CalibrationFile>,
    pub max_time: Option<Auto>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProcessFile {
    pub generation: Option<GenerationFile>,
    pub shaking: Option<ShakingFile>,
    pub damping: Option<f64>,
    pub convergence: Option<ConvergenceFile>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GenerationFile {
    pub spacing: Option<Auto>,
    pub velocity: Option<f64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShakingFile {
    pub amplitude: Option<f64>,
    pub period: Option<f64>,
    pub duration: Option<f64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConvergenceFile {
    pub height_change: Option<f64>,
    pub interval: Option<f64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvaluationFile {
    pub slice: Option<f64>,
    pub cutoff: Option<f64>,
    pub trim: Option<Auto>,
}

/// A measured porosity, or `table3`: the laboratory value of Table 3 for the named size case.
#[derive(Debug)]
pub enum ExperimentFile {
    Table3,
    Measured(MeasuredFile),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasuredFile {
    pub porosity: f64,
    pub std: Option<f64>,
}

/// A number, or `auto` for the paper's rule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Auto {
    Auto,
    Value(f64),
}

/// A measured porosity printed beside the simulated one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Experiment {
    pub porosity: f64,
    pub std: Option<f64>,
}

/// A fully resolved job: every default applied and every value checked.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JobSpec {
    pub name: String,
    /// The size case name (U1 … B70) or "custom".
    pub size_case: String,
    pub packing: PackingSpec,
    pub experiment: Option<Experiment>,
}

impl JobSpec {
    /// Canonical JSON of the resolved spec: the input of the job id.
    pub fn canonical_json(&self) -> String {
        serde_json::to_string(self).expect("a resolved spec serialises")
    }
}

/// Where a problem is: the file and, if found, the line of the dotted key.
pub struct Source<'a> {
    pub path: &'a Path,
    pub text: &'a str,
}

impl Source<'_> {
    /// "FILE:LINE: key: message" (line omitted when the key is not written in the file).
    pub fn error(&self, key: &str, message: impl fmt::Display) -> anyhow::Error {
        match locate(self.text, key) {
            Some(line) => anyhow!("{}:{line}: {key}: {message}", self.path.display()),
            None => anyhow!("{}: {key}: {message}", self.path.display()),
        }
    }
}

/// The 1-based line where the dotted key is written, following its parents (block or flow
/// style); None when the key is not in the text (a default).
pub fn locate(text: &str, key: &str) -> Option<usize> {
    let lines: Vec<&str> = text.lines().collect();
    let segments: Vec<&str> = key.split('.').collect();
    let mut from = 0;
    for s in 0..segments.len() {
        // A grid key is itself dotted ("material.friction:"), so try the rest whole first.
        let rest = segments[s..].join(".");
        if let Some(at) = (from..lines.len()).find(|&k| has_key(lines[k], &rest)) {
            return Some(at + 1);
        }
        from = (from..lines.len()).find(|&k| has_key(lines[k], segments[s]))?;
    }
    None
}

fn has_key(line: &str, key: &str) -> bool {
    let code = line.split('#').next().unwrap_or("");
    code.match_indices(key).any(|(at, _)| {
        let before = code[..at].chars().last();
        let after = code[at + key.len()..].trim_start().chars().next();
        matches!(before, None | Some(' ' | '{' | ',' | '\t')) && after == Some(':')
    })
}

/// Parses a job file's YAML text into the file structure; unknown keys and wrong types are
/// reported with line and dotted key.
pub fn parse_job_value(value: serde_norway::Value, source: &Source) -> anyhow::Result<JobFile> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let key = e.path().to_string();
        source.error(&key, e.into_inner())
    })
}

pub fn read_yaml(path: &Path) -> anyhow::Result<(String, serde_norway::Value)> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let value: serde_norway::Value = serde_norway::from_str(&text).map_err(|e| match e.location() {
        Some(l) => anyhow!("{}:{}: not valid YAML: {e}", path.display(), l.line()),
        None => anyhow!("{}: not valid YAML: {e}", path.display()),
    })?;
    Ok((text, value))
}

/// Reads and resolves a job file (a campaign without `grid:`).
pub fn read_job(path: &Path) -> anyhow::Result<JobSpec> {
    let (text, value) = read_yaml(path)?;
    let source = Source { path, text: &text };
    if let serde_norway::Value::Mapping(map) = &value {
        for key in ["grid", "seeds"] {
            if map.contains_key(key) {
                return Err(source.error(key, "is a campaign key: run campaigns with `sedpack run`"));
            }
        }
    }
    let file = parse_job_value(value, &source)?;
    resolve(file, &source)
}

fn check(source: &Source, key: &str, value: f64, ok: bool, expected: &str) -> anyhow::Result<f64> {
    if ok && value.is_finite() {
        Ok(value)
    } else {
        Err(source.error(key, format!("{value} is out of range: expected {expected}")))
    }
}

fn positive(source: &Source, key: &str, value: f64) -> anyhow::Result<f64> {
    check(source, key, value, value > 0.0, "a number > 0")
}

/// Applies the paper's defaults and checks every value.
pub fn resolve(file: JobFile, source: &Source) -> anyhow::Result<JobSpec> {
    let name = file.name.unwrap_or_else(|| {
        source.path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "job".into())
    });
    let d = file.domain.unwrap_or_default();
    let g = file.grains.unwrap_or_default();
    let m = file.material.unwrap_or_default();
    let s = file.solver.unwrap_or_default();
    let p = file.process.unwrap_or_default();
    let e = file.evaluation.unwrap_or_default();

    // §5.1 (cylinder: L = 0.104 m, 3 kg, t_s = 1 s) and §6.2 (periodic: L = 0.2 m, 16 kg, t_s = 6 s).
    let kind = d.kind.unwrap_or(DomainKind::Periodic);
    let (default_width, default_mass, default_shaking) = match kind {
        DomainKind::Periodic => (0.2, 16.0, 6.0),
        DomainKind::Cylinder => (0.104, 3.0, 1.0),
    };
    let width = positive(source, "domain.width", d.width.unwrap_or(default_width))?;
    let domain = match kind {
        DomainKind::Periodic => Domain::Periodic { width },
        DomainKind::Cylinder => Domain::Cylinder { diameter: width },
    };

    let (size, size_case, table_spacing) = match g.size.unwrap_or(SizeFile::Case("U1".into())) {
        SizeFile::Case(name) => {
            let case = Table3Case::find(&name).ok_or_else(|| {
                source.error("grains.size", format!("unknown size case '{name}': expected U1, U3, U5, U7, B30, B50, B70 or {{sieves: [m, …], fractions: […]}}"))
            })?;
            (case.sieve_curve(), case.name.to_string(), Some(case.spacing))
        }
        SizeFile::Curve { sieves, fractions } => {
            let curve = SieveCurve::new(sieves, fractions).map_err(|err| source.error("grains.size", err))?;
            (curve, "custom".to_string(), None)
        }
    };
    let mass = positive(source, "grains.mass", g.mass.unwrap_or(default_mass))?;
    let shape = match g.shape.unwrap_or(ShapeFile::Ellipsoid) {
        ShapeFile::Sphere => ShapeKind::Sphere,
        ShapeFile::Ellipsoid => ShapeKind::Ellipsoid,
        ShapeFile::BondedSpheres => ShapeKind::BondedSpheres,
        ShapeFile::Mesh => ShapeKind::Mesh,
    };
    let meshes = match (shape, g.meshes, g.faces) {
        (ShapeKind::Mesh, library, faces) => {
            // n_F ≤ 300, the simplification the paper settled on (§5.2.1, Table 4).
            let faces = faces.unwrap_or(300);
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
    let form = match (shape, g.form) {
        (ShapeKind::Sphere, Some(_)) => return Err(source.error("grains.form", "has no meaning for spheres")),
        (ShapeKind::Sphere, None) => FormSpec::Single { fl: 1.0, el: 1.0 },
        // Meshes keep their own forms unless told otherwise, the paper's default (§3.2).
        (ShapeKind::Mesh, None | Some(FormFile::Own)) => FormSpec::Own,
        (_, Some(FormFile::Own)) => {
            return Err(source.error("grains.form", "`mesh` (each mesh's own form) needs grains.shape: mesh"));
        }
        (_, None) => FormSpec::Distribution(solver::grain::pebble::RHINE_FORMS),
        (_, Some(FormFile::Single { fl, el })) => {
            check(source, "grains.form.fl", fl, fl > 0.0 && fl <= 1.0, "a flatness in (0, 1]")?;
            check(source, "grains.form.el", el, el > 0.0 && el <= 1.0, "an elongation in (0, 1]")?;
            FormSpec::Single { fl, el }
        }
        (_, Some(FormFile::Distribution { mu_fl, sigma_fl, mu_el, sigma_el })) => FormSpec::Distribution(
            FormDistribution::new(mu_fl, sigma_fl, mu_el, sigma_el).map_err(|err| source.error("grains.form", err))?,
        ),
    };

    let defaults = Material::default();
    let material = Material {
        density: positive(source, "material.density", m.density.unwrap_or(defaults.density))?,
        fluid_density: m.fluid_density.unwrap_or(defaults.fluid_density),
        gravity: positive(source, "material.gravity", m.gravity.unwrap_or(defaults.gravity))?,
        restitution: m.restitution.unwrap_or(defaults.restitution),
        collision_time: positive(
            source,
            "material.collision_time",
            m.collision_time.unwrap_or(defaults.collision_time),
        )?,
        poisson_ratio: m.poisson_ratio.unwrap_or(defaults.poisson_ratio),
        friction: m.friction.unwrap_or(defaults.friction),
    };
    let f = material.fluid_density;
    check(
        source,
        "material.fluid_density",
        f,
        f >= 0.0 && f < material.density,
        "≥ 0 and below material.density (grains must sink)",
    )?;
    let e_n = material.restitution;
    check(source, "material.restitution", e_n, e_n > 0.0 && e_n <= 1.0, "a coefficient in (0, 1]")?;
    let nu = material.poisson_ratio;
    check(source, "material.poisson_ratio", nu, (0.0..=0.5).contains(&nu), "a ratio in [0, 0.5]")?;
    check(source, "material.friction", material.friction, material.friction >= 0.0, "a coefficient ≥ 0")?;

    let time_step = positive(source, "solver.time_step", s.time_step.unwrap_or(5e-6))?;
    let steps_per_collision = material.collision_time / time_step;
    check(
        source,
        "solver.time_step",
        time_step,
        steps_per_collision >= solver::dem::MIN_STEPS_PER_COLLISION,
        "at most material.collision_time / 10 (the paper resolves a collision in 40 steps)",
    )?;
    let calibration = match s.calibration.unwrap_or(CalibrationFile::Discrete) {
        CalibrationFile::Discrete => Calibration::Discrete { time_step },
        CalibrationFile::Eq11 => Calibration::Continuous,
    };

    let generation = p.generation.unwrap_or_default();
    let largest_present = {
        let last = size.fractions().iter().rposition(|&f| f > 0.0).unwrap_or(size.classes() - 1);
        size.sieves()[last + 1]
    };
    let spacing = match generation.spacing.unwrap_or(Auto::Auto) {
        Auto::Value(v) => {
            let smallest = size.sieves()[size.fractions().iter().position(|&f| f > 0.0).unwrap_or(0)];
            check(
                source,
                "process.generation.spacing",
                v,
                v >= smallest,
                &format!("at least the smallest sieve in use, {smallest} m (a grid slot holds a grain)"),
            )?
        }
        Auto::Auto => table_spacing.unwrap_or(largest_present),
    };
    let velocity = generation.velocity.unwrap_or(1.0);
    check(source, "process.generation.velocity", velocity, velocity >= 0.0, "a speed ≥ 0")?;
    let shaking = p.shaking.unwrap_or_default();
    let amplitude = shaking.amplitude.unwrap_or(3e-4);
    check(source, "process.shaking.amplitude", amplitude, amplitude >= 0.0, "an amplitude ≥ 0")?;
    let period = positive(source, "process.shaking.period", shaking.period.unwrap_or(0.025))?;
    let duration = shaking.duration.unwrap_or(default_shaking);
    check(source, "process.shaking.duration", duration, duration >= 0.0, "a duration ≥ 0")?;
    let damping = p.damping.unwrap_or(1e-3);
    check(source, "process.damping", damping, damping > 0.0 && damping <= 1.0, "a factor c_d in (0, 1]")?;
    let convergence = p.convergence.unwrap_or_default();
    let height_change =
        positive(source, "process.convergence.height_change", convergence.height_change.unwrap_or(1e-5))?;
    let interval = convergence.interval.unwrap_or(0.01);
    check(source, "process.convergence.interval", interval, interval >= time_step, "an interval ≥ solver.time_step")?;

    // Auto height: the generation region [0.6, 1]·H must clear the finished bed (estimated at
    // porosity 0.4) by two grid spacings, so that sets can always leave it.
    let bed = mass / (material.density * domain.cross_section() * 0.6);
    let height = match d.height.unwrap_or(Auto::Auto) {
        Auto::Value(v) => positive(source, "domain.height", v)?,
        Auto::Auto => ((bed + 2.0 * spacing) / 0.6 * 100.0).ceil() / 100.0,
    };
    // Generation plus settling rarely takes more than a minute of simulated time.
    let max_time = match s.max_time.unwrap_or(Auto::Auto) {
        Auto::Auto => duration + 60.0,
        Auto::Value(t) => positive(source, "solver.max_time", t)?,
    };

    let slice = positive(source, "evaluation.slice", e.slice.unwrap_or(1e-3))?;
    let cutoff = e.cutoff.unwrap_or(0.5);
    check(source, "evaluation.cutoff", cutoff, cutoff > 0.0 && cutoff < 1.0, "a porosity in (0, 1)")?;
    let trim = match e.trim.unwrap_or(Auto::Auto) {
        Auto::Auto => None,
        Auto::Value(t) => Some(check(source, "evaluation.trim", t, t >= 0.0, "a height ≥ 0")?),
    };
    let experiment = match file.experiment {
        Some(ExperimentFile::Measured(x)) => {
            check(source, "experiment.porosity", x.porosity, (0.0..1.0).contains(&x.porosity), "a porosity in [0, 1)")?;
            if let Some(std) = x.std {
                check(source, "experiment.std", std, std >= 0.0, "a standard deviation ≥ 0")?;
            }
            Some(Experiment { porosity: x.porosity, std: x.std })
        }
        Some(ExperimentFile::Table3) => match Table3Case::find(&size_case) {
            Some(case) => Some(Experiment { porosity: case.porosity, std: Some(case.porosity_std) }),
            None => return Err(source.error("experiment", "`table3` needs grains.size to be a case of Table 3")),
        },
        None => None,
    };

    Ok(JobSpec {
        name,
        size_case,
        packing: PackingSpec {
            domain,
            height,
            grains: GrainSpec { shape, size, mass, form, meshes },
            material,
            time_step,
            calibration,
            process: Process {
                spacing,
                velocity,
                shaking: Shaking { amplitude, period },
                shaking_duration: duration,
                damping,
                height_change,
                interval,
                max_time,
            },
            slice,
            cutoff,
            trim,
            seed: file.seed.unwrap_or(1),
        },
        experiment,
    })
}

impl<'de> Deserialize<'de> for Auto {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct AutoVisitor;
        impl Visitor<'_> for AutoVisitor {
            type Value = Auto;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or `auto`")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Auto, E> {
                Ok(Auto::Value(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Auto, E> {
                Ok(Auto::Value(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Auto, E> {
                Ok(Auto::Value(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Auto, E> {
                if v == "auto" { Ok(Auto::Auto) } else { Err(E::invalid_value(de::Unexpected::Str(v), &self)) }
            }
        }
        deserializer.deserialize_any(AutoVisitor)
    }
}

impl<'de> Deserialize<'de> for SizeFile {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Curve {
            sieves: Vec<f64>,
            fractions: Vec<f64>,
        }
        struct SizeVisitor;
        impl<'de> Visitor<'de> for SizeVisitor {
            type Value = SizeFile;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a Table 3 case (U1, U3, U5, U7, B30, B50, B70) or {sieves: [m, …], fractions: […]}")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<SizeFile, E> {
                Ok(SizeFile::Case(v.to_string()))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<SizeFile, A::Error> {
                let c = Curve::deserialize(de::value::MapAccessDeserializer::new(map))?;
                Ok(SizeFile::Curve { sieves: c.sieves, fractions: c.fractions })
            }
        }
        deserializer.deserialize_any(SizeVisitor)
    }
}

impl<'de> Deserialize<'de> for FormFile {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Form {
            fl: Option<f64>,
            el: Option<f64>,
            mu_fl: Option<f64>,
            sigma_fl: Option<f64>,
            mu_el: Option<f64>,
            sigma_el: Option<f64>,
        }
        struct FormVisitor;
        impl<'de> Visitor<'de> for FormVisitor {
            type Value = FormFile;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("{fl, el}, {mu_fl, sigma_fl, mu_el, sigma_el} or `mesh`")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<FormFile, E> {
                if v == "mesh" { Ok(FormFile::Own) } else { Err(E::invalid_value(de::Unexpected::Str(v), &self)) }
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<FormFile, A::Error> {
                form(Form::deserialize(de::value::MapAccessDeserializer::new(map))?)
            }
        }
        fn form<E: de::Error>(f: Form) -> Result<FormFile, E> {
            match f {
                Form { fl: Some(fl), el: Some(el), mu_fl: None, sigma_fl: None, mu_el: None, sigma_el: None } => {
                    Ok(FormFile::Single { fl, el })
                }
                Form {
                    fl: None,
                    el: None,
                    mu_fl: Some(mu_fl),
                    sigma_fl: Some(sigma_fl),
                    mu_el: Some(mu_el),
                    sigma_el: Some(sigma_el),
                } => Ok(FormFile::Distribution { mu_fl, sigma_fl, mu_el, sigma_el }),
                _ => Err(de::Error::custom(
                    "expected either {fl, el} (one form), {mu_fl, sigma_fl, mu_el, sigma_el} (a distribution, §7.1) or `mesh` (each mesh's own form)",
                )),
            }
        }
        deserializer.deserialize_any(FormVisitor)
    }
}

impl<'de> Deserialize<'de> for ExperimentFile {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct ExperimentVisitor;
        impl<'de> Visitor<'de> for ExperimentVisitor {
            type Value = ExperimentFile;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("{porosity, std} or `table3`")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<ExperimentFile, E> {
                if v == "table3" {
                    Ok(ExperimentFile::Table3)
                } else {
                    Err(E::invalid_value(de::Unexpected::Str(v), &self))
                }
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<ExperimentFile, A::Error> {
                Ok(ExperimentFile::Measured(MeasuredFile::deserialize(de::value::MapAccessDeserializer::new(map))?))
            }
        }
        deserializer.deserialize_any(ExperimentVisitor)
    }
}
