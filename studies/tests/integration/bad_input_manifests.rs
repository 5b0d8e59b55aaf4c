//! Bad study manifests, as `bad_input.rs` (whose conventions these
//! follow): study names that leave the run folder, mistakes in a step's
//! fields, and effects the model lacks; each refused by `run --check` with
//! the manifest and the field named. The source studies' steps (Q1, R2) are
//! in `bad_input_benchmarks.rs`.

use crate::bad_input::UNI;
use crate::common;
use common::*;

fn manifest(s: &Scratch, name: &str, body: &str) -> String {
    s.file("d.csv", UNI);
    s.file(name, body)
}

const DATA: &str = "[data.uni]\nfile = \"d.csv\"\ntest = \"uniaxial\"\n\n[models.nh]\nlaw = \"neo-hookean\"\n\n[models.mr]\nlaw = \"mooney-rivlin\"\n";

fn step(name: &str, extra: &str) -> String {
    format!("[[steps]]\n[steps.calibrate]\nname = \"{name}\"\nmodels = [\"nh\"]\nfits = {{ u = [\"uni\"] }}\n{extra}\n")
}

#[test]
fn study_names_that_leave_the_run_folder_are_refused() {
    let s = Scratch::new();
    for name in [
        "../../escaped",
        "/tmp/abs",
        "",
        " ",
        "..",
        ".",
        "a/b",
        "a\\\\b",
        "tab\\there",
    ] {
        let m = manifest(
            &s,
            "m.toml",
            &format!("[study]\nname = \"{name}\"\n{DATA}{}", step("fit", "")),
        );
        for args in [vec!["run", "--check", &m], vec!["run", &m]] {
            refused(&s.run(&args), &["m.toml", "study.name"]);
        }
    }
    assert!(!s.0.path().parent().unwrap().join("escaped").exists());
    assert!(
        !s.path("runs").exists(),
        "nothing written for a refused study"
    );
}

#[test]
fn manifest_mistakes_name_the_manifest_and_the_field() {
    let s = Scratch::new();
    let head = "[study]\nname = \"t\"\n";
    let cases: Vec<(String, Vec<&str>)> = vec![
        (format!("{head}{DATA}{}{}", step("fit", ""), step("fit", "")), vec!["steps[1].calibrate.name", "steps[0]"]),
        (format!("{head}{DATA}{}", step("a/b", "")), vec!["steps[0].calibrate.name"]),
        (format!("{head}{DATA}{}", step("", "")), vec!["steps[0].calibrate.name"]),
        (format!("{head}{DATA}{}", step("..", "")), vec!["steps[0].calibrate.name"]),
        (format!("{head}{DATA}[[steps]]\n[steps.calibrate]\nname = \"f\"\nmodels = []\nfits = {{ u = [\"uni\"] }}\n"), vec!["models = []"]),
        (format!("{head}{DATA}{}", step("f", "residuals = []")), vec!["residuals = []"]),
        (format!("{head}{DATA}[[steps]]\n[steps.calibrate]\nname = \"f\"\nmodels = [\"nh\", \"nh\"]\nfits = {{ u = [\"uni\"] }}\n"), vec!["models", "\"nh\" is listed twice"]),
        (format!("{head}{DATA}{}", step("f", "residuals = [\"relative\", \"relative\"]")), vec!["residuals", "twice"]),
        (format!("{head}{DATA}{}", step("f", "residuals = [\"squared\"]")), vec!["residuals", "squared"]),
        (format!("{head}{DATA}{}", step("f", "estimator = \"magic\"")), vec!["estimator", "magic"]),
        (format!("{head}{DATA}{}", step("f", "predict = [\"nope\"]")), vec!["predict", "nope"]),
        (format!("{head}{DATA}[[steps]]\n[steps.calibrate]\nname = \"f\"\nmodels = [\"ghost\"]\nfits = {{ u = [\"uni\"] }}\n"), vec!["models", "ghost"]),
        (format!("{head}{DATA}[[steps]]\n[steps.calibrate]\nname = \"f\"\nmodels = [\"nh\"]\nfits = {{ u = [\"ghost\"] }}\n"), vec!["fits.u", "ghost"]),
        (format!("{head}{DATA}[[steps]]\n[steps.calibrate]\nname = \"f\"\nmodels = [\"nh\"]\nfits = {{ u = [] }}\n"), vec!["fits.u", "empty"]),
        (format!("{head}{DATA}[[steps]]\n[steps.calibrate]\nname = \"f\"\nmodels = [\"nh\"]\nfits = {{}}\n"), vec!["fits"]),
        (format!("{head}{DATA}steps = []\n"), vec!["steps"]),
        (format!("{head}[data.uni]\nfile = \"none.csv\"\ntest = \"uniaxial\"\n{}", step("f", "")), vec!["data.uni.file", "none.csv"]),
        (format!("{head}[data.uni]\nfile = \"d.csv\"\ntest = \"shear\"\n{}", step("f", "")), vec!["data.uni.test", "shear"]),
        (format!("{head}{DATA}[models.x]\nlaw = \"ogden:0\"\n{}", step("f", "")), vec!["models.x.law"]),
        (format!("{head}{DATA}[models.x.n1_needle]\nlaw = \"neo-hookean\"\nmesh = 0\n{}", step("f", "")), vec!["models.x.n1_needle.mesh", "line 14", "mesh = \"0\": expected coarse, medium, fine or a level 1..12"]),
        (format!("{head}{DATA}[models.x.c1_fe]\nlaw = \"neo-hookean\"\nplatens = \"glued\"\n{}", step("f", "")), vec!["models.x.c1_fe.platens", "line 14", "platens = \"glued\": expected frictionless or bonded"]),
        (format!("{head}{DATA}{}", step("f", "colour = 1")), vec!["colour"]),
        (format!("{head}{DATA}{}", step("f", "residuals = ")), vec!["m.toml"]),
    ];
    for (text, needles) in cases {
        let m = manifest(&s, "m.toml", &text);
        let mut n = needles.clone();
        n.push("m.toml");
        refused(&s.run(&["run", "--check", &m]), &n);
        refused(&s.run(&["run", &m]), &n);
    }
    assert!(!s.path("runs").exists());
}

#[test]
fn a_diagnose_step_with_an_effect_the_model_lacks_is_refused() {
    let s = Scratch::new();
    s.file(
        "c1.csv",
        "displacement_mm,force_N\n0,0\n0.5,1\n1,2.2\n1.5,3.6\n2,5.3\n",
    );
    let body = "[study]\nname = \"g\"\n[data.rec]\nfile = \"c1.csv\"\ntest = \"C1\"\n[[steps]]\n[steps.diagnose]\nname = \"gap\"\ndata = [\"rec\"]\nbase = \"neo-hookean\"\n";
    for (extra, needles) in [
        (
            "effects = [\"boundary_condition\"]",
            vec!["effects", "boundary_condition", "does not offer"],
        ),
        ("effects = []", vec!["effects = []"]),
        (
            "effects = [\"viscoelasticity\", \"viscoelasticity\"]",
            vec!["effects", "twice"],
        ),
        ("effects = [\"warp\"]", vec!["effects", "warp"]),
    ] {
        let m = s.file("g.toml", &format!("{body}{extra}\n"));
        refused(&s.run(&["run", "--check", &m]), &{
            let mut n = needles.clone();
            n.push("g.toml");
            n
        });
    }
    let m = s.file(
        "g.toml",
        &format!("{body}effects = [\"viscoelasticity\"]\n"),
    );
    accepted(&s.run(&["run", "--check", &m]));
}
