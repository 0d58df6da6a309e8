//! `vitrine serve --config FILE --check-config`: the file's keys are the
//! flags' names; a flag beats its `VITRINE_*` variable, which beats the file,
//! which beats the default; the effective configuration is printed with the
//! password redacted; an invalid one exits 1.

use std::path::Path;
use std::process::{Command, Output};

fn check(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_vitrine"));
    command.arg("serve").args(args).arg("--check-config");
    // Only what this test sets: no VITRINE_* from the caller's shell.
    for (k, _) in std::env::vars() {
        if k.starts_with("VITRINE_") {
            command.env_remove(k);
        }
    }
    command.envs(env.iter().copied());
    command.output().expect("run vitrine")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The printed value of `key` (a TOML line `key = value`).
fn value(o: &Output, key: &str) -> String {
    stdout(o)
        .lines()
        .find_map(|l| l.strip_prefix(&format!("{key} = ")))
        .unwrap_or_else(|| panic!("{key} not printed in:\n{}", stdout(o)))
        .to_owned()
}

fn write(dir: &Path, text: &str) -> String {
    let path = dir.join("vitrine.toml");
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

#[test]
fn precedence_flag_env_file_default() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(
        dir.path(),
        "db = \"postgres://vitrine:hunter2@db.example/vitrine\"\n\
         db-max-connections = 7\n\
         cache_bytes = 1234\n\
         admit-rate = 50.5\n\
         load-pin = true\n\
         cors-origin = [\"https://a.example\", \"https://b.example\"]\n\
         trusted-proxies = [\"127.0.0.1/32\", \"10.0.0.0/8\"]\n\
         listen = \"127.0.0.1:9001\"\n",
    );
    // File over default.
    let o = check(&["--config", &file], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(value(&o, "db-max-connections"), "7");
    assert_eq!(value(&o, "cache-bytes"), "1234");
    assert_eq!(value(&o, "admit-rate"), "50.5");
    assert_eq!(value(&o, "load-pin"), "true");
    assert_eq!(value(&o, "listen"), "\"127.0.0.1:9001\"");
    assert_eq!(
        value(&o, "cors-origin"),
        "[\"https://a.example\", \"https://b.example\"]"
    );
    assert_eq!(
        value(&o, "trusted-proxies"),
        "[\"127.0.0.1/32\", \"10.0.0.0/8\"]"
    );
    // A setting the file leaves out keeps its default.
    assert_eq!(value(&o, "db-timeout-ms"), "3000");
    // The password never shows.
    assert!(!stdout(&o).contains("hunter2"), "{}", stdout(&o));
    assert_eq!(
        value(&o, "db"),
        "\"postgres://vitrine:***@db.example/vitrine\""
    );

    // The variable over the file; the file through VITRINE_CONFIG.
    let o = check(
        &[],
        &[
            ("VITRINE_CONFIG", &file),
            ("VITRINE_DB_MAX_CONNECTIONS", "9"),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(value(&o, "db-max-connections"), "9");
    assert_eq!(value(&o, "cache-bytes"), "1234");

    // The flag over the variable.
    let o = check(
        &["--config", &file, "--db-max-connections", "11"],
        &[("VITRINE_DB_MAX_CONNECTIONS", "9")],
    );
    assert!(o.status.success());
    assert_eq!(value(&o, "db-max-connections"), "11");

    // No file: the defaults.
    let o = check(&[], &[]);
    assert!(o.status.success());
    assert_eq!(value(&o, "db-max-connections"), "16");
    assert_eq!(value(&o, "load-pin"), "false");
}

#[test]
fn invalid_configurations_exit_1_with_a_reason() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "db-max-conections = 3\n",
            "unknown setting `db-max-conections`",
        ),
        ("db-max-connections = \"many\"\n", "db-max-connections"),
        ("trusted-proxies = [\"10.0.0.0/33\"]\n", "trusted-proxies"),
        ("load-pin = 1\n", "expected true or false"),
        (
            "load-low-inflight = 500\n",
            "load-low-inflight is above load-high-inflight",
        ),
        ("db = \"mysql://x\"\n", "db:"),
        ("check-config = true\n", "cannot be set in the file"),
        ("this is not toml", "not valid TOML"),
    ];
    for (text, reason) in cases {
        let file = write(dir.path(), text);
        let o = check(&["--config", &file], &[]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{text:?}: {stderr}");
        assert!(
            stderr.contains(reason),
            "{text:?}: expected {reason:?} in {stderr}"
        );
    }
    let o = check(&["--config", "/nonexistent/vitrine.toml"], &[]);
    assert_eq!(o.status.code(), Some(1));
}

/// `[ui.strings.<language>]`: a museum's own words for the viewer, accepted
/// from the file (dotted keys or nested tables), refused with the setting
/// named when the language or a key is not one the viewer has.
#[test]
fn the_museums_own_words_come_from_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let good = write(
        dir.path(),
        "site-name = \"Museu\"\n\
         [ui.strings.en]\n\"page.allModels\" = \"← All stories\"\n\
         [ui.strings.pt.page]\nallModels = \"← Todas as histórias\"\n",
    );
    let o = check(&["--config", &good], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(value(&o, "site-name"), "\"Museu\"");
    for (text, named) in [
        (
            "[ui.strings.ja]\n\"page.allModels\" = \"x\"\n",
            "`ui.strings.ja`",
        ),
        (
            "[ui.strings.en]\n\"page all\" = \"x\"\n",
            "`ui.strings.en.\"page all\"`",
        ),
        ("[ui]\nstrings = 3\n", "`ui.strings`"),
    ] {
        let bad = write(dir.path(), text);
        let o = check(&["--config", &bad], &[]);
        assert!(!o.status.success(), "{text}");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(stderr.contains(named), "{text}: {stderr}");
    }
}
