//! The campaign report: report.md, a self-contained report.html (SVG inlined, no external
//! resources), figures/*.svg for the Markdown, dataset.csv and models/*.json. It formats an
//! analysis computed beforehand (`crate::campaign::analyse`) and computes nothing of its own. The
//! content follows the paper: campaign and packings (Fig. 11, Table 6), feature ranking and
//! primary feature (Fig. 8), form-factor correlations (Fig. 3), pair and set models (Tables 9,
//! 10), predicted against observed (Figs. 9, 12) and porosity profiles.

mod document;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;
use solver::fabric::Imbrication;
use solver::grain::{DrawnClass, graded, mass_shares, trimmed};
use thiserror::Error;

use crate::campaign::{Analysis, PACKINGS_PER_FEATURE, Support};
use crate::correlation::CorrelationMatrix;
use crate::dataset::{Dataset, FeatureKind};
use crate::form_factors::symbol;
use crate::model::LinearModel;
use crate::paper::{NearestSetup, paper_equation, paper_model};
use crate::plots::{self, PlotError, ScatterPlot, ZinggPacking};
use crate::record::{CampaignSummary, Cost, JobRecord};
use crate::selection::{Candidate, Selection, SelectionOptions, set_label};
use document::Block;

#[derive(Debug, Error)]
pub enum ReportError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error(transparent)]
    Plot(#[from] PlotError),
}

/// The files a report consists of.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportFiles {
    pub markdown: PathBuf,
    pub html: PathBuf,
    pub dataset: PathBuf,
    pub figures: Vec<PathBuf>,
    pub models: Vec<PathBuf>,
}

/// Writes the report of a campaign's finished jobs and their analysis into `out_dir`.
pub fn write_report(
    summary: &CampaignSummary,
    records: &[JobRecord],
    analysis: &Analysis,
    out_dir: &Path,
) -> Result<ReportFiles, ReportError> {
    let dataset = analysis.dataset.as_ref();
    let selection = analysis.selection.as_ref();
    let mut blocks = Vec::new();
    campaign_section(&mut blocks, summary, records, dataset);
    packings_section(&mut blocks, records)?;
    setups_section(&mut blocks, records);
    size_classes_section(&mut blocks, records);
    experiment_section(&mut blocks, records);
    paper_section(&mut blocks, records);
    model_section(&mut blocks, records);
    shape_section(&mut blocks, records)?;
    fluid_section(&mut blocks, records);
    match (dataset, selection) {
        (Some(d), Some(Ok(s))) => {
            dataset_section(&mut blocks, d);
            ranking_section(&mut blocks, records, d, s)?;
            if let Some(matrix) = &analysis.factor_correlation {
                correlation_section(&mut blocks, d.kind(), matrix)?;
            }
            filter_section(&mut blocks, s);
            pairs_section(&mut blocks, s);
            sets_section(&mut blocks, d, s, analysis)?;
        }
        (Some(d), Some(Err(e))) => {
            dataset_section(&mut blocks, d);
            blocks.push(Block::Heading("Models".into()));
            blocks.push(Block::Paragraph(format!("No model could be built: {e}.")));
        }
        _ => blocks
            .push(Block::Paragraph("The campaign has no finished job yet, so there is nothing to analyse.".into())),
    }
    method_section(&mut blocks, &analysis.options, dataset);

    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| ReportError::Io { path, source }
    };
    let figures_dir = out_dir.join("figures");
    let models_dir = out_dir.join("models");
    for dir in [out_dir, &figures_dir, &models_dir] {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
    }
    let write = |path: PathBuf, text: &str| std::fs::write(&path, text).map_err(io(&path)).map(|_| path);

    let mut figures = Vec::new();
    for block in &blocks {
        if let Block::Figure { file, svg, .. } = block {
            figures.push(write(figures_dir.join(format!("{file}.svg")), svg)?);
        }
    }
    let mut models = Vec::new();
    if let Some(Ok(s)) = selection {
        for fitted in s.sets.iter().filter_map(Candidate::fitted) {
            let json = serde_json::to_string_pretty(&fitted.model).expect("a model serialises");
            models.push(write(models_dir.join(model_file(&fitted.model)), &json)?);
        }
    }
    let csv = dataset.map_or_else(|| "job_id,porosity\n".to_string(), Dataset::to_csv);
    let title = format!("Porosity report: {}", summary.name);
    Ok(ReportFiles {
        dataset: write(out_dir.join("dataset.csv"), &csv)?,
        markdown: write(out_dir.join("report.md"), &document::markdown(&title, &blocks))?,
        html: write(out_dir.join("report.html"), &document::html(&title, &blocks))?,
        figures,
        models,
    })
}

/// models/ file name of a model: its features joined by '+'.
pub fn model_file(model: &LinearModel) -> String {
    format!("{}.json", model.features.join("+"))
}

/// `digits` significant digits, switching to exponent form outside [1e-4, 1e6).
fn sig(x: f64, digits: i32) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i32;
    if !(-4..6).contains(&magnitude) {
        return format!("{:.*e}", (digits - 1) as usize, x);
    }
    format!("{x:.*}", (digits - 1 - magnitude).max(0) as usize)
}

/// "12.3 s", "3 min 05 s", "1 h 02 min 05 s".
pub fn duration(seconds: f64) -> String {
    if seconds < 60.0 {
        return format!("{seconds:.1} s");
    }
    let s = seconds.round() as u64;
    if s < 3600 {
        format!("{} min {:02} s", s / 60, s % 60)
    } else {
        format!("{} h {:02} min {:02} s", s / 3600, s / 60 % 60, s % 60)
    }
}

