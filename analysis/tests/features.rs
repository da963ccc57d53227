//! Feature construction from grain statistics: names, inverses, the 104 of §7.2, dropped
//! columns with reasons, single-form detection and dataset.csv.

use std::collections::BTreeMap;

use analysis::dataset::{Dataset, FeatureKind, is_single_form, mixture_feature_names};
use analysis::form_factors::{form_feature_names, grain_statistics};
use analysis::record::{Cost, JobRecord};

fn record(id: &str, porosity: f64, grains: &[(f64, f64)]) -> JobRecord {
    JobRecord {
        job_id: id.into(),
        porosity,
        profile: vec![],
        parameters: BTreeMap::new(),
        grain_statistics: grain_statistics(grains),
        size_case: None,
        experiment: None,
        paper: None,
        paper_nearest: None,
        paper_model: None,
        fluid: None,
        imbrication: None,
        size_classes: Vec::new(),
        setup: Vec::new(),
        cost: Cost::default(),
    }
}

const VARIED: [(f64, f64); 3] = [(0.5, 0.8), (0.7, 0.6), (0.9, 0.9)];

#[test]
fn mixture_features_are_the_means_stds_and_their_inverses() {
    let records =
        vec![record("a", 0.35, &VARIED), record("b", 0.33, &[(0.4, 0.5), (0.6, 0.7), (0.3, 0.9), (0.8, 0.75)])];
    assert!(!is_single_form(&records).unwrap());
    let d = Dataset::from_records(&records).unwrap();
    assert_eq!(d.kind(), FeatureKind::Mixture);
    assert_eq!(d.features().len() + d.dropped().len(), 104);
    assert!(d.dropped().is_empty(), "{:?}", d.dropped());
    assert_eq!(d.features(), mixture_feature_names());

    // Job a by hand: EQ = FL·EL per grain = 0.4, 0.42, 0.81.
    let eq: [f64; 3] = [0.5 * 0.8, 0.7 * 0.6, 0.9 * 0.9];
    let mean = (eq[0] + eq[1] + eq[2]) / 3.0;
    let std = (eq.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / 3.0).sqrt();
    let inv_eq: Vec<f64> = eq.iter().map(|e| 1.0 / e).collect();
    let mean_inv = inv_eq.iter().sum::<f64>() / 3.0;
    let expect = [
        ("mean_EQ", mean),
        ("std_EQ", std),
        ("inv_mean_EQ", 1.0 / mean),
        ("inv_std_EQ", 1.0 / std),
        ("mean_inv_EQ", mean_inv),
        ("inv_mean_inv_EQ", 1.0 / mean_inv),
        ("mean_EL", (0.8 + 0.6 + 0.9) / 3.0),
        ("inv_mean_EL", 3.0 / (0.8 + 0.6 + 0.9)),
    ];
    for (name, want) in expect {
        let got = d.column(name).unwrap()[0];
        // Sums of three numbers of order 1: a few ulps.
        assert!((got - want).abs() < 1e-12 * want.abs().max(1.0), "{name}: {got} vs {want}");
    }
}

#[test]
fn non_finite_columns_are_dropped_with_the_reason() {
    let records = vec![
        record("varied", 0.35, &VARIED),
        // A sphere (FL = EL = 1): DRI and OPI are undefined for it, so their means are NaN.
        record("sphere", 0.36, &[(1.0, 1.0), (0.6, 0.7), (0.5, 0.5)]),
        // Identical grains in a mixture campaign: σ = 0, so 1/σ is undefined.
        record("uniform", 0.34, &[(0.6, 0.7); 4]),
    ];
    let d = Dataset::from_records(&records).unwrap();
    assert_eq!(d.kind(), FeatureKind::Mixture);
    let dropped: Vec<&str> = d.dropped().iter().map(|x| x.feature.as_str()).collect();
    // Keys DRI, inv_DRI, OPI, inv_OPI: all 4 columns each (mean, std, their inverses). Then
    // inv_std_X of the 22 other keys.
    let mut expected: Vec<String> = mixture_feature_names()
        .into_iter()
        .filter(|n| n.contains("DRI") || n.contains("OPI") || n.starts_with("inv_std_"))
        .collect();
    expected.sort();
    let mut got: Vec<String> = dropped.iter().map(|s| s.to_string()).collect();
    got.sort();
    assert_eq!(got, expected);
    assert_eq!(got.len(), 16 + 22);
    assert_eq!(d.features().len(), 104 - 38);
    let reason = |f: &str| d.dropped().iter().find(|x| x.feature == f).unwrap().reason.clone();
    assert!(reason("mean_DRI").contains("job sphere"), "{}", reason("mean_DRI"));
    assert!(
        reason("inv_std_FL").contains("job uniform") && reason("inv_std_FL").contains("std_FL"),
        "{}",
        reason("inv_std_FL")
    );
    assert!(d.features().iter().all(|f| d.column(f).unwrap().iter().all(|v| v.is_finite())));
}

#[test]
fn single_form_campaigns_get_the_26_factors() {
    let records = vec![
        record("a", 0.36, &[(0.6, 0.7); 5]),
        record("b", 0.38, &[(0.4, 0.5); 5]),
        record("c", 0.35, &[(0.9, 0.8); 5]),
    ];
    assert!(is_single_form(&records).unwrap());
    let d = Dataset::from_records(&records).unwrap();
    assert_eq!(d.kind(), FeatureKind::SingleForm);
    assert_eq!(d.features(), form_feature_names());
    assert_eq!(d.features().len(), 26);
    // Job b: FL = 0.4, EL = 0.5 → EQ⁻¹ = 1/0.2 = 5, EL⁻¹ = 2 (the features of Eqs. 17–19).
    assert!((d.column("inv_EQ").unwrap()[1] - 5.0).abs() < 1e-12);
    assert!((d.column("inv_EL").unwrap()[1] - 2.0).abs() < 1e-12);
    // One mixed packing makes the campaign a mixture campaign.
    let mut mixed = records.clone();
    mixed.push(record("d", 0.33, &VARIED));
    assert!(!is_single_form(&mixed).unwrap());
}

#[test]
fn dataset_csv_has_the_header_and_one_row_per_job() {
    let records = vec![record("a", 0.36, &[(0.6, 0.7); 2]), record("b,2", 0.375, &[(0.4, 0.5); 2])];
    let csv = Dataset::from_records(&records).unwrap().to_csv();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 3);
    assert_eq!(lines[0], format!("job_id,porosity,{}", form_feature_names().join(",")));
    // The id with a comma is quoted; FL = 0.4, FL⁻¹ = 2.5, EL = 0.5, EL⁻¹ = 2 follow.
    assert!(lines[2].starts_with("\"b,2\",0.375,0.4,2.5,0.5,2,"), "{}", lines[2]);
    assert_eq!(lines[2].matches(',').count(), 1 + 1 + 26, "a quoted comma, then porosity and 26 features");
    // Shortest round-trip numbers: parsing gives back the exact values.
    let fl: f64 = lines[1].split(',').nth(2).unwrap().parse().unwrap();
    assert_eq!(fl, 0.6);
}
