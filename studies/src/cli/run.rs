//! `palpate run` (not yet implemented).

/// Options of `palpate run`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `palpate run`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`palpate run` is not implemented yet")
}
