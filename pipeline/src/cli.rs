//! Command-line arguments (clap).

use std::path::PathBuf;

use clap::{ArgGroup, Args, Parser, Subcommand};

#[derive(Debug, Parser)]
#[command(
    name = "sedpack",
    version,
    about = "Porosity of sediment packings from DEM simulations of non-spherical grains"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Form parameters L, I, S, size D and the 13 form factors of a grain, a mesh, or the
    /// equancy statistics of a form distribution.
    Forms(FormsArgs),
    /// Draw a population of grains and report its statistics.
    #[command(subcommand)]
    Sample(SampleCommand),
    /// Predict porosity with a porosity model.
    Predict(PredictArgs),
    /// Simulate one packing from a job file and evaluate its porosity.
    Pack(PackArgs),
    /// Evaluate the porosity (§4.4) of a packing of spheres given as x,y,z,r rows.
    Porosity(PorosityArgs),
    /// Submit a campaign to the database and run its pending jobs.
    Run(RunArgs),
    /// Finish a campaign after an interruption: jobs of dead runners are run again, jobs that
    /// stopped in Slurm are submitted again.
    Resume(ResumeArgs),
    /// Cancel a Slurm campaign's tasks and return their jobs to pending.
    Cancel(CancelArgs),
    /// Jobs per state, failures, time spent and left.
    Status(StatusArgs),
    /// One CSV row per job (parameters, porosity and grain statistics), or the done jobs whole
    /// for `sedpack import`.
    Export(ExportArgs),
    /// Take the done jobs of files written by `sedpack export --format jsonl` into a database
    /// (created if missing), e.g. to report over seeds run on several machines.
    Import(ImportArgs),
    /// Fit and cross-validate porosity models on a campaign and write the report.
    Report(ReportArgs),
    /// Particle-steps per second of the DEM engine on standard settled beds, per shape, thread
    /// count and state (at rest, shaken, or shaken with new grains raining on it): how to size
    /// a campaign.
    Bench(BenchArgs),
    /// Terminal settling velocity of one grain in still water (the second paper's drag and lift),
    /// beside Haider & Levenspiel's and Dietrich's correlations.
    Settle(SettleArgs),
    /// Run one job of a Slurm campaign in its folder of the run directory (what each Slurm task
    /// runs; never opens the database).
    #[command(hide = true)]
    Task(TaskArgs),
}

/// The grain shapes `sedpack settle` drops.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SettleShape {
    Sphere,
    Ellipsoid,
    Mesh,
    BondedSpheres,
}

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("grain").required(true).args(["lis", "d"])))]
pub struct SettleArgs {
    /// Long, intermediate and short axes of the grain (m), L ≥ I ≥ S > 0.
    #[arg(long, num_args = 3, value_names = ["L", "I", "S"], allow_negative_numbers = true)]
    pub lis: Option<Vec<f64>>,
    /// Diameter of a sphere (m).
    #[arg(long, allow_negative_numbers = true)]
    pub d: Option<f64>,
    /// With --lis: ellipsoid (default), bonded-spheres (Sun & Xiao's grain for L, I, S) or mesh
    /// (the first Rhine scan stretched to L, I, S); --d drops a sphere.
    #[arg(long, value_enum)]
    pub shape: Option<SettleShape>,
    /// Grain density ρ_s (kg/m³).
    #[arg(long, default_value_t = 2650.0, allow_negative_numbers = true)]
    pub density: f64,
    /// Fluid density ρ_f (kg/m³); default: the papers' water.
    #[arg(long, default_value_t = solver::fluid::WATER.density, allow_negative_numbers = true)]
    pub fluid_density: f64,
    /// Dynamic viscosity μ (Pa·s); default: water at 20 °C.
    #[arg(long, default_value_t = solver::fluid::WATER.viscosity, allow_negative_numbers = true)]
    pub viscosity: f64,
    /// Powers' roundness P for Dietrich's correlation (6 perfectly round … 2 angular); default
    /// 6 for the smooth shapes, 3.5 (natural grains) for the mesh.
    #[arg(long, allow_negative_numbers = true)]
    pub roundness: Option<f64>,
    #[arg(long)]
    pub json: bool,
}

/// A shape of `sedpack bench`, or all of them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BenchShape {
    Sphere,
    Ellipsoid,
    Mesh,
    BondedSpheres,
    All,
}

