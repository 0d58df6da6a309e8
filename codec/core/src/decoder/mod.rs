//! Progressive stream → mesh, one refinement batch at a time.

mod charted;
mod conquest;
mod nested_view;
mod view;

use crate::base_mesh;
use crate::charts::nested::MAX_PHASE_CHARTS;
use crate::charts::MAX_CHARTS;
use crate::format::{
    ChunkHeader, Header, LevelInfo, Reader, BASE_TAG, BATCH_TAG, CHARTED_VERSION, NESTED_VERSION,
    PARTED_TAG,
};
use crate::gates::{GateStatistics, PassKind};
use crate::halfedge::Connectivity;
use crate::quantize::Quantization;
use crate::room::{self, Growth};
use crate::{Error, IndexedMesh, Result};
pub use charted::ChartLevel;
use charted::{read_part, Charted, Labelled};
use conquest::{PassInput, Scratch};
pub use nested_view::NestedView;
pub use view::ChartView;

/// Budget a decoder enforces before it allocates or grows anything.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    pub max_vertices: u32,
    pub max_faces: u32,
    pub max_batches: u32,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_vertices: 50_000_000,
            max_faces: 100_000_000,
            max_batches: 1024,
        }
    }
}

/// The mesh at the current level, kept as GPU-ready buffers.
#[derive(Clone)]
pub(crate) struct Level {
    pub conn: Connectivity,
    pub quantization: Quantization,
    pub positions_q: Vec<[i32; 3]>,
    pub positions: Vec<[f32; 3]>,
    pub colours: Option<Vec<[u8; 3]>>,
}

impl Level {
    pub(crate) fn vertex_count(&self) -> usize {
        self.positions_q.len()
    }

    /// Room for `grow` more vertices and their faces (two each, six
    /// half-edges), and in `scratch` for a level that size, reserved toward
    /// the size `growth` expects (see [`room`]).
    fn make_room(&mut self, grow: usize, growth: Growth, scratch: &mut Scratch) {
        let n = self.vertex_count();
        let (needed, target) = growth.room(n, grow);
        self.reserve_vertices(needed, target);
        scratch.make_room(needed, target);
        let h = self.conn.origin.len();
        let (needed, target) = (h + 6 * (needed - n), h + 6 * (target - n));
        room::reserve(&mut self.conn.origin, needed, target);
        room::reserve(&mut self.conn.twin, needed, target);
    }

    /// Room for `needed` vertices' positions and colours (`target` if they move).
    fn reserve_vertices(&mut self, needed: usize, target: usize) {
        room::reserve(&mut self.positions_q, needed, target);
        room::reserve(&mut self.positions, needed, target);
        room::reserve(&mut self.conn.out, needed, target);
        if let Some(colours) = &mut self.colours {
            room::reserve(colours, needed, target);
        }
    }

    /// Position and colour of the next vertex whose fan is already in
    /// `conn` (inserted during the traversal).
    pub(crate) fn push_vertex(&mut self, q: [i32; 3], colour: Option<[u8; 3]>) {
        self.positions_q.push(q);
        self.positions.push(self.quantization.dequantize(q));
        if let (Some(colours), Some(c)) = (&mut self.colours, colour) {
            colours.push(c);
        }
    }
}

/// Decodes a stream level by level.
///
/// ```
/// # fn demo(stream: &[u8]) -> vitrine_codec::Result<()> {
/// use vitrine_codec::{Decoder, Limits, StreamIndex};
/// let index = StreamIndex::parse(stream)?;
/// let mut decoder = Decoder::new(&stream[index.base.clone()], Limits::default())?;
/// for batch in &index.batches {
///     decoder.apply_batch(&stream[batch.clone()])?;
///     let (_positions, _indices) = (decoder.positions(), decoder.indices());
/// }
/// # Ok(()) }
/// ```
/// After an error the decoder's buffers are unspecified: drop it. (A batch
/// refused before it touched the level, for its header or counts, leaves
/// the decoder as it was; one that fails part-way makes every later batch
/// an error.)
pub struct Decoder {
    header: Header,
    level: Level,
    applied: usize,
    limits: Limits,
    scratch: Scratch,
    /// A batch failed after it began to change the level.
    broken: bool,
    /// A charted stream's charts, once its first parted batch cut them.
    charted: Option<Charted>,
    threads: usize,
    /// The charts this decoder refines, bit c for chart c (all by default).
    refined: u64,
    /// The first parted batch's labels, decoded by `chart_sizes` for the cut.
    labelled: Option<Labelled>,
}

