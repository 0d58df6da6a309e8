//! `vitrine`: encode scanned meshes into progressive streams, store them, serve them.

use clap::Parser;

/// mimalloc, not glibc's malloc: serving a cached batch allocates and frees
/// a few dozen small blocks (request, headers, futures), and glibc's
/// allocator was a tenth of the service's CPU under wrk (perf, issue 46).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

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