/// A grid value as a user writes it: a string without its quotes, anything else as JSON.
pub fn value_text(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// "n = 0.0320 μ(EQ)⁻¹ − 0.00300 σ(EQ)⁻¹ + 0.287".
fn equation(model: &LinearModel) -> String {
    let mut s = String::from("n =");
    for (k, (f, c)) in model.features.iter().zip(&model.coefficients).enumerate() {
        let sign = if *c < 0.0 {
            " −"
        } else if k == 0 {
            ""
        } else {
            " +"
        };
        s.push_str(&format!("{sign} {} {}", sig(c.abs(), 4), symbol(f)));
    }
    let sign = if model.intercept < 0.0 { "−" } else { "+" };
    format!("{s} {sign} {}", sig(model.intercept.abs(), 4))
}

/// Grid keys whose value differs between jobs, with their values in order of appearance.
fn varied_parameters(records: &[JobRecord]) -> Vec<(String, Vec<String>)> {
    let mut values: BTreeMap<&String, Vec<String>> = BTreeMap::new();
    for r in records {
        for (k, v) in &r.parameters {
            let list = values.entry(k).or_default();
            let text = value_text(v);
            if !list.contains(&text) {
                list.push(text);
            }
        }
    }
    values.into_iter().filter(|(_, v)| v.len() > 1).map(|(k, v)| (k.clone(), v)).collect()
}

/// The items of the setup that every packing shares, in the first packing's order (the others
/// differ by a grid key, which the campaign table lists with its values).
fn common_setup(records: &[JobRecord]) -> Vec<&(String, String)> {
    let Some((first, rest)) = records.split_first() else { return Vec::new() };
    first.setup.iter().filter(|item| rest.iter().all(|r| r.setup.contains(item))).collect()
}

/// The shortest prefixes (at least 8 characters) that still tell the jobs apart.
fn short_ids(records: &[JobRecord]) -> Vec<String> {
    let longest = records.iter().map(|r| r.job_id.chars().count()).max().unwrap_or(0);
    let prefixes = |n: usize| records.iter().map(|r| r.job_id.chars().take(n).collect::<String>()).collect::<Vec<_>>();
    (8..longest)
        .map(prefixes)
        .find(|p| p.iter().collect::<std::collections::BTreeSet<_>>().len() == p.len())
        .unwrap_or_else(|| prefixes(longest))
}

fn campaign_section(
    blocks: &mut Vec<Block>,
    summary: &CampaignSummary,
    records: &[JobRecord],
    dataset: Option<&Dataset>,
) {
    blocks.push(Block::Paragraph(
        "Written by sedpack from the campaign's finished jobs, following Rettinger et al. (2022), §6.3 (single-form packings) and §7.2 (form mixtures). Porosity n is dimensionless; heights are in metres.".into(),
    ));
    blocks.push(Block::Heading("Campaign".into()));
    let mut rows = vec![
        vec!["campaign".into(), format!("`{}`", summary.name)],
        vec!["jobs".into(), summary.jobs().to_string()],
        vec![
            "done / failed / pending / running".into(),
            format!("{} / {} / {} / {}", summary.done, summary.failed, summary.pending, summary.running),
        ],
        vec!["packings analysed".into(), records.len().to_string()],
        vec!["total runtime of finished jobs".into(), duration(summary.total_runtime)],
    ];
    if let Some(d) = dataset {
        rows.push(vec!["features".into(), d.kind().describe().into()]);
    }
    blocks.push(Block::Table { header: vec!["".into(), "value".into()], rows });
    let mut setup: Vec<Vec<String>> =
        common_setup(records).into_iter().map(|(item, value)| vec![item.clone(), value.clone()]).collect();
    setup.extend(
        varied_parameters(records).into_iter().map(|(key, values)| vec![format!("`{key}`"), values.join(", ")]),
    );
    if !setup.is_empty() {
        blocks.push(Block::Paragraph(
            "The setup every packing shares, then the keys the campaign's grid varies with their values.".into(),
        ));
        blocks.push(Block::Table { header: vec!["setup".into(), "value".into()], rows: setup });
    }
    if summary.dropped_grains > 0 {
        blocks.push(Block::Paragraph(format!(
            "**Warning:** {} of the finished jobs were packed by sedpack 0.1.0, which threw away every grain that \
             found no room on the generation grid instead of keeping it for the next set. Packings of wide sieve \
             curves lack most of their coarse grains (a U7 packing kept none above 16 mm) and form mixtures lose \
             some of their elongated grains, which biases their porosity; packings of one form in one sieve class \
             are barely affected. Pack the others again with this version (in a new database).",
            summary.dropped_grains
        )));
    }
    if summary.failed + summary.pending + summary.running > 0 {
        blocks.push(Block::Paragraph(format!(
            "Only finished jobs enter the analysis ({} here); of the others, {} failed, {} pending and {} running.",
            records.len(),
            summary.failed,
            summary.pending,
            summary.running
        )));
    }
}

fn packings_section(blocks: &mut Vec<Block>, records: &[JobRecord]) -> Result<(), ReportError> {
    if records.is_empty() {
        return Ok(());
    }
    blocks.push(Block::Heading("Packings".into()));
    let varied = varied_parameters(records);
    let mut header: Vec<String> = vec!["job".into()];
    header.extend(varied.iter().map(|(k, _)| format!("`{k}`")));
    header.extend(
        ["μ_FL", "σ_FL", "μ_EL", "σ_EL", "porosity n", "grains", "simulated time (s)", "wall time"].map(String::from),
    );
    let stat = |r: &JobRecord, key: &str, std: bool| {
        r.grain_statistics.get(key).map_or("–".to_string(), |&(m, s)| format!("{:.3}", if std { s } else { m }))
    };
    let ids = short_ids(records);
    let rows = records
        .iter()
        .zip(&ids)
        .map(|(r, id)| {
            let mut row = vec![format!("`{id}`")];
            row.extend(varied.iter().map(|(k, _)| r.parameters.get(k).map_or("–".into(), value_text)));
            row.extend([stat(r, "FL", false), stat(r, "FL", true), stat(r, "EL", false), stat(r, "EL", true)]);
            row.push(format!("{:.4}", r.porosity));
            row.extend(cost_cells(&r.cost));
            row
        })
        .collect();
    blocks.push(Block::Paragraph(
        "Number-based mean μ and standard deviation σ of flatness FL = S/I and elongation EL = I/L over each packing's grains, the packing's bulk porosity (§4.4), its grains, the time it simulated and the wall time it stepped for (summed over the runs it was resumed in).".into(),
    ));
    blocks.push(Block::Table { header, rows });
    let zingg: Vec<ZinggPacking> = records
        .iter()
        .filter_map(|r| {
            let fl = r.grain_statistics.get("FL")?;
            let el = r.grain_statistics.get("EL")?;
            Some(ZinggPacking { mean_el: el.0, std_el: el.1, mean_fl: fl.0, std_fl: fl.1 })
        })
        .collect();
    let caption = if zingg.iter().any(ZinggPacking::has_spread) {
        "Zingg diagram (like Fig. 11): each packing's mean elongation and flatness as a point, the standard deviations as the semi-axes of an ellipse; dashed lines are the class boundaries at 2/3."
    } else {
        "Zingg diagram (like Fig. 11): each packing's elongation and flatness as a point (all grains of a packing have one form: no spread to draw); dashed lines are the class boundaries at 2/3."
    };
    blocks.push(Block::Figure { file: "zingg".into(), caption: caption.into(), svg: plots::zingg_diagram(&zingg)? });
    let profiles: Vec<(String, Vec<_>)> =
        records.iter().zip(ids).filter(|(r, _)| !r.profile.is_empty()).map(|(r, id)| (id, r.profile.clone())).collect();
    if !profiles.is_empty() {
        blocks.push(Block::Figure {
            file: "profiles".into(),
            caption:
                "Porosity profiles n(z): the porosity of each horizontal slice against the slice centre height (§4.4)."
                    .into(),
            svg: plots::profiles(&profiles)?,
        });
    }
    Ok(())
}

/// Grains, simulated time and wall time of a packing or of the mean packing of a setup.
fn cost_cells(cost: &Cost) -> [String; 3] {
    [cost.grains.to_string(), format!("{:.2}", cost.simulated_time), duration(cost.wall_time)]
}

/// A packing's setup: its parameters apart from the seed.
fn setup_label(r: &JobRecord) -> String {
    setup_text(&r.parameters)
}

/// A setup in words, from a job's grid values: every one but the seed ("grains.size = U3"), or
/// "all jobs" when the seed is the only one.
pub fn setup_text<'a>(parameters: impl IntoIterator<Item = (&'a String, &'a Value)>) -> String {
    let setup: Vec<String> = parameters
        .into_iter()
        .filter(|(k, _)| k.as_str() != "seed")
        .map(|(k, v)| format!("{k} = {}", value_text(v)))
        .collect();
    if setup.is_empty() { "all jobs".to_string() } else { setup.join(", ") }
}

/// The runs of each setup over the seeds, as the paper's tables give them (Tables 6, 7, 11),
/// where some setup has more than one.
fn setups_section(blocks: &mut Vec<Block>, records: &[JobRecord]) {
    let groups = grouped(records, |r| Some(setup_label(r)));
    if groups.iter().all(|g| g.1.len() < 2) {
        return;
    }
    blocks.push(Block::Heading("Runs per setup".into()));
    blocks.push(Block::Paragraph(
        "The runs of each setup (differing only in seed): their porosities, mean and standard deviation (population, as the paper's tables give it), and the mean packing's grains, simulated time and wall time.".into(),
    ));
    let rows = groups
        .iter()
        .map(|(label, runs)| {
            let mean = |f: &dyn Fn(&JobRecord) -> f64| runs.iter().map(|r| f(r)).sum::<f64>() / runs.len() as f64;
            let (n, std) = mean_std(&runs.iter().map(|r| r.porosity).collect::<Vec<_>>());
            let typical = Cost {
                grains: mean(&|r| r.cost.grains as f64).round() as u64,
                simulated_time: mean(&|r| r.cost.simulated_time),
                wall_time: mean(&|r| r.cost.wall_time),
            };
            let mut row = vec![
                label.clone(),
                runs.iter().map(|r| format!("{:.3}", r.porosity)).collect::<Vec<_>>().join(", "),
                format!("{n:.3} ± {std:.3}"),
            ];
            row.extend(cost_cells(&typical));
            row
        })
        .collect();
    blocks.push(Block::Table {
        header: ["setup", "runs", "porosity n (mean ± std)", "grains", "simulated time (s)", "wall time"]
            .map(String::from)
            .to_vec(),
        rows,
    });
}

