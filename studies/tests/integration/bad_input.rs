//! Bad input as a hostile but realistic user gives it, against the built
//! `palpate` binary: every case must fail with a non-zero exit, without a
//! panic, and with the locator (the option and its value, the manifest
//! field, or file:line) in the message; data files are never overwritten.
//! A few cases check that input that only looks odd (a byte-order mark,
//! CR-only line endings) is read as what it is.

use crate::common;
use common::*;
use std::process::Output;

const C1_ARGS: [&str; 6] = [
    "simulate",
    "--benchmark",
    "C1",
    "--law",
    "neo-hookean",
    "--param",
];

/// `palpate simulate --benchmark BENCHMARK` of a neo-Hookean material with
/// the `extra` options, without the error estimate's second solve.
pub(crate) fn simulate(s: &Scratch, benchmark: &str, extra: &[&str]) -> Output {
    let mut a = vec![
        "simulate",
        "--benchmark",
        benchmark,
        "--law",
        "neo-hookean",
        "--param",
        "C10=0.0011",
        "--error-estimate",
        "off",
    ];
    a.extend_from_slice(extra);
    s.run(&a)
}

// ---------- sizes ----------

#[test]
fn absurd_simulation_sizes_are_refused_with_the_estimate() {
    let s = Scratch::new();
    for (depth, step) in [("2", "1e-300"), ("1e9", "1e-9"), ("1e300", "1e-300")] {
        let o = simulate(&s, "C1", &["--depth", depth, "--step", step]);
        refused(&o, &["--step", "samples", "fit in memory", "GiB"]);
    }
    for (depth, step) in [("2", "0"), ("2", "-1"), ("0", "0.1"), ("inf", "0.1")] {
        let o = simulate(&s, "C1", &["--depth", depth, "--step", step]);
        refused(&o, &["--step"]);
    }
    let _ = C1_ARGS;
}

#[test]
fn absurd_sampler_sizes_are_refused_with_the_estimate() {
    let s = Scratch::new();
    let uni = format!("uniaxial={}", treloar("uniaxial.csv"));
    for (flag, value, needle) in [
        ("--draws", "1000000000000", "--draws 1000000000000"),
        (
            "--draws",
            "18446744073709551615",
            "--draws 18446744073709551615",
        ),
        (
            "--parallel",
            "18446744073709551615",
            "--parallel 18446744073709551615",
        ),
    ] {
        for sampler in ["nuts", "ensemble", "demc"] {
            let o = s.run(&[
                "sample",
                "--law",
                "neo-hookean",
                "--data",
                &uni,
                "--sampler",
                sampler,
                flag,
                value,
            ]);
            refused(&o, &[needle, "fit in memory"]);
        }
    }
    for (flag, value) in [("--draws", "0"), ("--draws", "3"), ("--parallel", "0")] {
        let o = s.run(&[
            "sample",
            "--law",
            "neo-hookean",
            "--data",
            &uni,
            flag,
            value,
        ]);
        refused(&o, &[&format!("{flag} {value}")]);
    }
    let o = s.run(&[
        "sample",
        "--law",
        "neo-hookean",
        "--data",
        &uni,
        "--tune",
        "18446744073709551615",
        "--draws",
        "10",
    ]);
    refused(&o, &["--tune 18446744073709551615", "iterations"]);
}

fn runs_table(s: &Scratch) -> String {
    s.file(
        "runs.csv",
        "law,residual,r2\nnh,abs,0.9\nmr,abs,0.95\nnh,rel,0.91\nmr,rel,0.97\n",
    )
}

#[test]
fn anova_max_order_outside_the_factors_is_refused() {
    let s = Scratch::new();
    let t = runs_table(&s);
    for bad in ["0", "3", "1000000"] {
        let o = s.run(&[
            "anova",
            "--data",
            &t,
            "--response",
            "r2",
            "--factors",
            "law,residual",
            "--max-order",
            bad,
        ]);
        refused(
            &o,
            &[
                &format!("--max-order {bad}"),
                "1",
                "2 (the number of factors)",
            ],
        );
    }
    for alpha in ["-0.1", "0", "1", "7", "NaN"] {
        let o = s.run(&[
            "anova",
            "--data",
            &t,
            "--response",
            "r2",
            "--factors",
            "law",
            "--alpha",
            alpha,
        ]);
        refused(&o, &[&format!("--alpha {alpha}"), "between 0 and 1"]);
    }
    let o = s.run(&[
        "anova",
        "--data",
        &t,
        "--response",
        "r2",
        "--factors",
        "law,r2",
    ]);
    refused(&o, &["--factors law,r2", "`r2` is the response"]);
    let o = s.run(&[
        "anova",
        "--data",
        &t,
        "--response",
        "r2",
        "--factors",
        "law,law",
    ]);
    refused(&o, &["`law` appears twice"]);
    let o = s.run(&[
        "anova",
        "--data",
        &t,
        "--response",
        "r2",
        "--factors",
        "law,residual",
        "--max-order",
        "2",
    ]);
    accepted(&o);
}

