//! The progressive point stream (format in `codec/points/FORMAT.md`).
//!
//! Positions are quantized to a cube of 2^bits cells per axis and coded as an
//! octree in level order: each occupied cell's 8-bit child-occupancy mask,
//! range-coded with adaptive models chosen by the occupied neighbours the
//! decoder already knows (version 2, `context.rs`) or, in version 1 streams
//! and where no neighbour is occupied, by the parent's occupancy. Every
//! occupied cell has a representative point; a cell's first occupied child
//! keeps it and the others bring one new point each, so the points ordered
//! by the depth at which they appear put one point per occupied cell of
//! depth d before any point of depth d + 1: every level is a prefix of the
//! final order and an even subsample of the whole. Normals (octahedral) and
//! colours of a new point are coded as residuals against its parent's
//! representative or, with header flag bit 2, against a prediction from the
//! decoded points near it (`predict.rs`). Several points in one finest cell
//! are coded as a count.
//!
//! The stream is a header plus one self-delimiting chunk per level; the
//! decoder reproduces the quantized positions, normals and colours bit for
//! bit, in the stream's order.

mod attr;
mod context;
mod decode;
mod encode;
mod format;
mod models;
mod neighbourhood;
mod occupancy;
mod predict;
mod probability;
mod region;

pub use attr::{octahedral_decode, octahedral_encode};
pub use decode::{decode, DecodedPoints, Limits, PointDecoder};
pub use encode::{encode, EncodeOptions, EncodedPoints};
pub use format::{split, PointHeader, MAGIC, VERSION, VERSIONS};
