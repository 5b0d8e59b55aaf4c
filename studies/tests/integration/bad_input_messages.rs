//! Bad input, continued: every refusal names the
//! input (the option and its value, the manifest and its field, or
//! file:line) and says what would be valid; values that would fail deep in a
//! solver are refused before any work; an unwritable output is refused
//! before anything is computed or written. Each case asserts a non-zero
//! exit, no panic and the locator.

use crate::common;
use common::*;
use std::process::Output;

const UNI: &str = "stretch,stress_MPa\n1.0,0\n1.5,0.2\n2.0,0.35\n3.0,0.6\n";

fn simulate(s: &Scratch, benchmark: &str, extra: &[&str]) -> Output {
    let mut a = vec![
        "simulate",
        "--benchmark",
        benchmark,
        "--law",
        "neo-hookean",
        "--error-estimate",
        "off",
    ];
    a.extend_from_slice(extra);
    s.run(&a)
}

// ---------- values a solver cannot take ----------

#[test]
fn absurd_or_vanishing_moduli_are_refused_by_the_option() {
    let s = Scratch::new();
    for (value, needle) in [
        ("1e300", "within ±1e6"),
        ("1e7", "within ±1e6"),
        ("1e-300", "below 1e-6 MPa"),
        ("1e-12", "below 1e-6 MPa"),
        ("inf", "not finite"),
        ("NaN", "not finite"),
        ("-1", "must be > 0"),
        ("0", "must be > 0"),
    ] {
        let p = format!("C10={value}");
        let o = simulate(&s, "C1", &["--param", &p]);
        refused(&o, &["--param C10=", needle]);
        assert!(
            !String::from_utf8_lossy(&o.stderr).contains("18446744073709551615"),
            "the sentinel element index leaked"
        );
    }
    // A fixed parameter in a fit: by name, bounds and size.
    let u = format!("uniaxial={}", treloar("uniaxial.csv"));
    for (law, fix, needle) in [
        ("neo-hookean", "C10=1e300", "within ±1e6"),
        ("mooney-rivlin", "C01=1e300", "within ±1e6"),
        ("neo-hookean", "C10=-1", "strictly inside (0, inf)"),
        ("neo-hookean", "C11=0", "no parameter `C11`"),
        ("neo-hookean", "C10=0.001", "nothing is left to fit"),
        ("neo-hookean", "C10", "expected NAME=VALUE"),
        ("neo-hookean", "C10=abc", "not a finite number"),
    ] {
        let o = s.run(&["calibrate", "--law", law, "--data", &u, "--fix", fix]);
        refused(&o, &["--fix ", needle]);
    }
}

#[test]
fn a_tool_travelling_through_the_body_is_refused_before_solving() {
    let s = Scratch::new();
    for (benchmark, depth, height) in [
        ("C1", "9", "9 mm"),
        ("C1", "20", "9 mm"),
        ("C1", "1000", "9 mm"),
        ("N1", "80", "80 mm"),
        ("N1", "85", "80 mm"),
        ("Q1", "60", "60 mm"),
        ("Q1", "100", "60 mm"),
        ("N3", "80", "80 mm"),
    ] {
        let o = simulate(
            &s,
            benchmark,
            &["--param", "C10=0.0011", "--depth", depth, "--step", "1"],
        );
        refused(&o, &[&format!("--depth {depth}"), height, "below"]);
        assert!(
            !String::from_utf8_lossy(&o.stderr).contains("inverted"),
            "blamed on an element"
        );
    }
}

