//! Mesh repair: from an imported triangle soup to the oriented 2-manifold
//! (boundaries allowed) that the progressive encoder accepts.
//!
//! Everything runs on flat arrays in O(n α(n)) time plus small per-vertex
//! sorts, over the faces radix-sorted by their lowest vertex so that memory
//! is visited nearly in order whatever order the file came in (the input's
//! face order is restored at the end): edges are grouped by
//! `vitrine_codec::edges`, orientation spreads breadth-first over manifold edges,
//! and vertex fans are the components of a union-find over face corners.

use crate::{Error, IndexedMesh, Result};
use vitrine_codec::edges::Edges;

/// What [`prepare`] may change.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RepairOptions {
    /// Merge vertices with bit-identical positions (`-0.0 == 0.0`), such as
    /// the copies glTF and OBJ exporters make along texture seams. Default true.
    pub weld: bool,
    /// Split non-manifold edges and vertices (default true). When false, a
    /// mesh that would need splitting is refused with [`Error::Unsupported`]
    /// naming the first offending edge or vertex (orientation is still fixed
    /// where flipping faces suffices).
    pub split_non_manifold: bool,
}

impl Default for RepairOptions {
    fn default() -> Self {
        RepairOptions {
            weld: true,
            split_non_manifold: true,
        }
    }
}

/// What [`prepare`] changed.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct RepairReport {
    /// Vertices merged into an earlier vertex with the same position.
    pub welded_vertices: usize,
    /// Faces dropped because two of their corners are the same vertex.
    pub degenerate_faces: usize,
    /// Faces dropped because an earlier face has the same three vertices.
    pub duplicate_faces: usize,
    /// Edges shared by more than two faces, or by two faces whose
    /// orientations could not be made to agree.
    pub non_manifold_edges: usize,
    /// Vertices (after welding) that had to be split into several.
    pub non_manifold_vertices: usize,
    /// Vertices added by splitting.
    pub split_vertices: usize,
    /// Vertices no remaining face uses, dropped.
    pub unreferenced_vertices: usize,
    /// Faces whose winding was reversed to agree with their neighbours.
    pub flipped_faces: usize,
}

impl std::fmt::Display for RepairReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "welded {} vertices, dropped {} degenerate and {} duplicate faces, \
             {} non-manifold edges, {} non-manifold vertices ({} vertices added by splitting), \
             {} unreferenced vertices dropped, {} faces flipped",
            self.welded_vertices,
            self.degenerate_faces,
            self.duplicate_faces,
            self.non_manifold_edges,
            self.non_manifold_vertices,
            self.split_vertices,
            self.unreferenced_vertices,
            self.flipped_faces
        )
    }
}

const NONE: u32 = u32::MAX;
const NEXT: [usize; 3] = [1, 2, 0];

/// Start vertex of half-edge `h` (= 3 × face + corner).
#[inline]
fn from(tris: &[[u32; 3]], h: u32) -> u32 {
    tris[h as usize / 3][h as usize % 3]
}

/// End vertex of half-edge `h`.
#[inline]
fn to(tris: &[[u32; 3]], h: u32) -> u32 {
    tris[h as usize / 3][NEXT[h as usize % 3]]
}

/// The corner at the end of half-edge `h`.
#[inline]
fn to_corner(h: u32) -> u32 {
    let f = h / 3;
    3 * f + NEXT[(h % 3) as usize] as u32
}

/// Union-find over face corners (path halving, lower index wins).
struct Corners {
    parent: Vec<u32>,
}

impl Corners {
    fn new(n: usize) -> Self {
        Corners {
            parent: (0..n as u32).collect(),
        }
    }

    #[inline]
    fn find(&mut self, mut c: u32) -> u32 {
        while self.parent[c as usize] != c {
            let p = self.parent[c as usize];
            let gp = self.parent[p as usize];
            self.parent[c as usize] = gp;
            c = gp;
        }
        c
    }

    #[inline]
    fn union(&mut self, a: u32, b: u32) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            let (lo, hi) = (a.min(b), a.max(b));
            self.parent[hi as usize] = lo;
        }
    }

    /// Glues two opposite half-edges: their end corners share vertices.
    #[inline]
    fn glue(&mut self, h: u32, g: u32) {
        self.union(h, to_corner(g));
        self.union(to_corner(h), g);
    }
}

/// The two half-edges of an edge's "first manifold pair": the first face
/// using it in each direction.
fn first_pair(tris: &[[u32; 3]], hs: &[u32]) -> Option<(u32, u32)> {
    let lo = from(tris, hs[0]).min(to(tris, hs[0]));
    let fwd = hs.iter().copied().find(|&h| from(tris, h) == lo)?;
    let bwd = hs.iter().copied().find(|&h| from(tris, h) != lo)?;
    Some((fwd, bwd))
}

