//! k-fold cross-validation (§6.3.3: 10-fold, MAE as the robust measure; Table 10 adds R²).
//! Every row is predicted once by the model fitted without its fold; MAE and R² are of those
//! held-out predictions.

use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use thiserror::Error;

use crate::model::CrossValidation;
use crate::regression::{FitError, fit_least_squares};

#[derive(Debug, Error, PartialEq)]
pub enum CvError {
    #[error("cross-validation needs at least 2 folds, got {folds} (from {rows} rows)")]
    TooFewFolds { folds: usize, rows: usize },
    #[error("fold {fold} of {folds}: {source}")]
    Fold {
        fold: usize,
        folds: usize,
        #[source]
        source: FitError,
    },
    #[error("porosity is the same for every row, so R² is undefined")]
    ConstantPorosity,
    #[error("{folds} fold ids for {rows} rows: expected one per row")]
    FoldCount { folds: usize, rows: usize },
}

/// Held-out metrics and each row's held-out prediction.
#[derive(Debug, Clone, PartialEq)]
pub struct CvOutcome {
    pub metrics: CrossValidation,
    pub predictions: Vec<f64>,
}

/// Fold of each row: k is capped at the number of rows, rows are shuffled by a ChaCha8 stream
/// from `seed` and dealt round-robin, so fold sizes differ by at most one.
pub fn assign_folds(rows: usize, k: usize, seed: u64) -> Vec<usize> {
    let k = k.min(rows).max(1);
    let mut order: Vec<usize> = (0..rows).collect();
    order.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
    let mut folds = vec![0; rows];
    for (position, &row) in order.iter().enumerate() {
        folds[row] = position % k;
    }
    folds
}

/// Cross-validates the least-squares model of `y` on the named columns over the given fold of
/// each row (fold ids 0, 1, …; the number of folds is the number of distinct ids).
pub fn cross_validate(names: &[String], columns: &[&[f64]], y: &[f64], folds: &[usize]) -> Result<CvOutcome, CvError> {
    if folds.len() != y.len() {
        return Err(CvError::FoldCount { folds: folds.len(), rows: y.len() });
    }
    let mut ids: Vec<usize> = folds.to_vec();
    ids.sort_unstable();
    ids.dedup();
    if ids.len() < 2 {
        return Err(CvError::TooFewFolds { folds: ids.len(), rows: y.len() });
    }
    let mut predictions = vec![f64::NAN; y.len()];
    for &fold in &ids {
        let train: Vec<usize> = (0..y.len()).filter(|&i| folds[i] != fold).collect();
        let pick = |v: &[f64]| train.iter().map(|&i| v[i]).collect::<Vec<f64>>();
        let train_columns: Vec<Vec<f64>> = columns.iter().map(|c| pick(c)).collect();
        let train_refs: Vec<&[f64]> = train_columns.iter().map(Vec::as_slice).collect();
        let fit = fit_least_squares(names, &train_refs, &pick(y)).map_err(|source| CvError::Fold {
            fold,
            folds: ids.len(),
            source,
        })?;
        for i in (0..y.len()).filter(|&i| folds[i] == fold) {
            let row: Vec<f64> = columns.iter().map(|c| c[i]).collect();
            predictions[i] = fit.predict(&row);
        }
    }
    let n = y.len() as f64;
    let mean = y.iter().sum::<f64>() / n;
    let total: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
    let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if total <= (1e-12 * scale).powi(2) * n {
        return Err(CvError::ConstantPorosity);
    }
    let residual: f64 = y.iter().zip(&predictions).map(|(a, p)| (a - p).powi(2)).sum();
    let mae = y.iter().zip(&predictions).map(|(a, p)| (a - p).abs()).sum::<f64>() / n;
    Ok(CvOutcome { metrics: CrossValidation { folds: ids.len(), mae, r2: 1.0 - residual / total }, predictions })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folds_are_balanced_seeded_and_capped() {
        let folds = assign_folds(23, 10, 7);
        let mut sizes = [0usize; 10];
        folds.iter().for_each(|&f| sizes[f] += 1);
        assert_eq!(sizes.iter().sum::<usize>(), 23);
        assert!(sizes.iter().all(|&s| s == 2 || s == 3), "{sizes:?}");
        assert_eq!(folds, assign_folds(23, 10, 7), "same seed, same folds");
        assert_ne!(folds, assign_folds(23, 10, 8), "another seed shuffles differently");
        let capped = assign_folds(4, 10, 1);
        let mut ids = capped.clone();
        ids.sort_unstable();
        assert_eq!(ids, [0, 1, 2, 3], "k capped at the rows: leave-one-out");
    }

    #[test]
    fn fold_ids_that_do_not_match_the_rows_are_an_error() {
        let x = [1.0, 2.0, 3.0];
        let outcome = cross_validate(&["x".into()], &[&x], &[0.3, 0.4, 0.5], &[0, 1]);
        assert_eq!(outcome, Err(CvError::FoldCount { folds: 2, rows: 3 }));
    }
}
