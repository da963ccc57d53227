//! The report of synthetic campaigns: porosity planted as a known linear function of features
//! plus small noise; the report must find it, save it, and write well-formed, offline files.

use std::collections::BTreeMap;
use std::path::Path;

use analysis::analyse;
use analysis::dataset::mixture_feature_names;
use analysis::form_factors::{form_feature_names, grain_statistics};
use analysis::model::LinearModel;
use analysis::paper::{ModelPorosity, NearestSetup, PaperPorosity};
use analysis::record::{CampaignSummary, Cost, Experiment, JobRecord};
use analysis::report::{ReportFiles, write_report};
use analysis::selection::SelectionOptions;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::json;
use solver::fabric::Imbrication;
use solver::porosity::ProfilePoint;

/// Grains of a packing: FL and EL on a 4 × 4 grid at μ ± 0.5σ, ± 1.5σ, clipped to [0.1, 1]
/// like the sampler's redrawing range.
fn grains(mu_fl: f64, sigma_fl: f64, mu_el: f64, sigma_el: f64) -> Vec<(f64, f64)> {
    let z = [-1.5, -0.5, 0.5, 1.5];
    let clip = |x: f64| x.clamp(0.1, 1.0);
    z.iter().flat_map(|a| z.iter().map(move |b| (clip(mu_fl + a * sigma_fl), clip(mu_el + b * sigma_el)))).collect()
}

fn profile(porosity: f64) -> Vec<ProfilePoint> {
    (0..30)
        .map(|k| ProfilePoint {
            z: 0.0005 + 0.001 * k as f64,
            n: if k < 25 { porosity } else { 1.0 - (30 - k) as f64 * 0.1 },
        })
        .collect()
}

/// Planted model, Eq. 24's form with Eq. 23-like coefficients.
const PLANTED: [(&str, f64); 4] =
    [("inv_mean_EQ", 0.032), ("inv_std_EQ", -0.003), ("inv_mean_EL", 0.011), ("inv_std_EL", 0.002)];
const INTERCEPT: f64 = 0.287;
const NOISE: f64 = 2e-4;

fn mixture_campaign() -> Vec<JobRecord> {
    let mut rng = ChaCha8Rng::seed_from_u64(2022);
    let mut records = Vec::new();
    for mu_fl in [0.4, 0.6, 0.8] {
        for mu_el in [0.5, 0.7, 0.85] {
            for sigma_fl in [0.1, 0.2] {
                for sigma_el in [0.1, 0.15] {
                    let stats = grain_statistics(&grains(mu_fl, sigma_fl, mu_el, sigma_el));
                    let feature = |name: &str| match name {
                        "inv_mean_EQ" => 1.0 / stats["EQ"].0,
                        "inv_std_EQ" => 1.0 / stats["EQ"].1,
                        "inv_mean_EL" => 1.0 / stats["EL"].0,
                        "inv_std_EL" => 1.0 / stats["EL"].1,
                        _ => unreachable!(),
                    };
                    let porosity = INTERCEPT
                        + PLANTED.iter().map(|(f, c)| c * feature(f)).sum::<f64>()
                        + rng.random_range(-NOISE..NOISE);
                    records.push(JobRecord {
                        job_id: format!("{:016x}", (records.len() as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15)),
                        porosity,
                        profile: profile(porosity),
                        parameters: BTreeMap::from([
                            ("grains.form.mu_fl".to_string(), json!(mu_fl)),
                            ("grains.form.mu_el".to_string(), json!(mu_el)),
                            ("grains.form.sigma_fl".to_string(), json!(sigma_fl)),
                            ("grains.form.sigma_el".to_string(), json!(sigma_el)),
                            ("seed".to_string(), json!(1)),
                        ]),
                        grain_statistics: stats,
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
                    });
                }
            }
        }
    }
    records
}

fn summary(name: &str, done: usize) -> CampaignSummary {
    CampaignSummary {
        name: name.into(),
        pending: 0,
        running: 0,
        done,
        failed: 1,
        total_runtime: 7384.0,
        dropped_grains: 0,
    }
}

/// The analysis of the records with the default options, and its report in `out`.
fn report(name: &str, records: &[JobRecord], out: &Path) -> ReportFiles {
    let analysis = analyse(records, name, &SelectionOptions::default()).unwrap();
    write_report(&summary(name, records.len()), records, &analysis, out).unwrap()
}

/// Two-pass Pearson, independent of the library.
fn pearson(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    let syy: f64 = y.iter().map(|b| (b - my).powi(2)).sum();
    sxy / (sxx * syy).sqrt()
}

/// dataset.csv as (header, rows of job id and numbers).
fn read_csv(path: &Path) -> (Vec<String>, Vec<(String, Vec<f64>)>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| {
            let mut cells = l.split(',');
            let id = cells.next().unwrap().to_string();
            (id, cells.map(|c| c.parse().unwrap()).collect())
        })
        .collect();
    (header, rows)
}

