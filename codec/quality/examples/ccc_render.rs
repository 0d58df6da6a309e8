//! CPU snapshots of a stream's levels coloured by its cell complex (as
//! written by `vitrine encode --colour ccc`) or its vertex colours, for a look
//! by eye:
//!
//!     cargo run --release -p vitrine-quality --example ccc_render -- STREAM OUT_PREFIX [VIEW] [LEVEL...]

use vitrine_codec::{Decoder, Limits, StreamIndex};
use vitrine_colour::ccc::{CccParameters, CellComplex};
use vitrine_quality::metrics::{self, views, RenderOptions, SurfaceShader};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let stream = std::fs::read(&args[0]).expect("stream");
    let side = |s: &str| format!("{}{s}", args[0]);
    let complex = std::fs::read(side(".ccc.json")).ok().map(|json| {
        let p: CccParameters = serde_json::from_slice(&json).expect("parameters");
        CellComplex::from_images(
            &p,
            &std::fs::read(side(".cell.png")).unwrap(),
            &std::fs::read(side(".colour.jpg")).unwrap(),
        )
        .expect("complex")
    });
    let view: usize = args.get(2).map_or(0, |v| v.parse().unwrap());
    let index = StreamIndex::parse(&stream).unwrap();
    let last = index.batches.len();
    let levels: Vec<usize> = if args.len() > 3 {
        args[3..].iter().map(|l| l.parse().unwrap()).collect()
    } else {
        vec![0, last / 2, last]
    };
    let mut d = Decoder::new(&stream[index.base.clone()], Limits::default()).unwrap();
    let full = vitrine_codec::decode(&stream, None, Limits::default())
        .unwrap()
        .to_mesh();
    let (centre, radius) = views::bounding_sphere(&full);
    let camera = views::rhombicuboctahedron(centre, radius)[view];
    for level in 0..=last {
        if level > 0 {
            d.apply_batch(&stream[index.batches[level - 1].clone()])
                .unwrap();
        }
        if !levels.contains(&level) {
            continue;
        }
        let mesh = d.to_mesh();
        let shader: Box<dyn SurfaceShader + '_> = match &complex {
            Some(c) => Box::new(c.clone()),
            None => metrics::default_shader(&mesh),
        };
        let frame = metrics::render(&mesh, shader.as_ref(), &camera, &RenderOptions::square(512));
        let out = format!("{}-level{level}.png", args[1]);
        frame.write_png(&out).unwrap();
        println!("{out}: {} vertices", mesh.positions.len());
    }
}
