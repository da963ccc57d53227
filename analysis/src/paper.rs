//! The porosity models published in the paper: single-form models (Eqs. 17–19, features
//! L/S = EQ⁻¹ and L/I = EL⁻¹) and form-mixture models (Eqs. 23–24, features built from the
//! number-based mean and standard deviation of EQ and EL), what they give a packing in their
//! setting, and the porosities the paper simulated for the setups of its calibration and
//! validation (Tables 5–8 and 11).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use solver::grain::RHINE_FORMS;
use solver::packing::{Derived, DomainKind, FormSpec, GrainSpec, PackingSpec, ShapeKind};

use crate::dataset::is_single_form_statistics;
use crate::model::{CrossValidation, LinearModel};
use crate::prediction::{input_from_grain_statistics, predict};

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

/// The source a paper model names as its campaign, before its equation.
const SOURCE: &str = "Rettinger et al. (2022), ";

/// The equation a paper model is ("Eq. 17", …), from the campaign it names.
pub fn paper_equation(model: &LinearModel) -> String {
    model.campaign.as_deref().unwrap_or_default().replace(SOURCE, "")
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
        campaign: Some(format!("{SOURCE}{equation}")),
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

/// The porosity the paper obtained by simulation for a setup: the mean of its three runs and
/// their standard deviation where the table gives one (Table 8 does not).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PaperPorosity {
    /// "Table 7", …
    pub table: String,
    pub porosity: f64,
    pub std: Option<f64>,
}

/// A setup the paper simulated: domain, width L (m), total mass (kg), shaking duration t_s (s),
/// Table 3 case and the grains' forms.
struct Setup {
    kind: DomainKind,
    width: f64,
    mass: f64,
    shaking: f64,
    case: &'static str,
    form: FormSpec,
}

/// One simulated setup of Tables 5–8 and 11 with the porosity found.
struct Simulated {
    table: &'static str,
    setup: Setup,
    porosity: f64,
    std: Option<f64>,
}

const fn cylinder(table: &'static str, shaking: f64, case: &'static str, porosity: f64, std: f64) -> Simulated {
    let setup = Setup { kind: DomainKind::Cylinder, width: 0.104, mass: 3.0, shaking, case, form: FormSpec::Own };
    Simulated { table, setup, porosity, std: Some(std) }
}

const fn periodic(
    table: &'static str,
    width: f64,
    mass: f64,
    shaking: f64,
    case: &'static str,
    porosity: f64,
    std: Option<f64>,
) -> Simulated {
    let setup = Setup { kind: DomainKind::Periodic, width, mass, shaking, case, form: FormSpec::Own };
    Simulated { table, setup, porosity, std }
}

/// Table 11's "continuous" setup: the periodic default (0.2 m, 16 kg, t_s = 6 s) with the forms
/// drawn from the Rhine distribution of Table 2.
const fn rhine_forms(case: &'static str, porosity: f64) -> Simulated {
    Simulated {
        table: "Table 11",
        setup: model_setting(case, FormSpec::Distribution(RHINE_FORMS)),
        porosity,
        std: None,
    }
}

/// The setup of the packings the paper fitted its models to (§6.1–6.2): the periodic domain, L =
/// 0.2 m, 16 kg, t_s = 6 s, of `case` with `form`.
const fn model_setting(case: &'static str, form: FormSpec) -> Setup {
    Setup { kind: DomainKind::Periodic, width: 0.2, mass: 16.0, shaking: MODEL_SHAKING, case, form }
}

