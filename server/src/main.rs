//! `vitrine`: encode scanned meshes into progressive streams, store them, serve them.

use clap::Parser;

#[derive(Parser)]
#[command(
    name = "vitrine",
    version,
    about = "Progressive 3D scans for museum websites"
)]
struct Cli {
    #[command(subcommand)]
    command: vitrine::Command,
}

fn main() -> anyhow::Result<()> {
    Cli::parse().command.run()
}
