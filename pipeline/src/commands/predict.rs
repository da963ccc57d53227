//! `sedpack predict`: porosity from one of the paper's models or a saved model JSON, for a form
//! distribution (μ, σ of FL and EL), one form (FL, EL), or a CSV of measured grains.

use std::path::Path;

use analysis::LinearModel;
use analysis::paper::{MIXTURE_MEANS, MIXTURE_SIGMAS, PAPER_MODEL_NAMES, PaperModelKind, paper_model};
use analysis::prediction::{
    FormStatistics, input_from_grains, input_from_statistics, load_model, predict, read_grains_csv,
};
use anyhow::bail;
use serde::Serialize;

use crate::cli::PredictArgs;
use crate::output::{Table, number, print_json};

#[derive(Serialize)]
struct Output {
    model: String,
    porosity: f64,
    features: std::collections::BTreeMap<String, f64>,
    #[serde(skip_serializing_if = "Option::is_none", rename = "mu_EQ")]
    mu_eq: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", rename = "sigma_EQ")]
    sigma_eq: Option<f64>,
    warnings: Vec<String>,
}

pub fn run(args: &PredictArgs) -> anyhow::Result<()> {
    let (model, kind): (LinearModel, Option<PaperModelKind>) = match paper_model(&args.model) {
        Some(paper) => (paper.model, Some(paper.kind)),
        None if args.model.ends_with(".json") || Path::new(&args.model).is_file() => {
            (load_model(Path::new(&args.model))?, None)
        }
        None => bail!(
            "--model '{}' is neither a model file nor a known model: expected MODEL.json or one of {}",
            args.model,
            PAPER_MODEL_NAMES.join(", ")
        ),
    };
    let mut warnings = Vec::new();
    let distribution = args.distribution.given();
    let input = match (distribution.as_ref(), args.fl.zip(args.el), &args.grains) {
        (Some(d), _, _) => {
            if kind == Some(PaperModelKind::SingleForm) {
                bail!("model {} is a single-form model: give --fl and --el", args.model);
            }
            if kind == Some(PaperModelKind::FormMixture) {
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
            input_from_statistics(&FormStatistics {
                mu_fl: d.mu_fl,
                sigma_fl: d.sigma_fl,
                mu_el: d.mu_el,
                sigma_el: d.sigma_el,
            })?
        }
        (None, Some((fl, el)), _) => {
            if kind == Some(PaperModelKind::FormMixture) {
                bail!("model {} is a form-mixture model: give --mu-fl, --sigma-fl, --mu-el, --sigma-el", args.model);
            }
            for (name, value) in [("fl", fl), ("el", el)] {
                if !(value > 0.0 && value <= 1.0) {
                    bail!("--{name} = {value} is out of range: flatness and elongation lie in (0, 1]");
                }
            }
            input_from_statistics(&FormStatistics { mu_fl: fl, sigma_fl: 0.0, mu_el: el, sigma_el: 0.0 })?
        }
        (None, None, Some(path)) => input_from_grains(&read_grains_csv(path)?, &path.display().to_string())?,
        (None, None, None) => unreachable!("clap requires a form, a distribution or --grains"),
    };
    let prediction = predict(&model, &input)?;
    warnings.extend(prediction.warnings);
    let output = Output {
        model: args.model.clone(),
        porosity: prediction.porosity,
        mu_eq: input.features.get("mean_EQ").copied().filter(|_| distribution.is_some()),
        sigma_eq: input.features.get("std_EQ").copied().filter(|_| distribution.is_some()),
        features: prediction.features,
        warnings,
    };
    if args.json {
        return print_json(&output);
    }
    let mut table = Table::default();
    let source = model.campaign.clone().map(|c| format!(" ({c})")).unwrap_or_default();
    table.row("model", format!("{}{source}", output.model));
    for (k, v) in &output.features {
        table.row(k.as_str(), number(*v));
    }
    table.row("porosity", format!("{:.4}", output.porosity));
    table.print()?;
    for w in &output.warnings {
        eprintln!("warning: {w}");
    }
    Ok(())
}
