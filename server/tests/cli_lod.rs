//! `vitrine lod`, `vitrine simplify --method melax` and MD2 through
//! `encode --frame` / `decode -o x.md2`, as a user runs them, on a generated
//! animated MD2 model and a generated scan. Every GLB written goes through
//! the Khronos glTF-Validator (web/scripts/validate-gltf.mjs) and must have
//! 0 errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;
use vitrine_mesh::export::{sample_md2, write_md2};
use vitrine_mesh::import::md2::Md2;
use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_mesh::repair::check_manifold;

fn vitrine(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vitrine"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("vitrine runs")
}

fn succeeds(args: &[&str]) -> String {
    let out = vitrine(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "vitrine {args:?} failed: {stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned() + &stderr
}

fn text(path: &Path) -> &str {
    path.to_str().expect("a UTF-8 temporary path")
}

/// The sample: a 24 × 16 torus (384 vertices) with 6 frames.
fn md2_file(dir: &Path) -> (PathBuf, Md2) {
    let model = sample_md2(24, 16, 6);
    let path = dir.join("torus.md2");
    let mut bytes = Vec::new();
    write_md2(&model, &mut bytes).unwrap();
    std::fs::write(&path, bytes).unwrap();
    (path, model)
}

/// Runs the Khronos validator on `files`; every one must have 0 errors.
fn assert_valid_gltf(files: &[PathBuf]) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let script = root.join("web/scripts/validate-gltf.mjs");
    assert!(
        root.join("web/node_modules/gltf-validator").exists(),
        "web/node_modules/gltf-validator is missing: run `npm ci` in web/ (scripts/setup.sh does)"
    );
    let out = Command::new("node")
        .arg(&script)
        .args(files)
        .output()
        .expect("node runs (needed for the glTF validator)");
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "glTF validator: {report}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines: Vec<Value> = report
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), files.len());
    for l in lines {
        assert_eq!(l["errors"], 0, "{l}");
    }
}

/// A GLB's JSON and BIN chunks.
fn glb(path: &Path) -> (Value, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(u32_at(8), bytes.len());
    let json_len = u32_at(12);
    let json = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin_at = 20 + json_len;
    let bin = bytes[bin_at + 8..bin_at + 8 + u32_at(bin_at)].to_vec();
    (json, bin)
}

