//! Mesh → progressive stream.

mod coding;
mod conquest;
mod locality;

use crate::base_mesh::{self, BaseMesh};
use crate::format::{
    write_section, write_varint, ChunkHeader, Header, LevelInfo, BASE_TAG, BATCH_TAG,
    NESTED_VERSION, VERSION,
};
use crate::halfedge::{check_indices, connectivity, Connectivity};
use crate::patch::MAX_VALENCE;
use crate::quantize::Quantization;
use crate::{Error, IndexedMesh, Result};
use coding::{PassOutput, PassSink};
use conquest::{PassKind, Simplifier};
use locality::LocalityOrder;

/// Below this fraction of valence-3 vertices a layer skips its cleaning conquest.
const CLEANING_MIN_FRACTION: f64 = 0.1;

/// How small the base mesh should get.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BaseTarget {
    /// Stop once the mesh has at most this many vertices.
    Vertices(u32),
    /// Stop once the mesh has at most this fraction of the input's vertices.
    Fraction(f32),
}

/// Encoder settings; `EncodeOptions::default()` suits museum scans.
#[derive(Clone, Debug, PartialEq)]
pub struct EncodeOptions {
    /// Position quantization, 8–16 bits on the bounding cube.
    pub quantization_bits: u8,
    pub base: BaseTarget,
    /// Never fewer base vertices than this, whatever `base` says.
    pub min_base_vertices: u32,
    /// Never more layers than this. 64 stopped a 20 M-vertex upsampled scan
    /// at a base of 346,498 vertices (its noisy layers remove 2–5 % each),
    /// past a tablet's budget with the refinement; `min_layer_fraction`
    /// and `base` end every shared scan sooner than either bound.
    pub max_layers: u32,
    /// Stop when a layer removes less than this fraction of the vertices.
    pub min_layer_fraction: f32,
    /// Refuse retriangulations whose new faces fold against the patch
    /// (costs a little connectivity, keeps low levels clean).
    pub geometric_guard: bool,
    /// Code each pass on a second thread while simplification goes on (the
    /// same bytes either way; about 40 % of the work moves off the main
    /// thread, for up to a second mesh's worth of memory).
    pub pipelined: bool,
    /// Cut the stream into charts whose batches decode in parallel (format 5).
    pub charts: Charts,
}

/// Whether a stream is cut into charts (format 5, `charts` module).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Charts {
    /// A plain stream (format 4): every batch refines the whole mesh.
    #[default]
    Off,
    /// One chart per [`Charts::AUTO_VERTICES`] input vertices, rounded
    /// down to a power of two, at most [`Charts::AUTO_MAX`]: a plain stream
    /// below 100,000 vertices, 2 charts below 200,000, else 4.
    Auto,
    /// One chart per this many input vertices, at most 64; a plain stream
    /// when that makes fewer than two.
    PerVertices(u32),
    /// This many charts (2..=64, fewer when the mesh has fewer faces).
    Count(u32),
    /// Nested charts (format 6): a tree of charts whose shape follows the
    /// mesh's size ([`crate::NestedShape::for_vertices`]), so that the
    /// bytes before any chart's own part are a small global mesh.
    Nested,
    /// Nested charts of a given shape: `top` charts (2..=64), each split
    /// into `fanout` children (1..=64) at each of `phases − 1` splits.
    NestedShape { top: u8, fanout: u8, phases: u8 },
}

impl Charts {
    /// Vertices per chart under [`Charts::Auto`].
    pub const AUTO_VERTICES: u32 = 50_000;
    /// The most charts [`Charts::Auto`] makes: every chart costs bytes (its
    /// parts restart their coders' models, its cut stays out of the fine
    /// layers). igea upsampled to 2.1 M vertices: +1.3 % over format 4 at
    /// 4 charts, +1.4 % at 5, +2.0 % at 8 (BENCHMARKS.md, "Charts"). A
    /// power of two, so that pools of 2 and 4 decoders (web/src/decode-pool.js)
    /// share the charts evenly: at 5 charts two decoders split 3 : 2.
    pub const AUTO_MAX: usize = 4;

