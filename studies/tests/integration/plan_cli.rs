//! `palpate plan` from the command line and as a study step: a small plan
//! on N1's coarse mesh, and its bad input (a candidate that leaves the
//! description's validity, no free parameter, no noise, a bad field).

use super::common::refused;
use std::path::Path;
use std::process::{Command, Output};

fn palpate(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_palpate"))
        .args(args)
        .output()
        .expect("run palpate")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).to_string()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// N1 on its coarse mesh, a 1 mm ramp of 4 samples; `C10` as given.
fn n1_file(dir: &Path, c10: &str) -> String {
    let text = format!(
        "name = \"N1 small\"\n\n[specimen]\nshape = \"cylinder\"\nradius = 35.0\nheight = 80.0\n\
         support = \"bonded\"\n\n[materials.ecoflex]\nlaw = \"neo-hookean\"\nC10 = {c10}\n\n\
         [tool]\nshape = \"needle\"\nhalf_angle = 15.0\ntip_radius = 2.5\nfriction = 0.8\n\n\
         [protocol]\nsegments = [{{ ramp_to = 1.0 }}]\nsamples = 4\n\n\
         [mesh]\nlevel = 1\nelement = \"quad4\"\n"
    );
    let file = dir.join("n1.toml");
    std::fs::write(&file, text).unwrap();
    file.display().to_string()
}

#[test]
fn plan_help_explains_the_candidates_and_the_noise() {
    let o = palpate(&["plan", "--help"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let h = stdout(&o);
    for needle in [
        "--vary",
        "START:STOP:COUNT",
        "protocol.segments[0].ramp_to",
        "--noise-from",
        "worst-relative",
        "not identifiable",
    ] {
        assert!(h.contains(needle), "`{needle}` not in: {h}");
    }
}

#[test]
fn a_plan_ranks_candidates_and_writes_json() {
    let dir = tempfile::tempdir().unwrap();
    let file = n1_file(dir.path(), "{ start = 1.1e-3 }");
    let json = dir.path().join("plan.json");
    let o = palpate(&[
        "plan",
        "--experiment",
        &file,
        "--vary",
        "tool.tip_radius=1,2.5",
        "--noise",
        "1%",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.contains("tool.tip_radius=1") && out.contains("SE C10"),
        "{out}"
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let c = v["candidates"].as_array().unwrap();
    assert_eq!(c.len(), 2);
    assert_eq!(c[0]["rank"], 1);
    assert_eq!(c[0]["information"]["jacobian"], "exact");
    let se = c[0]["information"]["standard_errors"][0].as_f64().unwrap();
    assert!(se > 0.0 && se < 1.1e-3, "{se}");
    // the same plan as a study step
    let manifest = dir.path().join("study.toml");
    std::fs::write(
        &manifest,
        "[study]\nname = \"design\"\n\n[[steps]]\n[steps.plan]\nname = \"needle\"\n\
         experiment = \"n1.toml\"\nvary = [\"tool.tip_radius=1,2.5\"]\nnoise = \"1%\"\n",
    )
    .unwrap();
    let out_dir = dir.path().join("run");
    let o = palpate(&[
        "run",
        manifest.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let step: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("needle.json")).unwrap())
            .unwrap();
    assert_eq!(step["candidates"], v["candidates"]);
}

#[test]
fn plan_bad_input_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let file = n1_file(dir.path(), "{ start = 1.1e-3 }");
    // a candidate tool as large as the specimen (radius 35 mm)
    refused(
        &palpate(&[
            "plan",
            "--experiment",
            &file,
            "--vary",
            "tool.tip_radius=1,40",
            "--noise",
            "0.01",
        ]),
        &[
            "candidate tool.tip_radius=40",
            "tool.tip_radius",
            "as large as the specimen",
        ],
    );
    refused(
        &palpate(&["plan", "--experiment", &file, "--vary", "tool.tip_radius=1"]),
        &["--noise", "missing"],
    );
    refused(
        &palpate(&[
            "plan",
            "--experiment",
            &file,
            "--vary",
            "tool.tip=1",
            "--noise",
            "0.01",
        ]),
        &["tool.tip"],
    );
    refused(
        &palpate(&[
            "plan",
            "--experiment",
            &file,
            "--noise",
            "0.01",
            "--criterion",
            "C20",
        ]),
        &["criterion `C20`", "C10"],
    );
    let fixed = tempfile::tempdir().unwrap();
    let file = n1_file(fixed.path(), "1.1e-3");
    refused(
        &palpate(&["plan", "--experiment", &file, "--noise", "0.01"]),
        &["no free parameter", "C10"],
    );
}