#[test]
fn settings_that_would_hang_or_overflow_a_solver_are_refused() {
    let s = Scratch::new();
    let c10 = ["--param", "C10=0.0011"];
    for (bench, extra, needles) in [
        (
            "N1",
            vec!["--tool", "sphere:1e9"],
            vec!["--tool sphere:1e9", "up to 35 mm"],
        ),
        (
            "N1",
            vec!["--tool", "punch:40"],
            vec!["--tool punch:40", "overhangs"],
        ),
        (
            "N3",
            vec!["--tool", "sphere:100"],
            vec!["--tool sphere:100", "half-width"],
        ),
        (
            "C1",
            vec!["--prony", "g1=0.5,tau1=1e-300"],
            vec!["--prony", "increments", "at most 1e5"],
        ),
        (
            "C1",
            vec!["--prony", "g1=0.5,tau1=1", "--hold", "1e300"],
            vec!["--hold", "1e300 s of history"],
        ),
        (
            "Q1",
            vec!["--prony", "g1=0.5,tau1=1e-6", "--depth", "0.1"],
            vec!["--prony", "60.5 s of history take 6.050e8 increments"],
        ),
        (
            "C1",
            vec!["--bulk", "1e300"],
            vec!["--bulk `1e300`", "(0, 1e9]"],
        ),
        (
            "C1",
            vec!["--bulk", "1e10"],
            vec!["--bulk `1e10`", "(0, 1e9]"],
        ),
    ] {
        let mut a: Vec<&str> = c10.to_vec();
        a.extend(extra);
        refused(&simulate(&s, bench, &a), &needles);
    }
    let o = s.run(&[
        "simulate",
        "--benchmark",
        "C1",
        "--law",
        "ogden:1",
        "--param",
        "mu1=0.001",
        "--param",
        "alpha1=1e300",
        "--error-estimate",
        "off",
    ]);
    refused(&o, &["--param alpha1=1e300", "[-50, 50]"]);
}

// ---------- how the command line is read ----------

#[test]
fn negative_numbers_of_every_spelling_are_values_of_their_option() {
    let s = Scratch::new();
    for depth in ["-1", "-1e-3", "-.5", "-inf", "-1E2"] {
        let o = simulate(&s, "C1", &["--param", "C10=0.0011", "--depth", depth]);
        refused(&o, &["--depth", "must be positive"]);
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(
            !e.contains("unexpected argument"),
            "{depth} read as a flag: {e}"
        );
    }
    let u = format!("uniaxial={}", treloar("uniaxial.csv"));
    for sigma in ["-1e-3", "-0.5", "-inf"] {
        let o = s.run(&[
            "sample",
            "--law",
            "neo-hookean",
            "--data",
            &u,
            "--sigma",
            sigma,
        ]);
        refused(&o, &["--sigma", "positive"]);
    }
    let o = simulate(&s, "N1", &["--param", "C10=0.0011", "--friction", "-1e-2"]);
    refused(&o, &["--friction", "-0.01", ">= 0"]);
    // A missing value is still a missing value, not the next option.
    let o = simulate(
        &s,
        "C1",
        &["--param", "C10=0.0011", "--depth", "--csv", "x.csv"],
    );
    refused(&o, &["--depth", "value is required"]);
}

#[test]
fn counts_say_what_a_valid_count_is() {
    let s = Scratch::new();
    let u = format!("uniaxial={}", treloar("uniaxial.csv"));
    for (flag, value, needle) in [
        ("--seed", "-1", "cannot be negative"),
        ("--draws", "-5", "cannot be negative"),
        ("--draws", "2.5", "whole number"),
        ("--draws", "ten", "not a number"),
        ("--tune", "1e30", "too large"),
        ("--parallel", "-2", "cannot be negative"),
    ] {
        let o = s.run(&["sample", "--law", "neo-hookean", "--data", &u, flag, value]);
        refused(&o, &[flag, value, needle]);
    }
    let t = s.file("runs.csv", "a,b,y\nx,p,1\nz,p,2\nx,q,3\nz,q,5\n");
    let o = s.run(&[
        "anova",
        "--data",
        &t,
        "--response",
        "y",
        "--factors",
        "a,b",
        "--max-order",
        "-1",
    ]);
    refused(&o, &["--max-order", "-1", "cannot be negative"]);
}

