//! Where values cross from one stage to the next, each conversion in one place: a planned job
//! into the store's new job, a packing's result into store rows, and store rows into the
//! analysis's records.

use std::collections::BTreeMap;

use analysis::paper::{model_porosity, nearest_papers_setup, simulated_porosity};
use analysis::record::Cost;
use analysis::{CampaignSummary, Experiment, JobRecord};
use anyhow::Context;
use serde::{Deserialize, Serialize};
use solver::dem::{Calibration, ContactPoint, Domain};
use solver::fabric::Imbrication;
use solver::fluid::flow::Flow;
use solver::grain::DrawnClass;
use solver::packing::{FormSpec, Grid, Orientation, PackingResult, PackingSpec, ShapeKind};
use solver::porosity::ProfilePoint;
use store::{CampaignStatus, ExportRow, GrainStatistic, JobResult, NewJob};

use crate::campaign::PlannedJob;
use crate::{output, stored};

/// The versions of sedpack whose generation threw away the grains that found no room on the grid.
const DROPPED_GRAINS: [&str; 1] = ["0.1.0"];

/// A planned job as the store keeps it: the stored spec and, in typed columns, what later
/// stages read without decoding the spec.
pub fn new_job(job: &PlannedJob) -> NewJob {
    let experiment = job.spec.experiment;
    NewJob {
        id: job.id.clone(),
        format: stored::format(&job.spec),
        spec: stored::encode(&job.spec),
        seed: job.spec.packing.seed,
        parameters: job.parameters.clone(),
        experiment_porosity: experiment.map(|e| e.porosity),
        experiment_std: experiment.and_then(|e| e.std),
        fluid: FluidColumn::of(&job.spec.packing).map(|f| serde_json::to_value(f).expect("numbers and words")),
    }
}

/// The jobs table's `fluid` column: the fluid forces of a job, as later stages read them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct FluidColumn {
    /// kg/m³ and Pa·s.
    density: f64,
    viscosity: f64,
    flow: FlowColumn,
    lift: bool,
    /// m.
    cell: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
enum FlowColumn {
    Quiescent,
    Uniform { velocity: [f64; 3] },
    Laminar { shear_velocity: f64, depth: f64 },
    Logarithmic { shear_velocity: f64, roughness: f64 },
}

impl FluidColumn {
    fn of(spec: &PackingSpec) -> Option<Self> {
        let f = spec.fluid?;
        Some(Self {
            density: spec.material.fluid_density,
            viscosity: f.viscosity,
            flow: match f.flow {
                Flow::Quiescent => FlowColumn::Quiescent,
                Flow::Uniform { velocity } => FlowColumn::Uniform { velocity: velocity.into() },
                Flow::Laminar { shear_velocity, depth } => FlowColumn::Laminar { shear_velocity, depth },
                Flow::Logarithmic { shear_velocity, roughness } => {
                    FlowColumn::Logarithmic { shear_velocity, roughness }
                }
            },
            lift: f.lift,
            cell: spec.derived().fluid_cell,
        })
    }

    /// The fluid in words, for the report.
    fn describe(&self) -> String {
        let flow = match &self.flow {
            FlowColumn::Quiescent => "still water".to_string(),
            FlowColumn::Uniform { velocity: [u, v, w] } => format!("uniform flow ({u}, {v}, {w}) m/s"),
            FlowColumn::Laminar { shear_velocity, depth } => {
                format!("laminar channel, u* = {shear_velocity} m/s, depth {depth} m")
            }
            FlowColumn::Logarithmic { shear_velocity, roughness } => {
                format!("logarithmic current, u* = {shear_velocity} m/s, z₀ = {roughness} m")
            }
        };
        format!("drag{}, {flow}", if self.lift { " and lift" } else { "" })
    }
}

/// A number in a sentence: [`output::number`] without its trailing zeros (16 mm, 0.104 m).
fn number(x: f64) -> String {
    let s = output::number(x);
    if s.contains('.') && !s.contains('e') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s }
}

