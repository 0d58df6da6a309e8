//! Golden files: `name length fnv1a64-hex` per line, the exact bytes an
//! encoder writes for a fixed set of generated inputs. A test computes its
//! entries and calls [`check_or_bless`]; with `VITRINE_BLESS=1` it records
//! them instead.

use std::fmt::Write as _;
use std::path::Path;

/// FNV-1a, 64 bits.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// One recorded output: its name, length and hash.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GoldenEntry {
    pub name: String,
    pub len: usize,
    pub hash: u64,
}

impl GoldenEntry {
    pub fn of(name: &str, bytes: &[u8]) -> Self {
        GoldenEntry {
            name: name.to_owned(),
            len: bytes.len(),
            hash: fnv1a64(bytes),
        }
    }
}

/// Compares `found` with the file at `path` (whose `#` lines are comments)
/// and returns every difference in words, or writes `header` and `found`
/// there when `VITRINE_BLESS=1` (then the list is empty).
pub fn check_or_bless(path: &Path, header: &str, found: &[GoldenEntry]) -> Vec<String> {
    if std::env::var("VITRINE_BLESS").is_ok_and(|v| v == "1") {
        let mut text = String::from(header);
        for e in found {
            let _ = writeln!(text, "{} {} {:016x}", e.name, e.len, e.hash);
        }
        std::fs::write(path, text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        eprintln!("re-recorded {}", path.display());
        return Vec::new();
    }
    let recorded = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{} (record it with VITRINE_BLESS=1): {e}", path.display()));
    let mut expected = Vec::new();
    for line in recorded
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
    {
        let f: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(f.len(), 3, "malformed golden line {line:?}");
        let len: usize = f[1]
            .parse()
            .unwrap_or_else(|_| panic!("bad length in {line:?}"));
        let hash = u64::from_str_radix(f[2], 16).unwrap_or_else(|_| panic!("bad hash in {line:?}"));
        expected.push(GoldenEntry {
            name: f[0].to_owned(),
            len,
            hash,
        });
    }
    let mut diffs = Vec::new();
    for e in found {
        match expected.iter().find(|x| x.name == e.name) {
            None => diffs.push(format!("{}: not in {}", e.name, path.display())),
            Some(x) if (x.len, x.hash) != (e.len, e.hash) => diffs.push(format!(
                "{}: recorded {} bytes {:016x}, now {} bytes {:016x}",
                e.name, x.len, x.hash, e.len, e.hash
            )),
            Some(_) => {}
        }
    }
    for x in &expected {
        if !found.iter().any(|e| e.name == x.name) {
            diffs.push(format!("{}: recorded but no longer produced", x.name));
        }
    }
    diffs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a64_reference_values() {
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn a_changed_entry_is_named() {
        let dir = std::env::temp_dir().join(format!("golden-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("golden.txt");
        std::fs::write(&path, "# c\na 3 0000000000000001\nb 1 0000000000000002\n").unwrap();
        let found = [
            GoldenEntry {
                name: "a".into(),
                len: 3,
                hash: 1,
            },
            GoldenEntry {
                name: "b".into(),
                len: 1,
                hash: 3,
            },
            GoldenEntry {
                name: "c".into(),
                len: 1,
                hash: 3,
            },
        ];
        let diffs = check_or_bless(&path, "", &found);
        assert_eq!(diffs.len(), 2, "{diffs:?}");
        assert!(diffs[0].starts_with("b: recorded 1 bytes"), "{diffs:?}");
        assert!(diffs[1].starts_with("c: not in"), "{diffs:?}");
        std::fs::remove_dir_all(dir).unwrap();
    }
}