/// For each vertex, the first vertex with a bit-identical position
/// (`-0.0 == 0.0`). Sort-based: O(n log n) whatever the input, with no
/// hash table a hostile file could flood.
fn first_same_position(positions: &[[f32; 3]]) -> Vec<u32> {
    // Key bits above, vertex index below: one u128 sort groups equal
    // positions with the first vertex at the head of each group.
    let mut keyed: Vec<u128> = positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let k = p.map(|v| if v == 0.0 { 0 } else { v.to_bits() } as u128);
            k[0] << 96 | k[1] << 64 | k[2] << 32 | i as u128
        })
        .collect();
    keyed.sort_unstable();
    let mut first = vec![0u32; positions.len()];
    let mut rep = 0u32;
    for (j, &k) in keyed.iter().enumerate() {
        if j == 0 || keyed[j - 1] >> 32 != k >> 32 {
            rep = k as u32;
        }
        first[k as u32 as usize] = rep;
    }
    first
}

/// Marks each face whose three vertices are those of an earlier face
/// (either orientation). Such faces share all their edges, so it is enough
/// to compare the opposite vertices of the faces on each edge.
fn duplicate_faces(tris: &[[u32; 3]], edges: &Edges) -> Vec<bool> {
    let mut dup = vec![false; tris.len()];
    let third = |h: u32| tris[h as usize / 3][NEXT[NEXT[h as usize % 3]]];
    let mut scratch: Vec<(u32, u32)> = Vec::new();
    edges.for_each(|hs| {
        if hs.len() < 2 {
            return;
        }
        if hs.len() <= 16 {
            for j in 1..hs.len() {
                if (0..j).any(|i| third(hs[i]) == third(hs[j])) {
                    dup[hs[j] as usize / 3] = true;
                }
            }
        } else {
            scratch.clear();
            scratch.extend(hs.iter().map(|&h| (third(h), h / 3)));
            scratch.sort_unstable();
            for w in scratch.windows(2) {
                if w[0].0 == w[1].0 {
                    dup[w[1].1 as usize] = true;
                }
            }
        }
    });
    dup
}

/// Checks colours, sizes, finiteness and index ranges.
fn validate(mesh: &IndexedMesh, what: &'static str) -> Result<()> {
    let n = mesh.positions.len();
    if let Some(c) = &mesh.colors {
        if c.len() != n {
            return Err(Error::input(
                what,
                format!("{} colours for {n} vertices", c.len()),
            ));
        }
    }
    // Half-edge ids (3 per face) and vertex ids after splitting (at most
    // 3 more per face) must stay below u32::MAX.
    if n as u64 + 3 * mesh.triangles.len() as u64 >= NONE as u64 {
        return Err(Error::Limit(format!(
            "{n} vertices and {} triangles: at most 2^32 vertices and 2^32/3 triangles",
            mesh.triangles.len()
        )));
    }
    if let Some((i, p)) = mesh
        .positions
        .iter()
        .enumerate()
        .find(|(_, p)| !p.iter().all(|v| v.is_finite()))
    {
        return Err(Error::input(
            what,
            format!("vertex {i} has a non-finite coordinate {p:?}"),
        ));
    }
    if let Some((f, t)) = mesh
        .triangles
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&v| v as usize >= n))
    {
        return Err(Error::input(
            what,
            format!("face {f} {t:?} refers to a vertex past the {n} vertices"),
        ));
    }
    Ok(())
}

/// Cleans a mesh for the encoder and reports what it changed.
///
/// The result satisfies these invariants (checked by [`check_manifold`]):
/// 1. With `weld`, vertices with bit-identical positions (`-0.0 == 0.0`) are
///    merged into the first; it keeps its colour. (Splitting, below, then
///    deliberately re-creates copies at non-manifold places.)
/// 2. No degenerate face (two equal corners after welding): such faces are
///    dropped. Zero-area faces with three distinct vertices are kept.
/// 3. No duplicate faces (same three vertices, either orientation): the
///    first is kept.
/// 4. Every edge has one or two faces, and two faces use it in opposite
///    directions. Orientation is first made consistent by flipping faces,
///    per edge-connected component (the majority orientation wins); edges
///    that are still non-manifold (more than two faces, or a non-orientable
///    component) are split: the first face in each direction stay together,
///    the others get their own copy of the edge.
/// 5. Every vertex's faces form one edge-connected fan (a disc or a
///    half-disc): a "bow-tie" vertex is split into one vertex per fan.
/// 6. No unreferenced vertex. Surviving vertices keep their relative order
///    and vertices added by splitting come after them; triangles keep their
///    order (less the dropped ones) and corners, except that a flipped face
///    `[a, b, c]` becomes `[a, c, b]`.
/// 7. All positions finite (non-finite input is an [`Error::Input`]).
///
/// A mesh left without any triangle is [`Error::Unsupported`].
pub fn prepare(mesh: IndexedMesh, opts: &RepairOptions) -> Result<(IndexedMesh, RepairReport)> {
    prepare_traced(mesh, opts).map(|(mesh, report, _)| (mesh, report))
}