    /// How many charts a mesh of `vertices` vertices gets (below 2: none).
    pub fn count(self, vertices: usize) -> usize {
        match self {
            Charts::Off => 1,
            Charts::Auto => {
                let k = (vertices / Self::AUTO_VERTICES as usize).min(Self::AUTO_MAX);
                if k < 2 {
                    k
                } else {
                    1 << k.ilog2()
                }
            }
            Charts::PerVertices(per) => {
                (vertices / per.max(1) as usize).min(crate::charts::MAX_CHARTS)
            }
            Charts::Count(k) => (k as usize).min(crate::charts::MAX_CHARTS),
            // Not flat charts: [`Charts::Nested`] has its own shape.
            Charts::Nested | Charts::NestedShape { .. } => 1,
        }
    }
}

impl Default for EncodeOptions {
    fn default() -> Self {
        EncodeOptions {
            quantization_bits: 12,
            base: BaseTarget::Fraction(0.01),
            min_base_vertices: 64,
            max_layers: 128,
            min_layer_fraction: 0.02,
            geometric_guard: true,
            pipelined: true,
            charts: Charts::Off,
        }
    }
}

/// Progress reported after every layer.
#[derive(Clone, Copy, Debug)]
pub struct EncodeProgress {
    pub layer: u32,
    pub vertices: usize,
    pub input_vertices: usize,
}

/// An encoded stream and how its vertices map back to the input.
#[derive(Clone, Debug)]
pub struct Encoded {
    pub bytes: Vec<u8>,
    /// Decoded vertex `i` (at the final level) is input vertex `vertex_order[i]`.
    pub vertex_order: Vec<u32>,
    pub header: Header,
}

pub(crate) struct Layer {
    pub decimating: PassOutput,
    pub cleaning: PassOutput,
}

/// Encodes a manifold mesh (see `vitrine_mesh::repair::prepare`) with no
/// guard and no progress report: `Encoder::new(options.clone()).encode(mesh)`.
pub fn encode(mesh: &IndexedMesh, options: &EncodeOptions) -> Result<Encoded> {
    Encoder::new(options.clone()).encode(mesh)
}

/// One way to encode: options, the guards every decimation must pass, and
/// a progress callback.
///
/// ```
/// use vitrine_codec::{EncodeOptions, Encoder, IndexedMesh};
/// # fn demo(mesh: &IndexedMesh, guard: &dyn vitrine_codec::PatchGuard) -> vitrine_codec::Result<()> {
/// let encoded = Encoder::new(EncodeOptions::default())
///     .guard(guard)
///     .progress(|p| eprintln!("layer {}: {} vertices", p.layer, p.vertices))
///     .encode(mesh)?;
/// # let _ = encoded; Ok(()) }
/// ```
pub struct Encoder<'a> {
    options: EncodeOptions,
    guards: Vec<&'a dyn PatchGuard>,
    progress: Box<dyn FnMut(EncodeProgress) + 'a>,
}

impl<'a> Encoder<'a> {
    pub fn new(options: EncodeOptions) -> Self {
        Encoder {
            options,
            guards: Vec::new(),
            progress: Box::new(|_| {}),
        }
    }

    pub fn options(&self) -> &EncodeOptions {
        &self.options
    }

    /// Adds a decimation guard. Guards compose: a patch is decimated only
    /// when every guard allows it.
    pub fn guard(mut self, guard: &'a dyn PatchGuard) -> Self {
        self.guards.push(guard);
        self
    }

    /// Called after every layer.
    pub fn progress(mut self, progress: impl FnMut(EncodeProgress) + 'a) -> Self {
        self.progress = Box::new(progress);
        self
    }

