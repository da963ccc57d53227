//! The `sedpack` binary: parses the command line and hands over to the library.

use clap::Parser;

fn main() {
    let cli = sedpack::cli::Cli::parse();
    if let Err(error) = sedpack::run(cli) {
        // The reader of a pipe went away (`sedpack … | head`): it has what it wanted, as a Unix
        // tool killed by SIGPIPE would leave it, but without a message.
        if sedpack::output::is_closed_pipe(&error) {
            std::process::exit(0);
        }
        eprintln!("sedpack: error: {error:#}");
        std::process::exit(1);
    }
}
