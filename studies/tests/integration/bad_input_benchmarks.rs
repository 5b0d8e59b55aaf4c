//! Bad input to the source studies' benchmarks, as `bad_input.rs` (whose
//! conventions these follow): Q1's viscoelastic options, two-stage
//! identification and real-time surrogate, and R2's geometry,
//! `palpate localize` and the localize step. Every case fails
//! with a non-zero exit, without a panic, naming the option, the manifest
//! field or file:line.

use crate::bad_input::simulate;
use crate::common;
use common::*;

// ---------- Q1 two-stage identification and the real-time surrogate ----------

/// `palpate realtime build --benchmark BENCHMARK` of a neo-Hookean
/// material into `rt.json` of `s`, with `--prony PRONY --depth-max DEPTH`
/// and the `extra` options.
fn surrogate_build(
    s: &Scratch,
    benchmark: &str,
    prony: &str,
    depth: &str,
    extra: &[&str],
) -> std::process::Output {
    let out = s.path("rt.json").display().to_string();
    let mut args = vec![
        "realtime",
        "build",
        "--benchmark",
        benchmark,
        "--law",
        "neo-hookean",
        "--param",
        "C10=0.0016",
        "--prony",
        prony,
        "--depth-max",
        depth,
        "--out",
        &out,
    ];
    args.extend_from_slice(extra);
    s.run(&args)
}

#[test]
fn q1_edge_radius_is_checked() {
    let s = Scratch::new();
    let csv = s.path("q1.csv").display().to_string();
    let run = |benchmark: &str, edge: &str| {
        simulate(&s, benchmark, &["--edge-radius", edge, "--csv", &csv])
    };
    for bad in ["0", "-0.2", "2", "7.5", "NaN"] {
        refused(
            &run("Q1", bad),
            &["--edge-radius", "below the punch radius 2"],
        );
    }
    refused(&run("N1", "0.5"), &["--edge-radius", "benchmark Q1"]);
    refused(&run("Q1", "wide"), &["--edge-radius"]);
    assert!(!s.path("q1.csv").exists());
    // the real-time surrogate's build takes the same option
    let build = |benchmark: &str, edge: &str| {
        surrogate_build(
            &s,
            benchmark,
            "g1=0.3,tau1=1",
            "1",
            &["--edge-radius", edge],
        )
    };
    refused(
        &build("Q1", "0"),
        &["--edge-radius 0", "below the punch radius 2"],
    );
    refused(
        &build("Q1", "2.5"),
        &["--edge-radius 2.5", "below the punch radius 2"],
    );
    refused(&build("N1", "0.5"), &["--edge-radius", "Q1 only"]);
    assert!(!s.path("rt.json").exists());
    // the staged identification and the posterior take it too
    let rec = two_stage_record();
    let calibrate = |benchmark: &str, edge: &str| {
        s.run(&[
            "calibrate",
            "--benchmark",
            benchmark,
            "--law",
            "neo-hookean",
            "--data",
            &rec,
            "--edge-radius",
            edge,
        ])
    };
    refused(
        &calibrate("Q1", "0"),
        &["--edge-radius 0", "below the punch radius 2"],
    );
    refused(
        &calibrate("C1", "0.5"),
        &["--edge-radius", "--benchmark Q1"],
    );
    let o = s.run(&[
        "sample",
        "--benchmark",
        "N1",
        "--law",
        "neo-hookean",
        "--data",
        &rec,
        "--edge-radius",
        "0.5",
    ]);
    refused(&o, &["--edge-radius", "--benchmark Q1"]);
    // the study step of the staged identification
    let m = s.file(
        "q1.toml",
        &format!(
            "[study]\nname = \"q1\"\n\n[[steps]]\n[steps.two_stage]\nname = \"fit\"\nrecord = \"{}\"\nlaw = \"neo-hookean\"\nedge_radius = 2.5\n",
            rec.replace('\\', "/")
        ),
    );
    refused(
        &s.run(&["run", "--check", &m]),
        &["edge_radius = 2.5", "below the punch radius 2"],
    );
}