/// Tables 5–8 and 11 as printed. Where two tables give the same setup (t_s = 1 s in Tables 5
/// and 6, and in Tables 7 and 8; Table 11's "discrete" U7 and Table 8's U7 at t_s = 6 s) they
/// give the same value, and Table 6's, 7's or 8's row is listed. Table 11's "discrete" setup is
/// the periodic default with the meshes' own forms.
/// Table 4 (mesh resolution, t_s = 2 s) is left out: its meshes of ≤ 300 faces repeat Table 5's
/// setup with another run (U7 0.310 against 0.309), and its coarser meshes were simplified by
/// another tool than sedpack's.
const SIMULATED: [Simulated; 32] = [
    cylinder("Table 6", 1.0, "U1", 0.383, 0.002),
    cylinder("Table 6", 1.0, "U3", 0.369, 0.002),
    cylinder("Table 6", 1.0, "U5", 0.333, 0.002),
    cylinder("Table 6", 1.0, "U7", 0.314, 0.001),
    cylinder("Table 6", 1.0, "B30", 0.286, 0.003),
    cylinder("Table 6", 1.0, "B50", 0.280, 0.003),
    cylinder("Table 6", 1.0, "B70", 0.290, 0.001),
    cylinder("Table 5", 0.0, "U7", 0.323, 0.001),
    cylinder("Table 5", 0.0, "B50", 0.284, 0.004),
    cylinder("Table 5", 2.0, "U7", 0.309, 0.001),
    cylinder("Table 5", 2.0, "B50", 0.280, 0.004),
    cylinder("Table 5", 3.0, "U7", 0.309, 0.002),
    cylinder("Table 5", 3.0, "B50", 0.277, 0.004),
    periodic("Table 7", 0.1, 4.0, 1.0, "U7", 0.291, Some(0.001)),
    periodic("Table 7", 0.1, 4.0, 1.0, "B50", 0.246, Some(0.005)),
    periodic("Table 7", 0.2, 16.0, 1.0, "U7", 0.291, Some(0.002)),
    periodic("Table 7", 0.2, 16.0, 1.0, "B50", 0.245, Some(0.003)),
    periodic("Table 7", 0.3, 36.0, 1.0, "U7", 0.291, Some(0.001)),
    periodic("Table 7", 0.3, 36.0, 1.0, "B50", 0.251, Some(0.000)),
    periodic("Table 8", 0.2, 16.0, 2.0, "U7", 0.287, None),
    periodic("Table 8", 0.2, 16.0, 2.0, "B50", 0.241, None),
    periodic("Table 8", 0.2, 16.0, 3.0, "U7", 0.285, None),
    periodic("Table 8", 0.2, 16.0, 3.0, "B50", 0.241, None),
    periodic("Table 8", 0.2, 16.0, 4.0, "U7", 0.283, None),
    periodic("Table 8", 0.2, 16.0, 4.0, "B50", 0.243, None),
    periodic("Table 8", 0.2, 16.0, 6.0, "U7", 0.282, None),
    periodic("Table 8", 0.2, 16.0, 6.0, "B50", 0.242, None),
    periodic("Table 8", 0.2, 16.0, 8.0, "U7", 0.281, None),
    periodic("Table 8", 0.2, 16.0, 8.0, "B50", 0.241, None),
    periodic("Table 11", 0.2, 16.0, 6.0, "U1", 0.353, None),
    rhine_forms("U1", 0.356),
    rhine_forms("U7", 0.288),
];

/// The paper's simulated porosity for the setup of `spec`, if it is one of Tables 5–8 and 11
/// run by the paper's protocol: the table's domain, width, mass, shaking duration and size
/// case; meshes keeping their own forms (§5.1: any library, the paper's being its 63 Rhine
/// scans) or, for Table 11, drawn from the Rhine distribution; no fluid forces; and every other value of the protocol and the evaluation at the paper's
/// (`PackingSpec::paper`), the grid spacing and trim of its rules included. Only the seed, the
/// domain height, the time limit, the meshes, the contact point of polyhedra (sedpack's
/// centre of pressure or the paper's software's witness), the calibration of k_n and d_n
/// (sedpack's discrete one or Eq. 11 as printed), the orientation of new grains (sedpack's
/// random turns or the paper's software's upright grains) and their grid (the text's cubic one
/// or the software's close-packed one) may differ.
pub fn simulated_porosity(spec: &PackingSpec) -> Option<PaperPorosity> {
    let case = spec.grains.size.case()?.name;
    let row = SIMULATED.iter().find(|s| row_differences(&s.setup, spec, case).is_empty())?;
    follows_papers_protocol(spec, row.setup.form).then(|| PaperPorosity {
        table: row.table.to_string(),
        porosity: row.porosity,
        std: row.std,
    })
}

fn domain_kind(spec: &PackingSpec) -> DomainKind {
    if spec.domain.is_periodic() { DomainKind::Periodic } else { DomainKind::Cylinder }
}

