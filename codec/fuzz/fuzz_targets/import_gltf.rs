//! glTF JSON or GLB bytes → `import_bytes(.., MeshFormat::Gltf, ..)` with small
//! limits (a GLB is recognised by its magic whatever the format says).
#![no_main]

use libfuzzer_sys::fuzz_target;
use vitrine_mesh::import::{import_bytes, MeshFormat};
use vitrine_codec_fuzz::{check_import, import_options};

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = import_bytes(data, MeshFormat::Gltf, &import_options()) {
        check_import(&mesh);
    }
});
