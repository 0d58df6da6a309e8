//! `vitrine serve`'s configuration file: one TOML table whose keys are the
//! flags' names (`db-max-connections = 32`; `db_max_connections` is the same
//! key). Precedence, highest first: a flag on the command line, its
//! `VITRINE_*` variable, the file (`--config FILE` / `VITRINE_CONFIG`), the
//! default.
//!
//! The file is applied by clap itself: each of its settings that neither the
//! command line nor the environment gave becomes one more `--name=value`
//! argument, and the whole is parsed again. So a value in the file is checked
//! by the same parser, with the same messages, as the flag, and no setting
//! can exist in one form and not the other.
//!
//! One table is no flag: `[ui.strings.<language>]`, a museum's own words in
//! place of the viewer's (service/ui_strings.rs).

use crate::commands::serve::ServeArgs;
use anyhow::{bail, Context};
use clap::parser::ValueSource;
use clap::{ArgAction, CommandFactory, FromArgMatches, Parser};
use std::ffi::OsString;
use std::path::Path;

/// `vitrine serve`'s arguments on their own, to parse them again.
#[derive(Parser)]
#[command(name = "vitrine serve")]
struct ServeOnly {
    #[command(flatten)]
    serve: ServeArgs,
}

/// Settings a file may not make: which file, and what to do with it.
const NOT_IN_FILE: [&str; 2] = ["config", "check-config"];

/// The effective settings for `serve`'s arguments `argv` (without the
/// program and `serve`), the environment, and the file they name, if any.
pub fn resolve(argv: &[OsString]) -> anyhow::Result<ServeArgs> {
    let program = OsString::from("vitrine serve");
    let full: Vec<OsString> = std::iter::once(program.clone())
        .chain(argv.iter().cloned())
        .collect();
    let command = ServeOnly::command();
    let matches = command
        .clone()
        .try_get_matches_from(&full)
        .map_err(|e| anyhow::anyhow!("{}", e.render()))?;
    let first = ServeOnly::from_arg_matches(&matches)?.serve;
    let Some(path) = first.config.clone() else {
        return Ok(first);
    };
    let mut table = read_table(&path)?;
    let ui_strings = match table.remove("ui") {
        Some(ui) => crate::service::UiStrings::from_toml(&ui)
            .with_context(|| format!("{}: the museum's own words", path.display()))?,
        None => crate::service::UiStrings::default(),
    };
    let mut extra = Vec::new();
    for (key, value) in &table {
        let name = key.replace('_', "-");
        if NOT_IN_FILE.contains(&name.as_str()) {
            bail!("{}: `{key}` cannot be set in the file", path.display());
        }
        let Some(arg) = command
            .get_arguments()
            .find(|a| a.get_long() == Some(name.as_str()))
        else {
            bail!(
                "{}: unknown setting `{key}` (the names are those of `vitrine serve --help`)",
                path.display()
            );
        };
        let given = matches!(
            matches.value_source(arg.get_id().as_str()),
            Some(ValueSource::CommandLine | ValueSource::EnvVariable)
        );
        if given {
            continue;
        }
        let flag = matches!(arg.get_action(), ArgAction::SetTrue);
        if let Some(argument) = as_argument(&name, value, flag)
            .with_context(|| format!("{}: setting `{key}`", path.display()))?
        {
            extra.push(OsString::from(argument));
        }
    }
    let again: Vec<OsString> = full.into_iter().chain(extra).collect();
    let mut parsed = ServeOnly::try_parse_from(&again)
        .map_err(|e| anyhow::anyhow!("{} (from {})", e.render(), path.display()))?;
    parsed.serve.ui_strings = ui_strings;
    Ok(parsed.serve)
}

fn read_table(path: &Path) -> anyhow::Result<toml::Table> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading the configuration file {}", path.display()))?;
    text.parse::<toml::Table>()
        .with_context(|| format!("{} is not valid TOML", path.display()))
}

/// One file setting as the flag that says the same; `None` for a switch
/// that is off (the default of every switch).
fn as_argument(name: &str, value: &toml::Value, flag: bool) -> anyhow::Result<Option<String>> {
    use toml::Value;
    if flag {
        return match value {
            Value::Boolean(true) => Ok(Some(format!("--{name}"))),
            Value::Boolean(false) => Ok(None),
            other => bail!("expected true or false, found {}", other.type_str()),
        };
    }
    let scalar = |v: &Value| -> anyhow::Result<String> {
        match v {
            Value::String(s) => Ok(s.clone()),
            Value::Integer(i) => Ok(i.to_string()),
            Value::Float(f) => Ok(f.to_string()),
            Value::Boolean(b) => Ok(b.to_string()),
            other => bail!("expected a string or a number, found {}", other.type_str()),
        }
    };
    let text = match value {
        Value::Array(items) => items
            .iter()
            .map(scalar)
            .collect::<Result<Vec<_>, _>>()?
            .join(","),
        v => scalar(v)?,
    };
    Ok(Some(format!("--{name}={text}")))
}

/// The effective configuration as a TOML file of the same names, the
/// database password replaced by `***` (`vitrine serve --check-config`).
pub fn effective_toml(args: &ServeArgs) -> anyhow::Result<String> {
    let mut shown = args.clone();
    shown.db = crate::database::redact(&args.db);
    let mut text = String::from(
        "# vitrine serve: effective configuration (flag > VITRINE_* > file > default)\n",
    );
    if let Some(path) = &args.config {
        text.push_str(&format!("# file: {}\n", path.display()));
    }
    text.push_str(&toml::to_string(&shown)?);
    Ok(text)
}

/// Checks that go beyond each value's own parser: settings that contradict
/// one another, and a database URL that cannot be used.
pub fn validate(args: &ServeArgs) -> anyhow::Result<()> {
    let mut problems = Vec::new();
    if args.load_low_inflight > args.load_high_inflight {
        problems.push("load-low-inflight is above load-high-inflight".to_owned());
    }
    if args.load_low_latency_ms > args.load_high_latency_ms {
        problems.push("load-low-latency-ms is above load-high-latency-ms".to_owned());
    }
    if args.load_low_queue_ms > args.load_high_queue_ms {
        problems.push("load-low-queue-ms is above load-high-queue-ms".to_owned());
    }
    if args.db_max_connections == 0 {
        problems.push("db-max-connections must be at least 1".to_owned());
    }
    if args.max_concurrency == 0 {
        problems.push("max-concurrency must be at least 1".to_owned());
    }
    if !(0.0..=1.0).contains(&args.good_enough_fraction) {
        problems.push("good-enough-fraction must be between 0 and 1".to_owned());
    }
    if let Err(e) = crate::storage::connect(&args.db, &args.connect_options()) {
        problems.push(format!("db: {e}"));
    }
    if problems.is_empty() {
        Ok(())
    } else {
        bail!("invalid configuration:\n  {}", problems.join("\n  "))
    }
}