/// Every SVG parses as XML, the whole HTML parses as XML, and nothing is fetched from outside.
fn check_html(out: &Path, min_svgs: usize) -> String {
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let doc = roxmltree::Document::parse_with_options(
        &html,
        roxmltree::ParsingOptions { allow_dtd: true, ..Default::default() },
    )
    .unwrap_or_else(|e| panic!("report.html is not well-formed: {e}"));
    let svgs = doc.descendants().filter(|n| n.tag_name().name() == "svg").count();
    assert!(svgs >= min_svgs, "{svgs} inline SVGs");
    let mut rest = html.as_str();
    while let Some(start) = rest.find("<svg") {
        let end = rest[start..].find("</svg>").unwrap() + start + "</svg>".len();
        roxmltree::Document::parse(&rest[start..end])
            .unwrap_or_else(|e| panic!("an inline SVG is not well-formed: {e}"));
        rest = &rest[end..];
    }
    for figure in std::fs::read_dir(out.join("figures")).unwrap() {
        let text = std::fs::read_to_string(figure.unwrap().path()).unwrap();
        roxmltree::Document::parse(&text).unwrap();
    }
    for banned in ["<script", "<link", "<img", "<iframe", "url(", "href", "src="] {
        assert!(!html.contains(banned), "report.html contains {banned}");
    }
    let without_namespaces = html.replace("xmlns=\"http://www.w3.org/2000/svg\"", "");
    assert!(!without_namespaces.contains("http"), "report.html refers to something online");
    html
}

#[test]
fn a_mixture_campaign_report_recovers_the_planted_model() {
    let records = mixture_campaign();
    let out = tempfile::tempdir().unwrap();
    let files = report("synthetic-fm", &records, out.path());

    // dataset.csv: the header is job_id, porosity, then mixture features in their order.
    let (header, rows) = read_csv(&files.dataset);
    assert_eq!(header[..2], ["job_id", "porosity"]);
    let all = mixture_feature_names();
    let positions: Vec<usize> =
        header[2..].iter().map(|h| all.iter().position(|n| n == h).expect("a mixture feature")).collect();
    assert!(positions.windows(2).all(|w| w[0] < w[1]), "columns keep the feature order");
    assert_eq!(rows.len(), records.len());
    let md = std::fs::read_to_string(&files.markdown).unwrap();
    assert!(!md.contains("Runs per setup"), "one run per setup: the packings table says it all");
    for dropped in all.iter().filter(|n| !header.contains(n)) {
        assert!(md.contains(&format!("| `{dropped}` |")), "dropped {dropped} is explained in the report");
    }
    let col = |name: &str| header.iter().position(|h| h == name).unwrap() - 1;
    for ((id, values), r) in rows.iter().zip(&records) {
        assert_eq!(id, &r.job_id);
        assert_eq!(values[0], r.porosity, "porosity written exactly");
        assert_eq!(values[col("inv_mean_EQ")], 1.0 / r.grain_statistics["EQ"].0);
    }

    // The primary is the column with the largest |r| by an independent two-pass computation.
    let porosity: Vec<f64> = rows.iter().map(|r| r.1[0]).collect();
    let (primary, r) = header[2..]
        .iter()
        .map(|h| {
            let x: Vec<f64> = rows.iter().map(|row| row.1[col(h)]).collect();
            (h.clone(), pearson(&x, &porosity))
        })
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .unwrap();
    assert!(md.contains(&format!("The primary feature is **`{primary}`**")), "primary {primary}");
    assert!(md.contains(&format!("with r = {r:.3}.")));

    // The paper's four-feature set is always fitted; its coefficients are the planted ones.
    let file = out.path().join("models/inv_mean_EQ+inv_std_EQ+inv_mean_EL+inv_std_EL.json");
    let model: LinearModel = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    assert_eq!(model.campaign.as_deref(), Some("synthetic-fm"));
    // Uniform noise of ±2e-4 (σ = 1.2e-4) on 36 packings whose features spread by ~1 (1/μ) to
    // ~5 (1/σ): standard errors of the coefficients are ~1e-5 to ~5e-5 (the 1/σ features are
    // correlated), so 2e-4 is several of them and still tells the 0.002 coefficient from 0; the
    // intercept, extrapolated to zero features, gets 1e-3.
    for ((f, planted), (name, got)) in PLANTED.iter().zip(model.features.iter().zip(&model.coefficients)) {
        assert_eq!(f, name);
        assert!((got - planted).abs() < 2e-4, "{name}: {got} vs {planted}");
    }
    assert!((model.intercept - INTERCEPT).abs() < 1e-3, "{}", model.intercept);
    let cv = model.cv.unwrap();
    assert_eq!(cv.folds, 10);
    // Held-out errors of a correct model are of the noise size (mean |U(−a, a)| = a/2).
    assert!(cv.mae < 3.0 * NOISE && cv.r2 > 0.99, "{cv:?}");
    for f in &model.features {
        let x: Vec<f64> = rows.iter().map(|row| row.1[col(f)]).collect();
        let want =
            [x.iter().copied().fold(f64::INFINITY, f64::min), x.iter().copied().fold(f64::NEG_INFINITY, f64::max)];
        assert_eq!(model.ranges[f], want, "training range of {f}");
    }
    assert!(files.models.contains(&file));
    assert!(md.contains("Feature pairs (Table 9)") && md.contains("Models (Table 10)"));
    assert!(md.contains("**chosen**"));

    let html = check_html(out.path(), 5);
    assert!(html.contains("Zingg diagram") && html.contains("Porosity profiles n(z)"));
    // The ranking of every feature folds away; the short campaign table does not.
    let ranked = header.len() - 2;
    assert!(html.contains(&format!("<details>\n<summary>Show the {ranked} rows of this table</summary>")), "{html}");
    let campaign_table = html.find("<table>").unwrap();
    assert!(!html[..campaign_table].contains("<details>"));
    // 36 packings are enough for the four features fitted: no caution.
    assert!(!md.contains("Too few packings"));
    assert!(html.contains("elongation EL = I/L (–)"), "axis labels with units are text elements");
    assert_eq!(files.figures.len(), 5, "Zingg, profiles, primary, correlation, predicted vs observed");
}

