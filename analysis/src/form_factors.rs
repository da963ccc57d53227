//! Feature names built from the 13 form factors of Table 1, and per-grain features of measured
//! (FL, EL) pairs. The formulas themselves live once, in `solver::grain`.

use std::collections::BTreeMap;

use solver::grain::{FormFactor, FormParameters, feature_names, form_statistics};

/// Table 1 abbreviations in the table's order.
pub fn factors() -> [&'static str; 13] {
    FormFactor::ALL.map(FormFactor::symbol)
}

/// Column name of the inverse of feature `name` ("EQ" → "inv_EQ").
pub fn inverse_name(name: &str) -> String {
    format!("inv_{name}")
}

/// The 26 per-grain features in Table 1 order, each followed by its inverse: FL, inv_FL, EL, …
pub fn form_feature_names() -> Vec<String> {
    feature_names()
}

/// The form of a grain of flatness FL and elongation EL: the factors depend only on axis ratios.
fn form(fl: f64, el: f64) -> FormParameters {
    FormParameters::from_flatness_elongation(fl, el, 1.0)
}

/// The 26 features of a grain of flatness FL and elongation EL, in `form_feature_names` order;
/// NaN where a factor is undefined (DRI, OPI for L = S; DRI⁻¹ for L = I; OPI⁻¹ for DRI = 1/2).
pub fn form_features(fl: f64, el: f64) -> [f64; 26] {
    let factors = form(fl, el).factors();
    let mut out = [f64::NAN; 26];
    for (k, (_, x, inv)) in factors.iter().enumerate() {
        out[2 * k] = x.unwrap_or(f64::NAN);
        out[2 * k + 1] = inv.unwrap_or(f64::NAN);
    }
    out
}

/// Number-based mean and population standard deviation of the 26 features over a set of grains
/// given as (FL, EL) pairs, keyed "FL", "inv_FL", …; NaN where any grain's value is undefined.
pub fn grain_statistics(grains: &[(f64, f64)]) -> BTreeMap<String, (f64, f64)> {
    let forms: Vec<FormParameters> = grains.iter().map(|&(fl, el)| form(fl, el)).collect();
    let mut stats: BTreeMap<String, (f64, f64)> =
        form_feature_names().into_iter().map(|name| (name, (f64::NAN, f64::NAN))).collect();
    for s in form_statistics(&forms) {
        stats.insert(s.name, (s.mean, s.std));
    }
    stats
}

/// A reader's symbol for a feature column: "inv_mean_EQ" → "μ(EQ)⁻¹", "std_inv_EL" → "σ(EL⁻¹)".
pub fn symbol(feature: &str) -> String {
    let (outer_inverse, rest) = match feature.strip_prefix("inv_") {
        Some(rest) if rest.starts_with("mean_") || rest.starts_with("std_") => (true, rest),
        _ => (false, feature),
    };
    let (statistic, factor) = if let Some(f) = rest.strip_prefix("mean_") {
        (Some("μ"), f)
    } else if let Some(f) = rest.strip_prefix("std_") {
        (Some("σ"), f)
    } else {
        (None, rest)
    };
    let factor = match factor.strip_prefix("inv_") {
        Some(f) => format!("{f}⁻¹"),
        None => factor.to_string(),
    };
    let inner = match statistic {
        Some(s) => format!("{s}({factor})"),
        None => factor,
    };
    if outer_inverse { format!("{inner}⁻¹") } else { inner }
}

/// The Table 1 factor a feature is built from: "inv_mean_inv_EQ" → "EQ".
pub fn base_factor(feature: &str) -> &str {
    let mut rest = feature;
    for prefix in ["inv_", "mean_", "std_", "inv_"] {
        rest = rest.strip_prefix(prefix).unwrap_or(rest);
    }
    rest
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_of_a_known_form_match_table_1() {
        // L = 2, I = 1, S = 0.5 by hand: FL = 0.5, EL = 0.5, EQ = 0.25, ASF = 1, CSF = 0.5/√2,
        // DRI = 1/1.5, IFI = 2.5, IRI = 0.75, JFF = 0.5/√(5.25/3), KIS = ∛(0.5/4),
        // MPS = ∛(0.25/2), OPI = 10(2/3 − 1/2)/0.25, WFI = 3.
        let f = form_features(0.5, 0.5);
        let expected = [
            0.5,
            0.5,
            0.25,
            1.0,
            0.5 / 2f64.sqrt(),
            1.0 / 1.5,
            2.5,
            0.75,
            0.5 / (5.25f64 / 3.0).sqrt(),
            (0.5f64 / 4.0).cbrt(),
            (0.25f64 / 2.0).cbrt(),
            10.0 * (2.0 / 3.0 - 0.5) / 0.25,
            3.0,
        ];
        for (k, e) in expected.iter().enumerate() {
            // 1e-12: a handful of roundings on numbers of order 1.
            assert!((f[2 * k] - e).abs() < 1e-12, "{}: {} vs {e}", factors()[k], f[2 * k]);
            assert!((f[2 * k + 1] - 1.0 / e).abs() < 1e-12, "inv_{}", factors()[k]);
        }
    }

    #[test]
    fn undefined_factors_are_nan() {
        let sphere = form_features(1.0, 1.0);
        assert!(sphere[10].is_nan() && sphere[22].is_nan(), "DRI and OPI undefined for L = S");
        let disc = form_features(0.5, 1.0); // L = I
        assert_eq!(disc[10], 0.0);
        assert!(disc[11].is_nan(), "DRI⁻¹ undefined for L = I");
    }

    #[test]
    fn symbols_and_base_factors() {
        assert_eq!(symbol("inv_mean_EQ"), "μ(EQ)⁻¹");
        assert_eq!(symbol("std_inv_EL"), "σ(EL⁻¹)");
        assert_eq!(symbol("inv_EQ"), "EQ⁻¹");
        assert_eq!(symbol("FL"), "FL");
        assert_eq!(base_factor("inv_mean_inv_EQ"), "EQ");
        assert_eq!(base_factor("inv_EL"), "EL");
        assert_eq!(base_factor("std_WFI"), "WFI");
    }
}
