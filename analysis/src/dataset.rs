//! The feature table: one row per finished job with its porosity and features (§6.3.1, §7.2).
//! Single-form campaigns get the 26 Table 1 factors and inverses; form mixtures the number-based
//! mean and std of those 26 and the inverses of these 52 (104). Columns that are not finite for
//! some job are dropped, each with the reason, so every kept column is usable by every fit.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

use serde::Serialize;
use thiserror::Error;

use crate::csv;
use crate::form_factors::{form_feature_names, inverse_name};
use crate::record::JobRecord;

/// Standard deviation of FL and EL below which a packing counts as single-form: identical grains
/// give exactly 0 up to the rounding of sqrt(E[x²] − E[x]²), about 1e-8; real mixtures have σ ≳ 0.01.
/// Relative to the mean, the same bound decides when σ of any factor is too small to invert.
pub const SINGLE_FORM_STD_TOLERANCE: f64 = 1e-6;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum FeatureKind {
    /// Every grain of every packing has one form: the 26 factors and inverses (§6.3).
    SingleForm,
    /// Form mixtures: mean, std and their inverses of the 26 (§7.2).
    Mixture,
}

impl FeatureKind {
    pub fn describe(self) -> &'static str {
        match self {
            FeatureKind::SingleForm => {
                "single-form packings: the 13 factors of Table 1 and their inverses (26 features, §6.3)"
            }
            FeatureKind::Mixture => {
                "form mixtures: number-based mean and std of the 13 factors and their inverses, and the inverses of those (104 features, §7.2)"
            }
        }
    }
}

/// A candidate feature left out of the table, and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DroppedFeature {
    pub feature: String,
    pub reason: String,
}

#[derive(Debug, Error, PartialEq)]
pub enum DatasetError {
    #[error("no finished jobs to analyse")]
    NoRecords,
    #[error("job '{0}' appears twice")]
    DuplicateJob(String),
    #[error("job '{job_id}': porosity {value} is not a number in (0, 1)")]
    Porosity { job_id: String, value: f64 },
    #[error("job '{job_id}' has no grain statistic '{key}' (needed to tell single-form from mixture packings)")]
    MissingFormStatistic { job_id: String, key: String },
    #[error("column '{feature}' has {actual} values for {expected} jobs")]
    ColumnLength { feature: String, expected: usize, actual: usize },
}

#[derive(Debug, Clone, PartialEq)]
pub struct Dataset {
    kind: FeatureKind,
    job_ids: Vec<String>,
    porosity: Vec<f64>,
    features: Vec<String>,
    columns: Vec<Vec<f64>>,
    dropped: Vec<DroppedFeature>,
}

#[derive(Debug, Clone, Copy)]
enum Statistic {
    Mean,
    Std,
}

/// How a feature follows from a job's grain statistics.
struct Source {
    key: String,
    statistic: Statistic,
    inverted: bool,
}

impl Source {
    /// The value, or why it is not a finite number.
    fn value(&self, stats: &BTreeMap<String, (f64, f64)>) -> Result<f64, String> {
        let (mean, std) = *stats.get(&self.key).ok_or_else(|| format!("no grain statistic '{}'", self.key))?;
        let (label, v) = match self.statistic {
            Statistic::Mean => (format!("mean_{}", self.key), mean),
            Statistic::Std => (format!("std_{}", self.key), std),
        };
        if !v.is_finite() {
            return Err(format!("{label} = {v} (undefined for some grain)"));
        }
        if !self.inverted {
            return Ok(v);
        }
        // Identical grains leave a rounding residue instead of σ = 0; its inverse would be noise.
        if matches!(self.statistic, Statistic::Std) && v <= SINGLE_FORM_STD_TOLERANCE * mean.abs() {
            return Err(format!("{label} = {v:e} ≈ 0 (one form), so 1/{label} is undefined"));
        }
        let inverse = 1.0 / v;
        if inverse.is_finite() { Ok(inverse) } else { Err(format!("{label} = {v}, so 1/{label} is not finite")) }
    }
}

/// Column names of the 104 mixture features: per factor X of `form_feature_names`, mean_X,
/// std_X, inv_mean_X, inv_std_X.
pub fn mixture_feature_names() -> Vec<String> {
    mixture_sources().into_iter().map(|(name, _)| name).collect()
}