impl Decoder {
    /// `prefix` is the header followed by the base chunk.
    pub fn new(prefix: &[u8], limits: Limits) -> Result<Decoder> {
        let header = Header::parse(prefix)?;
        if header.batch_count() > limits.max_batches as usize {
            return Err(Error::Limit(format!(
                "{} batches exceed the limit of {}",
                header.batch_count(),
                limits.max_batches
            )));
        }
        let last = header.final_level();
        if last.vertices > limits.max_vertices || last.faces > limits.max_faces {
            return Err(Error::Limit(format!(
                "stream has {} vertices and {} faces, limits are {} and {}",
                last.vertices, last.faces, limits.max_vertices, limits.max_faces
            )));
        }
        let (chunk, payload) = ChunkHeader::parse(&prefix[header.byte_len()..], &[BASE_TAG])?;
        if chunk.version != header.version {
            return Err(version_mismatch(chunk.version, header.version));
        }
        let base = header.levels[0];
        if chunk.vertices_after != base.vertices || chunk.faces_after != base.faces {
            return Err(Error::stream("base chunk disagrees with the level table"));
        }
        let q = header.quantization;
        let mesh = base_mesh::decode(
            payload,
            base.vertices,
            base.faces,
            header.has_colour,
            q.max_value(),
        )?;
        let conn = Connectivity::from_triangles(mesh.positions.len(), &mesh.triangles)
            .map_err(|e| Error::stream(format!("base mesh is not a manifold: {e}")))?;
        let positions = mesh.positions.iter().map(|&p| q.dequantize(p)).collect();
        let level = Level {
            conn,
            quantization: q,
            positions_q: mesh.positions,
            positions,
            colours: mesh.colours,
        };
        Ok(Decoder {
            header,
            level,
            applied: 0,
            limits,
            scratch: Scratch::default(),
            broken: false,
            charted: None,
            threads: 1,
            refined: u64::MAX,
            labelled: None,
        })
    }

    /// Counts the connectivity codes of the batches applied from now on.
    pub(crate) fn collect_gate_statistics(&mut self, statistics: Box<GateStatistics>) {
        self.scratch.traversal.statistics = Some(statistics);
    }

    pub(crate) fn take_gate_statistics(&mut self) -> Option<Box<GateStatistics>> {
        self.scratch.traversal.statistics.take()
    }

    /// Starts (`Some`) or stops (`None`) measuring where the bits go;
    /// returns the meter that was running.
    pub(crate) fn meter(
        &mut self,
        meter: Option<Box<crate::meter::Meter>>,
    ) -> Option<Box<crate::meter::Meter>> {
        std::mem::replace(&mut self.scratch.meter, meter)
    }

    /// The level's connectivity and quantized positions (for the meter).
    pub(crate) fn connectivity_and_positions(&self) -> (&Connectivity, &[[i32; 3]]) {
        (&self.level.conn, &self.level.positions_q)
    }

    /// The batch the meter attributes the next passes to.
    pub(crate) fn meter_batch(&mut self, batch: u32) {
        if let Some(m) = self.scratch.meter.as_mut() {
            m.batch = batch;
        }
    }

    pub fn header(&self) -> &Header {
        &self.header
    }

    /// Number of batches applied so far (0 = base mesh).
    pub fn level(&self) -> usize {
        self.applied
    }

    pub fn is_complete(&self) -> bool {
        self.applied == self.header.batch_count()
    }