/// The sieve classes as each packing drew them, for curves of more than one class: §3.2 draws
/// every grain's class at random, so seeds of one setup hold different mixes, which the spread
/// of their porosities may follow.
fn size_classes_section(blocks: &mut Vec<Block>, records: &[JobRecord]) {
    let shown: Vec<(&JobRecord, String)> =
        records.iter().zip(short_ids(records)).filter(|(r, _)| graded(&r.size_classes)).collect();
    if shown.is_empty() {
        return;
    }
    let mut sieves: Vec<&DrawnClass> = shown.iter().flat_map(|(r, _)| &r.size_classes).collect();
    sieves.sort_by(|a, b| (a.lower, a.upper).partial_cmp(&(b.lower, b.upper)).expect("sieves are finite"));
    sieves.dedup_by(|a, b| (a.lower, a.upper) == (b.lower, b.upper));
    let varied = varied_parameters(records);
    let mut header: Vec<String> = vec!["job".into()];
    header.extend(varied.iter().map(|(k, _)| format!("`{k}`")));
    header.extend(["grains", "porosity n"].map(String::from));
    header.extend(sieves.iter().map(|c| c.label()));
    header.push("off the curve".into());
    let rows = shown
        .iter()
        .map(|(r, id)| {
            let shares = mass_shares(&r.size_classes);
            let mut row = vec![format!("`{id}`")];
            row.extend(varied.iter().map(|(k, _)| r.parameters.get(k).map_or("–".into(), value_text)));
            row.extend([r.cost.grains.to_string(), format!("{:.4}", r.porosity)]);
            row.extend(sieves.iter().map(|s| {
                (r.size_classes.iter().zip(&shares))
                    .find(|(c, _)| (c.lower, c.upper) == (s.lower, s.upper))
                    .map_or("–".into(), |(c, share)| format!("{:.1} ({})", 100.0 * share, trimmed(100.0 * c.asked)))
            }));
            let off: f64 =
                r.size_classes.iter().zip(&shares).map(|(c, share)| (share - c.asked).abs()).sum::<f64>() / 2.0;
            row.push(format!("{:.1}", 100.0 * off));
            row
        })
        .collect();
    blocks.push(Block::Heading("Sieve classes as drawn".into()));
    let mut text = "Each packing's share of the created mass in each sieve class, in %, with the sieve curve's share in parentheses; \"off the curve\" is the mass in % that would have to move between classes to match the curve (half the summed differences). The paper draws every grain's class at random by Eqs. 8–9 (§3.2), so seeds of one setup hold different mixes, the more so the fewer grains the coarse classes hold.".to_string();
    let unrecorded = records.iter().filter(|r| r.size_classes.is_empty()).count();
    if unrecorded > 0 {
        text.push_str(&format!(
            " {} stored by an earlier sedpack, which did not record the classes, {} not listed.",
            counted(unrecorded, "packing"),
            if unrecorded == 1 { "is" } else { "are" }
        ));
    }
    blocks.push(Block::Paragraph(text));
    blocks.push(Block::Table { header, rows });
}

/// Table 6: runs of the same setup (parameters apart from the seed) against the measurement.
fn experiment_section(blocks: &mut Vec<Block>, records: &[JobRecord]) {
    comparison(
        blocks,
        "Comparison with experiment",
        "Like Table 6: the runs of each setup (differing only in seed), their mean and standard deviation, the measured porosity, the difference simulated − measured and the relative error (simulated − measured)/measured.",
        ["simulated n (mean ± std)", "measured n", "difference", "relative error (%)"],
        &grouped(records, |r| Some((setup_label(r), r.experiment?))),
        |mean, experiment| {
            let measured = experiment.porosity;
            let shown = match experiment.std {
                Some(std) => format!("{measured:.3} ± {std:.3}"),
                None => format!("{measured:.3} (spread not given)"),
            };
            (
                measured,
                vec![shown, format!("{:.3}", mean - measured), format!("{:.2}", 100.0 * (mean - measured) / measured)],
            )
        },
    );
}

/// Tables 5–8 and 11: the runs of each setup the paper simulated against the paper's runs.
/// Setups that are none of them follow, each with the nearest of the paper's and what differs.
fn paper_section(blocks: &mut Vec<Block>, records: &[JobRecord]) {
    let compared = records.iter().any(|r| r.paper.is_some());
    comparison(
        blocks,
        "Comparison with the paper's simulations",
        "Like Tables 5–8 and 11: the runs of each setup that is one of the paper's simulated setups (the table's domain, width, mass, shaking duration t_s and Table 3 case, meshes keeping their own forms or, for Table 11, drawn from the Rhine distribution, no fluid forces, and the paper's protocol and evaluation otherwise; seed, domain height, time limit, meshes, the contact point of polyhedra, the calibration of Eq. 11, the orientation of new grains and their grid may differ), their mean and standard deviation, the paper's porosity for the setup (the mean of its three runs ± their standard deviation, where the table gives one) and the difference sedpack − paper. The paper drew its grains from 63 scanned Rhine grains; a library of fewer meshes samples fewer shapes.",
        ["sedpack n (mean ± std)", "paper n (mean ± std)", "source", "difference"],
        &grouped(records, |r| Some((setup_label(r), r.paper.clone()?))),
        |mean, paper| {
            let shown = match paper.std {
                Some(std) => format!("{:.3} ± {std:.3}", paper.porosity),
                None => format!("{:.3}", paper.porosity),
            };
            (paper.porosity, vec![shown, paper.table.clone(), format!("{:.3}", mean - paper.porosity)])
        },
    );
    let others = grouped(records, |r| Some((setup_label(r), r.paper_nearest.clone()?)));
    if others.is_empty() {
        return;
    }
    let intro = if compared {
        "The other setups are none of the paper's simulated setups; the nearest of those to each, and what differs:"
    } else {
        blocks.push(Block::Heading("Comparison with the paper's simulations".into()));
        "No setup of this campaign is one of the paper's simulated setups with a porosity in its tables (Tables 5–8 and 11, each by the paper's protocol: see the README's \"sedpack report\"), so there is no table value to set its porosity beside. The nearest of the paper's setups to each, and what differs:"
    };
    blocks.push(Block::Paragraph(intro.into()));
    // Setups told the same are one row: a grid over forms is one answer, not one per form.
    let mut told: Vec<(&NearestSetup, Vec<&str>)> = Vec::new();
    for ((label, nearest), _) in &others {
        match told.iter_mut().find(|t| t.0 == nearest) {
            Some(t) => t.1.push(label),
            None => told.push((nearest, vec![label])),
        }
    }
    let rows = told
        .iter()
        .map(|(nearest, labels)| {
            let setups = if !compared && labels.len() > 1 && told.len() == 1 {
                format!("all {} setups", labels.len())
            } else {
                labels.join("; ")
            };
            vec![setups, nearest.setup.clone().unwrap_or_else(|| "none".into()), nearest.differences.clone()]
        })
        .collect();
    blocks.push(Block::Table {
        header: ["setup", "nearest of the paper's setups", "what differs"].map(String::from).to_vec(),
        rows,
    });
}