/// What of domain, width, mass, t_s, Table 3 case (`case`, the spec's) and forms `spec` has
/// apart from `row`, in words; empty when it is the row's setup.
fn row_differences(row: &Setup, spec: &PackingSpec, case: &str) -> Vec<String> {
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1.0);
    let mut words = Vec::new();
    if row.kind != domain_kind(spec) {
        words.push(format!("the {}", domain_words(domain_kind(spec))));
    } else if !same(row.width, spec.domain.width()) {
        words.push(format!("L = {} m", spec.domain.width()));
    }
    if !same(row.mass, spec.grains.mass) {
        words.push(format!("{} kg", spec.grains.mass));
    }
    if !same(row.shaking, spec.process.shaking_duration) {
        words.push(format!("t_s = {} s", spec.process.shaking_duration));
    }
    if row.case != case {
        words.push(case.to_string());
    }
    if row.form != spec.grains.form {
        words.push(form_words(spec.grains.form));
    }
    words
}

/// Whether `spec` is the paper's protocol (`PackingSpec::paper` of its domain's kind) for meshes
/// of `form`, of its own domain, sieve curve, mass and shaking duration, with no fluid forces;
/// the seed, the domain height, the time limit, the meshes, the contact point of polyhedra, the
/// calibration, the orientation of new grains and their grid may differ, and the grid spacing and trim are compared as the paper's rules
/// work them out.
fn follows_papers_protocol(spec: &PackingSpec, form: FormSpec) -> bool {
    let (papers, rules) = papers_protocol(spec, form);
    let derived = spec.derived();
    papers == *spec && (derived.spacing, derived.trim) == (rules.spacing, rules.trim)
}

/// The paper's protocol for meshes of `form` with everything `follows_papers_protocol` lets
/// differ taken from `spec`, and the spacing and trim its rules give.
fn papers_protocol(spec: &PackingSpec, form: FormSpec) -> (PackingSpec, Derived) {
    let mut papers = PackingSpec::paper(domain_kind(spec));
    papers.domain = spec.domain;
    papers.grains = GrainSpec {
        shape: ShapeKind::Mesh,
        size: spec.grains.size.clone(),
        mass: spec.grains.mass,
        form,
        meshes: spec.grains.meshes.clone(),
    };
    papers.process.shaking_duration = spec.process.shaking_duration;
    papers.process.max_time = spec.process.max_time;
    papers.height = spec.height;
    papers.seed = spec.seed;
    papers.contact_point = spec.contact_point;
    // Eq. 11 as printed is the paper's calibration; sedpack's default is its discrete solution.
    papers.calibration = spec.calibration;
    // §4.3 does not say how new grains lie; its software creates them upright.
    papers.process.orientation = spec.process.orientation;
    // §4.3's grid is "hexahedral"; its software's is close-packed.
    papers.process.grid = spec.process.grid;
    // A stored job names the spacing and trim that the paper's rules give (the stored form is
    // concrete): compared as worked out, not as written.
    let rules = papers.derived();
    (papers.process.spacing, papers.trim) = (spec.process.spacing, spec.trim);
    (papers, rules)
}

/// The paper's simulated setup nearest a packing that is none of them, and what differs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NearestSetup {
    /// "Table 7's U7 (periodic domain, L = 0.1 m, 4 kg, t_s = 1 s, meshes of their own forms)";
    /// None when no row is near (a sieve curve not in Table 3).
    pub setup: Option<String>,
    /// "this setup has t_s = 6 s; it departs from the paper's protocol in process.damping".
    pub differences: String,
}

