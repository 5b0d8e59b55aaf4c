//! One model description: every model kind parses from a manifest, bad
//! values name their field, and the command line and a manifest describing
//! the same model build the same model.

use clap::Parser;
use palpate_core::{Drive, Loading};
use palpate_studies::cli::{Cli, Command};
use palpate_studies::model::{build, Model, ModelSpec};
use palpate_studies::study::manifest::{Manifest, ModelForm};
use std::path::Path;

fn models(body: &str) -> anyhow::Result<Manifest> {
    let text = format!(
        "[study]\nname = \"t\"\n\n{body}\n[[steps]]\n[steps.calibrate]\nname = \"f\"\nmodels = []\nfits = {{}}\n"
    );
    Manifest::parse(Path::new("m.toml"), &text)
}

fn spec(m: &Manifest, name: &str) -> ModelSpec {
    match &m.models[name].model {
        ModelForm::Spec(s) => s.clone(),
        ModelForm::Law(l) => panic!("{name} is the law form {l}"),
    }
}

#[test]
fn every_model_kind_parses_from_a_manifest() {
    let m = models(
        r#"
[models.nh]
law = "neo-hookean"
fixed = { C10 = 0.001 }

[models.tension.homogeneous]
law = "mooney-rivlin"
mode = "biaxial"

[models.press.c1]
law = "yeoh"

[models.press-fe.c1_fe]
law = "neo-hookean"
platens = "bonded"
mesh = 2
bulk = 1000

[models.needle.n1_needle]
law = "neo-hookean"
friction = 0
mesh = "coarse"
bulk = "exact"
base = "sliding"
tool = "sphere:5"
"#,
    )
    .unwrap();
    assert_eq!(m.models["nh"].model, ModelForm::Law("neo-hookean".into()));
    assert_eq!(m.models["nh"].fixed["C10"], 0.001);
    let kinds: Vec<&str> = ["tension", "press", "press-fe", "needle"]
        .iter()
        .map(|n| spec(&m, n).kind())
        .collect();
    assert_eq!(kinds, ["homogeneous", "c1", "c1_fe", "n1_needle"]);
    for n in ["tension", "press", "press-fe", "needle"] {
        let s = spec(&m, n);
        s.validate().unwrap_or_else(|e| panic!("{n}: {e}"));
        build(&s).unwrap();
    }
    match spec(&m, "press-fe").validate().unwrap() {
        Model::C1Fe(c) => {
            assert_eq!(c.elements, (38, 18));
            assert_eq!(c.bulk, palpate_fe::Bulk::Ratio(1000.0));
            assert_eq!(c.platens, palpate_fe::Platens::Bonded);
        }
        other => panic!("{other:?}"),
    }
    match spec(&m, "needle").validate().unwrap() {
        Model::N1Needle(n) => {
            assert_eq!(n.friction, 0.0);
            assert_eq!(n.mesh.level, 1);
            assert_eq!(n.base, palpate_fe::Support::Sliding);
            assert_eq!(n.tool, palpate_fe::ToolShape::Sphere { radius: 5.0 });
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn defaults_are_the_benchmark_settings() {
    let m = models("[models.needle.n1_needle]\nlaw = \"neo-hookean\"\n").unwrap();
    match spec(&m, "needle").validate().unwrap() {
        Model::N1Needle(n) => {
            // the reference settings, on the user path's default mesh: the
            // 9-node benchmark grading
            let mut expected = palpate_fe::N1Needle::new(palpate_material::Law::NeoHookean);
            expected.element = palpate_fe::PlaneCell::Quad9;
            expected.grading = Some(palpate_fe::accuracy::N1_QUAD9_BENCH);
            assert_eq!(n, expected)
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn misspelled_model_field_is_an_error_with_its_line() {
    let e = models("[models.needle.n1_needle]\nlaw = \"neo-hookean\"\nfrction = 0.8\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("m.toml") && e.contains("frction") && e.contains("line 6"),
        "{e}"
    );
    let e = models("[models.needle.n1_needel]\nlaw = \"neo-hookean\"\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("n1_needel") && e.contains("n1_needle"), "{e}");
}

#[test]
fn mesh_zero_is_an_error_naming_the_field() {
    for mesh in ["0", "\"0\"", "13", "\"finest\""] {
        let e = models(&format!(
            "[models.needle.n1_needle]\nlaw = \"neo-hookean\"\nmesh = {mesh}\n"
        ))
        .unwrap_err()
        .to_string();
        let value = mesh.trim_matches('"');
        assert!(
            e.starts_with("m.toml: models.needle.n1_needle.mesh: ")
                && e.contains("line 6")
                && e.contains(&format!(
                    "mesh = \"{value}\": expected coarse, medium, fine or a level 1..12"
                )),
            "{mesh}: {e}"
        );
    }
    let o = palpate_studies::model::parse_mesh("c1_fe", Some("0")).unwrap_err();
    assert_eq!(
        o.as_option(),
        "--mesh `0`: expected coarse, medium, fine or a level 1..12"
    );
}

fn simulate_spec(args: &[&str]) -> ModelSpec {
    let mut argv = vec!["palpate", "simulate"];
    argv.extend_from_slice(args);
    match Cli::try_parse_from(argv).unwrap().command {
        Command::Simulate(a) => palpate_studies::cli::simulate::model_spec(&a).unwrap(),
        other => panic!("{other:?}"),
    }
}

#[test]
fn command_line_and_manifest_build_the_same_model() {
    let m = models(
        r#"
[models.needle.n1_needle]
law = "neo-hookean"
friction = 0.3
mesh = 3
base = "sliding"

[models.press.c1_fe]
law = "neo-hookean"
mesh = "coarse"
bulk = 1000
"#,
    )
    .unwrap();
    let cli = simulate_spec(&[
        "--benchmark",
        "N1",
        "--law",
        "neo-hookean",
        "--friction",
        "0.3",
        "--mesh",
        "fine",
        "--sliding-base",
    ]);
    let toml = spec(&m, "needle");
    assert_eq!(cli.validate().unwrap(), toml.validate().unwrap());
    assert_eq!(build(&cli).unwrap().name(), build(&toml).unwrap().name());

    let cli = simulate_spec(&[
        "--benchmark",
        "C1",
        "--law",
        "neo-hookean",
        "--mesh",
        "1",
        "--bulk",
        "1000",
    ]);
    let toml = spec(&m, "press");
    assert_eq!(cli.validate().unwrap(), toml.validate().unwrap());
    let (a, b) = (build(&cli).unwrap(), build(&toml).unwrap());
    assert_eq!(a.name(), b.name());
    let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 0.1, 0.2]);
    let theta = [1.101295e-3];
    let (fa, fb) = (
        a.predict(&theta, &loading).unwrap(),
        b.predict(&theta, &loading).unwrap(),
    );
    assert!(fa[2] > 0.0, "{fa:?}");
    assert_eq!(fa, fb);
}