/// Accessor `a`'s components as 4-byte little-endian words.
fn words(json: &Value, bin: &[u8], a: usize) -> Vec<[u8; 4]> {
    let acc = &json["accessors"][a];
    let view = &json["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let len = view["byteLength"].as_u64().unwrap() as usize;
    bin[start..start + len]
        .chunks_exact(4)
        .map(|c| c.try_into().unwrap())
        .collect()
}

fn floats(json: &Value, bin: &[u8], a: usize) -> Vec<f32> {
    words(json, bin, a)
        .into_iter()
        .map(f32::from_le_bytes)
        .collect()
}

fn indices(json: &Value, bin: &[u8], a: usize) -> Vec<u32> {
    words(json, bin, a)
        .into_iter()
        .map(u32::from_le_bytes)
        .collect()
}

#[test]
fn lod_of_an_md2_is_one_valid_glb_with_msft_lod_and_its_animation() {
    let dir = tempfile::tempdir().unwrap();
    let (input, model) = md2_file(dir.path());
    let out = dir.path().join("lod.glb");
    succeeds(&[
        "lod",
        text(&input),
        "--levels",
        "100,80,60,40,20",
        "-o",
        text(&out),
    ]);
    assert_valid_gltf(std::slice::from_ref(&out));
    let (json, bin) = glb(&out);
    let node = &json["nodes"][0];
    assert_eq!(
        node["extensions"]["MSFT_lod"]["ids"],
        serde_json::json!([1, 2, 3, 4])
    );
    assert_eq!(
        node["extras"]["MSFT_screencoverage"]
            .as_array()
            .unwrap()
            .len(),
        5
    );
    assert_eq!(json["extensionsUsed"], serde_json::json!(["MSFT_lod"]));
    // A GLB vertex is a (vertex, texture coordinate) pair: the level's
    // vertices are its distinct positions (the torus has no two alike).
    let base = floats(&json, &bin, 0);
    for (i, p) in [100usize, 80, 60, 40, 20].iter().enumerate() {
        let prim = &json["meshes"][i]["primitives"][0];
        let idx = indices(&json, &bin, prim["indices"].as_u64().unwrap() as usize);
        let mut used: Vec<[u32; 3]> = idx
            .iter()
            .map(|&v| std::array::from_fn(|c| base[3 * v as usize + c].to_bits()))
            .collect();
        used.sort_unstable();
        used.dedup();
        assert_eq!(used.len(), 384 * p / 100, "level {p} %");
        assert_eq!(prim["targets"].as_array().unwrap().len(), 5);
    }
    // Frame midpoints: the animation's LINEAR weights at (k + ½)/fps give
    // the linear interpolation of frames k and k + 1.
    let frames: Vec<Vec<[f32; 3]>> = model.frames.iter().map(|f| f.positions()).collect();
    let anim = &json["animations"][0];
    let sampler = &anim["samplers"][0];
    assert_eq!(sampler["interpolation"], "LINEAR");
    let times = floats(&json, &bin, sampler["input"].as_u64().unwrap() as usize);
    assert_eq!(times, (0..6).map(|k| k as f32 / 10.0).collect::<Vec<_>>());
    let keys = floats(&json, &bin, sampler["output"].as_u64().unwrap() as usize);
    let targets: Vec<Vec<f32>> = json["meshes"][0]["primitives"][0]["targets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| floats(&json, &bin, t["POSITION"].as_u64().unwrap() as usize))
        .collect();
    for k in 0..5 {
        let t = (k as f32 + 0.5) / 10.0;
        let s = (t - times[k]) / (times[k + 1] - times[k]);
        let weight = |j: usize| keys[k * 5 + j] * (1.0 - s) + keys[(k + 1) * 5 + j] * s;
        for g in 0..base.len() / 3 {
            // The model vertex of GLB vertex g: the one at its frame 0 position.
            let v = (0..384)
                .find(|&v| (0..3).all(|c| frames[0][v][c] == base[3 * g + c]))
                .expect("every GLB vertex is a model vertex");
            for c in 0..3 {
                let morphed: f32 = base[3 * g + c]
                    + (0..5)
                        .map(|j| weight(j) * targets[j][3 * g + c])
                        .sum::<f32>();
                let midpoint = (frames[k][v][c] + frames[k + 1][v][c]) / 2.0;
                assert!(
                    (morphed - midpoint).abs() <= 1e-5 * midpoint.abs().max(1.0),
                    "frame {k}+½ GLB vertex {g}: {morphed} vs {midpoint}"
                );
            }
        }
    }
}

#[test]
fn lod_splits_into_glbs_and_md2s_of_exact_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let (input, model) = md2_file(dir.path());
    let out = dir.path().join("knight.glb");
    succeeds(&["lod", text(&input), "--split", "-o", text(&out)]);
    let files: Vec<PathBuf> = [100, 80, 60, 40, 20]
        .iter()
        .map(|p| dir.path().join(format!("knight-{p}.glb")))
        .collect();
    assert_valid_gltf(&files);
    succeeds(&["lod", text(&input), "--format", "md2", "-o", text(&out)]);
    for p in [100usize, 80, 60, 40, 20] {
        let path = dir.path().join(format!("knight-{p}.md2"));
        let bytes = std::fs::read(&path).unwrap();
        let level = Md2::parse(&bytes, &ImportOptions::default()).unwrap();
        assert_eq!(level.vertex_count(), 384 * p / 100, "{p} %");
        assert_eq!(level.frames.len(), 6);
        // Packed vertices are the input's, bit for bit.
        for (f, g) in level.frames.iter().zip(&model.frames) {
            assert!(f
                .vertices
                .iter()
                .all(|v| g.vertices.iter().any(|w| w[..3] == v[..3])));
            assert_eq!((f.scale, f.translate), (g.scale, g.translate));
        }
        let mut again = Vec::new();
        write_md2(&level, &mut again).unwrap();
        assert_eq!(again, bytes, "{p} %: re-written byte-identical");
        let mesh = import_path(&path, &ImportOptions::default()).unwrap();
        check_manifold(&vitrine_samples::compact(mesh)).unwrap();
    }
}

#[test]
fn lod_of_a_scan_and_melax_simplify() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("plate.ply");
    let mesh = vitrine_samples::plate_with_tunnels(3, 6);
    let n = mesh.positions.len();
    let file = std::fs::File::create(&input).unwrap();
    vitrine_mesh::export::write_ply(&mesh, &mut std::io::BufWriter::new(file)).unwrap();
    let out = dir.path().join("plate.glb");
    succeeds(&[
        "lod",
        text(&input),
        "--levels",
        "100,50,20",
        "-o",
        text(&out),
    ]);
    assert_valid_gltf(std::slice::from_ref(&out));
    let want = (0.3 * n as f64).round() as usize;
    // (The plate is flat but for its tunnels, so both terms order its
    // collapses alike; codec/simplify/tests/melax.rs shows them differ.)
    for cost in ["sine", "seed"] {
        let simplified = dir.path().join(format!("melax-{cost}.glb"));
        let report = succeeds(&[
            "simplify",
            text(&input),
            "--method",
            "melax",
            "--melax-cost",
            cost,
            "--target-fraction",
            "0.3",
            "--hausdorff-samples",
            "5000",
            "-o",
            text(&simplified),
        ]);
        assert!(report.contains(&format!("→ {want} vertices")), "{report}");
        assert!(report.contains("stopped: target"), "{report}");
        let back = import_path(&simplified, &ImportOptions::default()).unwrap();
        assert_eq!(back.positions.len(), want);
        check_manifold(&back).unwrap();
        assert_valid_gltf(std::slice::from_ref(&simplified));
    }
    let wrong = vitrine(&[
        "simplify",
        text(&input),
        "--method",
        "melax",
        "--melax-cost",
        "cubic",
        "--target-fraction",
        "0.3",
        "-o",
        text(&dir.path().join("x.glb")),
    ]);
    assert!(!wrong.status.success());
    assert!(String::from_utf8_lossy(&wrong.stderr).contains("sine, seed"));
}

