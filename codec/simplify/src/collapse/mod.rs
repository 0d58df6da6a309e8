//! The standalone multiresolution (seed 004, Alg. 1, 4 and 5, with the
//! fixes in SEEDS.md): passes of edge, half-edge or triangle collapses over
//! the vertices that are neither on a border nor near a feature, each merge
//! checked first (link condition, flip rejection), then the seed's
//! clean-up, until an exact vertex count.
//!
//! **Which θ decides.** A vertex is removable when the one-ring maximum of
//! θ on the *full resolution* is at most τ, the threshold also fixed once
//! from the full resolution; a merged vertex carries the largest value of
//! the vertices it stands for. The one-ring maximum because θ alone marks
//! the band beside a ridge and not its crest (SEEDS.md 004: a one-vertex
//! guard erodes ridges). The full resolution's because τ is measured
//! there: θ of a coarser mesh grows with its edge length on any curved
//! surface, so comparing it with τ would freeze a smooth sphere after a
//! pass or two and the target could never be met; and features are those
//! of the scan, not of its approximation. Flip rejection, not θ, guards
//! the coarse surface's shape. It also spares recomputing θ every pass.
//!
//! **What the seed lacks, as options.** [`Placement::Quadric`] puts a
//! merged vertex where the Garland–Heckbert quadric of the patch it stands
//! for is least and tries the cheapest merges first, instead of the seed's
//! midpoints and centroids, which drift the surface pass after pass.
//! [`Features::Last`] lets features go once nothing else can: when a pass
//! finds no candidate above the target, τ rises to free the least sharp
//! of the protected vertices, so a target is always met unless only
//! borders are left; [`Features::Keep`] is the seed's rule (never). With
//! quadric placement τ also rises as soon as the protected vertices would
//! merge more cheaply than the candidates (medians of their cheapest
//! merges): on a noisy scan mean + 2σ of θ protects the noise, and
//! simplifying around it cut bunny's ears through (Hausdorff 4.2× quadric's
//! at 10 %, issue 45); a pass then merges only its cheaper half.

mod cleanup;
mod pass;
pub(crate) mod quadric;
pub(crate) mod topology;
pub(crate) mod working;

use std::str::FromStr;

use vitrine_codec::{Error, IndexedMesh, Result};

use crate::FeatureThreshold;
use pass::Pass;
use working::WorkingMesh;

/// How a pass removes vertices (seed 004, §2.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Collapse {
    /// Both ends of an edge to its midpoint: −1 vertex, −2 faces.
    #[default]
    Edge,
    /// One end into the other, which stays put: −1 vertex, −2 faces.
    HalfEdge,
    /// A face's corners to its centroid: −2 vertices, −4 faces.
    Triangle,
}

impl FromStr for Collapse {
    type Err = Error;

    /// `edge`, `half-edge` or `triangle`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "edge" => Ok(Collapse::Edge),
            "half-edge" => Ok(Collapse::HalfEdge),
            "triangle" => Ok(Collapse::Triangle),
            _ => Err(Error::Parameter(format!(
                "collapse must be edge, half-edge or triangle, got {s:?}"
            ))),
        }
    }
}

/// Where a merged vertex goes, and which merges go first.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Placement {
    /// The seed's: the midpoint of an edge, the centroid of a triangle;
    /// vertices in ascending θ, each to its nearest neighbour.
    #[default]
    Seed,
    /// The least squared distance to the planes of the input faces the
    /// merged vertices stand for (Garland–Heckbert); within a pass the
    /// cheapest merges first.
    Quadric,
}

impl FromStr for Placement {
    type Err = Error;

    /// `seed` or `quadric`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "seed" => Ok(Placement::Seed),
            "quadric" => Ok(Placement::Quadric),
            _ => Err(Error::Parameter(format!(
                "placement must be seed or quadric, got {s:?}"
            ))),
        }
    }
}