#[test]
fn doe_run_counts_and_orders_are_checked_before_the_design_is_built() {
    let s = Scratch::new();
    let mut many = String::new();
    for k in 0..41 {
        many += &format!("[[factors]]\nname = \"f{k}\"\nlevels = [\"a\", \"b\"]\n");
    }
    let m = s.file("many.toml", &many);
    refused(
        &s.run(&["doe", "--manifest", &m]),
        &["many.toml", "runs", "2^20"],
    );
    let two = "[[factors]]\nname = \"a\"\nlevels = [\"x\", \"y\"]\n[[factors]]\nname = \"b\"\nlevels = [\"x\", \"y\"]\n";
    let m = s.file(
        "reps.toml",
        &format!("[design]\nreplicates = 1000000000000\n{two}"),
    );
    refused(
        &s.run(&["doe", "--manifest", &m]),
        &["reps.toml", "replicates = 1000000000000", "runs"],
    );
    let m = s.file("order.toml", &format!("{two}[analysis]\nmax_order = 0\n"));
    refused(
        &s.run(&["doe", "--manifest", &m]),
        &["order.toml", "analysis.max_order", "0"],
    );
    let m = s.file("alpha.toml", &format!("{two}[analysis]\nalpha = 5\n"));
    refused(
        &s.run(&["doe", "--manifest", &m]),
        &["alpha.toml", "analysis.alpha", "5"],
    );
    for (name, text, needle) in [
        (
            "e1.toml",
            "[[factors]]\nname = \"a\"\nlevels = []\n",
            "at least 2 levels",
        ),
        (
            "e2.toml",
            "[[factors]]\nname = \"a\"\nlevels = [\"x\", \"x\"]\n",
            "twice",
        ),
        ("e3.toml", "factors = []\n", "at least one factor"),
        (
            "e4.toml",
            &format!("[design]\nreplicates = 0\n{two}"),
            "replicates",
        ),
        (
            "e5.toml",
            &format!("[design]\ngenerators = [\"C=AB\"]\n{two}"),
            "C=AB",
        ),
        (
            "e6.toml",
            &format!("{two}[[factors]]\nname = \"a\"\nlevels = [\"p\", \"q\"]\n"),
            "`a`",
        ),
        ("e7.toml", &format!("{two}colour = 1\n"), "colour"),
    ] {
        let m = s.file(name, text);
        refused(&s.run(&["doe", "--manifest", &m]), &[name, needle]);
    }
    let m = s.file("ok.toml", two);
    accepted(&s.run(&["doe", "--manifest", &m]));
}

// ---------- CSV files ----------

pub(crate) const UNI: &str = "stretch,stress_MPa\n1.0,0\n1.5,0.2\n2.0,0.35\n3.0,0.6\n";

fn calibrate_file(s: &Scratch, name: &str, text: &str) -> (Output, String) {
    let f = s.file(name, text);
    let o = s.run(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--data",
        &format!("uniaxial={f}"),
    ]);
    (o, f)
}