/// Table 6's U1 and U3 runs with their experiments, as single-form packings.
fn validation_campaign() -> Vec<JobRecord> {
    let mut records = Vec::new();
    let cases = [
        ("U1", [0.382, 0.381, 0.386], Experiment { porosity: 0.371, std: Some(0.001) }, (0.6, 0.7)),
        ("U3", [0.367, 0.369, 0.372], Experiment { porosity: 0.356, std: Some(0.003) }, (0.5, 0.8)),
    ];
    for (case, runs, experiment, (fl, el)) in cases {
        for (seed, n) in runs.iter().enumerate() {
            records.push(JobRecord {
                job_id: format!("{case}-{seed}"),
                porosity: *n,
                profile: vec![],
                parameters: BTreeMap::from([("grains.size".into(), json!(case)), ("seed".into(), json!(seed + 1))]),
                grain_statistics: grain_statistics(&[(fl, el); 3]),
                size_case: None,
                experiment: Some(experiment),
                paper: None,
                paper_nearest: None,
                paper_model: None,
                fluid: None,
                imbrication: None,
                size_classes: Vec::new(),
                setup: Vec::new(),
                // Seeds 1–3: 4,000, 4,010, 4,020 grains, 2.9–3.1 s simulated, 1, 2 and 1.5 h.
                cost: Cost {
                    grains: 4_000 + 10 * seed as u64,
                    simulated_time: 2.9 + 0.1 * seed as f64,
                    wall_time: [3600.0, 7200.0, 5400.0][seed],
                },
            });
        }
    }
    records
}

#[test]
fn a_single_form_validation_report_has_table_6() {
    let records = validation_campaign();
    let out = tempfile::tempdir().unwrap();
    let files = report("validation", &records, out.path());
    let md = std::fs::read_to_string(&files.markdown).unwrap();
    // Table 6, U1: mean 0.383 ± 0.002 (population std), 0.383 − 0.371 = 0.012, 3.23 %;
    // U3: 0.369 ± 0.002, 0.369333 − 0.356 = 0.013, 3.75 %.
    assert!(
        md.contains("| grains.size = U1 | 0.382, 0.381, 0.386 | 0.383 ± 0.002 | 0.371 ± 0.001 | 0.012 | 3.23 |"),
        "{md}"
    );
    assert!(
        md.contains("| grains.size = U3 | 0.367, 0.369, 0.372 | 0.369 ± 0.002 | 0.356 ± 0.003 | 0.013 | 3.75 |"),
        "{md}"
    );
    // The runs per setup with the mean packing's cost: 4,010 grains, 3.00 s, 1.5 h, the same
    // for both cases; and each packing's own in the table of packings.
    let setups = md.find("## Runs per setup").expect(&md);
    assert!(
        md[setups..]
            .contains("| grains.size = U1 | 0.382, 0.381, 0.386 | 0.383 ± 0.002 | 4010 | 3.00 | 1 h 30 min 00 s |"),
        "{md}"
    );
    assert!(md[setups..].contains("| grains.size = U3 | 0.367, 0.369, 0.372 | 0.369 ± 0.002 | 4010 |"), "{md}");
    assert!(md[..setups].contains("| 0.3860 | 4020 | 3.10 | 1 h 30 min 00 s |"), "U1 seed 3: {md}");
    let (header, rows) = read_csv(&files.dataset);
    assert_eq!(header[2..], form_feature_names()[..], "single-form campaigns get the 26 factors");
    assert_eq!(rows.len(), 6);
    assert!(md.contains("single-form packings"));
    check_html(out.path(), 3);
}

#[test]
fn a_ranking_over_seeds_of_one_setup_says_it_measures_the_sampling() {
    // Three seeds of U1 whose grains' forms differ a little by sampling: the ranking exists
    // (the features vary) but describes that sampling, and the report says so; with a second
    // size case in the grid it does not.
    let mut records = validation_campaign();
    for (k, r) in records.iter_mut().enumerate() {
        r.grain_statistics = grain_statistics(&[(0.6 + 0.01 * k as f64, 0.7 - 0.004 * (k * k) as f64); 3]);
    }
    let caveat = "**All packings share one setup**";
    let out = tempfile::tempdir().unwrap();
    let one = std::fs::read_to_string(report("u1", &records[..3], out.path()).markdown).unwrap();
    let ranking = one.find("## Feature ranking").expect(&one);
    assert!(one[ranking..].contains(caveat), "{one}");
    let out = tempfile::tempdir().unwrap();
    let two = std::fs::read_to_string(report("u1-u3", &records, out.path()).markdown).unwrap();
    assert!(two.contains("## Feature ranking") && !two.contains(caveat), "{two}");
}

