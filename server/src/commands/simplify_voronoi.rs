//! `vitrine simplify --method voronoi`: the intrinsic Voronoi simplifier
//! (seed 001) behind the shared `simplify` report. Its own flags, and how
//! the shared target flags read for it: `--target-vertices N` searches the
//! radius whose output has the vertex count nearest to N (the method keeps
//! topology, so it cannot stop at an exact count), `--target-fraction F`
//! means N = F × the input's vertices, and `--radius R` fixes r.

use clap::{Args, ValueEnum};
use serde::Serialize;
use vitrine_codec::IndexedMesh;
use vitrine_simplify::{
    simplify_voronoi, Distance, Order, Radius, VoronoiOptions, VoronoiPlacement, VoronoiSpacing,
    SHARP_DEGREES,
};

/// How geodesic distance is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DistanceKind {
    /// Shortest paths along edges.
    Dijkstra,
    /// Fast marching across faces (never longer than Dijkstra).
    Fmm,
}

/// In which order disc centres are taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OrderKind {
    /// Vertex order.
    Incremental,
    /// The vertex farthest from the centres so far.
    Farthest,
    /// Largest Gaussian curvature |K| first.
    Curvature,
}

/// Where each output vertex goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum VoronoiPlacementKind {
    /// At its site, an input vertex (the seed's method: the output's
    /// vertices are a subset of the input's, bit for bit).
    Sites,
    /// At the minimum of its cell's quadric error (Valette et al.'s ACVD
    /// relocation): closer to the surface, vertices no longer the input's.
    Quadric,
}

/// How far apart the sites are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum VoronoiSpacingKind {
    /// One disc radius everywhere (the seed's cover).
    Uniform,
    /// Smaller discs where the surface bends within a cell's reach, larger
    /// where it is flat, then denser again where the error stayed largest.
    Adaptive,
}

#[derive(Args, Debug)]
pub struct VoronoiArgs {
    /// voronoi: where each output vertex goes.
    #[arg(long, value_enum, default_value_t = VoronoiPlacementKind::Sites)]
    pub voronoi_placement: VoronoiPlacementKind,
    /// voronoi: one cover radius everywhere (the seed's), or adapted to the
    /// surface (smaller where it bends or where the error stayed largest).
    #[arg(long, value_enum, default_value_t = VoronoiSpacingKind::Adaptive)]
    pub voronoi_spacing: VoronoiSpacingKind,
    /// voronoi: geodesic distance by Dijkstra on edges or fast marching.
    #[arg(long, value_enum, default_value_t = DistanceKind::Dijkstra)]
    pub distance: DistanceKind,
    /// voronoi: the order disc centres are taken in.
    #[arg(long, value_enum, default_value_t = OrderKind::Farthest)]
    pub order: OrderKind,
    /// voronoi: edges whose faces turn by this many degrees or more are
    /// creases, whose vertices become sites first (0: the seed's cover).
    #[arg(long, default_value_t = SHARP_DEGREES)]
    pub sharp_degrees: f64,
}

/// What the report adds for this method.
#[derive(Clone, Debug, Serialize)]
pub struct VoronoiReport {
    pub distance: &'static str,
    pub placement: &'static str,
    pub spacing: &'static str,
    pub order: &'static str,
    /// r over the bounding box's diagonal (given, or found by the search).
    pub radius: f64,
    pub sites: usize,
    pub cover_sites: usize,
    pub splits: usize,
    /// Radii tried to meet a vertex target.
    pub attempts: usize,
}

/// The shared target flags, as this method reads them.
#[derive(Clone, Copy, Debug)]
pub struct TargetFlags {
    pub radius: Option<f64>,
    pub target_vertices: Option<u64>,
    pub target_fraction: Option<f64>,
}

/// What the method made: the mesh, refinement rounds (the report's
/// passes), why it stopped (`radius`, `target` or `nearest`) and its part
/// of the report.
pub struct Simplified {
    pub mesh: IndexedMesh,
    pub rounds: usize,
    pub stopped: &'static str,
    pub report: VoronoiReport,
}

pub fn run(mesh: &IndexedMesh, args: &VoronoiArgs, t: TargetFlags) -> anyhow::Result<Simplified> {
    let radius = match (t.radius, t.target_vertices, t.target_fraction) {
        (Some(r), _, _) => Radius::Fraction(r),
        (None, Some(n), _) => Radius::TargetVertices(n as usize),
        (None, None, Some(f)) => {
            Radius::TargetVertices(((f * mesh.vertex_count() as f64).round() as usize).max(1))
        }
        (None, None, None) => {
            anyhow::bail!("give --radius, --target-vertices or --target-fraction")
        }
    };
    let (distance, distance_name) = match args.distance {
        DistanceKind::Dijkstra => (Distance::Dijkstra, "dijkstra"),
        DistanceKind::Fmm => (Distance::FastMarching, "fmm"),
    };
    let (order, order_name) = match args.order {
        OrderKind::Incremental => (Order::Incremental, "incremental"),
        OrderKind::Farthest => (Order::Farthest, "farthest"),
        OrderKind::Curvature => (Order::Curvature, "curvature"),
    };
    if !(0.0..=180.0).contains(&args.sharp_degrees) {
        anyhow::bail!(
            "--sharp-degrees must be within 0–180, got {}",
            args.sharp_degrees
        );
    }
    let (placement, placement_name) = match args.voronoi_placement {
        VoronoiPlacementKind::Sites => (VoronoiPlacement::Sites, "sites"),
        VoronoiPlacementKind::Quadric => (VoronoiPlacement::Quadric, "quadric"),
    };
    let (spacing, spacing_name) = match args.voronoi_spacing {
        VoronoiSpacingKind::Uniform => (VoronoiSpacing::Uniform, "uniform"),
        VoronoiSpacingKind::Adaptive => (VoronoiSpacing::Adaptive, "adaptive"),
    };
    let options = VoronoiOptions {
        distance,
        placement,
        spacing,
        order,
        radius,
        sharp_degrees: (args.sharp_degrees > 0.0).then_some(args.sharp_degrees),
        ..VoronoiOptions::default()
    };
    let out = simplify_voronoi(mesh, &options)?;
    let stopped = match radius {
        Radius::Fraction(_) => "radius",
        Radius::TargetVertices(n) if n == out.mesh.vertex_count() => "target",
        Radius::TargetVertices(_) => "nearest",
    };
    Ok(Simplified {
        rounds: out.rounds,
        stopped,
        report: VoronoiReport {
            distance: distance_name,
            placement: placement_name,
            spacing: spacing_name,
            order: order_name,
            radius: out.radius_fraction,
            sites: out.sites,
            cover_sites: out.cover_sites,
            splits: out.splits,
            attempts: out.attempts,
        },
        mesh: out.mesh,
    })
}

/// The report's extra words.
pub fn describe(v: &VoronoiReport) -> String {
    format!(
        " ({} distance, {} order, {} spacing, vertices at the {}, r = {:.5} × diagonal, {} sites from {} discs, {} splits, {} radii tried)",
        v.distance, v.order, v.spacing, v.placement, v.radius, v.sites, v.cover_sites, v.splits, v.attempts
    )
}
