//! Least squares, cross-validation, Pearson correlation and the correlation filter against
//! hand computations.

use analysis::correlation::{pearson, rank_features};
use analysis::cross_validation::{assign_folds, cross_validate};
use analysis::dataset::{Dataset, FeatureKind};
use analysis::regression::{FitError, fit_least_squares};
use analysis::selection::{SelectionOptions, filter_correlated, select_models};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn names(n: &[&str]) -> Vec<String> {
    n.iter().map(|s| s.to_string()).collect()
}

#[test]
fn least_squares_recovers_planted_coefficients_without_noise() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let x1: Vec<f64> = (0..40).map(|_| rng.random_range(1.0..5.0)).collect();
    let x2: Vec<f64> = (0..40).map(|_| rng.random_range(0.0..10.0)).collect();
    let x3: Vec<f64> = (0..40).map(|_| rng.random_range(2.0..20.0)).collect();
    let y: Vec<f64> = (0..40).map(|i| 0.287 + 0.032 * x1[i] - 0.003 * x2[i] + 0.011 * x3[i]).collect();
    let fit = fit_least_squares(&names(&["a", "b", "c"]), &[&x1, &x2, &x3], &y).unwrap();
    // Householder QR on a design with condition number ~10²: errors are a few ulps × 10², far below 1e-10.
    for (got, want) in fit.coefficients.iter().zip([0.032, -0.003, 0.011]) {
        assert!((got - want).abs() < 1e-10, "{got} vs {want}");
    }
    assert!((fit.intercept - 0.287).abs() < 1e-10, "{}", fit.intercept);
}

#[test]
fn least_squares_with_noise_stays_within_the_standard_error() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let n = 200;
    let x1: Vec<f64> = (0..n).map(|_| rng.random_range(1.0..5.0)).collect();
    let x2: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..10.0)).collect();
    let y: Vec<f64> = (0..n).map(|i| 0.30 + 0.02 * x1[i] - 0.01 * x2[i] + rng.random_range(-1e-3..1e-3)).collect();
    let fit = fit_least_squares(&names(&["a", "b"]), &[&x1, &x2], &y).unwrap();
    // Noise σ = 1e-3/√3 ≈ 5.8e-4; a slope's standard error is σ/(√n σ_x): 3.5e-5 for x1
    // (σ_x = 4/√12), 1.4e-5 for x2 (σ_x = 10/√12); the intercept's about 1.5e-4. Allow 5 of them.
    assert!((fit.coefficients[0] - 0.02).abs() < 5.0 * 3.5e-5, "{:?}", fit.coefficients);
    assert!((fit.coefficients[1] + 0.01).abs() < 5.0 * 1.4e-5, "{:?}", fit.coefficients);
    assert!((fit.intercept - 0.30).abs() < 5.0 * 1.5e-4, "{}", fit.intercept);
}

#[test]
fn degenerate_designs_are_errors_not_nan() {
    let a = [1.0, 2.0, 3.0, 4.0];
    let b = [2.0, 1.0, 0.0, 5.0];
    let sum: Vec<f64> = a.iter().zip(&b).map(|(x, y)| 2.0 * x - y).collect();
    let y = [0.3, 0.31, 0.33, 0.32];
    assert_eq!(
        fit_least_squares(&names(&["a", "b"]), &[&a[..2], &b[..2]], &y[..2]),
        Err(FitError::TooFewRows { rows: 2, parameters: 3, features: 2 })
    );
    assert_eq!(
        fit_least_squares(&names(&["a", "b", "2a-b"]), &[&a, &b, &sum], &y),
        Err(FitError::Collinear { feature: "2a-b".into(), others: names(&["a", "b"]) })
    );
    assert_eq!(
        fit_least_squares(&names(&["a", "k"]), &[&a, &[0.5; 4]], &y),
        Err(FitError::Constant { feature: "k".into(), rows: 4 })
    );
    assert_eq!(fit_least_squares(&[], &[], &y), Err(FitError::NoFeatures));
}

