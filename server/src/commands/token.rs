//! `vitrine token create --scope curator|researcher --label … [--model slug]`:
//! a new access token, printed once (only its digest is stored). The older
//! `vitrine token --label …` still makes a researcher token.

use crate::database::open_storage;
use crate::storage::{now_ms, sha256_hex, ConnectOptions, NewToken, TokenScope};

#[derive(clap::Args, Clone, Debug)]
#[command(args_conflicts_with_subcommands = true)]
pub struct TokenArgs {
    #[command(subcommand)]
    pub action: Option<TokenAction>,
    /// The older form, `vitrine token --label …`: a researcher token.
    #[command(flatten)]
    pub researcher: Option<TokenCreateArgs>,
}

#[derive(clap::Subcommand, Clone, Debug)]
pub enum TokenAction {
    /// Create a token and print it alone on the last line.
    Create(CreateArgs),
}

#[derive(clap::Args, Clone, Debug)]
pub struct CreateArgs {
    /// `researcher` opens researcher-only levels; `curator` publishes
    /// (uploads, withdraws, sets levels) and annotates. Separate scopes.
    #[arg(long)]
    pub scope: TokenScope,
    #[command(flatten)]
    pub token: TokenCreateArgs,
}

#[derive(clap::Args, Clone, Debug)]
pub struct TokenCreateArgs {
    #[arg(long, env = "VITRINE_DB", default_value = "sqlite:vitrine.db")]
    pub db: String,
    /// Who or what the token is for (shown in logs, never the token itself).
    #[arg(long)]
    pub label: String,
    /// Limit the token to one model (default: every model).
    #[arg(long)]
    pub model: Option<String>,
    #[arg(long)]
    pub expires_in_days: Option<u32>,
}

/// 256 random bits, hex, with a prefix that makes leaked tokens easy to grep for.
pub fn new_token() -> String {
    format!("vtr_{}", hex::encode(rand::random::<[u8; 32]>()))
}

pub async fn run(args: TokenArgs) -> anyhow::Result<()> {
    match (args.action, args.researcher) {
        (Some(TokenAction::Create(create)), _) => create_token(create.scope, create.token).await,
        (None, Some(token)) => create_token(TokenScope::Researcher, token).await,
        (None, None) => {
            anyhow::bail!("use `vitrine token create --scope curator|researcher --label …`")
        }
    }
}

/// Creates a token and prints it once; only its digest is stored.
async fn create_token(scope: TokenScope, args: TokenCreateArgs) -> anyhow::Result<()> {
    super::init_tracing();
    let storage = open_storage(&args.db, &ConnectOptions::default(), false).await?;
    let token = new_token();
    let expires_at_ms = args
        .expires_in_days
        .map(|d| now_ms() + i64::from(d) * 86_400_000);
    storage
        .insert_token(&NewToken {
            token_sha256: sha256_hex(token.as_bytes()),
            scope,
            label: args.label,
            model_slug: args.model,
            expires_at_ms,
        })
        .await?;
    println!("{token}");
    Ok(())
}