#[test]
fn the_campaign_table_names_the_setup_its_packings_share() {
    let mut records = validation_campaign();
    for r in &mut records {
        let case = r.parameters["grains.size"].as_str().unwrap().to_string();
        r.setup = vec![
            ("domain".into(), "cylinder, L = 0.104 m, H = 1 m".into()),
            ("sieve curve".into(), format!("{case} (Table 3)")),
            ("contact point".into(), "EPA's witness midpoint (the paper's software)".into()),
        ];
    }
    let out = tempfile::tempdir().unwrap();
    let md = std::fs::read_to_string(report("validation", &records, out.path()).markdown).unwrap();
    let campaign = &md[..md.find("## Packings").expect(&md)];
    assert!(campaign.contains("| domain | cylinder, L = 0.104 m, H = 1 m |"), "{campaign}");
    assert!(campaign.contains("| contact point | EPA's witness midpoint (the paper's software) |"), "{campaign}");
    // The sieve curve differs by the grid key, which the table gives with its values instead.
    assert!(!campaign.contains("| sieve curve |"), "{campaign}");
    assert!(campaign.contains("| `grains.size` | U1, U3 |"), "{campaign}");
    // A packing whose spec could not be read has no setup: nothing is claimed common.
    records[0].setup.clear();
    let md = std::fs::read_to_string(report("validation", &records, out.path()).markdown).unwrap();
    assert!(!md.contains("| domain |"), "{md}");
}

#[test]
fn packings_of_the_papers_setups_are_compared_with_its_simulations() {
    // Table 7's U7 run three times, and one B50 run of a Table 8 setup (no spread given).
    let mut records: Vec<JobRecord> = validation_campaign().into_iter().take(4).collect();
    let table7 = PaperPorosity { table: "Table 7".into(), porosity: 0.291, std: Some(0.001) };
    let table8 = PaperPorosity { table: "Table 8".into(), porosity: 0.242, std: None };
    for (r, n) in records.iter_mut().zip([0.288, 0.293, 0.290, 0.250]) {
        r.porosity = n;
        r.experiment = None;
        r.paper = Some(if r.job_id.starts_with("U1") { table7.clone() } else { table8.clone() });
    }
    let out = tempfile::tempdir().unwrap();
    let files = report("validation", &records, out.path());
    let md = std::fs::read_to_string(&files.markdown).unwrap();
    let section = md.find("## Comparison with the paper's simulations").expect(&md);
    // Mean 0.290333, population std 0.002055; 0.290333 − 0.291 = −0.000667 → −0.001.
    assert!(
        md[section..]
            .contains("| grains.size = U1 | 0.288, 0.293, 0.290 | 0.290 ± 0.002 | 0.291 ± 0.001 | Table 7 | -0.001 |"),
        "{md}"
    );
    // One run: its value, no spread; 0.250 − 0.242 = 0.008.
    assert!(md[section..].contains("| grains.size = U3 | 0.250 | 0.250 | 0.242 | Table 8 | 0.008 |"), "{md}");
    // (0.000667 + 0.008) / 2 = 0.004333.
    assert!(md[section..].contains("Mean absolute difference over 2 setups: 0.0043."), "{md}");
    assert!(!md.contains("## Comparison with experiment"), "no experiment, no such section");
}