#[test]
fn cross_validation_mae_matches_a_hand_computation() {
    let x = [1.0, 2.0, 3.0, 4.0];
    let y = [1.0, 2.5, 2.5, 4.5];
    let folds = [0, 1, 0, 1];
    let cv = cross_validate(&names(&["x"]), &[&x], &y, &folds).unwrap();
    // Fold 0 held out (rows 0, 2): the line through (2, 2.5), (4, 4.5) is y = x + 0.5, predicting
    // 1.5 and 3.5. Fold 1 held out (rows 1, 3): the line through (1, 1), (3, 2.5) is
    // y = 0.75x + 0.25, predicting 1.75 and 3.25.
    let predicted = [1.5, 1.75, 3.5, 3.25];
    for (got, want) in cv.predictions.iter().zip(predicted) {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
    // |errors| 0.5, 0.75, 1.0, 1.25 → MAE 3.5/4. Squared 0.25 + 0.5625 + 1 + 1.5625 = 3.375;
    // mean 2.625, Σ(y − ȳ)² = 1.625² + 0.125² + 0.125² + 1.875² = 6.1875.
    assert!((cv.metrics.mae - 0.875).abs() < 1e-12, "{}", cv.metrics.mae);
    assert!((cv.metrics.r2 - (1.0 - 3.375 / 6.1875)).abs() < 1e-12, "{}", cv.metrics.r2);
    assert_eq!(cv.metrics.folds, 2);
}

#[test]
fn leave_one_out_when_k_exceeds_the_rows() {
    // Three rows, k = 10 → three folds of one row; y = 2x + 1 exactly, so every held-out
    // prediction is exact.
    let x = [0.0, 1.0, 3.0];
    let y = [1.0, 3.0, 7.0];
    let folds = assign_folds(3, 10, 42);
    let cv = cross_validate(&names(&["x"]), &[&x], &y, &folds).unwrap();
    assert_eq!(cv.metrics.folds, 3);
    assert!(cv.metrics.mae < 1e-12);
}

/// Two-pass Pearson written out independently of the library's one-pass update.
fn two_pass(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    let syy: f64 = y.iter().map(|b| (b - my).powi(2)).sum();
    sxy / (sxx * syy).sqrt()
}

#[test]
fn pearson_equals_a_two_pass_computation() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for offset in [0.0, 1e4] {
        let x: Vec<f64> = (0..57).map(|_| offset + rng.random_range(0.0..1.0)).collect();
        let y: Vec<f64> = x.iter().map(|v| 0.5 * v + rng.random_range(0.0..0.3)).collect();
        let z: Vec<f64> = (0..57).map(|_| rng.random_range(-1.0..1.0)).collect();
        for (a, b) in [(&x, &y), (&x, &z), (&y, &z)] {
            let want = two_pass(a, b);
            // Both are backward stable; with an offset of 1e4 on unit spreads the relative
            // rounding is ~1e4 · 1e-16, so 1e-10 leaves a wide margin.
            assert!((pearson(a, b).unwrap() - want).abs() < 1e-10, "offset {offset}: {want}");
        }
    }
}

/// Orthogonal, centred unit vectors u, v: the feature ρu + √(1−ρ²)v has r = ρ with u.
fn correlated(rho: f64) -> Vec<f64> {
    let u = [0.5, -0.5, 0.5, -0.5, 0.0, 0.0];
    let v = [0.5, 0.5, -0.5, -0.5, 0.0, 0.0];
    u.iter().zip(&v).map(|(a, b)| 1.0 + rho * a + (1.0 - rho * rho).sqrt() * b).collect()
}

#[test]
fn the_filter_removes_exactly_the_features_above_the_threshold() {
    let u = correlated(1.0);
    let porosity: Vec<f64> = u.iter().map(|x| 0.3 + 0.01 * x).collect();
    let columns = vec![
        ("near".to_string(), correlated(0.95)),
        ("primary".to_string(), u.clone()),
        ("opposite".to_string(), correlated(-0.81)),
        ("edge".to_string(), correlated(0.79)),
        ("free".to_string(), correlated(0.1)),
    ];
    let ids = (0..6).map(|k| format!("job{k}")).collect();
    let dataset = Dataset::from_columns(FeatureKind::SingleForm, ids, porosity, columns).unwrap();
    let ranking = rank_features(&dataset);
    assert_eq!(ranking.primary(&dataset).unwrap().feature, "primary");
    let filter = filter_correlated(&dataset, "primary", dataset.features(), 0.8).unwrap();
    let removed: Vec<&str> = filter.removed.iter().map(|c| c.feature.as_str()).collect();
    let kept: Vec<&str> = filter.kept.iter().map(|c| c.feature.as_str()).collect();
    assert_eq!(removed, ["near", "opposite"]);
    assert_eq!(kept, ["edge", "free"]);
    assert!((filter.removed[1].r + 0.81).abs() < 1e-12);
    // The procedure applies the same filter; its lists follow the ranking, so compare as sets.
    let selection = select_models(&dataset, "c", &SelectionOptions { folds: 3, ..Default::default() }).unwrap();
    let mut removed_by_procedure: Vec<&str> = selection.filter.removed.iter().map(|c| c.feature.as_str()).collect();
    removed_by_procedure.sort_unstable();
    assert_eq!(removed_by_procedure, ["near", "opposite"]);
    // A primary that is not a column is an error, not a panic.
    let unknown = filter_correlated(&dataset, "nowhere", dataset.features(), 0.8).unwrap_err();
    assert!(unknown.to_string().contains("'nowhere'"), "{unknown}");
}