#[derive(Debug, Args)]
pub struct BenchArgs {
    /// The grains of the bed: spheres (the LAMMPS comparison bed), ellipsoids or bonded
    /// spheres of the Rhine form distribution, polyhedra of the Rhine scans, or all.
    #[arg(long, value_enum, default_value = "all")]
    pub shape: BenchShape,
    /// Grains in the bed (default: 2,450 spheres, the LAMMPS bed; 2,000 of the other shapes).
    #[arg(long)]
    pub grains: Option<usize>,
    /// Thread counts to measure with, e.g. 1,2 (default: 1 and all cores).
    #[arg(long, value_delimiter = ',')]
    pub threads: Vec<usize>,
    /// Time steps per measurement (default: about 4 million particle-steps).
    #[arg(long)]
    pub steps: Option<u64>,
    /// Folder of the cached beds (default: ~/.cache/sedpack/bench, or $XDG_CACHE_HOME).
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// Write the sphere bed as a LAMMPS data file here, with an input deck beside it
    /// (FILE.in) that times LAMMPS on exactly these spheres.
    #[arg(long)]
    pub lammps: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct ReportArgs {
    /// The campaign's name.
    pub name: String,
    #[arg(long, default_value = DEFAULT_DB)]
    pub db: PathBuf,
    /// Output folder: report.html, report.md, dataset.csv, models/*.json, figures/*.svg.
    #[arg(long)]
    pub out: PathBuf,
    /// Features correlated with the primary one above this |r| are removed (§6.3.3).
    #[arg(long, default_value_t = 0.8)]
    pub threshold: f64,
    /// k of the k-fold cross-validation.
    #[arg(long, default_value_t = 10)]
    pub folds: usize,
    /// Seed of the fold assignment.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

/// Default database file, in the current folder.
const DEFAULT_DB: &str = "sedpack.db";

#[derive(Debug, Args)]
pub struct RunArgs {
    /// A campaign file (YAML): a job template plus `grid:`, `seeds:` and `executor:`.
    pub campaign: PathBuf,
    #[arg(long, default_value = DEFAULT_DB)]
    pub db: PathBuf,
    #[command(flatten)]
    pub local: LocalArgs,
    #[command(flatten)]
    pub executor: ExecutorArgs,
    #[command(flatten)]
    pub common: ContinueArgs,
}

/// Where the jobs run: the keys of a campaign file's `executor:` block.
#[derive(Debug, Args)]
pub struct ExecutorArgs {
    /// local: this machine's workers (default); slurm: Slurm job arrays, one task per job
    /// (default: the campaign file's `executor.kind`, else what the campaign was submitted with).
    #[arg(long, value_enum)]
    pub executor: Option<crate::executor::Kind>,
    /// More sbatch arguments, one quoted string (e.g. "--partition=compute --account=geo").
    #[arg(long, allow_hyphen_values = true, value_name = "ARGS")]
    pub sbatch: Option<String>,
    /// CPUs of each Slurm task, the threads of its packing (default 1).
    #[arg(long)]
    pub cpus_per_task: Option<usize>,
    /// Wall-time limit of each Slurm task, HH:MM:SS or D-HH:MM:SS; a task is told to checkpoint
    /// and stop shortly before it, and `resume` continues it.
    #[arg(long, value_parser = crate::executor::TimeLimit::parse)]
    pub time: Option<crate::executor::TimeLimit>,
    /// Tasks of one Slurm job array running at once.
    #[arg(long)]
    pub max_parallel: Option<usize>,
}

/// Options of both `run` and `resume`.
#[derive(Debug, Args)]
pub struct ContinueArgs {
    /// Return failed jobs to pending and try them again.
    #[arg(long)]
    pub retry_failed: bool,
    /// Start over the pending jobs whose checkpoints another version of sedpack wrote (without
    /// it, such jobs stop `run` and `resume` before anything starts, so that an upgrade never
    /// throws packing work away unasked).
    #[arg(long)]
    pub discard_old_checkpoints: bool,
    /// Wall-clock seconds between checkpoints of a running packing.
    #[arg(long, default_value_t = 300.0)]
    pub checkpoint_interval: f64,
    /// Slurm: follow the jobs until they end, submitting again those that stopped before their
    /// time limit (without it, return once they are submitted).
    #[arg(long)]
    pub wait: bool,
    /// No progress bars.
    #[arg(long)]
    pub quiet: bool,
    /// Run (or submit to Slurm) only the pending jobs whose grid value KEY is VALUE, e.g.
    /// `--only grains.size=B50 --only seed=1`; given again with the same KEY, any of its values
    /// (the others stay pending for a later `resume`).
    #[arg(long, value_name = "KEY=VALUE")]
    pub only: Vec<String>,
}

#[derive(Debug, Args)]
pub struct ResumeArgs {
    /// The campaign's name.
    pub name: String,
    #[arg(long, default_value = DEFAULT_DB)]
    pub db: PathBuf,
    #[command(flatten)]
    pub local: LocalArgs,
    #[command(flatten)]
    pub common: ContinueArgs,
}

/// How the local executor uses this machine's cores (`run` and `resume`).
#[derive(Debug, Args)]
pub struct LocalArgs {
    /// Packings run at the same time (default: the number of cores); the cores are divided
    /// among them.
    #[arg(long)]
    pub workers: Option<usize>,
    /// Threads of each packing (default: the cores divided among the workers, at least 1); with
    /// two campaigns side by side, `--workers 1 --threads 1` each keeps them off each other's core.
    #[arg(long)]
    pub threads: Option<usize>,
}

#[derive(Debug, Args)]
pub struct CancelArgs {
    /// The campaign's name.
    pub name: String,
    #[arg(long, default_value = DEFAULT_DB)]
    pub db: PathBuf,
}

#[derive(Debug, Args)]
pub struct TaskArgs {
    /// The job's folder in the run directory (it holds job.json).
    pub job_dir: PathBuf,
    /// Threads of the packing.
    #[arg(long, default_value_t = 1)]
    pub threads: usize,
    /// Wall-clock seconds between checkpoints.
    #[arg(long, default_value_t = 300.0)]
    pub checkpoint_interval: f64,
    /// The submission the task belongs to, recorded with its events.
    #[arg(long)]
    pub submission: Option<String>,
}

#[derive(Debug, Args)]
pub struct StatusArgs {
    /// A campaign's name (default: every campaign in the database).
    pub name: Option<String>,
    #[arg(long, default_value = DEFAULT_DB)]
    pub db: PathBuf,
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ExportFormat {
    /// One row per job: parameters, porosity and grain statistics.
    Csv,
    /// The campaign and its done jobs whole, one JSON object per line: what `sedpack import`
    /// takes into another database.
    Jsonl,
}

#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The campaign's name.
    pub name: String,
    #[arg(long, default_value = DEFAULT_DB)]
    pub db: PathBuf,
    #[arg(long, value_enum)]
    pub format: ExportFormat,
    /// Output file (default: standard output).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct ImportArgs {
    /// Files written by `sedpack export --format jsonl`; each is taken in whole or not at all.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    #[arg(long, default_value = DEFAULT_DB)]
    pub db: PathBuf,
}

#[derive(Debug, Args)]
pub struct PackArgs {
    /// A job file (YAML): a campaign without `grid:`; every key has the paper's default.
    pub job: PathBuf,
    /// Output folder (default: the job's name).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print result.json to standard output instead of a table (no progress display).
    #[arg(long)]
    pub json: bool,
    /// Threads of the packing (default: the number of cores).
    #[arg(long)]
    pub threads: Option<usize>,
}

#[derive(Debug, Args)]
pub struct PorosityArgs {
    /// CSV with a header naming columns x, y, z, r (m), one sphere per row.
    pub file: PathBuf,
    /// Side of the horizontally periodic square box (m).
    #[arg(long, allow_negative_numbers = true)]
    pub width: f64,
    /// Slice height h_p (m).
    #[arg(long, default_value_t = 1e-3, allow_negative_numbers = true)]
    pub slice: f64,
    /// Height cut away above the floor and below the surface (m).
    #[arg(long, allow_negative_numbers = true)]
    pub trim: f64,
    /// Porosity defining the free surface.
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    pub cutoff: f64,
    #[arg(long)]
    pub json: bool,
}

/// Mean and standard deviation of flatness and elongation (§7.1).
#[derive(Debug, Clone, Args)]
pub struct DistributionArgs {
    /// Mean flatness μ_FL, in [0.1, 1].
    #[arg(long, allow_negative_numbers = true)]
    pub mu_fl: f64,
    /// Standard deviation of flatness σ_FL, in [0, 1].
    #[arg(long, allow_negative_numbers = true)]
    pub sigma_fl: f64,
    /// Mean elongation μ_EL, in [0.1, 1].
    #[arg(long, allow_negative_numbers = true)]
    pub mu_el: f64,
    /// Standard deviation of elongation σ_EL, in [0, 1].
    #[arg(long, allow_negative_numbers = true)]
    pub sigma_el: f64,
}

/// A form distribution given on the command line beside other inputs: all four parameters or none.
#[derive(Debug, Clone, Args)]
pub struct OptionalDistributionArgs {
    /// Mean flatness μ_FL of a form distribution (with --sigma-fl, --mu-el, --sigma-el).
    #[arg(long, allow_negative_numbers = true, requires_all = ["sigma_fl", "mu_el", "sigma_el"])]
    pub mu_fl: Option<f64>,
    #[arg(long, allow_negative_numbers = true, requires = "mu_fl")]
    pub sigma_fl: Option<f64>,
    #[arg(long, allow_negative_numbers = true, requires = "mu_fl")]
    pub mu_el: Option<f64>,
    #[arg(long, allow_negative_numbers = true, requires = "mu_fl")]
    pub sigma_el: Option<f64>,
}

impl OptionalDistributionArgs {
    /// The distribution, if given (clap makes it all four or none).
    pub fn given(&self) -> Option<DistributionArgs> {
        Some(DistributionArgs {
            mu_fl: self.mu_fl?,
            sigma_fl: self.sigma_fl?,
            mu_el: self.mu_el?,
            sigma_el: self.sigma_el?,
        })
    }
}

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("input").required(true).args(["lis", "mesh", "library", "mu_fl", "bonded"])))]
pub struct FormsArgs {
    /// Long, intermediate and short axes (L ≥ I ≥ S > 0, any length unit).
    #[arg(long, num_args = 3, value_names = ["L", "I", "S"], allow_negative_numbers = true)]
    pub lis: Option<Vec<f64>>,
    /// A closed triangle mesh (STL or OBJ); its form is that of its mass-equivalent ellipsoid.
    #[arg(long)]
    pub mesh: Option<PathBuf>,
    /// A mesh library as job files name it (builtin:rhine, builtin:pebbles or a folder of STL/OBJ
    /// files): each mesh's own form and angularity (its sphericity over that of the ellipsoid of
    /// its form), with their means, beside the Rhine form distribution of Table 2.
    #[arg(long)]
    pub library: Option<String>,
    /// Simplify the mesh (or the library's meshes) to at most this many faces first (quadric
    /// edge collapse, §5.2.1) and report the relative volume change; a library defaults to 300,
    /// as in packings.
    #[arg(long)]
    pub faces: Option<usize>,
    /// The bonded-sphere grain of Sun & Xiao built for axes L ≥ I ≥ S: its Zingg class, component
    /// spheres and mass properties beside those of the ellipsoid with the same axes.
    #[arg(long, num_args = 3, value_names = ["L", "I", "S"], allow_negative_numbers = true)]
    pub bonded: Option<Vec<f64>>,
    #[command(flatten)]
    pub distribution: OptionalDistributionArgs,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Subcommand)]