#[test]
fn a_byte_order_mark_and_cr_line_endings_read_as_the_plain_file() {
    let s = Scratch::new();
    let (plain, _) = calibrate_file(&s, "plain.csv", UNI);
    accepted(&plain);
    for (name, text) in [
        ("bom.csv", format!("\u{feff}{UNI}")),
        ("cr.csv", UNI.replace('\n', "\r")),
        ("crlf.csv", UNI.replace('\n', "\r\n")),
        ("bomcr.csv", format!("\u{feff}{}", UNI.replace('\n', "\r"))),
    ] {
        let (o, _) = calibrate_file(&s, name, &text);
        accepted(&o);
        assert_eq!(o.stdout, plain.stdout, "{name}");
    }
    // With a byte-order mark the time column keeps its name and its check.
    let (o, _) = calibrate_file(
        &s,
        "bomtime.csv",
        "\u{feff}time_s,stretch,stress_MPa\n1,1,0\n0.5,1.5,0.2\n2,2,0.3\n",
    );
    refused(&o, &["bomtime.csv:3", "monotonic"]);
    let (o, _) = calibrate_file(
        &s,
        "crtime.csv",
        "time_s,stretch,stress_MPa\r1,1,0\r0.5,1.5,0.2\r2,2,0.3\r",
    );
    refused(&o, &["crtime.csv:3", "monotonic"]);
}

#[test]
fn bad_csv_files_are_named_with_their_line() {
    let s = Scratch::new();
    for (name, text, needles) in [
        (
            "text.csv",
            "stretch,stress_MPa\n1,0\n1.5,abc\n",
            vec!["text.csv:3", "abc"],
        ),
        (
            "nan.csv",
            "stretch,stress_MPa\n1,0\n1.5,NaN\n",
            vec!["nan.csv:3", "NaN"],
        ),
        (
            "inf.csv",
            "stretch,stress_MPa\n1,0\ninf,1\n",
            vec!["inf.csv:3"],
        ),
        (
            "ragged.csv",
            "stretch,stress_MPa\n1,0\n1.5,0.2,7\n",
            vec!["ragged.csv:3", "fields"],
        ),
        (
            "short.csv",
            "stretch,stress_MPa\n1,0\n1.5\n",
            vec!["short.csv:3", "fields"],
        ),
        (
            "dup.csv",
            "stretch,stretch\n1,0\n1.5,0.2\n",
            vec!["dup.csv:1", "twice"],
        ),
        (
            "missing.csv",
            "stretch,force_N\n1,0\n1.5,0.2\n",
            vec!["missing.csv", "stress_MPa"],
        ),
        ("empty.csv", "", vec!["empty.csv"]),
        ("comments.csv", "# nothing\n# here\n", vec!["comments.csv"]),
        (
            "header.csv",
            "stretch,stress_MPa\n",
            vec!["header.csv", "no data rows"],
        ),
        (
            "negative.csv",
            "stretch,stress_MPa\n1,0\n-1.5,0.2\n",
            vec!["negative.csv:3", "stretch"],
        ),
        (
            "zero.csv",
            "stretch,stress_MPa\n1,0\n1.5,0\n2,0\n",
            vec!["zero.csv", "zero on every row"],
        ),
        (
            "zero2.csv",
            "stretch,stress_MPa\n1,0.0\n1.5,-0\n",
            vec!["zero2.csv", "stress_MPa"],
        ),
        (
            "one.csv",
            "stretch,stress_MPa\n1.5,0.2\n",
            vec!["one.csv:2", "single data row"],
        ),
        (
            "onec.csv",
            "# c\n\nstretch,stress_MPa\n1.5,0.2\n",
            vec!["onec.csv:4", "single data row"],
        ),
        (
            "time.csv",
            "time_s,stretch,stress_MPa\n1,1,0\n0.5,1.5,0.2\n",
            vec!["time.csv:3", "monotonic"],
        ),
    ] {
        let (o, _) = calibrate_file(&s, name, text);
        refused(&o, &needles);
    }
    let o = s.run(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--data",
        "uniaxial=nowhere.csv",
    ]);
    refused(&o, &["nowhere.csv"]);
    let o = s.run(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--data",
        "sideways=x.csv",
    ]);
    refused(&o, &["sideways"]);
}

#[test]
fn all_zero_and_single_row_force_records_are_refused() {
    let s = Scratch::new();
    let zero = s.file(
        "c1zero.csv",
        "displacement_mm,force_N\n0,0\n0.5,0\n1,0\n1.5,0\n",
    );
    let one = s.file("c1one.csv", "displacement_mm,force_N\n0.5,1\n");
    for (f, n) in [(&zero, "c1zero.csv"), (&one, "c1one.csv:2")] {
        let o = s.run(&[
            "calibrate",
            "--benchmark",
            "C1",
            "--law",
            "neo-hookean",
            "--data",
            f,
        ]);
        refused(&o, &[n]);
        let o = s.run(&["diagnose", "--benchmark", "C1", "--data", f]);
        refused(&o, &[n]);
        let o = s.run(&[
            "sample",
            "--benchmark",
            "C1",
            "--law",
            "neo-hookean",
            "--data",
            f,
        ]);
        refused(&o, &[n]);
    }
}

