//! Ordinary least squares n = Σ c_k x_k + c_0 through linfa-linear, whose solver is a
//! Householder QR of the design (no normal equations, so the condition number is not squared).
//! linfa only refuses an exactly singular R and silently returns a minimum-norm solution for
//! fewer rows than unknowns, so the design is checked here first, with errors naming features.

use linfa::traits::Fit as _;
use linfa_linear::LinearRegression;
use ndarray::{Array1, Array2};
use thiserror::Error;

/// Relative residual below which a centred column counts as a combination of the columns
/// before it: coefficients of such a design would be set by rounding (condition number ≳ 1e9).
pub const COLLINEARITY_TOLERANCE: f64 = 1e-9;

#[derive(Debug, Error, PartialEq)]
pub enum FitError {
    #[error("a linear fit needs at least one feature")]
    NoFeatures,
    #[error("{rows} rows cannot determine {parameters} parameters ({features} coefficients and the intercept)")]
    TooFewRows { rows: usize, parameters: usize, features: usize },
    #[error("feature '{feature}' is constant over the {rows} rows, so its coefficient is not determined")]
    Constant { feature: String, rows: usize },
    #[error("feature '{feature}' is a linear combination of {others:?} (and the intercept) on these rows")]
    Collinear { feature: String, others: Vec<String> },
    #[error("feature '{feature}' has a non-finite value in row {row}")]
    NonFinite { feature: String, row: usize },
    #[error("least squares failed: {0}")]
    Solver(String),
}

/// Coefficients (in feature order) and intercept of a least-squares fit.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    pub coefficients: Vec<f64>,
    pub intercept: f64,
}

impl Fit {
    /// Σ c_k x_k + c_0 for one row of feature values.
    pub fn predict(&self, x: &[f64]) -> f64 {
        self.intercept + self.coefficients.iter().zip(x).map(|(c, v)| c * v).sum::<f64>()
    }
}

/// Least-squares fit of `y` on the named feature columns plus an intercept.
pub fn fit_least_squares(names: &[String], columns: &[&[f64]], y: &[f64]) -> Result<Fit, FitError> {
    assert_eq!(names.len(), columns.len(), "one name per column");
    if columns.is_empty() {
        return Err(FitError::NoFeatures);
    }
    let rows = y.len();
    let parameters = columns.len() + 1;
    if rows < parameters {
        return Err(FitError::TooFewRows { rows, parameters, features: columns.len() });
    }
    for (name, column) in names.iter().zip(columns) {
        assert_eq!(column.len(), rows, "column '{name}' has one value per row");
        if let Some(row) = column.iter().position(|v| !v.is_finite()) {
            return Err(FitError::NonFinite { feature: name.clone(), row });
        }
    }
    check_rank(names, columns)?;
    let x = Array2::from_shape_fn((rows, columns.len()), |(i, j)| columns[j][i]);
    let targets = Array1::from_vec(y.to_vec());
    let fitted =
        LinearRegression::new().fit(&linfa::Dataset::new(x, targets)).map_err(|e| FitError::Solver(e.to_string()))?;
    let fit = Fit { coefficients: fitted.params().to_vec(), intercept: fitted.intercept() };
    if fit.coefficients.iter().chain([&fit.intercept]).all(|c| c.is_finite()) {
        Ok(fit)
    } else {
        Err(FitError::Solver(format!("non-finite parameters {:?} + {}", fit.coefficients, fit.intercept)))
    }
}

/// Modified Gram–Schmidt on the centred, unit-length columns (centring accounts for the
/// intercept): a column with (almost) nothing left after removing the earlier ones is dependent.
fn check_rank(names: &[String], columns: &[&[f64]]) -> Result<(), FitError> {
    let rows = columns[0].len();
    let mut basis: Vec<Vec<f64>> = Vec::new();
    for (k, column) in columns.iter().enumerate() {
        let mean = column.iter().sum::<f64>() / rows as f64;
        let mut v: Vec<f64> = column.iter().map(|x| x - mean).collect();
        let scale = column.iter().fold(0.0f64, |m, x| m.max(x.abs())) * (rows as f64).sqrt();
        let length = norm(&v);
        if length <= 1e-12 * scale {
            return Err(FitError::Constant { feature: names[k].clone(), rows });
        }
        v.iter_mut().for_each(|x| *x /= length);
        for b in &basis {
            let p: f64 = v.iter().zip(b).map(|(x, y)| x * y).sum();
            v.iter_mut().zip(b).for_each(|(x, y)| *x -= p * y);
        }
        let left = norm(&v);
        if left < COLLINEARITY_TOLERANCE {
            return Err(FitError::Collinear { feature: names[k].clone(), others: names[..k].to_vec() });
        }
        v.iter_mut().for_each(|x| *x /= left);
        basis.push(v);
    }
    Ok(())
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}
