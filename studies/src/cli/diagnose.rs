//! `palpate diagnose` (not yet implemented).

/// Options of `palpate diagnose`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `palpate diagnose`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`palpate diagnose` is not implemented yet")
}