#[test]
fn setups_that_are_none_of_the_papers_are_told_the_nearest_and_what_differs() {
    let nearest = NearestSetup {
        setup: Some("Table 7's U7 (periodic domain, L = 0.1 m, 4 kg, t_s = 1 s, meshes of their own forms)".into()),
        differences: "this setup has forms drawn from the Rhine distribution".into(),
    };
    let row = "| grains.size = U3 | Table 7's U7 (periodic domain, L = 0.1 m, 4 kg, t_s = 1 s, meshes of their own forms) | this setup has forms drawn from the Rhine distribution |";
    let mut records: Vec<JobRecord> = validation_campaign();
    for r in records.iter_mut().filter(|r| r.job_id.starts_with("U3")) {
        r.paper_nearest = Some(nearest.clone());
    }
    let out = tempfile::tempdir().unwrap();
    // U1 is the paper's setup: compared; U3 is not, and is told why after the comparison.
    for r in records.iter_mut().filter(|r| r.job_id.starts_with("U1")) {
        r.paper = Some(PaperPorosity { table: "Table 6".into(), porosity: 0.383, std: Some(0.002) });
    }
    let md = std::fs::read_to_string(report("validation", &records, out.path()).markdown).unwrap();
    let section = &md[md.find("## Comparison with the paper's simulations").expect(&md)..];
    let other = section.find("The other setups are none of the paper's simulated setups").expect(section);
    assert!(section[..other].contains("| grains.size = U1 |"), "{section}");
    assert!(section[other..].contains(row), "{section}");
    assert!(!section[other..].contains("| grains.size = U1 |"), "{section}");
    // No setup of the paper's: the section still comes, to say so.
    let mut records: Vec<JobRecord> = records.into_iter().filter(|r| r.job_id.starts_with("U3")).collect();
    let md = std::fs::read_to_string(report("validation", &records, out.path()).markdown).unwrap();
    let section = &md[md.find("## Comparison with the paper's simulations").expect(&md)..];
    assert!(section.contains("No setup of this campaign is one of the paper's simulated setups"), "{section}");
    assert!(section.contains(row), "{section}");
    // Two setups told the same are one row.
    let mut other = records.clone();
    for r in &mut other {
        r.parameters.insert("grains.size".into(), json!("U5"));
        r.job_id = r.job_id.replace("U3", "U5");
        r.porosity -= 0.03;
    }
    records.extend(other);
    let md = std::fs::read_to_string(report("validation", &records, out.path()).markdown).unwrap();
    let section = &md[md.find("## Comparison with the paper's simulations").expect(&md)..];
    let one = row.replace("| grains.size = U3 |", "| all 2 setups |");
    assert!(section.contains(&one), "{section}");
}

#[test]
fn packings_in_the_models_setting_are_compared_with_the_papers_model() {
    // Two runs of a form mixture (Eq. 23 at each run's measured forms: 0.356 and 0.358) and one
    // of the two scans' own forms, whose σ_EL lies far below the paper's.
    let mut records: Vec<JobRecord> = validation_campaign().into_iter().take(3).collect();
    let eq23 = |porosity: f64, caveat: Option<&str>| ModelPorosity {
        model: "paper-U1".into(),
        equation: "Eq. 23".into(),
        porosity,
        caveat: caveat.map(String::from),
    };
    let runs = [(0.360, eq23(0.356, None)), (0.364, eq23(0.358, None)), (0.366, eq23(0.373, Some("σ_EL = 0.006")))];
    for (r, (n, model)) in records.iter_mut().zip(runs) {
        (r.porosity, r.experiment, r.paper_model) = (n, None, Some(model));
    }
    records[2].parameters.insert("grains.form".into(), serde_json::json!("own"));
    let out = tempfile::tempdir().unwrap();
    let md = std::fs::read_to_string(report("validation", &records, out.path()).markdown).unwrap();
    let section = &md[md.find("## Comparison with the paper's porosity models").expect(&md)..];
    // Mean 0.362, population std 0.002; model mean 0.357; 0.362 − 0.357 = 0.005.
    assert!(section.contains("| grains.size = U1 | 0.360, 0.364 | 0.362 ± 0.002 | 0.357 | Eq. 23 | 0.005 |"), "{md}");
    // 0.366 − 0.373 = −0.007, with the caveat beside the equation.
    assert!(section.contains("| 0.366 | 0.366 | 0.373 | Eq. 23, extrapolated: σ_EL = 0.006 | -0.007 |"), "{md}");
    // (0.005 + 0.007) / 2 = 0.006.
    assert!(section.contains("Mean absolute difference over 2 setups: 0.0060."), "{md}");
    // Without a model, no section.
    for r in &mut records {
        r.paper_model = None;
    }
    let md = std::fs::read_to_string(report("validation", &records, out.path()).markdown).unwrap();
    assert!(!md.contains("porosity models"), "{md}");
}

#[test]
fn a_model_fitted_to_few_packings_comes_with_a_plain_warning() {
    let records: Vec<JobRecord> = mixture_campaign().into_iter().step_by(4).take(8).collect();
    let out = tempfile::tempdir().unwrap();
    let files = report("few", &records, out.path());
    let md = std::fs::read_to_string(&files.markdown).unwrap();
    let chosen = md.find("### Chosen model").expect("a model is chosen");
    let warning = md.find("**Too few packings for this model:** 8 packings for").expect(&md);
    assert!(warning > chosen && md[chosen..warning].matches("\n\n").count() == 2, "right after the choice: {md}");
    assert!(md[warning..].contains("Run more packings before relying on it."));
}

#[test]
fn a_measurement_without_its_spread_is_shown_without_one() {
    let mut records = validation_campaign();
    for r in &mut records[3..] {
        r.experiment = Some(Experiment { porosity: 0.356, std: None });
    }
    let out = tempfile::tempdir().unwrap();
    let files = report("validation", &records, out.path());
    let md = std::fs::read_to_string(&files.markdown).unwrap();
    assert!(md.contains("| 0.369 ± 0.002 | 0.356 (spread not given) | 0.013 |"), "{md}");
    assert!(md.contains("| 0.371 ± 0.001 |") && !md.contains("± 0.000"), "{md}");
}

