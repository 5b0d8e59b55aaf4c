//! `palpate anova` (not yet implemented).

/// Options of `palpate anova`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `palpate anova`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`palpate anova` is not implemented yet")
}