/// Why a packing that is none of the paper's simulated setups (`simulated_porosity` gives
/// None) is not: the nearest row of Tables 5–8 and 11 (fewest of domain, width, mass, t_s,
/// Table 3 case and forms apart) or, for one form of U1, U7 or B50, §6's single-form packings
/// (in no table), and what differs from it, the protocol's keys included.
pub fn nearest_papers_setup(spec: &PackingSpec) -> NearestSetup {
    let Some(case) = spec.grains.size.case().map(|c| c.name) else {
        let differences =
            "its sieve curve is not named as a case of Table 3 (grains.size: U1 … B70), the only ones the paper simulated"
                .into();
        return NearestSetup { setup: None, differences };
    };
    let single_form = single_form_study(spec, case);
    let (name, row) = match &single_form {
        Some((_, setup)) => (format!("§6's single-form {case} packings"), setup),
        None => {
            let row = SIMULATED
                .iter()
                .min_by_key(|s| row_differences(&s.setup, spec, case).len())
                .expect("the tables have rows");
            (format!("{}'s {}", row.table, row.setup.case), &row.setup)
        }
    };
    // The forms are judged against the row above; the protocol is the rest.
    let (mut papers, rules) = papers_protocol(spec, spec.grains.form);
    if single_form.is_some() && spec.grains.shape == ShapeKind::Ellipsoid {
        // §6.4 packed each form as a mesh and as its form-equivalent ellipsoid.
        papers.grains.shape = ShapeKind::Ellipsoid;
    }
    let mut keys = Vec::new();
    let to_value = |s: &PackingSpec| serde_json::to_value(s).expect("a spec is JSON");
    differing_keys("", &to_value(&papers), &to_value(spec), &mut keys);
    let derived = spec.derived();
    if derived.spacing != rules.spacing {
        keys.push("process.spacing".into());
    }
    if derived.trim != rules.trim {
        keys.push("trim".into());
    }
    let mut differences = Vec::new();
    let here = row_differences(row, spec, case);
    if !here.is_empty() {
        differences.push(format!("this setup has {}", here.join(", ")));
    }
    if !keys.is_empty() {
        differences.push(format!("it departs from the paper's protocol in {}", keys.join(", ")));
    }
    let forms = match &single_form {
        Some((equation, _)) => format!(
            "one form per packing, a scan's or its equivalent ellipsoid's; their porosities are given only as Fig. 10's points and {equation}"
        ),
        None => form_words(row.form),
    };
    let setup = format!(
        "{name} ({}, L = {} m, {} kg, t_s = {} s, {forms})",
        domain_words(row.kind),
        row.width,
        row.mass,
        row.shaking,
    );
    NearestSetup { setup: Some(setup), differences: differences.join("; ") }
}

/// The single-form packings of §6 (Fig. 10, Eqs. 17–19), when `spec` has one form and its
/// Table 3 case (`case`) is one §6 packed: the equation fitted to them and their setup, the
/// setting of the paper's models (`model_setting`) with `spec`'s form.
fn single_form_study(spec: &PackingSpec, case: &'static str) -> Option<(String, Setup)> {
    let FormSpec::Single { .. } = spec.grains.form else {
        return None;
    };
    let equation = paper_equation(&paper_model(&format!("paper-sf-{case}"))?.model);
    Some((equation, model_setting(case, spec.grains.form)))
}

fn domain_words(kind: DomainKind) -> &'static str {
    match kind {
        DomainKind::Periodic => "periodic domain",
        DomainKind::Cylinder => "cylinder",
    }
}

fn form_words(form: FormSpec) -> String {
    match form {
        FormSpec::Own => "meshes of their own forms".into(),
        FormSpec::Distribution(d) if d == RHINE_FORMS => "forms drawn from the Rhine distribution".into(),
        FormSpec::Distribution(d) => {
            format!("forms drawn from μ_FL {}, σ_FL {}, μ_EL {}, σ_EL {}", d.mu_fl, d.sigma_fl, d.mu_el, d.sigma_el)
        }
        FormSpec::Single { fl, el } => format!("one form, FL {fl}, EL {el}"),
    }
}

/// The dotted keys under which two JSON values differ.
fn differing_keys(path: &str, a: &serde_json::Value, b: &serde_json::Value, out: &mut Vec<String>) {
    use serde_json::Value::Object;
    match (a, b) {
        (Object(x), Object(y)) if x.keys().eq(y.keys()) => {
            for (key, value) in x {
                let inner = if path.is_empty() { key.clone() } else { format!("{path}.{key}") };
                differing_keys(&inner, value, &y[key], out);
            }
        }
        _ if a != b => out.push(path.to_string()),
        _ => {}
    }
}

/// The shaking duration t_s (s) of the packings the paper's porosity models were fitted to (§6.1).
const MODEL_SHAKING: f64 = 6.0;

/// Whether a packing is in the setting of the paper's porosity models (Eqs. 17–19, 23–24):
/// meshes of any form in the periodic domain, shaken t_s = 6 s, by the paper's protocol
/// otherwise (`follows_papers_protocol`). Width and mass may differ from the paper's 0.2 m and
/// 16 kg: the models predict a property of the bed, and §6.1 found none of the domain's size
/// from 0.1 m up (Table 7).
pub fn in_model_setting(spec: &PackingSpec) -> bool {
    spec.domain.is_periodic()
        && spec.process.shaking_duration == MODEL_SHAKING
        && follows_papers_protocol(spec, spec.grains.form)
}

/// The nominal parameters of the paper's 52 form-mixture setups (§7.1): means of FL and EL in
/// [0.4, 0.8], standard deviations in [0.1, 0.2]. Outside, the models extrapolate.
pub const MIXTURE_MEANS: [f64; 2] = [0.4, 0.8];
pub const MIXTURE_SIGMAS: [f64; 2] = [0.1, 0.2];

