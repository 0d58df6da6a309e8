//! MD2 bytes → `import_bytes(.., MeshFormat::Md2, ..)` with small limits,
//! and for every file that parses: write → parse → write is byte-identical.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vitrine_codec_fuzz::{check_import, import_options};
use vitrine_mesh::export::write_md2;
use vitrine_mesh::import::md2::Md2;
use vitrine_mesh::import::{import_bytes, MeshFormat};

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = import_bytes(data, MeshFormat::Md2, &import_options()) {
        check_import(&mesh);
    }
    if let Ok(model) = Md2::parse(data, &import_options()) {
        let mut once = Vec::new();
        if write_md2(&model, &mut once).is_ok() {
            let again = Md2::parse(&once, &import_options()).expect("a written MD2 reads back");
            let mut twice = Vec::new();
            write_md2(&again, &mut twice).expect("and writes again");
            assert_eq!(once, twice, "re-written MD2 differs");
        }
    }
});