#[test]
fn diagnose_options_are_checked_by_name_before_the_record_is_read() {
    let s = Scratch::new();
    // A record that is not even a force record: the options are refused first.
    let u = treloar("uniaxial.csv");
    for (args, needle) in [
        (vec!["--alpha", "-0.1"], "--alpha -0.1 must lie in (0, 0.5)"),
        (vec!["--alpha", "2"], "--alpha 2 must lie in (0, 0.5)"),
        (vec!["--folds", "0"], "--folds 0 must lie in [2, 20]"),
        (
            vec!["--folds", "1e6"],
            "--folds 1000000 must lie in [2, 20]",
        ),
        (vec!["--folds", "-3"], "cannot be negative"),
    ] {
        let mut a = vec!["diagnose", "--data", &u];
        a.extend(args);
        refused(&s.run(&a), &[needle]);
    }
    let c1 = s.file(
        "c1.csv",
        "displacement_mm,force_N\n0,0\n0.5,1\n1,2.1\n1.5,3.3\n2,4.6\n",
    );
    for (args, needle) in [
        (vec!["--benchmark", "Q1"], "--benchmark Q1"),
        (vec!["--benchmark", "uniaxial"], "expected C1 or N1"),
        (vec!["--base", "ogden:100"], "--base ogden:100"),
        (vec!["--base", "hooke"], "--base hooke"),
    ] {
        let mut a = vec!["diagnose", "--data", &c1];
        a.extend(args);
        refused(&s.run(&a), &[needle]);
    }
}