/// Where each part of a repaired mesh came from, for callers that carry
/// more per vertex or per corner than [`IndexedMesh`] holds (an MD2's
/// frames and texture coordinates).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RepairTrace {
    /// Each output vertex's input vertex (a split vertex's copies share it;
    /// with welding, the first of the merged vertices).
    pub vertex_origin: Vec<u32>,
    /// Each output face's input face. Its corners are the input face's in
    /// the same order, or `[a, c, b]` for `[a, b, c]` when it was flipped.
    pub face_origin: Vec<u32>,
}

/// [`prepare`], with where each output vertex and face came from.
pub fn prepare_traced(
    mesh: IndexedMesh,
    opts: &RepairOptions,
) -> Result<(IndexedMesh, RepairReport, RepairTrace)> {
    validate(&mesh, "mesh")?;
    let mut report = RepairReport::default();
    let IndexedMesh {
        positions,
        colors,
        triangles,
    } = mesh;
    let welded = weld(positions, colors, opts, &mut report);
    let (tris, face_of) = drop_degenerate_faces(triangles, welded.remap, &mut report);
    let (tris, face_of) = sort_by_lowest_vertex(tris, face_of);
    let mut work = Work {
        pos: welded.pos,
        col: welded.col,
        tris,
        face_of,
        first: welded.first,
    };
    let edges = drop_duplicate_faces(&mut work, &mut report)?;
    let nv0 = work.pos.len();
    let edges = orient_faces(&mut work.tris, edges, nv0, &mut report);
    let base = split_until_manifold(&mut work, edges, opts, &mut report)?;
    let (tris, face_origin) = restore_input_order(work.tris, work.face_of);
    let (mesh, kept) = drop_unreferenced_vertices(work.pos, work.col, tris, &mut report);
    debug_assert!(check_manifold(&mesh).is_ok(), "{:?}", check_manifold(&mesh));
    let vertex_origin = kept
        .iter()
        .map(|&v| work.first[base[v as usize] as usize])
        .collect();
    let trace = RepairTrace {
        vertex_origin,
        face_origin,
    };
    Ok((mesh, report, trace))
}

/// The vertices after welding, and how to renumber the faces.
struct Welded {
    pos: Vec<[f32; 3]>,
    col: Option<Vec<[u8; 3]>>,
    /// Input vertex → post-weld vertex; `None` when no vertex was merged.
    remap: Option<Vec<u32>>,
    /// `first[v]` is the input index of post-weld vertex v.
    first: Vec<u32>,
}

/// Step 1, weld (with [`RepairOptions::weld`]): vertices with bit-identical
/// positions merge into the first, which keeps its colour.
fn weld(
    positions: Vec<[f32; 3]>,
    colors: Option<Vec<[u8; 3]>>,
    opts: &RepairOptions,
    report: &mut RepairReport,
) -> Welded {
    if !opts.weld {
        let n = positions.len() as u32;
        return Welded {
            pos: positions,
            col: colors,
            remap: None,
            first: (0..n).collect(),
        };
    }
    let n = positions.len();
    // `remap[i]`: first vertex at i's position, then its new index.
    let mut remap = first_same_position(&positions);
    let mut first = Vec::new();
    for i in 0..n {
        if remap[i] as usize == i {
            remap[i] = first.len() as u32;
            first.push(i as u32);
        } else {
            remap[i] = remap[remap[i] as usize];
        }
    }
    report.welded_vertices = n - first.len();
    if first.len() == n {
        return Welded {
            pos: positions,
            col: colors,
            remap: None,
            first,
        };
    }
    let pos: Vec<[f32; 3]> = first.iter().map(|&i| positions[i as usize]).collect();
    let col = colors.map(|c| first.iter().map(|&i| c[i as usize]).collect());
    Welded {
        pos,
        col,
        remap: Some(remap),
        first,
    }
}

