//! `sedpack pack JOB.yaml`: one packing, with progress on the terminal; writes result.json,
//! profile.csv, particles.csv and packing.vtk.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;

use analysis::paper::{ModelPorosity, PaperPorosity, model_porosity, simulated_porosity};
use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use serde_json::{Map, Value, json};
use solver::fabric::Imbrication;
use solver::grain::{DrawnClass, graded, mass_shares};
use solver::packing::{Packing, PackingResult, Phase};

use crate::cli::PackArgs;
use crate::output::{Table, number, phase_words, print_json};
use crate::spec::{JobSpec, read_job};
use crate::vtk;

/// Steps between progress updates: 0.05 s of simulated time at the paper's Δt.
const STEPS_PER_UPDATE: u64 = 10_000;

#[derive(Serialize)]
struct ResultFile<'a> {
    name: &'a str,
    porosity: f64,
    z_minus: f64,
    z_plus: f64,
    surface: f64,
    particles: usize,
    simulated_time: f64,
    steps: u64,
    wall_time: f64,
    experiment: Option<analysis::Experiment>,
    /// The paper's simulated porosity, for one of its setups (Tables 5–8, 11).
    paper: Option<PaperPorosity>,
    /// The paper's porosity model at the grains' forms, in the models' setting (Eqs. 17–19, 23–24).
    paper_model: Option<ModelPorosity>,
    statistics: Map<String, Value>,
    profile: &'a [solver::porosity::ProfilePoint],
    /// With fluid forces on: the long axes' fabric against the flow.
    #[serde(skip_serializing_if = "Option::is_none")]
    imbrication: Option<&'a Imbrication>,
    /// Grains and mass created per sieve class, against the curve's mass fractions.
    size_classes: &'a [DrawnClass],
}

pub fn run(args: &PackArgs) -> anyhow::Result<()> {
    if args.threads == Some(0) {
        bail!("--threads must be at least 1");
    }
    let job = read_job(&args.job)?;
    if let Some(warning) = job.thin_bed() {
        eprintln!("sedpack: warning: {}: {warning}", args.job.display());
    }
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from(&job.name));
    let mut packing = Packing::new(job.packing.clone()).with_context(|| format!("{}", args.job.display()))?;
    let bar = progress_bar(args.json);
    // Stepping from inside the pool spares every parallel loop a hand-over to the pool.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(args.threads.unwrap_or(0)).build()?;
    pool.install(|| run_to_convergence(&mut packing, &bar, &args.job))?;
    bar.finish_and_clear();
    let result = packing.result().with_context(|| format!("{}", args.job.display()))?;
    write_outputs(&out, &job, &packing, &result)?;
    let record = result_file(&job, &result);
    if args.json {
        return print_json(&record);
    }
    let mut table = Table::default();
    table.row("porosity", format!("{:.4}", record.porosity));
    if let Some(e) = &job.experiment {
        table.row("experiment", format!("{:.4}{}", e.porosity, e.std.map(|s| format!(" ± {s}")).unwrap_or_default()));
    }
    if let Some(p) = &record.paper {
        let std = p.std.map(|s| format!(" ± {s}")).unwrap_or_default();
        table.row("paper", format!("{:.4}{std} (simulated, {})", p.porosity, p.table));
    }
    if let Some(m) = &record.paper_model {
        let caveat = m.caveat.as_ref().map(|c| format!("; {c}")).unwrap_or_default();
        table.row("paper's model", format!("{:.4} ({} at these grains' forms{caveat})", m.porosity, m.equation));
    }
    table
        .row(
            "evaluated",
            format!(
                "{} m – {} m (surface {} m)",
                number(record.z_minus),
                number(record.z_plus),
                number(record.surface)
            ),
        )
        .row("particles", record.particles.to_string())
        .row("simulated time", format!("{:.3} s in {} steps", record.simulated_time, record.steps))
        .row("wall time", format!("{:.1} s", record.wall_time));
    if let Some(f) = record.imbrication {
        table.row(
            "imbrication",
            format!(
                "{} grains: mean dip {:.1}°, {:.0} % dipping upstream, resultant {:.0}° (length {:.2})",
                f.grains,
                f.mean_dip,
                100.0 * f.upstream,
                f.resultant_direction,
                f.resultant_length
            ),
        );
    }
    if graded(record.size_classes) {
        let shares: Vec<String> = (record.size_classes.iter().zip(mass_shares(record.size_classes)))
            .map(|(c, share)| format!("{} {:.1} % ({:.0} % asked)", c.label(), 100.0 * share, 100.0 * c.asked))
            .collect();
        table.row("mass per class", shares.join(", "));
    }
    table.row("output", out.display().to_string());
    table.print()?;
    Ok(())
}

