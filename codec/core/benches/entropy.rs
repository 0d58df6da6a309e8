//! Entropy coder throughput: decode (and some encode) speed in symbols/s.
//!
//! `cargo bench -p vitrine-codec --bench entropy`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;

// The entropy module may be private to the codec crate, so compile its
// source straight into this bench. It needs only `crate::{Error, Result}`.
// (`cargo clippy --all-targets` checks benches with `cfg(test)` but without
// the test harness, leaving the module's test imports unused.)
#[allow(unused_imports)]
#[path = "../src/entropy/mod.rs"]
mod entropy;

use entropy::{BitModel, IntModel, RangeDecoder, RangeEncoder, SymbolModel};

/// Stand-in for the codec's error type, as the module's decoder uses it.
#[derive(Debug)]
pub struct Error;

impl Error {
    fn stream(_detail: impl std::fmt::Display) -> Self {
        Error
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

const N: usize = 1 << 20;

/// SplitMix64.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

fn bits(p1_permille: &[u64]) -> (Vec<(u8, bool)>, Vec<u8>) {
    let mut rng = Rng(1);
    let data: Vec<(u8, bool)> = (0..N)
        .map(|_| {
            let ctx = (rng.next() % p1_permille.len() as u64) as usize;
            (ctx as u8, rng.next() % 1000 < p1_permille[ctx])
        })
        .collect();
    let mut models = vec![BitModel::default(); p1_permille.len()];
    let mut enc = RangeEncoder::with_capacity(N / 4);
    for &(c, b) in &data {
        enc.encode_bit(&mut models[usize::from(c)], b);
    }
    (data, enc.finish())
}

/// Geometric-ish symbols: P(s) ~ 2^-(s+1), capped at the alphabet.
fn symbols(n: usize) -> Vec<usize> {
    let mut rng = Rng(2);
    (0..N)
        .map(|_| (rng.next().trailing_zeros() as usize).min(n - 1))
        .collect()
}

fn ints() -> Vec<i32> {
    let mut rng = Rng(3);
    (0..N)
        .map(|_| {
            let len = rng.next().trailing_zeros().min(20);
            let mag = (rng.next() as i32) & ((1 << len) - 1);
            if rng.next() & 1 == 0 {
                mag
            } else {
                -mag
            }
        })
        .collect()
}

fn bench_decode(c: &mut Criterion) {
    let mut g = c.benchmark_group("decode");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(20);

    for (name, probs) in [
        ("bit/p=0.05", &[50u64][..]),
        ("bit/p=0.5", &[500][..]),
        (
            "bit/16ctx",
            &[
                5, 20, 50, 100, 300, 500, 700, 900, 950, 990, 10, 30, 60, 150, 400, 800,
            ][..],
        ),
    ] {
        let (data, bytes) = bits(probs);
        let n_ctx = probs.len();
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut dec = RangeDecoder::new(black_box(&bytes));
                let mut models = [BitModel::default(); 16];
                let mut ones = 0u32;
                for &(ctx, _) in &data {
                    ones += u32::from(dec.decode_bit(&mut models[usize::from(ctx) % n_ctx]));
                }
                ones
            })
        });
    }

    for n in [2usize, 8, 33, 64] {
        let syms = symbols(n);
        let mut enc = RangeEncoder::new();
        let mut m = SymbolModel::new(n);
        for &s in &syms {
            enc.encode_symbol(&mut m, s);
        }
        let bytes = enc.finish();
        g.bench_with_input(BenchmarkId::new("symbol", n), &bytes, |b, bytes| {
            b.iter(|| {
                let mut dec = RangeDecoder::new(black_box(bytes));
                let mut m = SymbolModel::new(n);
                let mut acc = 0usize;
                for _ in 0..N {
                    acc += dec.decode_symbol(&mut m);
                }
                acc
            })
        });
    }

    let vals = ints();
    let mut enc = RangeEncoder::new();
    let mut m = IntModel::new();
    for &v in &vals {
        enc.encode_int(&mut m, v);
    }
    let bytes = enc.finish();
    g.bench_function("int/laplacian", |b| {
        b.iter(|| {
            let mut dec = RangeDecoder::new(black_box(&bytes));
            let mut m = IntModel::new();
            let mut acc = 0i32;
            for _ in 0..N {
                acc = acc.wrapping_add(dec.decode_int(&mut m));
            }
            acc
        })
    });

    let mut enc = RangeEncoder::new();
    for i in 0..N as u32 {
        enc.encode_raw(i.wrapping_mul(2_654_435_761) >> 24, 8);
    }
    let bytes = enc.finish();
    g.bench_function("raw/8bit", |b| {
        b.iter(|| {
            let mut dec = RangeDecoder::new(black_box(&bytes));
            let mut acc = 0u32;
            for _ in 0..N {
                acc = acc.wrapping_add(dec.decode_raw(8));
            }
            acc
        })
    });
    g.finish();
}

fn bench_encode(c: &mut Criterion) {
    let mut g = c.benchmark_group("encode");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(20);

    let (data, _) = bits(&[50]);
    g.bench_function("bit/p=0.05", |b| {
        b.iter(|| {
            let mut enc = RangeEncoder::with_capacity(N / 8);
            let mut m = BitModel::default();
            for &(_, bit) in &data {
                enc.encode_bit(&mut m, bit);
            }
            enc.finish()
        })
    });

    let syms = symbols(8);
    g.bench_function("symbol/8", |b| {
        b.iter(|| {
            let mut enc = RangeEncoder::with_capacity(N / 2);
            let mut m = SymbolModel::new(8);
            for &s in &syms {
                enc.encode_symbol(&mut m, s);
            }
            enc.finish()
        })
    });

    let vals = ints();
    g.bench_function("int/laplacian", |b| {
        b.iter(|| {
            let mut enc = RangeEncoder::with_capacity(N);
            let mut m = IntModel::new();
            for &v in &vals {
                enc.encode_int(&mut m, v);
            }
            enc.finish()
        })
    });
    g.finish();
}

criterion_group!(benches, bench_decode, bench_encode);
criterion_main!(benches);