/// Step 2: remap and drop degenerate faces. Returns the faces left and
/// `face_of`: `face_of[f]` is the input index of face f.
fn drop_degenerate_faces(
    triangles: Vec<[u32; 3]>,
    remap: Option<Vec<u32>>,
    report: &mut RepairReport,
) -> (Vec<[u32; 3]>, Vec<u32>) {
    let mut tris: Vec<[u32; 3]> = Vec::with_capacity(triangles.len());
    let mut face_of: Vec<u32> = Vec::with_capacity(triangles.len());
    for (f, t) in triangles.iter().enumerate() {
        let t = match &remap {
            Some(r) => t.map(|v| r[v as usize]),
            None => *t,
        };
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            report.degenerate_faces += 1;
            continue;
        }
        tris.push(t);
        face_of.push(f as u32);
    }
    (tris, face_of)
}

/// Work on the faces in the order of their lowest vertex, so that the
/// later passes, which visit edges by vertex, touch faces near each other
/// in memory (a scan's faces often come scattered); the input's order
/// comes back at the end ([`restore_input_order`]). Stable radix sorts:
/// sequential passes only.
fn sort_by_lowest_vertex(tris: Vec<[u32; 3]>, face_of: Vec<u32>) -> (Vec<[u32; 3]>, Vec<u32>) {
    let mut faces: Vec<([u32; 3], u32)> = tris.into_iter().zip(face_of).collect();
    radsort::sort_by_key(&mut faces, |(t, _)| t[0].min(t[1]).min(t[2]));
    faces.into_iter().unzip()
}

/// The mesh between the steps of [`prepare`], its faces in working order.
struct Work {
    pos: Vec<[f32; 3]>,
    col: Option<Vec<[u8; 3]>>,
    tris: Vec<[u32; 3]>,
    /// `face_of[f]` is the input index of face f.
    face_of: Vec<u32>,
    /// `first[v]` is the input index of post-weld vertex v.
    first: Vec<u32>,
}

/// Step 3: drop duplicate faces (found through their shared edges). Returns
/// the edges of the faces left; a mesh left without faces is refused.
fn drop_duplicate_faces(work: &mut Work, report: &mut RepairReport) -> Result<Edges> {
    let nv0 = work.pos.len();
    let mut edges = Edges::build(&work.tris, nv0);
    let dup = duplicate_faces(&work.tris, &edges);
    report.duplicate_faces = dup.iter().filter(|&&d| d).count();
    if report.duplicate_faces > 0 {
        let mut f = 0;
        work.tris.retain(|_| {
            f += 1;
            !dup[f - 1]
        });
        let mut f = 0;
        work.face_of.retain(|_| {
            f += 1;
            !dup[f - 1]
        });
        edges = Edges::build(&work.tris, nv0);
    }
    drop(dup);
    if work.tris.is_empty() {
        return Err(Error::Unsupported(
            "mesh has no triangles left after dropping degenerate and duplicate faces".into(),
        ));
    }
    Ok(edges)
}

/// Step 4a, orientation: spread across edges with exactly two faces.
/// Returns the edges of the faces as they now are.
fn orient_faces(
    tris: &mut [[u32; 3]],
    edges: Edges,
    nv0: usize,
    report: &mut RepairReport,
) -> Edges {
    report.flipped_faces = orient(tris, &edges);
    if report.flipped_faces > 0 {
        drop(edges);
        Edges::build(tris, nv0)
    } else {
        edges
    }
}

/// The vertices splitting adds.
struct Splits {
    /// `base[v]` is the post-weld vertex v copies.
    base: Vec<u32>,
    /// Post-weld vertices that were split.
    marked: Vec<bool>,
}

impl Work {
    /// A new vertex at the end, a copy of `v` (position and colour); the
    /// post-weld vertex it copies is marked split.
    fn copy_vertex(&mut self, splits: &mut Splits, v: u32) -> u32 {
        let id = self.pos.len() as u32;
        self.pos.push(self.pos[v as usize]);
        if let Some(c) = self.col.as_mut() {
            c.push(c[v as usize]);
        }
        splits.base.push(splits.base[v as usize]);
        splits.marked[splits.base[v as usize] as usize] = true;
        id
    }
}