    pub fn encode(self, mesh: &IndexedMesh) -> Result<Encoded> {
        let every = EveryGuard(&self.guards);
        // No guard at all skips the per-patch call; one guard is asked directly.
        let guard: Option<&dyn PatchGuard> = match self.guards.as_slice() {
            [] => None,
            [only] => Some(*only),
            _ => Some(&every),
        };
        encode_guarded(mesh, &self.options, guard, self.progress)
    }
}

/// Several guards as one: every guard must allow the patch.
struct EveryGuard<'g, 'a>(&'g [&'a dyn PatchGuard]);

impl PatchGuard for EveryGuard<'_, '_> {
    fn allows(&self, patch: &CandidatePatch<'_>) -> bool {
        self.0.iter().all(|g| g.allows(patch))
    }

    fn uses_mean_face_area(&self) -> bool {
        self.0.iter().any(|g| g.uses_mean_face_area())
    }
}

/// A caller's veto on decimating a patch: when it refuses, the vertex stays
/// (a null patch) and the stream records nothing more, so decoders need not
/// know the guard. Deterministic guards keep encoding deterministic.
pub trait PatchGuard: Sync {
    fn allows(&self, patch: &CandidatePatch<'_>) -> bool;

    /// Whether [`CandidatePatch::mean_face_area`] matters to this guard: it
    /// costs a sweep over the mesh per pass, so it is 0 unless asked for.
    fn uses_mean_face_area(&self) -> bool {
        false
    }
}

/// A patch the encoder is about to decimate, in quantized coordinates.
#[derive(Clone, Debug)]
pub struct CandidatePatch<'a> {
    /// The vertex that would be removed.
    pub centre: [i32; 3],
    pub centre_colour: Option<[u8; 3]>,
    pub valence: usize,
    /// Its neighbours, counter-clockwise; the first `valence` are meaningful.
    pub polygon: [[i32; 3]; MAX_VALENCE],
    pub polygon_colours: [[u8; 3]; MAX_VALENCE],
    /// The retriangulation, `valence − 2` counter-clockwise triangles of polygon indices.
    pub triangles: &'a [[u8; 3]],
    /// Mean face area of the current level (quantization units squared);
    /// 0 unless the guard [asks for it](PatchGuard::uses_mean_face_area).
    pub mean_face_area: f64,
}

fn encode_guarded(
    mesh: &IndexedMesh,
    options: &EncodeOptions,
    guard: Option<&dyn PatchGuard>,
    progress: impl FnMut(EncodeProgress),
) -> Result<Encoded> {
    if mesh.triangles.is_empty() {
        return Err(Error::input("mesh", "no triangles"));
    }
    if let Some(c) = &mesh.colors {
        if c.len() != mesh.positions.len() {
            return Err(Error::Parameter(
                "colour count differs from vertex count".into(),
            ));
        }
    }
    if mesh.positions.len() >= u32::MAX as usize / 2 {
        return Err(Error::Limit("more than 2^31 vertices".into()));
    }
    let quantization = Quantization::for_positions(&mesh.positions, options.quantization_bits)?;
    let positions: Vec<[i32; 3]> = mesh
        .positions
        .iter()
        .map(|&p| quantization.quantize(p))
        .collect();
    check_indices(mesh.positions.len(), &mesh.triangles)?;
    let target = match options.base {
        BaseTarget::Vertices(n) => n as usize,
        BaseTarget::Fraction(f) => (mesh.positions.len() as f64 * f as f64) as usize,
    }
    .max(options.min_base_vertices as usize);
    let shape = match options.charts {
        Charts::Nested => Some(crate::charts::nested::Shape::for_vertices(
            mesh.positions.len(),
        )),
        Charts::NestedShape {
            top,
            fanout,
            phases,
        } => Some(crate::charts::nested::Shape::new(
            top.into(),
            fanout.into(),
            phases.into(),
        )?),
        _ => None,
    };
    if let Some(shape) = shape {
        let nested = crate::charts::nested::encode_nested(
            &positions,
            &mesh.triangles,
            mesh.colors.as_deref(),
            quantization,
            options,
            shape,
            target,
            guard,
            |e| connectivity(mesh).err().unwrap_or(e),
        )?;
        if let Some(encoded) = nested {
            return Ok(encoded);
        }
        return plain(
            mesh,
            &positions,
            quantization,
            options,
            target,
            guard,
            progress,
        );
    }
    let charts = options.charts.count(mesh.positions.len());
    if charts >= 2 {
        let charted = crate::charts::encode::encode_charted(
            &positions,
            &mesh.triangles,
            mesh.colors.as_deref(),
            quantization,
            options,
            charts,
            target,
            guard,
            |e| connectivity(mesh).err().unwrap_or(e),
            progress,
        )?;
        return match charted {
            Some(encoded) => Ok(encoded),
            None => plain(
                mesh,
                &positions,
                quantization,
                options,
                target,
                guard,
                |_| {},
            ),
        };
    }
    plain(
        mesh,
        &positions,
        quantization,
        options,
        target,
        guard,
        progress,
    )
}

