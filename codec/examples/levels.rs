//! Prints the level table of a generated mesh's stream: `cargo run --example levels`.
use vitrine_codec::samples::{icosphere, torus};
use vitrine_codec::{encode, EncodeOptions};

fn main() {
    for (name, mesh) in [("icosphere(6)", icosphere(6)), ("torus 400x160", torus(400, 160, 1.0, 0.3))] {
        let e = encode(&mesh, &EncodeOptions::default()).unwrap();
        println!("{name}: {} vertices, {} bytes, {:.3} bits/vertex", mesh.positions.len(), e.bytes.len(), e.bytes.len() as f64 * 8.0 / mesh.positions.len() as f64);
        for (k, l) in e.header.levels.iter().enumerate() {
            println!("  level {k:2}: {:8} vertices {:8} faces {:8} bytes", l.vertices, l.faces, l.bytes);
        }
    }
}