#[test]
fn too_few_packings_still_give_a_report_that_says_why() {
    let records: Vec<JobRecord> = validation_campaign().into_iter().take(2).collect();
    let out = tempfile::tempdir().unwrap();
    let files = report("tiny", &records, out.path());
    let md = std::fs::read_to_string(&files.markdown).unwrap();
    assert!(md.contains("No model could be built: too few finished jobs (2) to rank features"), "{md}");
    assert!(md.contains("`dataset.csv` holds 2 rows (packings)"), "{md}");
    assert!(files.models.is_empty());
    check_html(out.path(), 1);
    let one = report("one", &records[..1], out.path());
    let md = std::fs::read_to_string(&one.markdown).unwrap();
    assert!(md.contains("`dataset.csv` holds 1 row (packings)"), "the noun agrees with one packing: {md}");

    let empty = report("empty", &[], out.path());
    assert_eq!(std::fs::read_to_string(empty.dataset).unwrap(), "job_id,porosity\n");
}

/// Two forms packed as ellipsoids and as meshes, of the size case `size_case`, porosities chosen
/// so that means, spreads and differences are worked by hand.
fn shape_records(size_case: Option<&str>) -> Vec<JobRecord> {
    let runs = [
        ("ellipsoid", 0.8, [0.360, 0.364].as_slice()),
        ("mesh", 0.8, &[0.350, 0.352]),
        ("ellipsoid", 0.5, &[0.400]),
        ("mesh", 0.5, &[0.405, 0.409, 0.407]),
    ];
    let mut records = Vec::new();
    for (shape, form, porosities) in runs {
        for (seed, n) in porosities.iter().enumerate() {
            records.push(JobRecord {
                job_id: format!("{shape}-{form}-{seed}"),
                porosity: *n,
                profile: vec![],
                parameters: BTreeMap::from([
                    ("grains.shape".into(), json!(shape)),
                    ("grains.form".into(), json!({"fl": form, "el": form})),
                    ("seed".into(), json!(seed + 1)),
                ]),
                grain_statistics: grain_statistics(&[(form, form); 3]),
                size_case: size_case.map(String::from),
                experiment: None,
                paper: None,
                paper_nearest: None,
                paper_model: None,
                fluid: None,
                imbrication: None,
                size_classes: Vec::new(),
                setup: Vec::new(),
                cost: Cost::default(),
            });
        }
    }
    records
}

