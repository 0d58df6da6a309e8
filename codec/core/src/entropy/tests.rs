//! Cross-cutting tests: mixed round trips, carries, determinism, the golden
//! stream, truncated and garbage input.

use super::*;
use proptest::prelude::*;

/// SplitMix64: a tiny deterministic PRNG.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h = 0xCBF2_9CE4_8422_2325_u64;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01B3);
    }
    h
}

/// One coded value; decoding fills in the value part.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Op {
    Bit { ctx: usize, bit: bool },
    Raw { value: u32, nbits: u32 },
    Sym { model: usize, sym: usize },
    Int { model: usize, v: i32 },
    Uint { model: usize, v: u32 },
}

const BIT_P1_PERMILLE: [u64; 8] = [1, 10, 50, 200, 500, 800, 950, 999];
const SYM_SIZES: [usize; 5] = [2, 3, 8, 33, 64];
const INT_MODELS: usize = 3;

struct Models {
    bits: Vec<BitModel>,
    syms: Vec<SymbolModel>,
    ints: Vec<IntModel>,
}

impl Models {
    fn new() -> Self {
        Models {
            bits: vec![BitModel::default(); BIT_P1_PERMILLE.len()],
            syms: SYM_SIZES.iter().map(|&n| SymbolModel::new(n)).collect(),
            ints: (0..INT_MODELS).map(|_| IntModel::new()).collect(),
        }
    }
}

fn laplacian_ish(rng: &mut Rng) -> i32 {
    if rng.below(100) == 0 {
        let extremes = [
            i32::MIN,
            i32::MIN + 1,
            i32::MAX,
            i32::MAX - 1,
            1 << 30,
            -(1 << 30),
        ];
        return extremes[rng.below(extremes.len() as u64) as usize];
    }
    // Geometric bit length, uniform bits below: roughly two-sided exponential.
    let len = (rng.next().trailing_zeros() * 2).min(31);
    let mag = (rng.next() as u32) & ((1u32 << len) - 1);
    if rng.next() & 1 == 0 {
        mag as i32
    } else {
        -(mag as i32)
    }
}

fn random_ops(rng: &mut Rng, n: usize) -> Vec<Op> {
    (0..n)
        .map(|_| match rng.below(10) {
            0..=3 => {
                let ctx = rng.below(BIT_P1_PERMILLE.len() as u64) as usize;
                Op::Bit {
                    ctx,
                    bit: rng.below(1000) < BIT_P1_PERMILLE[ctx],
                }
            }
            4 => {
                let nbits = rng.below(33) as u32;
                let value = (rng.next() as u32) & (((1u64 << nbits) - 1) as u32);
                Op::Raw { value, nbits }
            }
            5..=6 => {
                let model = rng.below(SYM_SIZES.len() as u64) as usize;
                let n = SYM_SIZES[model];
                // Skewed: geometric over the alphabet, with a uniform tail.
                let sym = if rng.below(8) == 0 {
                    rng.below(n as u64) as usize
                } else {
                    (rng.next().trailing_zeros() as usize).min(n - 1)
                };
                Op::Sym { model, sym }
            }
            7..=8 => Op::Int {
                model: rng.below(INT_MODELS as u64) as usize,
                v: laplacian_ish(rng),
            },
            _ => Op::Uint {
                model: rng.below(INT_MODELS as u64) as usize,
                v: laplacian_ish(rng).unsigned_abs() >> rng.below(4),
            },
        })
        .collect()
}

fn encode_ops(ops: &[Op]) -> Vec<u8> {
    let mut m = Models::new();
    let mut enc = RangeEncoder::new();
    for &op in ops {
        match op {
            Op::Bit { ctx, bit } => enc.encode_bit(&mut m.bits[ctx], bit),
            Op::Raw { value, nbits } => enc.encode_raw(value, nbits),
            Op::Sym { model, sym } => enc.encode_symbol(&mut m.syms[model], sym),
            Op::Int { model, v } => enc.encode_int(&mut m.ints[model], v),
            Op::Uint { model, v } => enc.encode_uint(&mut m.ints[model], v),
        }
    }
    enc.finish()
}

