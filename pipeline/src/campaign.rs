//! Campaign files: a job template plus `grid:` (dotted key → list of values, expanded as a
//! cartesian product), `seeds:` (each grid point runs once per seed) and an optional `executor:`
//! block (where the jobs run, which is not part of any job). Every job is resolved
//! in full and identified by a hash of its resolved spec, so that submitting a campaign twice
//! adds nothing and adding grid values adds only the new jobs.

use std::path::Path;

use anyhow::anyhow;
use serde_json::{Map, Value as Json};
use serde_norway::{Mapping, Value};

use crate::executor::Request;
use crate::job_file::{Source, parse_job_value, read_yaml};
use crate::spec::{JobSpec, resolve};
use crate::stored;

#[derive(Debug, Clone)]
pub struct Campaign {
    pub name: String,
    /// The campaign file as submitted.
    pub text: String,
    pub jobs: Vec<PlannedJob>,
    /// What the `executor:` block asks for (nothing without one).
    pub executor: Request,
}

#[derive(Debug, Clone)]
pub struct PlannedJob {
    pub id: String,
    pub spec: JobSpec,
    /// The grid values of this job (dotted key → value) and its seed.
    pub parameters: Map<String, Json>,
}

pub fn read_campaign(path: &Path) -> anyhow::Result<Campaign> {
    let (text, value) = read_yaml(path)?;
    let source = Source { path, text: &text };
    let Value::Mapping(mut template) = value else {
        return Err(anyhow!("{}: a campaign file must be a mapping of keys", path.display()));
    };
    let executor = match template.remove("executor") {
        None => Request::default(),
        Some(block) => {
            let request: Request = serde_path_to_error::deserialize(block).map_err(|e| {
                let key = match e.path().to_string().as_str() {
                    "." => "executor".to_string(),
                    path => format!("executor.{path}"),
                };
                source.error(&key, e.into_inner())
            })?;
            request.checked_block().map_err(|(key, message)| source.error(key, message))?
        }
    };
    let grid = match template.remove("grid") {
        None => Vec::new(),
        Some(Value::Mapping(grid)) => grid_axes(grid, &source)?,
        Some(_) => return Err(source.error("grid", "expected a mapping of dotted keys to lists of values")),
    };
    let seeds = match template.remove("seeds") {
        None => vec![None],
        Some(Value::Sequence(seeds)) if !seeds.is_empty() => {
            if template.contains_key("seed") {
                return Err(source.error("seeds", "give either `seed` or `seeds`, not both"));
            }
            seeds
                .iter()
                .map(|s| {
                    s.as_u64()
                        .map(Some)
                        .ok_or_else(|| source.error("seeds", format!("{s:?} is not a seed (an integer ≥ 0)")))
                })
                .collect::<anyhow::Result<_>>()?
        }
        Some(_) => return Err(source.error("seeds", "expected a non-empty list of integers")),
    };

    let mut jobs: Vec<PlannedJob> = Vec::new();
    for point in cartesian(&grid) {
        for seed in &seeds {
            let mut value = template.clone();
            let mut parameters = Map::new();
            for (key, v) in &point {
                set_dotted(&mut value, key, v.clone());
                parameters.insert(key.clone(), serde_json::to_value(v)?);
            }
            if let Some(seed) = seed {
                value.insert(Value::from("seed"), Value::from(*seed));
            }
            let describe = || parameters.iter().map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>().join(", ");
            let file = parse_job_value(Value::Mapping(value.clone()), &source)
                .map_err(|e| if point.is_empty() { e } else { e.context(format!("grid point {}", describe())) })?;
            let spec = resolve(file, &source)
                .map_err(|e| if point.is_empty() { e } else { e.context(format!("grid point {}", describe())) })?;
            parameters.insert("seed".into(), Json::from(spec.packing.seed));
            let id = stored::job_id(&spec);
            if let Some(twin) = jobs.iter().find(|j| j.id == id) {
                return Err(anyhow!(
                    "{}: grid points {:?} and {:?} give the same job: a grid key has no effect",
                    path.display(),
                    twin.parameters,
                    parameters
                ));
            }
            jobs.push(PlannedJob { id, spec, parameters });
        }
    }
    let name = jobs[0].spec.name.clone();
    Ok(Campaign { name, text, jobs, executor })
}

/// The grid as (dotted key, values) in file order; every list must be non-empty.
fn grid_axes(grid: Mapping, source: &Source) -> anyhow::Result<Vec<(String, Vec<Value>)>> {
    grid.into_iter()
        .map(|(key, values)| {
            let key =
                key.as_str().ok_or_else(|| source.error("grid", format!("{key:?} is not a dotted key")))?.to_string();
            match values {
                Value::Sequence(values) if !values.is_empty() => Ok((key, values)),
                Value::Sequence(_) => Err(source.error(&format!("grid.{key}"), "empty list: give at least one value")),
                _ => Err(source.error(&format!("grid.{key}"), "expected a list of values")),
            }
        })
        .collect()
}

/// Every combination of one value per axis, the first axis varying slowest.
fn cartesian(axes: &[(String, Vec<Value>)]) -> Vec<Vec<(String, Value)>> {
    let mut points = vec![Vec::new()];
    for (key, values) in axes {
        points = points
            .into_iter()
            .flat_map(|point: Vec<(String, Value)>| {
                values.iter().map(move |v| {
                    let mut p = point.clone();
                    p.push((key.clone(), v.clone()));
                    p
                })
            })
            .collect();
    }
    points
}

/// Sets `a.b.c` in a YAML mapping, creating the intermediate mappings.
fn set_dotted(map: &mut Mapping, key: &str, value: Value) {
    let mut segments = key.split('.').peekable();
    let mut current = map;
    while let Some(segment) = segments.next() {
        if segments.peek().is_none() {
            current.insert(Value::from(segment), value);
            return;
        }
        let entry = current.entry(Value::from(segment)).or_insert_with(|| Value::Mapping(Mapping::new()));
        if !entry.is_mapping() {
            *entry = Value::Mapping(Mapping::new());
        }
        current = entry.as_mapping_mut().expect("just made a mapping");
    }
}