    /// Applies the next refinement batch (a chunk as listed by [`crate::StreamIndex`]).
    pub fn apply_batch(&mut self, chunk_bytes: &[u8]) -> Result<()> {
        if self.broken {
            return Err(Error::stream(
                "an earlier batch failed part-way: decode again from the base",
            ));
        }
        let (chunk, payload) = ChunkHeader::parse(chunk_bytes, &[BATCH_TAG, PARTED_TAG])?;
        if chunk.version != self.header.version {
            return Err(version_mismatch(chunk.version, self.header.version));
        }
        let parted = chunk.tag == PARTED_TAG;
        if parted && self.header.version < CHARTED_VERSION {
            return Err(Error::stream(format!(
                "a parted batch in a version {} stream",
                self.header.version
            )));
        }
        if !parted && self.charted.is_some() {
            return Err(Error::stream("a whole-mesh batch after parted ones"));
        }
        let expected = self.applied + 1;
        if chunk.level as usize != expected || expected > self.header.batch_count() {
            return Err(Error::stream(format!(
                "batch for level {} applied at level {}",
                chunk.level, self.applied
            )));
        }
        let info = self.header.levels[expected];
        let (n, faces_now) = self.level_counts();
        if chunk.vertices_before as usize != n
            || chunk.vertices_after != info.vertices
            || chunk.faces_after != info.faces
        {
            return Err(Error::stream("batch counts disagree with the level table"));
        }
        if info.vertices > self.limits.max_vertices || info.faces > self.limits.max_faces {
            return Err(Error::Limit(
                "batch exceeds the vertex or face limit".into(),
            ));
        }
        if parted {
            return self.apply_parted(payload, info, (n, faces_now), expected);
        }
        let mut r = Reader::new(payload);
        if self.header.version >= NESTED_VERSION {
            read_precision(&mut r)?;
        }
        let cleaning = read_pass(&mut r, PassKind::Cleaning)?;
        let decimating = read_pass(&mut r, PassKind::Decimating)?;
        if r.remaining() != 0 {
            return Err(Error::stream("trailing bytes after the batch's passes"));
        }
        let added = cleaning.inserted as u64 + decimating.inserted as u64;
        if added != (info.vertices as usize - n) as u64 {
            return Err(Error::stream(
                "passes insert a different number of vertices than the batch",
            ));
        }
        // Each inserted vertex adds exactly two faces (AD01 patches are discs).
        if info.faces as u64 != faces_now as u64 + 2 * added {
            return Err(Error::stream(
                "level table's face count disagrees with the batch",
            ));
        }
        // Reserve no more than the payload could possibly describe (a bit per vertex).
        let grow = (added as usize).min(payload.len().saturating_mul(8));
        self.level
            .make_room(grow, self.growth(n), &mut self.scratch);
        let undone = self
            .level
            .undo_batch(&cleaning, &decimating, &mut self.scratch);
        if undone.is_err() {
            // Fans may be in without their vertices' positions: refuse
            // whatever comes next rather than walk a half-built level.
            self.broken = true;
        }
        undone?;
        self.applied = expected;
        Ok(())
    }

    /// Vertices and faces of the level applied last: the level table's once
    /// this decoder refines only some charts (it no longer holds the level).
    fn level_counts(&self) -> (usize, usize) {
        if self.refines_some() {
            let info = self.header.levels[self.applied];
            (info.vertices as usize, info.faces as usize)
        } else {
            (self.level.vertex_count(), self.face_count())
        }
    }

    /// How much the level of `now` vertices is expected to grow by the end
    /// of the stream (the header's claim, which [`room`] bounds).
    fn growth(&self, now: usize) -> Growth {
        Growth {
            now,
            last: self.header.final_level().vertices as usize,
        }
    }

    /// The charts are cut and this decoder leaves some of them to others.
    fn refines_some(&self) -> bool {
        self.header.version == CHARTED_VERSION
            && self
                .charted
                .as_ref()
                .is_some_and(|c| (0..c.chart_count()).any(|k| self.refined & (1 << k) == 0))
    }