/// Steps 4b–5, split until manifold: non-manifold edges are cut and each
/// fan of a vertex gets its own vertex, until a pass finds nothing to cut.
/// Refused at the first offending edge or vertex without
/// [`RepairOptions::split_non_manifold`].
fn split_until_manifold(
    work: &mut Work,
    mut edges: Edges,
    opts: &RepairOptions,
    report: &mut RepairReport,
) -> Result<Vec<u32>> {
    let nv0 = work.pos.len();
    let mut splits = Splits {
        base: (0..nv0 as u32).collect(),
        marked: vec![false; nv0],
    };
    for iteration in 0.. {
        let (mut uf, bad) = glue_fans(&work.tris, &edges);
        if iteration == 0 {
            report.non_manifold_edges += bad_edges(&bad).count();
            if !opts.split_non_manifold {
                if let Some(hs) = bad_edges(&bad).next() {
                    return Err(non_manifold_edge(work, hs));
                }
            }
        }
        let added = split_fans(work, &mut splits, &mut uf, opts)?;
        report.split_vertices += added;
        if bad.is_empty() {
            break;
        }
        if added == 0 {
            report.split_vertices += detach_extra_faces(work, &mut splits, &bad);
        }
        edges = Edges::build(&work.tris, work.pos.len());
    }
    drop(edges);
    report.non_manifold_vertices = splits.marked.iter().filter(|&&m| m).count();
    Ok(splits.base)
}

/// Glues the corners across every manifold edge, and across the first
/// manifold pair of every other edge ([`first_pair`]). Returns the corner
/// union-find and the non-manifold edges, flattened: length, then
/// half-edges (read them with [`bad_edges`]).
fn glue_fans(tris: &[[u32; 3]], edges: &Edges) -> (Corners, Vec<u32>) {
    let mut uf = Corners::new(tris.len() * 3);
    let mut bad: Vec<u32> = Vec::new();
    edges.for_each(|hs| match hs.len() {
        1 => {}
        2 if from(tris, hs[0]) != from(tris, hs[1]) => uf.glue(hs[0], hs[1]),
        _ => {
            if let Some((a, b)) = first_pair(tris, hs) {
                uf.glue(a, b);
            }
            bad.push(hs.len() as u32);
            bad.extend_from_slice(hs);
        }
    });
    (uf, bad)
}

/// The half-edges of each edge of a flattened list from [`glue_fans`].
fn bad_edges(bad: &[u32]) -> impl Iterator<Item = &[u32]> + '_ {
    let mut i = 0;
    std::iter::from_fn(move || {
        let len = *bad.get(i)? as usize;
        let hs = &bad[i + 1..=i + len];
        i += len + 1;
        Some(hs)
    })
}

/// The refusal of non-manifold edge `hs` when splitting is not allowed.
fn non_manifold_edge(work: &Work, hs: &[u32]) -> Error {
    let tris = &work.tris;
    let (a, b) = (from(tris, hs[0]), to(tris, hs[0]));
    let faces: Vec<u32> = hs.iter().map(|&h| work.face_of[h as usize / 3]).collect();
    let why = if hs.len() == 2 {
        "2 faces with orientations that cannot be made consistent".to_string()
    } else {
        format!("{} faces", hs.len())
    };
    Error::Unsupported(format!(
        "non-manifold edge between vertices {} and {}: shared by {why} (faces {faces:?})",
        work.first[a as usize], work.first[b as usize]
    ))
}

/// One vertex per fan: the first fan met (in corner order) keeps the id,
/// the others get copies. Returns the number of vertices added.
fn split_fans(
    work: &mut Work,
    splits: &mut Splits,
    uf: &mut Corners,
    opts: &RepairOptions,
) -> Result<usize> {
    let nv = work.pos.len();
    let nc = work.tris.len() * 3;
    let mut first_root = vec![NONE; nv];
    let mut root_vertex = vec![NONE; nc];
    let mut added = 0usize;
    for c in 0..nc as u32 {
        let (f, k) = (c as usize / 3, c as usize % 3);
        let v = work.tris[f][k];
        let r = uf.find(c);
        if root_vertex[r as usize] == NONE {
            if first_root[v as usize] == NONE {
                first_root[v as usize] = r;
                root_vertex[r as usize] = v;
            } else {
                if !opts.split_non_manifold {
                    return Err(Error::Unsupported(format!(
                        "non-manifold vertex {}: its faces form several separate fans \
                         (e.g. faces {} and {})",
                        work.first[splits.base[v as usize] as usize],
                        work.face_of[first_root[v as usize] as usize / 3],
                        work.face_of[f]
                    )));
                }
                root_vertex[r as usize] = work.copy_vertex(splits, v);
                added += 1;
            }
        }
        work.tris[f][k] = root_vertex[r as usize];
    }
    Ok(added)
}

