//! Hostile input: streams and mesh files built to break the codec.
//!
//! Every case must come back as an `Err` naming the problem (or, for bit
//! flips that happen to decode, an `Ok` whose buffers are still consistent),
//! quickly, without a panic, and without allocating what a header claims.
//!
//! Peak allocation is measured with `allocation-counter`, which installs a
//! counting `#[global_allocator]` (a wrapper around `System`) in this test
//! binary and counts per thread, so the other tests running in parallel do
//! not disturb a measurement. It is a dev-dependency rather than a
//! `GlobalAlloc` impl here because that impl needs `unsafe impl`, and the
//! workspace's `unsafe_code = "forbid"` applies to test targets too (a
//! command-line `forbid` cannot be lifted with `#![allow]`).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use vitrine_codec::{
    decode, encode, Decoder, EncodeOptions, Error, Header, Limits, StreamIndex, CHARTED_VERSION,
    MAGIC, NESTED_VERSION, VERSION,
};
use vitrine_samples::icosphere;

// ---------------------------------------------------------------- helpers

/// `encode(samples::icosphere(3))` with default options: 642 vertices, a
/// base mesh and a few batches.
fn sphere_stream() -> &'static [u8] {
    static S: OnceLock<Vec<u8>> = OnceLock::new();
    S.get_or_init(|| {
        encode(&icosphere(3), &EncodeOptions::default())
            .expect("encode")
            .bytes
    })
}

/// Peak bytes a hostile input may make the decoder hold at once.
const SMALL_PEAK: u64 = 4 << 20;

/// Limits that trust the stream completely: only the input's own bytes bound the work.
const NO_LIMITS: Limits = Limits {
    max_vertices: u32::MAX,
    max_faces: u32::MAX,
    max_batches: u32::MAX,
};

// Header layout (FORMAT.md): magic 0..4, version 4, flags 5, bits 6, reserved 7,
// min 8..20, step 20..24, batch count 24..28, then 12 bytes per level.
const AT_VERSION: usize = 4;
const AT_FLAGS: usize = 5;
const AT_BITS: usize = 6;
const AT_MIN: usize = 8;
const AT_STEP: usize = 20;
const AT_BATCHES: usize = 24;
const AT_LEVELS: usize = 28;
const HEADER_FIXED: usize = 40;
// Chunk header: tag, version, then varints: level (field 0), vertices before,
// vertices after, faces after, payload length.
const BEFORE: usize = 1;
const AFTER: usize = 2;
const FACES: usize = 3;
const PAYLOAD_LEN: usize = 4;

/// The five varint fields of the chunk starting at `bytes[0]`, and the
/// header's length.
fn chunk_fields(bytes: &[u8]) -> ([u32; 5], usize) {
    let mut at = 2;
    let fields = std::array::from_fn(|_| {
        let (mut v, mut shift) = (0u32, 0);
        loop {
            let b = bytes[at];
            at += 1;
            v |= ((b & 0x7f) as u32) << shift;
            shift += 7;
            if b & 0x80 == 0 {
                return v;
            }
        }
    });
    (fields, at)
}

/// Rewrites one field of the chunk header at `bytes[chunk_at..]`; the new
/// value must take as many varint bytes as the old, so nothing moves.
fn set_chunk_field(bytes: &mut [u8], chunk_at: usize, field: usize, v: u32) {
    let (mut fields, len) = chunk_fields(&bytes[chunk_at..]);
    fields[field] = v;
    let mut header = vec![bytes[chunk_at], bytes[chunk_at + 1]];
    for f in fields {
        varint(&mut header, f);
    }
    assert_eq!(
        header.len(),
        len,
        "field {field} = {v} changes the header's length"
    );
    bytes[chunk_at..chunk_at + len].copy_from_slice(&header);
}

