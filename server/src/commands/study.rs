//! `vitrine study create|invite|close|report|import|export`: the quality
//! study of a model's current version (issue 17, thesis §6.6).

use crate::database::open_storage;
use crate::storage::{
    for_analysis, now_ms, sha256_hex, ConnectOptions, ModelRecord, Storage, StudyRecord,
};
use crate::study::analysis::Report;
use crate::study::plan::{check_transitions, default_transitions, DEFAULT_STATE_SECONDS};
use crate::study::{csv, new_invitation, report, Transition};
use anyhow::{bail, Context};
use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(clap::Args, Clone, Debug)]
pub struct StudyArgs {
    #[command(subcommand)]
    pub action: StudyAction,
}

/// Which database and model every action works on.
#[derive(clap::Args, Clone, Debug)]
pub struct StudyTarget {
    #[arg(long, env = "VITRINE_DB", default_value = "sqlite:vitrine.db")]
    pub db: String,
    /// The model; the study is of its current (visible) version.
    #[arg(long)]
    pub slug: String,
}

#[derive(clap::Subcommand, Clone, Debug)]
pub enum StudyAction {
    /// Open a study of the model's current version.
    Create {
        #[command(flatten)]
        target: StudyTarget,
        #[command(flatten)]
        design: StudyDesign,
    },
    /// Print invitation links, one per line (opens a default study if none is open).
    Invite {
        #[command(flatten)]
        target: StudyTarget,
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=10_000))]
        count: u32,
        #[arg(long, default_value_t = 30)]
        expires_in_days: u32,
        /// Where the service is reached, for the links.
        #[arg(long, default_value = "http://127.0.0.1:8080")]
        base_url: String,
    },
    /// Close the open study: its invitations stop working.
    Close {
        #[command(flatten)]
        target: StudyTarget,
    },
    /// Analyse the answers; `--apply` sets the version's good-enough level.
    Report {
        #[command(flatten)]
        target: StudyTarget,
        #[arg(long)]
        json: bool,
        /// Valid sessions needed before `--apply` (and for a per-device level).
        #[arg(long, default_value_t = 10)]
        min_participants: usize,
        #[arg(long)]
        apply: bool,
        /// Apply with fewer valid sessions than the minimum.
        #[arg(long)]
        force: bool,
    },
    /// Load answers gathered elsewhere (CSV; all or nothing).
    Import {
        #[command(flatten)]
        target: StudyTarget,
        file: PathBuf,
    },
    /// Write the answers as CSV (stdout without -o) and, with --views, the view log.
    Export {
        #[command(flatten)]
        target: StudyTarget,
        #[arg(short, long)]
        output: Option<PathBuf>,
        #[arg(long)]
        views: Option<PathBuf>,
    },
}

/// The transitions and T of a new study.
#[derive(clap::Args, Clone, Debug)]
pub struct StudyDesign {
    /// T: each of m_a and m_b is shown at least this long.
    #[arg(long, default_value_t = DEFAULT_STATE_SECONDS)]
    pub seconds: f64,
    /// First level shown (default: the first with 1 % of the vertices).
    #[arg(long)]
    pub from: Option<u32>,
    /// Last level shown (default: the last).
    #[arg(long)]
    pub to: Option<u32>,
}

impl Default for StudyDesign {
    /// What `invite` and `import` open when no study is: T = 20 s, the default steps.
    fn default() -> Self {
        StudyDesign {
            seconds: DEFAULT_STATE_SECONDS,
            from: None,
            to: None,
        }
    }
}