/// What happens to feature vertices (θ above τ) on the way to the target.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Features {
    /// Never removed nor moved (the seed): simplification may stop short.
    Keep,
    /// Removed last: when nothing else can go, τ rises to free the half of
    /// the remaining protected vertices (or twice the vertices still to
    /// remove, if fewer) with the lowest θ.
    #[default]
    Last,
}

/// Where to stop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Target {
    /// This many vertices in the output.
    Vertices(usize),
    /// This fraction (0–1) of the input's used vertices, rounded.
    Fraction(f64),
}

impl Default for Target {
    fn default() -> Self {
        Target::Fraction(0.5)
    }
}

impl FromStr for Target {
    type Err = Error;

    /// A vertex count (`5000`) or a percentage (`25%`).
    fn from_str(s: &str) -> Result<Self> {
        let s = s.trim();
        let target = match s.strip_suffix('%') {
            Some(p) => p
                .trim()
                .parse::<f64>()
                .ok()
                .map(|p| Target::Fraction(p / 100.0)),
            None => s.parse().ok().map(Target::Vertices),
        };
        let target = target.ok_or_else(|| {
            Error::Parameter(format!(
                "target must be a vertex count (5000) or a percentage (25%), got {s:?}"
            ))
        })?;
        target.validate()?;
        Ok(target)
    }
}

impl Target {
    pub(crate) fn validate(self) -> Result<()> {
        match self {
            Target::Fraction(f) if !(0.0..=1.0).contains(&f) => Err(Error::Parameter(format!(
                "target fraction must be within 0–1, got {f}"
            ))),
            _ => Ok(()),
        }
    }

    pub(crate) fn vertices(self, used: usize) -> usize {
        match self {
            Target::Vertices(n) => n,
            Target::Fraction(f) => (f * used as f64).round() as usize,
        }
    }
}

/// Parameters of [`simplify`].
#[derive(Clone, Debug, PartialEq)]
pub struct SimplifyOptions {
    pub collapse: Collapse,
    pub target: Target,
    /// Where features start, in θ of the full resolution.
    pub threshold: FeatureThreshold,
    /// Passes at most (each one freezes the neighbours of its merges).
    pub max_passes: usize,
    pub placement: Placement,
    pub features: Features,
}

impl Default for SimplifyOptions {
    fn default() -> Self {
        SimplifyOptions {
            collapse: Collapse::Edge,
            target: Target::default(),
            threshold: FeatureThreshold::MeanPlusTwoSigma,
            max_passes: 200,
            placement: Placement::Seed,
            features: Features::Last,
        }
    }
}

/// Why simplification stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// The output has exactly the target vertex count (or the input had
    /// no more than that).
    Target,
    /// No removable vertex could be merged without breaking a check: the
    /// rest are borders, features ([`Features::Keep`]), or locked by the
    /// topology.
    NoCandidate,
    /// `max_passes` passes ran.
    MaxPasses,
}

/// What the seed's clean-up (Alg. 5) found after a pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Cleanup {
    /// Faces deleted for sharing their three vertices with another face.
    pub duplicates: usize,
    /// Valence-3 spikes whose three faces became one.
    pub pyramids: usize,
    /// Faces reversed for running against their neighbours.
    pub flipped: usize,
}

/// One pass, as it ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassReport {
    /// Vertex merges made (a full triangle collapse is two).
    pub merges: usize,
    /// Used vertices and live faces after the pass and its clean-up.
    pub vertices: usize,
    pub faces: usize,
    pub cleanup: Cleanup,
}

/// The simplified mesh and how it came about.
#[derive(Clone, Debug)]
pub struct Simplified {
    /// Compacted: unused vertices dropped, the rest in input order.
    pub mesh: IndexedMesh,
    /// For each output vertex, the input vertex whose slot it kept: equal
    /// positions for every vertex that never moved (borders, features).
    pub origin: Vec<u32>,
    /// The passes that changed the mesh, in order.
    pub passes: Vec<PassReport>,
    pub stopped: StopReason,
    /// τ in radians, from the full resolution.
    pub threshold_radians: f64,
    /// τ at the end: above `threshold_radians` when [`Features::Last`]
    /// had to free feature vertices to reach the target.
    pub final_threshold_radians: f64,
}