/// Decode the same kinds of values, with the same models, as `ops` lists.
fn decode_ops(dec: &mut RangeDecoder, ops: &[Op]) -> Vec<Op> {
    let mut m = Models::new();
    ops.iter()
        .map(|&op| match op {
            Op::Bit { ctx, .. } => Op::Bit {
                ctx,
                bit: dec.decode_bit(&mut m.bits[ctx]),
            },
            Op::Raw { nbits, .. } => Op::Raw {
                value: dec.decode_raw(nbits),
                nbits,
            },
            Op::Sym { model, .. } => {
                let sym = dec.decode_symbol(&mut m.syms[model]);
                assert!(sym < SYM_SIZES[model]);
                Op::Sym { model, sym }
            }
            Op::Int { model, .. } => Op::Int {
                model,
                v: dec.decode_int(&mut m.ints[model]),
            },
            Op::Uint { model, .. } => Op::Uint {
                model,
                v: dec.decode_uint(&mut m.ints[model]),
            },
        })
        .collect()
}

fn round_trip(ops: &[Op]) -> Vec<u8> {
    let bytes = encode_ops(ops);
    let mut dec = RangeDecoder::new(&bytes);
    let got = decode_ops(&mut dec, ops);
    if let Some(i) = (0..ops.len()).find(|&i| got[i] != ops[i]) {
        panic!("op {i}: coded {:?}, decoded {:?}", ops[i], got[i]);
    }
    dec.check_overrun().expect("no overrun on a whole stream");
    bytes
}

#[test]
fn entropy_mixed_round_trip_long_random() {
    for seed in 0..4 {
        let mut rng = Rng(seed);
        let ops = random_ops(&mut rng, 200_000);
        round_trip(&ops);
    }
}

#[test]
fn entropy_mixed_round_trip_many_short_streams() {
    let mut rng = Rng(1234);
    for len in 0..300 {
        let ops = random_ops(&mut rng, len);
        round_trip(&ops);
    }
}

#[test]
fn entropy_encoding_is_deterministic() {
    let mut rng = Rng(42);
    let ops = random_ops(&mut rng, 50_000);
    assert_eq!(encode_ops(&ops), encode_ops(&ops));
    // A cloned encoder finishes to the same bytes as the original.
    let mut enc = RangeEncoder::new();
    let mut m = BitModel::default();
    for i in 0..10_000u32 {
        enc.encode_bit(&mut m, i % 7 == 0);
    }
    let copy = enc.clone();
    assert_eq!(copy.finish(), enc.finish());
}

/// One step of a stream that keeps the interval straddling a byte boundary,
/// so the run of pending 0xFF bytes grows: alternately a model bit and 8 raw
/// bits, each chosen so that its sub-interval still contains the boundary.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Step {
    Bit(bool),
    Raw8(u32),
}

fn straddle(enc: &mut RangeEncoder, m: &mut BitModel, steps: usize, out: &mut Vec<Step>) {
    for i in 0..steps {
        // The boundary to straddle: 2^32 once a chain is pending (after a
        // shift it always sits there), else the next 2^24 multiple above low.
        let point = if enc.low + u64::from(enc.range) > 1 << 32 {
            1 << 32
        } else {
            ((enc.low >> 24) + 1) << 24
        };
        if i % 2 == 0 {
            let bound = u64::from((enc.range >> 12) * (4096 - m.p1_4096()));
            // Bit 1 takes [low + bound, low + range); bit 0 [low, low + bound).
            let bit = enc.low + bound < point;
            enc.encode_bit(m, bit);
            out.push(Step::Bit(bit));
        } else {
            let r = u64::from(enc.range >> 8);
            let v = ((point - enc.low) / r).min(255) as u32;
            enc.encode_raw(v, 8);
            out.push(Step::Raw8(v));
        }
    }
}