// ---------- outputs ----------

#[test]
fn an_output_on_an_input_is_refused_and_the_input_kept() {
    let s = Scratch::new();
    let data = s.file("in.csv", UNI);
    let uni = format!("uniaxial={data}");
    let rel = "./in.csv";
    let runs = runs_table(&s);
    let c1 = s.file(
        "c1.csv",
        "displacement_mm,force_N\n0,0\n0.5,1\n1,2.2\n1.5,3.6\n2,5.3\n",
    );
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "calibrate",
                "--law",
                "neo-hookean",
                "--data",
                &uni,
                "--json",
                &data,
            ],
            "--json",
        ),
        (
            vec![
                "calibrate",
                "--law",
                "neo-hookean",
                "--data",
                &uni,
                "--json",
                rel,
            ],
            "--json",
        ),
        (
            vec![
                "calibrate",
                "--law",
                "neo-hookean",
                "--data",
                &uni,
                "--plot",
                &data,
            ],
            "--plot",
        ),
        (
            vec![
                "sample",
                "--law",
                "neo-hookean",
                "--data",
                &uni,
                "--json",
                &data,
            ],
            "--json",
        ),
        (
            vec![
                "sample",
                "--law",
                "neo-hookean",
                "--data",
                &uni,
                "--chains",
                &data,
            ],
            "--chains",
        ),
        (vec!["diagnose", "--data", &c1, "--json", &c1], "--json"),
        (vec!["diagnose", "--data", &c1, "--report", &c1], "--report"),
        (
            vec!["diagnose", "--data", &c1, "--plot", "c1.csv"],
            "--plot",
        ),
        (
            vec![
                "anova",
                "--data",
                &runs,
                "--response",
                "r2",
                "--factors",
                "law",
                "--json",
                &runs,
            ],
            "--json",
        ),
    ];
    for (args, opt) in cases {
        let o = s.run(&args);
        refused(&o, &[opt, "input file"]);
    }
    assert_eq!(std::fs::read_to_string(&data).unwrap(), UNI);
    assert!(std::fs::read_to_string(&c1)
        .unwrap()
        .starts_with("displacement_mm"));
    assert!(std::fs::read_to_string(&runs).unwrap().starts_with("law,"));
}

#[test]
fn two_outputs_on_one_file_are_refused() {
    let s = Scratch::new();
    let uni = format!("uniaxial={}", s.file("in.csv", UNI));
    let o = s.run(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--data",
        &uni,
        "--json",
        "out",
        "--plot",
        "out",
    ]);
    refused(&o, &["--plot out", "--json"]);
    let o = simulate(&s, "C1", &["--csv", "x", "--plot", "./x"]);
    refused(&o, &["--plot ./x", "--csv"]);
    assert!(!s.path("x").exists() && !s.path("out").exists());
}

// ---------- options ----------

#[test]
fn options_of_the_other_benchmark_are_refused_by_name() {
    let s = Scratch::new();
    for (bench, extra, needle) in [
        ("C1", vec!["--tool", "sphere:0"], "--tool sphere:0"),
        ("C1", vec!["--tool", "needle"], "--tool needle"),
        ("C1", vec!["--friction", "1e9"], "--friction"),
        ("C1", vec!["--friction", "0.3"], "--friction 0.3"),
        ("C1", vec!["--sliding-base"], "--sliding-base"),
        ("C1", vec!["--element", "quad9"], "--element quad9"),
        ("N1", vec!["--bonded"], "--bonded"),
        (
            "N3",
            vec!["--prony", "g1=0.3,tau1=0.5"],
            "--prony g1=0.3,tau1=0.5",
        ),
        ("N3", vec!["--ramp", "1"], "--ramp"),
        ("N3", vec!["--hold", "2"], "--hold"),
    ] {
        let o = simulate(&s, bench, &extra);
        refused(&o, &[needle, "benchmark"]);
    }
}