#[test]
fn q1_viscoelastic_and_surrogate_bad_input_is_named() {
    let s = Scratch::new();
    let build = |prony: &str, depth: &str| surrogate_build(&s, "Q1", prony, depth, &[]);
    // Prony weights summing to 1 or more, a zero or negative time constant
    refused(
        &build("g1=0.6,tau1=1,g2=0.4,tau2=10", "1"),
        &["--prony g1=0.6,tau1=1,g2=0.4,tau2=10", "sum to 1"],
    );
    refused(&build("g1=0.3,tau1=0", "1"), &["--prony", "tau1"]);
    refused(&build("g1=0.3,tau1=-2", "1"), &["--prony", "tau1"]);
    refused(&build("g1=0.3,tau1=1", "0"), &["--depth-max 0"]);
    // too few training histories for the fitted memory's cross-validation
    refused(
        &surrogate_build(&s, "Q1", "g1=0.3,tau1=1", "1", &["--train", "3"]),
        &["--train 3", "5..64"],
    );
    // friction is the needle's: refused for the frictionless punch, and a
    // negative coefficient for N1
    let with_friction = |benchmark: &str, mu: &str| {
        surrogate_build(&s, benchmark, "g1=0.3,tau1=1", "1", &["--friction", mu])
    };
    refused(&with_friction("Q1", "0"), &["--friction", "N1 only"]);
    refused(&with_friction("N1", "-0.2"), &["--friction -0.2", ">= 0"]);
    // the error target is a per cent > 0
    for bad in ["0", "-2", "NaN"] {
        refused(
            &surrogate_build(&s, "Q1", "g1=0.3,tau1=1", "1", &["--target", bad]),
            &["--target", "per cent > 0"],
        );
    }
    assert!(!s.path("rt.json").exists());
    // a hold shorter than one step of the ramp
    let o = s.run(&[
        "simulate",
        "--benchmark",
        "Q1",
        "--law",
        "neo-hookean",
        "--param",
        "C10=0.0016",
        "--prony",
        "g1=0.3,tau1=0.5",
        "--depth",
        "1",
        "--hold",
        "1e-6",
        "--error-estimate",
        "off",
    ]);
    refused(&o, &["--hold 0.000001", "shorter than one step"]);
    // a history that leaves the real-time model's range: row and range named
    let curve =
        palpate_realtime::MonotoneCubic::new(vec![0.0, 0.5, 1.0], vec![0.0, 0.01, 0.03]).unwrap();
    let rt = palpate_realtime::RealTimeModel::new("test".into(), curve, vec![(0.3, 0.5)]).unwrap();
    let js = s.file("rt.json", &rt.to_json());
    let ok = s.file("ok.csv", "time_s,displacement_mm\n0.001,0.1\n0.002,0.2\n");
    let answer = s.run(&["realtime", "query", "--model", &js, "--csv", &ok]);
    accepted(&answer);
    // the command's and the option's former names are hidden aliases
    let former = s.run(&["surrogate", "query", "--surrogate", &js, "--csv", &ok]);
    accepted(&former);
    assert!(answer
        .stdout
        .starts_with(b"time_s,displacement_mm,force_N\n0.001,0.1,"));
    assert_eq!(former.stdout, answer.stdout);
    let deep = s.file("deep.csv", "time_s,displacement_mm\n0.001,0.5\n0.002,1.5\n");
    let o = s.run(&["realtime", "query", "--model", &js, "--csv", &deep]);
    refused(
        &o,
        &[
            "deep.csv: row 3",
            "depth 1.5 mm is outside the real-time model's trained range [0, 1] mm",
        ],
    );
    let back = s.file("back.csv", "time_s,displacement_mm\n0.002,0.5\n0.001,0.5\n");
    let o = s.run(&["realtime", "query", "--model", &js, "--csv", &back]);
    refused(&o, &["back.csv: line 3", "goes back"]);
    let not = s.file("not.json", "{\"a\": 1}");
    let o = s.run(&["realtime", "query", "--model", &not, "--csv", &ok]);
    refused(&o, &["--model", "not a real-time model"]);
    // the staged identification: a record without a hold, unknown stages
    let ramp = s.file(
        "ramp.csv",
        "time_s,displacement_mm,force_N\n0.1,0.1,0.001\n0.2,0.2,0.002\n0.3,0.3,0.003\n",
    );
    let q1 = |data: &str, stages: &str| {
        s.run(&[
            "calibrate",
            "--benchmark",
            "Q1",
            "--law",
            "neo-hookean",
            "--data",
            data,
            "--stages",
            stages,
        ])
    };
    refused(
        &q1(&ramp, "elastic,relaxation"),
        &["ramp.csv", "a hold after it"],
    );
    let rec = two_stage_record();
    refused(
        &q1(&rec, "elastic,viscous"),
        &["--stages", "unknown stage `viscous`"],
    );
    refused(
        &q1(&rec, "relaxation,elastic"),
        &["--stages", "order elastic,relaxation"],
    );
    let o = s.run(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--data",
        &ramp,
        "--stages",
        "elastic",
    ]);
    refused(&o, &["--stages", "--benchmark Q1"]);
}

fn two_stage_record() -> String {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/two-stage-q1/record.csv")
        .display()
        .to_string()
}