#[test]
fn entropy_long_carry_chains_round_trip() {
    for (chain_steps, go_up) in [(2_000, true), (2_000, false), (20_000, true), (300, true)] {
        let mut enc = RangeEncoder::new();
        let mut m = BitModel::default();
        let mut steps = Vec::new();
        // Some ordinary data first, so the chain starts mid-stream.
        for i in 0..500 {
            let b = i % 3 == 0;
            enc.encode_bit(&mut m, b);
            steps.push(Step::Bit(b));
        }
        straddle(&mut enc, &mut m, chain_steps, &mut steps);
        // Leave the straddle: upward resolves the chain with a carry,
        // downward writes it out as 0xFF bytes.
        let exit = if go_up { 0xFFFF } else { 0 };
        for _ in 0..4 {
            enc.encode_raw(exit, 16);
        }
        let before = enc.stats.clone();
        for i in 0..500 {
            let b = i % 5 == 0;
            enc.encode_bit(&mut m, b);
            steps.push(Step::Bit(b));
        }
        let stats = enc.stats.clone();
        // Each raw step adds about one pending byte.
        let want = (chain_steps / 2 - 8) as u64;
        assert!(stats.longest_pending >= want, "{stats:?}");
        if go_up {
            assert!(before.longest_carry_chain >= want, "{before:?}");
        }
        let bytes = enc.finish();
        if !go_up {
            let ff_run = bytes
                .windows(want as usize)
                .any(|w| w.iter().all(|&b| b == 0xFF));
            assert!(ff_run, "expected a long 0xFF run");
        }

        let mut dec = RangeDecoder::new(&bytes);
        let mut m = BitModel::default();
        let (head, tail) = steps.split_at(500 + chain_steps);
        for (k, &step) in head.iter().enumerate() {
            let got = match step {
                Step::Bit(_) => Step::Bit(dec.decode_bit(&mut m)),
                Step::Raw8(_) => Step::Raw8(dec.decode_raw(8)),
            };
            assert_eq!(got, step, "step {k}");
        }
        for _ in 0..4 {
            assert_eq!(dec.decode_raw(16), exit);
        }
        for &step in tail {
            assert_eq!(Step::Bit(dec.decode_bit(&mut m)), step);
        }
        dec.check_overrun().unwrap();
    }
}

#[test]
fn entropy_probable_then_improbable_carries() {
    // Long runs of a near-certain bit followed by surprises, repeated: the
    // natural way carry chains arise.
    let mut rng = Rng(5);
    let mut enc = RangeEncoder::new();
    let mut m = BitModel::default();
    let mut bits = Vec::new();
    for _ in 0..2_000 {
        let run = rng.below(3_000) as usize;
        bits.extend(std::iter::repeat_n(true, run));
        bits.extend((0..rng.below(4)).map(|_| false));
    }
    for &b in &bits {
        enc.encode_bit(&mut m, b);
    }
    assert!(enc.stats.carries > 0, "{:?}", enc.stats);
    let bytes = enc.finish();
    let mut dec = RangeDecoder::new(&bytes);
    let mut m = BitModel::default();
    assert!(bits.iter().all(|&b| dec.decode_bit(&mut m) == b));
    dec.check_overrun().unwrap();
}

/// Catches any accidental change of the stream format.
#[test]
fn entropy_golden_stream() {
    let mut rng = Rng(0x5EED);
    let ops = random_ops(&mut rng, 5_000);
    let bytes = round_trip(&ops);
    let hash = fnv1a64(&bytes);
    assert_eq!(
        (bytes.len(), hash),
        (GOLDEN_LEN, GOLDEN_FNV1A),
        "stream format changed: len {}, fnv1a64 {hash:#018x}",
        bytes.len()
    );
}

const GOLDEN_LEN: usize = 2142;
const GOLDEN_FNV1A: u64 = 0x83fc_652b_8eba_b9b6;

