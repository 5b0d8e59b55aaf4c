//! The `palpate` binary as a user meets it: good runs write their files, bad
//! input gives a clear error naming the file, line or field (exit code 2),
//! never a panic.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn palpate(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_palpate"))
        .args(args)
        .output()
        .expect("run palpate")
}

fn treloar(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/treloar")
        .join(name)
        .display()
        .to_string()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

fn assert_clean_failure(o: &Output, needles: &[&str]) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(2), "exit code; stderr: {e}");
    assert!(!e.contains("panicked"), "panic: {e}");
    for n in needles {
        assert!(e.contains(n), "`{n}` not in: {e}");
    }
}

#[test]
fn calibrate_writes_json_with_every_parameter_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("fit.json");
    let svg = dir.path().join("fit.svg");
    let uni = format!("uniaxial={}", treloar("uniaxial.csv"));
    let bi = format!("biaxial={}", treloar("biaxial.csv"));
    let o = palpate(&[
        "calibrate",
        "--law",
        "mooney-rivlin",
        "--data",
        &uni,
        "--data",
        &bi,
        "--residual",
        "relative",
        "--json",
        json.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    for p in ["C10", "C01"] {
        assert!(v["params"][p]["value"].is_f64(), "{p}: {v}");
        assert!(v["params"][p]["standard_error"].is_f64(), "{p}");
    }
    for k in ["r2", "rms", "iterations", "evaluations"] {
        assert!(v[k].is_number(), "{k}");
    }
    assert!(v["drucker"]["uniaxial"]["upper"].is_f64());
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
}

#[test]
fn calibrate_c1_benchmark_record() {
    let dir = tempfile::tempdir().unwrap();
    // A noise-free C1 record of ecoflex-nh: F = 2 C10 (1/s^2 - s) A, s = 1 - d/9.
    let area = std::f64::consts::PI * 19.0 * 19.0;
    let mut csv = String::from("time_s,displacement_mm,force_N\n");
    for i in 0..=40 {
        let d = 0.05 * i as f64;
        let s: f64 = 1.0 - d / 9.0;
        let f = 2.0 * 1.101295e-3 * (1.0 / (s * s) - s) * area;
        csv.push_str(&format!("{},{d},{f}\n", d / 0.4));
    }
    let file = dir.path().join("c1.csv");
    std::fs::write(&file, csv).unwrap();
    let json = dir.path().join("c1.json");
    let o = palpate(&[
        "calibrate",
        "--benchmark",
        "C1",
        "--law",
        "neo-hookean",
        "--data",
        file.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let c10 = v["params"]["C10"]["value"].as_f64().unwrap();
    assert!((c10 / 1.101295e-3 - 1.0).abs() < 1e-6, "{c10}");
}

#[test]
fn malformed_csv_names_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bad.csv");
    std::fs::write(&file, "# comment\nstretch,stress_MPa\n1,0\n1.5,oops\n").unwrap();
    let arg = format!("uniaxial={}", file.display());
    let o = palpate(&["calibrate", "--law", "neo-hookean", "--data", &arg]);
    assert_clean_failure(&o, &["bad.csv:4", "stress_MPa", "oops"]);
    std::fs::write(&file, "stretch,force_N\n1,0\n").unwrap();
    let o = palpate(&["calibrate", "--law", "neo-hookean", "--data", &arg]);
    assert_clean_failure(&o, &["bad.csv", "stress_MPa"]);
}

#[test]
fn bad_options_are_named() {
    let uni = format!("uniaxial={}", treloar("uniaxial.csv"));
    assert_clean_failure(
        &palpate(&["calibrate", "--law", "neo-hooke", "--data", &uni]),
        &["--law", "neo-hooke"],
    );
    assert_clean_failure(
        &palpate(&["calibrate", "--law", "neo-hookean", "--data", "shear=x.csv"]),
        &["shear"],
    );
    assert_clean_failure(
        &palpate(&[
            "calibrate",
            "--law",
            "neo-hookean",
            "--data",
            &uni,
            "--fix",
            "C10=-1",
        ]),
        &["C10"],
    );
    assert_clean_failure(
        &palpate(&[
            "calibrate",
            "--law",
            "neo-hookean",
            "--data",
            "uniaxial=/no/such/file.csv",
        ]),
        &["/no/such/file.csv"],
    );
    assert_clean_failure(
        &palpate(&[
            "simulate",
            "--benchmark",
            "C1",
            "--law",
            "neo-hookean",
            "--param",
            "C10=-0.001",
        ]),
        &["C10"],
    );
}

#[test]
fn run_check_reports_misspelled_manifest_field_with_line() {
    let dir = tempfile::tempdir().unwrap();
    let m: PathBuf = dir.path().join("s.toml");
    std::fs::write(&m, "[study]\nname = \"x\"\nseeed = 3\nsteps = []\n").unwrap();
    let o = palpate(&["run", "--check", m.to_str().unwrap()]);
    assert_clean_failure(&o, &["s.toml", "line 3", "seeed"]);
}

#[test]
fn mesh_zero_is_an_error_in_simulate_and_doe() {
    let o = palpate(&[
        "simulate",
        "--benchmark",
        "N1",
        "--law",
        "neo-hookean",
        "--param",
        "C10=0.001101295",
        "--mesh",
        "0",
    ]);
    assert_clean_failure(&o, &["--mesh", "`0`", "1..12"]);
    // doe used to run level 0 as level 1; every run's model is now checked
    // before any run starts.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("ref.csv"),
        "displacement_mm,force_N\n0,0\n1,0.1\n2,0.3\n",
    )
    .unwrap();
    let m = dir.path().join("d.toml");
    std::fs::write(
        &m,
        "[[factors]]\nname = \"mesh\"\nlevels = [\"0\", \"coarse\"]\n\n\
         [response.simulation]\nbenchmark = \"N1\"\nmetric = \"r2\"\nreference = \"ref.csv\"\n",
    )
    .unwrap();
    let o = palpate(&["doe", "--manifest", m.to_str().unwrap()]);
    assert_clean_failure(&o, &["n1_needle.mesh", "\"0\"", "1..12"]);
}

/// `simulate` states its discretisation error (one coarser solve,
/// Richardson with the model's documented order) and its volumetric
/// treatment, on the terminal and in the CSV's `#` lines, which the
/// project's reader skips; `--error-estimate off` runs one solve only.
#[test]
fn simulate_states_its_discretisation_error() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("c1.csv");
    let base = [
        "simulate",
        "--benchmark",
        "C1",
        "--bonded",
        "--law",
        "neo-hookean",
        "--param",
        "C10=0.001101295",
        "--mesh",
        "coarse",
        "--step",
        "1",
        "--csv",
        csv.to_str().unwrap(),
    ];
    let o = palpate(&base);
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    let line = "discretisation error (Richardson, order 0.58 from docs/validation/fe.md C1 bonded";
    for needle in [
        line,
        "coarse mesh 10x5",
        "% at 2 mm",
        "estimated converged force",
    ] {
        assert!(e.contains(needle), "`{needle}` not in: {e}");
    }
    assert!(e.contains("volumetric: exact incompressibility"), "{e}");
    let t = palpate_core::Table::read(&csv).unwrap();
    assert!(
        t.comments.iter().any(|c| c.starts_with(line)),
        "{:?}",
        t.comments
    );
    assert!(t
        .comments
        .iter()
        .any(|c| c.starts_with("volumetric: exact")));
    let f = t.column("force_N").unwrap();
    let err = t.column("error_estimate_N").unwrap();
    assert_eq!(err.len(), 3);
    // Bonded platens: the coarse mesh is stiffer, the fine one too.
    assert!(err[2] > 0.0 && err[2] < 0.1 * f[2], "{err:?} of {f:?}");

    let mut off = base.to_vec();
    off.extend(["--error-estimate", "off", "--bulk", "1000"]);
    let o = palpate(&off);
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    assert!(!e.contains("Richardson"), "{e}");
    assert!(e.contains("K = 1000 x mu"), "{e}");
    let t = palpate_core::Table::read(&csv).unwrap();
    assert!(t.column("error_estimate_N").is_err());
    assert!(!t.comments.iter().any(|c| c.contains("Richardson")));
    assert!(t.comments.iter().any(|c| c.contains("K = 1000 x mu")));

    let mut bad = base.to_vec();
    bad.extend(["--order", "0"]);
    assert_clean_failure(&palpate(&bad), &["--order"]);
}

