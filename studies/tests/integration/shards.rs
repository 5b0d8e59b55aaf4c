//! `palpate run --shard I/N` as separate processes, then `palpate merge`,
//! writes the same bytes as `palpate run` in one process: a calibrate ->
//! predict (FE, N1 coarse) -> anova chain, merged after one pass of the
//! shards (the merge computes the deferred FE runs) and after two passes
//! (the shards compute them, the merge only assembles). The same for two
//! sample steps, whose chains and surrogate FE runs are units, and (ignored:
//! minutes of CPU) a localize step, whose FE runs and posterior are. Bad
//! `--shard` values and a merge with a shard missing are refused with the
//! reason.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/mesa2011")
}

/// The Mesa-Munera chain of tests/integration/mesa2011.rs, axisymmetric only, records
/// cut at 1 mm (5 load steps per FE run).
fn manifest(dir: &Path) -> PathBuf {
    let recs: Vec<PathBuf> = (1..=3)
        .map(|r| {
            let text = std::fs::read_to_string(data_dir().join(format!("needle-{r}.csv"))).unwrap();
            let kept: Vec<&str> = text
                .lines()
                .filter(|l| {
                    l.starts_with('#')
                        || l.starts_with("displacement")
                        || l.split(',').next().unwrap().parse::<f64>().unwrap() <= 1.0
                })
                .collect();
            let p = dir.join(format!("needle-{r}.csv"));
            std::fs::write(&p, kept.join("\n") + "\n").unwrap();
            p
        })
        .collect();
    let text = format!(
        r#"
[study]
name = "sharded"
seed = 1

[data.compression]
file = "{c}"
test = "C1"

[data.needle-1]
file = "{n1}"
test = "N1"

[data.needle-2]
file = "{n2}"
test = "N1"

[data.needle-3]
file = "{n3}"
test = "N1"

[models.nh.c1]
law = "neo-hookean"

[models.rp.c1]
law = "reduced-polynomial:2"

[models.nh-axi.n1_needle]
law = "neo-hookean"
mesh = "coarse"

[models.rp-axi.n1_needle]
law = "reduced-polynomial:2"
mesh = "coarse"

[[steps]]
[steps.calibrate]
name = "compression"
models = ["nh", "rp"]
fits = {{ c1 = ["compression"] }}

[[steps]]
[steps.calibrate]
name = "relative"
models = ["nh", "rp"]
fits = {{ c1 = ["compression"] }}
residuals = ["relative"]

[[steps]]
[steps.predict]
name = "needle"
calibration = "compression"
models = ["nh-axi", "rp-axi"]
data = ["needle-1", "needle-2", "needle-3"]

[[steps]]
[steps.anova]
name = "law"
predictions = "needle"
factors.material = {{ nh-axi = "NH", rp-axi = "RP" }}
"#,
        c = data_dir().join("c1-compression.csv").display(),
        n1 = recs[0].display(),
        n2 = recs[1].display(),
        n3 = recs[2].display(),
    );
    let path = dir.join("sharded.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn palpate(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_palpate"));
    c.args(args);
    c
}

