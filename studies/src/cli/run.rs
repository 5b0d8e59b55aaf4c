//! `palpate run STUDY.toml`: run a whole study from one manifest.

use std::path::PathBuf;

/// Run a study described by one TOML manifest.
///
/// Writes into the run folder (default runs/<study name>): results.json
/// (byte-identical when the same manifest is run again), report.md, plots/*.svg
/// and provenance.json (manifest and data hashes, git commit, crate versions,
/// seed, thread count). Data file paths in the manifest are relative to it.
/// See studies/*.toml for examples and docs/guide.md for every field.
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment, allow_negative_numbers = true)]
pub struct Args {
    /// The study manifest (TOML).
    pub manifest: PathBuf,
    /// Run folder (default: runs/<study name> under the current directory).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Only check the manifest (fields, references, files) and exit.
    #[arg(long)]
    pub check: bool,
}

/// Runs `palpate run`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.check {
        let m = crate::manifest::Manifest::read(&args.manifest)?;
        m.validate(&args.manifest)?;
        println!(
            "{}: ok ({} data sets, {} models, {} steps)",
            args.manifest.display(),
            m.data.len(),
            m.models.len(),
            m.steps.len()
        );
        return Ok(());
    }
    let bar = indicatif::ProgressBar::new_spinner();
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    let observer = |msg: &str| bar.set_message(msg.to_string());
    let out = crate::runner::run_study(&args.manifest, args.out.as_deref(), &observer)?;
    bar.finish_and_clear();
    println!("study written to {}", out.display());
    println!("  {}", out.join("report.md").display());
    Ok(())
}