fn run_to_convergence(packing: &mut Packing, bar: &ProgressBar, job: &Path) -> anyhow::Result<()> {
    loop {
        let phase = packing.advance(STEPS_PER_UPDATE).with_context(|| format!("{}", job.display()))?;
        let p = packing.progress();
        bar.set_message(format!(
            "{:<10} t = {:7.3} s  grains {:6} ({:3.0} % of the mass)  contacts {:7}",
            phase_words(p.phase.name(), p.shaking_until),
            p.time,
            p.grains,
            100.0 * p.created,
            p.contacts
        ));
        bar.tick();
        if phase == Phase::Converged {
            break;
        }
    }
    Ok(())
}

fn progress_bar(hidden: bool) -> ProgressBar {
    if hidden {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new_spinner();
    bar.set_style(ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}").expect("valid template"));
    bar.enable_steady_tick(Duration::from_millis(250));
    bar
}

fn result_file<'a>(job: &'a JobSpec, result: &'a PackingResult) -> ResultFile<'a> {
    let mut statistics = Map::new();
    for s in &result.statistics {
        statistics.insert(format!("mean_{}", s.name), json!(s.mean));
        statistics.insert(format!("std_{}", s.name), json!(s.std));
    }
    ResultFile {
        name: &job.name,
        porosity: result.porosity.bulk,
        z_minus: result.porosity.z_minus,
        z_plus: result.porosity.z_plus,
        surface: result.porosity.surface,
        particles: result.particles,
        simulated_time: result.simulated_time,
        steps: result.steps,
        wall_time: result.wall_time.as_secs_f64(),
        experiment: job.experiment,
        paper: simulated_porosity(&job.packing),
        paper_model: model_porosity(
            &job.packing,
            &result.statistics.iter().map(|s| (s.name.to_string(), (s.mean, s.std))).collect(),
        ),
        statistics,
        profile: &result.porosity.profile,
        imbrication: result.imbrication.as_ref(),
        size_classes: &result.size_classes,
    }
}

fn create(path: &Path) -> anyhow::Result<BufWriter<std::fs::File>> {
    Ok(BufWriter::new(std::fs::File::create(path).with_context(|| format!("{}", path.display()))?))
}

fn write_outputs(out: &Path, job: &JobSpec, packing: &Packing, result: &PackingResult) -> anyhow::Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("{}", out.display()))?;
    let mut file = create(&out.join("result.json"))?;
    serde_json::to_writer_pretty(&mut file, &result_file(job, result))?;
    writeln!(file)?;

    let mut file = create(&out.join("profile.csv"))?;
    writeln!(file, "z,n")?;
    for p in &result.porosity.profile {
        writeln!(file, "{},{}", p.z, p.n)?;
    }

    let bodies = &packing.simulation.bodies;
    let mut file = create(&out.join("particles.csv"))?;
    writeln!(file, "id,shape,x,y,z,qw,qx,qy,qz,a,b,c,D,volume")?;
    for k in 0..bodies.len() {
        let (x, q) = (bodies.position[k], bodies.orientation[k]);
        // Semi-axes: the shape's own for spheres and ellipsoids, those of the mass-equivalent
        // ellipsoid (L/2, I/2, S/2) for bonded grains and polyhedra.
        let shape = &bodies.shape[k];
        let form = shape.form();
        let (kind, axes) = match shape {
            solver::dem::Shape::Sphere { radius } => ("sphere", [*radius; 3]),
            solver::dem::Shape::Ellipsoid { semi_axes } => ("ellipsoid", [semi_axes.x, semi_axes.y, semi_axes.z]),
            solver::dem::Shape::Bonded(_) => ("bonded-spheres", [form.l / 2.0, form.i / 2.0, form.s / 2.0]),
            solver::dem::Shape::Polyhedron(_) => ("mesh", [form.l / 2.0, form.i / 2.0, form.s / 2.0]),
        };
        writeln!(
            file,
            "{k},{kind},{},{},{},{},{},{},{},{},{},{},{},{}",
            x.x, x.y, x.z, q.w, q.i, q.j, q.k, axes[0], axes[1], axes[2], packing.grains[k].size, bodies.volume[k]
        )?;
    }
    let sizes: Vec<f64> = packing.grains.iter().map(|g| g.size).collect();
    let mut file = create(&out.join("packing.vtk"))?;
    vtk::write_packing(&mut file, bodies, &sizes, &format!("sedpack packing {}", job.name))?;
    file.flush()?;
    Ok(())
}