/// `simulate --prony` on C1: a timed ramp and hold written with `time_s`,
/// relaxing over the hold towards `g_inf` times the elastic force; bad
/// Prony series and misplaced timing options are clear errors.
#[test]
fn simulate_c1_viscoelastic_ramp_and_hold() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("c1v.csv");
    let o = palpate(&[
        "simulate",
        "--benchmark",
        "C1",
        "--law",
        "neo-hookean",
        "--param",
        "C10=0.001101295",
        "--mesh",
        "coarse",
        "--depth",
        "1.8",
        "--prony",
        "g1=0.3,tau1=0.2,g2=0.25,tau2=2",
        "--ramp",
        "1",
        "--hold",
        "20",
        "--error-estimate",
        "off",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let t = palpate_core::Table::read(&csv).unwrap();
    let time = t.column("time_s").unwrap();
    let f = t.column("force_N").unwrap();
    assert_eq!(time.len(), 19 + 200);
    assert!((time[18] - 1.0).abs() < 1e-9 && (time[218] - 21.0).abs() < 1e-9);
    // neo-Hookean elastic force at 1.8 mm: 2 C10 (1/l^2 - l) A, l = 0.8
    let elastic = 2.0 * 0.001101295 * (1.0 / 0.64 - 0.8) * std::f64::consts::PI * 19.0 * 19.0;
    assert!(f[18] < elastic && f[18] > f[218], "{} {}", f[18], f[218]);
    let relaxed = 0.45 * elastic;
    assert!(
        (f[218] - relaxed).abs() < 0.01 * relaxed,
        "{} vs {relaxed}",
        f[218]
    );

    let base = [
        "simulate",
        "--benchmark",
        "C1",
        "--law",
        "neo-hookean",
        "--param",
        "C10=0.001101295",
    ];
    for (extra, says) in [
        (
            &["--prony", "g1=0.6,tau1=1,g2=0.4,tau2=2"][..],
            &["--prony", "sum to 1"][..],
        ),
        (&["--prony", "g1=0.3,tau1=0"], &["tau1", "positive"]),
        (&["--hold", "5"], &["need --prony"]),
    ] {
        let mut args = base.to_vec();
        args.extend(extra);
        assert_clean_failure(&palpate(&args), says);
    }
}

/// `palpate simulate` of Q1 with a neo-Hookean material (C10 = 0.001 MPa).
const Q1_NH: [&str; 7] = [
    "simulate",
    "--benchmark",
    "Q1",
    "--law",
    "neo-hookean",
    "--param",
    "C10=0.001",
];

/// `simulate --benchmark Q1 --edge-radius`: the punch's edge rounding is
/// the user's to choose; a 1 mm edge is a rounded punch whose force at
/// 0.1 mm is well below the flat punch's (docs/validation/fe.md "Q1":
/// 0.571 of Sneddon's 8 G a d on 0.1 mm elements), and the CSV names it.
#[test]
fn simulate_q1_edge_radius_rounds_the_punch() {
    let dir = tempfile::tempdir().unwrap();
    let force = |edge: Option<&str>| {
        let csv = dir
            .path()
            .join(format!("q1-{}.csv", edge.unwrap_or("default")));
        let mut args = Q1_NH.to_vec();
        args.extend([
            "--mesh",
            "coarse",
            "--depth",
            "0.1",
            "--hold",
            "1",
            "--error-estimate",
            "off",
            "--csv",
            csv.to_str().unwrap(),
        ]);
        if let Some(e) = edge {
            args.extend(["--edge-radius", e]);
        }
        let o = palpate(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let text = std::fs::read_to_string(&csv).unwrap();
        let t = palpate_core::Table::read(&csv).unwrap();
        let f = t.column("force_N").unwrap();
        (f[100], text)
    };
    // Sneddon's incompressible flat punch: 8 G a d, G = 2 C10
    let sneddon = 8.0 * 2e-3 * 2.0 * 0.1;
    let (flat, text) = force(None);
    assert!(text.contains("edge 0.2 mm"), "{text}");
    assert!(
        (0.93..0.96).contains(&(flat / sneddon)),
        "{}",
        flat / sneddon
    );
    let (rounded, text) = force(Some("1"));
    assert!(text.contains("edge 1 mm"), "{text}");
    assert!(
        (0.55..0.62).contains(&(rounded / sneddon)),
        "{}",
        rounded / sneddon
    );
}

/// `simulate --benchmark Q1`: always timed (ramp then hold), `time_s`,
/// 100 ramp samples and 200 hold samples, relaxing with a Prony series;
/// bad timing and geometry-free options are clear errors.
#[test]
fn simulate_q1_ramp_and_hold() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("q1.csv");
    let mut args = Q1_NH.to_vec();
    args.extend([
        "--mesh",
        "coarse",
        "--depth",
        "0.1",
        "--prony",
        "g1=0.3,tau1=0.2,g2=0.2,tau2=2",
        "--ramp",
        "0.05",
        "--hold",
        "2",
        "--error-estimate",
        "off",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    let o = palpate(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(
        text.lines().any(|l| l == "time_s,displacement_mm,force_N"),
        "{text}"
    );
    let t = palpate_core::Table::read(&csv).unwrap();
    let time = t.column("time_s").unwrap();
    let f = t.column("force_N").unwrap();
    assert_eq!(time.len(), 101 + 200);
    assert!((time[100] - 0.05).abs() < 1e-9 && (time[300] - 2.05).abs() < 1e-9);
    // relaxes towards g_inf = 0.5 of the instantaneous force
    assert!(
        f[100] > f[300] && f[300] > 0.5 * f[100],
        "{} {}",
        f[100],
        f[300]
    );

    for (extra, says) in [
        (&["--hold=-1"][..], &["--hold", "zero or more"][..]),
        (&["--hold", "0.001"], &["--hold", "shorter than one step"]),
        (&["--ramp", "0"], &["--ramp", "positive"]),
        (&["--prony", "g1=0.3,tau1=-1"], &["tau1", "positive"]),
        (&["--element", "quad8"], &["--element", "quad4 or quad9"]),
    ] {
        let mut args = Q1_NH.to_vec();
        args.extend(extra);
        assert_clean_failure(&palpate(&args), says);
    }
}

/// With stderr not a terminal (a log file, CI), a long `sample` run still
/// shows that it is alive: plain progress lines instead of a hidden bar.
#[test]
fn sample_reports_progress_when_stderr_is_not_a_terminal() {
    let uni = format!("uniaxial={}", treloar("uniaxial.csv"));
    let o = palpate(&[
        "sample",
        "--law",
        "neo-hookean",
        "--data",
        &uni,
        "--draws",
        "200",
        "--tune",
        "200",
        "--parallel",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines: Vec<String> = stderr(&o)
        .lines()
        .filter(|l| l.starts_with("nuts: ") && l.ends_with("%)"))
        .map(String::from)
        .collect();
    assert!(lines.len() >= 3, "progress lines: {lines:?}");
    assert!(lines.iter().any(|l| l.contains("/800 (")), "{lines:?}");
}

/// `palpate CMD --help` shows the subcommand's own description, not only a
/// one-line summary (a `///` comment on a `Command` variant would replace
/// the `Args` doc comment: clap), and the summary is the line of `palpate
/// --help`.
#[test]
fn every_subcommands_help_explains_itself() {
    let top = String::from_utf8_lossy(&palpate(&["--help"]).stdout).to_string();
    for (cmd, needle) in [
        (vec!["calibrate"], "Homogeneous tests"),
        (vec!["simulate"], "Richardson"),
        (vec!["sample"], "R-hat"),
        (vec!["anova"], "Bartlett"),
        (vec!["doe"], "design.csv"),
        (vec!["diagnose"], "candidates"),
        (vec!["run"], "INCOMPLETE"),
        (vec!["realtime"], "query"),
        (vec!["realtime", "build"], "held-out"),
        (vec!["realtime", "query"], "depth-max"),
        (vec!["localize"], "credible intervals"),
    ] {
        let mut args = cmd.clone();
        args.push("--help");
        let o = palpate(&args);
        let help = String::from_utf8_lossy(&o.stdout).to_string();
        assert!(o.status.success(), "{cmd:?}: {}", stderr(&o));
        assert!(
            help.contains(needle),
            "{cmd:?} --help lacks `{needle}`:\n{help}"
        );
        // Summary, blank line, then a description before the usage line.
        let lines: Vec<&str> = help.lines().collect();
        assert!(
            lines.len() > 3 && lines[1].is_empty() && !lines[2].starts_with("Usage:"),
            "{cmd:?} --help has no description:\n{help}"
        );
        if cmd.len() == 1 {
            assert!(
                top.lines()
                    .any(|l| l.trim_start().starts_with(cmd[0]) && l.contains(lines[0])),
                "`palpate --help` does not list {} with `{}`",
                cmd[0],
                lines[0]
            );
        }
    }
}

/// `palpate realtime`'s help quotes no measured accuracy: it names the
/// page that holds it; its former name `surrogate` is a hidden alias.
#[test]
fn realtime_help_links_to_its_accuracy_page() {
    for cmd in [
        vec!["realtime"],
        vec!["realtime", "build"],
        vec!["realtime", "query"],
    ] {
        let mut args = cmd.clone();
        args.push("--help");
        let help = String::from_utf8_lossy(&palpate(&args).stdout).to_string();
        let measured = help
            .char_indices()
            .filter(|&(_, c)| c == '%')
            .any(|(i, _)| help[..i].trim_end().ends_with(|c: char| c.is_ascii_digit()));
        assert!(!measured, "{cmd:?} --help quotes a percentage:\n{help}");
        if cmd.len() < 3 {
            assert!(
                help.contains("docs/validation/realtime.md"),
                "{cmd:?}:\n{help}"
            );
        }
    }
    let top = String::from_utf8_lossy(&palpate(&["--help"]).stdout).to_string();
    let listed = |name: &str| top.lines().any(|l| l.trim_start().starts_with(name));
    assert!(listed("realtime") && !listed("surrogate"), "{top}");
    let old = palpate(&["surrogate", "build", "--help"]);
    assert!(old.status.success(), "{}", stderr(&old));
    assert!(String::from_utf8_lossy(&old.stdout).contains("held-out"));
}

/// A parameter the fit leaves on a bound of its range is said to be there
/// in report.md (brain cortex compression/tension, Ogden-2: the second term
/// is not needed, its exponent ends on +OGDEN_ALPHA_BOUND with mu ~ 1e-5 MPa,
/// docs/validation/real-data.md).
#[test]
fn the_report_says_when_a_parameter_ends_on_its_bound() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = dir.path().join("s.toml");
    std::fs::write(
        &manifest,
        format!(
            "[study]\nname = \"bound\"\nseed = 1\n\n\
             [data.uniaxial]\nfile = \"{}\"\ntest = \"uniaxial\"\n\n\
             [models.ogden2]\nlaw = \"ogden:2\"\n\n\
             [[steps]]\n[steps.calibrate]\nname = \"fit\"\nmodels = [\"ogden2\"]\n\
             fits = {{ uniaxial = [\"uniaxial\"] }}\nresiduals = [\"absolute\"]\n",
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("data/real/brain_budday2017/cortex_compression_tension.csv")
                .display()
        ),
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = palpate(&[
        "run",
        manifest.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("= 5.00000e1 (on its upper bound)"),
        "{report}"
    );
}
