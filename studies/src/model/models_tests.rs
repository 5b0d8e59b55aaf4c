//! Unit tests of [`crate::model`] (the spec and its factory).

use crate::model::*;
use palpate_fe::PlaneCell;

#[test]
fn a_spec_reads_from_its_own_toml_table() {
    let s: ModelSpec = toml::from_str("[c1_fe]\nlaw = \"yeoh\"\nmesh = 4\n").unwrap();
    assert_eq!(
        s,
        ModelSpec::C1Fe(C1FeSpec {
            law: "yeoh".into(),
            mesh: Some(Mesh::Level(4)),
            ..Default::default()
        })
    );
    assert!(matches!(s.validate(), Ok(Model::C1Fe(m)) if m.elements == (76, 36)));
    let e = toml::from_str::<ModelSpec>("[c1]\nlaw = \"yeoh\"\nmesh = 4\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("mesh"), "{e}");
}

/// `[n3_needle]`: coarse by default, friction and mesh checked by name.
#[test]
fn n3_needle_spec() {
    let s: ModelSpec =
        toml::from_str("[n3_needle]\nlaw = \"neo-hookean\"\nfriction = 0\n").unwrap();
    assert_eq!(s.kind(), "n3_needle");
    assert!(matches!(s.validate(), Ok(Model::N3Needle(m)) if m.level == 1 && m.friction == 0.0));
    let n3 = |f: fn(&mut N3NeedleSpec)| {
        let mut s = N3NeedleSpec {
            law: "neo-hookean".into(),
            ..Default::default()
        };
        f(&mut s);
        ModelSpec::N3Needle(s).validate().unwrap_err().to_string()
    };
    assert!(n3(|s| s.friction = Some(-0.1)).starts_with("n3_needle.friction"));
    let e = n3(|s| s.mesh = Some(Mesh::Level(3)));
    assert!(
        e.starts_with("n3_needle.mesh = \"fine\"") && e.contains("241703 equations"),
        "{e}"
    );
    let e = n3(|s| s.mesh = Some(Mesh::Bench));
    assert!(e.starts_with("n3_needle.mesh = \"bench\""), "{e}");
    assert_eq!(
        spec_error("[n3_needle]\nlaw = \"neo-hookean\"\ntool = \"cone\"\n"),
        "tool = \"cone\": expected needle, sphere:RADIUS, punch:RADIUS or platen"
    );
    assert_eq!(
        spec_error("[n3_needle]\nlaw = \"neo-hookean\"\nelement = \"hex20\"\n"),
        "element = \"hex20\": expected hex8 or hex27"
    );
    let s: ModelSpec =
        toml::from_str("[n3_needle]\nlaw = \"neo-hookean\"\nelement = \"hex27\"\n").unwrap();
    assert!(matches!(s.validate(),
        Ok(Model::N3Needle(m)) if m.element == N3Element::Hex27 && m.mesh == N3Mesh::OGrid && m.level == 1));
}

#[test]
fn c1_fe_takes_a_prony_series() {
    let s: ModelSpec =
        toml::from_str("[c1_fe]\nlaw = \"yeoh\"\nprony = \"g1=0.3,tau1=0.5\"\n").unwrap();
    assert!(matches!(s.validate(),
        Ok(Model::C1Fe(m)) if m.prony.as_ref().map(|p| p.terms().to_vec()) == Some(vec![(0.3, 0.5)])));
    let e = spec_error("[c1_fe]\nlaw = \"yeoh\"\nprony = \"g1=0.7,tau1=1,g2=0.3,tau2=2\"\n");
    assert!(
        e.starts_with("prony = \"g1=0.7") && e.contains("sum to 1"),
        "{e}"
    );
}

#[test]
fn q1_reads_its_mesh_element_and_prony() {
    let s: ModelSpec = toml::from_str(
        "[q1]\nlaw = \"neo-hookean\"\nmesh = 1\nelement = \"quad9\"\nprony = \"g1=0.3,tau1=0.5\"\n",
    )
    .unwrap();
    assert_eq!(s.kind(), "q1");
    assert!(matches!(s.validate(),
        Ok(Model::Q1(m)) if m.level == 1 && m.element == PlaneCell::Quad9 && m.prony.is_some()));
    assert!(s.test().unwrap_err().to_string().contains("Q1 records"));
    assert_eq!(
        spec_error("[q1]\nlaw = \"neo-hookean\"\nelement = \"tri3\"\n"),
        "element = \"tri3\": expected quad4 or quad9"
    );
    // `bench` reads (an N1 mesh); the other kinds refuse it by name
    let s: ModelSpec = toml::from_str("[q1]\nlaw = \"neo-hookean\"\nmesh = \"bench\"\n").unwrap();
    let e = s.validate().unwrap_err().to_string();
    assert!(
        e.starts_with("q1.mesh = \"bench\"") && e.contains("bench is a mesh of n1_needle"),
        "{e}"
    );
}

#[test]
fn q1_reads_its_edge_radius() {
    let q1 = |extra: &str| -> ModelSpec {
        toml::from_str(&format!("[q1]\nlaw = \"neo-hookean\"\n{extra}")).unwrap()
    };
    assert!(matches!(q1("").validate(),
        Ok(Model::Q1(m)) if m.edge_radius == palpate_fe::q1::DEFAULT_EDGE_RADIUS));
    assert!(matches!(q1("edge_radius = 1.0\n").validate(),
        Ok(Model::Q1(m)) if m.edge_radius == 1.0));
    for bad in ["0", "-0.2", "2.0", "5.0", "nan"] {
        let e = q1(&format!("edge_radius = {bad}\n"))
            .validate()
            .unwrap_err();
        assert_eq!(e.field, "edge_radius", "{bad}");
        assert!(e.to_string().starts_with("q1.edge_radius"), "{e}");
    }
}

#[test]
fn the_one_mesh_parser() {
    for (s, level) in [("coarse", 1), ("medium", 2), ("fine", 3), ("12", 12)] {
        assert_eq!(parse_mesh("n1_needle", Some(s)), Ok(level));
    }
    assert_eq!(parse_mesh("n1_needle", None), Ok(2));
    for bad in ["0", "13", "-1", "1.5", "Coarse"] {
        let e = parse_mesh("n1_needle", Some(bad)).unwrap_err();
        assert_eq!((e.field, e.value.as_str()), ("mesh", bad));
    }
}

#[test]
fn bad_values_name_their_field() {
    let n1 = |f: fn(&mut N1NeedleSpec)| {
        let mut s = N1NeedleSpec {
            law: "neo-hookean".into(),
            ..Default::default()
        };
        f(&mut s);
        ModelSpec::N1Needle(s).validate().unwrap_err().to_string()
    };
    assert!(n1(|s| s.law = "neo".into()).starts_with("n1_needle.law = \"neo\""));
    assert!(n1(|s| s.friction = Some(-0.1)).starts_with("n1_needle.friction"));
    // the settings read from text name the field, the value and what is valid
    for (line, message) in [
        (
            "element = \"quad8\"",
            "element = \"quad8\": expected quad4 or quad9",
        ),
        (
            "bulk = 0",
            "bulk = \"0\": expected `exact` or a ratio K/mu in (0, 1e9] such as 1000",
        ),
        (
            "bulk = \"soft\"",
            "bulk = \"soft\": expected `exact` or a ratio K/mu in (0, 1e9] such as 1000",
        ),
        (
            "base = \"glued\"",
            "base = \"glued\": expected bonded or sliding",
        ),
        (
            "tool = \"sphere:-1\"",
            "tool = \"sphere:-1\": `-1` is not a positive radius in mm",
        ),
        ("tool = true", "tool: expected text or a number"),
        (
            "mesh = 0",
            "mesh = \"0\": expected coarse, medium, fine or a level 1..12",
        ),
        (
            "mesh = \"finest\"",
            "mesh = \"finest\": expected coarse, medium, fine or a level 1..12",
        ),
    ] {
        let e = spec_error(&format!("[n1_needle]\nlaw = \"neo-hookean\"\n{line}\n"));
        assert_eq!(e, message, "{line}");
    }
    assert_eq!(
        spec_error("[c1_fe]\nlaw = \"yeoh\"\nplatens = \"glued\"\n"),
        "platens = \"glued\": expected frictionless or bonded"
    );
    assert_eq!(
        spec_error(
            "[homogeneous]\nlaw = \"yeoh\"\nmode = \"uniaxial\"\nviscoelastic = \"qlv:9\"\n"
        ),
        "viscoelastic = \"qlv:9\": `qlv:9`: the number of Prony terms must be 1 to 6"
    );
}

/// Every text a manifest or a command accepted as a string before the
/// settings were typed reads to the same model, numbers included.
#[test]
fn settings_read_as_text_or_number() {
    let read = |extra: &str| -> ModelSpec {
        toml::from_str(&format!("[n1_needle]\nlaw = \"neo-hookean\"\n{extra}\n")).unwrap()
    };
    let n1 = |extra: &str| match read(extra).validate() {
        Ok(Model::N1Needle(m)) => m,
        other => panic!("{extra}: {other:?}"),
    };
    assert_eq!(n1("mesh = 2"), n1("mesh = \"2\""));
    assert_eq!(n1("mesh = 2"), n1("mesh = \"medium\""));
    assert_eq!(n1("mesh = 2.0"), n1("mesh = \"medium\""));
    assert_eq!(n1("bulk = 1000").bulk, palpate_fe::Bulk::Ratio(1000.0));
    assert_eq!(n1("bulk = \"1000\"").bulk, palpate_fe::Bulk::Ratio(1000.0));
    assert_eq!(n1("bulk = 2.5e3").bulk, palpate_fe::Bulk::Ratio(2500.0));
    assert_eq!(n1("").bulk, palpate_fe::Bulk::Exact);
    assert_eq!(n1("base = \"sliding\"").base, palpate_fe::Support::Sliding);
    assert_eq!(n1("tool = \"platen\"").tool, palpate_fe::ToolShape::Platen);
    assert_eq!(
        n1("tool = \"sphere:2.5\"").tool,
        palpate_fe::ToolShape::Sphere { radius: 2.5 }
    );
    assert_eq!(
        n1("tool = \"punch:0.1\"").tool,
        palpate_fe::ToolShape::FlatPunch {
            radius: 0.1,
            edge_radius: 0.05
        }
    );
    // the needle without a mesh: the Q2/P1 benchmark mesh; `bench` names it
    let auto = n1("");
    assert_eq!(auto.element, PlaneCell::Quad9);
    assert_eq!(auto, n1("mesh = \"bench\""));
    assert_eq!(
        n1("mesh = \"bench\"\nelement = \"quad4\"").element,
        PlaneCell::Quad4
    );
    assert_eq!(n1("element = \"quad4\"").mesh.level, 2);
    // the typed spec and the text it was read from say the same
    assert_eq!(
        read("mesh = \"fine\"\nbulk = 1000\nelement = \"quad9\""),
        ModelSpec::N1Needle(N1NeedleSpec {
            law: "neo-hookean".into(),
            mesh: Some(Mesh::Level(3)),
            bulk: Some(palpate_fe::Bulk::Ratio(1000.0)),
            element: Some(PlaneCell::Quad9),
            ..Default::default()
        })
    );
    // a command-line option reads as the manifest's setting
    assert_eq!(
        parse_setting::<Mesh>("n1_needle", Some("fine")),
        Ok(Some(Mesh::Level(3)))
    );
    let e = parse_setting::<palpate_fe::Bulk>("n1_needle", Some("-1")).unwrap_err();
    assert_eq!(
        e.as_option(),
        "--bulk `-1`: expected `exact` or a ratio K/mu in (0, 1e9] such as 1000"
    );
}

/// The message of a spec that does not read (TOML's line context cut off).
fn spec_error(text: &str) -> String {
    match toml::from_str::<ModelSpec>(text) {
        Err(e) => e.message().to_string(),
        Ok(s) => panic!("{text} reads: {s:?}"),
    }
}

/// `[r2]`: the nodules read as `X:DEPTH,...` or `none`, and write back so.
#[test]
fn r2_reads_its_nodules() {
    let r2 =
        |extra: &str| -> ModelSpec { toml::from_str(&format!("[r2]\nrd = 6\n{extra}\n")).unwrap() };
    let ModelSpec::R2(s) = r2("nodules = \"37.5:10, 75:15\"") else {
        panic!("not r2")
    };
    let n = s.nodules.unwrap();
    assert_eq!(nodules_text(&n), "37.5:10,75:15");
    assert_eq!(
        Vec::<palpate_fe::Nodule>::from_text(&nodules_text(&n)),
        Ok(n)
    );
    let default = match r2("").validate() {
        Ok(Model::R2(m)) => m.nodules.clone(),
        other => panic!("{other:?}"),
    };
    assert_eq!(nodules_text(&default), R2_DEFAULT_NODULES);
    assert!(
        matches!(r2("nodules = \"none\"").validate(), Ok(Model::R2(m)) if m.nodules.is_empty())
    );
    assert_eq!(
        spec_error("[r2]\nrd = 6\nnodules = \"75\"\n"),
        "nodules = \"75\": `75`: expected X:DEPTH (mm), e.g. 75:15"
    );
    let e = r2("nodules = \"200:15\"")
        .validate()
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("r2.nodules = \"200:15\""), "{e}");
}