/// Splitting fans did not separate the remaining bad edges (their extra
/// faces sit in the same fans as the kept pair): give each extra face its
/// own copy of the edge's lower vertex. Returns the number of vertices added.
fn detach_extra_faces(work: &mut Work, splits: &mut Splits, bad: &[u32]) -> usize {
    let mut added = 0;
    for hs in bad_edges(bad) {
        let keep = first_pair(&work.tris, hs).unwrap_or((hs[0], hs[0]));
        let lo = from(&work.tris, hs[0]).min(to(&work.tris, hs[0]));
        for &h in hs {
            if h == keep.0 || h == keep.1 {
                continue;
            }
            let c = if from(&work.tris, h) == lo {
                h
            } else {
                to_corner(h)
            };
            let (f, k) = (c as usize / 3, c as usize % 3);
            let v = work.tris[f][k];
            work.tris[f][k] = work.copy_vertex(splits, v);
            added += 1;
        }
    }
    added
}

/// Back to the input's face order (less the dropped faces), with each
/// face's input index.
fn restore_input_order(tris: Vec<[u32; 3]>, face_of: Vec<u32>) -> (Vec<[u32; 3]>, Vec<u32>) {
    let mut faces: Vec<([u32; 3], u32)> = tris.into_iter().zip(face_of).collect();
    radsort::sort_by_key(&mut faces, |&(_, input)| input);
    faces.into_iter().unzip()
}

/// Step 6: drop unreferenced vertices, keeping order. Returns the mesh and
/// the vertex each output vertex was.
fn drop_unreferenced_vertices(
    mut pos: Vec<[f32; 3]>,
    mut col: Option<Vec<[u8; 3]>>,
    mut tris: Vec<[u32; 3]>,
    report: &mut RepairReport,
) -> (IndexedMesh, Vec<u32>) {
    let mut new_id = vec![NONE; pos.len()];
    for t in &tris {
        for &v in t {
            new_id[v as usize] = 0;
        }
    }
    let mut next = 0u32;
    for id in new_id.iter_mut() {
        if *id == 0 {
            *id = next;
            next += 1;
        }
    }
    report.unreferenced_vertices = pos.len() - next as usize;
    if report.unreferenced_vertices > 0 {
        let keep = |i: usize| new_id[i] != NONE;
        let mut i = 0;
        pos.retain(|_| {
            i += 1;
            keep(i - 1)
        });
        if let Some(c) = col.as_mut() {
            let mut i = 0;
            c.retain(|_| {
                i += 1;
                keep(i - 1)
            });
        }
        for t in tris.iter_mut() {
            *t = t.map(|v| new_id[v as usize]);
        }
    }
    let kept = (0..new_id.len() as u32)
        .filter(|&v| new_id[v as usize] != NONE)
        .collect();
    let mesh = IndexedMesh {
        positions: pos,
        colors: col,
        triangles: tris,
    };
    (mesh, kept)
}

/// Flips faces so that faces sharing an edge (with exactly two faces) agree,
/// per connected component, keeping the majority's orientation. Returns the
/// number of faces flipped. Components that cannot be oriented (Möbius-like)
/// keep conflicting edges, which splitting then cuts.
fn orient(tris: &mut [[u32; 3]], edges: &Edges) -> usize {
    let nf = tris.len();
    let mut mate = vec![NONE; nf * 3];
    let mut conflict = false;
    edges.for_each(|hs| {
        if hs.len() == 2 {
            mate[hs[0] as usize] = hs[1];
            mate[hs[1] as usize] = hs[0];
            conflict |= from(tris, hs[0]) == from(tris, hs[1]);
        }
    });
    if !conflict {
        return 0;
    }
    let mut flip = vec![false; nf];
    let mut seen = vec![false; nf];
    let mut queue: Vec<u32> = Vec::new();
    let mut flipped = 0;
    for s in 0..nf {
        if seen[s] {
            continue;
        }
        queue.clear();
        queue.push(s as u32);
        seen[s] = true;
        let mut head = 0;
        while head < queue.len() {
            let f = queue[head] as usize;
            head += 1;
            for k in 0..3 {
                let h = (3 * f + k) as u32;
                let m = mate[h as usize];
                if m == NONE {
                    continue;
                }
                let g = m as usize / 3;
                if seen[g] {
                    continue;
                }
                seen[g] = true;
                flip[g] = flip[f] ^ (from(tris, h) == from(tris, m));
                queue.push(g as u32);
            }
        }
        let n = queue.iter().filter(|&&f| flip[f as usize]).count();
        let invert = 2 * n > queue.len();
        for &f in &queue {
            let f = f as usize;
            if flip[f] != invert {
                tris[f].swap(1, 2);
                flipped += 1;
            }
        }
    }
    flipped
}

