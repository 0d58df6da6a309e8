//! `vitrine-dev dump-levels`: the native decoder's buffers at every level, as raw
//! little-endian files, so other decoders (WebAssembly) can be compared byte
//! for byte: `level-K.positions` (f32), `level-K.colours` (u8), `level-K.indices` (u32).

use anyhow::Context;
use clap::Args;
use std::path::PathBuf;
use vitrine_codec::{Decoder, Limits, StreamIndex};

#[derive(Args, Debug)]
pub struct DumpArgs {
    pub stream: PathBuf,
    pub out_dir: PathBuf,
}

pub fn run(args: DumpArgs) -> anyhow::Result<()> {
    let bytes = std::fs::read(&args.stream)
        .with_context(|| format!("reading {}", args.stream.display()))?;
    let index = StreamIndex::parse(&bytes)?;
    std::fs::create_dir_all(&args.out_dir)?;
    let mut decoder = Decoder::new(&bytes[index.base.clone()], Limits::default())?;
    let write = |d: &Decoder| -> anyhow::Result<()> {
        let k = d.level();
        let path = |what: &str| args.out_dir.join(format!("level-{k}.{what}"));
        std::fs::write(
            path("positions"),
            d.positions()
                .iter()
                .flat_map(|v| v.to_le_bytes())
                .collect::<Vec<u8>>(),
        )?;
        std::fs::write(
            path("indices"),
            d.indices()
                .iter()
                .flat_map(|v| v.to_le_bytes())
                .collect::<Vec<u8>>(),
        )?;
        if let Some(c) = d.colours() {
            std::fs::write(path("colours"), c)?;
        }
        Ok(())
    };
    write(&decoder)?;
    for range in &index.batches {
        decoder.apply_batch(&bytes[range.clone()])?;
        write(&decoder)?;
    }
    Ok(())
}
