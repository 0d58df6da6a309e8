//! Simplification from the intrinsic Voronoi diagram (Oliveira 2011, seed
//! 001, with the repairs of SEEDS.md 001): cover the surface with geodesic
//! discs of radius r, label every vertex with its nearest centre by one
//! multi-source propagation, split the cells that break the closed-ball
//! property (halving their radius and re-covering what falls outside it,
//! re-propagating only from the new sites) until none does, and take the
//! dual. The output's vertices are input vertices, bit for bit (or, with
//! [`VoronoiPlacement::Quadric`], moved to their cells' quadric minimum:
//! `placement`), and it has the input's genus, components and border loops
//! (holes are coned while the diagram is built: `closure`).

mod closed_ball;
mod closure;
mod cover;
mod creases;
mod curvature;
mod dual;
mod faces;
mod placement;
mod search;
mod spacing;

use std::time::{Duration, Instant};

use glam::DVec3;
use vitrine_codec::{Error, IndexedMesh, Result};
use vitrine_geodesic::{Propagation, Surface};
use vitrine_quality::metrics::distances_to_surface;

/// How geodesic distance is measured (`vitrine_geodesic::Method`).
pub use vitrine_geodesic::Method as Distance;

use closed_ball::Violation;
use closure::Closed;
pub use cover::Order;
pub use creases::SHARP_DEGREES;
pub use placement::VoronoiPlacement;
pub use spacing::VoronoiSpacing;

/// The disc radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Radius {
    /// r as this fraction of the bounding box's diagonal (the seed gives no
    /// unit; SEEDS.md 001).
    Fraction(f64),
    /// The r whose output has the vertex count nearest to this, by search.
    TargetVertices(usize),
}

/// Parameters of [`simplify_voronoi`].
#[derive(Clone, Debug, PartialEq)]
pub struct VoronoiOptions {
    pub distance: Distance,
    pub order: Order,
    pub radius: Radius,
    /// Refinement rounds at most before giving up with an error.
    pub max_rounds: usize,
    /// Edges whose faces' normals differ by this many degrees or more are
    /// creases, whose vertices the cover takes first (`creases`); `None`
    /// covers as the seed does.
    pub sharp_degrees: Option<f64>,
    /// Where the output's vertices go: at the sites (the seed), or where
    /// their cells' quadrics put them (`placement`).
    pub placement: VoronoiPlacement,
    /// One cover radius everywhere (the seed), or smaller where the
    /// surface bends (`spacing`).
    pub spacing: VoronoiSpacing,
}

impl Default for VoronoiOptions {
    fn default() -> Self {
        VoronoiOptions {
            distance: Distance::Dijkstra,
            order: Order::Farthest,
            radius: Radius::Fraction(0.05),
            max_rounds: 500,
            sharp_degrees: Some(SHARP_DEGREES),
            placement: VoronoiPlacement::Sites,
            spacing: VoronoiSpacing::Adaptive,
        }
    }
}

/// Time spent in each stage (the seed's Tabela 4.2 splits them so).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stages {
    pub cover: Duration,
    pub diagram: Duration,
    pub refinement: Duration,
    pub dual: Duration,
}

/// The simplified mesh and how it came about.
#[derive(Clone, Debug)]
pub struct VoronoiSimplified {
    /// One vertex per site used, in the sites' input order, colours
    /// copied; positions the sites' own, bit for bit, unless the placement
    /// moved them; faces oriented as the input.
    pub mesh: IndexedMesh,
    /// For each output vertex, the input vertex that is its site.
    pub origin: Vec<u32>,
    /// r over the bounding box's diagonal, as given or as the search found.
    pub radius_fraction: f64,
    /// Sites at the end (cones included) and at the end of the cover.
    pub sites: usize,
    pub cover_sites: usize,
    /// Refinement rounds, and cells split over all of them.
    pub rounds: usize,
    pub splits: usize,
    /// Radii tried (1 unless searching for a vertex count).
    pub attempts: usize,
    /// Of the last attempt.
    pub stages: Stages,
}