    /// A parted batch (format 5): every chart's part, the charts cut first
    /// when this is the first such batch; its counts are checked already
    /// (`now`: the vertices and faces before it).
    fn apply_parted(
        &mut self,
        payload: &[u8],
        info: LevelInfo,
        now: (usize, usize),
        expected: usize,
    ) -> Result<()> {
        let mut r = Reader::new(payload);
        if self.header.version >= NESTED_VERSION {
            return self.apply_nested(r, info, now, expected);
        }
        let charts = read_chart_count(&mut r)?;
        let cut = match &self.charted {
            Some(c) if c.chart_count() != charts => {
                return Err(Error::stream("a parted batch changes the number of charts"))
            }
            Some(_) => None,
            None => Some(Charted::cut(
                &self.level,
                r.section()?,
                charts,
                self.labelled.take(),
            )?),
        };
        let mut parts = Vec::with_capacity(charts);
        for _ in 0..charts {
            parts.push(read_part(r.section()?)?);
        }
        if r.remaining() != 0 {
            return Err(Error::stream("trailing bytes after the batch's parts"));
        }
        let added: u64 = parts
            .iter()
            .flatten()
            .map(|(c, d, _)| c.inserted as u64 + d.inserted as u64)
            .sum();
        if added != (info.vertices as usize - now.0) as u64 {
            return Err(Error::stream(
                "parts insert a different number of vertices than the batch",
            ));
        }
        if info.faces as u64 != now.1 as u64 + 2 * added {
            return Err(Error::stream(
                "level table's face count disagrees with the batch",
            ));
        }
        if let Some(c) = cut {
            self.charted = Some(c);
            // The charts hold the connectivity from now on.
            self.level.conn = Connectivity {
                origin: Vec::new(),
                twin: Vec::new(),
                out: Vec::new(),
            };
        }
        let some = self.refines_some();
        let inserted: Vec<u64> = parts
            .iter()
            .map(|p| {
                p.as_ref()
                    .map_or(0, |(c, d, _)| c.inserted as u64 + d.inserted as u64)
            })
            .collect();
        if some {
            for (k, part) in parts.iter_mut().enumerate() {
                if self.refined & (1 << k) == 0 {
                    *part = None;
                }
            }
        }
        let growth = self.growth(now.0);
        let charted = self.charted.as_mut().expect("cut above");
        if let Err(e) = charted.apply(parts, growth, self.threads) {
            self.broken = true;
            return Err(e);
        }
        if some {
            charted.number_owned(now.0, &inserted, self.refined);
        } else {
            charted.merge(&mut self.level, growth);
        }
        self.applied = expected;
        Ok(())
    }

    /// A parted batch of a nested stream (format 6), `r` just past its
    /// chunk header: the phase's charts cut (phase 0) or split from the
    /// previous phase's when this batch begins a phase, then every chart's
    /// part; its counts are checked already (`now`: before it).
    fn apply_nested(
        &mut self,
        mut r: Reader,
        info: LevelInfo,
        now: (usize, usize),
        expected: usize,
    ) -> Result<()> {
        read_precision(&mut r)?;
        let phase = r.varint()? as usize;
        let charts = r.varint()? as usize;
        if !(1..=MAX_PHASE_CHARTS).contains(&charts) {
            return Err(Error::stream(format!("{charts} charts is out of range")));
        }
        let current = self.charted.as_ref().map(Charted::phase);
        let begins = match current {
            None if phase == 0 => true,
            Some(p) if p == phase => false,
            Some(p) if p + 1 == phase => true,
            _ => {
                return Err(Error::stream(format!(
                    "a parted batch of phase {phase} after phase {current:?}"
                )))
            }
        };
        if !begins && self.chart_count() != charts {
            return Err(Error::stream("a parted batch changes the number of charts"));
        }
        let head = if begins { Some(r.section()?) } else { None };
        let mut parts = Vec::with_capacity(charts.min(r.remaining()));
        for _ in 0..charts {
            parts.push(read_part(r.section()?)?);
        }
        if r.remaining() != 0 {
            return Err(Error::stream("trailing bytes after the batch's parts"));
        }
        let added: u64 = parts
            .iter()
            .flatten()
            .map(|(c, d, _)| c.inserted as u64 + d.inserted as u64)
            .sum();
        if added != (info.vertices as usize - now.0) as u64 {
            return Err(Error::stream(
                "parts insert a different number of vertices than the batch",
            ));
        }
        if info.faces as u64 != now.1 as u64 + 2 * added {
            return Err(Error::stream(
                "level table's face count disagrees with the batch",
            ));
        }
        match (head, &mut self.charted) {
            (Some(labels), None) => {
                let c = Charted::cut(&self.level, labels, charts, None)?;
                self.charted = Some(c);
                // The charts hold the connectivity from now on.
                self.level.conn = Connectivity {
                    origin: Vec::new(),
                    twin: Vec::new(),
                    out: Vec::new(),
                };
            }
            (Some(head), Some(c)) => {
                if let Err(e) = c.split(head, charts) {
                    self.broken = true;
                    return Err(e);
                }
            }
            (None, _) => {}
        }
        let growth = self.growth(now.0);
        let charted = self.charted.as_mut().expect("cut above");
        if let Err(e) = charted.apply(parts, growth, self.threads) {
            self.broken = true;
            return Err(e);
        }
        charted.merge(&mut self.level, growth);
        self.applied = expected;
        Ok(())
    }