/// Eqs. 17–19 and 23–24: the runs of each setup in the setting of the paper's porosity models
/// against the model of their case at their grains' measured forms.
fn model_section(blocks: &mut Vec<Block>, records: &[JobRecord]) {
    // Per setup: the runs' mean prediction, the equation and a caveat of some run.
    type Model = (f64, String, Option<String>);
    let groups: Vec<((String, Model), Vec<&JobRecord>)> =
        grouped(records, |r| Some((setup_label(r), r.paper_model.as_ref()?.model.clone())))
            .into_iter()
            .map(|((label, _), runs)| {
                let models: Vec<_> = runs.iter().filter_map(|r| r.paper_model.as_ref()).collect();
                let mean = models.iter().map(|m| m.porosity).sum::<f64>() / models.len() as f64;
                let caveat = models.iter().find_map(|m| m.caveat.clone());
                ((label, (mean, models[0].equation.clone(), caveat)), runs)
            })
            .collect();
    comparison(
        blocks,
        "Comparison with the paper's porosity models",
        "The runs of each setup in the setting of the paper's porosity models (meshes in the periodic domain shaken t_s = 6 s by the paper's protocol, of a Table 3 case with a model: single forms of U1, U7 and B50, Eqs. 17–19, form mixtures of U1 and U7, Eqs. 23–24; width and mass may differ from the paper's 0.2 m and 16 kg), their mean and standard deviation, the model of their case at their grains' measured form statistics (the mean over the runs) and the difference sedpack − model. The models' own mean absolute errors in the paper's 10-fold cross-validation: 0.005, 0.004 and 0.006 for Eqs. 17–19 (Table 9), 0.004 and 0.005 for Eqs. 23 and 24 (Table 10). The paper's own test of Eq. 23 (Table 11: U1, the Rhine form distribution, 0.356) simulated 0.356 with forms drawn from the distribution and 0.353 with its 63 scans keeping their own forms.",
        ["sedpack n (mean ± std)", "paper's model n", "model", "difference"],
        &groups,
        |mean, (model, equation, caveat)| {
            let named = match caveat {
                Some(c) => format!("{equation}, extrapolated: {c}"),
                None => equation.clone(),
            };
            (*model, vec![format!("{model:.3}"), named, format!("{:.3}", mean - model)])
        },
    );
}

/// A section comparing the runs of each setup with a reference porosity: `columns` head the
/// runs' mean ± std and the cells that `reference` gives from the runs' mean (with the
/// reference's porosity, for the mean absolute difference that closes the section).
fn comparison<R>(
    blocks: &mut Vec<Block>,
    heading: &str,
    text: &str,
    columns: [&str; 4],
    groups: &[((String, R), Vec<&JobRecord>)],
    reference: impl Fn(f64, &R) -> (f64, Vec<String>),
) {
    if groups.is_empty() {
        return;
    }
    blocks.push(Block::Heading(heading.into()));
    blocks.push(Block::Paragraph(text.into()));
    let mut differences = Vec::new();
    let rows = groups
        .iter()
        .map(|((label, r), runs)| {
            let (mean, [runs, spread]) = run_cells(runs);
            let (porosity, cells) = reference(mean, r);
            differences.push((mean - porosity).abs());
            [vec![label.clone(), runs, spread], cells].concat()
        })
        .collect();
    blocks
        .push(Block::Table { header: ["setup", "runs"].into_iter().chain(columns).map(String::from).collect(), rows });
    blocks.push(Block::Paragraph(format!(
        "Mean absolute difference over {}: {:.4}.",
        counted(differences.len(), "setup"),
        differences.iter().sum::<f64>() / differences.len() as f64
    )));
}

/// The porosities of a setup's runs, and their mean ± std (the mean alone for one run), with
/// the mean.
fn run_cells(runs: &[&JobRecord]) -> (f64, [String; 2]) {
    let porosities: Vec<f64> = runs.iter().map(|r| r.porosity).collect();
    // Population std of the runs, as Table 6 reports it (its U1 row: 0.382, 0.381, 0.386 → ± 0.002).
    let (mean, std) = mean_std(&porosities);
    let spread = if runs.len() > 1 { format!("{mean:.3} ± {std:.3}") } else { format!("{mean:.3}") };
    (mean, [porosities.iter().map(|n| format!("{n:.3}")).collect::<Vec<_>>().join(", "), spread])
}

/// The records grouped by `key` (those without one left out), in the order keys first appear.
fn grouped<K: PartialEq>(records: &[JobRecord], key: impl Fn(&JobRecord) -> Option<K>) -> Vec<(K, Vec<&JobRecord>)> {
    let mut groups: Vec<(K, Vec<&JobRecord>)> = Vec::new();
    for r in records {
        let Some(k) = key(r) else { continue };
        match groups.iter_mut().find(|g| g.0 == k) {
            Some(g) => g.1.push(r),
            None => groups.push((k, vec![r])),
        }
    }
    groups
}

/// "1 setup", "2 setups": a count with its noun agreed.
fn counted(n: usize, noun: &str) -> String {
    format!("{n} {noun}{}", if n == 1 { "" } else { "s" })
}

/// Mean and population standard deviation: the ± of the report's setups.
pub fn mean_std(values: &[f64]) -> (f64, f64) {
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    (mean, (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64).sqrt())
}

/// (L/S, porosity) of each run of one grain shape in one setup.
type ShapeRuns = Vec<(f64, f64)>;

/// One setup of the shape comparison: its label, (L/S, L/I) of every run, the runs per shape.
type ShapeSetup = (String, Vec<(f64, f64)>, Vec<ShapeRuns>);

/// The paper's single-form model of the records' size case (Eqs. 17–19), where every record is
/// a packing of one form (flatness and elongation without spread) of that one Table 3 case.
fn paper_single_form_model<'a>(records: impl IntoIterator<Item = &'a JobRecord>) -> Option<LinearModel> {
    let mut case = None;
    for r in records {
        let single = ["FL", "EL"].iter().all(|f| r.grain_statistics.get(*f).is_some_and(|s| s.1 < 1e-9));
        if !single || r.size_case.is_none() || (case.is_some() && case != r.size_case.as_ref()) {
            return None;
        }
        case = r.size_case.as_ref();
    }
    paper_model(&format!("paper-sf-{}", case?)).map(|m| m.model)
}