/// Simplifies `mesh` (an oriented 2-manifold, borders allowed: what
/// `vitrine_mesh::repair::prepare` produces). Errors on a mesh that is not
/// one, on NaN coordinates, on no faces and on a radius out of range.
pub fn simplify_voronoi(mesh: &IndexedMesh, options: &VoronoiOptions) -> Result<VoronoiSimplified> {
    if mesh.triangles.is_empty() {
        return Err(Error::input("mesh", "it has no faces"));
    }
    if mesh
        .colors
        .as_ref()
        .is_some_and(|c| c.len() != mesh.positions.len())
    {
        return Err(Error::input(
            "mesh",
            "its colours do not match its vertices",
        ));
    }
    let closed = Closed::new(mesh)?;
    if closed.surface.diagonal() <= 0.0 {
        return Err(Error::input("mesh", "all its vertices coincide"));
    }
    let curvature =
        (options.order == Order::Curvature).then(|| curvature::gaussian_curvature(&closed.surface));
    // The scale the adaptive density is measured at: r, or the search's
    // first estimate of it.
    let scale = match options.radius {
        Radius::Fraction(f) if f.is_finite() && f > 0.0 && f <= 10.0 => f,
        Radius::Fraction(f) => {
            return Err(Error::Parameter(format!(
                "radius must be a fraction of the diagonal within (0, 10], got {f}"
            )))
        }
        Radius::TargetVertices(0) => {
            return Err(Error::Parameter(
                "target vertices must be at least 1".into(),
            ))
        }
        Radius::TargetVertices(n) => search::first_fraction(&closed.surface, n),
    } * closed.surface.diagonal();
    let factors = (options.spacing == VoronoiSpacing::Adaptive)
        .then(|| spacing::radius_factors(&closed.surface, closed.first_cone, scale));
    let context = Context {
        closed: &closed,
        curvature: curvature.as_deref(),
        factors: factors.as_deref(),
    };
    let surface = &closed.surface;
    let run = |context: &Context, start: f64, step: f64| {
        let run = |fraction: f64| Diagram::simplify(context, mesh, options, fraction);
        match options.radius {
            Radius::Fraction(f) => run(f),
            Radius::TargetVertices(n) => search::nearest(n, start, step, run),
        }
    };
    let start = scale / surface.diagonal();
    let mut out = run(&context, start, 2.0)?;
    let Some(factors) = &factors else {
        return Ok(out);
    };
    // Where the first pass left its error, the sites move closer (`spacing`);
    // each pass is kept only if its worst input vertex lies closer.
    let points: Vec<DVec3> = (0..closed.first_cone)
        .map(|v| surface.position(v))
        .collect();
    let worst = |out: &VoronoiSimplified| {
        let d = distances_to_surface(&points, &out.mesh);
        let max = d.iter().copied().fold(0.0, f64::max);
        (d, max)
    };
    let (mut error, mut max) = worst(&out);
    let mut factors = factors.clone();
    for _ in 0..spacing::ERROR_PASSES {
        if max <= 1e-6 * surface.diagonal() {
            break; // exact but for rounding: nothing to move sites for
        }
        let refined = spacing::refined_factors(surface, closed.first_cone, scale, &factors, &error);
        let context = Context {
            factors: Some(&refined),
            ..context
        };
        // The density is normalised, so the last radius is nearly right.
        let next = run(&context, out.radius_fraction, 1.05)?;
        let attempts = out.attempts + next.attempts;
        let (next_error, next_max) = worst(&next);
        if next_max >= max {
            out.attempts = attempts;
            break;
        }
        (out, error, max, factors) = (
            VoronoiSimplified { attempts, ..next },
            next_error,
            next_max,
            refined,
        );
    }
    Ok(out)
}

/// What every radius tried shares.
#[derive(Clone, Copy)]
struct Context<'a> {
    closed: &'a Closed,
    curvature: Option<&'a [f64]>,
    /// Each vertex's cover radius over r (`spacing`); `None`: uniform.
    factors: Option<&'a [f64]>,
}

