//! `sedpack bench`: the engine's speed on standard settled beds ([`solver::bed`]), per shape,
//! thread count and state (at rest; shaken by Eq. 14 with the paper's amplitude and period; or
//! shaken while a layer of new grains lands on it, as in the generation of §4.3), from beds built
//! once and cached.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use solver::bed::{BedSpec, build, rain};
use solver::dem::{Shaking, Shape, Simulation};
use solver::packing::ShapeKind;

use crate::cli::{BenchArgs, BenchShape};
use crate::outln;
use crate::output::{number, print_json};

/// Bumped whenever a cached bed of an earlier build should no longer be used. Beds are stored as
/// JSON, so one whose layout no longer matches fails to read and is built again.
const BED_FORMAT: u32 = 7;
/// The shaking of §4.3 (Eq. 14): amplitude 3e-4 m, period 0.025 s.
const SHAKING: Shaking = Shaking { amplitude: 3e-4, period: 0.025 };
/// Steps run before the clock starts, so that caches are warm and contacts cached.
const WARM_UP: u64 = 20;
/// Default work per measurement, in particle-steps.
const WORK: f64 = 4e6;

#[derive(Debug, Serialize)]
struct Row {
    shape: &'static str,
    grains: usize,
    threads: usize,
    state: &'static str,
    steps: u64,
    seconds: f64,
    particle_steps_per_second: f64,
    /// Contact-stage CPU time (wall time × threads) per open contact between grains.
    us_per_contact: f64,
    /// Mean number of contacts per grain (each pair contact counts for both grains).
    contacts_per_grain: f64,
    /// Memory per grain: its state, shape and pose plus its share of the pair lists.
    bytes_per_grain: f64,
    /// Memory of the base meshes polyhedra share, counted once.
    shared_mesh_bytes: usize,
    /// The machine's 1-minute load average just before the measurement.
    load: Option<f64>,
}

pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    let shapes = match args.shape {
        BenchShape::All => vec![ShapeKind::Sphere, ShapeKind::Ellipsoid, ShapeKind::Mesh, ShapeKind::BondedSpheres],
        BenchShape::Sphere => vec![ShapeKind::Sphere],
        BenchShape::Ellipsoid => vec![ShapeKind::Ellipsoid],
        BenchShape::Mesh => vec![ShapeKind::Mesh],
        BenchShape::BondedSpheres => vec![ShapeKind::BondedSpheres],
    };
    if args.grains.is_some_and(|n| n < 8) {
        bail!("--grains = {} is out of range: expected at least 8 grains", args.grains.unwrap_or(0));
    }
    if args.steps == Some(0) {
        bail!("--steps = 0 is out of range: expected at least 1 step");
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads =
        if args.threads.is_empty() { if cores > 1 { vec![1, cores] } else { vec![1] } } else { args.threads.clone() };
    if let Some(&t) = threads.iter().find(|&&t| t == 0) {
        bail!("--threads = {t} is out of range: expected thread counts of at least 1");
    }
    if args.lammps.is_some() && !shapes.contains(&ShapeKind::Sphere) {
        bail!("--lammps writes the sphere bed: use it with --shape sphere or --shape all");
    }
    let cache = args.cache.clone().unwrap_or_else(default_cache);
    if !args.json {
        eprintln!("sedpack bench: beds cached in {}", cache.display());
    }
    let mut rows = Vec::new();
    for shape in shapes {
        let spec =
            BedSpec { grains: args.grains.unwrap_or(BedSpec::standard(shape).grains), ..BedSpec::standard(shape) };
        let bed = cached_bed(&spec, &cache, args.json)?;
        if shape == ShapeKind::Sphere
            && let Some(path) = &args.lammps
        {
            write_lammps(&bed, path)?;
            if !args.json {
                eprintln!("sedpack bench: wrote {} and {}", path.display(), deck_path(path).display());
            }
        }
        let steps = args.steps.unwrap_or(((WORK / bed.bodies.len() as f64).ceil() as u64).max(50));
        for &t in &threads {
            for state in [State::Settled, State::Shaken, State::Raining] {
                let row = measure(&spec, &bed, t, steps, state)?;
                if !args.json {
                    print_row(&row, rows.is_empty())?;
                }
                rows.push(row);
            }
        }
    }
    if args.json {
        print_json(&rows)?;
    }
    Ok(())
}

fn shape_name(shape: ShapeKind) -> &'static str {
    match shape {
        ShapeKind::Sphere => "sphere",
        ShapeKind::Ellipsoid => "ellipsoid",
        ShapeKind::Mesh => "mesh",
        ShapeKind::BondedSpheres => "bonded-spheres",
    }
}

