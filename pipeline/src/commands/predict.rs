//! `sedpack predict`: porosity from a porosity model.

use std::collections::BTreeMap;

use analysis::paper::{PAPER_MODEL_NAMES, PaperModelKind, paper_model};
use anyhow::{anyhow, bail};
use serde::Serialize;
use solver::grain::FormDistribution;

use crate::cli::PredictArgs;
use crate::output::{Table, number, print_json};

/// The nominal parameters of the paper's 52 form-mixture setups (§7.1): means in [0.4, 0.8],
/// standard deviations in [0.1, 0.2]. Outside, the models extrapolate.
const MIXTURE_MEANS: [f64; 2] = [0.4, 0.8];
const MIXTURE_SIGMAS: [f64; 2] = [0.1, 0.2];

#[derive(Serialize)]
struct Prediction {
    model: String,
    porosity: f64,
    features: BTreeMap<String, f64>,
    #[serde(skip_serializing_if = "Option::is_none", rename = "mu_EQ")]
    mu_eq: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", rename = "sigma_EQ")]
    sigma_eq: Option<f64>,
    warnings: Vec<String>,
}

pub fn run(args: &PredictArgs) -> anyhow::Result<()> {
    let paper = paper_model(&args.model).ok_or_else(|| {
        anyhow!("--model '{}' is not a known model: expected one of {}", args.model, PAPER_MODEL_NAMES.join(", "))
    })?;
    let mut features = BTreeMap::new();
    let mut warnings = Vec::new();
    let (mut mu_eq, mut sigma_eq) = (None, None);
    match (paper.kind, args.distribution(), args.fl.zip(args.el)) {
        (PaperModelKind::FormMixture, Some(d), _) => {
            let dist = FormDistribution::new(d.mu_fl, d.sigma_fl, d.mu_el, d.sigma_el)?;
            if d.sigma_fl <= 0.0 || d.sigma_el <= 0.0 {
                bail!(
                    "form-mixture model {} needs sigma_fl > 0 and sigma_el > 0: it uses 1/σ and is invalid without form variance (§7.2)",
                    args.model
                );
            }
            let (mu, sigma) = dist.equancy_statistics();
            features.insert("inv_mean_EQ".to_string(), 1.0 / mu);
            features.insert("inv_std_EQ".to_string(), 1.0 / sigma);
            features.insert("inv_mean_EL".to_string(), 1.0 / d.mu_el);
            features.insert("inv_std_EL".to_string(), 1.0 / d.sigma_el);
            (mu_eq, sigma_eq) = (Some(mu), Some(sigma));
            for (name, value, range) in [
                ("mu_fl", d.mu_fl, MIXTURE_MEANS),
                ("mu_el", d.mu_el, MIXTURE_MEANS),
                ("sigma_fl", d.sigma_fl, MIXTURE_SIGMAS),
                ("sigma_el", d.sigma_el, MIXTURE_SIGMAS),
            ] {
                if value < range[0] || value > range[1] {
                    warnings.push(format!(
                        "{name} = {value} lies outside the paper's setups [{}, {}] (§7.1): extrapolating",
                        range[0], range[1]
                    ));
                }
            }
        }
        (PaperModelKind::SingleForm, _, Some((fl, el))) => {
            for (name, value) in [("fl", fl), ("el", el)] {
                if !(value > 0.0 && value <= 1.0) {
                    bail!("--{name} = {value} is out of range: flatness and elongation lie in (0, 1]");
                }
            }
            features.insert("inv_EQ".to_string(), 1.0 / (fl * el));
            features.insert("inv_EL".to_string(), 1.0 / el);
        }
        (PaperModelKind::FormMixture, None, _) => {
            bail!("model {} is a form-mixture model: give --mu-fl, --sigma-fl, --mu-el, --sigma-el", args.model)
        }
        (PaperModelKind::SingleForm, _, None) => {
            bail!("model {} is a single-form model: give --fl and --el", args.model)
        }
    }
    let porosity = paper.model.predict(&features)?;
    features.retain(|k, _| paper.model.features.contains(k));
    let prediction = Prediction { model: args.model.clone(), porosity, features, mu_eq, sigma_eq, warnings };
    if args.json {
        return print_json(&prediction);
    }
    let mut table = Table::default();
    table.row("model", format!("{} ({})", prediction.model, paper.model.campaign.clone().unwrap_or_default()));
    for (k, v) in &prediction.features {
        table.row(k.as_str(), number(*v));
    }
    table.row("porosity", format!("{:.4}", prediction.porosity));
    table.print();
    for w in &prediction.warnings {
        eprintln!("warning: {w}");
    }
    Ok(())
}