/// The diagram as it is refined: the sites (cones first), their radii and
/// the front that labels every vertex.
struct Diagram<'a> {
    closed: &'a Closed,
    options: &'a VoronoiOptions,
    curvature: Option<&'a [f64]>,
    factors: Option<&'a [f64]>,
    /// Each vertex's `creases` rank: the cover takes lower ranks first.
    ranks: Vec<u8>,
    site_vertex: Vec<u32>,
    radius: Vec<f64>,
    front: Propagation<'a>,
    scratch: Propagation<'a>,
}

impl<'a> Diagram<'a> {
    fn simplify(
        context: &Context<'a>,
        mesh: &IndexedMesh,
        options: &'a VoronoiOptions,
        fraction: f64,
    ) -> Result<VoronoiSimplified> {
        let closed = context.closed;
        let surface = &closed.surface;
        let r = fraction * surface.diagonal();
        let mut stages = Stages::default();
        let mut diagram = Diagram {
            closed,
            options,
            curvature: context.curvature,
            factors: context.factors,
            ranks: match options.sharp_degrees {
                // A crease shorter than a disc's diameter is left to the cover.
                Some(degrees) => {
                    creases::crease_ranks(surface, closed.first_cone, degrees, 2.0 * r)
                }
                None => vec![creases::SMOOTH; surface.vertex_count()],
            },
            site_vertex: (closed.first_cone..surface.vertex_count() as u32).collect(),
            radius: vec![0.0; surface.vertex_count() - closed.first_cone as usize],
            front: Propagation::new(surface, options.distance),
            scratch: Propagation::new(surface, options.distance),
        };
        let started = Instant::now();
        diagram.cover(r);
        let cover_sites = diagram.site_vertex.len();
        stages.cover = started.elapsed();
        let started = Instant::now();
        diagram.front.run(f64::INFINITY);
        stages.diagram = started.elapsed();
        let started = Instant::now();
        let (mut rounds, mut splits) = (0, 0);
        let checks = faces::FaceChecks::new(surface, closed.first_cone);
        let mut dual_time;
        let (faces, labels) = loop {
            let labels = diagram.labels();
            let mut violations =
                closed_ball::violations(surface, &labels, diagram.site_vertex.len());
            if violations.is_empty() {
                let started = Instant::now();
                let (faces, cells) =
                    dual::dual_faces(surface, &labels, &diagram.site_vertex, |v| {
                        closed.is_cone(v)
                    });
                dual_time = started.elapsed();
                violations = checks.violations(&faces, &cells, &labels);
                // A face whose cells cannot split any more stays as it is.
                let members = Members::new(&labels, diagram.site_vertex.len());
                violations.retain(|v| diagram.cell_to_split(v, &members).is_some());
                if violations.is_empty() {
                    break (faces, labels);
                }
            }
            if rounds == options.max_rounds {
                return Err(Error::Unsupported(format!(
                    "the Voronoi diagram still breaks the closed-ball property or folds after \
                     {rounds} refinement rounds ({} violations)",
                    violations.len()
                )));
            }
            splits += diagram.refine(&labels, &violations)?;
            rounds += 1;
        };
        stages.refinement = started.elapsed().saturating_sub(dual_time);
        stages.dual = dual_time;
        let started = Instant::now();
        let (mut mesh, origin) = compact(mesh, &faces);
        if options.placement == VoronoiPlacement::Quadric {
            let at = placement::Dual {
                surface,
                first_cone: closed.first_cone,
                labels: &labels,
                site_vertex: &diagram.site_vertex,
                faces: &faces,
                normals: &checks.normals,
            }
            .relocate();
            for (p, &v) in mesh.positions.iter_mut().zip(&origin) {
                *p = at[labels[v as usize] as usize].as_vec3().to_array();
            }
        }
        stages.dual += started.elapsed();
        Ok(VoronoiSimplified {
            mesh,
            origin,
            radius_fraction: fraction,
            sites: diagram.site_vertex.len(),
            cover_sites,
            rounds,
            splits,
            attempts: 1,
            stages,
        })
    }

