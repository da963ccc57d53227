//! Applying a saved model to new sediment (§7.3): load the model JSON, build the features it
//! needs from μ/σ of FL and EL (independent FL and EL) or from measured (FL, EL) pairs of real
//! grains, and predict, warning where the input leaves the training range.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Serialize;
use thiserror::Error;

use crate::csv::{CsvError, read_columns};
use crate::dataset::{
    DroppedFeature, is_single_form_statistics, mixture_feature_names, mixture_features, single_form_features,
};
use solver::grain::FormDistribution;

use crate::form_factors::{form_feature_names, form_features, grain_statistics, inverse_name};
use crate::model::{LinearModel, ModelError};

#[derive(Debug, Error)]
pub enum PredictionError {
    #[error("{path}: cannot read: {source}")]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}: not a model JSON ({{\"name\", \"features\", \"coefficients\", \"intercept\", …}}): {message}")]
    Parse { path: PathBuf, message: String },
    #[error("{path}: key '{key}': {message}")]
    InvalidModel { path: PathBuf, key: String, message: String },
    #[error(transparent)]
    Csv(#[from] CsvError),
    #[error("{0}")]
    InvalidInput(String),
    #[error("model '{model}' needs feature '{feature}', which {input} cannot give: {why}")]
    MissingFeature { model: String, feature: String, input: String, why: String },
    #[error(transparent)]
    Model(#[from] ModelError),
}

/// Number-based mean and standard deviation of flatness and elongation (Table 2's columns).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FormStatistics {
    pub mu_fl: f64,
    pub sigma_fl: f64,
    pub mu_el: f64,
    pub sigma_el: f64,
}

/// Where a model's input came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum InputSource {
    /// μ/σ of FL and EL: only FL, EL and EQ statistics follow.
    Statistics,
    /// Measured (FL, EL) pairs: every Table 1 factor per grain.
    Grains,
}

/// The features an input can give a model, and those it cannot, with the reason.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelInput {
    pub source: InputSource,
    /// What the input is, for messages: "μ/σ of FL and EL", "12 grains of FILE".
    pub description: String,
    pub features: BTreeMap<String, f64>,
    pub unavailable: Vec<DroppedFeature>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Prediction {
    pub model: String,
    pub porosity: f64,
    /// The values of the model's features that were used.
    pub features: BTreeMap<String, f64>,
    pub warnings: Vec<String>,
}

/// Reads and checks a model saved by the report (or written by hand).
pub fn load_model(path: &Path) -> Result<LinearModel, PredictionError> {
    let text = std::fs::read_to_string(path).map_err(|source| PredictionError::Read { path: path.into(), source })?;
    let model: LinearModel = serde_json::from_str(&text)
        .map_err(|e| PredictionError::Parse { path: path.into(), message: e.to_string() })?;
    let invalid =
        |key: &str, message: String| PredictionError::InvalidModel { path: path.into(), key: key.into(), message };
    if model.features.is_empty() {
        return Err(invalid("features", "the list is empty".into()));
    }
    if model.coefficients.len() != model.features.len() {
        return Err(invalid(
            "coefficients",
            format!("{} values for {} features", model.coefficients.len(), model.features.len()),
        ));
    }
    for (feature, range) in &model.ranges {
        if !model.features.contains(feature) {
            return Err(invalid(&format!("ranges.{feature}"), "not one of the model's features".into()));
        }
        if range[0] > range[1] {
            return Err(invalid(&format!("ranges.{feature}"), format!("min {} exceeds max {}", range[0], range[1])));
        }
    }
    Ok(model)
}

/// Features from μ/σ of FL and EL: the mean and std of FL, EL and EQ (μ_EQ = μ_EL μ_FL,
/// σ_EQ² = (μ_EL² + σ_EL²)(μ_FL² + σ_FL²) − μ_EL² μ_FL², §7.3) and their inverses; for σ = 0
/// (one form) also the 26 single-form features.
pub fn input_from_statistics(s: &FormStatistics) -> Result<ModelInput, PredictionError> {
    for (name, mu) in [("mu_fl", s.mu_fl), ("mu_el", s.mu_el)] {
        if !(mu > 0.0 && mu <= 1.0) {
            return Err(PredictionError::InvalidInput(format!(
                "{name} = {mu} is out of range: a mean form factor lies in (0, 1]"
            )));
        }
    }
    for (name, sigma) in [("sigma_fl", s.sigma_fl), ("sigma_el", s.sigma_el)] {
        if !(sigma >= 0.0 && sigma.is_finite()) {
            return Err(PredictionError::InvalidInput(format!(
                "{name} = {sigma} is out of range: a standard deviation is ≥ 0"
            )));
        }
    }
    let (mu_eq, sigma_eq) =
        FormDistribution { mu_fl: s.mu_fl, sigma_fl: s.sigma_fl, mu_el: s.mu_el, sigma_el: s.sigma_el }
            .equancy_statistics();
    let mut features = BTreeMap::new();
    let mut unavailable = Vec::new();
    for (key, mean, std) in [("FL", s.mu_fl, s.sigma_fl), ("EL", s.mu_el, s.sigma_el), ("EQ", mu_eq, sigma_eq)] {
        for (statistic, value) in [("mean", mean), ("std", std)] {
            let name = format!("{statistic}_{key}");
            features.insert(name.clone(), value);
            if value > 0.0 {
                features.insert(inverse_name(&name), 1.0 / value);
            } else {
                unavailable.push(DroppedFeature {
                    feature: inverse_name(&name),
                    reason: format!(
                        "{name} = 0 (one form), and a form-mixture model is invalid without form variance (§7.2)"
                    ),
                });
            }
        }
    }
    if s.sigma_fl == 0.0 && s.sigma_el == 0.0 {
        let values = form_features(s.mu_fl, s.mu_el);
        for (name, v) in form_feature_names().into_iter().zip(values) {
            if v.is_finite() {
                features.insert(name, v);
            } else {
                unavailable.push(DroppedFeature { feature: name, reason: "undefined for this form (Table 1)".into() });
            }
        }
    }
    Ok(ModelInput { source: InputSource::Statistics, description: "μ/σ of FL and EL".into(), features, unavailable })
}

