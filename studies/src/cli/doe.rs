//! `palpate doe` (not yet implemented).

/// Options of `palpate doe`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `palpate doe`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`palpate doe` is not implemented yet")
}
