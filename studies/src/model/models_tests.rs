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
            mesh: Some("4".into()),
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
    let e = n3(|s| s.mesh = Some("fine".into()));
    assert!(
        e.starts_with("n3_needle.mesh") && e.contains("241703 equations"),
        "{e}"
    );
    assert!(n3(|s| s.tool = Some("cone".into())).starts_with("n3_needle.tool"));
    assert!(n3(|s| s.element = Some("hex20".into())).starts_with("n3_needle.element"));
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
    let s: ModelSpec =
        toml::from_str("[c1_fe]\nlaw = \"yeoh\"\nprony = \"g1=0.7,tau1=1,g2=0.3,tau2=2\"\n")
            .unwrap();
    let e = s.validate().unwrap_err().to_string();
    assert!(e.contains("prony") && e.contains("sum to 1"), "{e}");
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
    let s: ModelSpec = toml::from_str("[q1]\nlaw = \"neo-hookean\"\nelement = \"tri3\"\n").unwrap();
    assert!(s
        .validate()
        .unwrap_err()
        .to_string()
        .starts_with("q1.element"));
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
    assert!(
        n1(|s| s.element = Some("quad8".into())).contains("element"),
        "a misspelled element is named"
    );
    assert!(n1(|s| s.friction = Some(-0.1)).starts_with("n1_needle.friction"));
    assert!(n1(|s| s.bulk = Some("0".into())).starts_with("n1_needle.bulk"));
    assert!(n1(|s| s.base = Some("glued".into())).starts_with("n1_needle.base"));
    assert!(n1(|s| s.tool = Some("sphere:-1".into())).starts_with("n1_needle.tool"));
}
