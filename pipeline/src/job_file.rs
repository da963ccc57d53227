//! The job and campaign file as written: its raw YAML types, parsed without defaults, and the
//! locator that turns a dotted key into the file's line, so that every later error can name the
//! file, the line and the key. Resolution into a checked job is `crate::spec`.

use std::fmt;
use std::path::Path;

use anyhow::{Context, anyhow};
use serde::Deserialize;
use serde::de::{self, Deserializer, MapAccess, Visitor};

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
    pub fluid: Option<FluidFile>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DomainKindFile {
    Periodic,
    Cylinder,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DomainFile {
    pub kind: Option<DomainKindFile>,
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

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ContactPointFile {
    /// The centroid of the overlap; a face on a wall spreads over its corners (default).
    CentreOfPressure,
    /// EPA's witness midpoint, and the deepest vertex against a wall: the paper's software.
    Witness,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverFile {
    pub time_step: Option<f64>,
    pub calibration: Option<CalibrationFile>,
    pub contact_point: Option<ContactPointFile>,
    pub max_time: Option<Auto>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProcessFile {
    pub generation: Option<GenerationFile>,
    pub shaking: Option<ShakingFile>,
    pub damping: Option<f64>,
    pub convergence: Option<ConvergenceFile>,
    pub fluid: Option<ProcessFluidFile>,
}

/// Which fluid forces act during the protocol.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ProcessFluidFile {
    /// Buoyancy only, the first paper's protocol (default).
    None,
    /// Drag (Sun & Xiao Eqs. 3–7) and lift (Eq. 8) in the flow of the `fluid:` block.
    Drag,
}

/// The fluid: its density (buoyancy's too), viscosity, prescribed flow, lift and averaging.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidFile {
    pub density: Option<f64>,
    pub viscosity: Option<f64>,
    pub flow: Option<FlowFile>,
    pub lift: Option<bool>,
    pub cell: Option<Auto>,
    pub coupling: Option<Auto>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FlowKindFile {
    Quiescent,
    Uniform,
    Laminar,
    Logarithmic,
}

/// A prescribed flow: its kind and the keys that kind takes.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlowFile {
    pub kind: Option<FlowKindFile>,
    pub velocity: Option<[f64; 3]>,
    pub shear_velocity: Option<f64>,
    pub depth: Option<f64>,
    pub roughness: Option<f64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GenerationFile {
    pub spacing: Option<Auto>,
    pub velocity: Option<f64>,
    pub orientation: Option<OrientationFile>,
    pub grid: Option<GridFile>,
}

/// How a new grain lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OrientationFile {
    /// Turned uniformly at random (default).
    Random,
    /// Long axis vertical, short axis along x, every grain alike: the paper's software.
    Upright,
}

/// The grid new grains are created on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GridFile {
    /// Cubic, centred (default): the text's hexahedral grid.
    Cubic,
    /// Hexagonal close-packed from the domain's axis: the paper's software.
    Hcp,
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

impl Auto {
    /// The number given, None for the paper's rule.
    pub fn given(self) -> Option<f64> {
        match self {
            Auto::Auto => None,
            Auto::Value(v) => Some(v),
        }
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
        // A key left out is shown at the line of the nearest parent written, where it belongs.
        let written = |k: &str| locate(self.text, k);
        let line = written(key).or_else(|| key.rmatch_indices('.').find_map(|(at, _)| written(&key[..at])));
        match line {
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

/// Reads and parses a job file (a campaign without `grid:` and `seeds:`): its text, for line
/// numbers, and its raw values.
pub fn read_job_file(path: &Path) -> anyhow::Result<(String, JobFile)> {
    let (text, value) = read_yaml(path)?;
    let source = Source { path, text: &text };
    if let serde_norway::Value::Mapping(map) = &value {
        for key in ["grid", "seeds", "executor"] {
            if map.contains_key(key) {
                return Err(source.error(key, "is a campaign key: run campaigns with `sedpack run`"));
            }
        }
    }
    let file = parse_job_value(value, &source)?;
    Ok((text, file))
}

/// A YAML file's text and its value; invalid YAML is an error with the file and line.
pub fn read_yaml(path: &Path) -> anyhow::Result<(String, serde_norway::Value)> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let value: serde_norway::Value = serde_norway::from_str(&text).map_err(|e| match e.location() {
        Some(l) => anyhow!("{}:{}: not valid YAML: {e}", path.display(), l.line()),
        None => anyhow!("{}: not valid YAML: {e}", path.display()),
    })?;
    Ok((text, value))
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

/// A key written either as one word or as a mapping (`form: mesh` or `form: {fl: 0.6, el: 0.7}`):
/// the word goes through `word`, the mapping is read as `M` and goes through `map`.
fn word_or_map<'de, D, M, T>(
    deserializer: D,
    expecting: &'static str,
    word: fn(&str) -> Option<T>,
    map: fn(M) -> Result<T, &'static str>,
) -> Result<T, D::Error>
where
    D: Deserializer<'de>,
    M: Deserialize<'de>,
{
    struct WordOrMap<M, T> {
        expecting: &'static str,
        word: fn(&str) -> Option<T>,
        map: fn(M) -> Result<T, &'static str>,
    }
    impl<'de, M: Deserialize<'de>, T> Visitor<'de> for WordOrMap<M, T> {
        type Value = T;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str(self.expecting)
        }
        fn visit_str<E: de::Error>(self, v: &str) -> Result<T, E> {
            (self.word)(v).ok_or_else(|| E::invalid_value(de::Unexpected::Str(v), &self))
        }
        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<T, A::Error> {
            (self.map)(M::deserialize(de::value::MapAccessDeserializer::new(map))?).map_err(de::Error::custom)
        }
    }
    deserializer.deserialize_any(WordOrMap { expecting, word, map })
}

impl<'de> Deserialize<'de> for SizeFile {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Curve {
            sieves: Vec<f64>,
            fractions: Vec<f64>,
        }
        word_or_map(
            deserializer,
            "a Table 3 case (U1, U3, U5, U7, B30, B50, B70) or {sieves: [m, …], fractions: […]}",
            |case| Some(SizeFile::Case(case.to_string())),
            |c: Curve| Ok(SizeFile::Curve { sieves: c.sieves, fractions: c.fractions }),
        )
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
        word_or_map(
            deserializer,
            "{fl, el}, {mu_fl, sigma_fl, mu_el, sigma_el} or `mesh`",
            |word| (word == "mesh").then_some(FormFile::Own),
            |f: Form| match f {
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
                _ => Err(
                    "expected either {fl, el} (one form), {mu_fl, sigma_fl, mu_el, sigma_el} (a distribution, §7.1) or `mesh` (each mesh's own form)",
                ),
            },
        )
    }
}

impl<'de> Deserialize<'de> for ExperimentFile {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        word_or_map(
            deserializer,
            "{porosity, std} or `table3`",
            |word| (word == "table3").then_some(ExperimentFile::Table3),
            |measured: MeasuredFile| Ok(ExperimentFile::Measured(measured)),
        )
    }
}
