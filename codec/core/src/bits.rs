//! Where a stream's bits go: [`bit_budget`] decodes a stream with the
//! [`Meter`] running (`meter.rs`: the shadow models, the trial predictors).

use crate::decoder::Decoder;
use crate::meter::{Meter, PassBits};
use crate::{Error, Limits, Result, StreamIndex};

/// Measures a plain (version 4) stream pass by pass.
pub fn bit_budget(stream: &[u8]) -> Result<Vec<PassBits>> {
    let index = StreamIndex::parse(stream)?;
    if index.header.version != crate::VERSION {
        return Err(Error::Unsupported(
            "bit budget of a charted stream: encode it without charts".into(),
        ));
    }
    let mut decoder = Decoder::new(&stream[index.base.clone()], Limits::default())?;
    decoder.meter(Some(Box::<Meter>::default()));
    for (k, range) in index.batches.iter().enumerate() {
        decoder.meter_batch(k as u32 + 1);
        decoder.apply_batch(&stream[range.clone()])?;
    }
    let mut meter = decoder.meter(None).unwrap_or_default();
    let (conn, positions) = decoder.connectivity_and_positions();
    meter.price_deferral(conn, positions);
    Ok(meter.passes)
}