#[test]
fn entropy_truncated_streams_never_panic_and_report_overrun() {
    let mut rng = Rng(77);
    let ops = random_ops(&mut rng, 3_000);
    let bytes = encode_ops(&ops);
    assert!(bytes.len() > 100);
    for cut in 1..=bytes.len() {
        let short = &bytes[..bytes.len() - cut];
        let mut dec = RangeDecoder::new(short);
        let got = decode_ops(&mut dec, &ops);
        let overrun = dec.check_overrun();
        if cut > 4 {
            assert!(overrun.is_err(), "cut {cut}: overrun not reported");
        } else {
            assert!(overrun.is_ok() || got != ops, "cut {cut}");
        }
    }
}

#[test]
fn entropy_garbage_input_never_panics() {
    let mut rng = Rng(2024);
    let ops = random_ops(&mut rng, 20_000);
    let mut inputs: Vec<Vec<u8>> = vec![
        vec![0],
        vec![0; 64],
        [0].into_iter()
            .chain(std::iter::repeat_n(0xFF, 4000))
            .collect(),
        [0].into_iter()
            .chain(std::iter::repeat_n(0x80, 100))
            .collect(),
    ];
    for len in [1usize, 5, 17, 1000, 50_000] {
        let mut v: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
        v[0] = 0;
        inputs.push(v);
    }
    for input in &inputs {
        let mut dec = RangeDecoder::new(input);
        let _ = decode_ops(&mut dec, &ops);
        // Only symbols and ints, which have the most arithmetic.
        let mut s = SymbolModel::new(64);
        let mut s2 = SymbolModel::new(2);
        let mut im = IntModel::new();
        for _ in 0..20_000 {
            assert!(dec.decode_symbol(&mut s) < 64);
            assert!(dec.decode_symbol(&mut s2) < 2);
            let _ = dec.decode_int(&mut im);
            let _ = dec.decode_uint(&mut im);
        }
        let _ = dec.check_overrun();
    }
}

#[test]
fn entropy_garbage_code_above_range_stays_in_alphabet() {
    // A stream whose first 4 bytes make code = 0xFFFF_FFFF = range: never
    // produced by the encoder; decoding must cope anyway.
    let input = [0, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF];
    let mut dec = RangeDecoder::new(&input);
    let mut s = SymbolModel::new(5);
    let mut im = IntModel::new();
    let mut b = BitModel::new();
    for _ in 0..1000 {
        assert!(dec.decode_symbol(&mut s) < 5);
        let _ = dec.decode_int(&mut im);
        let _ = dec.decode_bit(&mut b);
        let _ = dec.decode_raw(32);
    }
    assert!(dec.check_overrun().is_err());
}

fn op_strategy() -> impl Strategy<Value = Op> {
    prop_oneof![
        (0..BIT_P1_PERMILLE.len(), any::<bool>()).prop_map(|(ctx, bit)| Op::Bit { ctx, bit }),
        (any::<u32>(), 0u32..=32).prop_map(|(v, nbits)| Op::Raw {
            value: v & (((1u64 << nbits) - 1) as u32),
            nbits
        }),
        (0..SYM_SIZES.len(), any::<usize>()).prop_map(|(model, s)| Op::Sym {
            model,
            sym: s % SYM_SIZES[model]
        }),
        (0..INT_MODELS, any::<i32>()).prop_map(|(model, v)| Op::Int { model, v }),
        (0..INT_MODELS, -40i32..40).prop_map(|(model, v)| Op::Int { model, v }),
        (0..INT_MODELS, any::<u32>()).prop_map(|(model, v)| Op::Uint { model, v }),
    ]
}

proptest! {
    #[test]
    fn entropy_prop_round_trip(ops in proptest::collection::vec(op_strategy(), 0..400)) {
        round_trip(&ops);
    }

    #[test]
    fn entropy_prop_arbitrary_bytes_never_panic(
        mut bytes in proptest::collection::vec(any::<u8>(), 1..64),
        ops in proptest::collection::vec(op_strategy(), 0..200),
    ) {
        bytes[0] = 0;
        let mut dec = RangeDecoder::new(&bytes);
        let _ = decode_ops(&mut dec, &ops);
        let _ = dec.check_overrun();
    }
}