fn plain(
    mesh: &IndexedMesh,
    positions: &[[i32; 3]],
    quantization: Quantization,
    options: &EncodeOptions,
    target: usize,
    guard: Option<&dyn PatchGuard>,
    progress: impl FnMut(EncodeProgress),
) -> Result<Encoded> {
    let (s, coded) = simplify(
        QuantizedMesh {
            positions,
            triangles: &mesh.triangles,
            colours: mesh.colors.as_deref(),
            max_value: quantization.max_value(),
        },
        Vec::new(),
        options,
        target,
        guard,
        // Name the culprit in the caller's vertex ids: the input's own order.
        |e| connectivity(mesh).err().unwrap_or(e),
        progress,
    )?;
    Ok(write_stream(
        &s,
        &coded,
        quantization,
        positions,
        mesh.colors.as_deref(),
    ))
}

/// A mesh already quantized and checked (every corner indexes a vertex).
pub(crate) struct QuantizedMesh<'m> {
    pub positions: &'m [[i32; 3]],
    pub triangles: &'m [[u32; 3]],
    pub colours: Option<&'m [[u8; 3]]>,
    pub max_value: i32,
}

/// Simplifies `mesh` layer by layer down to `target` vertices and codes
/// every pass: the coarse mesh left, and its layers finest first.
/// `culprit` rewrites a connectivity error in the caller's terms.
pub(crate) fn simplify<'g>(
    mesh: QuantizedMesh<'_>,
    cut: Vec<bool>,
    options: &EncodeOptions,
    target: usize,
    guard: Option<&'g dyn PatchGuard>,
    culprit: impl FnOnce(Error) -> Error,
    mut progress: impl FnMut(EncodeProgress),
) -> Result<(Simplifier<'g>, Vec<Layer>)> {
    let input_vertices = mesh.positions.len();
    let mut order = LocalityOrder::of(mesh.positions, mesh.triangles, mesh.max_value);
    // Renumbered from checked faces: every corner indexes a vertex.
    let conn = match Connectivity::from_indexed_triangles(input_vertices, &order.triangles) {
        Ok(conn) => conn,
        Err(e) => return Err(culprit(e)),
    };
    // The connectivity holds the faces now; a scan's worth of memory back.
    order.triangles = Vec::new();
    if conn.out.contains(&crate::halfedge::NONE) {
        return Err(Error::Unsupported(
            "mesh has vertices no face uses (run repair first)".into(),
        ));
    }
    let local_positions = order.permute(mesh.positions);
    let local_colours = mesh.colours.map(|c| order.permute(c));
    let mut s = Simplifier::new(
        conn,
        order.vertices,
        local_positions,
        local_colours,
        options.geometric_guard,
        guard,
    );
    s.cut = cut;
    let mut layers = Vec::new();
    let outputs = std::thread::scope(|scope| -> Result<Vec<PassOutput>> {
        let mut sink = PassSink::start(scope, options.pipelined);
        while s.live_vertices > target && layers.len() < options.max_layers as usize {
            let before = s.live_vertices;
            let decimating = s.run_pass(PassKind::Decimating);
            if !sink.send(s.coarse_mesh(), decimating)? {
                break;
            }
            // A cleaning traversal costs a code per face; skip it when few
            // valence-3 vertices exist to be removed (common on irregular scans).
            let cleaning = (s.valence_three_vertices() as f64)
                >= CLEANING_MIN_FRACTION * s.live_vertices as f64;
            if cleaning {
                let record = s.run_pass(PassKind::Cleaning);
                if !sink.send(s.coarse_mesh(), record)? {
                    break;
                }
            }
            let removed = before - s.live_vertices;
            if removed == 0 {
                // Coded, but not kept: pairing below stops at the last layer.
                break;
            }
            layers.push(cleaning);
            s.compact();
            progress(EncodeProgress {
                layer: layers.len() as u32,
                vertices: s.live_vertices,
                input_vertices,
            });
            if (removed as f64) < before as f64 * options.min_layer_fraction as f64 {
                break;
            }
        }
        sink.finish()
    })?;
    // Pair the coded passes back into layers (a layer without a cleaning pass gets an empty one).
    let mut outputs = outputs.into_iter();
    let mut next = || {
        outputs
            .next()
            .ok_or_else(|| Error::Unsupported("internal error: a pass was not coded".into()))
    };
    let coded = layers
        .iter()
        .map(|&cleaning| {
            Ok(Layer {
                decimating: next()?,
                cleaning: if cleaning {
                    next()?
                } else {
                    PassOutput::empty()
                },
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((s, coded))
}

pub(crate) fn write_stream(
    s: &Simplifier,
    layers: &[Layer],
    quantization: Quantization,
    quantized: &[[i32; 3]],
    colours: Option<&[[u8; 3]]>,
) -> Encoded {
    let plain = plain_chunks(s, layers, quantization, quantized, colours, VERSION);
    let header = Header {
        version: VERSION,
        has_colour: colours.is_some(),
        quantization,
        levels: plain.levels,
    };
    let mut bytes = Vec::new();
    header.write(&mut bytes);
    bytes.extend_from_slice(&plain.chunks);
    Encoded {
        bytes,
        vertex_order: plain.vertex_order,
        header,
    }
}

/// A simplification written as a base chunk and one batch chunk per layer,
/// without the stream's header.
pub(crate) struct PlainChunks {
    /// The level each chunk makes, the base first.
    pub levels: Vec<LevelInfo>,
    /// The chunks, back to back.
    pub chunks: Vec<u8>,
    /// Final vertex `i` is input vertex `vertex_order[i]`.
    pub vertex_order: Vec<u32>,
    /// Every input vertex's final id.
    pub new_id: Vec<u32>,
}

/// Writes `s`'s coarse mesh as the base chunk and `layers` as batches, in
/// chunks of stream version `version`; `quantized` and `colours` are the
/// simplification's input.
pub(crate) fn plain_chunks(
    s: &Simplifier,
    layers: &[Layer],
    quantization: Quantization,
    quantized: &[[i32; 3]],
    colours: Option<&[[u8; 3]]>,
    version: u8,
) -> PlainChunks {
    let input_vertices = quantized.len();
    // Final numbering: base vertices by first appearance, then each batch's
    // vertices in insertion order (coarsest layer first, cleaning before decimation).
    let walk = base_mesh::face_walk(&s.conn);
    let base_triangles: Vec<[u32; 3]> = walk
        .triangles
        .iter()
        .map(|t| t.map(|v| s.ids[v as usize]))
        .collect();
    let mut vertex_order = base_mesh::first_appearance_order(input_vertices, &base_triangles);
    let base_vertices = vertex_order.len();
    let new_id = number_layers(&mut vertex_order, layers, input_vertices);
    let base = BaseMesh {
        positions: vertex_order[..base_vertices]
            .iter()
            .map(|&v| quantized[v as usize])
            .collect(),
        colours: colours.map(|c| {
            vertex_order[..base_vertices]
                .iter()
                .map(|&v| c[v as usize])
                .collect()
        }),
        triangles: base_triangles
            .iter()
            .map(|t| t.map(|v| new_id[v as usize]))
            .collect(),
    };
    let base_payload = base_mesh::encode(&base, &walk.pushed, quantization.max_value());
    let mut chunks = Vec::new();
    ChunkHeader {
        tag: BASE_TAG,
        version,
        level: 0,
        vertices_before: 0,
        vertices_after: base_vertices as u32,
        faces_after: base.triangles.len() as u32,
        payload_len: base_payload.len() as u32,
    }
    .write(&mut chunks);
    chunks.extend_from_slice(&base_payload);
    let mut levels = vec![LevelInfo {
        vertices: base_vertices as u32,
        faces: base.triangles.len() as u32,
        bytes: chunks.len() as u32,
    }];
    let batches = batch_chunks(
        layers,
        &new_id,
        base_vertices,
        base.triangles.len(),
        version,
    );
    for (level, chunk) in batches {
        levels.push(level);
        chunks.extend_from_slice(&chunk);
    }
    PlainChunks {
        levels,
        chunks,
        vertex_order,
        new_id,
    }
}

/// Appends each layer's removed vertices to `vertex_order` (which holds the
/// base vertices) in insertion order, coarsest layer first and cleaning
/// before decimation, and returns every input vertex's final id.
pub(crate) fn number_layers(
    vertex_order: &mut Vec<u32>,
    layers: &[Layer],
    input_vertices: usize,
) -> Vec<u32> {
    for layer in layers.iter().rev() {
        vertex_order.extend_from_slice(&layer.cleaning.removed);
        vertex_order.extend_from_slice(&layer.decimating.removed);
    }
    let mut new_id = vec![u32::MAX; input_vertices];
    for (new, &old) in vertex_order.iter().enumerate() {
        new_id[old as usize] = new as u32;
    }
    new_id
}

/// One batch chunk per layer, coarsest first, with the level each makes;
/// `new_id` gives every input vertex its final id.
pub(crate) fn batch_chunks(
    layers: &[Layer],
    new_id: &[u32],
    base_vertices: usize,
    base_faces: usize,
    version: u8,
) -> Vec<(LevelInfo, Vec<u8>)> {
    let mut batches = Vec::new();
    let mut vertices = base_vertices;
    let mut faces = base_faces;
    for (i, layer) in layers.iter().rev().enumerate() {
        let mut payload = Vec::new();
        if version >= NESTED_VERSION {
            // The tangential step exponent: 0, exact (FORMAT.md, "Deferred precision").
            payload.push(0);
        }
        write_pass(&mut payload, &layer.cleaning, new_id);
        write_pass(&mut payload, &layer.decimating, new_id);
        let added = layer.cleaning.removed.len() + layer.decimating.removed.len();
        let mut chunk = Vec::new();
        ChunkHeader {
            tag: BATCH_TAG,
            version,
            level: (i + 1) as u16,
            vertices_before: vertices as u32,
            vertices_after: (vertices + added) as u32,
            faces_after: (faces + 2 * added) as u32,
            payload_len: payload.len() as u32,
        }
        .write(&mut chunk);
        chunk.extend_from_slice(&payload);
        vertices += added;
        faces += 2 * added;
        let level = LevelInfo {
            vertices: vertices as u32,
            faces: faces as u32,
            bytes: chunk.len() as u32,
        };
        batches.push((level, chunk));
    }
    batches
}

pub(crate) fn write_pass(out: &mut Vec<u8>, pass: &PassOutput, new_id: &[u32]) {
    write_varint(out, pass.seeds.len() as u32);
    for seed in &pass.seeds {
        write_varint(out, new_id[seed[0] as usize]);
        write_varint(out, new_id[seed[1] as usize]);
    }
    write_varint(out, pass.removed.len() as u32);
    write_section(out, &pass.connectivity);
    write_section(out, &pass.geometry);
    write_section(out, &pass.colour);
}
