//! `palpate sample` (not yet implemented).

/// Options of `palpate sample`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `palpate sample`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`palpate sample` is not implemented yet")
}
