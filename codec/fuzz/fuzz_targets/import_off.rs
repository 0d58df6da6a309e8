//! Mesh file bytes → `import_bytes(.., MeshFormat::Off, ..)` with small limits.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vitrine_mesh::import::{import_bytes, MeshFormat};
use vitrine_codec_fuzz::{check_import, import_options};

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = import_bytes(data, MeshFormat::Off, &import_options()) {
        check_import(&mesh);
    }
});
