//! `vitrine texts --db … --slug …`: a model version's title, description
//! and credit in other languages (issue 43). With `--language` (and
//! `--title`, `--description`, `--credit`) it sets that language's
//! translation, replacing the one there; with `--remove` it drops one;
//! alone it lists them. The version is the visible one unless `--version`
//! names another. The same checks and storage as `/admin`'s editor
//! (`PUT /api/admin/models/{slug}/versions/{version}/texts`).

use crate::database::open_storage;
use crate::service::texts::input::translation;
use crate::storage::{valid_slug, ConnectOptions, ModelTexts, Storage};

#[derive(clap::Args, Clone, Debug)]
pub struct TextsArgs {
    #[arg(long, env = "VITRINE_DB", default_value = "sqlite:vitrine.db")]
    pub db: String,
    #[arg(long)]
    pub slug: String,
    /// The version (default: the visible one, the highest ready).
    #[arg(long)]
    pub version: Option<u32>,
    /// The translation's language, a BCP 47 tag (pt, pt-BR, es).
    #[arg(long, conflicts_with = "remove")]
    pub language: Option<String>,
    /// The title in that language (one line, at most 200 characters).
    #[arg(long, requires = "language")]
    pub title: Option<String>,
    /// The description in that language (at most 10,000 characters).
    #[arg(long, requires = "language")]
    pub description: Option<String>,
    /// The credit line in that language (one line, at most 300 bytes).
    #[arg(long, requires = "language")]
    pub credit: Option<String>,
    /// Drop the translation in this language.
    #[arg(long)]
    pub remove: Option<String>,
}

pub async fn run(args: TextsArgs) -> anyhow::Result<()> {
    super::init_tracing();
    if !valid_slug(&args.slug) {
        anyhow::bail!("{:?} is not a model slug", args.slug);
    }
    let storage = open_storage(&args.db, &ConnectOptions::default(), false).await?;
    let version = version_of(storage.as_ref(), &args.slug, args.version).await?;
    let Some(current) = storage.version_texts(&args.slug, version).await? else {
        anyhow::bail!("{} has no version {version}", args.slug);
    };
    let mut texts: ModelTexts = current.texts;
    if let Some(language) = &args.language {
        let (tag, t) = translation(
            language,
            args.title.clone(),
            args.description.clone(),
            args.credit.clone(),
        )
        .map_err(anyhow::Error::msg)?;
        if texts
            .language
            .as_deref()
            .is_some_and(|own| own.eq_ignore_ascii_case(&tag))
        {
            anyhow::bail!(
                "{tag} is the language of the version's own texts (vitrine ingest --language)"
            );
        }
        texts
            .translations
            .retain(|k, _| !k.eq_ignore_ascii_case(&tag));
        texts.translations.insert(tag, t);
    } else if let Some(remove) = &args.remove {
        let before = texts.translations.len();
        texts
            .translations
            .retain(|k, _| !k.eq_ignore_ascii_case(remove.trim()));
        if texts.translations.len() == before {
            anyhow::bail!(
                "{} version {version} has no {remove} translation",
                args.slug
            );
        }
    } else {
        print!("{}", listing(&args.slug, version, &current.title, &texts));
        return Ok(());
    }
    if texts.translations.len() > crate::service::texts::input::MAX_LANGUAGES {
        anyhow::bail!(
            "more than {} translations",
            crate::service::texts::input::MAX_LANGUAGES
        );
    }
    storage
        .set_version_texts(&args.slug, version, &texts)
        .await?;
    print!("{}", listing(&args.slug, version, &current.title, &texts));
    Ok(())
}

/// `--version`, else the highest ready version.
async fn version_of(storage: &dyn Storage, slug: &str, asked: Option<u32>) -> anyhow::Result<u32> {
    let versions = storage.versions(slug).await?;
    let found = match asked {
        Some(v) => versions.iter().find(|r| r.version == v),
        None => versions
            .iter()
            .filter(|r| r.status == "ready")
            .max_by_key(|r| r.version),
    };
    match (found, asked) {
        (Some(r), _) => Ok(r.version),
        (None, Some(v)) => anyhow::bail!("{slug} has no version {v}"),
        (None, None) => anyhow::bail!("{slug} has no ready version"),
    }
}

/// One line per language: the tag and what it gives.
fn listing(slug: &str, version: u32, title: &str, texts: &ModelTexts) -> String {
    let own = texts.language.as_deref().unwrap_or("(language not stated)");
    let mut out = format!("{slug} version {version}: {own}: {title}\n");
    for (tag, t) in &texts.translations {
        let fields: Vec<&str> = [
            t.title.as_ref().map(|_| "title"),
            t.description.as_ref().map(|_| "description"),
            t.credit.as_ref().map(|_| "credit"),
        ]
        .into_iter()
        .flatten()
        .collect();
        let title = t.title.as_deref().unwrap_or("(title as above)");
        out.push_str(&format!("  {tag}: {title} [{}]\n", fields.join(", ")));
    }
    out
}
