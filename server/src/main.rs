//! `vitrine`: encode scanned meshes into progressive streams, store them, serve them.

mod cli;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "vitrine",
    version,
    about = "Progressive 3D scans for museum websites"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Encode a mesh and store it in the database (one transaction).
    Ingest(vitrine::IngestArgs),
    /// Serve models, refinement batches and the viewer over HTTP.
    Serve(vitrine::ServeArgs),
    /// Create an access token for researcher-level audiences.
    Token(vitrine::TokenArgs),
    /// List the stored models and whether this build serves their stream format.
    Models(vitrine::ModelsArgs),
    /// Encode a mesh (PLY, OBJ, OFF, glTF/GLB) into a progressive stream file.
    Encode(cli::encode::EncodeArgs),
    /// Decode a stream file up to a level and write PLY, OBJ or GLB.
    Decode(cli::decode::DecodeArgs),
    /// Per-level table of a stream: vertices, faces, bytes, bits per vertex.
    Inspect(cli::inspect::InspectArgs),
    /// Benchmark the codec on a folder of meshes and print a markdown table.
    Bench(cli::bench::BenchArgs),
    /// Compare the colour modes (ccc, vertex, vertex-metric) on coloured meshes: sizes and quality per level.
    ColourBench(cli::colour_bench::ColourBenchArgs),
    /// Write a generated sample mesh (torus, sphere, plate) as PLY.
    Sample(cli::sample::SampleArgs),
    /// Write the native decoder's buffers at every level (for cross-checks).
    #[command(hide = true)]
    DumpLevels(cli::dump::DumpArgs),
    /// One mesh of `bench`, in its own process so peak memory is its own.
    #[command(hide = true)]
    BenchOne(cli::bench::BenchOneArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    let runtime = || {
        tokio::runtime::Builder::new_multi_thread()
            .enable_all()
            .build()
    };
    match cli.command {
        Command::Ingest(args) => runtime()?.block_on(vitrine::run_ingest(args)),
        Command::Serve(args) => runtime()?.block_on(vitrine::run_serve(args)),
        Command::Token(args) => runtime()?.block_on(vitrine::run_token(args)),
        Command::Models(args) => runtime()?.block_on(vitrine::run_models(args)),
        Command::Encode(args) => cli::encode::run(args),
        Command::Decode(args) => cli::decode::run(args),
        Command::Inspect(args) => cli::inspect::run(args),
        Command::Bench(args) => cli::bench::run(args),
        Command::BenchOne(args) => cli::bench::run_one(args),
        Command::Sample(args) => cli::sample::run(args),
        Command::ColourBench(args) => cli::colour_bench::run(args),
        Command::DumpLevels(args) => cli::dump::run(args),
    }
}