/// The packing's setup in words, item → value, as the report's campaign table shows it.
fn setup(spec: &PackingSpec) -> Vec<(String, String)> {
    let derived = spec.derived();
    let domain = match spec.domain {
        Domain::Periodic { width } => format!("periodic, L = {} m", number(width)),
        Domain::Cylinder { diameter } => format!("cylinder, L = {} m", number(diameter)),
    };
    let grains = match (spec.grains.shape, &spec.grains.meshes) {
        (ShapeKind::Mesh, Some(library)) => format!("polyhedra from {}, ≤ {} faces", library.source, library.faces),
        (ShapeKind::Mesh, None) => "polyhedra".to_string(),
        (ShapeKind::Sphere, _) => "spheres".to_string(),
        (ShapeKind::Ellipsoid, _) => "ellipsoids".to_string(),
        (ShapeKind::BondedSpheres, _) => "bonded spheres (Sun & Xiao)".to_string(),
    };
    let form = match spec.grains.form {
        FormSpec::Single { fl, el } => format!("FL = {}, EL = {}", number(fl), number(el)),
        FormSpec::Distribution(d) => format!(
            "μ_FL = {}, σ_FL = {}, μ_EL = {}, σ_EL = {}",
            number(d.mu_fl),
            number(d.sigma_fl),
            number(d.mu_el),
            number(d.sigma_el)
        ),
        FormSpec::Own => "each mesh its own".to_string(),
    };
    let size = &spec.grains.size;
    let curve = size.case().map_or_else(
        || {
            let (lo, hi, classes) = (size.smallest_in_use(), size.largest_in_use(), size.classes());
            format!(
                "{}–{} mm, {classes} class{}",
                number(1e3 * lo),
                number(1e3 * hi),
                if classes == 1 { "" } else { "es" }
            )
        },
        |c| format!("{} (Table 3)", c.name),
    );
    let mut items = vec![
        ("domain", format!("{domain}, H = {} m", number(derived.height))),
        ("grains", grains),
        ("form", form),
        ("sieve curve", curve),
        ("mass", format!("{} kg", number(spec.grains.mass))),
        ("generation spacing h_g", format!("{} mm", number(1e3 * derived.spacing))),
        ("shaking after the last grain t_s", format!("{} s", number(spec.process.shaking_duration))),
    ];
    if spec.grains.shape == ShapeKind::Mesh {
        let rule = match spec.contact_point {
            ContactPoint::CentreOfPressure => "centre of pressure of the overlap",
            ContactPoint::Witness => "EPA's witness midpoint (the paper's software)",
        };
        items.push(("contact point", rule.to_string()));
    }
    if spec.calibration == Calibration::Continuous {
        items.push(("k_n and d_n", "Eq. 11 as printed (the paper's software)".to_string()));
    }
    if spec.process.orientation == Orientation::Upright {
        items.push(("new grains", "upright, long axis vertical (the paper's software)".to_string()));
    }
    if spec.process.grid == Grid::Hcp {
        items.push(("generation grid", "hexagonal close-packed (the paper's software)".to_string()));
    }
    items.push((
        "fluid forces",
        FluidColumn::of(spec).map_or_else(|| "none (buoyancy only)".to_string(), |f| f.describe()),
    ));
    items.push(("porosity trim T", format!("{} m", number(derived.trim))));
    items.into_iter().map(|(item, value)| (item.to_string(), value)).collect()
}

/// A finished packing's result row and grain statistics.
pub fn result_rows(result: &PackingResult) -> (JobResult, Vec<GrainStatistic>) {
    let p = &result.porosity;
    let row = JobResult {
        porosity: p.bulk,
        z_minus: p.z_minus,
        z_plus: p.z_plus,
        profile: serde_json::to_value(&p.profile).expect("profile points are two numbers"),
        particles: result.particles as u64,
        simulated_time: result.simulated_time,
        steps: result.steps,
        wall_time: result.wall_time.as_secs_f64(),
        solver_version: solver::VERSION.to_string(),
        imbrication: result.imbrication.as_ref().map(|i| serde_json::to_value(i).expect("numbers")),
        size_classes: Some(serde_json::to_value(&result.size_classes).expect("numbers")),
    };
    let statistics = result
        .statistics
        .iter()
        .map(|s| GrainStatistic { name: s.name.to_string(), mean: s.mean, std: s.std })
        .collect();
    (row, statistics)
}