    /// The used input vertices in the cover's order: crease corners, then
    /// creases, then the rest (`creases`), each in the order's own.
    fn candidates(&self) -> Vec<u32> {
        let surface = &self.closed.surface;
        let mut c: Vec<u32> = (0..self.closed.first_cone)
            .filter(|&v| !surface.faces_of(v).is_empty())
            .collect();
        if let Some(k) = self.curvature {
            c.sort_by(|&a, &b| k[b as usize].abs().total_cmp(&k[a as usize].abs()));
        }
        c.sort_by_key(|&v| self.ranks[v as usize]);
        c
    }

    /// The creases are covered first with discs of r/2, so that a point of a
    /// crease is nearer a site on it (within r/2) than any site off it (r
    /// from those, so r/2 from the point at least): neighbouring crease
    /// sites then share a Voronoi edge, and the dual joins them along the
    /// crease rather than across a face.
    fn cover(&mut self, r: f64) {
        let candidates = self.candidates();
        let first = self.site_vertex.len() as u32;
        let creases: Vec<u32> = candidates
            .iter()
            .copied()
            .filter(|&v| self.ranks[v as usize] != creases::SMOOTH)
            .collect();
        let centres = if self.options.order == Order::Farthest {
            let mut centres = Vec::new();
            for rank in [creases::CORNER, creases::CREASE] {
                let pass: Vec<u32> = creases
                    .iter()
                    .copied()
                    .filter(|&v| self.ranks[v as usize] == rank)
                    .collect();
                if !pass.is_empty() {
                    let label = first + centres.len() as u32;
                    let found = cover::farthest_points(
                        &mut self.front,
                        &pass,
                        r / 2.0,
                        self.factors,
                        label,
                    );
                    centres.extend(found);
                }
            }
            let label = first + centres.len() as u32;
            centres.extend(cover::farthest_points(
                &mut self.front,
                &candidates,
                r,
                self.factors,
                label,
            ));
            centres
        } else {
            let mut near = vec![false; self.closed.surface.vertex_count()];
            let mut centres = cover::greedy_discs(
                &mut self.scratch,
                &creases,
                r / 2.0,
                self.factors,
                &mut near,
            );
            let mut covered = vec![false; self.closed.surface.vertex_count()];
            cover::mark_discs(&mut self.scratch, &centres, r, self.factors, &mut covered);
            centres.extend(cover::greedy_discs(
                &mut self.scratch,
                &candidates,
                r,
                self.factors,
                &mut covered,
            ));
            for (i, &c) in centres.iter().enumerate() {
                self.front.seed(c, first + i as u32, 0.0);
            }
            centres
        };
        // A crease site's cell splits as the others do, from its r.
        let factor = |v: u32| self.factors.map_or(1.0, |f| f[v as usize]);
        self.radius.extend(centres.iter().map(|&c| r * factor(c)));
        self.site_vertex.extend(centres);
    }

    /// Each vertex's site; cones (which the front does not enter) their own.
    fn labels(&self) -> Vec<u32> {
        let mut labels = self.front.labels().to_vec();
        for (s, &v) in self.site_vertex.iter().enumerate() {
            if self.closed.is_cone(v) {
                labels[v as usize] = s as u32;
            }
        }
        labels
    }

    /// Splits one cell per violation (seed Alg. 5): its radius halves, its
    /// vertices now beyond it are covered by new discs of that radius, and
    /// the front re-runs from the new sites only. Returns cells split.
    fn refine(&mut self, labels: &[u32], violations: &[Violation]) -> Result<usize> {
        let members = Members::new(labels, self.site_vertex.len());
        let mut cells: Vec<u32> = violations
            .iter()
            .filter_map(|v| self.cell_to_split(v, &members))
            .collect();
        cells.sort_unstable();
        cells.dedup();
        if cells.is_empty() {
            return Err(Error::Unsupported(
                "the Voronoi diagram breaks the closed-ball property where no cell can be split"
                    .into(),
            ));
        }
        let mut covered = vec![false; self.closed.surface.vertex_count()];
        for &cell in &cells {
            let site = self.site_vertex[cell as usize];
            let r = self.radius[cell as usize] / 2.0;
            self.radius[cell as usize] = r;
            let mut orphans: Vec<u32> = members
                .of(cell)
                .iter()
                .copied()
                .filter(|&v| v != site && self.front.distance(v) >= r)
                .collect();
            if orphans.is_empty() {
                let far = members.of(cell).iter().copied().filter(|&v| v != site);
                orphans.extend(
                    far.max_by(|&a, &b| self.front.distance(a).total_cmp(&self.front.distance(b))),
                );
            }
            self.order(&mut orphans);
            for c in cover::greedy_discs(&mut self.scratch, &orphans, r, None, &mut covered) {
                self.front.seed(c, self.site_vertex.len() as u32, 0.0);
                self.site_vertex.push(c);
                self.radius.push(r);
            }
        }
        self.front.run(f64::INFINITY);
        Ok(cells.len())
    }

