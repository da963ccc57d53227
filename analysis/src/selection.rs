//! The paper's model-building procedure (§6.3.2–6.3.3, §7.2): rank features by |r| with
//! porosity, take the primary, drop features correlated with it above a threshold, fit every
//! (primary, remaining feature) pair with k-fold CV (Table 9), then fit chosen multivariate
//! sets (Table 10) and pick the final model.

use serde::Serialize;
use thiserror::Error;

use crate::correlation::{FeatureCorrelation, Ranking, pearson, rank_features};
use crate::cross_validation::{CvError, assign_folds, cross_validate};
use crate::dataset::{Dataset, FeatureKind};
use crate::form_factors::{base_factor, symbol};
use crate::model::LinearModel;
use crate::regression::{FitError, fit_least_squares};

/// §6.3.3: features with |r| above 0.8 with the primary are removed.
pub const DEFAULT_THRESHOLD: f64 = 0.8;
/// §6.3.3: 10-fold cross-validation.
pub const DEFAULT_FOLDS: usize = 10;
/// The paper's final feature sets, compared beside the procedure's own: Eqs. 23–24 and 17–19.
pub const PAPER_MIXTURE_FEATURES: [&str; 4] = ["inv_mean_EQ", "inv_std_EQ", "inv_mean_EL", "inv_std_EL"];
pub const PAPER_SINGLE_FORM_FEATURES: [&str; 2] = ["inv_EQ", "inv_EL"];

#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SelectionOptions {
    /// |r| with the primary above which a feature is removed.
    pub threshold: f64,
    /// k of the k-fold cross-validation (capped at the number of rows).
    pub folds: usize,
    /// Seed of the fold assignment.
    pub seed: u64,
}

impl Default for SelectionOptions {
    fn default() -> Self {
        Self { threshold: DEFAULT_THRESHOLD, folds: DEFAULT_FOLDS, seed: 0 }
    }
}

#[derive(Debug, Clone, Error, PartialEq)]
pub enum SelectionError {
    #[error("threshold {0} must lie in (0, 1]")]
    Threshold(f64),
    #[error("k-fold cross-validation needs k ≥ 2, got {0}")]
    Folds(usize),
    #[error("too few finished jobs ({rows}) to rank features and cross-validate a fit (at least 3)")]
    TooFewRows { rows: usize },
    #[error("porosity is the same for every job, so no feature can be correlated with it")]
    ConstantPorosity,
    #[error("no feature varies across the jobs, so none can be correlated with porosity")]
    NoRankableFeature,
    #[error("feature '{0}' is not a column of the dataset")]
    UnknownFeature(String),
}

#[derive(Debug, Error, PartialEq)]
pub enum ModelFitError {
    #[error("feature '{0}' is not in the dataset")]
    UnknownFeature(String),
    #[error("cross-validation: {0}")]
    CrossValidation(#[from] CvError),
    #[error("fit on all rows: {0}")]
    Fit(#[from] FitError),
}

/// A model fitted on all rows with its cross-validation, and its predictions of every row.
#[derive(Debug, Clone, PartialEq)]
pub struct FittedModel {
    /// Coefficients from all rows; `cv` from the k-fold fits; `ranges` the training ranges.
    pub model: LinearModel,
    /// Each row predicted by the fold model that did not see it.
    pub held_out: Vec<f64>,
    /// Each row predicted by the model fitted on all rows.
    pub fitted: Vec<f64>,
}

/// A feature set tried, and its fit or why there is none.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    pub features: Vec<String>,
    pub result: Result<FittedModel, String>,
}

impl Candidate {
    pub fn fitted(&self) -> Option<&FittedModel> {
        self.result.as_ref().ok()
    }

    pub fn mae(&self) -> Option<f64> {
        self.fitted().and_then(|f| f.model.cv).map(|cv| cv.mae)
    }
}

/// The features compared with the primary, split by |r| with it.
#[derive(Debug, Clone, PartialEq)]
pub struct CorrelationFilter {
    pub threshold: f64,
    /// |r| with the primary above the threshold, with that r.
    pub removed: Vec<FeatureCorrelation>,
    pub kept: Vec<FeatureCorrelation>,
}

/// Everything the procedure found, in the order the paper reports it.
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    pub options: SelectionOptions,
    /// Fold of each row, shared by every fit so their errors compare like for like.
    pub folds: Vec<usize>,
    pub ranking: Ranking,
    pub primary: FeatureCorrelation,
    pub filter: CorrelationFilter,
    /// The primary alone, then the primary with each kept feature (Table 9).
    pub pairs: Vec<Candidate>,
    /// The second factor: the best pair partner of another factor (and, for mixtures, of the
    /// same statistic as the primary).
    pub second: Option<String>,
    /// Multivariate sets (Table 10); the last may be the paper's own set for comparison.
    pub sets: Vec<Candidate>,
    /// Index into `sets` of the paper's own set, when it was added for comparison.
    pub paper_set: Option<usize>,
    /// Index into `sets` of the final model.
    pub chosen: Option<usize>,
}