fn default_cache() -> PathBuf {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    base.join("sedpack").join("bench")
}

/// The settled bed of `spec`, read from the cache or built (with a progress line) and stored
/// there atomically.
fn cached_bed(spec: &BedSpec, cache: &Path, quiet: bool) -> anyhow::Result<Simulation> {
    let path = cache.join(format!("{}-v{}-f{BED_FORMAT}.json", spec.name(), solver::VERSION));
    if let Ok(bytes) = std::fs::read(&path)
        && let Ok(sim) = serde_json::from_slice::<Simulation>(&bytes)
        && sim.bodies.len() == spec.grains
        && sim.bodies.position.iter().all(|p| p.iter().all(|c| c.is_finite()))
    {
        return Ok(sim);
    }
    let bar = if quiet { ProgressBar::hidden() } else { ProgressBar::new_spinner() };
    bar.set_style(ProgressStyle::with_template("{spinner} {msg} [{elapsed}]").expect("a valid template"));
    bar.enable_steady_tick(Duration::from_millis(200));
    let name = spec.name();
    let sim = build(spec, &mut |p| {
        bar.set_message(format!(
            "building {name}: {} t = {:.3} s, {} grains, {} contacts",
            p.phase, p.time, p.grains, p.contacts
        ))
    })
    .with_context(|| format!("building the bed {name}"))?;
    bar.finish_and_clear();
    std::fs::create_dir_all(cache).with_context(|| format!("{}", cache.display()))?;
    let temporary = path.with_extension("tmp");
    std::fs::write(&temporary, serde_json::to_vec(&sim)?).with_context(|| format!("{}", temporary.display()))?;
    std::fs::rename(&temporary, &path).with_context(|| format!("{}", path.display()))?;
    Ok(sim)
}

fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg").ok()?.split_whitespace().next()?.parse().ok()
}

/// What a bed is doing while it is measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// At rest.
    Settled,
    /// Under the shaking of Eq. 14.
    Shaken,
    /// Shaken while a layer of new grains lands on it ([`rain`]), as in the generation.
    Raining,
}

/// Steps a copy of the bed on `threads` threads in `state`.
fn measure(spec: &BedSpec, bed: &Simulation, threads: usize, steps: u64, state: State) -> anyhow::Result<Row> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    let mut sim = bed.clone();
    sim.shaking = (state != State::Settled).then_some(SHAKING);
    if state == State::Raining {
        rain(spec, &mut sim);
    }
    let load = load_average();
    let (elapsed, contact_time, pair_contacts, all_contacts) = pool.install(|| -> anyhow::Result<_> {
        for _ in 0..WARM_UP {
            sim.step()?;
        }
        let before = sim.stage_times().contacts;
        let (mut pairs, mut all) = (0usize, 0usize);
        let start = Instant::now();
        for _ in 0..steps {
            sim.step()?;
            pairs += sim.pair_contacts;
            all += sim.contacts;
        }
        Ok((start.elapsed(), sim.stage_times().contacts - before, pairs, all))
    })?;
    let n = sim.bodies.len();
    let memory = sim.memory();
    let seconds = elapsed.as_secs_f64();
    Ok(Row {
        shape: shape_name(spec.shape),
        grains: n,
        threads,
        state: match state {
            State::Settled => "settled",
            State::Shaken => "shaken",
            State::Raining => "raining",
        },
        steps,
        seconds,
        particle_steps_per_second: (n as u64 * steps) as f64 / seconds,
        us_per_contact: contact_time.as_secs_f64() * threads as f64 / pair_contacts.max(1) as f64 * 1e6,
        contacts_per_grain: (2 * pair_contacts + (all_contacts - pair_contacts)) as f64 / (n as u64 * steps) as f64,
        bytes_per_grain: (memory.bodies + memory.pairs) as f64 / n as f64,
        shared_mesh_bytes: memory.shared_meshes,
        load,
    })
}

fn print_row(row: &Row, header: bool) -> std::io::Result<()> {
    if header {
        outln!(
            "{:<15} {:>6} {:>7} {:>8} {:>17} {:>10} {:>14} {:>12} {:>6}",
            "shape",
            "grains",
            "threads",
            "state",
            "particle-steps/s",
            "µs/contact",
            "contacts/grain",
            "bytes/grain",
            "load"
        )?;
    }
    outln!(
        "{:<15} {:>6} {:>7} {:>8} {:>17} {:>10} {:>14} {:>12} {:>6}",
        row.shape,
        row.grains,
        row.threads,
        row.state,
        number(row.particle_steps_per_second),
        number(row.us_per_contact),
        format!("{:.2}", row.contacts_per_grain),
        format!("{:.0}", row.bytes_per_grain),
        row.load.map_or("?".into(), |l| format!("{l:.2}")),
    )
}

