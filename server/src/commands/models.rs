//! `vitrine models`: what a database holds, and whether this build serves
//! it — the check to run after upgrading Vitrine, before `serve` — and
//! under which licence each model is published (a rights audit: the public
//! models that state none are counted).

use crate::database::open_storage;
use crate::storage::{ConnectOptions, ModelKind, ModelSummary, Storage};
use std::fmt::Write as _;
use vitrine_codec::{CHARTED_VERSION, NESTED_VERSION};

#[derive(clap::Args, Clone, Debug)]
pub struct ModelsArgs {
    #[arg(long, env = "VITRINE_DB", default_value = "sqlite:vitrine.db")]
    pub db: String,
    /// Fail (exit status 1) when a model is stored in a stream format this
    /// build cannot serve, for upgrade scripts.
    #[arg(long)]
    pub check: bool,
}

/// What `vitrine models` prints for `storage`, and how many models must be
/// ingested again because this build does not read their stream format.
pub async fn models_listing(storage: &dyn Storage) -> crate::storage::Result<(String, usize)> {
    let models = storage.list_models().await?;
    let unmeasured = storage.slugs_with_unmeasured_parts().await?;
    Ok(models_table(&models, &unmeasured))
}

/// One line per model (its visible version), and how many must be ingested
/// again because this build does not read their stream format;
/// `unmeasured_slugs` names the models whose parts lack a bulk error.
fn models_table(models: &[ModelSummary], unmeasured_slugs: &[String]) -> (String, usize) {
    let width = models
        .iter()
        .map(|m| m.slug.len())
        .max()
        .unwrap_or(4)
        .max(4);
    let mut out = format!(
        "{:width$}  version    kind  levels  public  {:15}  stream format\n",
        "slug", "licence"
    );
    let mut stale = 0;
    let mut unlicensed = 0;
    let mut partless = 0;
    let mut unmeasured = 0;
    for m in models {
        let charted = m.kind == ModelKind::Mesh
            && (m.stream_format == CHARTED_VERSION || m.stream_format == NESTED_VERSION);
        let format = if charted && !m.has_parts {
            partless += 1;
            format!(
                "{} (no part index: ingest it again to refine where visitors look)",
                m.stream_format
            )
        } else if charted && unmeasured_slugs.contains(&m.slug) {
            unmeasured += 1;
            format!(
                "{} (parts without a bulk error: ingest it again so visitors' \
                 viewers refine by it, not by each part's noisiest vertex)",
                m.stream_format
            )
        } else if m.servable() {
            m.stream_format.to_string()
        } else {
            stale += 1;
            format!(
                "{} (this build reads {}: ingest it again)",
                m.stream_format,
                m.kind.reads()
            )
        };
        let public = if m.public_access { "yes" } else { "no" };
        if m.public_access && m.licence.is_none() {
            unlicensed += 1;
        }
        let _ = writeln!(
            out,
            "{:width$}  {:>7}  {:>6}  {:>6}  {public:>6}  {:15}  {format}",
            m.slug,
            m.version,
            m.kind.name(),
            m.batch_count + 1,
            m.licence.as_deref().unwrap_or("-"),
        );
    }
    let _ = write!(
        out,
        "{} model(s); {stale} stored in a stream format this build cannot serve; \
         {unlicensed} public without a stated licence; \
         {partless} charted without a part index; \
         {unmeasured} with parts measured before their bulk error",
        models.len()
    );
    (out, stale)
}

pub async fn run(args: ModelsArgs) -> anyhow::Result<()> {
    super::init_tracing();
    let storage = open_storage(&args.db, &ConnectOptions::default(), false).await?;
    let (table, stale) = models_listing(&*storage).await?;
    println!("{table}");
    if args.check && stale > 0 {
        anyhow::bail!("{stale} model(s) must be ingested again (vitrine ingest … --new-version)");
    }
    Ok(())
}