#[test]
fn a_data_option_without_its_test_names_the_option() {
    let s = Scratch::new();
    let f = s.file("d.csv", UNI);
    let o = s.run(&["calibrate", "--law", "neo-hookean", "--data", &f]);
    refused(&o, &["--data ", "expected TEST=FILE"]);
    let o = s.run(&["calibrate", "--law", "neo-hookean", "--data", "uniaxial="]);
    refused(&o, &["--data ", "expected TEST=FILE"]);
    // A missing file: its path, and the reason once.
    let o = s.run(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--data",
        "uniaxial=nope.csv",
    ]);
    refused(&o, &["nope.csv", "cannot read"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(e.matches("No such file").count(), 1, "{e}");
}

// ---------- designs ----------

#[test]
fn design_sizes_are_stated_as_the_product_they_are() {
    let s = Scratch::new();
    let factors = |n: usize| {
        (0..n)
            .map(|k| format!("[[factors]]\nname = \"f{k}\"\nlevels = [\"a\", \"b\"]\n"))
            .collect::<String>()
    };
    let m = s.file("forty.toml", &factors(40));
    let o = s.run(&["doe", "--manifest", &m]);
    refused(
        &o,
        &[
            "forty.toml",
            "2^40 = 1.100e12 runs",
            "40 factors of 2 levels",
        ],
    );
    let m = s.file("seventy.toml", &factors(70));
    let o = s.run(&["doe", "--manifest", &m]);
    refused(&o, &["seventy.toml", "2^70", "70 factors of 2 levels"]);
    assert!(
        String::from_utf8_lossy(&o.stderr).len() < 400,
        "a list of 70 factors"
    );
    let m = s.file(
        "reps.toml",
        &format!(
            "[design]\nreplicates = 18446744073709551615\n{}",
            factors(3)
        ),
    );
    let o = s.run(&["doe", "--manifest", &m]);
    refused(
        &o,
        &["reps.toml", "2^3 x 18446744073709551615 replicates = "],
    );
    assert!(!String::from_utf8_lossy(&o.stderr).contains("18446744073709551615 runs"));
}

#[test]
fn doe_response_errors_name_the_manifest_and_write_nothing() {
    let s = Scratch::new();
    s.file("u.csv", UNI);
    let two = "[[factors]]\nname = \"law\"\nlevels = [\"neo-hookean\", \"yeoh\"]\n";
    for (name, response, needle) in [
        (
            "metric.toml",
            "[response.calibration]\nmetric = \"r3\"\ndata = { uniaxial = \"u.csv\" }\n",
            "response.calibration.metric",
        ),
        (
            "missing.toml",
            "[response.calibration]\nmetric = \"r2\"\ndata = { uniaxial = \"nope.csv\" }\n",
            "nope.csv",
        ),
        (
            "mode.toml",
            "[response.calibration]\nmetric = \"r2\"\ndata = { \"u:sideways\" = \"u.csv\" }\n",
            "sideways",
        ),
        (
            "bench.toml",
            "[response.simulation]\nbenchmark = \"N9\"\nmetric = \"r2\"\nreference = \"u.csv\"\n",
            "benchmark",
        ),
        (
            "depth.toml",
            "[response.simulation]\nbenchmark = \"N1\"\nmetric = \"r2\"\nreference = \"u.csv\"\nmax_depth_mm = -1\n",
            "max_depth_mm = -1",
        ),
    ] {
        let m = s.file(name, &format!("{two}{response}"));
        let out = s.path(&format!("out-{name}"));
        let o = s.run(&["doe", "--manifest", &m, "--out", out.to_str().unwrap()]);
        refused(&o, &[name, needle]);
        assert!(!out.exists(), "{name}: wrote {out:?} before refusing");
    }
}

#[test]
fn doe_out_is_checked_before_the_design_is_run() {
    let s = Scratch::new();
    let two = "[[factors]]\nname = \"a\"\nlevels = [\"x\", \"y\"]\n";
    let m = s.file("d.toml", two);
    let blocker = s.file("plain-file", "x");
    let under = format!("{blocker}/out");
    let o = s.run(&["doe", "--manifest", &m, "--out", &under]);
    refused(&o, &["--out", "plain-file", "is a file"]);
    let o = s.run(&["doe", "--manifest", &m, "--out", &blocker]);
    refused(&o, &["--out", "is a file"]);
    assert_eq!(std::fs::read_to_string(&blocker).unwrap(), "x");
}

// ---------- outputs checked before the work ----------

#[test]
fn an_unwritable_output_is_refused_before_anything_is_computed_or_written() {
    let s = Scratch::new();
    let blocker = s.file("blocker", "keep");
    let bad_file = format!("{blocker}/x.svg");
    let json = s.path("first.json");
    let json = json.to_str().unwrap();
    let u = format!("uniaxial={}", treloar("uniaxial.csv"));

    let o = s.run(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--data",
        &u,
        "--json",
        json,
        "--plot",
        &bad_file,
    ]);
    refused(&o, &["--plot", "blocker", "is a file"]);
    let o = simulate(
        &s,
        "C1",
        &["--param", "C10=0.0011", "--csv", json, "--plot", &bad_file],
    );
    refused(&o, &["--plot", "is a file"]);
    let o = simulate(
        &s,
        "C1",
        &[
            "--param",
            "C10=0.0011",
            "--csv",
            s.0.path().to_str().unwrap(),
        ],
    );
    refused(&o, &["--csv", "is a directory"]);
    let o = s.run(&[
        "sample",
        "--law",
        "neo-hookean",
        "--data",
        &u,
        "--json",
        json,
        "--plot",
        &blocker,
    ]);
    refused(&o, &["--plot", "is a file", "give a directory"]);
    let t = s.file("runs.csv", "a,b,y\nx,p,1\nz,p,2\nx,q,3\nz,q,5\n");
    let o = s.run(&[
        "anova",
        "--data",
        &t,
        "--response",
        "y",
        "--factors",
        "a,b",
        "--json",
        json,
        "--plot",
        &blocker,
    ]);
    refused(&o, &["--plot", "is a file"]);
    let c1 = s.file(
        "c1.csv",
        "displacement_mm,force_N\n0,0\n0.5,1\n1,2.1\n1.5,3.3\n2,4.6\n",
    );
    let o = s.run(&[
        "diagnose", "--data", &c1, "--json", json, "--report", &bad_file,
    ]);
    refused(&o, &["--report", "is a file"]);
    let o = s.run(&[
        "diagnose",
        "--data",
        &c1,
        "--json",
        json,
        "--plot",
        s.0.path().to_str().unwrap(),
    ]);
    refused(&o, &["--plot", "is a directory"]);
    assert!(
        !s.path("first.json").exists(),
        "an earlier output was written"
    );
    assert_eq!(std::fs::read_to_string(&blocker).unwrap(), "keep");
}