/// A job as the analysis reads it, with what its packing `spec` says (the Table 3 case of its
/// grains, the paper's porosity for its setup); None for a job without a result.
pub fn job_record(row: &ExportRow, spec: Option<&PackingSpec>) -> anyhow::Result<Option<JobRecord>> {
    let Some(result) = &row.result else { return Ok(None) };
    let profile: Vec<ProfilePoint> = serde_json::from_value(result.profile.clone())
        .with_context(|| format!("job {}: the stored porosity profile is not [{{z, n}}, …]", row.job_id))?;
    let fluid: Option<FluidColumn> = row
        .fluid
        .clone()
        .map(serde_json::from_value)
        .transpose()
        .with_context(|| format!("job {}: the stored fluid is not sedpack's", row.job_id))?;
    let imbrication: Option<Imbrication> = result
        .imbrication
        .clone()
        .map(serde_json::from_value)
        .transpose()
        .with_context(|| format!("job {}: the stored imbrication is not sedpack's", row.job_id))?;
    let size_classes: Vec<DrawnClass> = result
        .size_classes
        .clone()
        .map(serde_json::from_value)
        .transpose()
        .with_context(|| format!("job {}: the stored size classes are not sedpack's", row.job_id))?
        .unwrap_or_default();
    let grain_statistics: BTreeMap<_, _> =
        row.grain_statistics.iter().map(|s| (s.name.clone(), (s.mean, s.std))).collect();
    let paper = spec.and_then(simulated_porosity);
    Ok(Some(JobRecord {
        job_id: row.job_id.clone(),
        porosity: result.porosity,
        profile,
        parameters: row.parameters.iter().map(|(k, v)| (k.clone(), v.clone())).collect(),
        size_case: spec.and_then(|s| s.grains.size.case()).map(|c| c.name.to_string()),
        experiment: row.experiment_porosity.map(|porosity| Experiment { porosity, std: row.experiment_std }),
        paper_nearest: spec.filter(|_| paper.is_none()).map(nearest_papers_setup),
        paper,
        paper_model: spec.and_then(|s| model_porosity(s, &grain_statistics)),
        grain_statistics,
        fluid: fluid.map(|f| f.describe()),
        imbrication,
        size_classes,
        setup: spec.map(setup).unwrap_or_default(),
        cost: Cost { grains: result.particles, simulated_time: result.simulated_time, wall_time: result.wall_time },
    }))
}

