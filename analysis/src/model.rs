//! Linear porosity models n = Σ c_k x_k + c_0 over named features, saved as JSON.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use thiserror::Error;

#[derive(Debug, Error, PartialEq)]
pub enum ModelError {
    #[error("model '{model}' needs feature '{feature}', which was not given")]
    MissingFeature { model: String, feature: String },
    #[error("model '{model}': feature '{feature}' is {value}, not a finite number")]
    NonFinite { model: String, feature: String, value: f64 },
    #[error("model '{model}' has {features} features but {coefficients} coefficients")]
    Shape { model: String, features: usize, coefficients: usize },
}

/// k-fold cross-validation metrics of a fitted model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CrossValidation {
    pub folds: usize,
    /// Mean absolute error of the held-out predictions.
    pub mae: f64,
    /// Coefficient of determination.
    pub r2: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinearModel {
    pub name: String,
    /// Column names of the feature table (dataset.csv).
    pub features: Vec<String>,
    pub coefficients: Vec<f64>,
    pub intercept: f64,
    pub cv: Option<CrossValidation>,
    /// Training range [min, max] of each feature.
    #[serde(default)]
    pub ranges: BTreeMap<String, [f64; 2]>,
    pub campaign: Option<String>,
}

impl LinearModel {
    /// Porosity for the given feature values.
    pub fn predict(&self, values: &BTreeMap<String, f64>) -> Result<f64, ModelError> {
        if self.features.len() != self.coefficients.len() {
            return Err(ModelError::Shape {
                model: self.name.clone(),
                features: self.features.len(),
                coefficients: self.coefficients.len(),
            });
        }
        let mut n = self.intercept;
        for (feature, c) in self.features.iter().zip(&self.coefficients) {
            let x = *values
                .get(feature)
                .ok_or_else(|| ModelError::MissingFeature { model: self.name.clone(), feature: feature.clone() })?;
            if !x.is_finite() {
                return Err(ModelError::NonFinite { model: self.name.clone(), feature: feature.clone(), value: x });
            }
            n += c * x;
        }
        Ok(n)
    }

    /// Features whose value lies outside the training range, with the range.
    pub fn out_of_range(&self, values: &BTreeMap<String, f64>) -> Vec<(String, f64, [f64; 2])> {
        self.features
            .iter()
            .filter_map(|f| {
                let range = *self.ranges.get(f)?;
                let x = *values.get(f)?;
                (x < range[0] || x > range[1]).then(|| (f.clone(), x, range))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> LinearModel {
        LinearModel {
            name: "m".into(),
            features: vec!["a".into(), "b".into()],
            coefficients: vec![2.0, -0.5],
            intercept: 0.25,
            cv: None,
            ranges: BTreeMap::from([("a".to_string(), [0.0, 1.0])]),
            campaign: None,
        }
    }

    #[test]
    fn predicts_the_linear_combination_and_flags_extrapolation() {
        let values = BTreeMap::from([("a".to_string(), 1.5), ("b".to_string(), 4.0)]);
        // 2·1.5 − 0.5·4 + 0.25 = 1.25
        assert_eq!(model().predict(&values), Ok(1.25));
        assert_eq!(model().out_of_range(&values), vec![("a".to_string(), 1.5, [0.0, 1.0])]);
        let missing = BTreeMap::from([("a".to_string(), 0.5)]);
        assert!(matches!(model().predict(&missing), Err(ModelError::MissingFeature { .. })));
    }

    #[test]
    fn json_round_trip_keeps_every_field() {
        let m = LinearModel { cv: Some(CrossValidation { folds: 10, mae: 0.004, r2: 0.98 }), ..model() };
        let text = serde_json::to_string(&m).unwrap();
        assert_eq!(serde_json::from_str::<LinearModel>(&text).unwrap(), m);
    }
}