/// Features from measured grains: every Table 1 factor per grain, their number-based mean and
/// std and the inverses (the 104 mixture features); for identical grains also the 26
/// single-form features.
pub fn input_from_grains(grains: &[(f64, f64)], description: &str) -> Result<ModelInput, PredictionError> {
    if grains.is_empty() {
        return Err(PredictionError::InvalidInput(format!("{description}: no grains")));
    }
    for (k, &(fl, el)) in grains.iter().enumerate() {
        if !(fl > 0.0 && fl <= 1.0 && el > 0.0 && el <= 1.0) {
            return Err(PredictionError::InvalidInput(format!(
                "{description}: grain {} has FL = {fl}, EL = {el}; both lie in (0, 1]",
                k + 1
            )));
        }
    }
    Ok(input_from_grain_statistics(&grain_statistics(grains), description))
}

/// Features from the number-based (mean, std) of every Table 1 factor over some grains (a
/// packing's or measured ones): the 104 mixture features and, for one form, the 26 single-form
/// features.
pub fn input_from_grain_statistics(stats: &BTreeMap<String, (f64, f64)>, description: &str) -> ModelInput {
    let (mut features, mut unavailable) = mixture_features(stats);
    if is_single_form_statistics(stats) == Some(true) {
        let (single, undefined) = single_form_features(stats);
        features.extend(single);
        unavailable.extend(undefined);
    }
    ModelInput { source: InputSource::Grains, description: description.to_string(), features, unavailable }
}

/// (FL, EL) pairs from a CSV whose header names columns FL and EL (any case, any order, other
/// columns ignored); blank lines and lines starting with '#' are skipped.
pub fn read_grains_csv(path: &Path) -> Result<Vec<(f64, f64)>, PredictionError> {
    read_columns(path, &["FL", "EL"])?
        .into_iter()
        .map(|(line, values)| {
            for (name, v) in ["FL", "EL"].iter().zip(&values) {
                if !(*v > 0.0 && *v <= 1.0) {
                    let message = format!("column '{name}': {v} is outside (0, 1]");
                    return Err(CsvError::Line { path: path.into(), line, message }.into());
                }
            }
            Ok((values[0], values[1]))
        })
        .collect()
}

/// The model's porosity for an input, with a warning for every feature outside the training
/// range; an error naming the feature when the input cannot give one.
pub fn predict(model: &LinearModel, input: &ModelInput) -> Result<Prediction, PredictionError> {
    let mut used = BTreeMap::new();
    for feature in &model.features {
        let Some(&v) = input.features.get(feature) else {
            let why = match input.unavailable.iter().find(|d| &d.feature == feature) {
                Some(d) => d.reason.clone(),
                None => missing_reason(feature, input.source),
            };
            return Err(PredictionError::MissingFeature {
                model: model.name.clone(),
                feature: feature.clone(),
                input: input.description.clone(),
                why,
            });
        };
        used.insert(feature.clone(), v);
    }
    let porosity = model.predict(&used)?;
    let warnings = model
        .out_of_range(&used)
        .into_iter()
        .map(|(f, v, [lo, hi])| {
            format!("{f} = {v:.4} lies outside the training range [{lo:.4}, {hi:.4}]: the model extrapolates")
        })
        .collect();
    Ok(Prediction { model: model.name.clone(), porosity, features: used, warnings })
}

/// Why an input lacks a feature that it does not list as unavailable.
fn missing_reason(feature: &str, source: InputSource) -> String {
    if mixture_feature_names().iter().any(|f| f == feature) {
        match source {
            InputSource::Statistics => "only the mean and std of FL, EL and EQ follow from μ/σ of FL and EL (§7.3); give a CSV of measured (FL, EL) pairs".into(),
            InputSource::Grains => "the grain statistics do not define it".into(),
        }
    } else if form_feature_names().iter().any(|f| f == feature) {
        "it is a single-form feature, and the input is a form mixture (σ of FL or EL > 0)".into()
    } else {
        "it is not a feature sedpack builds: X or inv_X for a Table 1 factor X, or mean_, std_, inv_mean_, inv_std_ of those"
            .into()
    }
}