pub enum SampleCommand {
    /// Draw flatness and elongation from a form distribution (§7.1) and report their statistics.
    Forms(SampleFormsArgs),
    /// Draw grain sizes from a sieve curve (§3.2) and report the mass fraction per sieve class.
    Sizes(SampleSizesArgs),
}

/// How many grains `sample` draws, from which seed, and how it prints them.
#[derive(Debug, Args)]
pub struct DrawArgs {
    /// Number of grains to draw.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub count: u64,
    /// Seed of the random number generator.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct SampleFormsArgs {
    #[command(flatten)]
    pub distribution: DistributionArgs,
    #[command(flatten)]
    pub draw: DrawArgs,
}

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("curve").required(true).args(["case", "sieves"])))]
pub struct SampleSizesArgs {
    /// A size case of Table 3: U1, U3, U5, U7, B30, B50, B70.
    #[arg(long)]
    pub case: Option<String>,
    /// A sieve-curve file (YAML or JSON): {sieves: [m, …], fractions: [mass fraction per class]}.
    #[arg(long)]
    pub sieves: Option<PathBuf>,
    #[command(flatten)]
    pub draw: DrawArgs,
}

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("form").required(true).args(["mu_fl", "fl", "grains"])))]
pub struct PredictArgs {
    /// A saved model (MODEL.json, written by `sedpack report`), or one of the paper's:
    /// paper-U1 | paper-U7 (form mixtures, Eqs. 23–24), paper-sf-U1 | paper-sf-U7 |
    /// paper-sf-B50 (single form, Eqs. 17–19).
    #[arg(long)]
    pub model: String,
    #[command(flatten)]
    pub distribution: OptionalDistributionArgs,
    /// Flatness FL = S/I of a single form, in (0, 1].
    #[arg(long, allow_negative_numbers = true, requires = "el")]
    pub fl: Option<f64>,
    /// Elongation EL = I/L of a single form, in (0, 1].
    #[arg(long, allow_negative_numbers = true, requires = "fl")]
    pub el: Option<f64>,
    /// A CSV of measured grains (a Zingg data set) with columns FL and EL.
    #[arg(long)]
    pub grains: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
}