fn mixture_sources() -> Vec<(String, Source)> {
    let mut out = Vec::with_capacity(104);
    for key in form_feature_names() {
        for inverted in [false, true] {
            for (statistic, prefix) in [(Statistic::Mean, "mean"), (Statistic::Std, "std")] {
                let plain = format!("{prefix}_{key}");
                let name = if inverted { inverse_name(&plain) } else { plain };
                out.push((name, Source { key: key.clone(), statistic, inverted }));
            }
        }
    }
    out
}

fn single_form_sources() -> Vec<(String, Source)> {
    form_feature_names()
        .into_iter()
        .map(|key| (key.clone(), Source { key, statistic: Statistic::Mean, inverted: false }))
        .collect()
}

/// The mixture features of one set of grain statistics (e.g. of measured grains), those that
/// are finite; the others with the reason.
pub fn mixture_features(stats: &BTreeMap<String, (f64, f64)>) -> (BTreeMap<String, f64>, Vec<DroppedFeature>) {
    evaluate(&mixture_sources(), stats)
}

/// The single-form features (the per-grain factors, read from the means) of one set of grain
/// statistics; the non-finite ones with the reason.
pub fn single_form_features(stats: &BTreeMap<String, (f64, f64)>) -> (BTreeMap<String, f64>, Vec<DroppedFeature>) {
    evaluate(&single_form_sources(), stats)
}

fn evaluate(
    sources: &[(String, Source)],
    stats: &BTreeMap<String, (f64, f64)>,
) -> (BTreeMap<String, f64>, Vec<DroppedFeature>) {
    let mut values = BTreeMap::new();
    let mut dropped = Vec::new();
    for (name, source) in sources {
        match source.value(stats) {
            Ok(v) => {
                values.insert(name.clone(), v);
            }
            Err(reason) => dropped.push(DroppedFeature { feature: name.clone(), reason }),
        }
    }
    (values, dropped)
}

/// Whether σ_FL and σ_EL of these grain statistics are zero (one form for all grains).
pub fn is_single_form_statistics(stats: &BTreeMap<String, (f64, f64)>) -> Option<bool> {
    let fl = stats.get("FL")?.1;
    let el = stats.get("EL")?.1;
    Some(fl.abs() <= SINGLE_FORM_STD_TOLERANCE && el.abs() <= SINGLE_FORM_STD_TOLERANCE)
}

/// Whether every job's grains share one form (σ_FL = σ_EL = 0 within the tolerance).
pub fn is_single_form(records: &[JobRecord]) -> Result<bool, DatasetError> {
    let mut all = true;
    for r in records {
        for key in ["FL", "EL"] {
            if !r.grain_statistics.contains_key(key) {
                return Err(DatasetError::MissingFormStatistic { job_id: r.job_id.clone(), key: key.into() });
            }
        }
        all &= is_single_form_statistics(&r.grain_statistics) == Some(true);
    }
    Ok(all)
}

impl Dataset {
    /// The feature table of a campaign's finished jobs, in the order given.
    pub fn from_records(records: &[JobRecord]) -> Result<Self, DatasetError> {
        let kind = if is_single_form(records)? { FeatureKind::SingleForm } else { FeatureKind::Mixture };
        let sources = match kind {
            FeatureKind::SingleForm => single_form_sources(),
            FeatureKind::Mixture => mixture_sources(),
        };
        let columns = sources
            .iter()
            .map(|(name, source)| (name.clone(), records.iter().map(|r| source.value(&r.grain_statistics)).collect()))
            .collect();
        Self::build(
            kind,
            records.iter().map(|r| r.job_id.clone()).collect(),
            records.iter().map(|r| r.porosity).collect(),
            columns,
        )
    }

    /// A table from given columns (for data that do not come from grain statistics); columns
    /// with a non-finite value are dropped like in `from_records`.
    pub fn from_columns(
        kind: FeatureKind,
        job_ids: Vec<String>,
        porosity: Vec<f64>,
        columns: Vec<(String, Vec<f64>)>,
    ) -> Result<Self, DatasetError> {
        let columns = columns
            .into_iter()
            .map(|(name, values)| {
                let checked = values.into_iter().map(|v| if v.is_finite() { Ok(v) } else { Err(format!("value {v}")) });
                (name, checked.collect())
            })
            .collect();
        Self::build(kind, job_ids, porosity, columns)
    }