pub async fn run(args: StudyArgs) -> anyhow::Result<()> {
    super::init_tracing();
    let target = match &args.action {
        StudyAction::Create { target, .. }
        | StudyAction::Invite { target, .. }
        | StudyAction::Close { target }
        | StudyAction::Report { target, .. }
        | StudyAction::Import { target, .. }
        | StudyAction::Export { target, .. } => target.clone(),
    };
    let storage = open_storage(&target.db, &ConnectOptions::default(), false).await?;
    let record = storage
        .model_by_slug(&target.slug)
        .await?
        .with_context(|| format!("no model {:?}", target.slug))?;
    match args.action {
        StudyAction::Create { design, .. } => {
            let id = create(&storage, &record, &design).await?;
            println!(
                "study {id} of {} version {} is open",
                record.slug, record.version
            );
        }
        StudyAction::Invite {
            count,
            expires_in_days,
            base_url,
            ..
        } => invite(&storage, &record, count, expires_in_days, &base_url).await?,
        StudyAction::Close { .. } => {
            let study = open_study(&storage, &record)
                .await?
                .context("no study is open")?;
            storage.close_study(study.id).await?;
            println!("study {} closed", study.id);
        }
        StudyAction::Report {
            json,
            min_participants,
            apply,
            force,
            ..
        } => {
            let study = current(&storage, &record).await?;
            let sessions = storage.study_sessions(study.id).await?;
            let r = report(
                &for_analysis(&sessions),
                record.batch_count(),
                min_participants,
            );
            if json {
                let mut value = serde_json::to_value(&r)?;
                value["study"] = study.id.into();
                println!("{}", serde_json::to_string_pretty(&value)?);
            } else {
                print_report(&r, &study);
            }
            if apply {
                let level = applicable(&r, force)?;
                storage
                    .apply_good_enough(record.model_id, level, study.id)
                    .await?;
                eprintln!(
                    "{} version {}: good-enough level {level} (from study {})",
                    record.slug, record.version, study.id
                );
            }
        }
        StudyAction::Import { file, .. } => {
            let text = std::fs::File::open(&file)
                .with_context(|| format!("opening {}", file.display()))?;
            let sessions = csv::read(text, record.batch_count())
                .with_context(|| format!("{} is not a study answer file", file.display()))?;
            let study = match storage.current_study(&record.slug).await? {
                Some(s) => s,
                None => {
                    let id = create(&storage, &record, &StudyDesign::default()).await?;
                    eprintln!("opened study {id} for the imported answers");
                    current(&storage, &record).await?
                }
            };
            storage.import_sessions(study.id, &sessions).await?;
            let answers: usize = sessions.iter().map(|s| s.answers.len()).sum();
            println!(
                "imported {} participants, {answers} answers into study {}",
                sessions.len(),
                study.id
            );
        }
        StudyAction::Export { output, views, .. } => {
            let study = current(&storage, &record).await?;
            let sessions = storage.study_sessions(study.id).await?;
            let rows: Vec<_> = for_analysis(&sessions);
            let pairs = rows
                .iter()
                .map(|s| (s.participant.as_str(), s.answers.as_slice()));
            match output {
                Some(path) => csv::write(create_file(&path)?, pairs)?,
                None => csv::write(std::io::stdout().lock(), pairs)?,
            }
            if let Some(path) = views {
                write_views(&storage, study.id, &path).await?;
            }
        }
    }
    Ok(())
}

async fn open_study(
    storage: &Arc<dyn Storage>,
    record: &ModelRecord,
) -> anyhow::Result<Option<StudyRecord>> {
    Ok(storage
        .current_study(&record.slug)
        .await?
        .filter(|s| s.open && s.model_id == record.model_id))
}

async fn current(storage: &Arc<dyn Storage>, record: &ModelRecord) -> anyhow::Result<StudyRecord> {
    storage.current_study(&record.slug).await?.with_context(|| {
        format!(
            "{} version {} has no study: vitrine study create (or invite) opens one",
            record.slug, record.version
        )
    })
}

async fn create(
    storage: &Arc<dyn Storage>,
    record: &ModelRecord,
    design: &StudyDesign,
) -> anyhow::Result<i64> {
    if let Some(open) = open_study(storage, record).await? {
        bail!(
            "study {} of {} is open already: close it first (vitrine study close)",
            open.id,
            record.slug
        );
    }
    if !(design.seconds.is_finite() && (0.0..=600.0).contains(&design.seconds)) {
        bail!("--seconds must be 0 to 600");
    }
    let last = record.batch_count();
    // The default is every consecutive pair from the first level with 1 %
    // of the vertices to the last; --from and --to move either end.
    let vertices: Vec<u32> = record.levels.iter().map(|l| l.vertices).collect();
    let defaults = default_transitions(&vertices);
    let from = design
        .from
        .unwrap_or_else(|| defaults.first().map_or(0, |t| t.from()));
    let to = design.to.unwrap_or(last);
    let transitions: Vec<Transition> = (from..to).map(|a| Transition(a, a + 1)).collect();
    check_transitions(&transitions, last).map_err(anyhow::Error::msg)?;
    let state_ms = (design.seconds * 1000.0).round() as u64;
    Ok(storage
        .create_study(record.model_id, &transitions, state_ms)
        .await?)
}