fn put_u32(bytes: &mut [u8], at: usize, v: u32) {
    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

fn put_f32(bytes: &mut [u8], at: usize, v: f32) {
    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

fn get_u32(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
}

fn level_at(level: usize) -> usize {
    AT_LEVELS + 12 * level
}

fn varint(out: &mut Vec<u8>, mut v: u32) {
    while v >= 0x80 {
        out.push((v as u8 & 0x7f) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

fn chunk(tag: u8, level: u16, before: u32, after: u32, faces: u32, payload: &[u8]) -> Vec<u8> {
    chunk_claiming(
        tag,
        [level as u32, before, after, faces, payload.len() as u32],
        payload,
    )
}

/// A chunk whose header says `fields` whatever `payload` holds.
fn chunk_claiming(tag: u8, fields: [u32; 5], payload: &[u8]) -> Vec<u8> {
    let mut out = vec![tag, VERSION];
    for v in fields {
        varint(&mut out, v);
    }
    out.extend_from_slice(payload);
    out
}

/// One pass as the decoder reads it; each section holds one byte.
fn pass(seeds: &[[u32; 2]], inserted: u32) -> Vec<u8> {
    let mut out = Vec::new();
    varint(&mut out, seeds.len() as u32);
    for s in seeds {
        varint(&mut out, s[0]);
        varint(&mut out, s[1]);
    }
    varint(&mut out, inserted);
    for _ in 0..3 {
        out.extend_from_slice(&[1, 0]);
    }
    out
}

/// The sphere stream's header and base chunk, followed by `batch` as the
/// only batch, with level 1 of the table set to (`vertices`, `faces`).
fn sphere_with_batch(vertices: u32, faces: u32, batch: &[u8]) -> Vec<u8> {
    let s = sphere_stream();
    let index = StreamIndex::parse(s).unwrap();
    let header_len = index.header.byte_len();
    let mut out = s[..HEADER_FIXED].to_vec();
    put_u32(&mut out, AT_BATCHES, 1);
    out.extend_from_slice(&vertices.to_le_bytes());
    out.extend_from_slice(&faces.to_le_bytes());
    out.extend_from_slice(&(batch.len() as u32).to_le_bytes());
    out.extend_from_slice(&s[header_len..index.base.end]);
    out.extend_from_slice(batch);
    out
}

fn err_of(r: vitrine_codec::Result<Decoder>) -> Error {
    match r {
        Ok(d) => panic!("expected an error, decoded {} vertices", d.vertex_count()),
        Err(e) => e,
    }
}

/// The input is rejected as a malformed stream whose message mentions every needle.
#[track_caller]
fn assert_stream_err(r: vitrine_codec::Result<Decoder>, needles: &[&str]) {
    let e = err_of(r);
    assert!(
        matches!(e, Error::Input { what: "stream", .. }),
        "not a stream error: {e:?}"
    );
    let s = e.to_string();
    for n in needles {
        assert!(s.contains(n), "error {s:?} does not mention {n:?}");
    }
}

#[track_caller]
fn assert_limit(r: vitrine_codec::Result<Decoder>, needle: &str) {
    match err_of(r) {
        Error::Limit(m) => assert!(m.contains(needle), "{m:?} does not mention {needle:?}"),
        e => panic!("expected Error::Limit, got {e:?}"),
    }
}

/// What must hold for any decoder that returned `Ok`, whatever its input.
#[track_caller]
fn assert_consistent(d: &Decoder) {
    let n = d.vertex_count();
    assert_eq!(d.indices().len(), 3 * d.face_count());
    if let Some(i) = d.indices().iter().position(|&v| v as usize >= n) {
        panic!("index {i} is {} but there are {n} vertices", d.indices()[i]);
    }
    assert_eq!(d.positions().len(), 3 * n);
    assert_eq!(d.quantized_positions().len(), n);
    if let Some(c) = d.colours() {
        assert_eq!(c.len(), 3 * n);
    }
    let max = (1i32 << d.header().quantization.bits) - 1;
    assert!(d
        .quantized_positions()
        .iter()
        .flatten()
        .all(|&q| (0..=max).contains(&q)));
    let level = d.header().levels[d.level()];
    assert_eq!(
        n, level.vertices as usize,
        "vertex count disagrees with the level table"
    );
}

/// Every undirected edge has at most two faces, and each direction at most one.
fn manifold_violation(indices: &[u32]) -> Option<String> {
    let mut directed: Vec<(u32, u32)> = indices
        .chunks_exact(3)
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .collect();
    directed.sort_unstable();
    if let Some(w) = directed.windows(2).find(|w| w[0] == w[1]) {
        return Some(format!("half-edge {:?} appears twice", w[0]));
    }
    let mut undirected: Vec<(u32, u32)> = directed
        .iter()
        .map(|&(a, b)| (a.min(b), a.max(b)))
        .collect();
    undirected.sort_unstable();
    undirected
        .windows(3)
        .find(|w| w[0] == w[2])
        .map(|w| format!("edge {:?} has more than two faces", w[0]))
}

/// Runs `f`, turning a panic into a message instead of failing at once, so
/// that a sweep can report every bad input together.
fn no_panic<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    catch_unwind(AssertUnwindSafe(f)).map_err(|p| {
        p.downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "non-string panic".into())
    })
}

// ---------------------------------------------------------------- header

#[test]
fn empty_and_tiny_inputs_are_truncated() {
    for len in 0..=HEADER_FIXED {
        let bytes = &sphere_stream()[..len];
        assert_stream_err(decode(bytes, None, Limits::default()), &["truncated"]);
        assert_stream_err(Decoder::new(bytes, Limits::default()), &["truncated"]);
        assert!(Header::parse(bytes).is_err());
        assert!(StreamIndex::parse(bytes).is_err());
    }
}

#[test]
fn wrong_magic_is_refused() {
    let s = sphere_stream();
    for magic in [*b"VTRX", *b"vtrn", *b"NRTV", [0; 4], *b"ply\n", *b"glTF"] {
        let mut b = s.to_vec();
        b[..4].copy_from_slice(&magic);
        assert_stream_err(decode(&b, None, Limits::default()), &["bad magic"]);
    }
    assert_stream_err(
        decode(b"ply\nformat ascii 1.0\n", None, Limits::default()),
        &["bad magic"],
    );
    assert_eq!(&s[..4], &MAGIC);
}

#[test]
fn unsupported_version_is_refused() {
    // VERSION − 1: a stream from the previous format, as a database may hold.
    for v in [0, VERSION - 1, NESTED_VERSION + 1, 0x7f, 0xff] {
        let mut b = sphere_stream().to_vec();
        b[AT_VERSION] = v;
        assert_stream_err(
            decode(&b, None, Limits::default()),
            &["unsupported version", &v.to_string()],
        );
    }
    // A plain stream's header claiming the charted format: its chunks say 4.
    let mut b = sphere_stream().to_vec();
    b[AT_VERSION] = CHARTED_VERSION;
    assert_stream_err(
        decode(&b, None, Limits::default()),
        &[
            "chunk version mismatch",
            "version 4 chunk in a version 5 stream",
        ],
    );
    // And claiming the nested format (6).
    b[AT_VERSION] = NESTED_VERSION;
    assert_stream_err(
        decode(&b, None, Limits::default()),
        &[
            "chunk version mismatch",
            "version 4 chunk in a version 6 stream",
        ],
    );
}

#[test]
fn unknown_flags_are_refused() {
    for flags in [0x02, 0x03, 0x80, 0xff] {
        let mut b = sphere_stream().to_vec();
        b[AT_FLAGS] = flags;
        assert_stream_err(decode(&b, None, Limits::default()), &["unknown flags"]);
    }
}

#[test]
fn quantization_bits_out_of_range_are_refused() {
    for bits in [0, 1, 7, 17, 32, 255] {
        let mut b = sphere_stream().to_vec();
        b[AT_BITS] = bits;
        assert_stream_err(
            decode(&b, None, Limits::default()),
            &[&format!("quantization of {bits} bits")],
        );
    }
}

#[test]
fn non_finite_bounding_box_is_refused() {
    let bad = [
        f32::NAN,
        -f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::from_bits(0x7f80_0001),
    ];
    for axis in 0..3 {
        for v in bad {
            let mut b = sphere_stream().to_vec();
            put_f32(&mut b, AT_MIN + 4 * axis, v);
            assert_stream_err(decode(&b, None, Limits::default()), &["not finite"]);
        }
    }
    for step in [f32::NAN, f32::INFINITY, 0.0, -0.0, -1.0, f32::NEG_INFINITY] {
        let mut b = sphere_stream().to_vec();
        put_f32(&mut b, AT_STEP, step);
        assert_stream_err(decode(&b, None, Limits::default()), &["not finite"]);
    }
}

#[test]
fn level_table_claiming_billions_is_refused_at_once() {
    let t = Instant::now();
    let s = sphere_stream();
    // 4e9 batches in a stream of a few hundred bytes.
    for batches in [4_000_000_000, u32::MAX, 1 << 28] {
        let mut b = s[..100].to_vec();
        put_u32(&mut b, AT_BATCHES, batches);
        assert_stream_err(
            decode(&b, None, NO_LIMITS),
            &[&format!("declares {batches} batches")],
        );
        assert_stream_err(Decoder::new(&b, NO_LIMITS), &["truncated"]);
    }
    // A final level of 4e9 vertices or faces in a 100-byte file.
    let batch = chunk(b'L', 1, 0, 0, 0, &[]);
    let tiny = sphere_with_batch(4_000_000_000, 4_000_000_000, &batch);
    assert!(tiny.len() < 1024);
    // Two faces per added vertex is a format invariant: this table breaks it.
    assert_stream_err(decode(&tiny, None, Limits::default()), &["two per vertex"]);
    // A consistent table claiming 60 M vertices exceeds the default limits.
    let base = StreamIndex::parse(sphere_stream()).unwrap().header.levels[0];
    let (v, f) = (60_000_000u32, base.faces + 2 * (60_000_000 - base.vertices));
    let tiny = sphere_with_batch(v, f, &batch);
    assert_limit(decode(&tiny, None, Limits::default()), "60000000 vertices");
    let base_faces = get_u32(s, level_at(0) + 4);
    let fewer_faces = sphere_with_batch(4_000_000_000, base_faces, &batch);
    assert_stream_err(
        decode(&fewer_faces, None, Limits::default()),
        &["two per vertex"],
    );
    let many_faces = sphere_with_batch(get_u32(s, level_at(0)) + 1, 4_000_000_000, &batch);
    assert_stream_err(
        decode(&many_faces, None, Limits::default()),
        &["two per vertex"],
    );
    // Chunk sizes past the end of the input.
    let mut b = s.to_vec();
    put_u32(&mut b, level_at(1) + 8, u32::MAX);
    assert_stream_err(
        decode(&b, None, Limits::default()),
        &["shorter than its level table"],
    );
    let mut b = s.to_vec();
    put_u32(&mut b, level_at(0) + 8, u32::MAX);
    assert_stream_err(
        decode(&b, None, Limits::default()),
        &["shorter than its level table"],
    );
    assert!(t.elapsed() < Duration::from_secs(2), "{:?}", t.elapsed());
}

#[test]
fn level_table_that_does_not_grow_is_refused() {
    let s = sphere_stream();
    let header = Header::parse(s).unwrap();
    assert!(
        header.batch_count() >= 2,
        "the sample stream needs two batches"
    );
    for k in 1..=header.batch_count() {
        let prev = header.levels[k - 1];
        // Same vertex count as the level before.
        let mut b = s.to_vec();
        put_u32(&mut b, level_at(k), prev.vertices);
        assert_stream_err(decode(&b, None, Limits::default()), &["does not grow"]);
        // Fewer vertices.
        let mut b = s.to_vec();
        put_u32(&mut b, level_at(k), prev.vertices.saturating_sub(1));
        assert_stream_err(decode(&b, None, Limits::default()), &["does not grow"]);
        // Fewer faces.
        let mut b = s.to_vec();
        put_u32(&mut b, level_at(k) + 4, prev.faces - 1);
        assert_stream_err(decode(&b, None, Limits::default()), &["does not grow"]);
    }
}

#[test]
fn limits_are_enforced() {
    let s = sphere_stream();
    let header = Header::parse(s).unwrap();
    let last = header.final_level();
    let exact = Limits {
        max_vertices: last.vertices,
        max_faces: last.faces,
        max_batches: header.batch_count() as u32,
    };
    let d = decode(s, None, exact).unwrap();
    assert_consistent(&d);
    assert!(d.is_complete());

    let fewer_vertices = Limits {
        max_vertices: last.vertices - 1,
        ..exact
    };
    assert_limit(decode(s, None, fewer_vertices), "limits are");
    let fewer_faces = Limits {
        max_faces: last.faces - 1,
        ..exact
    };
    assert_limit(decode(s, None, fewer_faces), "limits are");
    let fewer_batches = Limits {
        max_batches: header.batch_count() as u32 - 1,
        ..exact
    };
    assert_limit(decode(s, None, fewer_batches), "exceed the limit");
    let nothing = Limits {
        max_vertices: 0,
        max_faces: 0,
        max_batches: 0,
    };
    assert!(matches!(decode(s, None, nothing), Err(Error::Limit(_))));
    // The same through the incremental API.
    let index = StreamIndex::parse(s).unwrap();
    assert_limit(
        Decoder::new(&s[index.base.clone()], fewer_vertices),
        "limits are",
    );
    // Decoding only the base level still checks the whole stream against the limits.
    assert_limit(decode(s, Some(0), fewer_vertices), "limits are");
}

// ---------------------------------------------------------------- truncation

#[test]
fn every_prefix_of_a_stream_fails_except_the_whole() {
    let s = sphere_stream();
    for len in 0..s.len() {
        match no_panic(|| decode(&s[..len], None, Limits::default())) {
            Ok(Err(_)) => {}
            Ok(Ok(_)) => panic!("a {len}-byte prefix of a {}-byte stream decoded", s.len()),
            Err(p) => panic!("prefix of {len} bytes panicked: {p}"),
        }
    }
    let d = decode(s, None, Limits::default()).unwrap();
    assert!(d.is_complete());
    assert_consistent(&d);
}

#[test]
fn every_prefix_of_each_chunk_fails() {
    let s = sphere_stream();
    let index = StreamIndex::parse(s).unwrap();
    for len in 0..index.base.end {
        assert!(
            Decoder::new(&s[..len], Limits::default()).is_err(),
            "base prefix {len}"
        );
    }
    let mut reference = Decoder::new(&s[index.base.clone()], Limits::default()).unwrap();
    for (k, range) in index.batches.iter().enumerate() {
        let batch = &s[range.clone()];
        for len in 0..batch.len() {
            // A fresh decoder at the right level for each attempt: a failed
            // batch leaves the decoder unspecified.
            let mut d = decode(s, Some(k), Limits::default()).unwrap();
            let e = d
                .apply_batch(&batch[..len])
                .expect_err("truncated batch accepted");
            assert!(
                e.to_string().contains("truncated"),
                "batch {k} cut at {len}: {e}"
            );
        }
        reference.apply_batch(batch).unwrap();
    }
    assert!(reference.is_complete());
}

/// Cutting a chunk's payload but fixing up every length field, so the
/// container parses and the entropy-coded sections themselves run short.
#[test]
fn payloads_cut_short_with_consistent_lengths_fail() {
    let s = sphere_stream();
    let index = StreamIndex::parse(s).unwrap();
    let mut failures = Vec::new();
    for (k, range) in index.batches.iter().enumerate() {
        let batch = &s[range.clone()];
        let (mut fields, header) = chunk_fields(batch);
        let payload = &batch[header..];
        for cut in 0..payload.len() {
            fields[PAYLOAD_LEN] = cut as u32;
            let short = chunk_claiming(b'L', fields, &payload[..cut]);
            let mut d = decode(s, Some(k), Limits::default()).unwrap();
            match no_panic(|| d.apply_batch(&short)) {
                Ok(Err(_)) => {}
                Ok(Ok(())) => failures.push(format!(
                    "batch {k} cut to {cut} of {} payload bytes decoded",
                    payload.len()
                )),
                Err(p) => failures.push(format!("batch {k} cut to {cut} bytes panicked: {p}")),
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The decoder re-inserts vertices while it walks a batch, so a batch that
/// fails part-way leaves a level half-built: everything after it must be
/// refused, not walked. A batch refused before it touched the level (its
/// framing) changes nothing, and the right batch still applies after it,
/// exactly.
#[test]
fn a_batch_failing_part_way_refuses_what_follows() {
    let s = sphere_stream();
    let index = StreamIndex::parse(s).unwrap();
    let k = index.batches.len() - 1;
    let batch = &s[index.batches[k].clone()];
    let whole = decode(s, None, Limits::default()).unwrap();
    let (mut refused, mut untouched) = (0, 0);
    for at in 0..batch.len() {
        let mut flipped = batch.to_vec();
        flipped[at] ^= 0xff;
        let mut d = decode(s, Some(k), Limits::default()).unwrap();
        if d.apply_batch(&flipped).is_ok() {
            continue; // a flip the codes absorb: a different, valid level
        }
        match no_panic(|| d.apply_batch(batch)).unwrap_or_else(|p| panic!("byte {at}: {p}")) {
            Err(e) => {
                assert!(
                    e.to_string().contains("earlier batch failed"),
                    "byte {at}: {e}"
                );
                refused += 1;
            }
            Ok(()) => {
                assert_eq!(d.indices(), whole.indices(), "byte {at}");
                assert_eq!(d.quantized_positions(), whole.quantized_positions());
                untouched += 1;
            }
        }
    }
    assert!(
        refused > 0 && untouched > 0,
        "{refused} refused, {untouched} untouched"
    );
}

// ---------------------------------------------------------------- batches out of place

#[test]
fn batches_applied_twice_out_of_order_or_from_another_stream_fail() {
    let s = sphere_stream();
    let index = StreamIndex::parse(s).unwrap();
    let batch = |k: usize| &s[index.batches[k].clone()];
    let base = &s[index.base.clone()];

    // Twice.
    let mut d = Decoder::new(base, Limits::default()).unwrap();
    d.apply_batch(batch(0)).unwrap();
    assert!(d
        .apply_batch(batch(0))
        .unwrap_err()
        .to_string()
        .contains("batch for level 1 applied at level 1"));

    // Out of order: batch 2 first.
    let mut d = Decoder::new(base, Limits::default()).unwrap();
    let e = d.apply_batch(batch(1)).unwrap_err().to_string();
    assert!(e.contains("batch for level 2 applied at level 0"), "{e}");

    // Past the end: every batch applied, then one more.
    let mut d = Decoder::new(base, Limits::default()).unwrap();
    for k in 0..index.batches.len() {
        d.apply_batch(batch(k)).unwrap();
    }
    assert!(d.apply_batch(batch(0)).is_err());
    let mut renumbered = batch(0).to_vec();
    renumbered[2..4].copy_from_slice(&(index.batches.len() as u16 + 1).to_le_bytes());
    assert!(d.apply_batch(&renumbered).is_err());

    // The base chunk where a batch belongs, and a batch where the base belongs.
    let mut d = Decoder::new(base, Limits::default()).unwrap();
    let header_len = index.header.byte_len();
    let e = d.apply_batch(&base[header_len..]).unwrap_err().to_string();
    assert!(e.contains("expected a batch chunk"), "{e}");
    let mut wrong = base[..header_len].to_vec();
    wrong.extend_from_slice(batch(0));
    assert_stream_err(
        Decoder::new(&wrong, Limits::default()),
        &["expected a base chunk"],
    );

    // A batch from another stream: a torus has different counts.
    let other = encode(
        &vitrine_samples::torus(40, 16, 1.0, 0.4),
        &EncodeOptions::default(),
    )
    .unwrap();
    let oi = StreamIndex::parse(&other.bytes).unwrap();
    let mut d = Decoder::new(base, Limits::default()).unwrap();
    for r in &oi.batches {
        assert!(d.apply_batch(&other.bytes[r.clone()]).is_err());
    }
    // A batch from another stream of the same counts (the same sphere at a
    // different quantization, when that keeps the counts): nothing in the
    // format can tell the geometry apart, but the result must stay consistent.
    let q10 = encode(
        &icosphere(3),
        &EncodeOptions {
            quantization_bits: 10,
            ..Default::default()
        },
    )
    .unwrap();
    let qi = StreamIndex::parse(&q10.bytes).unwrap();
    let mut d = Decoder::new(base, Limits::default()).unwrap();
    for r in &qi.batches {
        if d.apply_batch(&q10.bytes[r.clone()]).is_err() {
            break;
        }
        assert_consistent(&d);
    }
}

#[test]
fn malformed_batch_payloads_are_refused() {
    let s = sphere_stream();
    let index = StreamIndex::parse(s).unwrap();
    let n = index.header.levels[0].vertices;
    let fresh = || Decoder::new(&s[index.base.clone()], Limits::default()).unwrap();
    let real = &s[index.batches[0].clone()];
    let (fields, header) = chunk_fields(real);
    let (after, faces) = (fields[AFTER], fields[FACES]);

    // Chunk version.
    let mut b = real.to_vec();
    b[1] = VERSION + 1;
    assert!(fresh()
        .apply_batch(&b)
        .unwrap_err()
        .to_string()
        .contains("chunk version mismatch"));
    // Counts that disagree with the level table.
    for (field, v) in [(BEFORE, n + 1), (AFTER, after + 1), (FACES, faces + 1)] {
        let mut b = real.to_vec();
        set_chunk_field(&mut b, 0, field, v);
        let e = fresh().apply_batch(&b).unwrap_err().to_string();
        assert!(e.contains("disagree with the level table"), "{e}");
    }
    // Payload length past the chunk.
    let mut long = fields;
    long[PAYLOAD_LEN] = u32::MAX;
    let b = chunk_claiming(b'L', long, &real[header..]);
    assert!(fresh()
        .apply_batch(&b)
        .unwrap_err()
        .to_string()
        .contains("truncated"));

    let batch_with = |payload: &[u8]| chunk(b'L', 1, n, after, faces, payload);
    let apply = |payload: &[u8]| {
        fresh()
            .apply_batch(&batch_with(payload))
            .unwrap_err()
            .to_string()
    };
    // A seed count far beyond the bytes present.
    let mut p = Vec::new();
    varint(&mut p, u32::MAX);
    assert!(apply(&p).contains("more seeds than it has bytes"));
    // Varints longer than five bytes or wider than 32 bits.
    assert!(apply(&[0x80, 0x80, 0x80, 0x80, 0x80, 0x01]).contains("varint longer than 5 bytes"));
    assert!(apply(&[0xff, 0xff, 0xff, 0xff, 0x7f]).contains("varint exceeds 32 bits"));
    // Trailing bytes after both passes.
    let mut p = pass(&[], 0);
    p.extend(pass(&[], after - n));
    p.push(0);
    assert!(apply(&p).contains("trailing bytes"));
    // Passes that insert a different number of vertices than the batch.
    let mut p = pass(&[], 0);
    p.extend(pass(&[], after - n + 1));
    assert!(apply(&p).contains("different number of vertices"));
    let mut p = pass(&[], u32::MAX);
    p.extend(pass(&[], u32::MAX));
    assert!(apply(&p).contains("different number of vertices"));
    // From here on the passes parse; what is wrong is inside them, found by
    // the conquest (whose messages are the decoder's business: only the kind
    // of error is checked).
    let stream_err = |payload: &[u8]| {
        let e = fresh().apply_batch(&batch_with(payload)).unwrap_err();
        assert!(matches!(e, Error::Input { what: "stream", .. }), "{e:?}");
    };
    let seed = {
        // A real edge of the base mesh, as a seed gate.
        let d = fresh();
        let t = &d.indices()[..3];
        [t[0], t[1]]
    };
    // Sections that are empty, or do not start with the range coder's zero byte.
    for seeds in [&[][..], &[seed][..]] {
        let mut p = vec![0, 0, 0, 0, 0];
        p.extend(pass(seeds, after - n));
        stream_err(&p);
        let mut p = pass(seeds, after - n);
        let k = p.len() - 6;
        p[k..].copy_from_slice(&[1, 7, 1, 0, 1, 0]);
        p.extend(pass(&[], 0));
        stream_err(&p);
    }
    // Seeds naming vertices that do not exist yet, or no edge.
    for bad in [
        [n, 0],
        [0, u32::MAX],
        [u32::MAX, u32::MAX],
        [0, 0],
        [seed[1], seed[0] + n],
    ] {
        let mut p = pass(&[bad], after - n);
        p.extend(pass(&[], 0));
        stream_err(&p);
        let mut p = pass(&[], 0);
        p.extend(pass(&[seed, bad], after - n));
        stream_err(&p);
    }
    // The same seed twice.
    let mut p = pass(&[seed, seed], after - n);
    p.extend(pass(&[], 0));
    stream_err(&p);
    // Passes with no seeds cannot insert anything, and empty sections
    // cannot hold the codes for the gates a seed opens.
    let mut p = pass(&[], after - n);
    p.extend(pass(&[], 0));
    stream_err(&p);
    let mut p = pass(&[seed], after - n);
    p.extend(pass(&[seed], 0));
    stream_err(&p);
}

#[test]
fn base_chunk_that_disagrees_with_the_level_table_is_refused() {
    let s = sphere_stream();
    let index = StreamIndex::parse(s).unwrap();
    let at = index.header.byte_len();
    for field in [AFTER, FACES] {
        let mut b = s.to_vec();
        let v = chunk_fields(&b[at..]).0[field];
        set_chunk_field(&mut b, at, field, v + 1);
        assert_stream_err(
            decode(&b, None, Limits::default()),
            &["base chunk disagrees"],
        );
    }
    // The table and the chunk agree on one vertex more than the faces use.
    let mut b = s.to_vec();
    let v = get_u32(&b, level_at(0));
    put_u32(&mut b, level_at(0), v + 1);
    set_chunk_field(&mut b, at, AFTER, v + 1);
    // Caught by the level table's two-faces-per-vertex rule before the base is decoded.
    assert_stream_err(decode(&b, None, Limits::default()), &["level table"]);
    // One face fewer than coded.
    let mut b = s.to_vec();
    let faces = get_u32(&b, level_at(0) + 4);
    put_u32(&mut b, level_at(0) + 4, faces - 1);
    set_chunk_field(&mut b, at, FACES, faces - 1);
    assert!(decode(&b, None, Limits::default()).is_err());
}

/// A level table whose face counts disagree with what the batches produce
/// (each inserted vertex adds exactly two faces) must not decode as if it
/// were right: a viewer sizes buffers from the table.
#[test]
fn level_table_lying_about_faces_is_refused() {
    let s = sphere_stream();
    let index = StreamIndex::parse(s).unwrap();
    let k = index.header.batch_count();
    let mut b = s.to_vec();
    let last = index.batches[k - 1].start;
    let faces = get_u32(&b, level_at(k) + 4);
    put_u32(&mut b, level_at(k) + 4, faces + 1);
    set_chunk_field(&mut b, last, FACES, faces + 1);
    match decode(&b, None, Limits::default()) {
        Err(_) => {}
        Ok(d) => panic!(
            "header says {} faces, decoder has {}",
            faces + 1,
            d.face_count()
        ),
    }
}

// ---------------------------------------------------------------- bit flips

/// Flips bits of the stream one at a time: every bit of every batch, and
/// three bits of every header and base byte. The decoder must return Err, or
/// Ok with buffers that are still consistent. A flip in batch `k` is decoded
/// through batch `k + 1` (the batch after a damaged one must cope with the
/// state it left), which keeps the sweep to a few seconds.
#[test]
fn every_single_bit_flip_is_an_error_or_consistent() {
    let s = sphere_stream();
    let index = StreamIndex::parse(s).unwrap();
    let t = Instant::now();
    let (mut flips, mut oks, mut errs) = (0usize, 0usize, 0usize);
    let mut failures = Vec::new();
    let mut not_manifold = Vec::new();
    let mut b = s.to_vec();
    for at in 0..s.len() {
        let batch = index.batches.iter().position(|r| r.contains(&at));
        let (bits, levels): (&[u8], _) = match batch {
            Some(k) => (&[0, 1, 2, 3, 4, 5, 6, 7], Some(k + 2)),
            None => (&[0, 4, 7], None),
        };
        for &bit in bits {
            flips += 1;
            b[at] ^= 1 << bit;
            match no_panic(|| {
                decode(&b, levels, Limits::default())
                    .map(|d| (no_panic(|| assert_consistent(&d)), d))
            }) {
                Ok(Ok((Ok(()), d))) => {
                    oks += 1;
                    if let Some(v) = manifold_violation(d.indices()) {
                        not_manifold.push(format!("byte {at} bit {bit}: {v}"));
                    }
                }
                Ok(Ok((Err(p), _))) => {
                    failures.push(format!("byte {at} bit {bit}: inconsistent decoder: {p}"))
                }
                Ok(Err(_)) => errs += 1,
                Err(p) => failures.push(format!("byte {at} bit {bit}: panicked: {p}")),
            }
            b[at] ^= 1 << bit;
        }
    }
    eprintln!(
        "{flips} bit flips over {} bytes ({} header and base, {} batches): {errs} errors, {oks} decoded, in {:?}",
        s.len(),
        index.base.len(),
        index.batches.len(),
        t.elapsed()
    );
    assert!(
        failures.is_empty(),
        "{} failures: {failures:#?}",
        failures.len()
    );
    // Not a requirement of the format (a flipped bit can make any other valid
    // stream); reported so that a change in it is noticed.
    if !not_manifold.is_empty() {
        eprintln!("decoded to a non-manifold mesh: {not_manifold:#?}");
    }
}

/// The same for the incremental API, batch by batch, with a few bytes at a
/// time overwritten by every value.
#[test]
fn overwritten_batch_bytes_are_errors_or_consistent() {
    let s = sphere_stream();
    let index = StreamIndex::parse(s).unwrap();
    let mut failures = Vec::new();
    for (k, range) in index.batches.iter().enumerate() {
        let batch = &s[range.clone()];
        // The chunk header and the first bytes of the payload, where the pass
        // counts and seeds live.
        let header = chunk_fields(batch).1;
        for at in (0..batch.len().min(header + 24)).chain([batch.len() / 2, batch.len() - 1]) {
            for v in [0u8, 1, 2, 0x7f, 0x80, 0xfe, 0xff] {
                let mut b = batch.to_vec();
                if b[at] == v {
                    continue;
                }
                b[at] = v;
                let mut d = decode(s, Some(k), Limits::default()).unwrap();
                match no_panic(|| d.apply_batch(&b)) {
                    Ok(Ok(())) => {
                        if let Err(p) = no_panic(|| assert_consistent(&d)) {
                            failures
                                .push(format!("batch {k} byte {at} = {v:#x}: inconsistent: {p}"));
                        }
                    }
                    Ok(Err(_)) => {}
                    Err(p) => failures.push(format!("batch {k} byte {at} = {v:#x}: panicked: {p}")),
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

// ---------------------------------------------------------------- allocation

/// A 59-byte stream whose base level claims 2^32 − 1 vertices and faces,
/// with a 4-byte payload.
fn claims_four_billion() -> Vec<u8> {
    let b = base_claiming(u32::MAX, u32::MAX);
    assert_eq!(b.len(), 59);
    b
}

/// A stream with no batches whose base claims `vertices` and `faces` (in
/// the level table and the chunk), with a 4-byte payload.
fn base_claiming(vertices: u32, faces: u32) -> Vec<u8> {
    let mut b = MAGIC.to_vec();
    b.extend_from_slice(&[VERSION, 0, 12, 0]);
    for v in [0f32, 0.0, 0.0, 1.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&0u32.to_le_bytes()); // no batches
    let payload = [0u8; 4];
    let base = chunk(b'M', 0, 0, vertices, faces, &payload);
    for v in [vertices, faces, base.len() as u32] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&base);
    b
}

#[track_caller]
fn assert_small_peak<T>(what: &str, f: impl FnOnce() -> T) -> T {
    let mut out = None;
    let t = Instant::now();
    let info = allocation_counter::measure(|| out = Some(f()));
    let took = t.elapsed();
    assert!(
        info.bytes_max <= SMALL_PEAK,
        "{what}: peak allocation {} bytes",
        info.bytes_max
    );
    assert!(took < Duration::from_secs(2), "{what}: took {took:?}");
    out.unwrap()
}

#[test]
fn hostile_headers_do_not_allocate_what_they_claim() {
    let tiny = claims_four_billion();
    // Default limits: refused by the limit check.
    let r = assert_small_peak("2^32 vertices, default limits", || {
        decode(&tiny, None, Limits::default())
    });
    assert_limit(r, "4294967295 vertices");
    // No limits at all: refused by the base mesh decoder, whose payload runs out.
    let r = assert_small_peak("2^32 vertices, no limits", || {
        decode(&tiny, None, NO_LIMITS)
    });
    assert_stream_err(r, &["truncated entropy-coded payload"]);
    let r = assert_small_peak("2^32 vertices, no limits, Decoder::new", || {
        Decoder::new(&tiny, NO_LIMITS)
    });
    assert!(r.is_err());

    // The base at the default limits: 50 M vertices and 100 M faces in 59 bytes.
    let l = Limits::default();
    let b = base_claiming(l.max_vertices, l.max_faces);
    let r = assert_small_peak("base at the default limits", || decode(&b, None, l));
    assert_stream_err(r, &["truncated entropy-coded payload"]);

    // 4e9 batches and a batch chunk of 4 GB, each in under a kilobyte.
    let mut b = sphere_stream()[..200].to_vec();
    put_u32(&mut b, AT_BATCHES, 4_000_000_000);
    assert!(assert_small_peak("4e9 batches", || decode(&b, None, NO_LIMITS)).is_err());
    let mut b = sphere_stream().to_vec();
    put_u32(&mut b, level_at(1) + 8, u32::MAX);
    assert!(assert_small_peak("4 GB chunk", || decode(&b, None, NO_LIMITS)).is_err());

    // A batch growing the sphere to 2^32 − 1 vertices, with no limits, whose
    // passes do not parse.
    let base_vertices = get_u32(sphere_stream(), level_at(0));
    let batch = chunk(b'L', 1, base_vertices, u32::MAX, u32::MAX, &[0xff; 8]);
    let b = sphere_with_batch(u32::MAX, u32::MAX, &batch);
    assert!(
        assert_small_peak("2^32 vertices in a garbage batch", || decode(
            &b, None, NO_LIMITS
        ))
        .is_err()
    );
}

/// A ~200-byte batch whose passes parse and whose counts agree, claiming to
/// grow the sphere to the default vertex limit (50 M vertices). The decoder
/// must not reserve buffers for 50 M vertices (≈ 3.6 GB) before it has
/// decoded a single one.
#[test]
fn batch_claiming_millions_of_vertices_does_not_allocate_them() {
    let limits = Limits::default();
    let s = sphere_stream();
    let n = get_u32(s, level_at(0));
    let (target, faces) = (limits.max_vertices, limits.max_faces);
    let mut payload = pass(&[], target - n);
    payload.extend(pass(&[], 0));
    let batch = chunk(b'L', 1, n, target, faces, &payload);
    let b = sphere_with_batch(target, faces, &batch);
    assert!(b.len() < 4096);
    let r = assert_small_peak("batch claiming 50 M vertices", || decode(&b, None, limits));
    assert!(r.is_err());
}

/// A real stream whose level table claims a final level at the default
/// vertex limit: the decoder reserves toward the final count as batches
/// come, but no further than a few times what each batch verifies, so the
/// real batches still decode, in small memory.
#[test]
fn final_level_claiming_millions_reserves_only_what_batches_verify() {
    let limits = Limits::default();
    let s = sphere_stream();
    let header = Header::parse(s).unwrap();
    let k = header.batch_count();
    assert!(k >= 2, "the sample stream needs two batches");
    let prev = header.levels[k - 1];
    let mut b = s.to_vec();
    put_u32(&mut b, level_at(k), limits.max_vertices);
    put_u32(
        &mut b,
        level_at(k) + 4,
        prev.faces + 2 * (limits.max_vertices - prev.vertices),
    );
    let d = assert_small_peak("final level claiming 50 M vertices", || {
        decode(&b, Some(k - 1), limits)
    })
    .expect("the batches before the last are real");
    let real = decode(s, Some(k - 1), limits).unwrap();
    assert_eq!(d.positions(), real.positions());
    assert_eq!(d.indices(), real.indices());
    // The last batch disagrees with the claim, and says so.
    assert_stream_err(decode(&b, None, limits), &["level table"]);
}

// ---------------------------------------------------------------- mesh files

mod files {
    use super::*;
    use vitrine_codec::{IndexedMesh, Quantization};
    use vitrine_mesh::import::{import_bytes, ImportOptions, MeshFormat};
    use vitrine_mesh::repair::{check_manifold, prepare, RepairOptions};

    fn small() -> ImportOptions {
        ImportOptions {
            max_vertices: 1000,
            max_faces: 2000,
            ..ImportOptions::default()
        }
    }

    #[track_caller]
    fn assert_import_err(bytes: &[u8], format: MeshFormat, needles: &[&str]) {
        let r = assert_small_peak("import", || {
            import_bytes(bytes, format, &ImportOptions::default())
        });
        let e = match r {
            Ok(m) => panic!("expected an error, got {} vertices", m.positions.len()),
            Err(e) => e.to_string(),
        };
        for n in needles {
            assert!(e.contains(n), "error {e:?} does not mention {n:?}");
        }
    }

    fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
        let mut json = json.as_bytes().to_vec();
        json.resize(json.len().next_multiple_of(4), b' ');
        let mut bin = bin.to_vec();
        bin.resize(bin.len().next_multiple_of(4), 0);
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = b"glTF".to_vec();
        for v in [2, total as u32, json.len() as u32] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }

    fn base64(data: &[u8]) -> String {
        const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut s = String::new();
        for c in data.chunks(3) {
            let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
            let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
            for k in 0..4 {
                s.push(if k <= c.len() {
                    T[(n >> (18 - 6 * k) & 63) as usize] as char
                } else {
                    '='
                });
            }
        }
        s
    }

    /// One triangle: three float positions and three u32 indices.
    fn triangle_bin(p: [[f32; 3]; 3], idx: [u32; 3]) -> Vec<u8> {
        let mut bin = Vec::new();
        for v in p.iter().flatten() {
            bin.extend_from_slice(&v.to_le_bytes());
        }
        for i in idx {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        bin
    }

    fn triangle_json(buffer: &str, vertex_count: u32) -> String {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
            "buffers":[{buffer}],
            "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":12}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":{vertex_count},"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                         {{"bufferView":1,"componentType":5125,"count":3,"type":"SCALAR"}}]}}"#
        )
    }

    const GOOD: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    #[test]
    fn gltf_triangle_fixture_imports() {
        let bin = triangle_bin(GOOD, [0, 1, 2]);
        let m = import_bytes(
            &glb(&triangle_json(r#"{"byteLength":48}"#, 3), &bin),
            MeshFormat::Glb,
            &small(),
        )
        .unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        let uri = format!(
            r#"{{"byteLength":48,"uri":"data:application/octet-stream;base64,{}"}}"#,
            base64(&bin)
        );
        let m = import_bytes(
            triangle_json(&uri, 3).as_bytes(),
            MeshFormat::Gltf,
            &small(),
        )
        .unwrap();
        assert_eq!(m.positions, GOOD.to_vec());
    }

    #[test]
    fn nan_and_infinity_in_every_format() {
        use MeshFormat::*;
        for bad in ["nan", "NaN", "inf", "-inf", "1e999"] {
            let ply = format!(
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                 element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 {bad}\n0 1 0\n3 0 1 2\n"
            );
            assert_import_err(ply.as_bytes(), Ply, &["non-finite"]);
            let obj = format!("v 0 0 0\nv 1 0 0\nv {bad} 1 0\nf 1 2 3\n");
            assert_import_err(obj.as_bytes(), Obj, &["line 3", "non-finite"]);
            let off = format!("OFF\n3 1 0\n0 0 0\n{bad} 0 0\n0 1 0\n3 0 1 2\n");
            assert_import_err(off.as_bytes(), Off, &["line 4", "non-finite"]);
            let coff = format!("COFF\n3 1 0\n0 0 0 1 1 1\n1 0 0 1 1 1\n0 {bad} 0 1 1 1\n3 0 1 2\n");
            assert_import_err(coff.as_bytes(), Off, &["non-finite"]);
        }
        // Binary PLY, big-endian doubles.
        let mut ply = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\n\
                        property double z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n"
            .to_vec();
        for v in [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, f64::NAN] {
            ply.extend_from_slice(&f64::to_be_bytes(v));
        }
        ply.push(3);
        for i in [0u32, 1, 2] {
            ply.extend_from_slice(&i.to_be_bytes());
        }
        assert_import_err(&ply, Ply, &["vertex 2", "non-finite"]);
        // glTF and GLB.
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let mut p = GOOD;
            p[1][2] = bad;
            let bin = triangle_bin(p, [0, 1, 2]);
            assert_import_err(
                &glb(&triangle_json(r#"{"byteLength":48}"#, 3), &bin),
                Glb,
                &["vertex 1", "non-finite"],
            );
            let uri = format!(
                r#"{{"byteLength":48,"uri":"data:application/octet-stream;base64,{}"}}"#,
                base64(&bin)
            );
            assert_import_err(
                triangle_json(&uri, 3).as_bytes(),
                Gltf,
                &["vertex 1", "non-finite"],
            );
        }
        // Finite in the file, infinite once a node's transform is applied.
        let bin = triangle_bin(GOOD, [0, 1, 2]);
        let json = triangle_json(r#"{"byteLength":48}"#, 3).replacen(
            r#""meshes""#,
            r#""scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0,"scale":[3e38,3e38,3e38]},{"mesh":0}],"meshes""#,
            1,
        );
        let json = json.replace(
            r#""scale":[3e38,3e38,3e38]},{"mesh":0}"#,
            r#""scale":[3e38,3e38,3e38],"translation":[3e38,0,0]}"#,
        );
        assert_import_err(&glb(&json, &bin), Glb, &["non-finite"]);
    }

    #[test]
    fn indices_out_of_range_in_every_format() {
        use MeshFormat::*;
        let ply = |idx: &str| {
            format!(
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                 element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 {idx}\n"
            )
        };
        assert_import_err(
            ply("0 1 3").as_bytes(),
            Ply,
            &["face 0", "vertex index 3", "out of range"],
        );
        assert_import_err(
            ply("0 1 -1").as_bytes(),
            Ply,
            &["face 0", "vertex index -1"],
        );
        assert_import_err(
            ply("0 1 2147483647").as_bytes(),
            Ply,
            &["vertex index 2147483647"],
        );
        // Indices as uint beyond i32.
        let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                      property float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n"
            .to_vec();
        b.extend_from_slice(&[0u8; 36]);
        b.push(3);
        for i in [0u32, 1, u32::MAX] {
            b.extend_from_slice(&i.to_le_bytes());
        }
        assert_import_err(&b, Ply, &["face 0", "out of range"]);
        // OBJ: past the end, zero, before the first, beyond u32.
        assert_import_err(
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
            Obj,
            &["vertex index 4", "out of range"],
        );
        assert_import_err(
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n",
            Obj,
            &["vertex index 0"],
        );
        assert_import_err(
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
            Obj,
            &["before the first vertex"],
        );
        assert_import_err(
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999\n",
            Obj,
            &["out of range"],
        );
        assert_import_err(
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -99999999999\n",
            Obj,
            &["before the first vertex"],
        );
        assert_import_err(
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999999\n",
            Obj,
            &["bad vertex index"],
        );
        // OFF: past the end and negative.
        assert_import_err(
            b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
            Off,
            &["vertex index 3"],
        );
        assert!(import_bytes(
            b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n",
            Off,
            &small()
        )
        .is_err());
        assert!(import_bytes(
            b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 4294967296\n",
            Off,
            &small()
        )
        .is_err());
        // glTF and GLB: one index past the positions, and u32::MAX.
        for bad in [3, u32::MAX] {
            let bin = triangle_bin(GOOD, [0, 1, bad]);
            assert_import_err(
                &glb(&triangle_json(r#"{"byteLength":48}"#, 3), &bin),
                Glb,
                &["triangle 0", "out of range"],
            );
            let uri = format!(
                r#"{{"byteLength":48,"uri":"data:application/octet-stream;base64,{}"}}"#,
                base64(&bin)
            );
            assert_import_err(
                triangle_json(&uri, 3).as_bytes(),
                Gltf,
                &["triangle 0", "out of range"],
            );
        }
        // An accessor claiming more positions than its buffer view holds.
        let bin = triangle_bin(GOOD, [0, 1, 2]);
        assert_import_err(
            &glb(&triangle_json(r#"{"byteLength":48}"#, 4_000_000_000), &bin),
            Glb,
            &["run past the end"],
        );
    }

    #[test]
    fn decompression_bomb_declarations_are_bounded() {
        use MeshFormat::*;
        let t = Instant::now();
        // Binary PLY declaring 4e9 faces after three vertices.
        let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                      property float z\nelement face 4000000000\nproperty list uchar int vertex_indices\nend_header\n"
            .to_vec();
        b.extend_from_slice(&[0u8; 36]);
        b.extend_from_slice(&[3, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0]);
        assert_import_err(&b, Ply, &["4000000000 faces"]);
        // Lists that each claim 255 entries but end at once.
        let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                      property float z\nelement face 3\nproperty list uint int vertex_indices\nend_header\n"
            .to_vec();
        b.extend_from_slice(&[0u8; 36]);
        b.extend_from_slice(&0x4000_0000u32.to_le_bytes());
        b.extend_from_slice(&[0; 8]);
        assert_import_err(&b, Ply, &["truncated", "face 0"]);
        // ASCII PLY element counts at u64 scale.
        let huge = "ply\nformat ascii 1.0\nelement vertex 18446744073709551615\nproperty float x\nproperty float y\n\
                    property float z\nend_header\n0 0 0\n";
        assert!(import_bytes(huge.as_bytes(), Ply, &small()).is_err());
        // OFF declaring 4e9 faces and 4e9 vertices.
        assert_import_err(
            b"OFF\n3 4000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
            Off,
            &["4000000000 faces"],
        );
        assert_import_err(b"OFF 4000000000 1 0\n", Off, &["4000000000 vertices"]);
        // A polygon with four billion corners.
        assert!(import_bytes(
            b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n",
            Off,
            &small()
        )
        .is_err());
        // glTF: a buffer declaring 4 GB, an accessor of 4e9 elements with no data.
        let bin = triangle_bin(GOOD, [0, 1, 2]);
        assert_import_err(
            &glb(&triangle_json(r#"{"byteLength":4000000000}"#, 3), &bin),
            Glb,
            &["truncated"],
        );
        let no_view = triangle_json(r#"{"byteLength":48}"#, 3).replace(
            r#"{"bufferView":0,"componentType":5126,"count":3"#,
            r#"{"componentType":5126,"count":4000000000"#,
        );
        assert!(assert_small_peak("accessor without view", || import_bytes(
            &glb(&no_view, &bin),
            Glb,
            &ImportOptions::default()
        ))
        .is_err());
        assert!(t.elapsed() < Duration::from_secs(3), "{:?}", t.elapsed());
    }

    /// Ten million `f 1 1 1` lines: with small limits an error as soon as the
    /// limit is passed; with the defaults a mesh whose memory is linear in
    /// the file's size.
    #[test]
    fn obj_with_ten_million_faces_is_bounded() {
        const LINES: usize = 10_000_000;
        let mut obj = b"v 0 0 0\n".to_vec();
        obj.extend_from_slice(&b"f 1 1 1\n".repeat(LINES));
        let t = Instant::now();
        let info =
            allocation_counter::measure(|| match import_bytes(&obj, MeshFormat::Obj, &small()) {
                Err(Error::Limit(m)) => assert!(m.contains("more than 2000 triangles"), "{m}"),
                other => panic!("{:?}", other.map(|m| m.triangles.len())),
            });
        assert!(info.bytes_max < 1 << 20, "{}", info.bytes_max);
        assert!(t.elapsed() < Duration::from_secs(1), "{:?}", t.elapsed());

        let t = Instant::now();
        let mut mesh = None;
        let info = allocation_counter::measure(|| {
            mesh = Some(import_bytes(
                &obj,
                MeshFormat::Obj,
                &ImportOptions::default(),
            ))
        });
        let mesh = mesh.unwrap().unwrap();
        assert_eq!(mesh.triangles.len(), LINES);
        assert!(
            info.bytes_max < 4 * obj.len() as u64,
            "{} bytes for a {}-byte file",
            info.bytes_max,
            obj.len()
        );
        eprintln!(
            "10^7 OBJ faces: {:?}, peak {} MB",
            t.elapsed(),
            info.bytes_max >> 20
        );
        assert!(t.elapsed() < Duration::from_secs(20), "{:?}", t.elapsed());
        // Every face is degenerate: repair leaves nothing to encode.
        drop(obj);
        let e = prepare(mesh, &RepairOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("no triangles left"), "{e}");
    }

    /// Found by the `import_gltf` fuzz target: gltf-json's validation
    /// indexed a primitive's POSITION accessor before checking it exists
    /// (`gltf-json-1.4.1/src/mesh.rs:151`: index out of bounds).
    #[test]
    fn gltf_position_accessor_past_the_end_is_an_error() {
        let json = br#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}"#;
        for format in [MeshFormat::Gltf, MeshFormat::Glb] {
            let bytes = if format == MeshFormat::Glb {
                glb(std::str::from_utf8(json).unwrap(), &[])
            } else {
                json.to_vec()
            };
            let e = no_panic(|| import_bytes(&bytes, format, &small()))
                .unwrap_or_else(|p| panic!("{format:?} panicked: {p}"))
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("accessor 0") && e.contains("mesh 0 primitive 0"),
                "{e}"
            );
        }
        let json = r#"{"asset":{"version":"2.0"},"accessors":[],"meshes":[{"primitives":[{"attributes":{"COLOR_0":7,"POSITION":0}}]}]}"#;
        assert!(
            no_panic(|| import_bytes(json.as_bytes(), MeshFormat::Gltf, &small()))
                .unwrap()
                .is_err()
        );
    }

    /// Every input under `tests/corpus/<target>/` (crashes the fuzz targets
    /// found, kept whole) goes through what its target calls: no panic.
    #[test]
    fn fuzz_crash_corpus_does_not_panic() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus");
        let mut seen = 0;
        for (dir, format) in [
            ("decode_stream", None),
            ("import_ply", Some(MeshFormat::Ply)),
            ("import_obj", Some(MeshFormat::Obj)),
            ("import_off", Some(MeshFormat::Off)),
            ("import_gltf", Some(MeshFormat::Gltf)),
        ] {
            let Ok(entries) = std::fs::read_dir(root.join(dir)) else {
                continue;
            };
            for entry in entries {
                let path = entry.unwrap().path();
                let bytes = std::fs::read(&path).unwrap();
                let outcome = match format {
                    Some(f) => no_panic(|| import_bytes(&bytes, f, &small()).map(|_| ())),
                    None => no_panic(|| decode(&bytes, None, Limits::default()).map(|_| ())),
                };
                if let Err(p) = outcome {
                    panic!("{} panicked: {p}", path.display());
                }
                seen += 1;
            }
        }
        assert!(seen > 0, "no corpus under {}", root.display());
    }

    fn canonical(t: [u32; 3]) -> [u32; 3] {
        let i = (0..3).min_by_key(|&i| t[i]).unwrap();
        [t[i], t[(i + 1) % 3], t[(i + 2) % 3]]
    }

    /// prepare → check_manifold → encode → decode: the final level is the
    /// quantized repaired mesh.
    fn assert_repairs_and_round_trips(mesh: IndexedMesh, expect_split: bool) {
        let (fixed, report) = prepare(mesh, &RepairOptions::default()).unwrap();
        check_manifold(&fixed).unwrap();
        if expect_split {
            assert!(report.split_vertices > 0, "{report}");
        }
        // Without welding: the copies a split makes share their position.
        let strict = RepairOptions {
            weld: false,
            split_non_manifold: false,
        };
        if let Err(e) = prepare(fixed.clone(), &strict) {
            panic!("a repaired mesh needs no more splitting: {e}");
        }
        let options = EncodeOptions {
            min_base_vertices: 8,
            ..Default::default()
        };
        let encoded = encode(&fixed, &options).unwrap();
        let d = decode(&encoded.bytes, None, Limits::default()).unwrap();
        assert_consistent(&d);
        let q = Quantization::for_positions(&fixed.positions, options.quantization_bits).unwrap();
        let order = &encoded.vertex_order;
        for (i, &v) in order.iter().enumerate() {
            assert_eq!(
                d.quantized_positions()[i],
                q.quantize(fixed.positions[v as usize]),
                "vertex {i}"
            );
        }
        let mut expected: Vec<_> = fixed.triangles.iter().map(|&t| canonical(t)).collect();
        let mut got: Vec<_> = d
            .indices()
            .chunks_exact(3)
            .map(|t| {
                canonical([
                    order[t[0] as usize],
                    order[t[1] as usize],
                    order[t[2] as usize],
                ])
            })
            .collect();
        expected.sort_unstable();
        got.sort_unstable();
        assert_eq!(got, expected);
    }

    /// Two spheres touching at one shared vertex (a bow tie of fans), a fin
    /// on an edge (three faces on it), and three cones sharing their apex.
    #[test]
    fn non_manifold_fans_are_split_and_round_trip() {
        // Sphere B is sphere A mirrored through the tangent plane at vertex 0,
        // with vertex 0 shared (same index, not merely the same position).
        let a = icosphere(2);
        let n = a.positions.len() as u32;
        let apex = a.positions[0];
        let mut m = a.clone();
        for p in &a.positions {
            let d: f32 = (0..3).map(|k| (p[k] - apex[k]) * apex[k]).sum();
            m.positions
                .push(std::array::from_fn(|k| p[k] - 2.0 * d * apex[k]));
        }
        let map = |v: u32| if v == 0 { 0 } else { v + n };
        m.triangles.extend(
            a.triangles
                .iter()
                .map(|t| [map(t[0]), map(t[2]), map(t[1])]),
        );
        m = vitrine_samples::compact(m);
        assert!(check_manifold(&m).is_err());
        assert_repairs_and_round_trips(m, true);

        // A fin: a fourth vertex off an edge of the sphere, making a third face on it.
        let mut m = icosphere(2);
        let [x, y, _] = m.triangles[0];
        m.positions.push([3.0, 3.0, 3.0]);
        m.triangles.push([x, y, m.positions.len() as u32 - 1]);
        assert!(check_manifold(&m).is_err());
        assert_repairs_and_round_trips(m, true);

        // Three cones (open, 8 sides each) sharing one apex vertex.
        let mut m = IndexedMesh {
            positions: vec![[0.0; 3]],
            colors: None,
            triangles: Vec::new(),
        };
        for c in 0..3u32 {
            let base = m.positions.len() as u32;
            let axis = c as f32 * 2.1;
            for i in 0..8u32 {
                let a = i as f32 / 8.0 * std::f32::consts::TAU;
                m.positions.push([
                    axis.cos() + 0.3 * a.cos(),
                    axis.sin() + 0.3 * a.sin(),
                    0.5 + 0.1 * c as f32,
                ]);
            }
            for i in 0..8u32 {
                m.triangles.push([0, base + i, base + (i + 1) % 8]);
            }
        }
        assert!(check_manifold(&m).is_err());
        assert_repairs_and_round_trips(m, true);
    }
}