fn deck_path(data: &Path) -> PathBuf {
    let mut name = data.as_os_str().to_owned();
    name.push(".in");
    PathBuf::from(name)
}

/// The sphere bed as a LAMMPS data file (atom style sphere, at rest) and a deck that times
/// LAMMPS on it with the contact law of `peers/lammps/throughput.in`.
fn write_lammps(bed: &Simulation, path: &Path) -> anyhow::Result<()> {
    let width = bed.domain.width();
    let b = &bed.bodies;
    let top = b.position.iter().zip(&b.bounding_radius).map(|(p, r)| p.z + r).fold(0.0, f64::max);
    let mut data = format!(
        "LAMMPS data file: the settled sphere bed of sedpack bench ({} spheres, at rest)\n\n{} atoms\n1 atom types\n\n\
         0 {width:.17e} xlo xhi\n0 {width:.17e} ylo yhi\n0 {:.17e} zlo zhi\n\nAtoms # sphere\n\n",
        b.len(),
        b.len(),
        (2.0 * top).max(0.55),
    );
    for k in 0..b.len() {
        let Shape::Sphere { radius } = b.shape[k] else { bail!("the LAMMPS bed holds spheres only") };
        let p = b.position[k];
        let wrap = |x: f64| x.rem_euclid(width);
        data += &format!(
            "{} 1 {:.17e} {:.17e} {:.17e} {:.17e} {:.17e}\n",
            k + 1,
            2.0 * radius,
            bed.settings.material.density,
            wrap(p.x),
            wrap(p.y),
            p.z
        );
    }
    std::fs::write(path, data).with_context(|| format!("{}", path.display()))?;
    let s = &bed.settings;
    let file = path.file_name().map_or_else(|| path.display().to_string(), |f| f.to_string_lossy().into_owned());
    let deck = format!(
        "# Times LAMMPS on the settled sphere bed written by sedpack bench (run from this folder):\n\
         #   lmp -in {file}.in -log none        (mpirun -np 2 lmp ... for 2 ranks)\n\
         # It prints \"Loop time of T on P procs for N steps with M atoms\": particle-steps/s = M N / T.\n\
         # Contact law as peers/lammps/throughput.in: gran/hooke/history from e, T_c, nu, mu.\n\
         variable nsteps index 20000\n\
         units si\natom_style sphere\nboundary p p f\nnewton off\ncomm_modify vel yes\n\
         read_data {file}\n\
         variable d equal {d:e}\nvariable rho equal {rho}\nvariable geff equal {g}*({rho}-{rho_f})/{rho}\n\
         variable e equal {e}\nvariable Tc equal {tc:e}\nvariable nu equal {nu}\nvariable mu equal {mu}\n\
         variable m equal ${{rho}}*PI*${{d}}^3/6\nvariable meff equal ${{m}}/2\n\
         variable kn equal ${{meff}}*(PI^2+ln(${{e}})^2)/${{Tc}}^2\nvariable gn equal -2*ln(${{e}})/${{Tc}}\n\
         variable kappa equal 2*(1-${{nu}})/(2-${{nu}})\nvariable kt equal ${{kappa}}*${{kn}}\nvariable gt equal 0.5*${{gn}}\n\
         pair_style gran/hooke/history ${{kn}} ${{kt}} ${{gn}} ${{gt}} ${{mu}} 1\npair_coeff * *\n\
         fix wall all wall/gran hooke/history ${{kn}} ${{kt}} ${{gn}} ${{gt}} ${{mu}} 1 zplane 0.0 NULL\n\
         fix grav all gravity ${{geff}} vector 0 0 -1\nfix integ all nve/sphere\n\
         timestep {dt:e}\nneighbor {skin:e} bin\nneigh_modify delay 0 every 1 check yes\n\
         thermo 5000\nrun ${{nsteps}}\n",
        d = 2.0 * b.bounding_radius[0],
        rho = s.material.density,
        rho_f = s.material.fluid_density,
        g = -s.material.gravity.z,
        e = s.material.restitution,
        tc = s.material.collision_time,
        nu = s.material.poisson_ratio,
        mu = s.material.friction,
        dt = s.time_step,
        skin = bed.neighbours().skin(),
    );
    let deck_file = deck_path(path);
    std::fs::write(&deck_file, deck).with_context(|| format!("{}", deck_file.display()))?;
    Ok(())
}
