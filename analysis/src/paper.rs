//! The porosity models published in the paper: single-form models (Eqs. 17–19, features
//! L/S = EQ⁻¹ and L/I = EL⁻¹) and form-mixture models (Eqs. 23–24, features built from the
//! number-based mean and standard deviation of EQ and EL).

use std::collections::BTreeMap;

use crate::model::{CrossValidation, LinearModel};

/// Whether a paper model takes one form (FL, EL) or a form distribution (μ, σ of FL and EL).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PaperModelKind {
    SingleForm,
    FormMixture,
}

pub struct PaperModel {
    pub kind: PaperModelKind,
    pub model: LinearModel,
}

fn model(
    name: &str,
    equation: &str,
    features: &[&str],
    coefficients: &[f64],
    intercept: f64,
    cv: Option<CrossValidation>,
) -> LinearModel {
    LinearModel {
        name: name.into(),
        features: features.iter().map(|f| f.to_string()).collect(),
        coefficients: coefficients.to_vec(),
        intercept,
        cv,
        ranges: BTreeMap::new(),
        campaign: Some(format!("Rettinger et al. (2022), {equation}")),
    }
}

/// Names accepted by `sedpack predict --model`.
pub const PAPER_MODEL_NAMES: [&str; 5] = ["paper-U1", "paper-U7", "paper-sf-U1", "paper-sf-U7", "paper-sf-B50"];

/// A published model by name, with its CV metrics where the paper gives them: Table 10's row
/// with all four features (Eq. 23 prints three; the σ_EL coefficient rounds to zero for U1).
pub fn paper_model(name: &str) -> Option<PaperModel> {
    let single = ["inv_EQ", "inv_EL"];
    let mixture_u1 = ["inv_mean_EQ", "inv_std_EQ", "inv_mean_EL"];
    let mixture_u7 = ["inv_mean_EQ", "inv_std_EQ", "inv_mean_EL", "inv_std_EL"];
    let (kind, model) = match name {
        "paper-sf-U1" => (PaperModelKind::SingleForm, model(name, "Eq. 17", &single, &[0.019, 0.014], 0.278, None)),
        "paper-sf-U7" => (PaperModelKind::SingleForm, model(name, "Eq. 18", &single, &[0.014, 0.007], 0.234, None)),
        "paper-sf-B50" => (PaperModelKind::SingleForm, model(name, "Eq. 19", &single, &[0.014, -0.006], 0.217, None)),
        "paper-U1" => (
            PaperModelKind::FormMixture,
            model(
                name,
                "Eq. 23",
                &mixture_u1,
                &[0.032, -0.003, 0.011],
                0.287,
                Some(CrossValidation { folds: 10, mae: 4.33e-3, r2: 0.980 }),
            ),
        ),
        "paper-U7" => (
            PaperModelKind::FormMixture,
            model(
                name,
                "Eq. 24",
                &mixture_u7,
                &[0.024, -0.003, 0.002, 0.001],
                0.239,
                Some(CrossValidation { folds: 10, mae: 5.33e-3, r2: 0.914 }),
            ),
        ),
        _ => return None,
    };
    Some(PaperModel { kind, model })
}
