//! Texel sampling shared by everything that reads a scan's texture or the
//! cell complex's atlas (the colour and quality crates).

use glam::DVec2;

/// Bilinear sample at texture coordinates with glTF's convention (v down),
/// repeating outside `[0, 1]` as glTF's default sampler does.
pub fn sample_bilinear(image: &image::RgbImage, uv: DVec2) -> [f64; 3] {
    let x = uv.x.rem_euclid(1.0) * image.width() as f64;
    let y = uv.y.rem_euclid(1.0) * image.height() as f64;
    bilinear(image, x, y, i64::rem_euclid)
}

/// Bilinear sample (0–255) at texel-space coordinates, texel centres at
/// `i + 0.5`; `edge` maps an index outside `0..n` back in (repeat or clamp).
pub fn bilinear(image: &image::RgbImage, x: f64, y: f64, edge: fn(i64, i64) -> i64) -> [f64; 3] {
    let (w, h) = (image.width() as i64, image.height() as i64);
    let (x, y) = (x - 0.5, y - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let px = |xi: i64, yi: i64| image.get_pixel(edge(xi, w) as u32, edge(yi, h) as u32).0;
    let (x0, y0) = (x0 as i64, y0 as i64);
    let (a, b, c, d) = (
        px(x0, y0),
        px(x0 + 1, y0),
        px(x0, y0 + 1),
        px(x0 + 1, y0 + 1),
    );
    std::array::from_fn(|k| {
        let top = a[k] as f64 * (1.0 - fx) + b[k] as f64 * fx;
        let bottom = c[k] as f64 * (1.0 - fx) + d[k] as f64 * fx;
        top * (1.0 - fy) + bottom * fy
    })
}