// ---------- study manifests and run folders ----------

fn study(s: &Scratch, name: &str, data_file: &str, model: &str) -> String {
    s.file(
        name,
        &format!(
            "[study]\nname = \"s\"\n\n[data.u]\nfile = \"{data_file}\"\ntest = \"uniaxial\"\n\n\
             [models.nh]\n{model}\n\n[[steps]]\n[steps.calibrate]\nname = \"fit\"\n\
             models = [\"nh\"]\nfits = {{ a = [\"u\"] }}\n"
        ),
    )
}

#[test]
fn run_check_reads_the_data_files_it_checks() {
    let s = Scratch::new();
    for (csv, text, needle) in [
        ("bad.csv", "stretch,stress_MPa\n1,0\n1.1,abc\n", "bad.csv:3"),
        ("one.csv", "stretch,stress_MPa\n1,0.1\n", "one.csv:2"),
        (
            "zero.csv",
            "stretch,stress_MPa\n1,0\n2,0\n",
            "zero on every row",
        ),
        ("cols.csv", "displacement_mm,force_N\n0,0\n1,1\n", "stretch"),
        ("neg.csv", "stretch,stress_MPa\n1,0\n-1,0.1\n", "neg.csv:3"),
    ] {
        s.file(csv, text);
        let m = study(&s, &format!("{csv}.toml"), csv, "law = \"neo-hookean\"");
        for cmd in [vec!["run", &m, "--check"], vec!["run", &m]] {
            let o = s.run(&cmd);
            refused(&o, &[&format!("{csv}.toml"), "data.u", needle]);
        }
    }
    s.file("good.csv", UNI);
    let m = study(&s, "good.toml", "good.csv", "law = \"neo-hookean\"");
    let o = s.run(&["run", &m, "--check"]);
    accepted(&o);
    assert!(String::from_utf8_lossy(&o.stdout).contains("4 rows"));
}

#[test]
fn fixed_values_in_a_manifest_are_checked_by_field() {
    let s = Scratch::new();
    s.file("good.csv", UNI);
    for (model, needle) in [
        (
            "law = \"neo-hookean\"\nfixed = { C10 = 1e300 }",
            "models.nh.fixed: C10=1e300",
        ),
        (
            "law = \"neo-hookean\"\nfixed = { C11 = 1 }",
            "no parameter `C11`",
        ),
        (
            "law = \"neo-hookean\"\nfixed = { C10 = -1 }",
            "strictly inside",
        ),
        (
            "law = \"neo-hookean\"\nfixed = { C10 = 0.001 }",
            "nothing is left to fit",
        ),
        (
            "law = \"mooney-rivlin\"\nfixed = { C01 = -1e9 }",
            "models.nh.fixed: C01=",
        ),
    ] {
        let m = study(&s, "m.toml", "good.csv", model);
        refused(&s.run(&["run", &m, "--check"]), &["m.toml", needle]);
    }
}

