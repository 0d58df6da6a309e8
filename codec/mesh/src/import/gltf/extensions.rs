//! The glTF extensions a file may require, and what the importer does with
//! each: read it ([`READ`]), accept it because it changes only how a
//! material looks ([`MATERIAL_ONLY`]), or refuse the file naming it.
//!
//! The `gltf` crate refuses every required extension outside its own
//! feature list; the importer decides here instead and then clears
//! `extensionsRequired` before the crate validates the document.

use crate::{Error, Result};

/// Extensions the importer reads.
pub(super) const READ: &[&str] = &[
    // Decoded by `draco.rs` (draco-core) and `meshopt.rs` (meshopt).
    "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",
    // Integer (normalized or not) positions and texture coordinates:
    // `Accessor::value` reads every component type.
    "KHR_mesh_quantization",
    // Applied to the texture coordinates of the base colour texture.
    "KHR_texture_transform",
];

/// Extensions that change only a material's shading, never the geometry
/// nor the base colour texture and its coordinates: a scan that requires
/// them still has every triangle the importer reads.
pub(super) const MATERIAL_ONLY: &[&str] = &[
    "KHR_materials_anisotropy",
    "KHR_materials_clearcoat",
    "KHR_materials_diffuse_transmission",
    "KHR_materials_dispersion",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_iridescence",
    "KHR_materials_sheen",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_unlit",
    "KHR_materials_variants",
    "KHR_materials_volume",
];

/// Why a known extension the importer cannot honour is refused.
fn refusal(name: &str) -> &'static str {
    match name {
        "KHR_materials_pbrSpecularGlossiness" => {
            "its diffuse texture replaces the base colour texture the importer reads"
        }
        "KHR_texture_basisu" | "EXT_texture_webp" | "EXT_texture_avif" | "MSFT_texture_dds" => {
            "the base colour image is in a format the importer does not decode"
        }
        "EXT_mesh_gpu_instancing" => "instanced meshes are not expanded",
        _ => "the importer does not know it",
    }
}

/// Refuses a document that requires an extension the importer neither
/// reads nor may ignore, naming the first; otherwise clears the list.
pub(super) fn accept_required(root: &mut gltf::json::Root, what: &'static str) -> Result<()> {
    for name in &root.extensions_required {
        let name = name.as_str();
        if !READ.contains(&name) && !MATERIAL_ONLY.contains(&name) {
            return Err(Error::Unsupported(format!(
                "{what}: glTF extension {name} is not supported: {}",
                refusal(name)
            )));
        }
    }
    root.extensions_required.clear();
    Ok(())
}