#[test]
fn an_md2_frame_encodes_and_decodes_to_md2() {
    let dir = tempfile::tempdir().unwrap();
    let (input, model) = md2_file(dir.path());
    let stream = dir.path().join("torus.vtr");
    succeeds(&["encode", text(&input), "--frame", "3", "-o", text(&stream)]);
    let level = dir.path().join("level.md2");
    succeeds(&["decode", text(&stream), "-o", text(&level)]);
    let back = import_path(&level, &ImportOptions::default()).unwrap();
    assert_eq!(back.positions.len(), 384);
    // Frame 3's bounding box, within the stream's and MD2's quantization.
    let frame = model.frames[3].positions();
    let extent = |ps: &[[f32; 3]], k: usize| {
        let (lo, hi) = ps
            .iter()
            .fold((f32::MAX, f32::MIN), |(l, h), p| (l.min(p[k]), h.max(p[k])));
        hi - lo
    };
    for k in 0..3 {
        let (a, b) = (extent(&back.positions, k), extent(&frame, k));
        assert!((a - b).abs() < 0.02 * b.max(1.0), "axis {k}: {a} vs {b}");
    }
    let missing = vitrine(&["encode", text(&input), "--frame", "6", "-o", text(&stream)]);
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("has 6 frames"));
}

/// Writes `name` (an RGB test pattern of `w × h`) into `dir`.
fn write_png(dir: &Path, name: &str, (w, h): (u32, u32)) {
    image::RgbImage::from_fn(w, h, |x, y| image::Rgb([(x * 4) as u8, (y * 8) as u8, 77]))
        .save(dir.join(name))
        .unwrap();
}