#[test]
fn a_run_folder_that_is_not_one_is_refused() {
    let s = Scratch::new();
    s.file("good.csv", UNI);
    let m = study(&s, "m.toml", "good.csv", "law = \"neo-hookean\"");
    // The manifest's own folder (it holds the manifest and the data).
    refused(
        &s.run(&["run", &m, "--out", "."]),
        &["run folder .", "--out"],
    );
    // A data file as the folder.
    refused(
        &s.run(&["run", &m, "--out", "good.csv"]),
        &["run folder good.csv"],
    );
    // A folder of someone's files.
    let mine = s.path("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("thesis.tex"), "keep").unwrap();
    refused(
        &s.run(&["run", &m, "--out", "mine"]),
        &["run folder mine", "not a palpate run folder"],
    );
    assert_eq!(
        std::fs::read_to_string(mine.join("thesis.tex")).unwrap(),
        "keep"
    );
    // Under a file.
    refused(
        &s.run(&["run", &m, "--out", "good.csv/run"]),
        &["good.csv", "is a file"],
    );
    assert_eq!(std::fs::read_to_string(s.path("good.csv")).unwrap(), UNI);
}

// ---------- R2: rolling depth, nodules, friction ----------

/// The value appears in the message (any case: `NaN` for `nan`).
#[track_caller]
fn mentions(o: &Output, value: &str) {
    let e = String::from_utf8_lossy(&o.stderr).to_lowercase();
    assert!(e.contains(&value.to_lowercase()), "`{value}` not in: {e}");
}

fn r2(s: &Scratch, extra: &[&str]) -> Output {
    let mut a = vec!["simulate", "--benchmark", "R2", "--error-estimate", "off"];
    a.extend_from_slice(extra);
    s.run(&a)
}

#[test]
fn r2_options_are_checked_by_name_before_solving() {
    let s = Scratch::new();
    // A rolling depth of zero or less, not a number, or as deep as the wheel.
    for rd in ["0", "-1", "nan", "inf", "8", "100"] {
        let o = r2(&s, &["--rd", rd]);
        refused(&o, &["--rd"]);
        mentions(&o, rd);
    }
    let o = r2(&s, &[]);
    refused(&o, &["--rd"]);
    // Nodules outside the block, through its surface or bottom, overlapping,
    // or not written as X:DEPTH.
    for nodules in [
        "200:15",
        "-10:15",
        "2:15",
        "75:1",
        "75:29",
        "75:100",
        "75:15,80:15",
        "75",
        "75:x",
        "x:15",
        "75:15,",
        "75;15",
        "",
    ] {
        let o = r2(&s, &["--rd", "6", "--nodules", nodules]);
        refused(&o, &["--nodules"]);
        if !nodules.is_empty() {
            refused(&o, &[nodules]);
        }
    }
    // Friction below zero or not a number.
    for mu in ["-0.1", "-5", "nan", "inf"] {
        let o = r2(&s, &["--rd", "6", "--friction", mu]);
        refused(&o, &["--friction"]);
        mentions(&o, mu);
    }
    // Meshes beyond what R2 offers, the nodule law and its parameters.
    for (extra, needle) in [
        (vec!["--mesh", "4"], "--mesh"),
        (vec!["--mesh", "0"], "--mesh"),
        (vec!["--nodule-law", "ogden:100"], "ogden:100"),
        (vec!["--nodule-law", "rubber"], "rubber"),
        (
            vec!["--nodule-param", "mu=-1", "--nodule-param", "lambda_m=1.05"],
            "--nodule-param mu=-1",
        ),
        (vec!["--nodule-param", "mu=1"], "missing --nodule-param"),
        (vec!["--nodule-param", "C10=1"], "--nodule-param"),
        (vec!["--step", "0"], "--step"),
        (vec!["--step", "1e-300"], "--step"),
    ] {
        let mut a = vec!["--rd", "6"];
        a.extend_from_slice(&extra);
        refused(&r2(&s, &a), &[needle]);
    }
    // R2's own options on the other benchmarks.
    for (bench, extra, needle) in [
        ("C1", vec!["--rd", "6"], "--rd"),
        ("N1", vec!["--nodules", "75:15"], "--nodules"),
        ("C1", vec!["--nodule-law", "neo-hookean"], "--nodule-law"),
        ("Q1", vec!["--nodule-param", "mu=1"], "--nodule-param"),
    ] {
        let mut a = extra.clone();
        a.extend_from_slice(&["--param", "C10=0.0011"]);
        refused(&simulate(&s, bench, &a), &[needle, "benchmark"]);
    }
}

// ---------- priors and fixed values ----------

#[test]
fn priors_are_checked_by_name_and_value() {
    let s = Scratch::new();
    let u = format!("uniaxial={}", treloar("uniaxial.csv"));
    for (prior, needle) in [
        ("C10=normal:1,0", "positive"),
        ("C10=normal:1,-1", "positive"),
        ("C10=normal:nan,1", "finite"),
        ("C10=uniform:2,1", "must exceed"),
        ("C10=uniform:1,1", "must exceed"),
        ("C10=uniform:0,inf", "finite"),
        ("C10=uniform:-2,-1", "outside the range of C10"),
        ("C10=lognormal", "2 numbers"),
        ("C10=lognormal:1", "2 numbers"),
        ("C10=halfnormal:inf", "finite"),
        ("C10=halfnormal:1,2", "1 number"),
        ("C10=halfnormal:0", "positive"),
        ("C10=halfnormal:x", "not a number"),
        ("C10=gamma:1,2", "gamma"),
        ("C10=", "NAME=SPEC"),
        ("=flat", "NAME=SPEC"),
        ("C10", "NAME=SPEC"),
        ("C99=flat", "C99"),
        ("c10=flat", "c10"),
    ] {
        let o = s.run(&[
            "sample",
            "--law",
            "neo-hookean",
            "--data",
            &u,
            "--prior",
            prior,
        ]);
        refused(&o, &[&format!("--prior {prior}"), needle]);
    }
    // A prior that excludes what the data say: named, with the fitted value.
    let o = s.run(&[
        "sample",
        "--law",
        "neo-hookean",
        "--data",
        &u,
        "--prior",
        "C10=uniform:1,2",
    ]);
    refused(&o, &["C10 = ", "uniform:1,2", "widen the prior"]);
}

#[test]
fn fixed_values_outside_the_laws_domain_name_the_option() {
    let s = Scratch::new();
    let u = format!("uniaxial={}", treloar("uniaxial.csv"));
    for (law, fix, needle) in [
        ("neo-hookean", "C10=0", "--fix C10=0"),
        ("ogden:1", "alpha1=0", "--fix alpha1=0"),
        ("ogden:1", "alpha1=60", "--fix alpha1=60"),
        // mu1 alone < 0: the initial shear modulus cannot be positive.
        ("ogden:1", "mu1=-1", "--fix mu1=-1"),
        ("arruda-boyce", "lambda_m=1", "--fix lambda_m=1"),
        ("arruda-boyce", "lambda_m=0.5", "--fix lambda_m=0.5"),
        ("yeoh", "C20=1e300", "--fix C20=1e300"),
    ] {
        let o = s.run(&["calibrate", "--law", law, "--data", &u, "--fix", fix]);
        refused(&o, &[needle]);
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(!e.contains("NaN"), "{fix}: {e}");
    }
    // C01 < 0 (or C10 < 0) is allowed while C10 + C01 > 0: the fit starts
    // inside that domain (the other one above 0.1 MPa) instead of failing
    // on a NaN at its start.
    let brain = format!(
        "uniaxial={}/data/real/brain_budday2017/cortex_compression_tension.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    for data in [&u, &brain] {
        for (fix, free) in [("C01=-0.1", "C10"), ("C10=-0.1", "C01")] {
            let json = s.path("fit.json").display().to_string();
            let o = s.run(&[
                "calibrate",
                "--law",
                "mooney-rivlin",
                "--data",
                data,
                "--fix",
                fix,
                "--json",
                &json,
            ]);
            accepted(&o);
            let v: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
            let other = v["params"][free]["value"].as_f64().unwrap();
            assert!(
                other > 0.1,
                "{fix}: {free} = {other}: C10 + C01 must stay > 0"
            );
        }
    }
}