async fn invite(
    storage: &Arc<dyn Storage>,
    record: &ModelRecord,
    count: u32,
    expires_in_days: u32,
    base_url: &str,
) -> anyhow::Result<()> {
    let study = match open_study(storage, record).await? {
        Some(s) => s,
        None => {
            let id = create(storage, record, &StudyDesign::default()).await?;
            eprintln!(
                "opened study {id} of {} version {} (T = {DEFAULT_STATE_SECONDS} s)",
                record.slug, record.version
            );
            current(storage, record).await?
        }
    };
    let tokens: Vec<String> = (0..count).map(|_| new_invitation()).collect();
    let digests: Vec<String> = tokens.iter().map(|t| sha256_hex(t.as_bytes())).collect();
    let expires = now_ms() + i64::from(expires_in_days) * 86_400_000;
    storage
        .insert_invitations(study.id, &digests, Some(expires))
        .await?;
    let base = base_url.trim_end_matches('/');
    let mut out = std::io::stdout().lock();
    for token in tokens {
        writeln!(out, "{base}/study/{}?invitation={token}", record.slug)?;
    }
    Ok(())
}

/// The level `--apply` writes, or why not.
fn applicable(r: &Report, force: bool) -> anyhow::Result<u32> {
    let Some(level) = r.good_enough_level else {
        bail!("no valid session: nothing to apply");
    };
    if !r.enough && !force {
        bail!(
            "{} valid sessions, fewer than --min-participants {}: collect more, or --force",
            r.valid_sessions,
            r.min_participants
        );
    }
    Ok(level)
}

fn print_report(r: &Report, study: &StudyRecord) {
    println!(
        "study {} of {} version {}: {} valid sessions, {} excluded",
        study.id, study.slug, study.version, r.valid_sessions, r.excluded_sessions
    );
    for e in &r.excluded {
        println!("  excluded {}: {:?}", e.participant, e.reason);
    }
    println!("level  none  a-little  improved  greatly  sufficient  not");
    for l in &r.levels {
        println!(
            "{:>5}  {:>4}  {:>8}  {:>8}  {:>7}  {:>10}  {:>3}",
            l.level, l.none, l.a_little, l.improved, l.greatly, l.sufficient, l.insufficient
        );
    }
    for s in &r.sessions {
        let level = s.good_level.map_or("never".into(), |l| l.to_string());
        println!("  {}: good at level {level}", s.participant);
    }
    match r.good_enough_level {
        Some(level) => println!(
            "good-enough level: {level} (nearest-rank {:.0}th percentile){}",
            r.percentile * 100.0,
            if r.enough {
                ""
            } else {
                "; fewer sessions than the minimum"
            }
        ),
        None => println!("good-enough level: none (no valid session)"),
    }
}

fn create_file(path: &PathBuf) -> anyhow::Result<std::fs::File> {
    std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))
}

async fn write_views(
    storage: &Arc<dyn Storage>,
    study_id: i64,
    path: &PathBuf,
) -> anyhow::Result<()> {
    let mut writer = ::csv::Writer::from_writer(create_file(path)?);
    writer.write_record(["participant", "at_ms", "step", "state", "kind", "data"])?;
    for (participant, e) in storage.study_views(study_id).await? {
        writer.write_record([
            participant.as_str(),
            &e.at_ms.to_string(),
            &e.step.to_string(),
            &e.state,
            &e.kind,
            &e.data,
        ])?;
    }
    writer.flush()?;
    Ok(())
}