/// Accessor `a` of a primitive's attribute `name`.
fn attribute(json: &Value, level: usize, name: &str) -> usize {
    json["meshes"][level]["primitives"][0]["attributes"][name]
        .as_u64()
        .unwrap_or_else(|| panic!("level {level} has no {name}")) as usize
}

#[test]
fn lod_glbs_carry_the_md2_skin_and_its_texture_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let (input, model) = md2_file(dir.path());
    write_png(dir.path(), "skin.png", (64, 32));
    let out = dir.path().join("skinned.glb");
    succeeds(&["lod", text(&input), "--levels", "100,30", "-o", text(&out)]);
    assert_valid_gltf(std::slice::from_ref(&out));
    let (json, bin) = glb(&out);
    assert_eq!(json["images"][0]["mimeType"], "image/png");
    let material = &json["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"];
    assert_eq!(material["index"], 0);
    let base = floats(&json, &bin, 0);
    let uvs = floats(&json, &bin, attribute(&json, 0, "TEXCOORD_0"));
    assert_eq!(uvs.len() / 2, base.len() / 3);
    // Every GLB vertex is a (vertex, st) pair of the model's triangles:
    // positions and coordinates carry over per kept vertex, and a seam
    // vertex keeps one GLB vertex per side.
    let frame = model.frames[0].positions();
    let pairs: std::collections::HashSet<[u32; 5]> = model
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |c| (t.vertex[c] as usize, t.st[c] as usize)))
        .map(|(v, st)| {
            let [s, t] = model.st[st];
            let uv = [f32::from(s) / 64.0, f32::from(t) / 32.0];
            [frame[v][0], frame[v][1], frame[v][2], uv[0], uv[1]].map(f32::to_bits)
        })
        .collect();
    for g in 0..uvs.len() / 2 {
        let pair = [
            base[3 * g],
            base[3 * g + 1],
            base[3 * g + 2],
            uvs[2 * g],
            uvs[2 * g + 1],
        ]
        .map(f32::to_bits);
        assert!(
            pairs.contains(&pair),
            "GLB vertex {g} is no vertex of the model"
        );
    }
    assert!(uvs.len() / 2 > 384, "the seam's vertices are split");
    // The coarse level uses the same material.
    assert_eq!(json["meshes"][1]["primitives"][0]["material"], 0);
}