/// Fig. 10: where the campaign varies `grains.shape`, each setup's porosity per shape against
/// its mean inverse equancy L/S, how far the shapes lie from the first one and, for single forms
/// of U1, U7 or B50, from the paper's single-form model of that case.
fn shape_section(blocks: &mut Vec<Block>, records: &[JobRecord]) -> Result<(), ReportError> {
    const SHAPE: &str = "grains.shape";
    let Some((_, shapes)) = varied_parameters(records).into_iter().find(|(k, _)| k == SHAPE) else {
        return Ok(());
    };
    let with_form = |r: &&JobRecord| {
        r.parameters.contains_key(SHAPE)
            && r.grain_statistics.contains_key("inv_EQ")
            && r.grain_statistics.contains_key("inv_EL")
    };
    let paper = paper_single_form_model(records.iter().filter(with_form));
    // setup (the parameters but shape and seed) → (L/S, L/I) of every run, and per shape the
    // (L/S, porosity) of its runs.
    let mut setups: Vec<ShapeSetup> = Vec::new();
    for r in records.iter().filter(with_form) {
        let (inv_eq, inv_el) = (r.grain_statistics["inv_EQ"].0, r.grain_statistics["inv_EL"].0);
        let k = shapes.iter().position(|s| *s == value_text(&r.parameters[SHAPE])).expect("a varied value");
        let label = r
            .parameters
            .iter()
            .filter(|(key, _)| key.as_str() != "seed" && key.as_str() != SHAPE)
            .map(|(key, v)| format!("{key} = {}", value_text(v)))
            .collect::<Vec<_>>()
            .join(", ");
        let at = match setups.iter().position(|s| s.0 == label) {
            Some(at) => at,
            None => {
                setups.push((label, Vec::new(), vec![Vec::new(); shapes.len()]));
                setups.len() - 1
            }
        };
        setups[at].1.push((inv_eq, inv_el));
        setups[at].2[k].push((inv_eq, r.porosity));
    }
    // Each setup's mean (L/S, L/I) over all its runs, and the paper's model there.
    let form_means: Vec<(f64, f64)> = setups
        .iter()
        .map(|(_, forms, _)| {
            let n = forms.len() as f64;
            (forms.iter().map(|f| f.0).sum::<f64>() / n, forms.iter().map(|f| f.1).sum::<f64>() / n)
        })
        .collect();
    let predicted: Vec<Option<f64>> = form_means
        .iter()
        .map(|&(inv_eq, inv_el)| {
            let values = BTreeMap::from([("inv_EQ".to_string(), inv_eq), ("inv_EL".to_string(), inv_el)]);
            paper.as_ref()?.predict(&values).ok()
        })
        .collect();
    let equation = paper.as_ref().map(paper_equation);
    blocks.push(Block::Heading("Grain shape at equal form (Fig. 10)".into()));
    let mut intro = format!(
        "Each setup's packings per grain shape: the mean inverse equancy L/S of their grains, and their porosity (mean ± population std over the seeds, runs in brackets; a single run shows its value alone). The differences are to the first shape, `{}`; RMS over the setups where both have runs (the paper finds ~0.008 between meshes and their equivalent ellipsoids).",
        shapes[0]
    );
    if let (Some(model), Some(equation)) = (&paper, &equation) {
        intro.push_str(&format!(
            " Beside them, the paper's {equation} (`{}`), n = {:.3} EQ⁻¹ {} {:.3} EL⁻¹ + {:.3}: its fit to its own single-form mesh packings of the case, in the periodic domain shaken t_s = 6 s, at the setup's form.",
            model.name,
            model.coefficients[0],
            if model.coefficients[1] < 0.0 { "−" } else { "+" },
            model.coefficients[1].abs(),
            model.intercept
        ));
    }
    blocks.push(Block::Paragraph(intro));
    let cell = |runs: &[(f64, f64)]| {
        if runs.is_empty() {
            return "–".to_string();
        }
        let (mean, std) = mean_std(&runs.iter().map(|r| r.1).collect::<Vec<_>>());
        // One run has no spread to show.
        match runs.len() {
            1 => format!("{mean:.3} (1)"),
            n => format!("{mean:.3} ± {std:.3} ({n})"),
        }
    };
    let mean =
        |runs: &[(f64, f64)]| (!runs.is_empty()).then(|| mean_std(&runs.iter().map(|r| r.1).collect::<Vec<_>>()).0);
    let mut squares = vec![Vec::new(); shapes.len()];
    let mut from_paper = vec![Vec::new(); shapes.len()];
    let rows = setups
        .iter()
        .zip(form_means.iter().zip(&predicted))
        .map(|((label, _, per_shape), (&(inv_eq, _), predicted))| {
            let mut row = vec![if label.is_empty() { "all jobs".into() } else { label.clone() }];
            row.push(format!("{inv_eq:.2}"));
            if paper.is_some() {
                row.push(predicted.map_or("–".into(), |p| format!("{p:.3}")));
            }
            row.extend(per_shape.iter().map(|runs| cell(runs)));
            for (k, runs) in per_shape.iter().enumerate().skip(1) {
                row.push(match (mean(&per_shape[0]), mean(runs)) {
                    (Some(first), Some(this)) => {
                        squares[k].push((this - first).powi(2));
                        format!("{:+.3}", this - first)
                    }
                    _ => "–".into(),
                });
            }
            for (k, runs) in per_shape.iter().enumerate() {
                if let (Some(p), Some(this)) = (predicted, mean(runs)) {
                    from_paper[k].push(this - p);
                }
            }
            row
        })
        .collect();
    let mut header = vec!["setup".to_string(), "L/S".to_string()];
    if let Some(equation) = &equation {
        header.push(format!("{equation} (paper, meshes)"));
    }
    header.extend(shapes.iter().map(|s| format!("n, `{s}`")));
    header.extend(shapes.iter().skip(1).map(|s| format!("`{s}` − `{}`", shapes[0])));
    blocks.push(Block::Table { header, rows });
    for (k, sq) in squares.iter().enumerate().filter(|(_, sq)| !sq.is_empty()) {
        blocks.push(Block::Paragraph(format!(
            "RMS difference `{}` − `{}` over {}: {:.4}.",
            shapes[k],
            shapes[0],
            counted(sq.len(), "setup"),
            (sq.iter().sum::<f64>() / sq.len() as f64).sqrt()
        )));
    }
    if let Some(equation) = &equation {
        let summaries: Vec<String> = shapes
            .iter()
            .zip(&from_paper)
            .filter(|(_, d)| !d.is_empty())
            .map(|(shape, d)| {
                let n = d.len() as f64;
                format!(
                    "`{shape}` {:+.4} on average, mean absolute difference {:.4} ({})",
                    d.iter().sum::<f64>() / n,
                    d.iter().map(|x| x.abs()).sum::<f64>() / n,
                    counted(d.len(), "setup")
                )
            })
            .collect();
        blocks.push(Block::Paragraph(format!("Against {equation}: {}.", summaries.join("; "))));
    }
    let mut series: Vec<plots::Series> = shapes
        .iter()
        .enumerate()
        .map(|(k, shape)| plots::Series {
            label: shape.clone(),
            points: setups
                .iter()
                .filter(|(_, _, per_shape)| !per_shape[k].is_empty())
                .map(|(_, _, per_shape)| {
                    let runs = &per_shape[k];
                    let (n, std) = mean_std(&runs.iter().map(|r| r.1).collect::<Vec<_>>());
                    (mean_std(&runs.iter().map(|r| r.0).collect::<Vec<_>>()).0, n, std)
                })
                .collect(),
            model: false,
        })
        .collect();
    if let Some(equation) = &equation {
        series.push(plots::Series {
            label: format!("{equation} (paper's fit, meshes)"),
            points: form_means
                .iter()
                .zip(&predicted)
                .filter_map(|(&(inv_eq, _), p)| Some((inv_eq, (*p)?, 0.0)))
                .collect(),
            model: true,
        });
    }
    blocks.push(Block::Figure {
        file: "shapes".into(),
        caption: "Porosity against the inverse equancy L/S per grain shape (like Fig. 10); bars are ± one standard deviation over the seeds.".into(),
        svg: plots::series_with_spread("Porosity by grain shape", "inverse equancy L/S (–)", "porosity n (–)", &series)?,
    });
    Ok(())
}

/// The fluid of a packing deposited without fluid forces.
const DRY: &str = "buoyancy only";

/// A run's seed (None where the campaign did not vary it) and porosity.
type SeededRun = (Option<String>, f64);

/// Mean ± standard error of the differences `wet − dry` over the seeds both have, and the
/// number of pairs; "—" without any.
fn paired_difference(wet: &[SeededRun], dry: &[SeededRun]) -> String {
    let differences: Vec<f64> = wet
        .iter()
        .filter_map(|(seed, n)| {
            let seed = seed.as_ref()?;
            dry.iter().find(|(s, _)| s.as_ref() == Some(seed)).map(|(_, m)| n - m)
        })
        .collect();
    let pairs = differences.len();
    if pairs == 0 {
        return "—".into();
    }
    let mean = differences.iter().sum::<f64>() / pairs as f64;
    if pairs == 1 {
        return format!("{mean:+.4} (1 pair)");
    }
    let variance = differences.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (pairs - 1) as f64;
    format!("{mean:+.4} ± {:.4} ({pairs} pairs)", (variance / pairs as f64).sqrt())
}

