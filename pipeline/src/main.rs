//! The `sedpack` binary: parses the command line and hands over to the library.

use clap::Parser;

fn main() {
    let cli = sedpack::cli::Cli::parse();
    if let Err(error) = sedpack::run(cli) {
        eprintln!("sedpack: error: {error:#}");
        std::process::exit(1);
    }
}
