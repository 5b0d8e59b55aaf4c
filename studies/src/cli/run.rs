//! `palpate run STUDY.toml`: run a whole study from one manifest.

use std::io::IsTerminal;
use std::path::PathBuf;

/// Run a whole study described by one TOML manifest into a run folder
///
/// Writes into the run folder (default runs/<study name>): results.json
/// (byte-identical when the same manifest is run again), report.md, plots/*.svg
/// and provenance.json (manifest and data hashes, git commit, crate versions,
/// seed, thread count). Data file paths in the manifest are relative to it.
///
/// The run folder is safe to rerun into and to interrupt:
///   * the run is written into DIR/.palpate/staging and swapped in at the end,
///     so the folder holds either the previous complete run or the new one,
///     never a mix of both; files of a previous run that this one does not
///     write (plots of a larger study) are removed;
///   * DIR/INCOMPLETE is present while the folder holds no complete run;
///   * each fit, each diagnosed record and each model run of a predict step
///     is cached in DIR/.palpate/cache under the hash of its inputs: a rerun after a kill (Ctrl-C, SIGKILL)
///     or after editing another step computes only what changed (--fresh
///     computes everything again);
///   * one run at a time: a second run into the same folder is refused with
///     the pid of the one writing it.
///
/// See studies/*.toml for examples and docs/guide/studies-and-clusters.md for every field.
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment, allow_negative_numbers = true)]
pub struct Args {
    /// The study manifest (TOML).
    pub manifest: PathBuf,
    /// Run folder (default: runs/<study name> under the current directory).
    /// It must be new, empty or a run folder of palpate.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Only check the manifest (fields, references) and read every data
    /// file it names, then exit without running.
    #[arg(long)]
    pub check: bool,
    /// Compute every fit and diagnosis again instead of reusing the ones
    /// cached in the run folder.
    #[arg(long)]
    pub fresh: bool,
    /// Compute only the I-th of N deterministic slices of the study's units
    /// (fits, diagnosed records, model runs of predict steps, two-stage
    /// identifications) into the run folder's cache, 0 <= I < N; shards
    /// run at the same time, as separate processes or on other machines
    /// sharing the folder. Then `palpate merge DIR` writes the results,
    /// byte-identical to a run without shards. See docs/cluster.md.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<crate::run::shard::Shard>,
}

/// Runs `palpate run`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.check {
        let c = crate::api::check_study(&args.manifest)?;
        println!(
            "{}: ok ({} data sets with {} rows, {} models, {} steps)",
            args.manifest.display(),
            c.data_sets,
            c.rows,
            c.models,
            c.steps
        );
        return Ok(());
    }
    let observer = CliObserver::new();
    let bar = observer.bar.clone();
    let options = crate::study::runner::RunOptions {
        out: args.out.clone(),
        fresh: args.fresh,
        shard: args.shard,
    };
    let summary = crate::api::run_study(&args.manifest, &options, &observer);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let summary = summary?;
    let out = summary.folder;
    if let Some(shard) = args.shard {
        let u = summary.units;
        println!(
            "shard {shard} done in {}: {} units computed, {} cached, {} of other shards not yet cached",
            out.display(),
            u.computed,
            u.cached,
            u.others
        );
        if !summary.deferred_steps.is_empty() {
            println!(
                "  steps left to a second pass of the shards or to the merge: {}",
                summary.deferred_steps.join(", ")
            );
        }
        println!(
            "  when every shard is done: palpate merge {}",
            out.display()
        );
        return Ok(());
    }
    println!("study written to {}", out.display());
    println!("  {}", out.join("report.md").display());
    Ok(())
}

/// What `palpate run` shows: messages on a spinner, FE load steps on a bar
/// (a terminal), or plain lines, progress every 10 % (a log file).
pub(crate) struct CliObserver {
    bar: Option<indicatif::ProgressBar>,
    /// The label and the tenth last printed (plain lines).
    shown: std::sync::Mutex<(String, u64)>,
}

impl CliObserver {
    /// A spinner on a terminal (a bar over the FE runs of a predict step);
    /// plain lines when stderr is a log file.
    pub(crate) fn new() -> CliObserver {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = indicatif::ProgressBar::new_spinner();
            bar.enable_steady_tick(std::time::Duration::from_millis(120));
            bar
        });
        CliObserver {
            bar,
            shown: std::sync::Mutex::new((String::new(), 0)),
        }
    }

    /// Clears the spinner.
    pub(crate) fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

const SPINNER: &str = "{spinner} {msg}";
const BAR: &str = "{msg} [{bar:30}] {pos}/{len} load steps ({elapsed}, eta {eta})";

impl crate::study::runner::RunObserver for CliObserver {
    fn message(&self, text: &str) {
        match &self.bar {
            Some(b) => {
                if let Ok(style) = indicatif::ProgressStyle::with_template(SPINNER) {
                    b.set_style(style);
                }
                b.set_message(text.to_string());
            }
            None => eprintln!("{text}"),
        }
    }

    fn progress(&self, label: &str, done: u64, total: u64) {
        match &self.bar {
            Some(b) => {
                if b.length() != Some(total) {
                    if let Ok(style) = indicatif::ProgressStyle::with_template(BAR) {
                        b.set_style(style.progress_chars("=> "));
                    }
                    b.set_length(total);
                    b.set_message(label.to_string());
                }
                b.set_position(done);
            }
            None => {
                let tenth = done * 10 / total.max(1);
                if let Ok(mut shown) = self.shown.lock() {
                    if shown.0 != label || tenth > shown.1 {
                        eprintln!("{label}: {done}/{total} load steps ({} %)", 10 * tenth);
                        *shown = (label.to_string(), tenth);
                    }
                }
            }
        }
    }
}
