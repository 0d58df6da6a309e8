//! `KHR_draco_mesh_compression`: primitives whose attributes and indices
//! are one Draco stream in a buffer view, decoded with `draco-core` (a
//! pure-Rust port of Google's decoder, with its own decode limits) before the
//! document is validated.
//!
//! The extension names the stream's view and, per attribute semantic, the
//! Draco attribute's unique id. Each decoded attribute is written as `f32`
//! (normalised integers divided as glTF says) and the indices as `u32` into a
//! buffer of their own; the primitive's accessors are pointed at them (an
//! accessor two Draco primitives share is refused), and everything after
//! reads them through the ordinary checked path. An attribute the stream does not carry keeps its own
//! accessor. The decoder itself checks the face count and the decoded
//! attribute bytes (which bound the point count) against the import limits
//! before it allocates.

use draco_core::{DecodeLimits, DecoderBuffer, Mesh, MeshDecoder};
use gltf::json::accessor::{ComponentType, GenericComponentType, Type};
use gltf::json::validation::Checked;
use gltf::json::{self, Value};

use super::buffers::Buffers;
use crate::import::ImportOptions;
use crate::{Error, Result};

const NAME: &str = "KHR_draco_mesh_compression";

/// Most decoded attribute bytes a file may produce, whatever its counts.
const MAX_DECODED_BYTES: u64 = 4 << 30;

/// Decodes every Draco-compressed primitive of `root`.
pub(super) fn decode_primitives(
    root: &mut json::Root,
    buffers: &mut Buffers<'_>,
    opts: &ImportOptions,
) -> Result<()> {
    let what = buffers.what;
    let mut rewritten = std::collections::HashSet::new();
    for m in 0..root.meshes.len() {
        for p in 0..root.meshes[m].primitives.len() {
            let Some(ext) = extension(&root.meshes[m].primitives[p]).cloned() else {
                continue;
            };
            let at = format!("mesh {m} primitive {p}: {NAME}");
            decode_primitive(root, buffers, opts, (m, p), &ext, &mut rewritten)
                .map_err(|e| Error::input(what, format!("{at}: {e}")))?;
            if let Some(ext) = root.meshes[m].primitives[p].extensions.as_mut() {
                ext.others.remove(NAME);
            }
        }
    }
    Ok(())
}

fn extension(prim: &json::mesh::Primitive) -> Option<&Value> {
    prim.extensions.as_ref()?.others.get(NAME)
}

