//! `palpate calibrate` (not yet implemented).

/// Options of `palpate calibrate`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `palpate calibrate`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`palpate calibrate` is not implemented yet")
}