/// Half the smallest nominal standard deviation: the measured spreads of the paper's packings lie
/// somewhat below nominal (the redraw of out-of-range forms), so a model is said to extrapolate
/// for a packing's measured forms only well below.
const SMALLEST_FITTED_SPREAD: f64 = MIXTURE_SIGMAS[0] / 2.0;

/// What the paper's porosity model of a packing's Table 3 case gives at its grains' measured
/// form statistics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelPorosity {
    /// The model's name for `sedpack predict --model`: "paper-sf-U1", "paper-U1", …
    pub model: String,
    /// "Eq. 17", …
    pub equation: String,
    pub porosity: f64,
    /// Why the model extrapolates for these grains, if it does.
    pub caveat: Option<String>,
}

/// The paper's model for a packing of `spec` whose grains have the number-based (mean, std)
/// `statistics` of the Table 1 factors: the single-form model of its case (Eqs. 17–19) for one
/// form, the form-mixture model (Eqs. 23–24) otherwise. None outside the models' setting
/// (`in_model_setting`) or for a case without a model (single forms: U1, U7, B50; mixtures: U1,
/// U7).
pub fn model_porosity(spec: &PackingSpec, statistics: &BTreeMap<String, (f64, f64)>) -> Option<ModelPorosity> {
    if !in_model_setting(spec) {
        return None;
    }
    let case = spec.grains.size.case()?.name;
    let single = is_single_form_statistics(statistics)?;
    let name = if single { format!("paper-sf-{case}") } else { format!("paper-{case}") };
    let paper = paper_model(&name)?;
    let porosity =
        predict(&paper.model, &input_from_grain_statistics(statistics, "the packing's grains")).ok()?.porosity;
    let narrow: Vec<String> = ["FL", "EL"]
        .into_iter()
        .filter_map(|f| {
            let std = statistics.get(f)?.1;
            (std < SMALLEST_FITTED_SPREAD).then(|| format!("σ_{f} = {std:.3}"))
        })
        .collect();
    let caveat = (!single && !narrow.is_empty()).then(|| {
        format!(
            "{}, far below the paper's smallest spread ({}); the form-mixture model does not hold for vanishing spread (§7.2)",
            narrow.join(", "),
            MIXTURE_SIGMAS[0]
        )
    });
    let equation = paper_equation(&paper.model);
    Some(ModelPorosity { model: name, equation, porosity, caveat })
}

#[cfg(test)]
mod tests {
    use super::*;
    use solver::dem::Domain;
    use solver::grain::TABLE3;

    /// The paper's protocol with meshes of their own forms, of `case` in a domain of `kind`.
    fn meshes(kind: DomainKind, case: &str) -> PackingSpec {
        let mut spec = PackingSpec::paper(kind);
        spec.grains.shape = ShapeKind::Mesh;
        spec.grains.form = FormSpec::Own;
        spec.grains.size = TABLE3.iter().find(|c| c.name == case).unwrap().sieve_curve();
        spec
    }

    fn table7(case: &str) -> PackingSpec {
        let mut spec = meshes(DomainKind::Periodic, case);
        (spec.domain, spec.grains.mass, spec.process.shaking_duration) = (Domain::Periodic { width: 0.1 }, 4.0, 1.0);
        spec
    }

    fn found(spec: &PackingSpec) -> Option<(String, f64, Option<f64>)> {
        simulated_porosity(spec).map(|p| (p.table, p.porosity, p.std))
    }

