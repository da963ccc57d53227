//! The sedpack pipeline: the command line, campaign files and the runner. This is the only
//! crate that knows the solver, the store and the analysis together.

pub mod cli;
pub mod commands;
pub mod output;

use cli::{Cli, Command, SampleCommand};

pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Forms(args) => commands::forms::run(&args),
        Command::Sample(SampleCommand::Forms(args)) => commands::sample::forms(&args),
        Command::Sample(SampleCommand::Sizes(args)) => commands::sample::sizes(&args),
        Command::Predict(args) => commands::predict::run(&args),
    }
}
