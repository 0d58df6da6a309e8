//! Adaptive, context-modelled range coding.
//!
//! # Why hand-written
//!
//! The mesh coder needs *adaptive* (context-modelled) arithmetic coding: the
//! probability of every valence, split bit or residual bucket is learned as the
//! stream is coded, and a different model is chosen per context. The output
//! must be bit-identical on native x86_64 and on wasm32 (the viewer decodes in
//! the browser what the server encoded natively), every symbol must be coded
//! without allocating, and decoding has to run at hundreds of millions of
//! binary decisions per second.
//!
//! General-purpose entropy-coding crates such as `constriction` are built
//! around *static* models (a fixed distribution per symbol, often described
//! with floats); using them adaptively means rebuilding a model per symbol,
//! which allocates, costs far more than the coding step itself, and brings
//! float rounding into the format. So this module is a small, self-contained
//! coder using integer arithmetic only, whose bytes depend on nothing but the
//! coded data:
//!
//! * [`RangeEncoder`] / [`RangeDecoder`]: a 32-bit range coder in the style of
//!   LZMA's (64-bit `low` with `cache`/`cache_size` carry propagation,
//!   normalisation when `range < 2^24`, a 5-byte flush; the decoder keeps a
//!   32-bit `code` and starts by reading 5 bytes).
//! * [`BitModel`]: an adaptive binary model (12-bit probability, shift-5
//!   update), coded with [`RangeEncoder::encode_bit`].
//! * raw, equiprobable bits: [`RangeEncoder::encode_raw`] (up to 32 at once).
//! * [`SymbolModel`]: an adaptive frequency model over 2..=64 symbols, one
//!   range-coder step per symbol ([`RangeEncoder::encode_symbol`]).
//! * [`IntModel`]: adaptive Elias-gamma style coding of any `i32` / `u32`
//!   ([`RangeEncoder::encode_int`], [`RangeEncoder::encode_uint`]).
//!
//! # Format notes
//!
//! * LZMA's leading cache byte, always `0`, is not written: the decoder
//!   implies it, and a stream with nothing coded is empty.
//! * [`RangeEncoder::finish`] flushes the shortest-tailed value inside the
//!   final interval and drops up to 4 trailing zero bytes. The decoder reads
//!   bytes past the end as zeros, so this is lossless; reading *more* than
//!   4 bytes past the end means the payload was truncated, which
//!   [`RangeDecoder::check_overrun`] reports.
//! * Decoding hostile input never panics, never loops forever, and never
//!   returns a symbol index outside the model: it only yields wrong values
//!   (and, for truncated input, an overrun).
//!
//! Encoder and decoder must code the same kinds of values with the same
//! models in the same order; the stream itself carries no framing.

// A toolkit: not every build uses every primitive (and the crate may keep
// this module private), so unused items are not an error here.
#![allow(dead_code)]

mod bit;
mod coder;
mod int;
mod symbol;

#[cfg(test)]
mod tests;

#[allow(unused_imports)]
pub use bit::BitModel;
#[allow(unused_imports)]
pub use coder::{RangeDecoder, RangeEncoder};
#[allow(unused_imports)]
pub use int::IntModel;
#[allow(unused_imports)]
pub use symbol::{FrequencyModel, SymbolModel, MAX_SYMBOLS};
