//! What the glTF import tests share: a GLB built in memory.
#![allow(dead_code)] // each test file uses its own part

/// A GLB under construction: BIN views and accessors as JSON.
#[derive(Default)]
pub struct Glb {
    pub bin: Vec<u8>,
    pub views: Vec<String>,
    pub accessors: Vec<String>,
    /// Buffers after the BIN chunk's (JSON objects).
    pub more_buffers: Vec<String>,
}

impl Glb {
    /// Appends `bytes` as a buffer view (4-byte aligned); its index.
    pub fn view(&mut self, bytes: &[u8]) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        self.views.push(format!(
            r#"{{"buffer":0,"byteOffset":{},"byteLength":{}}}"#,
            self.bin.len(),
            bytes.len()
        ));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// Appends an accessor (its JSON without braces); its index.
    pub fn accessor(&mut self, json: String) -> usize {
        self.accessors.push(format!("{{{json}}}"));
        self.accessors.len() - 1
    }

    /// The file: `rest` holds the document's other members (meshes, nodes…).
    pub fn bytes(&self, rest: &str) -> Vec<u8> {
        let mut bin = self.bin.clone();
        bin.resize(bin.len().next_multiple_of(4), 0);
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},{rest},"buffers":[{{"byteLength":{}}}{}],"bufferViews":[{}],"accessors":[{}]}}"#,
            bin.len(),
            self.more_buffers
                .iter()
                .map(|b| format!(",{b}"))
                .collect::<String>(),
            self.views.join(","),
            self.accessors.join(",")
        );
        let mut json = json.into_bytes();
        json.resize(json.len().next_multiple_of(4), b' ');
        let mut out = b"glTF".to_vec();
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&((28 + json.len() + bin.len()) as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }
}

pub fn le<T: Copy, const N: usize>(values: &[T], f: impl Fn(T) -> [u8; N]) -> Vec<u8> {
    values.iter().flat_map(|&v| f(v)).collect()
}
