//! The native side of `web/test/geodesic.test.mjs`: the geodesic distances
//! the WebAssembly build must reproduce, on a small torus, written into
//! `web/test/fixtures/geodesic-torus.json`. Fails when the committed file
//! is not what the library computes today; `VITRINE_BLESS=1` rewrites it.

use std::fmt::Write;
use std::path::Path;

use glam::DVec3;
use vitrine_geodesic::{distance_field, point_distance, Method, Surface, SurfacePoint};

const FROM: [f64; 3] = [1.35, 0.0, 0.0];
const TO: [[f64; 3]; 4] = [
    [-1.35, 0.0, 0.0],
    [0.0, 0.65, 0.0],
    [0.7, 0.7, 0.35],
    [1.0, -0.2, -0.33],
];

fn numbers(values: impl IntoIterator<Item = f64>) -> String {
    let items: Vec<String> = values.into_iter().map(|v| format!("{v:?}")).collect();
    items.join(",")
}

fn fixture() -> String {
    let mesh = vitrine_samples::torus(24, 12, 1.0, 0.35);
    let surface = Surface::new(&mesh).unwrap();
    let point = |p: [f64; 3]| SurfacePoint::nearest(&surface, DVec3::from(p)).unwrap();
    let mut json = String::from("{\n");
    let positions = mesh.positions.iter().flatten().map(|&c| f64::from(c));
    let indices: Vec<String> = mesh
        .triangles
        .iter()
        .flatten()
        .map(u32::to_string)
        .collect();
    writeln!(json, "  \"positions\": [{}],", numbers(positions)).unwrap();
    writeln!(json, "  \"indices\": [{}],", indices.join(",")).unwrap();
    writeln!(json, "  \"from\": [{}],", numbers(FROM)).unwrap();
    json.push_str("  \"distances\": [\n");
    let mut rows = Vec::new();
    for (code, method) in [(0, Method::Dijkstra), (1, Method::FastMarching)] {
        for to in TO {
            let d = point_distance(&surface, &point(FROM), &point(to), method);
            rows.push(format!(
                "    {{ \"method\": {code}, \"to\": [{}], \"distance\": {d:?} }}",
                numbers(to)
            ));
        }
    }
    json.push_str(&rows.join(",\n"));
    json.push_str("\n  ],\n");
    let field = distance_field(&surface, &point(FROM), Method::FastMarching);
    writeln!(
        json,
        "  \"field\": {{ \"method\": 1, \"values\": [{}] }}",
        numbers(field)
    )
    .unwrap();
    json.push_str("}\n");
    json
}

#[test]
fn the_committed_fixture_is_what_the_native_library_computes() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../web/test/fixtures/geodesic-torus.json");
    let now = fixture();
    if std::env::var_os("VITRINE_BLESS").is_some() {
        std::fs::write(&path, &now).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == now,
        "{} is not what vitrine-geodesic computes; if the change is meant, run \
         VITRINE_BLESS=1 cargo test -p vitrine-wasm --test geodesic_fixture",
        path.display()
    );
}