/// Packings deposited with fluid forces: porosity per fluid beside the same setup without, and
/// the long axes' imbrication where jobs report it.
fn fluid_section(blocks: &mut Vec<Block>, records: &[JobRecord]) {
    if records.iter().all(|r| r.fluid.is_none()) {
        return;
    }
    blocks.push(Block::Heading("Fluid forces".into()));
    blocks.push(Block::Paragraph(
        "Packings deposited with the fluid forces of Sun & Xiao (§2.3: drag per component sphere after Syamlal et al., Eqs. 3–7, with the local fluid fraction; Saffman lift, Eq. 8) in a prescribed flow, beside those deposited with buoyancy only (the first paper's protocol). Runs that differ only in seed are grouped; the setup lists the other varied parameters.".into(),
    ));
    let fluid_key = |k: &str| k == "seed" || k == "process.fluid" || k.starts_with("fluid.");
    let mut groups: Vec<(String, String, Vec<&JobRecord>)> = Vec::new();
    for r in records {
        let setup: Vec<String> = r
            .parameters
            .iter()
            .filter(|(k, _)| !fluid_key(k))
            .map(|(k, v)| format!("{k} = {}", value_text(v)))
            .collect();
        let setup = if setup.is_empty() { "all jobs".to_string() } else { setup.join(", ") };
        let fluid = r.fluid.clone().unwrap_or_else(|| DRY.into());
        match groups.iter_mut().find(|g| g.0 == setup && g.1 == fluid) {
            Some(g) => g.2.push(r),
            None => groups.push((setup, fluid, vec![r])),
        }
    }
    groups.sort_by(|a, b| a.0.cmp(&b.0));
    let seeded = |runs: &[&JobRecord]| -> Vec<SeededRun> {
        runs.iter().map(|r| (r.parameters.get("seed").map(value_text), r.porosity)).collect()
    };
    // Runs deposited with buoyancy only are what the fluid's runs are paired with, if any.
    let paired = groups.iter().any(|g| g.1 == DRY);
    let rows = groups
        .iter()
        .map(|(setup, fluid, runs)| {
            let porosities: Vec<f64> = runs.iter().map(|r| r.porosity).collect();
            let (mean, std) = mean_std(&porosities);
            let mut row =
                vec![setup.clone(), fluid.clone(), runs.len().to_string(), format!("{mean:.4}"), format!("{std:.4}")];
            if paired {
                let dry = groups.iter().find(|g| g.0 == *setup && g.1 == DRY).filter(|_| fluid != DRY);
                row.push(dry.map_or("—".to_string(), |dry| paired_difference(&seeded(runs), &seeded(&dry.2))));
            }
            row
        })
        .collect();
    let mut header: Vec<String> = ["setup", "fluid", "runs", "porosity n (mean)", "std"].map(String::from).to_vec();
    if paired {
        header.push("minus buoyancy only, same seeds".into());
    }
    blocks.push(Block::Table { header, rows });
    if paired {
        blocks.push(Block::Paragraph(
            "The last column pairs each run with the run of the same seed deposited with buoyancy only: the mean of their differences ± its standard error (the sample standard deviation of the differences over √pairs), and the number of pairs. Pairing takes out what the seed alone decides, so a small effect shows sooner than in the two means.".into(),
        ));
    }

    let imbricated: Vec<(&JobRecord, String)> =
        records.iter().zip(short_ids(records)).filter(|(r, _)| r.imbrication.is_some()).collect();
    if imbricated.is_empty() {
        return;
    }
    blocks.push(Block::Subheading("Imbrication".into()));
    blocks.push(Block::Paragraph(
        "The grains' long axes against the flow (+x): the dip is the angle between the long axis and the horizontal; its direction is the azimuth, from the flow direction, of the end that points down, so 180° means the axis dips upstream, leaning against the current as imbricated gravel does. The resultant is the mean of the dip directions weighted by the sine of the dip: its length runs from 0 (no preferred direction) to 1 (all alike).".into(),
    ));
    blocks.push(Block::Paragraph(
        "Per setup: the share of grains dipping upstream (mean ± population standard deviation over the runs); the runs' resultants added as vectors and divided by their number, its direction and, in brackets, its length (near 0 when the runs point different ways, however long each is); and the runs' resultant lengths (mean, least–greatest).".into(),
    ));
    let summaries = groups
        .iter()
        .filter_map(|(setup, fluid, runs)| {
            let fabrics: Vec<&Imbrication> = runs.iter().filter_map(|r| r.imbrication.as_ref()).collect();
            (!fabrics.is_empty()).then(|| imbrication_row(setup, fluid, &fabrics))
        })
        .collect();
    blocks.push(Block::Table {
        header: ["setup", "fluid", "runs", "dipping upstream (%)", "mean resultant (°)", "resultant lengths"]
            .map(String::from)
            .to_vec(),
        rows: summaries,
    });
    let percent = |x: f64| format!("{:.0}", 100.0 * x);
    blocks.push(Block::Table {
        header: [
            "job",
            "fluid",
            "grains",
            "mean dip (°)",
            "dipping upstream (%)",
            "resultant direction (°)",
            "resultant length",
        ]
        .map(String::from)
        .to_vec(),
        rows: imbricated
            .iter()
            .map(|(r, id)| {
                let f = r.imbrication.as_ref().expect("filtered");
                vec![
                    format!("`{id}`"),
                    r.fluid.clone().unwrap_or_default(),
                    f.grains.to_string(),
                    format!("{:.1}", f.mean_dip),
                    percent(f.upstream),
                    format!("{:.0}", f.resultant_direction),
                    format!("{:.2}", f.resultant_length),
                ]
            })
            .collect(),
    });
    let histogram = |title: &str, labels: Vec<String>, shares: fn(&JobRecord) -> &[f64]| {
        let mut header = vec![title.to_string()];
        header.extend(labels);
        let rows = imbricated
            .iter()
            .map(|(r, id)| {
                let mut row = vec![format!("`{id}`")];
                row.extend(shares(r).iter().map(|&x| percent(x)));
                row
            })
            .collect();
        Block::Table { header, rows }
    };
    blocks.push(Block::Paragraph("Share of the grains (%) per class of dip, then per direction of dip.".into()));
    blocks.push(histogram(
        "dip (°)",
        (0..solver::fabric::DIP_BINS).map(|k| format!("{}–{}", 10 * k, 10 * k + 10)).collect(),
        |r| &r.imbrication.as_ref().expect("filtered").dip,
    ));
    blocks.push(histogram(
        "direction (°)",
        (0..solver::fabric::DIRECTION_BINS).map(|k| format!("{}", 30 * k)).collect(),
        |r| &r.imbrication.as_ref().expect("filtered").direction,
    ));
}

/// One setup's imbrication over its runs: upstream share, mean resultant vector, lengths.
fn imbrication_row(setup: &str, fluid: &str, fabrics: &[&Imbrication]) -> Vec<String> {
    let upstream: Vec<f64> = fabrics.iter().map(|f| 100.0 * f.upstream).collect();
    let (mean, std) = mean_std(&upstream);
    let (x, y) = fabrics.iter().fold((0.0, 0.0), |(x, y), f| {
        let a = f.resultant_direction.to_radians();
        (x + f.resultant_length * a.cos(), y + f.resultant_length * a.sin())
    });
    let lengths: Vec<f64> = fabrics.iter().map(|f| f.resultant_length).collect();
    let (least, greatest) =
        lengths.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &l| (lo.min(l), hi.max(l)));
    vec![
        setup.to_string(),
        fluid.to_string(),
        fabrics.len().to_string(),
        format!("{mean:.1} ± {std:.1}"),
        format!("{:.0} ({:.2})", y.atan2(x).to_degrees(), x.hypot(y) / fabrics.len() as f64),
        format!("{:.2} ({least:.2}–{greatest:.2})", mean_std(&lengths).0),
    ]
}

fn dataset_section(blocks: &mut Vec<Block>, d: &Dataset) {
    blocks.push(Block::Heading("Dataset".into()));
    blocks.push(Block::Paragraph(format!(
        "`dataset.csv` holds {} (packings) and {} feature columns ({}), besides `job_id` and `porosity`.",
        counted(d.len(), "row"),
        d.features().len(),
        d.kind().describe()
    )));
    if !d.dropped().is_empty() {
        blocks.push(Block::Paragraph(format!(
            "{} candidate features were dropped because they are not a finite number for every packing:",
            d.dropped().len()
        )));
        blocks.push(Block::Table {
            header: vec!["feature".into(), "reason".into()],
            rows: d.dropped().iter().map(|x| vec![format!("`{}`", x.feature), x.reason.clone()]).collect(),
        });
    }
}