fn decode_primitive(
    root: &mut json::Root,
    buffers: &mut Buffers<'_>,
    opts: &ImportOptions,
    (m, p): (usize, usize),
    ext: &Value,
    rewritten: &mut std::collections::HashSet<usize>,
) -> std::result::Result<(), String> {
    let view_index = ext
        .get("bufferView")
        .and_then(Value::as_u64)
        .and_then(|v| usize::try_from(v).ok())
        .ok_or("bufferView is missing or not an index")?;
    let view = root
        .buffer_views
        .get(view_index)
        .ok_or_else(|| format!("buffer view {view_index} does not exist"))?
        .clone();
    let buffer_index = view.buffer.value();
    let buffer = root
        .buffers
        .get(buffer_index)
        .ok_or_else(|| format!("buffer {buffer_index} does not exist"))?;
    buffers
        .load_json(buffer_index, buffer)
        .map_err(|e| e.to_string())?;
    let offset = view.byte_offset.map_or(0, |o| o.0);
    let stream = usize::try_from(offset)
        .ok()
        .and_then(|o| buffers.get(buffer_index).get(o..))
        .and_then(|rest| rest.get(..usize::try_from(view.byte_length.0).ok()?))
        .ok_or_else(|| format!("buffer view {view_index} runs past the end of its buffer"))?;

    let limits = DecodeLimits::default()
        .with_max_points(opts.max_vertices as u64)
        .with_max_faces(opts.max_faces as u64)
        // The point count of a mesh is only known once decoded: the bytes
        // of its attributes bound it (128 a point is more than any glTF
        // primitive's attribute set needs).
        .with_max_decoded_bytes(
            (opts.max_vertices as u64)
                .saturating_mul(128)
                .min(MAX_DECODED_BYTES),
        );
    let mut input = DecoderBuffer::new(stream).with_limits(limits);
    let mut mesh = Mesh::new();
    MeshDecoder::new()
        .decode(&mut input, &mut mesh)
        .map_err(|e| format!("the Draco stream does not decode: {e}"))?;
    let points = mesh.num_points();

    let ids = ext
        .get("attributes")
        .and_then(Value::as_object)
        .ok_or("attributes is missing")?;
    let mut out = Vec::<u8>::new();
    // (accessor, its decoded form), applied once everything decoded.
    let mut replaced = Vec::new();
    let semantics: Vec<_> = root.meshes[m].primitives[p]
        .attributes
        .iter()
        .map(|(s, a)| (s.clone(), a.value()))
        .collect();
    for (semantic, accessor_index) in semantics {
        let name = match &semantic {
            Checked::Valid(s) => s.to_string(),
            Checked::Invalid => continue,
        };
        let Some(id) = ids.get(&name) else {
            continue; // not in the stream: the accessor's own bytes
        };
        let id = id
            .as_u64()
            .and_then(|id| u32::try_from(id).ok())
            .ok_or_else(|| format!("attribute {name}'s id is not an integer"))?;
        let attribute = mesh.attribute_by_unique_id(id).ok_or_else(|| {
            format!("attribute {name} names Draco attribute {id}, which the stream lacks")
        })?;
        let accessor = root
            .accessors
            .get(accessor_index)
            .ok_or_else(|| format!("accessor {accessor_index} does not exist"))?;
        let components = match accessor.type_ {
            Checked::Valid(t) => t.multiplicity(),
            Checked::Invalid => return Err(format!("accessor {accessor_index} has no valid type")),
        };
        if accessor.count.0 != points as u64 {
            return Err(format!(
                "accessor {accessor_index} ({name}) declares {} elements but the stream decodes {points} points",
                accessor.count.0
            ));
        }
        let scale = normalisation(accessor);
        let start = out.len();
        for v in attribute.read_f32s(points, components) {
            // Signed normalised integers: max(c / (2^(b−1) − 1), −1).
            let v = if scale == 1.0 {
                v
            } else {
                (v * scale).max(-1.0)
            };
            out.extend_from_slice(&v.to_le_bytes());
        }
        let mut decoded = accessor.clone();
        decoded.component_type = Checked::Valid(GenericComponentType(ComponentType::F32));
        decoded.normalized = false;
        decoded.sparse = None;
        decoded.byte_offset = Some((start as u64).into());
        replaced.push((accessor_index, decoded));
    }

    let faces = mesh.num_faces();
    let indices_start = out.len();
    for face in mesh.faces() {
        for corner in face {
            out.extend_from_slice(&corner.0.to_le_bytes());
        }
    }
    // The indices' accessor is a copy of the primitive's own (or, without
    // one, of an attribute's: a Draco primitive is always indexed once
    // decoded).
    let prim = &root.meshes[m].primitives[p];
    let template = prim
        .indices
        .or_else(|| prim.attributes.values().next().copied())
        .and_then(|i| root.accessors.get(i.value()))
        .ok_or("the primitive has no accessor")?;
    let mut indices = template.clone();
    indices.component_type = Checked::Valid(GenericComponentType(ComponentType::U32));
    indices.type_ = Checked::Valid(Type::Scalar);
    indices.normalized = false;
    indices.sparse = None;
    indices.min = None;
    indices.max = None;
    indices.count = (faces * 3).into();
    indices.byte_offset = Some((indices_start as u64).into());

    // One new buffer and view for everything this primitive decoded.
    let new_buffer = root.buffers.len();
    let mut buffer = root.buffers[buffer_index].clone();
    buffer.uri = None;
    buffer.extensions = None;
    buffer.byte_length = out.len().into();
    root.buffers.push(buffer);
    let new_view = root.buffer_views.len();
    let mut view = view;
    view.buffer = json::Index::new(new_buffer as u32);
    view.byte_offset = None;
    view.byte_length = out.len().into();
    view.byte_stride = None;
    view.target = None;
    view.extensions = None;
    root.buffer_views.push(view);
    buffers.preload(new_buffer, out);

    // The primitive's accessors now read the decoded bytes. They are changed
    // in place (the originals have no bytes of their own to keep, and the
    // crate's validation refuses an accessor without data), so one that
    // two Draco primitives share is refused rather than read twice.
    let view_ref = Some(json::Index::new(new_view as u32));
    let own_indices = root.meshes[m].primitives[p].indices.map(|i| i.value());
    for (index, mut accessor) in own_indices
        .map(|i| (i, indices.clone()))
        .into_iter()
        .chain(replaced)
    {
        if !rewritten.insert(index) {
            return Err(format!(
                "accessor {index} is shared with another Draco-compressed primitive"
            ));
        }
        accessor.buffer_view = view_ref;
        root.accessors[index] = accessor;
    }
    if own_indices.is_none() {
        indices.buffer_view = view_ref;
        root.accessors.push(indices);
        root.meshes[m].primitives[p].indices =
            Some(json::Index::new((root.accessors.len() - 1) as u32));
    }
    Ok(())
}

/// What a decoded integer is multiplied by to give the value glTF means: a
/// normalised accessor's integers map onto [0, 1] or [−1, 1].
fn normalisation(accessor: &json::Accessor) -> f32 {
    if !accessor.normalized {
        return 1.0;
    }
    match accessor.component_type {
        Checked::Valid(GenericComponentType(ComponentType::U8)) => 1.0 / 255.0,
        Checked::Valid(GenericComponentType(ComponentType::I8)) => 1.0 / 127.0,
        Checked::Valid(GenericComponentType(ComponentType::U16)) => 1.0 / 65535.0,
        Checked::Valid(GenericComponentType(ComponentType::I16)) => 1.0 / 32767.0,
        _ => 1.0,
    }
}
