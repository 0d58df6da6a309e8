//! The subcommands, one module each, holding its clap arguments and its
//! `run`: [`Command`] is `vitrine`'s, `DevCommand` (feature `dev-tools`)
//! the developer tools of `vitrine-dev`. The binaries only parse and call
//! [`Command::run`].

pub mod charts;
pub mod decode;
pub mod encode;
pub mod guard;
pub mod ingest;
pub mod inspect;
pub mod lod;
pub mod mesh_format;
pub mod models;
mod parts;
pub mod sample;
pub mod serve;
pub mod simplify;
pub mod simplify_voronoi;
pub mod study;
pub mod texts;
pub mod token;

#[cfg(feature = "dev-tools")]
pub mod bench;
#[cfg(feature = "dev-tools")]
pub mod bit_budget;
#[cfg(feature = "dev-tools")]
pub mod colour_bench;
#[cfg(feature = "dev-tools")]
pub mod dump_levels;

use clap::Subcommand;
use std::future::Future;

#[derive(Subcommand)]
pub enum Command {
    /// Encode a mesh and store it in the database (one transaction).
    Ingest(ingest::IngestArgs),
    /// Serve models, refinement batches and the viewer over HTTP.
    Serve(serve::ServeArgs),
    /// Create an access token for researcher-level audiences.
    Token(token::TokenArgs),
    /// List the stored models and whether this build serves their stream format.
    Models(models::ModelsArgs),
    /// Encode a mesh (PLY, OBJ, OFF, glTF/GLB) into a progressive stream file.
    Encode(encode::EncodeArgs),
    /// Decode a stream file up to a level and write PLY, OBJ or GLB.
    Decode(decode::DecodeArgs),
    /// Per-level table of a stream: vertices, faces, bytes, bits per vertex.
    Inspect(inspect::InspectArgs),
    /// Write a generated sample mesh (torus, sphere, plate) as PLY.
    Sample(sample::SampleArgs),
    /// Simplify a mesh to a vertex count and write PLY, OBJ, GLB or MD2, with a report.
    Simplify(simplify::SimplifyArgs),
    /// The quality study: invitations, answers, and the level cap they set.
    Study(study::StudyArgs),
    /// Levels of detail by Melax's collapses: one GLB with MSFT_lod (and an
    /// MD2's frames as morph targets), or one GLB or MD2 per level.
    Lod(lod::LodArgs),
    /// A model's title, description and credit in other languages: set,
    /// remove or list the translations of a version.
    Texts(texts::TextsArgs),
}

impl Command {
    pub fn run(self) -> anyhow::Result<()> {
        match self {
            Command::Ingest(args) => block_on(ingest::run(args)),
            Command::Serve(args) => block_on(serve::run(args)),
            Command::Token(args) => block_on(token::run(args)),
            Command::Models(args) => block_on(models::run(args)),
            Command::Encode(args) => encode::run(args),
            Command::Decode(args) => decode::run(args),
            Command::Inspect(args) => inspect::run(args),
            Command::Sample(args) => sample::run(args),
            Command::Simplify(args) => simplify::run(args),
            Command::Study(args) => block_on(study::run(args)),
            Command::Lod(args) => lod::run(args),
            Command::Texts(args) => block_on(texts::run(args)),
        }
    }
}

#[cfg(feature = "dev-tools")]
#[derive(Subcommand)]
pub enum DevCommand {
    /// Benchmark the codec on a folder of meshes and print a markdown table.
    Bench(bench::BenchArgs),
    /// Compare the colour modes (ccc, vertex, vertex-metric) on coloured meshes: sizes and quality per level.
    ColourBench(colour_bench::ColourBenchArgs),
    /// Write the native decoder's buffers at every level (for cross-checks).
    DumpLevels(dump_levels::DumpArgs),
    /// Where a stream's bits go, layer by layer (connectivity, tangential
    /// and normal geometry), and what trial predictors would spend.
    Bits(bit_budget::BitsArgs),
    /// One mesh of `bench`, in its own process so peak memory is its own.
    #[command(hide = true)]
    BenchOne(bench::BenchOneArgs),
}

#[cfg(feature = "dev-tools")]
impl DevCommand {
    pub fn run(self) -> anyhow::Result<()> {
        match self {
            DevCommand::Bench(args) => bench::run(args),
            DevCommand::ColourBench(args) => colour_bench::run(args),
            DevCommand::Bits(args) => bit_budget::run(args),
            DevCommand::DumpLevels(args) => dump_levels::run(args),
            DevCommand::BenchOne(args) => bench::run_one(args),
        }
    }
}

/// Runs an async command on a multi-threaded runtime of its own.
fn block_on(command: impl Future<Output = anyhow::Result<()>>) -> anyhow::Result<()> {
    tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()?
        .block_on(command)
}

/// Logs to stderr, filtered by `RUST_LOG` (default `info`). Safe to call twice.
pub fn init_tracing() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .try_init();
}