fn ranking_section(
    blocks: &mut Vec<Block>,
    records: &[JobRecord],
    d: &Dataset,
    s: &Selection,
) -> Result<(), ReportError> {
    blocks.push(Block::Heading("Feature ranking".into()));
    if records.len() > 1 && grouped(records, |r| Some(setup_label(r))).len() == 1 {
        blocks.push(Block::Paragraph(
            "**All packings share one setup** (they differ in seed only): their form statistics differ by the sampling of grains alone, so the correlations and models below describe that sampling, not an effect of form or size. A campaign studies one by varying forms or sizes in its grid.".into(),
        ));
    }
    blocks.push(Block::Paragraph(format!(
        "Pearson's correlation coefficient r of every feature with porosity, ranked by |r| (§6.3.2). The primary feature is **`{}`** ({}) with r = {:.3}.",
        s.primary.feature,
        symbol(&s.primary.feature),
        s.primary.r
    )));
    let rows = s
        .ranking
        .ranked
        .iter()
        .enumerate()
        .map(|(k, c)| vec![(k + 1).to_string(), format!("`{}`", c.feature), symbol(&c.feature), format!("{:.3}", c.r)])
        .collect();
    blocks.push(Block::Table { header: ["rank", "feature", "symbol", "r"].map(String::from).to_vec(), rows });
    if !s.ranking.constant.is_empty() {
        blocks.push(Block::Paragraph(format!(
            "Not ranked, being constant over the packings: {}.",
            s.ranking.constant.iter().map(|f| format!("`{f}`")).collect::<Vec<_>>().join(", ")
        )));
    }
    let x = d.column(&s.primary.feature).expect("the primary is a column");
    let points: Vec<(f64, f64)> = x.iter().copied().zip(d.porosity().iter().copied()).collect();
    let line = s.pairs[0].fitted().map(|f| {
        (
            f.model.coefficients[0],
            f.model.intercept,
            format!(
                "n = {} x + {} (r = {:.3})",
                sig(f.model.coefficients[0], 3),
                sig(f.model.intercept, 3),
                s.primary.r
            ),
        )
    });
    let x_label = format!("{} (–)", symbol(&s.primary.feature));
    blocks.push(Block::Figure {
        file: "primary".into(),
        caption: format!(
            "Porosity against the primary feature {} with the implied linear model (like Fig. 8).",
            symbol(&s.primary.feature)
        ),
        svg: plots::scatter(&ScatterPlot {
            title: "Porosity against the primary feature",
            x_label: &x_label,
            y_label: "porosity n (–)",
            points: &points,
            line,
        })?,
    });
    Ok(())
}

fn correlation_section(
    blocks: &mut Vec<Block>,
    kind: FeatureKind,
    matrix: &CorrelationMatrix,
) -> Result<(), ReportError> {
    if matrix.features.len() < 2 {
        return Ok(());
    }
    let what = match kind {
        FeatureKind::SingleForm => "the 13 form factors",
        FeatureKind::Mixture => "the packing means of the 13 form factors",
    };
    blocks.push(Block::Heading("Correlation of the form factors".into()));
    blocks.push(Block::Figure {
        file: "correlation".into(),
        caption: format!("Pearson correlation of {what} over the packings (like Fig. 3); grey cells are undefined (a constant factor)."),
        svg: plots::heat_map("Correlation of the form factors", matrix)?,
    });
    Ok(())
}

fn filter_section(blocks: &mut Vec<Block>, s: &Selection) {
    blocks.push(Block::Heading("Correlation filter".into()));
    blocks.push(Block::Paragraph(format!(
        "Features whose |r| with the primary feature `{}` exceeds {} carry little new information and are removed (§6.3.3): {} removed, {} kept.",
        s.primary.feature,
        s.filter.threshold,
        s.filter.removed.len(),
        s.filter.kept.len()
    )));
    if !s.filter.removed.is_empty() {
        blocks.push(Block::Table {
            header: ["removed feature", "symbol", "r with the primary"].map(String::from).to_vec(),
            rows: s
                .filter
                .removed
                .iter()
                .map(|c| vec![format!("`{}`", c.feature), symbol(&c.feature), format!("{:.3}", c.r)])
                .collect(),
        });
    }
}

fn metrics(c: &Candidate, bold: bool) -> [String; 2] {
    match c.fitted().and_then(|f| f.model.cv) {
        Some(cv) => {
            let mae = format!("{:.2}", cv.mae * 1e3);
            [if bold { format!("**{mae}**") } else { mae }, format!("{:.3}", cv.r2)]
        }
        None => ["–".into(), "–".into()],
    }
}

fn pairs_section(blocks: &mut Vec<Block>, s: &Selection) {
    blocks.push(Block::Heading("Feature pairs (Table 9)".into()));
    blocks.push(Block::Paragraph(format!(
        "The primary feature alone and with each kept feature, fitted by least squares; {}-fold cross-validated mean absolute error (MAE, ×10⁻³) and R² of the held-out predictions. The three smallest errors are in bold.",
        s.folds.iter().max().map_or(0, |m| m + 1)
    )));
    let mut maes: Vec<f64> = s.pairs.iter().filter_map(Candidate::mae).collect();
    maes.sort_by(f64::total_cmp);
    let third = maes.get(2.min(maes.len().saturating_sub(1))).copied();
    let rows = s
        .pairs
        .iter()
        .map(|c| {
            let bold = matches!((c.mae(), third), (Some(m), Some(t)) if m <= t);
            let [mae, r2] = metrics(c, bold);
            let with = c.features.get(1).map_or("(primary alone)".to_string(), |f| format!("`{f}` ({})", symbol(f)));
            let coefficients = match &c.result {
                Ok(f) => {
                    f.model.coefficients.iter().map(|x| sig(*x, 3)).collect::<Vec<_>>().join(", ")
                        + &format!("; {}", sig(f.model.intercept, 3))
                }
                Err(e) => format!("not fitted: {e}"),
            };
            vec![with, mae, r2, coefficients]
        })
        .collect();
    blocks.push(Block::Table {
        header: ["with the primary", "MAE (×10⁻³)", "R²", "coefficients; intercept"].map(String::from).to_vec(),
        rows,
    });
    if let Some(q) = &s.second {
        blocks.push(Block::Paragraph(format!(
            "Second factor: `{q}` ({}), the partner of another form factor with the smallest MAE{}.",
            symbol(q),
            if s.primary.feature.contains("mean_") || s.primary.feature.contains("std_") {
                " among those of the same statistic as the primary"
            } else {
                ""
            }
        )));
    }
}

