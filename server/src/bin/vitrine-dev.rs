//! `vitrine-dev`: the developer tools (benchmarks beside Google Draco, the
//! colour-mode comparison, the native decoder's buffers for cross-checks).
//! Not shipped: built with `cargo build -p vitrine --features dev-tools`.

use clap::Parser;

#[derive(Parser)]
#[command(
    name = "vitrine-dev",
    version,
    about = "Vitrine's developer tools: codec benchmarks and cross-checks"
)]
struct Cli {
    #[command(subcommand)]
    command: vitrine::DevCommand,
}

fn main() -> anyhow::Result<()> {
    Cli::parse().command.run()
}