impl Selection {
    pub fn chosen_model(&self) -> Option<&FittedModel> {
        self.sets.get(self.chosen?)?.fitted()
    }
}

/// Features of `candidates` whose |r| with `primary` exceeds `threshold` are removed; the rest
/// are kept. Both lists carry the r with the primary.
pub fn filter_correlated(
    dataset: &Dataset,
    primary: &str,
    candidates: &[String],
    threshold: f64,
) -> Result<CorrelationFilter, SelectionError> {
    let p = dataset.column(primary).ok_or_else(|| SelectionError::UnknownFeature(primary.to_string()))?;
    let (mut removed, mut kept) = (Vec::new(), Vec::new());
    for f in candidates.iter().filter(|f| f.as_str() != primary) {
        let Some(column) = dataset.column(f) else { continue };
        let Some(r) = pearson(p, column) else { continue };
        let entry = FeatureCorrelation { feature: f.clone(), r };
        if r.abs() > threshold { removed.push(entry) } else { kept.push(entry) }
    }
    Ok(CorrelationFilter { threshold, removed, kept })
}

/// Cross-validates the model of porosity on `features` over `folds`, then fits it on all rows;
/// the saved model carries the CV metrics and each feature's training range.
pub fn fit_model(
    dataset: &Dataset,
    features: &[String],
    folds: &[usize],
    campaign: &str,
) -> Result<FittedModel, ModelFitError> {
    let columns = features
        .iter()
        .map(|f| dataset.column(f).ok_or_else(|| ModelFitError::UnknownFeature(f.clone())))
        .collect::<Result<Vec<&[f64]>, _>>()?;
    let y = dataset.porosity();
    let cv = cross_validate(features, &columns, y, folds)?;
    let fit = fit_least_squares(features, &columns, y)?;
    let fitted = (0..y.len()).map(|i| fit.predict(&columns.iter().map(|c| c[i]).collect::<Vec<_>>())).collect();
    let ranges = features.iter().map(|f| (f.clone(), dataset.range(f).expect("checked above"))).collect();
    let model = LinearModel {
        name: features.join(" + "),
        features: features.to_vec(),
        coefficients: fit.coefficients,
        intercept: fit.intercept,
        cv: Some(cv.metrics),
        ranges,
        campaign: Some(campaign.to_string()),
    };
    Ok(FittedModel { model, held_out: cv.predictions, fitted })
}

fn candidate(dataset: &Dataset, features: Vec<String>, folds: &[usize], campaign: &str) -> Candidate {
    let result = fit_model(dataset, &features, folds, campaign).map_err(|e| match e {
        ModelFitError::UnknownFeature(f) => match dataset.dropped().iter().find(|d| d.feature == f) {
            Some(d) => format!("feature '{f}' was dropped from the dataset: {}", d.reason),
            None => format!("feature '{f}' is not in the dataset"),
        },
        other => other.to_string(),
    });
    Candidate { features, result }
}

/// Splits a mixture feature's outer inverse off: "inv_mean_EQ" → ("inv_", "mean_EQ").
fn split_outer_inverse(feature: &str) -> (&'static str, &str) {
    match feature.strip_prefix("inv_") {
        Some(rest) if rest.starts_with("mean_") || rest.starts_with("std_") => ("inv_", rest),
        _ => ("", feature),
    }
}

/// "mean" or "std" for a mixture feature, None for a single-form one.
fn statistic(feature: &str) -> Option<&'static str> {
    let (_, rest) = split_outer_inverse(feature);
    ["mean", "std"].into_iter().find(|s| rest.starts_with(&format!("{s}_")))
}

/// The same feature of the other statistic: inv_mean_EQ ↔ inv_std_EQ.
fn statistic_partner(feature: &str) -> Option<String> {
    let (outer, rest) = split_outer_inverse(feature);
    let swapped = match rest.strip_prefix("mean_") {
        Some(f) => format!("std_{f}"),
        None => format!("mean_{}", rest.strip_prefix("std_")?),
    };
    Some(format!("{outer}{swapped}"))
}

