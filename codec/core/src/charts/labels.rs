//! Chart labels of the level where charts begin, one per face in canonical
//! order, range-coded with the previous face's label as context (faces
//! sorted by their smallest vertex come in small neighbourhoods, so a label
//! mostly repeats).

use crate::entropy::{RangeDecoder, RangeEncoder, SymbolModel};
use crate::{Error, Result};

fn models(charts: usize) -> Vec<SymbolModel> {
    (0..charts).map(|_| SymbolModel::new(charts)).collect()
}

/// `labels` are each below `charts` (2..=64).
pub(crate) fn encode_labels(labels: &[u32], charts: usize) -> Vec<u8> {
    let mut models = models(charts);
    let mut coder = RangeEncoder::with_capacity(labels.len() / 8 + 16);
    let mut previous = 0;
    for &label in labels {
        coder.encode_symbol(&mut models[previous], label as usize);
        previous = label as usize;
    }
    coder.finish()
}

/// The labels of `faces` faces (a count the caller holds in memory already).
pub(crate) fn decode_labels(bytes: &[u8], faces: usize, charts: usize) -> Result<Vec<u32>> {
    if !(2..=super::MAX_CHARTS).contains(&charts) {
        return Err(Error::stream(format!("{charts} charts is out of range")));
    }
    let mut models = models(charts);
    let mut coder = RangeDecoder::new(bytes);
    let mut labels = Vec::with_capacity(faces);
    let mut previous = 0;
    for _ in 0..faces {
        previous = coder.decode_symbol(&mut models[previous]);
        labels.push(previous as u32);
    }
    coder.check_overrun()?;
    Ok(labels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_round_trip_and_runs_cost_little() {
        let labels: Vec<u32> = (0..10_000u32).map(|i| (i / 1000) % 7).collect();
        let bytes = encode_labels(&labels, 7);
        assert!(bytes.len() < 200, "{} bytes for 10 runs", bytes.len());
        assert_eq!(decode_labels(&bytes, labels.len(), 7).unwrap(), labels);
        // Truncated: an overrun, never a panic.
        assert!(decode_labels(&bytes[..bytes.len() / 2], labels.len(), 7).is_err());
        assert!(decode_labels(&bytes, 10, 65).is_err());
    }
}
