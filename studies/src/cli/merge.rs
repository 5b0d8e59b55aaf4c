//! `palpate merge RUN_DIR`: assemble the results of the shards of a study.

use std::path::PathBuf;

/// Assemble a study's results from its shards (palpate run --shard I/N).
///
/// Checks that every shard of one count N has finished in RUN_DIR (each
/// leaves RUN_DIR/.palpate/shards/I-of-N.json) and that the manifest is
/// unchanged since, then runs the study into RUN_DIR over the cache the
/// shards filled: results.json, report.md and plots/ are byte-identical to
/// those of `palpate run` without shards. Units of steps the shards had to
/// defer (a predict step on the fits of a calibrate step split over
/// shards) are computed here; run the shards a second time first to spread
/// them too. Run it from the shards' working directory. See docs/cluster.md.
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// The run folder the shards wrote into (their --out).
    pub run_dir: PathBuf,
}

/// Runs `palpate merge`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let observer = super::run::CliObserver::new();
    let merged = crate::study::merge::merge(&args.run_dir, &observer);
    observer.finish();
    let m = merged?;
    println!(
        "merged {} shards into {}: {} units from the shards' cache, {} computed here",
        m.shards,
        m.folder.display(),
        m.cached,
        m.computed
    );
    println!("  {}", m.folder.join("report.md").display());
    Ok(())
}