    #[test]
    fn the_papers_setups_find_their_tables_row() {
        // Values as printed in Tables 5–8 and 11 of the paper.
        assert_eq!(found(&table7("U7")), Some(("Table 7".into(), 0.291, Some(0.001))));
        assert_eq!(found(&table7("B50")), Some(("Table 7".into(), 0.246, Some(0.005))));
        // The cylinder of §5.1 (0.104 m, 3 kg, t_s = 1 s) is Table 6's setup, for every case.
        assert_eq!(found(&meshes(DomainKind::Cylinder, "U3")), Some(("Table 6".into(), 0.369, Some(0.002))));
        assert_eq!(found(&meshes(DomainKind::Cylinder, "B70")), Some(("Table 6".into(), 0.290, Some(0.001))));
        let mut unshaken = meshes(DomainKind::Cylinder, "U7");
        unshaken.process.shaking_duration = 0.0;
        assert_eq!(found(&unshaken), Some(("Table 5".into(), 0.323, Some(0.001))));
        // The periodic default (0.2 m, 16 kg, t_s = 6 s) is a column of Table 8, without spread,
        // and for U1 Table 11's "discrete" run; with the Rhine forms drawn, its "continuous" one.
        assert_eq!(found(&meshes(DomainKind::Periodic, "U7")), Some(("Table 8".into(), 0.282, None)));
        assert_eq!(found(&meshes(DomainKind::Periodic, "U1")), Some(("Table 11".into(), 0.353, None)));
        let mut drawn = meshes(DomainKind::Periodic, "U1");
        drawn.grains.form = FormSpec::Distribution(RHINE_FORMS);
        assert_eq!(found(&drawn), Some(("Table 11".into(), 0.356, None)));
        drawn.grains.size = TABLE3.iter().find(|c| c.name == "U7").unwrap().sieve_curve();
        assert_eq!(found(&drawn), Some(("Table 11".into(), 0.288, None)));
        // Another distribution, or Table 11's scaled down, is no setup of the paper's.
        let mut other = drawn.clone();
        other.grains.form = FormSpec::Distribution(solver::grain::FormDistribution { mu_fl: 0.5, ..RHINE_FORMS });
        assert_eq!(found(&other), None);
        drawn.domain = Domain::Periodic { width: 0.06 };
        drawn.grains.mass = 1.44;
        assert_eq!(found(&drawn), None);
    }

    #[test]
    fn seed_height_time_limit_explicit_defaults_and_the_papers_software_keep_the_setup() {
        let mut spec = table7("U7");
        spec.seed = 7;
        spec.height = Some(0.5);
        spec.process.max_time = Some(20.0);
        // The periodic trim is the largest sieve, 31.5 mm for U7 (§6.1: h^pd = 31.5 mm), and the
        // grid spacing Table 3's h_g, 22 mm: stored jobs name both.
        spec.trim = Some(0.0315);
        spec.process.spacing = Some(0.022);
        assert_eq!(found(&spec).map(|f| f.1), Some(0.291));
        // The paper's software's contact point is the paper's setup too.
        spec.contact_point = solver::dem::ContactPoint::Witness;
        assert_eq!(found(&spec).map(|f| f.1), Some(0.291));
        // So is Eq. 11 as the paper prints it, which its software uses, and its software's
        // upright new grains and close-packed grid.
        spec.calibration = solver::dem::Calibration::Continuous;
        assert_eq!(found(&spec).map(|f| f.1), Some(0.291));
        spec.process.orientation = solver::packing::Orientation::Upright;
        assert_eq!(found(&spec).map(|f| f.1), Some(0.291));
        spec.process.grid = solver::packing::Grid::Hcp;
        assert_eq!(found(&spec).map(|f| f.1), Some(0.291));
    }

