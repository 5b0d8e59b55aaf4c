//! `palpate simulate` (not yet implemented).

/// Options of `palpate simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `palpate simulate`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`palpate simulate` is not implemented yet")
}