    /// The faces of each chart that a charted stream's first parted batch
    /// (`chunk_bytes`, not applied yet) will cut this level into: how a
    /// pool shares the charts out before any member applies it. The level
    /// is not changed; the labels decoded are kept for the cut.
    pub fn chart_sizes(&mut self, chunk_bytes: &[u8]) -> Result<Vec<usize>> {
        if self.header.version != CHARTED_VERSION {
            return Err(nested_pool_refused(self.header.version));
        }
        if self.charted.is_some() {
            return Err(Error::stream("the charts are cut already"));
        }
        let (chunk, payload) = ChunkHeader::parse(chunk_bytes, &[PARTED_TAG])?;
        if chunk.version != self.header.version || chunk.level as usize != self.applied + 1 {
            return Err(Error::stream(
                "not the next batch of this stream, or not parted",
            ));
        }
        let mut r = Reader::new(payload);
        let charts = read_chart_count(&mut r)?;
        let labelled = Charted::labelled(&self.level, r.section()?, charts)?;
        let sizes = labelled.sizes();
        self.labelled = Some(labelled);
        Ok(sizes)
    }

    /// Makes this decoder one member of a pool that decodes a charted
    /// stream (format 5) together: from the next parted batch on it refines
    /// only the charts in `charts` (bit c for chart c), checking every
    /// part's counts but decoding only its own. Its level then stays as it
    /// is ([`Decoder::positions`], [`Decoder::indices`] and the counts stop
    /// changing); read its charts with [`Decoder::chart`] and merge them
    /// with the other members' as the full decoder does: each chart's new
    /// vertices appended in chart order, then every chart's triangles
    /// (`web/src/decode-pool.js`): [`ChartLevel::level_indices`] gives its
    /// charts' triangles in the level's ids already. [`Decoder::chart_sizes`]
    /// tells how big each chart will be before the first parted batch. Once
    /// it refines only some charts, the choice is final.
    pub fn refine_only(&mut self, charts: u64) -> Result<()> {
        if self.header.version != CHARTED_VERSION {
            return Err(nested_pool_refused(self.header.version));
        }
        if self.refines_some() {
            return Err(Error::stream(
                "this decoder refines some charts already: the choice is final",
            ));
        }
        self.refined = charts;
        Ok(())
    }

    /// Charts of a charted stream once its first parted batch is applied;
    /// 0 before, and for a plain stream.
    pub fn chart_count(&self) -> usize {
        self.charted.as_ref().map_or(0, Charted::chart_count)
    }

