//! `--only KEY=VALUE`: the jobs of a campaign that `run` and `resume` are limited to, picked by
//! their grid values (e.g. one size distribution of a grid before the others).

use std::collections::BTreeMap;

use analysis::report::value_text;
use anyhow::bail;
use serde_json::{Map, Value};

/// The grid values asked for: a job is picked when, for every key, its value is one of the
/// key's values.
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    wanted: BTreeMap<String, Vec<String>>,
}

impl Selection {
    /// The selection of the `--only` arguments; None when there are none (every job).
    pub fn parse(args: &[String]) -> anyhow::Result<Option<Self>> {
        let mut wanted: BTreeMap<String, Vec<String>> = BTreeMap::new();
        for arg in args {
            match arg.split_once('=') {
                Some((key, value)) if !key.trim().is_empty() && !value.trim().is_empty() => {
                    wanted.entry(key.trim().to_string()).or_default().push(value.trim().to_string());
                }
                _ => bail!(
                    "--only {arg}: expected KEY=VALUE with a grid key of the campaign, e.g. --only grains.size=B50"
                ),
            }
        }
        Ok((!wanted.is_empty()).then_some(Self { wanted }))
    }

    /// The ids of the campaign's jobs (id, grid values) that the selection picks. A key that no
    /// job has, or a value no job has for its key, is an error naming what the jobs have.
    pub fn pick(&self, campaign: &str, jobs: &[(String, Map<String, Value>)]) -> anyhow::Result<Vec<String>> {
        for (key, values) in &self.wanted {
            let mut known: Vec<String> = jobs.iter().filter_map(|(_, p)| p.get(key)).map(value_text).collect();
            if known.is_empty() {
                let mut keys: Vec<&str> = jobs.iter().flat_map(|(_, p)| p.keys()).map(String::as_str).collect();
                keys.sort_unstable();
                keys.dedup();
                let keys = if keys.is_empty() { "none".to_string() } else { keys.join(", ") };
                bail!("--only {key}=…: {key} is not a grid value of campaign {campaign}; its jobs have: {keys}");
            }
            known.sort_unstable();
            known.dedup();
            for value in values {
                if !jobs.iter().any(|(_, p)| p.get(key).is_some_and(|v| same(v, value))) {
                    bail!(
                        "--only {key}={value}: no job of campaign {campaign} has {key} = {value}; its jobs have: {}",
                        known.join(", ")
                    );
                }
            }
        }
        let picked = |p: &Map<String, Value>| {
            self.wanted.iter().all(|(key, values)| p.get(key).is_some_and(|v| values.iter().any(|w| same(v, w))))
        };
        Ok(jobs.iter().filter(|(_, p)| picked(p)).map(|(id, _)| id.clone()).collect())
    }
}

/// Whether a grid value is the one written, numbers compared as numbers (`0.5` is `0.50`).
fn same(value: &Value, written: &str) -> bool {
    if value_text(value) == written {
        return true;
    }
    match (value.as_f64(), written.parse::<f64>()) {
        (Some(a), Ok(b)) => a == b,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;

    fn jobs() -> Vec<(String, Map<String, Value>)> {
        let mut out = Vec::new();
        for (k, (size, seed, friction)) in
            [("U7", 1, 0.5), ("B50", 1, 0.5), ("U7", 2, 0.5), ("B50", 2, 0.25), ("B70", 1, 0.5)].into_iter().enumerate()
        {
            let p = json!({"grains.size": size, "seed": seed, "material.friction": friction});
            out.push((format!("job{k}"), p.as_object().unwrap().clone()));
        }
        out
    }

    fn pick(args: &[&str]) -> anyhow::Result<Vec<String>> {
        let args: Vec<String> = args.iter().map(|a| a.to_string()).collect();
        Selection::parse(&args)?.expect("a selection").pick("grid", &jobs())
    }

    #[test]
    fn keys_are_all_required_and_a_key_given_twice_takes_either_value() {
        assert_eq!(pick(&["grains.size=B50"]).unwrap(), ["job1", "job3"]);
        assert_eq!(pick(&["grains.size=B50", "seed=2"]).unwrap(), ["job3"]);
        assert_eq!(pick(&["grains.size=B50", "grains.size=B70"]).unwrap(), ["job1", "job3", "job4"]);
        assert_eq!(pick(&["material.friction=0.25"]).unwrap(), ["job3"], "numbers compare as numbers");
        assert_eq!(pick(&["seed=1.0", "material.friction=.5"]).unwrap(), ["job0", "job1", "job4"]);
        assert_eq!(Selection::parse(&[]).unwrap(), None, "no --only: every job");
    }

    #[test]
    fn an_unknown_key_or_value_is_refused_with_what_the_jobs_have() {
        let error = pick(&["grains.sizes=B50"]).unwrap_err().to_string();
        assert!(error.contains("grains.sizes is not a grid value of campaign grid"), "{error}");
        assert!(error.contains("grains.size, material.friction, seed"), "{error}");
        let error = pick(&["grains.size=B90"]).unwrap_err().to_string();
        assert!(error.contains("no job of campaign grid has grains.size = B90"), "{error}");
        assert!(error.contains("its jobs have: B50, B70, U7"), "{error}");
        for bad in ["grains.size", "=B50", "grains.size="] {
            let error = pick(&[bad]).unwrap_err().to_string();
            assert!(error.contains(&format!("--only {bad}: expected KEY=VALUE")), "{error}");
        }
    }
}