/// Fig. 10 for grains of no Table 3 case: the shapes side by side, without a paper model.
#[test]
fn a_campaign_over_grain_shapes_compares_them_at_equal_form() {
    let out = tempfile::tempdir().unwrap();
    let files = report("shapes", &shape_records(None), out.path());
    let md = std::fs::read_to_string(&files.markdown).unwrap();
    // L/S = 1/(FL·EL): 1/0.64 = 1.5625 and 1/0.25 = 4. Form 0.8: 0.362 ± 0.002 against
    // 0.351 ± 0.001, difference −0.011; form 0.5: 0.400 against 0.407 ± 0.00163, +0.007.
    // RMS of (−0.011, +0.007) = √(8.5e-5) = 0.00922.
    assert!(
        md.contains(r#"| grains.form = {"fl":0.8,"el":0.8} | 1.56 | 0.362 ± 0.002 (2) | 0.351 ± 0.001 (2) | -0.011 |"#),
        "{md}"
    );
    assert!(
        md.contains(r#"| grains.form = {"fl":0.5,"el":0.5} | 4.00 | 0.400 (1) | 0.407 ± 0.002 (3) | +0.007 |"#),
        "{md}"
    );
    assert!(md.contains("RMS difference `mesh` − `ellipsoid` over 2 setups: 0.0092."), "{md}");
    assert!(!md.contains("Eq. 17"), "{md}");
    assert!(files.figures.iter().any(|f| f.ends_with("shapes.svg")));
    let svg = check_html(out.path(), 3);
    assert!(svg.contains("Porosity by grain shape"));
}

/// Fig. 10 for single forms of U1: Eq. 17 beside each setup, and each shape's distance from it.
#[test]
fn single_forms_of_a_paper_case_are_compared_with_its_single_form_model() {
    let out = tempfile::tempdir().unwrap();
    let files = report("shapes-u1", &shape_records(Some("U1")), out.path());
    let md = std::fs::read_to_string(&files.markdown).unwrap();
    // Eq. 17 at FL = EL = 0.8 (EQ⁻¹ = 1.5625, EL⁻¹ = 1.25): 0.0296875 + 0.0175 + 0.278 = 0.3251875;
    // at 0.5 (4, 2): 0.076 + 0.028 + 0.278 = 0.382. Ellipsoids lie 0.0368125 and 0.018 above it
    // (mean 0.0274), meshes 0.0258125 and 0.025 (mean 0.0254).
    assert!(
        md.contains(
            r#"| grains.form = {"fl":0.8,"el":0.8} | 1.56 | 0.325 | 0.362 ± 0.002 (2) | 0.351 ± 0.001 (2) | -0.011 |"#
        ),
        "{md}"
    );
    assert!(md.contains(r#"| grains.form = {"fl":0.5,"el":0.5} | 4.00 | 0.382 | 0.400 (1) |"#), "{md}");
    assert!(md.contains("n = 0.019 EQ⁻¹ + 0.014 EL⁻¹ + 0.278"), "{md}");
    assert!(
        md.contains(
            "Against Eq. 17: `ellipsoid` +0.0274 on average, mean absolute difference 0.0274 (2 setups); \
             `mesh` +0.0254 on average, mean absolute difference 0.0254 (2 setups)."
        ),
        "{md}"
    );
    let svg = check_html(out.path(), 3);
    assert!(svg.contains("Eq. 17 (paper&apos;s fit, meshes)") || svg.contains("Eq. 17 (paper's fit, meshes)"), "{svg}");

    // One form alone: the counts are singular. Ellipsoids 0.362 − 0.3251875, meshes 0.351 − 0.3251875.
    let one: Vec<JobRecord> = shape_records(Some("U1")).into_iter().filter(|r| r.job_id.contains("-0.8-")).collect();
    let md = std::fs::read_to_string(report("one-form", &one, out.path()).markdown).unwrap();
    assert!(md.contains("RMS difference `mesh` − `ellipsoid` over 1 setup: 0.0110."), "{md}");
    assert!(md.contains("`mesh` +0.0258 on average, mean absolute difference 0.0258 (1 setup)."), "{md}");

    // Grains of two cases, or drawn from a form distribution, have no one single-form model.
    let mut mixed = shape_records(Some("U1"));
    mixed[0].size_case = Some("U7".into());
    let md = std::fs::read_to_string(report("mixed", &mixed, out.path()).markdown).unwrap();
    assert!(!md.contains("Eq. 17"), "{md}");
    let mut spread = shape_records(Some("U1"));
    spread[0].grain_statistics = grain_statistics(&[(0.7, 0.8), (0.9, 0.8)]);
    let md = std::fs::read_to_string(report("spread", &spread, out.path()).markdown).unwrap();
    assert!(!md.contains("Eq. 17"), "{md}");
}

/// Packings with and without drag, paired by seed; numbers worked by hand.
#[test]
fn a_campaign_with_and_without_drag_compares_them_seed_by_seed() {
    let runs = [
        (None, [(1, 0.350), (2, 0.360), (3, 0.340)].as_slice()),
        (Some("drag and lift, still water"), &[(1, 0.372), (2, 0.380), (3, 0.365), (4, 0.391)]),
    ];
    let mut records = Vec::new();
    for (fluid, porosities) in runs {
        for &(seed, n) in porosities {
            records.push(JobRecord {
                job_id: format!("{}-{seed}", fluid.is_some()),
                porosity: n,
                profile: vec![],
                parameters: BTreeMap::from([
                    ("process.fluid".into(), json!(if fluid.is_some() { "drag" } else { "none" })),
                    ("seed".into(), json!(seed)),
                ]),
                grain_statistics: grain_statistics(&[(0.6, 0.7); 3]),
                size_case: None,
                experiment: None,
                paper: None,
                paper_nearest: None,
                paper_model: None,
                fluid: fluid.map(String::from),
                imbrication: None,
                size_classes: Vec::new(),
                setup: Vec::new(),
                cost: Cost::default(),
            });
        }
    }
    let out = tempfile::tempdir().unwrap();
    let files = report("drag", &records, out.path());
    let md = std::fs::read_to_string(&files.markdown).unwrap();
    // Without drag: mean 0.350, population std √(2e-4/3) = 0.00816. With drag: mean 0.377,
    // std √(3.74e-4/4) = 0.00967. Seeds 1–3 pair: differences 0.022, 0.020, 0.025, mean
    // 0.02233, sample std 0.002517, standard error 0.002517/√3 = 0.00145; seed 4 has no pair.
    assert!(md.contains("| all jobs | buoyancy only | 3 | 0.3500 | 0.0082 | — |"), "{md}");
    assert!(
        md.contains("| all jobs | drag and lift, still water | 4 | 0.3770 | 0.0097 | +0.0223 ± 0.0015 (3 pairs) |"),
        "{md}"
    );
    check_html(out.path(), 0);
}

/// Packings in still water and under a current: the imbrication per setup, worked by hand.
#[test]
fn the_imbrication_of_each_setup_is_summed_over_its_runs() {
    let fabric = |upstream: f64, direction: f64, length: f64| Imbrication {
        grains: 100,
        dip: vec![0.0; solver::fabric::DIP_BINS],
        direction: vec![0.0; solver::fabric::DIRECTION_BINS],
        mean_dip: 18.0,
        upstream,
        resultant_direction: direction,
        resultant_length: length,
    };
    let runs = [
        ("drag and lift, still water", 0.0, vec![fabric(0.5, 0.0, 0.1), fabric(0.4, 90.0, 0.1)]),
        (
            "drag and lift, logarithmic current",
            0.05,
            vec![fabric(0.70, 170.0, 0.4), fabric(0.74, -170.0, 0.4), fabric(0.72, 180.0, 0.5)],
        ),
    ];
    let mut records = Vec::new();
    for (fluid, shear_velocity, fabrics) in runs {
        for (seed, f) in fabrics.into_iter().enumerate() {
            records.push(JobRecord {
                job_id: format!("{shear_velocity}-{seed}"),
                porosity: 0.37,
                profile: vec![],
                parameters: BTreeMap::from([
                    ("fluid.flow.shear_velocity".into(), json!(shear_velocity)),
                    ("seed".into(), json!(seed + 1)),
                ]),
                grain_statistics: grain_statistics(&[(0.8, 0.5); 3]),
                size_case: None,
                experiment: None,
                paper: None,
                paper_nearest: None,
                paper_model: None,
                fluid: Some(fluid.into()),
                imbrication: Some(f),
                size_classes: Vec::new(),
                setup: Vec::new(),
                cost: Cost::default(),
            });
        }
    }
    let out = tempfile::tempdir().unwrap();
    let files = report("imbrication", &records, out.path());
    let md = std::fs::read_to_string(&files.markdown).unwrap();
    // Still water: 50 % and 40 % upstream, mean 45, population std 5; resultants 0.1 at 0° and
    // 0.1 at 90° add to (0.1, 0.1): 45°, length 0.1414/2 = 0.071. Current: 70, 74, 72 %, mean
    // 72, std √(8/3) = 1.63; 0.4 at ±170° and 0.5 at 180° add to (−0.4·2·cos 10° − 0.5, 0) =
    // (−1.288, 0): 180°, length 1.288/3 = 0.429; lengths 0.4, 0.4, 0.5, mean 0.433.
    assert!(
        md.contains("| all jobs | drag and lift, still water | 2 | 45.0 ± 5.0 | 45 (0.07) | 0.10 (0.10–0.10) |"),
        "{md}"
    );
    assert!(
        md.contains(
            "| all jobs | drag and lift, logarithmic current | 3 | 72.0 ± 1.6 | 180 (0.43) | 0.43 (0.40–0.50) |"
        ),
        "{md}"
    );
    // No run deposited with buoyancy only: nothing to pair the porosities with.
    assert!(md.contains("| all jobs | drag and lift, still water | 2 | 0.3700 | 0.0000 |\n"), "{md}");
    assert!(!md.contains("minus buoyancy only"), "{md}");
    check_html(out.path(), 0);
}

#[test]
fn the_report_lists_each_graded_packings_sieve_classes_as_drawn_against_its_curve() {
    use solver::grain::DrawnClass;
    let class =
        |lower: f64, upper: f64, asked: f64, grains: usize, mass: f64| DrawnClass { lower, upper, asked, grains, mass };
    let mut records = validation_campaign();
    for r in &mut records {
        r.size_classes = match r.job_id.as_str() {
            // U1 has one class: nothing to compare, not listed.
            id if id.starts_with("U1") => vec![class(5.6e-3, 8e-3, 1.0, 4000, 3.0)],
            "U3-0" => vec![
                class(5.6e-3, 8e-3, 0.21, 2000, 0.6),
                class(8e-3, 11.2e-3, 0.58, 1800, 1.8),
                class(11.2e-3, 16e-3, 0.21, 200, 0.6),
            ],
            "U3-1" => vec![
                class(5.6e-3, 8e-3, 0.21, 3000, 0.9),
                class(8e-3, 11.2e-3, 0.58, 1500, 1.5),
                class(11.2e-3, 16e-3, 0.21, 200, 0.6),
            ],
            // Stored by an earlier sedpack.
            _ => Vec::new(),
        };
    }
    let out = tempfile::tempdir().unwrap();
    let files = report("validation", &records, out.path());
    let md = std::fs::read_to_string(&files.markdown).unwrap();
    let section = &md[md.find("## Sieve classes as drawn").expect(&md)..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |k| k + 3)];
    assert!(
        section.contains(
            "| job | `grains.size` | `seed` | grains | porosity n | 5.6–8 mm | 8–11.2 mm | 11.2–16 mm | off the curve |"
        ),
        "{section}"
    );
    // U3-0: 0.6, 1.8, 0.6 of 3 kg = 20, 60, 20 % against 21, 58, 21: (1 + 2 + 1)/2 = 2 % off.
    // U3-1: 0.9, 1.5, 0.6 of 3 kg = 30, 50, 20 %: (9 + 8 + 1)/2 = 9 % off.
    assert!(
        section.contains("| `U3-0` | U3 | 1 | 4000 | 0.3670 | 20.0 (21) | 60.0 (58) | 20.0 (21) | 2.0 |"),
        "{section}"
    );
    assert!(
        section.contains("| `U3-1` | U3 | 2 | 4010 | 0.3690 | 30.0 (21) | 50.0 (58) | 20.0 (21) | 9.0 |"),
        "{section}"
    );
    assert!(!section.contains("`U1-") && !section.contains("`U3-2`"), "{section}");
    assert!(
        section.contains("1 packing stored by an earlier sedpack, which did not record the classes, is not listed.")
    );

    // Without a graded packing there is no such section.
    for r in &mut records {
        r.size_classes.retain(|c| c.lower == 5.6e-3);
    }
    let files = report("validation", &records, out.path());
    assert!(!std::fs::read_to_string(&files.markdown).unwrap().contains("Sieve classes as drawn"));
}
