//! The sedpack pipeline: the command line, campaign files and the runner. This is the only
//! crate that knows the solver, the store and the analysis together. A job file is parsed
//! (`job_file`), resolved into a checked `JobSpec` (`spec`) and expanded into a campaign's jobs
//! (`campaign`); each is stored in its numbered format (`stored`) and run (`runner`), all of a
//! campaign's pending jobs or those `--only` picks (`selection`); store rows and analysis records
//! meet in `records`.

pub mod campaign;
pub mod cli;
pub mod commands;
pub mod executor;
pub mod job_file;
pub mod meshes;
pub mod output;
pub mod records;
pub mod runner;
pub mod selection;
pub mod slurm;
pub mod spec;
pub mod stored;
pub mod vtk;

use cli::{Cli, Command, SampleCommand};

pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Forms(args) => commands::forms::run(&args),
        Command::Sample(SampleCommand::Forms(args)) => commands::sample::forms(&args),
        Command::Sample(SampleCommand::Sizes(args)) => commands::sample::sizes(&args),
        Command::Predict(args) => commands::predict::run(&args),
        Command::Pack(args) => commands::pack::run(&args),
        Command::Porosity(args) => commands::porosity::run(&args),
        Command::Run(args) => commands::campaign::run(&args),
        Command::Resume(args) => commands::campaign::resume(&args),
        Command::Cancel(args) => commands::campaign::cancel(&args),
        Command::Status(args) => commands::campaign::status(&args),
        Command::Export(args) => commands::campaign::export(&args),
        Command::Import(args) => commands::archive::import(&args),
        Command::Report(args) => commands::report::run(&args),
        Command::Bench(args) => commands::bench::run(&args),
        Command::Settle(args) => commands::settle::run(&args),
        Command::Task(args) => slurm::task::run(&args),
    }
}