#[test]
fn a_parameter_given_twice_is_refused() {
    let s = Scratch::new();
    let o = simulate(&s, "C1", &["--param", "C10=0.002"]);
    refused(&o, &["--param `C10=0.002`", "twice"]);
    let uni = format!("uniaxial={}", s.file("in.csv", UNI));
    let o = s.run(&[
        "calibrate",
        "--law",
        "mooney-rivlin",
        "--data",
        &uni,
        "--fix",
        "C01=0",
        "--fix",
        "C01=0.1",
    ]);
    refused(&o, &["--fix C01=0.1", "twice"]);
    let o = s.run(&[
        "sample",
        "--law",
        "neo-hookean",
        "--data",
        &uni,
        "--prior",
        "C10=flat",
        "--prior",
        "C10=halfnormal:1",
    ]);
    refused(&o, &["--prior C10=halfnormal:1", "twice"]);
}

#[test]
fn bad_option_values_name_the_option() {
    let s = Scratch::new();
    for (extra, needle) in [
        (vec!["--mesh", "0"], "--mesh `0`"),
        (vec!["--mesh", "13"], "--mesh `13`"),
        (vec!["--bulk", "0"], "--bulk `0`"),
        (vec!["--bulk", "-5"], "--bulk `-5`"),
        (vec!["--param", "C20=1"], "C20"),
        (vec!["--order", "0"], "--order"),
        (vec!["--prony", "g1=2,tau1=1"], "--prony"),
        (vec!["--ramp", "1"], "--ramp"),
    ] {
        refused(&simulate(&s, "C1", &extra), &[needle]);
    }
    let uni = format!("uniaxial={}", s.file("in.csv", UNI));
    for law in [
        "ogden:0",
        "ogden:100",
        "ogden:18446744073709551615",
        "reduced-polynomial:1000000",
    ] {
        for cmd in ["calibrate", "sample"] {
            let o = s.run(&[cmd, "--law", law, "--data", &uni]);
            refused(&o, &[&format!("--law {law}"), "allowed: 1..="]);
        }
        let o = s.run(&[
            "simulate",
            "--benchmark",
            "C1",
            "--law",
            law,
            "--param",
            "mu1=1",
        ]);
        refused(&o, &[law, "allowed: 1..="]);
    }
    for v in ["nan", "inf", "x"] {
        let fix = format!("C01={v}");
        let o = s.run(&[
            "calibrate",
            "--law",
            "mooney-rivlin",
            "--data",
            &uni,
            "--fix",
            &fix,
        ]);
        refused(&o, &[&format!("--fix {fix}")]);
    }
    let o = s.run(&[
        "calibrate",
        "--benchmark",
        "C1",
        "--law",
        "neo-hookean",
        "--data",
        "uniaxial=F",
    ]);
    refused(&o, &["--data uniaxial=F", "C1=FILE"]);
    let o = s.run(&["simulate", "--benchmark", "C1", "--law", "nonsense"]);
    refused(&o, &["nonsense"]);
    let o = s.run(&[
        "simulate",
        "--benchmark",
        "C1",
        "--law",
        "mooney-rivlin",
        "--param",
        "C10=1",
    ]);
    refused(&o, &["missing --param", "C01"]);
    let o = s.run(&[
        "simulate",
        "--benchmark",
        "C1",
        "--law",
        "neo-hookean",
        "--param",
        "C10",
    ]);
    refused(&o, &["--param `C10`"]);
    let o = s.run(&[
        "simulate",
        "--benchmark",
        "C1",
        "--law",
        "neo-hookean",
        "--param",
        "C10=x",
    ]);
    refused(&o, &["--param `C10=x`"]);
}

#[test]
fn effects_the_model_does_not_offer_are_refused() {
    let s = Scratch::new();
    let c1 = s.file(
        "c1.csv",
        "displacement_mm,force_N\n0,0\n0.5,1\n1,2.2\n1.5,3.6\n2,5.3\n",
    );
    for e in ["boundary_condition", "friction"] {
        let o = s.run(&[
            "diagnose",
            "--benchmark",
            "C1",
            "--data",
            &c1,
            "--effects",
            e,
        ]);
        refused(
            &o,
            &[
                &format!("--effects {e}"),
                "does not offer",
                "viscoelasticity",
            ],
        );
    }
    let o = s.run(&["diagnose", "--data", &c1, "--effects", "warp_drive"]);
    refused(&o, &["warp_drive"]);
}