// ---------- R2 localisation and the R2 geometry ----------

/// `palpate localize`: RD not positive or deeper than the wheel allows,
/// no nodule, records outside the rolled path, not increasing, without the
/// columns: refused before any FE run, naming the option or file:line.
#[test]
fn localize_refuses_bad_rd_nodules_and_records() {
    let s = Scratch::new();
    let good = s.file(
        "rec.csv",
        "position_mm,force_N\n10,9\n11,9\n12,9\n13,9\n14,9\n",
    );
    let run = |rd: &str, data: &str, extra: &[&str]| {
        let mut a = vec!["localize", "--benchmark", "R2", "--rd", rd, "--data", data];
        a.extend_from_slice(extra);
        let cache = s.path("cache");
        let cache = cache.to_str().unwrap().to_string();
        a.extend_from_slice(&["--cache", &cache]);
        s.run(&a)
    };
    for rd in ["0", "-1", "8", "12", "nan"] {
        refused(&run(rd, &good, &[]), &["rd"]);
    }
    refused(&run("6", &good, &["--nodules", "0"]), &["--nodules 0"]);
    let outside = s.file(
        "out.csv",
        "position_mm,force_N\n10,9\n11,9\n12,9\n13,9\n150,9\n",
    );
    refused(
        &run("6", &outside, &[]),
        &["out.csv:6", "150", "outside the rolled path"],
    );
    let before = s.file(
        "before.csv",
        "position_mm,force_N\n5,9\n11,9\n12,9\n13,9\n14,9\n",
    );
    refused(&run("6", &before, &[]), &["before.csv:2", "outside"]);
    let back = s.file(
        "back.csv",
        "position_mm,force_N\n10,9\n11,9\n12,9\n12,9\n14,9\n",
    );
    refused(&run("6", &back, &[]), &["back.csv:5", "does not increase"]);
    let cols = s.file("cols.csv", "x_mm,force_N\n10,9\n11,9\n12,9\n13,9\n14,9\n");
    refused(&run("6", &cols, &[]), &["cols.csv", "position_mm"]);
    refused(
        &run("6", &s.path("missing.csv").display().to_string(), &[]),
        &["missing.csv"],
    );
    assert!(!s.path("cache").exists(), "no FE run, no cache entry");
}

/// `palpate simulate --benchmark R2`: a nodule outside the block or
/// overlapping another, RD not positive or too deep: refused up front.
#[test]
fn r2_geometry_is_checked_before_the_fe_run() {
    let s = Scratch::new();
    let r2 = |extra: &[&str]| {
        let mut a = vec!["simulate", "--benchmark", "R2", "--error-estimate", "off"];
        a.extend_from_slice(extra);
        s.run(&a)
    };
    refused(
        &r2(&["--rd", "3", "--nodules", "75:2"]),
        &["nodule", "depth"],
    );
    refused(
        &r2(&["--rd", "3", "--nodules", "200:15"]),
        &["nodule", "200"],
    );
    refused(
        &r2(&["--rd", "3", "--nodules", "75:15,80:15"]),
        &["overlaps"],
    );
    refused(&r2(&["--rd", "0"]), &["rd"]);
    refused(&r2(&["--rd", "9"]), &["rd", "deeper"]);
}

/// `[steps.localize]`: a bad RD, nodule list or scan, or the surrogate
/// cache of an earlier palpate, is refused by `run --check`, naming the manifest
/// field.
#[test]
fn localize_step_fields_are_checked() {
    let s = Scratch::new();
    let step = |body: &str| {
        format!("[study]\nname = \"t\"\n\n[[steps]]\n[steps.localize]\nname = \"r2\"\n{body}\n")
    };
    for (body, needles) in [
        (
            "rds = [3, 9]",
            vec!["steps[0].localize", "rds: 9", "deeper"],
        ),
        ("rds = [0]", vec!["rds: 0"]),
        ("rds = []", vec!["rds = []"]),
        (
            "rds = [3]\nnodules = \"37.5:10,40:15\"",
            vec!["nodules", "overlaps"],
        ),
        ("rds = [3]\nnodules = \"75:29\"", vec!["nodules", "depth"]),
        ("rds = [3]\nnoise = -1", vec!["noise = -1"]),
        (
            "rds = [3]\nscan = \"middle\"",
            vec!["line 8", "middle", "expected `lean` or `centre`"],
        ),
        (
            "rds = [3]\ncache = \"c\"",
            vec![
                "steps[0].localize",
                "cache = \"c\"",
                "run folder",
                "remove the field",
            ],
        ),
    ] {
        let m = s.file("m.toml", &step(body));
        refused(&s.run(&["run", "--check", &m]), &needles);
    }
}
