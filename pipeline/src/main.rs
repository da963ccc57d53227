//! The `sedpack` binary: parses the command line and hands over to the library.

use clap::Parser;

fn main() {
    let missing = missing_cpu_features();
    if !missing.is_empty() {
        eprintln!(
            "sedpack: error: this sedpack was built for CPUs with {}, which this CPU lacks; \
             build it for every x86-64 CPU with `RUSTFLAGS= cargo build --release` (.cargo/config.toml)",
            missing.join(", ")
        );
        std::process::exit(1);
    }
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

/// The instruction-set extensions this binary was compiled to use that the CPU does not have.
fn missing_cpu_features() -> Vec<&'static str> {
    #[allow(unused_mut)]
    let mut missing = Vec::new();
    #[cfg(target_arch = "x86_64")]
    {
        macro_rules! check {
            ($($feature:tt),*) => {$(
                if cfg!(target_feature = $feature) && !std::is_x86_feature_detected!($feature) {
                    missing.push($feature);
                }
            )*};
        }
        check!("avx", "avx2", "bmi1", "bmi2", "f16c", "fma", "lzcnt", "movbe", "popcnt", "sse4.2");
    }
    missing
}