/// Simplifies `mesh` (an oriented 2-manifold, borders allowed: what
/// `vitrine_mesh::repair::prepare` produces) down to `options.target`
/// vertices. Deterministic: the same input and options give the same bytes.
pub fn simplify(mesh: &IndexedMesh, options: &SimplifyOptions) -> Result<Simplified> {
    run(mesh, options, None)
}

/// [`simplify`], calling `on_pass` after every pass with its report, the
/// compacted mesh as it stands and each vertex's origin (compacting costs
/// a copy of the mesh per pass).
pub fn simplify_with(
    mesh: &IndexedMesh,
    options: &SimplifyOptions,
    mut on_pass: impl FnMut(&PassReport, &IndexedMesh, &[u32]),
) -> Result<Simplified> {
    run(mesh, options, Some(&mut on_pass))
}

type OnPass<'a> = &'a mut dyn FnMut(&PassReport, &IndexedMesh, &[u32]);

fn run(
    mesh: &IndexedMesh,
    options: &SimplifyOptions,
    mut on_pass: Option<OnPass<'_>>,
) -> Result<Simplified> {
    options.target.validate()?;
    let (working, mut threshold) = WorkingMesh::new(mesh, options.threshold)?;
    let first_threshold = threshold;
    let mut working = match options.placement {
        Placement::Seed => working,
        Placement::Quadric => working.with_quadrics(),
    };
    let target = options.target.vertices(working.live_vertices);
    let mut passes = Vec::new();
    // Triangle collapses make dear merges only once no feature is left to
    // free: a feature's triangles along its crease cost nothing, and the
    // dear ones cut across it (the genus-3 plate's edges, 6–9 % of its
    // diagonal). Edge merges into a feature's vertex need no such wait.
    let mut dear = options.collapse != Collapse::Triangle;
    let stopped = loop {
        if working.live_vertices <= target {
            break StopReason::Target;
        }
        if passes.len() >= options.max_passes {
            break StopReason::MaxPasses;
        }
        let mut pass = Pass::new(&mut working, options, threshold, target, dear);
        if options.features == Features::Last
            && options.placement == Placement::Quadric
            && pass.features_cheaper()
        {
            if let Some(raised) = release(pass.mesh(), threshold, target) {
                threshold = raised;
                continue;
            }
        }
        let merges = pass.run();
        let cleanup = cleanup::clean(&mut working, threshold, target);
        if merges == 0 && cleanup == Cleanup::default() {
            let raised = match options.features {
                Features::Last => release(&working, threshold, target),
                Features::Keep => None,
            };
            match raised {
                Some(raised) => threshold = raised,
                None if !dear => dear = true,
                None => break StopReason::NoCandidate,
            }
            continue;
        }
        let report = PassReport {
            merges,
            vertices: working.live_vertices,
            faces: working.live_faces(),
            cleanup,
        };
        if let Some(f) = on_pass.as_mut() {
            let (mesh, origin) = working.compact();
            f(&report, &mesh, &origin);
        }
        passes.push(report);
    };
    let (mesh, origin) = working.compact();
    Ok(Simplified {
        mesh,
        origin,
        passes,
        stopped,
        threshold_radians: first_threshold,
        final_threshold_radians: threshold,
    })
}

/// The τ that frees the lowest-θ half of the live, off-border vertices
/// above `threshold` (or twice as many as are still to go, if fewer);
/// `None` when there are none (only borders are left).
fn release(working: &WorkingMesh, threshold: f64, target: usize) -> Option<f64> {
    let mut protected: Vec<f64> = (0..working.positions.len())
        .filter(|&v| !working.border[v] && !working.faces_of[v].is_empty())
        .map(|v| working.theta[v])
        .filter(|&t| t > threshold)
        .collect();
    if protected.is_empty() {
        return None;
    }
    protected.sort_by(f64::total_cmp);
    let still = working.live_vertices.saturating_sub(target);
    let count = (protected.len() / 2).min(2 * still).max(1);
    Some(protected[count - 1])
}
