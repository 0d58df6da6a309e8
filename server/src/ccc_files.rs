//! The cell complex beside a stream file: `vitrine encode --colour ccc`
//! writes it, `vitrine inspect --original` reads it back for colour.

use anyhow::Context;
use std::path::{Path, PathBuf};
use vitrine_colour::ccc::{CccParameters, CellComplex, TextureMapping};

/// Where the complex of `STREAM` lies: `STREAM.ccc.json`, `.cell.png`,
/// `.colour.jpg` and `.colour-low.jpg`.
pub struct CccFiles {
    pub parameters: PathBuf,
    pub cell: PathBuf,
    pub colour: PathBuf,
    pub colour_low: PathBuf,
}

impl CccFiles {
    pub fn beside(stream: &Path) -> CccFiles {
        let with = |suffix: &str| {
            let mut name = stream.as_os_str().to_owned();
            name.push(suffix);
            PathBuf::from(name)
        };
        CccFiles {
            parameters: with(".ccc.json"),
            cell: with(".cell.png"),
            colour: with(".colour.jpg"),
            colour_low: with(".colour-low.jpg"),
        }
    }

    pub fn write(&self, mapping: &TextureMapping) -> anyhow::Result<()> {
        let write = |path: &Path, bytes: &[u8]| {
            std::fs::write(path, bytes).with_context(|| format!("writing {}", path.display()))
        };
        write(
            &self.parameters,
            &serde_json::to_vec_pretty(&mapping.parameters)?,
        )?;
        write(&self.cell, &mapping.cell_png)?;
        write(&self.colour, &mapping.colour_jpeg)?;
        write(&self.colour_low, &mapping.colour_low_jpeg)
    }

    /// The complex with its full-resolution atlas, or `None` when no
    /// parameters file lies beside the stream.
    pub fn read_complex(&self) -> anyhow::Result<Option<CellComplex>> {
        if !self.parameters.exists() {
            return Ok(None);
        }
        let read = |p: &Path| std::fs::read(p).with_context(|| format!("reading {}", p.display()));
        let parameters: CccParameters = serde_json::from_slice(&read(&self.parameters)?)?;
        let complex =
            CellComplex::from_images(&parameters, &read(&self.cell)?, &read(&self.colour)?)?;
        Ok(Some(complex))
    }
}