/// Checks the invariants [`prepare`] establishes (all but welding, which
/// splitting deliberately undoes at non-manifold places): finite positions,
/// indices in range, no degenerate or duplicate faces, every edge on one or
/// two faces with opposite directions, one fan per vertex, no unreferenced
/// vertex. Returns [`Error::Unsupported`] naming the first violation.
pub fn check_manifold(mesh: &IndexedMesh) -> Result<()> {
    validate(mesh, "mesh")?;
    let tris = &mesh.triangles;
    let nv = mesh.positions.len();
    let fail = |s: String| Err(Error::Unsupported(s));
    if let Some((f, t)) = tris
        .iter()
        .enumerate()
        .find(|(_, t)| t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
    {
        return fail(format!("face {f} {t:?} is degenerate"));
    }
    let edges = Edges::build(tris, nv);
    if let Some(f) = duplicate_faces(tris, &edges).iter().position(|&d| d) {
        return fail(format!("face {f} {:?} duplicates an earlier face", tris[f]));
    }
    let mut uf = Corners::new(tris.len() * 3);
    let mut problem = None;
    edges.for_each(|hs| {
        if problem.is_some() {
            return;
        }
        let (a, b) = (from(tris, hs[0]), to(tris, hs[0]));
        match hs.len() {
            1 => {}
            2 if from(tris, hs[1]) != a => uf.glue(hs[0], hs[1]),
            2 => {
                problem = Some(format!(
                    "edge ({a}, {b}) is used in the same direction by faces {} and {}",
                    hs[0] / 3,
                    hs[1] / 3
                ))
            }
            n => problem = Some(format!("edge ({a}, {b}) is shared by {n} faces")),
        }
    });
    if let Some(p) = problem {
        return fail(p);
    }
    let mut root = vec![NONE; nv];
    for c in 0..(tris.len() * 3) as u32 {
        let v = tris[c as usize / 3][c as usize % 3] as usize;
        let r = uf.find(c);
        if root[v] == NONE {
            root[v] = r;
        } else if root[v] != r {
            return fail(format!(
                "vertex {v} is non-manifold: faces {} and {} are in separate fans",
                root[v] / 3,
                c / 3
            ));
        }
    }
    if let Some(v) = root.iter().position(|&r| r == NONE) {
        return fail(format!("vertex {v} is not used by any face"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(positions: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> IndexedMesh {
        IndexedMesh {
            positions,
            colors: None,
            triangles,
        }
    }

    fn grid(n: u32) -> IndexedMesh {
        let mut p = Vec::new();
        for y in 0..=n {
            for x in 0..=n {
                p.push([x as f32, y as f32, 0.0]);
            }
        }
        let mut t = Vec::new();
        let id = |x: u32, y: u32| y * (n + 1) + x;
        for y in 0..n {
            for x in 0..n {
                t.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
                t.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
            }
        }
        mesh(p, t)
    }

    #[test]
    fn clean_mesh_is_unchanged() {
        let m = grid(4);
        let (out, report) = prepare(m.clone(), &RepairOptions::default()).unwrap();
        assert_eq!(out, m);
        assert_eq!(report, RepairReport::default());
        check_manifold(&out).unwrap();
    }

    /// Repair works on the faces sorted by their lowest vertex; what it
    /// returns must still be in the input's order, less the faces it drops.
    #[test]
    fn scattered_faces_come_back_in_input_order() {
        let g = grid(8);
        let n = g.triangles.len();
        // A stride coprime to the face count scatters the faces over the grid.
        let mut t: Vec<[u32; 3]> = (0..n).map(|i| g.triangles[i * 37 % n]).collect();
        let kept = t.clone();
        t.insert(40, kept[7]); // a duplicate of an earlier face: dropped
        t.insert(90, [5, 5, 6]); // degenerate: dropped
        t[3].swap(1, 2); // against its neighbours: flipped back
        let (out, report) =
            prepare(mesh(g.positions.clone(), t), &RepairOptions::default()).unwrap();
        assert_eq!(report.duplicate_faces, 1, "{report:?}");
        assert_eq!(report.degenerate_faces, 1, "{report:?}");
        assert_eq!(report.flipped_faces, 1, "{report:?}");
        let cyclic =
            |a: [u32; 3], b: [u32; 3]| (0..3).any(|r| b == [a[r], a[(r + 1) % 3], a[(r + 2) % 3]]);
        assert_eq!(out.triangles.len(), kept.len());
        for (f, (&got, &want)) in out.triangles.iter().zip(&kept).enumerate() {
            assert!(cyclic(got, want), "face {f}: {got:?} for {want:?}");
        }
        assert_eq!(out.positions, g.positions);
        check_manifold(&out).unwrap();
    }

    #[test]
    fn orientation_majority_wins() {
        let mut m = grid(3);
        m.triangles[4].swap(0, 1);
        let (out, report) = prepare(m, &RepairOptions::default()).unwrap();
        assert_eq!(report.flipped_faces, 1);
        let mut want = grid(3).triangles;
        let t = want[4];
        want[4] = [t[1], t[2], t[0]]; // swapped (0,1), then flipped (1,2)
        assert_eq!(out.triangles, want);
        check_manifold(&out).unwrap();
    }

    #[test]
    fn extra_face_in_the_same_fans_is_detached() {
        // Edge 1–2 has three faces, and the extra one is joined to the kept
        // pair around both ends, so splitting fans cannot separate it.
        let p = (0..5).map(|i| [i as f32, (i * i) as f32, 0.0]).collect();
        let t = vec![[4, 1, 2], [3, 1, 2], [2, 0, 3], [0, 1, 3], [0, 2, 1]];
        let (out, report) = prepare(mesh(p, t), &RepairOptions::default()).unwrap();
        check_manifold(&out).unwrap();
        assert!(report.non_manifold_edges >= 1, "{report:?}");
        assert!(report.split_vertices >= 1, "{report:?}");
    }

    #[test]
    fn mobius_strip_is_cut() {
        // A strip of 6 quads whose ends are glued with a half twist.
        let n = 6u32;
        let mut p = Vec::new();
        for i in 0..n {
            let a = i as f32;
            p.push([a, 0.0, 0.0]);
            p.push([a, 1.0, 0.0]);
        }
        let mut t = Vec::new();
        for i in 0..n {
            let (a0, a1) = (2 * i, 2 * i + 1);
            let (b0, b1) = if i + 1 < n {
                (2 * i + 2, 2 * i + 3)
            } else {
                (1, 0)
            };
            t.push([a0, b0, b1]);
            t.push([a0, b1, a1]);
        }
        let (out, report) = prepare(mesh(p.clone(), t.clone()), &RepairOptions::default()).unwrap();
        check_manifold(&out).unwrap();
        assert!(report.non_manifold_edges >= 1, "{report:?}");
        let strict = RepairOptions {
            split_non_manifold: false,
            ..Default::default()
        };
        let e = prepare(mesh(p, t), &strict).unwrap_err();
        assert!(e.to_string().contains("non-manifold edge"), "{e}");
    }

    #[test]
    fn the_trace_names_each_output_vertex_and_face_of_the_input() {
        // A grid with a flipped face, a degenerate and a duplicate face, an
        // unused vertex, and a bow-tie (two fans at one vertex).
        let mut m = grid(3);
        m.triangles[4].swap(0, 1);
        m.triangles.insert(2, [5, 5, 6]);
        m.triangles.push(m.triangles[0]);
        m.positions.push([9.0, 9.0, 9.0]); // unused
        let tip = m.positions.len() as u32;
        m.positions.extend([[-1.0, -1.0, 0.0], [-1.0, -2.0, 0.0]]);
        m.triangles.push([0, tip + 1, tip]); // touches the grid at vertex 0 only
        let input = m.clone();
        let options = RepairOptions {
            weld: false,
            ..Default::default()
        };
        let (out, report, trace) = prepare_traced(m, &options).unwrap();
        assert!(
            report.split_vertices >= 1 && report.flipped_faces == 1,
            "{report:?}"
        );
        assert_eq!(trace.vertex_origin.len(), out.positions.len());
        assert_eq!(trace.face_origin.len(), out.triangles.len());
        for (v, &o) in trace.vertex_origin.iter().enumerate() {
            assert_eq!(out.positions[v], input.positions[o as usize], "vertex {v}");
        }
        for (t, &f) in out.triangles.iter().zip(&trace.face_origin) {
            let back = t.map(|v| trace.vertex_origin[v as usize]);
            let u = input.triangles[f as usize];
            let flipped = [u[0], u[2], u[1]];
            let rotations = |w: [u32; 3]| [w, [w[1], w[2], w[0]], [w[2], w[0], w[1]]];
            assert!(
                rotations(u).contains(&back) || rotations(flipped).contains(&back),
                "face {f}: {back:?} from {u:?}"
            );
        }
        // The degenerate, the duplicate and the unused vertex are gone.
        assert!(!trace.face_origin.contains(&2));
        assert!(!trace
            .face_origin
            .contains(&(input.triangles.len() as u32 - 2)));
        assert!(!trace.vertex_origin.contains(&(tip - 1)));
        check_manifold(&out).unwrap();
    }
}