fn ok(out: Output, what: &str) -> String {
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{what} failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// Runs the N shards at once, as separate processes.
fn shards(m: &Path, out: &Path, n: usize) -> Vec<String> {
    let children: Vec<_> = (0..n)
        .map(|i| {
            palpate(&[
                "run",
                m.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--shard",
                &format!("{i}/{n}"),
            ])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
        })
        .collect();
    children
        .into_iter()
        .enumerate()
        .map(|(i, c)| ok(c.wait_with_output().unwrap(), &format!("shard {i}/{n}")))
        .collect()
}

/// The files a run writes (provenance.json holds times and the command line).
fn compared_files(dir: &Path) -> Vec<String> {
    let mut files = vec!["results.json".to_string(), "report.md".to_string()];
    // (A study without plots has no plots folder.)
    let mut plots: Vec<String> = std::fs::read_dir(dir.join("plots"))
        .map(|d| {
            d.map(|e| format!("plots/{}", e.unwrap().file_name().to_string_lossy()))
                .collect()
        })
        .unwrap_or_default();
    plots.sort();
    files.extend(plots);
    files
}

fn assert_same(a: &Path, b: &Path) {
    let files = compared_files(a);
    assert_eq!(files, compared_files(b), "different plots");
    for f in files {
        let (x, y) = (
            std::fs::read(a.join(&f)).unwrap(),
            std::fs::read(b.join(&f)).unwrap(),
        );
        assert!(x == y, "{f} differs between the single run and the merge");
    }
}

#[test]
fn shards_then_merge_write_the_bytes_of_a_single_run() {
    let dir = tempfile::tempdir().unwrap();
    let m = manifest(dir.path());
    let single = dir.path().join("single");
    ok(
        palpate(&[
            "run",
            m.to_str().unwrap(),
            "--out",
            single.to_str().unwrap(),
        ])
        .output()
        .unwrap(),
        "single run",
    );
    assert!(compared_files(&single).len() >= 6);

    // One pass of 3 shards: the 4 fits of two calibrate steps spread over
    // them (1, 2 and 1); the predict step waits for the fits, so its 2 FE
    // runs are left to the merge, unless a shard found all the fits already
    // cached by faster ones and ran its own FE run. Either way every unit
    // is computed exactly once.
    let one = dir.path().join("one-pass");
    let said = shards(&m, &one, 3);
    let fits: Vec<usize> = said.iter().map(|s| count(s, "units computed")).collect();
    assert!(fits[0] >= 1 && fits[1] >= 2 && fits[2] >= 1, "{said:?}");
    assert!(said[0].contains("shard 0/3 done"), "{}", said[0]);
    assert!(!one.join("results.json").exists() && one.join("INCOMPLETE").exists());
    let merged = ok(
        palpate(&["merge", one.to_str().unwrap()]).output().unwrap(),
        "merge",
    );
    assert!(merged.contains("merged 3 shards"), "{merged}");
    let here = count(&merged, "computed here");
    assert_eq!(fits.iter().sum::<usize>() + here, 6, "{said:?} {merged}");
    assert_eq!(
        count(&merged, "units from the shards' cache") + here,
        6,
        "{merged}"
    );
    assert_same(&single, &one);
    assert!(!one.join("INCOMPLETE").exists());

    // Two passes of 2 shards: the second spreads the FE runs; the merge
    // only assembles.
    two_passes_then_merge(&m, &dir.path().join("two-passes"), &single, 6);
}

/// Two passes of 2 shards into `two` (the second computes what waited on
/// the first), which compute `units` units between them; the merge then
/// only assembles, and the run folder equals the single run's `single`.
fn two_passes_then_merge(m: &Path, two: &Path, single: &Path, units: usize) {
    let first = shards(m, two, 2);
    let second = shards(m, two, 2);
    let total: usize = first
        .iter()
        .chain(&second)
        .map(|s| count(s, "units computed"))
        .sum();
    assert_eq!(total, units, "{first:?} {second:?}");
    let merged = ok(
        palpate(&["merge", two.to_str().unwrap()]).output().unwrap(),
        "merge",
    );
    assert!(
        merged.contains(&format!(
            "{units} units from the shards' cache, 0 computed here"
        )),
        "{merged}"
    );
    assert_same(single, two);
}

/// A run of the manifest `m` in one process into `out`: what it printed
/// and its results.json.
fn single_run(m: &Path, out: &Path) -> (String, serde_json::Value) {
    let said = ok(
        palpate(&["run", m.to_str().unwrap(), "--out", out.to_str().unwrap()])
            .output()
            .unwrap(),
        "single run",
    );
    let results =
        serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    (said, results)
}

/// The number before `what` in a line of output.
fn count(text: &str, what: &str) -> usize {
    let at = text
        .find(what)
        .unwrap_or_else(|| panic!("no `{what}` in {text}"));
    text[..at]
        .split_whitespace()
        .last()
        .and_then(|n| n.trim_start_matches(':').parse().ok())
        .unwrap_or_else(|| panic!("no count before `{what}` in {text}"))
}

fn fails(out: Output) -> String {
    assert!(!out.status.success(), "accepted");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn bad_shards_and_an_unfinished_merge_are_refused_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let m = manifest(dir.path());
    let out = dir.path().join("run");
    let (m, o) = (m.to_str().unwrap(), out.to_str().unwrap());
    for (shard, says) in [
        ("3/2", "shard index 3 is not below the shard count 2"),
        ("0/0", "shard count must be at least 1"),
        ("garbage", "expected I/N"),
        ("1/two", "shard count `two` is not a whole number"),
    ] {
        let e = fails(
            palpate(&["run", m, "--out", o, "--shard", shard])
                .output()
                .unwrap(),
        );
        assert!(e.contains("--shard") && e.contains(says), "{shard}: {e}");
    }
    let e = fails(
        palpate(&["run", m, "--out", o, "--shard", "0/2", "--fresh"])
            .output()
            .unwrap(),
    );
    assert!(e.contains("--fresh with --shard 0/2"), "{e}");

    let e = fails(palpate(&["merge", o]).output().unwrap());
    assert!(e.contains("does not exist"), "{e}");
    ok(
        palpate(&["run", m, "--out", o, "--shard", "1/2"])
            .output()
            .unwrap(),
        "shard 1/2",
    );
    let e = fails(palpate(&["merge", o]).output().unwrap());
    assert!(
        e.contains("of 2 shards, 1 not finished (0/2)") && e.contains("--shard I/N"),
        "{e}"
    );
    // An edit of the manifest after the shards ran.
    ok(
        palpate(&["run", m, "--out", o, "--shard", "0/2"])
            .output()
            .unwrap(),
        "shard 0/2",
    );
    let text = std::fs::read_to_string(m).unwrap();
    std::fs::write(m, text.replace("seed = 1", "seed = 2")).unwrap();
    let e = fails(palpate(&["merge", o]).output().unwrap());
    assert!(e.contains("run the shards again"), "{e}");
}

/// The Slurm scripts of docs/cluster.md, run as Slurm would run them.
fn script(name: &str) -> String {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/cluster.md"))
            .unwrap();
    doc.split("```bash\n")
        .skip(1)
        .map(|b| b.split("```").next().unwrap())
        .find(|b| {
            b.lines()
                .nth(1)
                .is_some_and(|l| l.starts_with(&format!("# {name}:")))
        })
        .unwrap_or_else(|| panic!("docs/cluster.md has no {name}"))
        .to_string()
}

#[test]
fn the_slurm_scripts_of_the_docs_run_an_array_and_merge_it() {
    let dir = tempfile::tempdir().unwrap();
    let m = manifest(dir.path());
    let single = dir.path().join("single");
    ok(
        palpate(&[
            "run",
            m.to_str().unwrap(),
            "--out",
            single.to_str().unwrap(),
        ])
        .output()
        .unwrap(),
        "single run",
    );
    let run_dir = dir.path().join("slurm");
    let (shards_sh, merge_sh) = (dir.path().join("shards.sh"), dir.path().join("merge.sh"));
    std::fs::write(&shards_sh, script("shards.sh")).unwrap();
    std::fs::write(&merge_sh, script("merge.sh")).unwrap();
    let env = |c: &mut Command| {
        c.env("PALPATE", env!("CARGO_BIN_EXE_palpate"))
            .env("STUDY", &m)
            .env("RUN_DIR", &run_dir)
            .env("SLURM_CPUS_PER_TASK", "1")
            .current_dir(dir.path());
    };
    // Two passes of a 2-task array (each task its own process), then the merge.
    for _pass in 0..2 {
        let tasks: Vec<_> = (0..2)
            .map(|i| {
                let mut c = Command::new("bash");
                c.arg(&shards_sh)
                    .env("SLURM_ARRAY_TASK_ID", i.to_string())
                    .env("SLURM_ARRAY_TASK_COUNT", "2")
                    .stdout(std::process::Stdio::piped())
                    .stderr(std::process::Stdio::piped());
                env(&mut c);
                c.spawn().unwrap()
            })
            .collect();
        for t in tasks {
            ok(t.wait_with_output().unwrap(), "shards.sh");
        }
    }
    let mut c = Command::new("bash");
    c.arg(&merge_sh);
    env(&mut c);
    let said = ok(c.output().unwrap(), "merge.sh");
    assert!(said.contains("0 computed here"), "{said}");
    assert_same(&single, &run_dir);
}

/// A study of two sample steps: a C1 posterior (analytic model, 4 NUTS
/// chains) and an N1 posterior through a surrogate (coarse mesh, record cut
/// at 1 mm: 5 load steps; 4 + 2 FE runs in its design, 2 chains). Units:
/// 4 chains; 6 FE runs, then 2 chains that need all 6.
fn sample_manifest(dir: &Path) -> PathBuf {
    manifest(dir); // writes the cut needle records
    let text = format!(
        r#"
[study]
name = "sampled"
seed = 5

[data.compression]
file = "{c}"
test = "C1"

[data.needle-1]
file = "{n1}"
test = "N1"

[models.nh]
law = "neo-hookean"

[models.nh-axi.n1_needle]
law = "neo-hookean"
mesh = "coarse"

[[steps]]
[steps.sample]
name = "c1-posterior"
model = "nh"
data = ["compression"]
draws = 150
tune = 150
chains = 4

[[steps]]
[steps.sample]
name = "n1-posterior"
model = "nh-axi"
data = ["needle-1"]
sampler = "demc"
draws = 100
tune = 100
chains = 2
box = {{ C10 = [0.0002, 0.003] }}
design = 4
holdout = 2
"#,
        c = data_dir().join("c1-compression.csv").display(),
        n1 = dir.join("needle-1.csv").display(),
    );
    let path = dir.join("sampled.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn chains_and_surrogate_runs_are_shard_units_and_merge_to_the_single_run() {
    let dir = tempfile::tempdir().unwrap();
    let m = sample_manifest(dir.path());
    let single = dir.path().join("single");
    let (said, results) = single_run(&m, &single);
    let steps = results["steps"].as_array().unwrap();
    let c1 = &steps[0]["sample"]["result"];
    assert_eq!(c1["chains"], 4, "{said}");
    assert_eq!(c1["draws_per_chain"], 150);
    assert!(c1["params"]["C10"]["mean"].as_f64().unwrap() > 0.0);
    let n1 = &steps[1]["sample"]["result"];
    assert_eq!(n1["surrogate"]["training_runs"], 4, "{n1}");
    assert_eq!(n1["surrogate"]["held_out_runs"], 2, "{n1}");
    assert_eq!(
        n1["chains"].as_u64().unwrap(),
        2 * 3,
        "demc: 2 populations of 3 chains"
    );

    // One pass of 3 shards: the 4 C1 chains and the 6 FE runs are spread;
    // the N1 chains wait for all 6 FE runs, so the merge computes those
    // still missing. Every unit is computed exactly once.
    let one = dir.path().join("one-pass");
    let said = shards(&m, &one, 3);
    let computed: Vec<usize> = said.iter().map(|s| count(s, "units computed")).collect();
    assert!(computed.iter().all(|&c| c >= 3), "{said:?}");
    let merged = ok(
        palpate(&["merge", one.to_str().unwrap()]).output().unwrap(),
        "merge",
    );
    let here = count(&merged, "computed here");
    assert_eq!(
        computed.iter().sum::<usize>() + here,
        12,
        "{said:?} {merged}"
    );
    assert_same(&single, &one);

    // Two passes of 2 shards: the second pass runs the N1 chains on the
    // surrogate the first pass's FE runs make; the merge only assembles.
    two_passes_then_merge(&m, &dir.path().join("two-passes"), &single, 12);
}

/// The cheapest localize step the manifest allows: one RD (3 mm), one
/// nodule (75:15), the record on a 3 mm mesh every 10 mm (14 positions).
/// The localisation model is fixed by R2; `scan = "centre"` (`LocSetup::r2`:
/// 6 + 2 FE scans of 16 offsets at h = 2 mm, and the nodule-free pass of 34
/// positions) leaves out the default lean's 16 FE scans, whose units are
/// tested on a stand-in by localize_units.rs.
/// Units: 10 FE runs (the pass, 8 scans, the record), then 1 posterior.
fn localize_manifest(dir: &Path) -> PathBuf {
    let text = r#"
[study]
name = "localized"
seed = 3

[[steps]]
[steps.localize]
name = "r2"
rds = [3]
nodules = "75:15"
record_h_mm = 3.0
record_step_mm = 10.0
noise = 0.01
scan = "centre"
"#;
    let path = dir.join("localized.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// A localize step's FE runs and its posterior are shard units: two
/// passes of two shards (the first computes the 10 FE runs, 5 each; the
/// second the posterior, which needs them all), then the merge, which only
/// assembles; its files (results, report, the record, the localisation
/// JSON and plot) are byte for byte those of a single run.
///
/// Cost: the single run and the shards each compute the 10 FE runs once,
/// far past the ~90 s of CPU an un-ignored test may take (one run of this
/// step: 367 s of CPU in the dev profile). Measured in release on the
/// 2-core machine shared with other jobs (load average 7.3 to 10.4): the
/// whole test 499 s of CPU (user+sys), 819 s wall (a second run: 703 s
/// wall); per process in
/// docs/cluster.md ("A localize step"). The units' enumeration and
/// assembly are tested cheaply by studies/tests/integration/localize_units.rs.
#[test]
#[ignore = "about 8 minutes of CPU: cargo test -p palpate-studies --release --test integration -- --ignored shards::localize"]
fn localize_fe_runs_and_posterior_are_shard_units_and_merge_to_the_single_run() {
    let dir = tempfile::tempdir().unwrap();
    let m = localize_manifest(dir.path());
    let single = dir.path().join("single");
    let (said, results) = single_run(&m, &single);
    let rd = &results["steps"][0]["localize"]["results"][0];
    assert_eq!(rd["rd_mm"], 3.0, "{said}");
    assert_eq!(rd["localisation"]["surrogate"]["fe_runs"], 9, "{rd}");

    let sharded = dir.path().join("sharded");
    let first = shards(&m, &sharded, 2);
    let fe: Vec<usize> = first.iter().map(|s| count(s, "units computed")).collect();
    assert_eq!(fe, [5, 5], "{first:?}");
    assert!(!sharded.join("results.json").exists());
    let second = shards(&m, &sharded, 2);
    let post: Vec<usize> = second.iter().map(|s| count(s, "units computed")).collect();
    assert_eq!(post.iter().sum::<usize>(), 1, "{second:?}");
    let merged = ok(
        palpate(&["merge", sharded.to_str().unwrap()])
            .output()
            .unwrap(),
        "merge",
    );
    assert!(
        merged.contains("11 units from the shards' cache, 0 computed here"),
        "{merged}"
    );
    assert_same(&single, &sharded);
    for f in ["r2-rd3-record.csv", "r2-rd3.json", "r2-rd3.svg"] {
        let (x, y) = (
            std::fs::read(single.join(f)).unwrap(),
            std::fs::read(sharded.join(f)).unwrap(),
        );
        assert!(x == y, "{f} differs between the single run and the merge");
    }
}
