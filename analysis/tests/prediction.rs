//! Applying saved models: loading with clear errors, features from μ/σ (§7.3) and from measured
//! (FL, EL) pairs, the formula by hand, and warnings outside the training range.

use std::collections::BTreeMap;

use analysis::model::{CrossValidation, LinearModel};
use analysis::paper::paper_model;
use analysis::prediction::{
    FormStatistics, PredictionError, input_from_grains, input_from_statistics, load_model, predict, read_grains_csv,
};

/// Table 2's Rhine sediment.
const RHINE: FormStatistics = FormStatistics { mu_fl: 0.647, sigma_fl: 0.175, mu_el: 0.682, sigma_el: 0.139 };

fn saved_model() -> LinearModel {
    LinearModel {
        name: "inv_mean_EQ + inv_std_EQ + inv_mean_EL".into(),
        features: vec!["inv_mean_EQ".into(), "inv_std_EQ".into(), "inv_mean_EL".into()],
        coefficients: vec![0.031, -0.0025, 0.012],
        intercept: 0.29,
        cv: Some(CrossValidation { folds: 10, mae: 0.004, r2: 0.98 }),
        ranges: BTreeMap::from([
            ("inv_mean_EQ".to_string(), [1.5, 2.2]),
            ("inv_std_EQ".to_string(), [4.0, 12.0]),
            ("inv_mean_EL".to_string(), [1.2, 2.5]),
        ]),
        campaign: Some("synthetic".into()),
    }
}

#[test]
fn features_from_mu_sigma_follow_section_7_3() {
    let input = input_from_statistics(&RHINE).unwrap();
    // μ_EQ = μ_EL μ_FL; σ_EQ² = (μ_EL² + σ_EL²)(μ_FL² + σ_FL²) − μ_EL² μ_FL².
    let mu_eq = 0.682 * 0.647;
    let sigma_eq =
        ((0.682f64.powi(2) + 0.139f64.powi(2)) * (0.647f64.powi(2) + 0.175f64.powi(2)) - mu_eq * mu_eq).sqrt();
    let f = &input.features;
    for (name, want) in [
        ("mean_EQ", mu_eq),
        ("std_EQ", sigma_eq),
        ("inv_mean_EQ", 1.0 / mu_eq),
        ("inv_std_EQ", 1.0 / sigma_eq),
        ("mean_FL", 0.647),
        ("inv_std_FL", 1.0 / 0.175),
        ("inv_mean_EL", 1.0 / 0.682),
        ("inv_std_EL", 1.0 / 0.139),
    ] {
        assert!((f[name] - want).abs() < 1e-12 * want, "{name}: {} vs {want}", f[name]);
    }
    // 0.682·0.647 = 0.441254 and σ_EQ = 0.15141 to five figures, by hand.
    assert!((mu_eq - 0.441254).abs() < 1e-9 && (sigma_eq - 0.15141).abs() < 1e-5);
    assert!(!f.contains_key("inv_EQ"), "a form distribution gives no single-form features");
}

#[test]
fn the_paper_u1_model_reproduces_table_11() {
    // Table 11: Eq. 23 predicts 0.356 for the Rhine distribution; its coefficients are printed
    // to three decimals, and the recomputation gives 0.3558, so 1e-3 covers the rounding.
    let input = input_from_statistics(&RHINE).unwrap();
    let p = predict(&paper_model("paper-U1").unwrap().model, &input).unwrap();
    assert!((p.porosity - 0.356).abs() < 1e-3, "{}", p.porosity);
}

#[test]
fn a_saved_model_predicts_the_formula_by_hand() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("model.json");
    std::fs::write(&path, serde_json::to_string_pretty(&saved_model()).unwrap()).unwrap();
    let model = load_model(&path).unwrap();
    assert_eq!(model, saved_model());
    let p = predict(&model, &input_from_statistics(&RHINE).unwrap()).unwrap();
    let mu_eq: f64 = 0.682 * 0.647;
    let sigma_eq =
        ((0.682f64.powi(2) + 0.139f64.powi(2)) * (0.647f64.powi(2) + 0.175f64.powi(2)) - mu_eq * mu_eq).sqrt();
    let by_hand = 0.031 / mu_eq - 0.0025 / sigma_eq + 0.012 / 0.682 + 0.29;
    assert!((p.porosity - by_hand).abs() < 1e-14, "{} vs {by_hand}", p.porosity);
    assert_eq!(p.features.len(), 3);
    // 1/μ_EQ = 2.266 lies above the training range [1.5, 2.2]; the other two inside.
    assert_eq!(p.warnings.len(), 1, "{:?}", p.warnings);
    assert!(
        p.warnings[0].starts_with("inv_mean_EQ = 2.2663 lies outside the training range [1.5000, 2.2000]"),
        "{}",
        p.warnings[0]
    );
}

