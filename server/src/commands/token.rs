//! `vitrine token --label … [--model slug]`: a researcher token.

use crate::database::open_storage;
use crate::storage::{now_ms, sha256_hex, ConnectOptions, NewToken};

#[derive(clap::Args, Clone, Debug)]
pub struct TokenArgs {
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

/// Creates a token and prints it once; only its digest is stored.
pub async fn run(args: TokenArgs) -> anyhow::Result<()> {
    super::init_tracing();
    let storage = open_storage(&args.db, &ConnectOptions::default(), false).await?;
    let token = new_token();
    let expires_at_ms = args
        .expires_in_days
        .map(|d| now_ms() + i64::from(d) * 86_400_000);
    storage
        .insert_token(&NewToken {
            token_sha256: sha256_hex(token.as_bytes()),
            label: args.label,
            model_slug: args.model,
            expires_at_ms,
        })
        .await?;
    println!("{token}");
    Ok(())
}