fn sets_section(blocks: &mut Vec<Block>, d: &Dataset, s: &Selection, analysis: &Analysis) -> Result<(), ReportError> {
    blocks.push(Block::Heading("Models (Table 10)".into()));
    blocks.push(Block::Paragraph(
        "Multivariate feature sets built from the primary P, its counterpart of the other statistic P′ (μ ↔ σ), the second factor Q and its counterpart Q′, in the order of Table 10: P; P + P′; P + P′ + Q; P + P′ + Q + Q′; P + Q; P + P′ + Q′. The paper's own final set is added for comparison when the procedure did not reach it. Each set's equation and model file, or why it could not be fitted, follow the table under its number.".into(),
    ));
    let mut columns: Vec<String> = Vec::new();
    for c in &s.sets {
        for f in &c.features {
            if !columns.contains(f) {
                columns.push(f.clone());
            }
        }
    }
    let mut header: Vec<String> = vec!["set".into()];
    header.extend(columns.iter().map(|f| symbol(f)));
    header.extend(["MAE (×10⁻³)", "R²", "note"].map(String::from));
    let rows = s
        .sets
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let mut row = vec![format!("{}", k + 1)];
            row.extend(columns.iter().map(|f| if c.features.contains(f) { "✓".into() } else { "".into() }));
            row.extend(metrics(c, false));
            let mut notes = Vec::new();
            if s.chosen == Some(k) {
                notes.push("**chosen**");
            }
            if s.paper_set == Some(k) {
                notes.push("paper's set");
            }
            if c.result.is_err() {
                notes.push("not fitted");
            }
            row.push(notes.join("; "));
            row
        })
        .collect();
    blocks.push(Block::Table { header, rows });
    blocks.push(Block::List(
        s.sets
            .iter()
            .enumerate()
            .map(|(k, c)| match &c.result {
                Ok(f) => {
                    let (label, model) = (set_label(&c.features), &f.model);
                    format!("set {}, {label}: {}, `models/{}`", k + 1, equation(model), model_file(model))
                }
                Err(e) => format!("set {}, {}: not fitted: {e}", k + 1, set_label(&c.features)),
            })
            .collect(),
    ));

    let Some(chosen) = s.chosen_model() else {
        blocks.push(Block::Paragraph("No feature set could be fitted, so no model is chosen.".into()));
        return Ok(());
    };
    let model = &chosen.model;
    let cv = model.cv.expect("fitted models carry their cross-validation");
    blocks.push(Block::Subheading("Chosen model".into()));
    blocks.push(Block::Paragraph(format!(
        "Like the paper (§6.3.3, §7.2: \"generally include all four features\"), the largest feature set the procedure built is kept (ties to the smaller MAE): **{}**, fitted on all {} packings. Cross-validation ({}-fold): MAE = {:.2}×10⁻³, R² = {:.3}. Saved as `models/{}`; apply it with `sedpack predict --model REPORT_FOLDER/models/{}`.",
        equation(model),
        d.len(),
        cv.folds,
        cv.mae * 1e3,
        cv.r2,
        model_file(model),
        model_file(model)
    )));
    if let Some(caution) = analysis.support().and_then(|support| caution(&support, cv.mae)) {
        blocks.push(Block::Paragraph(caution));
    }
    blocks.push(Block::Table {
        header: ["feature", "symbol", "coefficient", "training range"].map(String::from).to_vec(),
        rows: model
            .features
            .iter()
            .zip(&model.coefficients)
            .map(|(f, c)| {
                let range =
                    model.ranges.get(f).map_or("–".into(), |r| format!("[{}, {}]", sig(r[0], 4), sig(r[1], 4)));
                vec![format!("`{f}`"), symbol(f), sig(*c, 4), range]
            })
            .chain(std::iter::once(vec!["intercept".into(), "".into(), sig(model.intercept, 4), "".into()]))
            .collect(),
    });
    blocks.push(Block::Figure {
        file: "predicted-vs-observed".into(),
        caption: "Predicted against observed porosity for the chosen model (like Figs. 9 and 12); the black line is perfect agreement.".into(),
        svg: plots::predicted_vs_observed(&set_label(&model.features), d.porosity(), &chosen.fitted, &chosen.held_out)?,
    });
    Ok(())
}

/// A plain warning when the packings are few for the chosen model's features, saying how its
/// cross-validated error compares with the other sets'.
fn caution(support: &Support, mae: f64) -> Option<String> {
    if !support.few {
        return None;
    }
    let comparison = match (support.worst, support.better) {
        (true, _) => "its cross-validated error is the largest of the fitted sets".to_string(),
        (false, Some(better)) => format!(
            "the set {} cross-validates better (MAE {:.2}×10⁻³ against {:.2}×10⁻³)",
            set_label(&better.features),
            better.mae().unwrap_or(f64::NAN) * 1e3,
            mae * 1e3
        ),
        (false, None) => "it cross-validates best here, but on so few packings that may be chance".to_string(),
    };
    Some(format!(
        "**Too few packings for this model:** {} packings for {} features, fewer than {PACKINGS_PER_FEATURE} per feature (the paper fitted four features to 52 packings). The largest set is kept by the paper's rule, not on the evidence: {comparison}. Run more packings before relying on it.",
        support.packings, support.features
    ))
}

fn method_section(blocks: &mut Vec<Block>, options: &SelectionOptions, dataset: Option<&Dataset>) {
    blocks.push(Block::Heading("Method".into()));
    let mut items = vec![
        "Grain statistics are number-based: mean and population standard deviation of each form factor over the packing's grains, as stored per job.".to_string(),
        format!(
            "A campaign is single-form when every packing has σ_FL and σ_EL ≤ {:e}; otherwise the 104 mixture features are built.",
            crate::dataset::SINGLE_FORM_STD_TOLERANCE
        ),
        "Ties in |r| (within 1e-12) go to the earlier dataset column (Table 1 order, the factor before its inverse).".to_string(),
        format!(
            "Correlation filter threshold |r| > {}; {}-fold cross-validation (fewer when there are fewer packings), folds dealt at random from seed {} and shared by every fit, so errors compare like for like.",
            options.threshold, options.folds, options.seed
        ),
        "Least squares with intercept through linfa-linear (Householder QR); designs with too few rows, a constant feature or collinear features are reported rather than fitted.".to_string(),
        "MAE and R² are of the held-out predictions: each packing is predicted by the model fitted without its fold; R² = 1 − Σ(n − n̂)² / Σ(n − n̄)².".to_string(),
    ];
    if dataset.is_some_and(|d| d.kind() == FeatureKind::Mixture) {
        items.push("A form-mixture model uses 1/σ and is not valid for a single form (§7.2); it applies within the training ranges listed with it.".into());
    }
    blocks.push(Block::List(items));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_printed_with_sensible_precision() {
        assert_eq!(sig(0.0321456, 3), "0.0321");
        assert_eq!(sig(0.287, 4), "0.2870");
        assert_eq!(sig(-3.4567, 3), "-3.46");
        assert_eq!(sig(1234.7, 3), "1235");
        assert_eq!(sig(0.00001234, 3), "1.23e-5");
        assert_eq!(sig(-0.000910, 3), "-0.000910");
        assert_eq!(duration(12.34), "12.3 s");
        assert_eq!(duration(3725.0), "1 h 02 min 05 s");
    }

    #[test]
    fn the_campaign_section_counts_the_jobs_left_out_of_the_analysis_by_state() {
        let summary = CampaignSummary {
            name: "c".into(),
            pending: 1,
            running: 2,
            done: 0,
            failed: 3,
            total_runtime: 0.0,
            dropped_grains: 0,
        };
        let mut blocks = Vec::new();
        campaign_section(&mut blocks, &summary, &[], None);
        let note = "Only finished jobs enter the analysis (0 here); of the others, 3 failed, 1 pending and 2 running.";
        assert!(blocks.iter().any(|b| matches!(b, Block::Paragraph(p) if p == note)));
    }

    #[test]
    fn job_ids_are_shortened_only_as_far_as_they_stay_distinct() {
        let record = |id: &str| JobRecord {
            job_id: id.into(),
            porosity: 0.3,
            profile: vec![],
            parameters: BTreeMap::new(),
            grain_statistics: BTreeMap::new(),
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
        };
        let records = [record("0123456789abcdef"), record("0123456789abXdef"), record("short")];
        assert_eq!(short_ids(&records), ["0123456789abc", "0123456789abX", "short"]);
    }

    #[test]
    fn equations_read_like_the_paper() {
        let model = LinearModel {
            name: "m".into(),
            features: vec!["inv_mean_EQ".into(), "inv_std_EQ".into()],
            coefficients: vec![0.032, -0.003],
            intercept: 0.287,
            cv: None,
            ranges: BTreeMap::new(),
            campaign: None,
        };
        assert_eq!(equation(&model), "n = 0.03200 μ(EQ)⁻¹ − 0.003000 σ(EQ)⁻¹ + 0.2870");
        assert_eq!(model_file(&model), "inv_mean_EQ+inv_std_EQ.json");
    }
}