/// Runs the whole procedure on a dataset.
pub fn select_models(
    dataset: &Dataset,
    campaign: &str,
    options: &SelectionOptions,
) -> Result<Selection, SelectionError> {
    if !(options.threshold > 0.0 && options.threshold <= 1.0) {
        return Err(SelectionError::Threshold(options.threshold));
    }
    if options.folds < 2 {
        return Err(SelectionError::Folds(options.folds));
    }
    if dataset.len() < 3 {
        return Err(SelectionError::TooFewRows { rows: dataset.len() });
    }
    let n = dataset.porosity();
    let (lo, hi) = n.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    if hi - lo <= 1e-12 * hi {
        return Err(SelectionError::ConstantPorosity);
    }
    let folds = assign_folds(dataset.len(), options.folds, options.seed);
    let ranking = rank_features(dataset);
    let primary = ranking.primary(dataset).ok_or(SelectionError::NoRankableFeature)?.clone();
    let p = primary.feature.clone();
    let ranked: Vec<String> = ranking.ranked.iter().map(|c| c.feature.clone()).collect();
    let filter = filter_correlated(dataset, &p, &ranked, options.threshold)?;

    let mut pairs = vec![candidate(dataset, vec![p.clone()], &folds, campaign)];
    pairs.extend(filter.kept.iter().map(|k| candidate(dataset, vec![p.clone(), k.feature.clone()], &folds, campaign)));

    let other_factor = |c: &&Candidate| base_factor(&c.features[1]) != base_factor(&p);
    let best = |cs: Vec<&Candidate>| {
        cs.into_iter()
            .filter_map(|c| c.mae().map(|m| (m, c.features[1].clone())))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, f)| f)
    };
    let partners: Vec<&Candidate> = pairs[1..].iter().filter(other_factor).collect();
    let same_statistic: Vec<&Candidate> =
        partners.iter().copied().filter(|c| statistic(&c.features[1]) == statistic(&p)).collect();
    let second = best(same_statistic).or_else(|| best(partners));

    let mut sets: Vec<Vec<String>> = vec![vec![p.clone()]];
    match (dataset.kind(), statistic_partner(&p)) {
        (FeatureKind::Mixture, Some(sp)) => {
            // Table 10's rows: P = p, P′ = sp (its other statistic), Q = q, Q′ = sq.
            sets.push(vec![p.clone(), sp.clone()]);
            if let Some(q) = &second {
                let sq = statistic_partner(q);
                sets.push(vec![p.clone(), sp.clone(), q.clone()]);
                if let Some(sq) = &sq {
                    sets.push(vec![p.clone(), sp.clone(), q.clone(), sq.clone()]);
                }
                sets.push(vec![p.clone(), q.clone()]);
                if let Some(sq) = sq {
                    sets.push(vec![p.clone(), sp, sq]);
                }
            }
        }
        _ => sets.extend(second.iter().map(|q| vec![p.clone(), q.clone()])),
    }
    let paper: Vec<String> = match dataset.kind() {
        FeatureKind::Mixture => PAPER_MIXTURE_FEATURES.iter().map(|f| f.to_string()).collect(),
        FeatureKind::SingleForm => PAPER_SINGLE_FORM_FEATURES.iter().map(|f| f.to_string()).collect(),
    };
    let procedure_sets = sets.len();
    let same_set = |a: &[String], b: &[String]| a.len() == b.len() && a.iter().all(|f| b.contains(f));
    if !sets.iter().any(|s| same_set(s, &paper)) {
        sets.push(paper);
    }
    let paper_set = (sets.len() > procedure_sets).then_some(procedure_sets);
    let sets: Vec<Candidate> = sets.into_iter().map(|s| candidate(dataset, s, &folds, campaign)).collect();

    // The paper keeps every feature of its final set (§7.2: "generally include all four"):
    // the largest set the procedure built that fits, ties to the lower CV MAE.
    let chosen = sets[..procedure_sets]
        .iter()
        .enumerate()
        .filter_map(|(k, c)| c.mae().map(|m| (k, c.features.len(), m)))
        .max_by(|a, b| a.1.cmp(&b.1).then(b.2.total_cmp(&a.2)))
        .map(|(k, _, _)| k);

    Ok(Selection { options: *options, folds, ranking, primary, filter, pairs, second, sets, paper_set, chosen })
}

/// "μ(EQ)⁻¹ + σ(EQ)⁻¹" for a feature set.
pub fn set_label(features: &[String]) -> String {
    features.iter().map(|f| symbol(f)).collect::<Vec<_>>().join(" + ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistic_partners_swap_mean_and_std() {
        assert_eq!(statistic_partner("inv_mean_EQ").as_deref(), Some("inv_std_EQ"));
        assert_eq!(statistic_partner("std_inv_EL").as_deref(), Some("mean_inv_EL"));
        assert_eq!(statistic_partner("inv_std_inv_FL").as_deref(), Some("inv_mean_inv_FL"));
        assert_eq!(statistic_partner("inv_EQ"), None);
        assert_eq!(statistic("inv_mean_EQ"), Some("mean"));
        assert_eq!(statistic("std_inv_EL"), Some("std"));
        assert_eq!(statistic("inv_EL"), None);
    }
}