    #[test]
    fn any_other_change_is_not_the_papers_setup() {
        type Change = (&'static str, fn(&mut PackingSpec));
        let changes: [Change; 13] = [
            ("ellipsoids", |s| s.grains.shape = ShapeKind::Ellipsoid),
            ("one form", |s| s.grains.form = FormSpec::Single { fl: 0.6, el: 0.7 }),
            ("mass", |s| s.grains.mass = 4.5),
            ("width", |s| s.domain = Domain::Periodic { width: 0.15 }),
            ("cylinder", |s| s.domain = Domain::Cylinder { diameter: 0.1 }),
            ("shaking not in Table 7", |s| s.process.shaking_duration = 2.0),
            ("a case the table lacks", |s| s.grains.size = TABLE3[0].sieve_curve()),
            ("time step", |s| s.time_step = 1e-5),
            ("damping", |s| s.process.damping = 1e-2),
            ("grid spacing", |s| s.process.spacing = Some(0.03)),
            ("trim", |s| s.trim = Some(0.0)),
            ("slice", |s| s.slice = 2e-3),
            ("fluid", |s| {
                s.fluid = Some(solver::packing::FluidSpec {
                    viscosity: 1e-3,
                    flow: solver::fluid::flow::Flow::Quiescent,
                    lift: false,
                    cell: None,
                    coupling: None,
                })
            }),
        ];
        for (what, change) in changes {
            let mut spec = table7("U7");
            change(&mut spec);
            assert_eq!(found(&spec), None, "{what}");
        }
    }

    #[test]
    fn a_setup_that_is_none_of_the_papers_is_told_the_nearest_and_what_differs() {
        let told = |change: fn(&mut PackingSpec)| {
            let mut spec = table7("U7");
            change(&mut spec);
            assert_eq!(found(&spec), None);
            let nearest = nearest_papers_setup(&spec);
            (nearest.setup.unwrap_or_default(), nearest.differences)
        };
        let row = "Table 7's U7 (periodic domain, L = 0.1 m, 4 kg, t_s = 1 s, meshes of their own forms)";
        // Table 11's U7 forms in Table 7's setup: one apart from Table 7's row, three from Table 11's.
        let drawn = told(|s| s.grains.form = FormSpec::Distribution(RHINE_FORMS));
        assert_eq!(drawn, (row.into(), "this setup has forms drawn from the Rhine distribution".into()));
        let ellipsoids = told(|s| s.grains.shape = ShapeKind::Ellipsoid);
        assert_eq!(ellipsoids, (row.into(), "it departs from the paper's protocol in grains.shape".into()));
        let both = told(|s| (s.process.shaking_duration, s.process.damping) = (2.0, 1e-2));
        let differences = "this setup has t_s = 2 s; it departs from the paper's protocol in process.damping";
        assert_eq!(both, (row.into(), differences.into()));
        let spacing = told(|s| s.process.spacing = Some(0.03));
        assert_eq!(spacing.1, "it departs from the paper's protocol in process.spacing");
        // Scaled down, Table 11's U1 is nearest the default periodic U1 of Table 11's scans.
        let mut scaled = table11();
        scaled.grains.size = TABLE3[0].sieve_curve();
        let nearest = nearest_papers_setup(&scaled);
        assert_eq!(
            nearest.setup.as_deref(),
            Some(
                "Table 11's U1 (periodic domain, L = 0.2 m, 16 kg, t_s = 6 s, forms drawn from the Rhine distribution)"
            )
        );
        assert_eq!(nearest.differences, "this setup has L = 0.06 m, 1.44 kg");
        let mut custom = table7("U7");
        custom.grains.size = solver::grain::SieveCurve::new(vec![0.01, 0.02], vec![1.0]).unwrap();
        assert_eq!(nearest_papers_setup(&custom).setup, None);
    }

    #[test]
    fn a_single_form_packing_is_told_the_single_form_study_of_section_6_in_no_table() {
        // Fig. 10 scaled down like validation-single-forms: U1 in 0.04 m, 0.64 kg, one form.
        let single = |shape, case: usize| {
            let mut spec = table11();
            (spec.domain, spec.grains.mass) = (Domain::Periodic { width: 0.04 }, 0.64);
            spec.grains.size = TABLE3[case].sieve_curve();
            (spec.grains.shape, spec.grains.form) = (shape, FormSpec::Single { fl: 0.53, el: 0.53 });
            assert_eq!(found(&spec), None);
            nearest_papers_setup(&spec)
        };
        let study = "§6's single-form U1 packings (periodic domain, L = 0.2 m, 16 kg, t_s = 6 s, one form per packing, a scan's or its equivalent ellipsoid's; their porosities are given only as Fig. 10's points and Eq. 17)";
        // §6.4 packed every form both as a mesh and as its ellipsoid: neither departs.
        for shape in [ShapeKind::Mesh, ShapeKind::Ellipsoid] {
            let nearest = single(shape, 0);
            assert_eq!(nearest.setup.as_deref(), Some(study), "{shape:?}");
            assert_eq!(nearest.differences, "this setup has L = 0.04 m, 0.64 kg", "{shape:?}");
        }
        let spheres = single(ShapeKind::Sphere, 0);
        assert_eq!(
            spheres.differences,
            "this setup has L = 0.04 m, 0.64 kg; it departs from the paper's protocol in grains.shape"
        );
        // B50 has its own single-form model (Eq. 19); U3 (TABLE3[1]) was not packed in single
        // forms, so the nearest is a table's row.
        let b50 = TABLE3.iter().position(|c| c.name == "B50").unwrap();
        assert!(single(ShapeKind::Mesh, b50).setup.unwrap().ends_with("Fig. 10's points and Eq. 19)"));
        assert_eq!(TABLE3[1].name, "U3");
        let u3 = single(ShapeKind::Mesh, 1).setup.unwrap();
        assert!(u3.starts_with("Table ") && !u3.contains("Fig. 10"), "{u3}");
    }

    /// The paper's periodic setting of its models (t_s = 6 s) with meshes of the Rhine form
    /// distribution, scaled down like Table 11's campaign (L = 0.06 m, 1.44 kg).
    fn table11() -> PackingSpec {
        let mut spec = PackingSpec::paper(DomainKind::Periodic);
        spec.grains.shape = ShapeKind::Mesh;
        (spec.domain, spec.grains.mass) = (Domain::Periodic { width: 0.06 }, 1.44);
        spec
    }

    #[test]
    fn the_models_setting_is_the_periodic_protocol_at_six_seconds_for_any_form_width_and_mass() {
        assert!(in_model_setting(&table11()));
        let mut own = table11();
        own.grains.form = FormSpec::Own;
        assert!(in_model_setting(&own), "the scans' own forms (Table 11's discrete variant)");
        let mut witness = table11();
        witness.contact_point = solver::dem::ContactPoint::Witness;
        assert!(in_model_setting(&witness));
        type Change = (&'static str, fn(&mut PackingSpec));
        let changes: [Change; 4] = [
            ("ellipsoids", |s| s.grains.shape = ShapeKind::Ellipsoid),
            ("t_s = 1 s (Table 7)", |s| s.process.shaking_duration = 1.0),
            ("cylinder", |s| s.domain = Domain::Cylinder { diameter: 0.104 }),
            ("damping", |s| s.process.damping = 1e-2),
        ];
        for (what, change) in changes {
            let mut spec = table11();
            change(&mut spec);
            assert!(!in_model_setting(&spec), "{what}");
        }
    }

    #[test]
    fn a_packing_gets_its_cases_model_at_its_grains_measured_forms() {
        // One form, FL = EL = 0.5: L/S = 1/(FL·EL) = 4, L/I = 2; Eq. 17 gives
        // 0.019·4 + 0.014·2 + 0.278 = 0.382.
        let single = crate::form_factors::grain_statistics(&[(0.5, 0.5); 3]);
        let p = model_porosity(&table11(), &single).expect("U1 has a single-form model");
        assert_eq!((p.model.as_str(), p.equation.as_str(), p.caveat.as_deref()), ("paper-sf-U1", "Eq. 17", None));
        assert!((p.porosity - 0.382).abs() < 1e-12, "{}", p.porosity);
        // Two grains (FL, EL) = (0.4, 0.5) and (0.8, 1.0): EQ = FL·EL = 0.2 and 0.8, so
        // μ_EQ = 0.5, σ_EQ = 0.3 (population), μ_EL = 0.75; Eq. 23 gives
        // 0.032/0.5 − 0.003/0.3 + 0.011/0.75 + 0.287 = 0.355667.
        let mixture = crate::form_factors::grain_statistics(&[(0.4, 0.5), (0.8, 1.0)]);
        let p = model_porosity(&table11(), &mixture).expect("U1 has a form-mixture model");
        assert_eq!((p.model.as_str(), p.equation.as_str(), p.caveat.as_deref()), ("paper-U1", "Eq. 23", None));
        assert!((p.porosity - (0.064 - 0.01 + 0.011 / 0.75 + 0.287)).abs() < 1e-12, "{}", p.porosity);
        // The two scans' forms: σ_EL of 0.006, where the paper's packings had 0.1 or 0.2.
        let scans = crate::form_factors::grain_statistics(&[(0.446, 0.538), (0.856, 0.526)]);
        let caveat = model_porosity(&table11(), &scans).and_then(|p| p.caveat).expect("a caveat");
        assert!(caveat.starts_with("σ_EL = 0.006, far below"), "{caveat}");
        // No mixture model for B50, no model at all for U3, none outside the setting.
        let mut b50 = table11();
        b50.grains.size = TABLE3.iter().find(|c| c.name == "B50").unwrap().sieve_curve();
        assert_eq!(model_porosity(&b50, &mixture), None);
        assert_eq!(model_porosity(&b50, &single).map(|p| p.equation), Some("Eq. 19".into()));
        let mut u3 = table11();
        u3.grains.size = TABLE3.iter().find(|c| c.name == "U3").unwrap().sieve_curve();
        assert_eq!(model_porosity(&u3, &single), None);
        let mut table7 = table11();
        table7.process.shaking_duration = 1.0;
        assert_eq!(model_porosity(&table7, &single), None);
    }
}