    /// Re-covering follows the cover's order; "farthest" takes the
    /// vertices farthest from the site first.
    /// Crease vertices come first here too.
    fn order(&self, vertices: &mut [u32]) {
        match (self.options.order, self.curvature) {
            (Order::Curvature, Some(k)) => {
                vertices.sort_by(|&a, &b| k[b as usize].abs().total_cmp(&k[a as usize].abs()))
            }
            (Order::Farthest, _) => {
                vertices.sort_by(|&a, &b| self.front.distance(b).total_cmp(&self.front.distance(a)))
            }
            _ => vertices.sort_unstable(),
        }
        vertices.sort_by_key(|&v| self.ranks[v as usize]);
    }

    /// The cell a violation splits: the one in question, or the largest of
    /// those involved (cones and one-vertex cells cannot split).
    fn cell_to_split(&self, violation: &Violation, members: &Members) -> Option<u32> {
        let involved: &[u32] = match violation {
            Violation::Cell(c) => std::slice::from_ref(c),
            Violation::Pair(a, b) => &[*a, *b],
            Violation::Triple(t) => t,
        };
        involved
            .iter()
            .copied()
            .filter(|&c| {
                !self.closed.is_cone(self.site_vertex[c as usize]) && members.of(c).len() > 1
            })
            .max_by_key(|&c| (members.of(c).len(), std::cmp::Reverse(c)))
    }
}

/// The vertices of each cell.
struct Members {
    offsets: Vec<u32>,
    vertices: Vec<u32>,
}

impl Members {
    fn new(labels: &[u32], sites: usize) -> Self {
        let mut offsets = vec![0u32; sites + 1];
        for &l in labels.iter().filter(|&&l| (l as usize) < sites) {
            offsets[l as usize + 1] += 1;
        }
        for i in 0..sites {
            offsets[i + 1] += offsets[i];
        }
        let mut next = offsets.clone();
        let mut vertices = vec![0; offsets[sites] as usize];
        for (v, &l) in labels.iter().enumerate() {
            if (l as usize) < sites {
                vertices[next[l as usize] as usize] = v as u32;
                next[l as usize] += 1;
            }
        }
        Members { offsets, vertices }
    }

    fn of(&self, cell: u32) -> &[u32] {
        &self.vertices
            [self.offsets[cell as usize] as usize..self.offsets[cell as usize + 1] as usize]
    }
}

/// The output over the input vertices its faces use, in input order.
fn compact(mesh: &IndexedMesh, faces: &[[u32; 3]]) -> (IndexedMesh, Vec<u32>) {
    let mut origin: Vec<u32> = faces.iter().flatten().copied().collect();
    origin.sort_unstable();
    origin.dedup();
    let mut index = vec![u32::MAX; mesh.positions.len()];
    for (i, &v) in origin.iter().enumerate() {
        index[v as usize] = i as u32;
    }
    let out = IndexedMesh {
        positions: origin.iter().map(|&v| mesh.positions[v as usize]).collect(),
        colors: mesh
            .colors
            .as_ref()
            .map(|c| origin.iter().map(|&v| c[v as usize]).collect()),
        triangles: faces.iter().map(|f| f.map(|v| index[v as usize])).collect(),
    };
    (out, origin)
}

/// Area of the mesh (for the search's first radius).
fn area(surface: &Surface) -> f64 {
    surface
        .triangles()
        .iter()
        .map(|t| {
            let p = t.map(|v| surface.position(v));
            (p[1] - p[0]).cross(p[2] - p[0]).length() / 2.0
        })
        .sum()
}