#[test]
fn lod_glbs_of_a_textured_and_of_a_coloured_scan() {
    let dir = tempfile::tempdir().unwrap();
    // A textured OBJ: a 12 × 12 grid, texture coordinates from its plan.
    let grid = vitrine_samples::grid(12);
    let mut obj = String::from("mtllib grid.mtl\nusemtl skin\n");
    for p in &grid.positions {
        obj += &format!(
            "v {} {} {}\nvt {} {}\n",
            p[0],
            p[1],
            p[2],
            p[0] / 12.0,
            p[1] / 12.0
        );
    }
    for t in &grid.triangles {
        let [a, b, c] = t.map(|v| v + 1);
        obj += &format!("f {a}/{a} {b}/{b} {c}/{c}\n");
    }
    std::fs::write(dir.path().join("grid.obj"), obj).unwrap();
    std::fs::write(dir.path().join("grid.mtl"), "newmtl skin\nmap_Kd tex.png\n").unwrap();
    write_png(dir.path(), "tex.png", (16, 8));
    let out = dir.path().join("grid.glb");
    let input = dir.path().join("grid.obj");
    succeeds(&[
        "lod",
        text(&input),
        "--levels",
        "100,50",
        "--split",
        "-o",
        text(&out),
    ]);
    let files = [
        dir.path().join("grid-100.glb"),
        dir.path().join("grid-50.glb"),
    ];
    assert_valid_gltf(&files);
    for f in &files {
        let (json, bin) = glb(f);
        let base = floats(&json, &bin, 0);
        let uvs = floats(&json, &bin, attribute(&json, 0, "TEXCOORD_0"));
        for g in 0..uvs.len() / 2 {
            // The OBJ's own coordinate of the kept vertex (v = 1 − y / 12:
            // OBJ's rows count from the bottom, glTF's from the top).
            let want = [base[3 * g] / 12.0, 1.0 - base[3 * g + 1] / 12.0];
            assert!(
                (uvs[2 * g] - want[0]).abs() < 1e-6 && (uvs[2 * g + 1] - want[1]).abs() < 1e-6,
                "{}: GLB vertex {g}",
                f.display()
            );
        }
        assert!(json["images"][0]["bufferView"].is_u64());
    }
    // A coloured PLY: COLOR_0 holds each kept vertex's colour, linear.
    let mut plate = vitrine_samples::plate_with_tunnels(2, 5);
    vitrine_samples::paint(&mut plate);
    let input = dir.path().join("plate.ply");
    let file = std::fs::File::create(&input).unwrap();
    vitrine_mesh::export::write_ply(&plate, &mut std::io::BufWriter::new(file)).unwrap();
    let out = dir.path().join("plate.glb");
    succeeds(&["lod", text(&input), "--levels", "100,40", "-o", text(&out)]);
    assert_valid_gltf(std::slice::from_ref(&out));
    let (json, bin) = glb(&out);
    let base = floats(&json, &bin, 0);
    let colours = floats(&json, &bin, attribute(&json, 1, "COLOR_0"));
    let srgb = |l: f32| {
        let s = if l <= 0.003_130_8 {
            12.92 * l
        } else {
            1.055 * l.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round() as u8
    };
    let colour_of = |p: [f32; 3]| {
        let v = plate
            .positions
            .iter()
            .position(|q| *q == p)
            .expect("a plate vertex");
        plate.colors.as_ref().unwrap()[v]
    };
    for g in 0..base.len() / 3 {
        let p = [base[3 * g], base[3 * g + 1], base[3 * g + 2]];
        let got = [0, 1, 2].map(|c| srgb(colours[3 * g + c]));
        assert_eq!(got, colour_of(p), "GLB vertex {g}");
    }
}

#[test]
fn lod_repairs_a_slightly_broken_md2_as_every_other_import() {
    // The sample, plus what real models carry: a third face on one edge
    // (non-manifold) and a face with a repeated corner (degenerate).
    let mut model = sample_md2(24, 16, 3);
    let first = model.triangles[0];
    model
        .triangles
        .push(vitrine_mesh::import::md2::Md2Triangle {
            vertex: [first.vertex[1], first.vertex[0], 200],
            st: [first.st[1], first.st[0], 0],
        });
    model
        .triangles
        .push(vitrine_mesh::import::md2::Md2Triangle {
            vertex: [5, 5, 6],
            st: [5, 5, 6],
        });
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("broken.md2");
    let mut bytes = Vec::new();
    write_md2(&model, &mut bytes).unwrap();
    std::fs::write(&input, bytes).unwrap();
    let out = dir.path().join("broken.glb");
    let log = succeeds(&["lod", text(&input), "--format", "md2", "-o", text(&out)]);
    assert!(
        log.contains("repair:") && log.contains("non-manifold"),
        "{log}"
    );
    assert!(log.contains("degenerate"), "{log}");
    let mut sizes = Vec::new();
    for p in [100usize, 80, 60, 40, 20] {
        let path = dir.path().join(format!("broken-{p}.md2"));
        let level = Md2::parse(&std::fs::read(&path).unwrap(), &ImportOptions::default()).unwrap();
        assert_eq!(level.frames.len(), 3);
        sizes.push(level.vertex_count());
        let mesh = import_path(&path, &ImportOptions::default()).unwrap();
        check_manifold(&vitrine_samples::compact(mesh)).unwrap();
    }
    // The split copies a vertex or more: exact percentages of the repaired model.
    assert!(sizes[0] > 384, "{sizes:?}");
    for (p, &n) in [100usize, 80, 60, 40, 20].iter().zip(&sizes) {
        assert_eq!(n, sizes[0] * p / 100, "{p} %");
    }
    // A GLB as well, valid.
    succeeds(&["lod", text(&input), "-o", text(&out)]);
    assert_valid_gltf(std::slice::from_ref(&out));
}
