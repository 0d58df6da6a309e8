//! Geodesic distance on a triangle mesh: the length of the shortest path
//! along the surface, for the viewer's measurement tool and the intrinsic
//! Voronoi simplifier (seed 001, `vitrine-simplify`).
//!
//! Two ways across the surface ([`Method`]): Dijkstra on the edge lengths
//! (an upper bound: paths bend at vertices) and fast marching on the faces
//! (never longer than Dijkstra, exact on a plane; obtuse corners unfolded).
//! One [`Propagation`] carries any number of labelled sources at once, and
//! takes more sources after a run, re-opening only what they bring closer.
//!
//! ```
//! use vitrine_geodesic::{distance_field, point_distance, Method, Surface, SurfacePoint};
//! use glam::DVec3;
//! let surface = Surface::new(&vitrine_samples::grid(20))?;
//! let from = SurfacePoint::nearest(&surface, DVec3::new(2.0, 2.0, 0.0)).unwrap();
//! let to = SurfacePoint::nearest(&surface, DVec3::new(14.0, 7.0, 0.0)).unwrap();
//! let d = point_distance(&surface, &from, &to, Method::FastMarching);
//! assert!((d - 13.0).abs() < 1e-9); // a plane: the straight line
//! let field = distance_field(&surface, &from, Method::Dijkstra);
//! assert_eq!(field.len(), 21 * 21);
//! # Ok::<(), vitrine_codec::Error>(())
//! ```
//!
//! Builds for `wasm32-unknown-unknown` (its only dependencies are
//! `vitrine-codec` and `glam`); `vitrine-wasm` exports it to the viewer.
#![forbid(unsafe_code)]

mod field;
mod march;
mod point;
mod propagation;
mod surface;

pub use field::{distance_field, point_distance};
pub use point::SurfacePoint;
pub use propagation::{Method, Propagation, UNREACHED};
pub use surface::{Surface, MAX_FACES, NONE};