/// The campaign's counts and time spent, for the report's header.
pub fn campaign_summary(status: &CampaignStatus, rows: &[ExportRow]) -> CampaignSummary {
    CampaignSummary {
        name: status.campaign.clone(),
        pending: status.pending as usize,
        running: status.running as usize,
        done: status.done as usize,
        failed: status.failed as usize,
        total_runtime: status.wall_time_finished,
        dropped_grains: rows
            .iter()
            .filter(|row| row.result.as_ref().is_some_and(|r| DROPPED_GRAINS.contains(&r.solver_version.as_str())))
            .count(),
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;
    use solver::grain::library::MeshLibrary;
    use solver::grain::size::SieveCurve;
    use solver::packing::DomainKind;
    use store::JobState;

    use super::*;

    fn item<'a>(items: &'a [(String, String)], name: &str) -> Option<&'a str> {
        items.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }

    #[test]
    fn the_setup_in_words_names_the_domain_grains_and_contact_point() {
        // Table 6's cylinder: 3 kg at n = 0.4 fill π 0.052² m² to 3/(2650 · 0.0084949 · 0.6) =
        // 0.2221 m; H = ⌈(0.2221 + 2 · 0.016)/0.6⌉ = 0.43 m (to the centimetre); trim 0.
        let mut cylinder = PackingSpec::paper(DomainKind::Cylinder);
        cylinder.grains.shape = ShapeKind::Mesh;
        cylinder.grains.form = FormSpec::Own;
        cylinder.grains.meshes =
            Some(MeshLibrary { source: "builtin:rhine".into(), faces: 300, digest: String::new(), meshes: vec![] });
        cylinder.contact_point = ContactPoint::Witness;
        let items = setup(&cylinder);
        assert_eq!(item(&items, "domain"), Some("cylinder, L = 0.104 m, H = 0.43 m"));
        assert_eq!(item(&items, "grains"), Some("polyhedra from builtin:rhine, ≤ 300 faces"));
        assert_eq!(item(&items, "form"), Some("each mesh its own"));
        assert_eq!(item(&items, "sieve curve"), Some("U1 (Table 3)"));
        assert_eq!(item(&items, "mass"), Some("3 kg"));
        assert_eq!(item(&items, "generation spacing h_g"), Some("16 mm"));
        assert_eq!(item(&items, "shaking after the last grain t_s"), Some("1 s"));
        assert_eq!(item(&items, "contact point"), Some("EPA's witness midpoint (the paper's software)"));
        assert_eq!(item(&items, "fluid forces"), Some("none (buoyancy only)"));
        assert_eq!(item(&items, "porosity trim T"), Some("0 m"));
        cylinder.contact_point = ContactPoint::CentreOfPressure;
        assert_eq!(item(&setup(&cylinder), "contact point"), Some("centre of pressure of the overlap"));
        // The paper's software's Eq. 11, upright grains and grid are named; sedpack's defaults are not.
        assert_eq!((item(&items, "k_n and d_n"), item(&items, "new grains")), (None, None));
        assert_eq!(item(&items, "generation grid"), None);
        cylinder.calibration = Calibration::Continuous;
        cylinder.process.orientation = Orientation::Upright;
        cylinder.process.grid = Grid::Hcp;
        let items = setup(&cylinder);
        assert_eq!(item(&items, "k_n and d_n"), Some("Eq. 11 as printed (the paper's software)"));
        assert_eq!(item(&items, "new grains"), Some("upright, long axis vertical (the paper's software)"));
        assert_eq!(item(&items, "generation grid"), Some("hexagonal close-packed (the paper's software)"));

        // §6: 16 kg in 0.2 m × 0.2 m reach 16/(2650 · 0.04 · 0.6) = 0.2516 m; a 4–8 mm curve
        // without a case spaces the grid by its largest grain, H = ⌈(0.2516 + 0.016)/0.6⌉ =
        // 0.45 m, and trims its largest sieve. Ellipsoids have no contact point to choose.
        let mut periodic = PackingSpec::paper(DomainKind::Periodic);
        periodic.grains.size = SieveCurve::new(vec![0.004, 0.008], vec![1.0]).unwrap();
        periodic.fluid = Some(solver::packing::FluidSpec::STILL_WATER);
        let items = setup(&periodic);
        assert_eq!(item(&items, "domain"), Some("periodic, L = 0.2 m, H = 0.45 m"));
        assert_eq!(item(&items, "grains"), Some("ellipsoids"));
        assert_eq!(item(&items, "form"), Some("μ_FL = 0.647, σ_FL = 0.175, μ_EL = 0.682, σ_EL = 0.139"));
        assert_eq!(item(&items, "sieve curve"), Some("4–8 mm, 1 class"));
        assert_eq!(item(&items, "generation spacing h_g"), Some("8 mm"));
        assert_eq!(item(&items, "contact point"), None);
        assert_eq!(item(&items, "fluid forces"), Some("drag and lift, still water"));
        assert_eq!(item(&items, "porosity trim T"), Some("0.008 m"));
    }

    fn row(profile: serde_json::Value) -> ExportRow {
        ExportRow {
            job_id: "j1".into(),
            state: JobState::Done,
            seed: 1,
            attempts: 1,
            error: None,
            parameters: serde_json::Map::new(),
            experiment_porosity: Some(0.4),
            experiment_std: None,
            fluid: None,
            result: Some(JobResult {
                porosity: 0.38,
                z_minus: 0.003,
                z_plus: 0.02,
                profile,
                particles: 80,
                simulated_time: 0.3,
                steps: 60_000,
                wall_time: 1.0,
                solver_version: "0.1.0".into(),
                imbrication: None,
                size_classes: None,
            }),
            grain_statistics: vec![GrainStatistic { name: "FL".into(), mean: 0.6, std: 0.05 }],
        }
    }

    #[test]
    fn a_stored_row_becomes_a_record_and_an_unreadable_profile_an_error() {
        let record = job_record(&row(json!([{"z": 0.0005, "n": 0.5}])), None).unwrap().unwrap();
        assert_eq!(record.profile, [ProfilePoint { z: 0.0005, n: 0.5 }]);
        assert_eq!(record.experiment, Some(Experiment { porosity: 0.4, std: None }));
        assert_eq!(record.grain_statistics["FL"], (0.6, 0.05));
        let error = job_record(&row(json!({"z": 1})), None).unwrap_err().to_string();
        assert!(error.contains("job j1") && error.contains("porosity profile"), "{error}");
        let pending = ExportRow { result: None, ..row(json!([])) };
        assert_eq!(job_record(&pending, None).unwrap(), None);
    }

    #[test]
    fn a_jobs_fluid_is_written_at_submission_and_read_back_in_words() {
        use solver::packing::{DomainKind, FluidSpec};
        let mut spec = PackingSpec::paper(DomainKind::Periodic);
        assert_eq!(FluidColumn::of(&spec), None);
        spec.fluid = Some(FluidSpec {
            flow: Flow::Logarithmic { shear_velocity: 0.05, roughness: 2e-4 },
            ..FluidSpec::STILL_WATER
        });
        let column = serde_json::to_value(FluidColumn::of(&spec).unwrap()).unwrap();
        assert_eq!(column["flow"], json!({"kind": "logarithmic", "shear_velocity": 0.05, "roughness": 2e-4}));
        let record = job_record(&ExportRow { fluid: Some(column), ..row(json!([])) }, None).unwrap().unwrap();
        assert_eq!(record.fluid.as_deref(), Some("drag and lift, logarithmic current, u* = 0.05 m/s, z₀ = 0.0002 m"));
        let error = job_record(&ExportRow { fluid: Some(json!({"flow": 1})), ..row(json!([])) }, None).unwrap_err();
        assert!(error.to_string().contains("stored fluid"), "{error}");
    }

    #[test]
    fn a_packing_in_the_models_setting_reads_back_with_the_papers_model_at_its_grains() {
        use solver::packing::DomainKind;
        // Forms with FL and EL spread: Eq. 23 needs μ_EQ, σ_EQ and μ_EL. μ_EQ = 0.5, σ_EQ = 0.1,
        // μ_EL = 0.8 give 0.032·2 − 0.003·10 + 0.011·1.25 + 0.287 = 0.33475.
        let stats = [("FL", 0.6, 0.15), ("EL", 0.8, 0.12), ("EQ", 0.5, 0.1)];
        let grains = stats.map(|(name, mean, std)| GrainStatistic { name: name.into(), mean, std }).to_vec();
        let row = ExportRow { grain_statistics: grains, ..row(json!([])) };
        let mut spec = PackingSpec::paper(DomainKind::Periodic);
        spec.grains.shape = ShapeKind::Mesh;
        let model = job_record(&row, Some(&spec)).unwrap().unwrap().paper_model.expect("in the models' setting");
        assert_eq!(model.equation, "Eq. 23");
        assert!((model.porosity - 0.33475).abs() < 1e-12, "{}", model.porosity);
        // Ellipsoids are not what the models were fitted to.
        spec.grains.shape = ShapeKind::Ellipsoid;
        assert_eq!(job_record(&row, Some(&spec)).unwrap().unwrap().paper_model, None);
    }
}