#[test]
fn ties_in_correlation_go_to_the_earlier_column() {
    let x = vec![1.0, 2.0, 4.0, 3.0];
    let porosity = vec![0.30, 0.32, 0.35, 0.33];
    let columns = vec![("second".to_string(), x.clone()), ("first".to_string(), x)];
    let ids = (0..4).map(|k| format!("j{k}")).collect();
    let dataset = Dataset::from_columns(FeatureKind::SingleForm, ids, porosity, columns).unwrap();
    assert_eq!(rank_features(&dataset).primary(&dataset).unwrap().feature, "second");
}

#[test]
fn the_procedure_builds_table_10_and_keeps_all_four_features() {
    // Independent features planted like Eq. 24: the procedure must find μ(EQ)⁻¹ as primary,
    // μ(EL)⁻¹ as the second factor (the decoy mean_FL carries nothing), and Table 10's rows.
    let mut rng = ChaCha8Rng::seed_from_u64(24);
    let n = 52;
    let mut draw = |lo: f64, hi: f64| (0..n).map(|_| rng.random_range(lo..hi)).collect::<Vec<f64>>();
    let (x1, x2, x3, x4, decoy) = (draw(1.5, 6.0), draw(4.0, 12.0), draw(1.2, 2.5), draw(5.0, 10.0), draw(0.3, 0.9));
    let noise = draw(-1e-4, 1e-4);
    let porosity: Vec<f64> =
        (0..n).map(|i| 0.24 + 0.024 * x1[i] - 0.003 * x2[i] + 0.02 * x3[i] + 0.001 * x4[i] + noise[i]).collect();
    let columns = vec![
        ("mean_FL".to_string(), decoy),
        ("inv_mean_EL".to_string(), x3),
        ("inv_std_EL".to_string(), x4),
        ("inv_mean_EQ".to_string(), x1),
        ("inv_std_EQ".to_string(), x2),
    ];
    let ids = (0..n).map(|k| format!("j{k}")).collect();
    let dataset = Dataset::from_columns(FeatureKind::Mixture, ids, porosity, columns).unwrap();
    let s = select_models(&dataset, "fm", &SelectionOptions::default()).unwrap();
    assert_eq!(s.primary.feature, "inv_mean_EQ");
    assert_eq!(s.second.as_deref(), Some("inv_mean_EL"));
    let sets: Vec<Vec<String>> = s.sets.iter().map(|c| c.features.clone()).collect();
    let p = "inv_mean_EQ";
    assert_eq!(
        sets,
        [
            names(&[p]),
            names(&[p, "inv_std_EQ"]),
            names(&[p, "inv_std_EQ", "inv_mean_EL"]),
            names(&[p, "inv_std_EQ", "inv_mean_EL", "inv_std_EL"]),
            names(&[p, "inv_mean_EL"]),
            names(&[p, "inv_std_EQ", "inv_std_EL"]),
        ]
    );
    assert_eq!(s.paper_set, None, "the procedure reached the paper's set itself");
    assert_eq!(s.chosen, Some(3));
    let chosen = &s.chosen_model().unwrap().model;
    // Noise ±1e-4 over feature spreads of 1–8: coefficient errors ~1e-5; 2e-4 is a safe bound
    // that still tells 0.001 from 0.
    for (got, want) in chosen.coefficients.iter().zip([0.024, -0.003, 0.02, 0.001]) {
        assert!((got - want).abs() < 2e-4, "{:?}", chosen.coefficients);
    }
    assert_eq!(chosen.cv.unwrap().folds, 10);
}

#[test]
fn constant_porosity_is_an_error() {
    let ids = (0..4).map(|k| format!("j{k}")).collect();
    let columns = vec![("a".to_string(), vec![1.0, 2.0, 3.0, 5.0])];
    let dataset = Dataset::from_columns(FeatureKind::SingleForm, ids, vec![0.35; 4], columns).unwrap();
    assert_eq!(
        select_models(&dataset, "c", &SelectionOptions::default()),
        Err(analysis::selection::SelectionError::ConstantPorosity)
    );
}