    /// Chart `chart` as this decoder holds it (refined by this decoder's
    /// parts, or where the cut left it when another member refines it).
    pub fn chart(&self, chart: usize) -> Option<ChartLevel<'_>> {
        self.charted.as_ref()?.chart(chart)
    }

    /// Decodes each parted batch's charts on up to `threads` threads (format
    /// 5 streams, native builds; WebAssembly decodes them in turn). The
    /// levels are the same bytes whatever the number. Default: 1.
    pub fn set_threads(&mut self, threads: usize) {
        self.threads = threads.max(1);
    }

    /// Positions as `x, y, z` per vertex, in model units.
    pub fn positions(&self) -> &[f32] {
        self.level.positions.as_flattened()
    }

    /// sRGB colours as `r, g, b` per vertex, when the stream has colour.
    pub fn colours(&self) -> Option<&[u8]> {
        self.level.colours.as_ref().map(|c| c.as_flattened())
    }

    /// Triangle list, three indices per face, counter-clockwise.
    pub fn indices(&self) -> &[u32] {
        match &self.charted {
            Some(c) => &c.indices,
            None => &self.level.conn.origin,
        }
    }

    /// Quantized positions: exactly the encoder's input at this quantization.
    pub fn quantized_positions(&self) -> &[[i32; 3]] {
        &self.level.positions_q
    }

    pub fn vertex_count(&self) -> usize {
        self.level.vertex_count()
    }

    pub fn face_count(&self) -> usize {
        self.indices().len() / 3
    }

    /// The current level as an indexed mesh (dequantized positions).
    pub fn to_mesh(&self) -> IndexedMesh {
        IndexedMesh {
            positions: self.level.positions.clone(),
            colors: self.level.colours.clone(),
            triangles: self
                .indices()
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
        }
    }
}

/// Why a pool member cannot take a share of a stream's charts: only
/// version 5's flat charts are shared out (a nested stream's, version 6,
/// are not yet; decode it on one worker).
fn nested_pool_refused(version: u8) -> Error {
    Error::stream(format!(
        "sharing charts among decoders needs a version {CHARTED_VERSION} stream, not version {version}: decode it on one worker"
    ))
}

/// A version 6 batch payload's first byte, the tangential step exponent
/// of deferred precision (FORMAT.md): this build decodes only 0, exact.
pub(crate) fn read_precision(r: &mut Reader) -> Result<()> {
    match r.u8()? {
        0 => Ok(()),
        e => Err(Error::stream(format!(
            "deferred precision is not decoded by this build (tangential step exponent {e})"
        ))),
    }
}

fn version_mismatch(chunk: u8, stream: u8) -> Error {
    Error::stream(format!(
        "chunk version mismatch: a version {chunk} chunk in a version {stream} stream"
    ))
}

/// A parted batch's payload begins with its number of charts.
pub(crate) fn read_chart_count(r: &mut Reader) -> Result<usize> {
    let charts = r.varint()? as usize;
    if !(2..=MAX_CHARTS).contains(&charts) {
        return Err(Error::stream(format!("{charts} charts is out of range")));
    }
    Ok(charts)
}

/// One pass of a batch or a chart's part: its seeds, its count and its
/// three sections (FORMAT.md).
pub(crate) fn read_pass<'a>(r: &mut Reader<'a>, kind: PassKind) -> Result<PassInput<'a>> {
    let count = r.varint()? as usize;
    // Each seed takes at least two bytes: never trust the count beyond that.
    if count > r.remaining() / 2 {
        return Err(Error::stream("pass declares more seeds than it has bytes"));
    }
    let mut seeds = Vec::with_capacity(count);
    for _ in 0..count {
        seeds.push([r.varint()?, r.varint()?]);
    }
    Ok(PassInput {
        kind,
        seeds,
        inserted: r.varint()?,
        connectivity: r.section()?,
        geometry: r.section()?,
        colour: r.section()?,
    })
}

/// Decodes a whole stream up to `max_level` batches (all when `None`).
pub fn decode(bytes: &[u8], max_level: Option<usize>, limits: Limits) -> Result<Decoder> {
    let index = crate::StreamIndex::parse(bytes)?;
    let mut decoder = Decoder::new(&bytes[index.base.clone()], limits)?;
    let n = max_level.unwrap_or(usize::MAX).min(index.batches.len());
    for range in &index.batches[..n] {
        decoder.apply_batch(&bytes[range.clone()])?;
    }
    Ok(decoder)
}
