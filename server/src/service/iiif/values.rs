//! JSON values that the Manifest and the Web Annotations both write.

use serde_json::{json, Value};

/// `{key: [text]}`: a Presentation language map of one value.
pub fn language_map(language: Option<&str>, text: &str) -> Value {
    let mut map = serde_json::Map::new();
    map.insert(language.unwrap_or("none").to_owned(), json!([text]));
    Value::Object(map)
}

/// A language map of one text in several languages (`None`: unstated,
/// keyed `none`); a language met twice keeps its first text.
pub fn language_maps<'a>(texts: impl IntoIterator<Item = (Option<&'a str>, &'a str)>) -> Value {
    let mut map = serde_json::Map::new();
    for (language, text) in texts {
        map.entry(language.unwrap_or("none"))
            .or_insert_with(|| json!([text]));
    }
    Value::Object(map)
}

/// A W3C PointSelector at `p` (scene coordinates).
pub fn point_selector(p: [f64; 3]) -> Value {
    json!({ "type": "PointSelector", "x": p[0], "y": p[1], "z": p[2] })
}