#[test]
fn features_from_measured_grains_match_a_hand_computation() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("zingg.csv");
    std::fs::write(&path, "# three grains\nid, el ,fl\ng1,0.8,0.5\n\ng2,0.6,0.7\ng3,0.9,0.9\n").unwrap();
    let grains = read_grains_csv(&path).unwrap();
    assert_eq!(grains, [(0.5, 0.8), (0.7, 0.6), (0.9, 0.9)]);
    let input = input_from_grains(&grains, "zingg.csv").unwrap();
    let f = &input.features;
    // Per grain (I = 1, L = 1/EL, S = FL): EQ = FL·EL; WFI = (L + I)/(2S).
    let eq: [f64; 3] = [0.4, 0.42, 0.81];
    let wfi: [f64; 3] = [(1.25 + 1.0) / 1.0, (1.0 / 0.6 + 1.0) / 1.4, (1.0 / 0.9 + 1.0) / 1.8];
    let mean = |v: &[f64; 3]| (v[0] + v[1] + v[2]) / 3.0;
    let std = |v: &[f64; 3]| (v.iter().map(|x| (x - mean(v)).powi(2)).sum::<f64>() / 3.0).sqrt();
    let inv_eq = eq.map(|x| 1.0 / x);
    for (name, want) in [
        ("mean_EQ", mean(&eq)),
        ("std_EQ", std(&eq)),
        ("inv_mean_EQ", 1.0 / mean(&eq)),
        ("inv_std_EQ", 1.0 / std(&eq)),
        ("mean_inv_EQ", mean(&inv_eq)),
        ("std_inv_EQ", std(&inv_eq)),
        ("mean_WFI", mean(&wfi)),
        ("inv_std_WFI", 1.0 / std(&wfi)),
        ("inv_mean_EL", 3.0 / 2.3),
    ] {
        assert!((f[name] - want).abs() < 1e-12 * want.abs().max(1.0), "{name}: {} vs {want}", f[name]);
    }
    assert_eq!(f.len(), 104, "all mixture features are defined for these grains");
    // A model of any mixture features applies to measured grains.
    let model = LinearModel {
        features: vec!["mean_WFI".into(), "inv_std_EQ".into()],
        coefficients: vec![0.01, -0.002],
        intercept: 0.3,
        ranges: BTreeMap::new(),
        ..saved_model()
    };
    let p = predict(&model, &input).unwrap();
    assert!((p.porosity - (0.3 + 0.01 * mean(&wfi) - 0.002 / std(&eq))).abs() < 1e-14);
    assert!(p.warnings.is_empty(), "no ranges, no warnings");
}

#[test]
fn missing_features_are_named() {
    let input = input_from_statistics(&RHINE).unwrap();
    let needs_asf = LinearModel { features: vec!["mean_ASF".into()], coefficients: vec![0.1], ..saved_model() };
    let e = predict(&needs_asf, &input).unwrap_err().to_string();
    assert!(e.contains("'mean_ASF'") && e.contains("CSV of measured (FL, EL) pairs"), "{e}");

    let single = paper_model("paper-sf-U1").unwrap().model;
    let e = predict(&single, &input).unwrap_err().to_string();
    assert!(e.contains("'inv_EQ'") && e.contains("single-form feature"), "{e}");

    // σ = 0 is one form: the single-form model applies, a mixture model cannot (1/σ).
    let one_form = FormStatistics { sigma_fl: 0.0, sigma_el: 0.0, ..RHINE };
    let input = input_from_statistics(&one_form).unwrap();
    let p = predict(&single, &input).unwrap();
    // Eq. 17 by hand: 0.019/(0.647·0.682) + 0.014/0.682 + 0.278.
    assert!((p.porosity - (0.019 / (0.647 * 0.682) + 0.014 / 0.682 + 0.278)).abs() < 1e-14);
    let e = predict(&saved_model(), &input).unwrap_err().to_string();
    assert!(e.contains("'inv_std_EQ'") && e.contains("std_EQ = 0"), "{e}");
}

#[test]
fn bad_files_are_errors_naming_the_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("broken.json");
    std::fs::write(
        &path,
        r#"{"name": "m", "features": ["inv_mean_EQ"], "coefficients": [0.03], "cv": null, "campaign": null}"#,
    )
    .unwrap();
    let e = load_model(&path).unwrap_err();
    assert!(matches!(e, PredictionError::Parse { .. }));
    let text = e.to_string();
    assert!(text.contains("broken.json") && text.contains("intercept"), "{text}");

    std::fs::write(
        &path,
        r#"{"name": "m", "features": ["a", "b"], "coefficients": [0.03], "intercept": 0.2, "cv": null, "campaign": null}"#,
    )
    .unwrap();
    let text = load_model(&path).unwrap_err().to_string();
    assert!(
        text.contains("broken.json") && text.contains("key 'coefficients'") && text.contains("1 values for 2 features"),
        "{text}"
    );

    let missing = dir.path().join("nowhere.json");
    assert!(load_model(&missing).unwrap_err().to_string().contains("nowhere.json"));

    let csv = dir.path().join("grains.csv");
    std::fs::write(&csv, "FL,EL\n0.5,0.8\n0.7,x\n").unwrap();
    let text = read_grains_csv(&csv).unwrap_err().to_string();
    assert!(text.contains("grains.csv, line 3") && text.contains("'x' is not a number"), "{text}");
    std::fs::write(&csv, "FL,EL\n0.5,1.3\n").unwrap();
    assert!(read_grains_csv(&csv).unwrap_err().to_string().contains("outside (0, 1]"));
    std::fs::write(&csv, "flatness,EL\n0.5,0.8\n").unwrap();
    assert!(read_grains_csv(&csv).unwrap_err().to_string().contains("no column 'FL'"));
}