    fn build(
        kind: FeatureKind,
        job_ids: Vec<String>,
        porosity: Vec<f64>,
        candidates: Vec<(String, Vec<Result<f64, String>>)>,
    ) -> Result<Self, DatasetError> {
        if job_ids.is_empty() {
            return Err(DatasetError::NoRecords);
        }
        let mut seen = BTreeSet::new();
        for id in &job_ids {
            if !seen.insert(id) {
                return Err(DatasetError::DuplicateJob(id.clone()));
            }
        }
        if porosity.len() != job_ids.len() {
            return Err(DatasetError::ColumnLength {
                feature: "porosity".into(),
                expected: job_ids.len(),
                actual: porosity.len(),
            });
        }
        for (id, &n) in job_ids.iter().zip(&porosity) {
            if !(n > 0.0 && n < 1.0) {
                return Err(DatasetError::Porosity { job_id: id.clone(), value: n });
            }
        }
        let (mut features, mut columns, mut dropped) = (Vec::new(), Vec::new(), Vec::new());
        for (name, values) in candidates {
            if values.len() != job_ids.len() {
                return Err(DatasetError::ColumnLength {
                    feature: name,
                    expected: job_ids.len(),
                    actual: values.len(),
                });
            }
            let failures: Vec<(&String, &String)> =
                job_ids.iter().zip(&values).filter_map(|(id, v)| v.as_ref().err().map(|e| (id, e))).collect();
            match failures.first() {
                None => {
                    features.push(name);
                    columns.push(values.into_iter().flatten().collect());
                }
                Some((id, why)) => dropped.push(DroppedFeature {
                    feature: name,
                    reason: format!(
                        "not finite for {} of {} jobs, e.g. job {id}: {why}",
                        failures.len(),
                        job_ids.len()
                    ),
                }),
            }
        }
        Ok(Self { kind, job_ids, porosity, features, columns, dropped })
    }

    pub fn kind(&self) -> FeatureKind {
        self.kind
    }

    /// Number of rows (jobs).
    pub fn len(&self) -> usize {
        self.job_ids.len()
    }

    pub fn is_empty(&self) -> bool {
        self.job_ids.is_empty()
    }

    pub fn job_ids(&self) -> &[String] {
        &self.job_ids
    }

    pub fn porosity(&self) -> &[f64] {
        &self.porosity
    }

    /// Kept feature columns, in construction order (Table 1 order for campaign data).
    pub fn features(&self) -> &[String] {
        &self.features
    }

    pub fn dropped(&self) -> &[DroppedFeature] {
        &self.dropped
    }

    pub fn column(&self, feature: &str) -> Option<&[f64]> {
        let k = self.features.iter().position(|f| f == feature)?;
        Some(&self.columns[k])
    }

    /// [min, max] of a feature over the rows.
    pub fn range(&self, feature: &str) -> Option<[f64; 2]> {
        let c = self.column(feature)?;
        Some([c.iter().copied().fold(f64::INFINITY, f64::min), c.iter().copied().fold(f64::NEG_INFINITY, f64::max)])
    }

    /// dataset.csv: job_id, porosity, one column per feature; numbers in Rust's shortest
    /// round-trip form so the file reproduces the fits exactly.
    pub fn to_csv(&self) -> String {
        let mut out = String::from("job_id,porosity");
        for f in &self.features {
            out.push(',');
            out.push_str(f);
        }
        out.push('\n');
        for (row, id) in self.job_ids.iter().enumerate() {
            out.push_str(&csv::field(id));
            let _ = write!(out, ",{}", self.porosity[row]);
            for c in &self.columns {
                let _ = write!(out, ",{}", c[row]);
            }
            out.push('\n');
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mixture_names_are_the_104_of_section_7_2() {
        let names = mixture_feature_names();
        assert_eq!(names.len(), 104);
        assert_eq!(names.iter().collect::<BTreeSet<_>>().len(), 104, "names are unique");
        assert_eq!(
            names[..8],
            [
                "mean_FL",
                "std_FL",
                "inv_mean_FL",
                "inv_std_FL",
                "mean_inv_FL",
                "std_inv_FL",
                "inv_mean_inv_FL",
                "inv_std_inv_FL"
            ]
        );
        for paper in ["inv_mean_EQ", "inv_std_EQ", "inv_mean_EL", "inv_std_EL"] {
            assert!(names.iter().any(|n| n == paper), "{paper}");
        }
    }
}
