//! The description's parsing, round trip, presets and checks.

use super::*;
use crate::FeError;

const GEL: &str = r#"
[specimen]
shape = "cylinder"
radius = 20.0
height = 10.0
support = "bonded"

[materials.gel]
law = "neo-hookean"
C10 = { start = 2e-3 }

[tool]
shape = "sphere"
radius = 2.5

[protocol]
segments = [{ ramp_to = 3.0 }]
"#;

/// The error of reading `text`, as a string.
fn read_err(text: &str) -> String {
    Experiment::from_toml_str(text, "gel.toml")
        .unwrap_err()
        .to_string()
}

/// The field of a check's error (panics, failing the test, otherwise).
fn field_of(text: &str) -> (String, String) {
    match Experiment::from_toml_str(text, "gel.toml") {
        Err(FeError::InvalidConfig { field, reason }) => (field, reason),
        other => panic!("expected InvalidConfig, got {other:?}"),
    }
}

fn assert_field(text: &str, field: &str) {
    let (f, reason) = field_of(text);
    assert_eq!(f, field, "{reason}");
    assert!(reason.contains("gel.toml"), "{reason}");
}

#[test]
fn the_gel_disc_reads() {
    let e = Experiment::from_toml_str(GEL, "gel.toml").unwrap();
    assert_eq!(e.height(), Some(10.0));
    assert_eq!(e.param_space().unwrap().names(), ["C10"]);
}

#[test]
fn a_bad_value_says_what_a_value_may_be() {
    let err = read_err(&GEL.replace("C10 = { start = 2e-3 }", "C10 = [1.0]"));
    assert!(err.contains("expected a number, { start = .. }"), "{err}");
    assert!(err.contains("\"bonded\"/\"frictionless\""), "{err}");
    assert!(!err.contains("untagged"), "{err}");
    let err = read_err(&GEL.replace("radius = 2.5", "radius = 2.5\nfriction = \"sticky\""));
    assert!(
        err.contains("`sticky`") && err.contains("\"bonded\""),
        "{err}"
    );
}

#[test]
fn an_unknown_key_of_a_parameter_is_named() {
    let err = read_err(&GEL.replace("{ start = 2e-3 }", "{ start = 2e-3, uper = 1.0 }"));
    assert!(err.contains("`uper`"), "{err}");
    assert!(err.contains("start, fit, lower, upper, nuisance"), "{err}");
    let err = read_err(&GEL.replace("{ start = 2e-3 }", "{ lower = 1e-3 }"));
    assert!(err.contains("without `start`"), "{err}");
}

#[test]
fn a_parameter_table_keeps_its_fields() {
    let e = Experiment::from_toml_str(
        &GEL.replace(
            "{ start = 2e-3 }",
            "{ start = 2, fit = false, lower = 1e-3, upper = 9, nuisance = true }",
        ),
        "gel.toml",
    )
    .unwrap();
    assert_eq!(
        e.materials["gel"].params["C10"],
        Value::Param(ParamValue {
            start: 2.0,
            fit: false,
            lower: Some(1e-3),
            upper: Some(9.0),
            nuisance: true,
        })
    );
}

#[test]
fn a_toml_error_has_the_file_and_line() {
    let text = GEL.replace("radius = 2.5", "radius = 2.5\ntip = 1.0");
    match Experiment::from_toml_str(&text, "gel.toml") {
        Err(FeError::ConfigFile { file, line, reason }) => {
            assert_eq!(file, "gel.toml");
            let want = text.lines().position(|l| l.starts_with("tip")).unwrap() + 1;
            assert_eq!(line, want, "{reason}");
            assert!(reason.contains("tip"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    let err = read_err("[specimen\n");
    assert!(err.starts_with("gel.toml:1:"), "{err}");
}

#[test]
fn descriptions_round_trip_through_toml() {
    let layered = r#"
name = "skin"
[specimen]
shape = "cylinder"
radius = 30.0
layers = [{ thickness = 2.0, material = "skin" }, { thickness = 18.0, material = "fat" }]
support = { friction = { start = 0.3, fit = false } }
inclusions = [{ shape = "sphere", depth = 8.0, radius = 2.0, material = "fat" }]

[materials.skin]
law = "mooney-rivlin"
bulk = 1000.0
C10 = 1e-3
prony = [{ g = 0.3, tau = { start = 0.5 } }]

[materials.fat]
law = "ogden:2"
bulk = "exact"

[tool]
shape = "cone"
half_angle = 30.0
tip_radius = 0.1
friction = "bonded"

[protocol]
segments = [{ ramp_to = 2.0, time = 1.0 }, { hold = 5.0, samples = 50 }, { unload_to = 0.0, time = 1.0 }]
samples = 10

[mesh]
accuracy = 0.02
element = "quad9"
"#;
    let mut texts: Vec<String> = vec![GEL.into(), layered.into()];
    for name in Experiment::PRESETS {
        texts.push(Experiment::preset_toml(name).unwrap().into());
    }
    for text in texts {
        let e = Experiment::from_toml_str(&text, "x.toml").unwrap();
        let back = e.to_toml();
        let again = Experiment::from_toml_str(&back, "back.toml")
            .unwrap_or_else(|err| panic!("{err}\n{back}"));
        assert_eq!(again, e, "{back}");
    }
}

#[test]
fn a_file_s_paths_are_its_folder_s() {
    let dir = std::env::temp_dir().join(format!("palpate-exp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("gel.toml");
    let text = GEL.replace(
        "segments = [{ ramp_to = 3.0 }]",
        "from_record = \"indent_01.csv\"",
    );
    std::fs::write(&path, text).unwrap();
    let e = Experiment::from_toml_file(&path).unwrap();
    assert_eq!(
        e.protocol.from_record.as_deref(),
        Some(dir.join("indent_01.csv").display().to_string().as_str())
    );
    assert_eq!(e.name.as_deref(), Some("gel"));
    let missing = Experiment::from_toml_file(dir.join("none.toml")).unwrap_err();
    assert!(
        matches!(&missing, FeError::ConfigFile { file, line: 0, .. } if file.ends_with("none.toml")),
        "{missing}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn presets_are_named_case_insensitively() {
    for name in Experiment::preset_names() {
        let e = Experiment::preset(&name.to_lowercase()).unwrap();
        assert_eq!(e.name.as_deref(), Some(*name));
        assert!(Experiment::preset_toml(name).unwrap().starts_with("# "));
    }
    let err = Experiment::preset("N2").unwrap_err().to_string();
    assert!(
        err.contains("`N2`") && err.contains("N1, N3, C1, C1-bonded, Q1, R2, R2-1"),
        "{err}"
    );
}

#[test]
fn preset_parameter_spaces_are_the_reference_models() {
    let names = |p: &str| {
        Experiment::preset(p)
            .unwrap()
            .param_space()
            .unwrap()
            .names()
    };
    assert_eq!(names("N1"), ["C10"]);
    assert_eq!(names("N3"), ["C10"]);
    assert_eq!(names("C1"), ["C10", "C20"]);
    assert_eq!(names("C1-bonded"), ["C10", "C20"]);
    assert_eq!(names("Q1"), ["C10", "g1", "tau1_s", "g2", "tau2_s"]);
    assert_eq!(
        names("R2"),
        [
            "tissue_mu",
            "tissue_lambda_m",
            "nodule_mu",
            "nodule_lambda_m"
        ]
    );
}

// ---- bad input: one test per case, each naming the field ----

#[test]
fn a_sphere_larger_than_the_specimen() {
    assert_field(&GEL.replace("radius = 2.5", "radius = 20.0"), "tool.radius");
}

#[test]
fn a_punch_larger_than_the_block() {
    let text = block3d("shape = \"flat_punch\"\nradius = 35.0");
    assert_field(&text, "tool.radius");
}

#[test]
fn a_negative_size() {
    assert_field(
        &GEL.replace("radius = 20.0", "radius = -20.0"),
        "specimen.radius",
    );
    assert_field(
        &GEL.replace("height = 10.0", "height = 0.0"),
        "specimen.height",
    );
    assert_field(&GEL.replace("radius = 2.5", "radius = -1.0"), "tool.radius");
}

#[test]
fn a_tool_outside_the_top_face() {
    let text = block3d("shape = \"needle\"\nat = [36.0, 0.0]");
    assert_field(&text, "tool.at[0]");
    let text = block3d("shape = \"needle\"\nat = [0.0, -40.0]");
    assert_field(&text, "tool.at[1]");
}

#[test]
fn a_position_on_an_axisymmetric_specimen() {
    assert_field(
        &GEL.replace("radius = 2.5", "radius = 2.5\nat = [1.0, 0.0]"),
        "tool.at",
    );
}

#[test]
fn a_first_segment_above_the_surface() {
    assert_field(
        &GEL.replace("ramp_to = 3.0", "ramp_to = -1.0"),
        "protocol.segments[0].ramp_to",
    );
}

#[test]
fn a_protocol_deeper_than_the_specimen() {
    let (field, reason) = field_of(&GEL.replace("ramp_to = 3.0", "ramp_to = 10.0"));
    assert_eq!(field, "protocol.segments[0].ramp_to");
    assert!(reason.contains("10 mm"), "{reason}");
    let text = GEL.replace(
        "segments = [{ ramp_to = 3.0 }]",
        "segments = [{ ramp_to = 3.0 }, { unload_to = 1.0 }, { ramp_to = 12.0 }]",
    );
    assert_field(&text, "protocol.segments[2].ramp_to");
}

#[test]
fn a_segment_of_two_kinds_or_none() {
    assert_field(
        &GEL.replace("ramp_to = 3.0", "ramp_to = 3.0, hold = 1.0"),
        "protocol.segments[0]",
    );
    assert_field(
        &GEL.replace("{ ramp_to = 3.0 }", "{}"),
        "protocol.segments[0]",
    );
}

#[test]
fn an_unload_below_the_tool_or_a_hold_without_times() {
    let text = GEL.replace(
        "[{ ramp_to = 3.0 }]",
        "[{ ramp_to = 3.0 }, { unload_to = 4.0 }]",
    );
    assert_field(&text, "protocol.segments[1].unload_to");
    let text = GEL.replace("[{ ramp_to = 3.0 }]", "[{ ramp_to = 3.0 }, { hold = 4.0 }]");
    assert_field(&text, "protocol.segments[1].hold");
    let text = GEL.replace(
        "[{ ramp_to = 3.0 }]",
        "[{ ramp_to = 3.0, time = 1.0 }, { unload_to = 0.0 }]",
    );
    assert_field(&text, "protocol.segments[1].time");
}

#[test]
fn a_record_and_segments_together() {
    let text = GEL.replace("[protocol]", "[protocol]\nfrom_record = \"a.csv\"");
    assert_field(&text, "protocol.segments");
}

#[test]
fn a_layer_of_zero_thickness() {
    let text = GEL.replace(
        "height = 10.0",
        "layers = [{ thickness = 0.0, material = \"gel\" }]",
    );
    assert_field(&text, "specimen.layers[0].thickness");
    let text = GEL.replace(
        "height = 10.0",
        "layers = [{ thickness = 5.0, material = \"gel\" }, { thickness = -1.0, material = \"gel\" }]",
    );
    assert_field(&text, "specimen.layers[1].thickness");
}

#[test]
fn layers_that_do_not_add_up_to_the_height() {
    let text = GEL.replace(
        "height = 10.0",
        "height = 10.0\nlayers = [{ thickness = 4.0, material = \"gel\" }, { thickness = 5.0, material = \"gel\" }]",
    );
    let (field, reason) = field_of(&text);
    assert_eq!(field, "specimen.height");
    assert!(reason.contains("9 mm"), "{reason}");
}

#[test]
fn an_inclusion_cut_by_the_surface() {
    let text = GEL.replace(
        "support = \"bonded\"",
        &sphere_inclusion("depth = 1.0, radius = 2.0"),
    );
    let (field, reason) = field_of(&text);
    assert_eq!(field, "specimen.inclusions[0].depth");
    assert!(reason.contains("top surface"), "{reason}");
}

#[test]
fn an_inclusion_cut_by_the_base() {
    let text = GEL.replace(
        "support = \"bonded\"",
        &sphere_inclusion("depth = 9.0, radius = 2.0"),
    );
    let (field, reason) = field_of(&text);
    assert_eq!(field, "specimen.inclusions[0].depth");
    assert!(reason.contains("base"), "{reason}");
}

#[test]
fn an_inclusion_outside_the_specimen() {
    let text = GEL.replace("radius = 20.0", "radius = 3.0").replace(
        "support = \"bonded\"",
        &sphere_inclusion("depth = 5.0, radius = 3.5"),
    );
    assert_field(&text, "specimen.inclusions[0].radius");
    let text = plane(
        "inclusions = [{ shape = \"circle\", x = 148.0, depth = 15.0, radius = 5.0, material = \"tissue\" }]",
    );
    assert_field(&text, "specimen.inclusions[0].x");
    let text = block3d_with(
        "inclusions = [{ shape = \"sphere\", centre = [33.0, 0.0], depth = 20.0, radius = 4.0, material = \"gel\" }]",
        "shape = \"needle\"",
    );
    assert_field(&text, "specimen.inclusions[0].centre");
}

#[test]
fn overlapping_inclusions() {
    let text = plane(
        "inclusions = [{ shape = \"circle\", x = 70.0, depth = 15.0, radius = 5.0, material = \"tissue\" }, { shape = \"circle\", x = 78.0, depth = 15.0, radius = 5.0, material = \"tissue\" }]",
    );
    let (field, reason) = field_of(&text);
    assert_eq!(field, "specimen.inclusions[1]");
    assert!(reason.contains("specimen.inclusions[0]"), "{reason}");
}

#[test]
fn an_inclusion_of_the_wrong_shape() {
    let text = plane(
        "inclusions = [{ shape = \"sphere\", x = 70.0, depth = 15.0, radius = 5.0, material = \"tissue\" }]",
    );
    assert_field(&text, "specimen.inclusions[0].shape");
}

#[test]
fn a_wheel_on_a_cylinder() {
    let text = GEL.replace("shape = \"sphere\"", "shape = \"wheel\"");
    let (field, reason) = field_of(&text);
    assert_eq!(field, "tool.shape");
    assert!(reason.contains("plane block"), "{reason}");
}

#[test]
fn platens_on_a_3d_block() {
    assert_field(&block3d("shape = \"platens\""), "tool.shape");
}

#[test]
fn a_sphere_on_a_plane_block() {
    let text = plane("")
        .replace("shape = \"wheel\"", "shape = \"sphere\"")
        .replace(
            "path = [{ press_to = 6.0, at_x = 10.0 }, { roll_to_x = 140.0 }]",
            "",
        );
    assert_field(&text, "tool.shape");
}

#[test]
fn a_wheel_outside_the_block() {
    let text = plane("").replace("at_x = 10.0", "at_x = 160.0");
    let (field, reason) = field_of(&text);
    assert_eq!(field, "tool.path[0].at_x");
    assert!(reason.contains("[0, 150]"), "{reason}");
    let text = plane("").replace("roll_to_x = 140.0", "roll_to_x = -3.0");
    assert_field(&text, "tool.path[1].roll_to_x");
}

#[test]
fn a_wheel_that_starts_rolling() {
    let text = plane("").replace(
        "path = [{ press_to = 6.0, at_x = 10.0 }, { roll_to_x = 140.0 }]",
        "path = [{ roll_to_x = 140.0 }]",
    );
    assert_field(&text, "tool.path[0].roll_to_x");
}

#[test]
fn a_wheel_pressed_through_the_block() {
    let text = plane("").replace("press_to = 6.0", "press_to = 30.0");
    assert_field(&text, "tool.path[0].press_to");
}

#[test]
fn a_plane_block_without_thickness() {
    let text = plane("").replace("thickness = 50.0\n", "");
    assert_field(&text, "specimen.thickness");
}

#[test]
fn a_3d_block_with_a_length() {
    let text = block3d("shape = \"needle\"").replace("size = ", "length = 5.0\nsize = ");
    assert_field(&text, "specimen.length");
}

#[test]
fn a_parameter_named_twice() {
    // in one table: TOML refuses the key, with the line
    let text = GEL.replace(
        "C10 = { start = 2e-3 }",
        "C10 = { start = 2e-3 }\nC10 = 1e-3",
    );
    match Experiment::from_toml_str(&text, "gel.toml") {
        Err(FeError::ConfigFile { line, reason, .. }) => {
            let want = text.lines().position(|l| l == "C10 = 1e-3").unwrap() + 1;
            assert_eq!(line, want, "{reason}");
        }
        other => panic!("{other:?}"),
    }
    // in a parameter's table
    let err = read_err(&GEL.replace("{ start = 2e-3 }", "{ start = 2e-3, start = 1e-3 }"));
    assert!(
        err.starts_with("gel.toml:10:") && err.contains("duplicate"),
        "{err}"
    );
}

#[test]
fn a_bad_mesh_element_or_accuracy() {
    let text = GEL.to_string() + "\n[mesh]\nelement = \"hex8\"\n";
    assert_field(&text, "mesh.element");
    let text = GEL.to_string() + "\n[mesh]\naccuracy = 1.5\n";
    assert_field(&text, "mesh.accuracy");
    let text = GEL.to_string() + "\n[mesh]\naccuracy = 0.01\nlevel = 2\n";
    assert_field(&text, "mesh.level");
}

#[test]
fn a_bad_prony_series_or_bulk() {
    let text = GEL.replace(
        "C10 = { start = 2e-3 }",
        "C10 = { start = 2e-3 }\nprony = [{ g = 0.6, tau = 1.0 }, { g = 0.5, tau = 2.0 }]",
    );
    assert_field(&text, "materials.gel.prony");
    let text = GEL.replace("C10 = { start = 2e-3 }", "C10 = 2e-3\nbulk = \"soft\"");
    assert_field(&text, "materials.gel.bulk");
}

#[test]
fn a_gmsh_file_without_regions_is_named() {
    let dir = std::env::temp_dir().join(format!("palpate-exp-msh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // a 2D mesh of one triangle-free quad with only a boundary group
    let msh = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n1 1 \"top\"\n$EndPhysicalNames\n$Entities\n0 1 1 0\n1 0 1 0 1 1 0 1 1 0\n1 0 0 0 1 1 0 0 0\n$EndEntities\n$Nodes\n2 4 1 4\n1 1 0 2\n1\n2\n0 1 0\n1 1 0\n2 1 0 2\n3\n4\n0 0 0\n1 0 0\n$EndNodes\n$Elements\n2 2 1 2\n1 1 1 1\n1 1 2\n2 1 3 1\n2 1 2 4 3\n$EndElements\n";
    std::fs::write(dir.join("slice.msh"), msh).unwrap();
    let text = r#"
[specimen]
shape = "mesh"
file = "slice.msh"
kinematics = "plane_strain"
support = { group = "top", kind = "bonded" }
contact_surface = "top"

[materials.gel]
law = "neo-hookean"

[tool]
shape = "sphere"
radius = 1.0
"#;
    std::fs::write(dir.join("e.toml"), text).unwrap();
    let err = Experiment::from_toml_file(dir.join("e.toml")).unwrap_err();
    let s = err.to_string();
    assert!(s.contains("slice.msh"), "{s}");
    match err {
        FeError::InvalidConfig { field, reason } => {
            assert_eq!(field, "specimen.file", "{reason}");
            assert!(reason.contains("region"), "{reason}");
        }
        // the reader refusing the file is as good: it names the file and line
        FeError::MeshFile { file, .. } => assert!(file.ends_with("slice.msh")),
        other => panic!("{other:?}"),
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn no_mutation_of_a_preset_panics() {
    // every number of every preset replaced by values a user might mistype
    let bad = ["0", "-1", "1e9", "nan", "inf", "-inf", "0.5", "3"];
    for name in Experiment::PRESETS {
        let text = Experiment::preset_toml(name).unwrap();
        let numbers: Vec<(usize, usize)> = number_spans(text);
        for (start, end) in numbers {
            for b in bad {
                let mutated = format!("{}{}{}", &text[..start], b, &text[end..]);
                let r = std::panic::catch_unwind(|| {
                    if let Ok(e) = Experiment::from_toml_str(&mutated, "m.toml") {
                        let _ = e.to_toml();
                        let _ = e.param_space();
                    }
                });
                assert!(r.is_ok(), "panicked on\n{mutated}");
            }
        }
    }
}

/// Byte spans of the numbers outside comments.
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let code = line.split('#').next().unwrap_or("");
        let b = code.as_bytes();
        let mut i = 0;
        while i < b.len() {
            let starts = (b[i].is_ascii_digit() || b[i] == b'-')
                && (i == 0 || matches!(b[i - 1], b' ' | b'[' | b'='));
            if starts {
                let mut j = i + 1;
                while j < b.len()
                    && (b[j].is_ascii_alphanumeric() || matches!(b[j], b'.' | b'-' | b'+'))
                {
                    j += 1;
                }
                out.push((offset + i, offset + j));
                i = j;
            } else {
                i += 1;
            }
        }
        offset += line.len();
    }
    out
}

fn sphere_inclusion(fields: &str) -> String {
    format!(
        "support = \"bonded\"\ninclusions = [{{ shape = \"sphere\", {fields}, material = \"gel\" }}]"
    )
}

fn block3d(tool: &str) -> String {
    block3d_with("", tool)
}

fn block3d_with(specimen: &str, tool: &str) -> String {
    format!(
        r#"
[specimen]
shape = "block"
kinematics = "3d"
size = [70.0, 80.0, 80.0]
{specimen}

[materials.gel]
law = "neo-hookean"

[tool]
{tool}
"#
    )
}

fn plane(specimen: &str) -> String {
    format!(
        r#"
[specimen]
shape = "block"
kinematics = "plane_stress"
length = 150.0
height = 30.0
thickness = 50.0
{specimen}

[materials.tissue]
law = "arruda-boyce"

[tool]
shape = "wheel"
radius = 4.0
path = [{{ press_to = 6.0, at_x = 10.0 }}, {{ roll_to_x = 140.0 }}]
"#
    )
}

// ---- models and loadings ----

mod models {
    use super::*;
    use crate::r2::Nodule;
    use crate::{C1Fe, N3Needle, Platens, Q1Punch, R2Rolling};
    use palpate_core::{Drive, ForwardModel};
    use palpate_material::Law;

    fn model(name: &str) -> (Experiment, ExperimentModel) {
        let e = Experiment::preset(name).unwrap();
        let m = e.model().unwrap();
        assert_eq!(m.as_forward().space(), &e.param_space().unwrap(), "{name}");
        (e, m)
    }

    #[test]
    fn the_c1_presets_are_c1_s_models() {
        let rp2 = Law::ReducedPolynomial(2);
        match model("C1").1 {
            ExperimentModel::Compression(m) => {
                assert_eq!(*m.model(), C1Fe::new(rp2, Platens::Frictionless))
            }
            other => panic!("{}", other.kind()),
        }
        match model("c1-bonded").1 {
            ExperimentModel::Compression(m) => {
                assert_eq!(*m.model(), C1Fe::new(rp2, Platens::Bonded))
            }
            other => panic!("{}", other.kind()),
        }
    }

    #[test]
    fn the_q1_preset_is_q1_s_model_with_its_prony_terms_as_parameters() {
        match model("Q1").1 {
            ExperimentModel::Punch(m) => assert_eq!(
                *m.model(),
                Q1Punch::new(Law::NeoHookean).with_prony_parameters(2)
            ),
            other => panic!("{}", other.kind()),
        }
    }

    #[test]
    fn the_n3_preset_is_n3_s_model() {
        match model("N3").1 {
            ExperimentModel::Block(m) => assert_eq!(*m.model(), N3Needle::new(Law::NeoHookean)),
            other => panic!("{}", other.kind()),
        }
    }

    #[test]
    fn the_r2_presets_are_r2_s_models() {
        let ab = Law::ArrudaBoyce;
        let r2 = R2Rolling::new(ab, ab, 6.0);
        match model("R2").1 {
            ExperimentModel::Rolling(m) => assert_eq!(*m.model(), r2),
            other => panic!("{}", other.kind()),
        }
        match model("R2-1").1 {
            ExperimentModel::Rolling(m) => assert_eq!(
                *m.model(),
                r2.with_nodules(vec![Nodule {
                    x: 75.0,
                    depth: 15.0
                }])
            ),
            other => panic!("{}", other.kind()),
        }
    }

    #[test]
    fn the_n1_preset_is_n1_s_model() {
        // the same mesh and settings; the forces are compared to 1e-9 in
        // tests/integration/closed_form_experiments.rs
        let n1 = crate::N1Needle::new(Law::NeoHookean);
        match model("N1").1 {
            ExperimentModel::Cylinder(m) => {
                let m = m.model();
                assert_eq!(m.build_mesh().unwrap(), n1.build_mesh().unwrap());
                assert_eq!(
                    (m.friction, m.tool, m.base, m.element, m.bulk, m.options),
                    (
                        n1.friction,
                        n1.tool,
                        n1.base,
                        n1.element,
                        n1.bulk,
                        n1.options
                    )
                );
                assert_eq!(m.space().names(), ["C10"]);
            }
            other => panic!("{}", other.kind()),
        }
    }

    #[test]
    fn a_change_in_the_description_changes_the_setup() {
        let text = Experiment::preset_toml("N3")
            .unwrap()
            .replace("friction = 0.8", "friction = { start = 0.5 }")
            .replace("size = [70.0, 80.0, 80.0]", "size = [40.0, 50.0, 30.0]")
            .replace("element = \"hex8\"", "element = \"hex27\"");
        let e = Experiment::from_toml_str(&text, "n3.toml").unwrap();
        let ExperimentModel::Block(m) = e.model().unwrap() else {
            panic!("not N3")
        };
        assert_eq!(m.size, [20.0, 25.0, 30.0]);
        assert_eq!(m.friction, 0.5);
        assert_eq!(m.model().space().names(), ["C10", "friction"]);
        assert_eq!(m.space().names(), ["C10", "friction"]);
        assert_eq!(m.element, crate::n3::N3Element::Hex27);
        let text = Experiment::preset_toml("Q1")
            .unwrap()
            .replace("radius = 2.0", "radius = 1.0\n")
            .replace("edge_radius = 0.2", "")
            .replace("radius = 50.0", "radius = 20.0")
            .replace("height = 60.0", "height = 10.0")
            .replace("ramp_to = 5.0", "ramp_to = 2.0");
        let e = Experiment::from_toml_str(&text, "q1.toml").unwrap();
        let ExperimentModel::Punch(m) = e.model().unwrap() else {
            panic!("not Q1")
        };
        assert_eq!(
            (m.punch_radius, m.edge_radius, m.radius, m.height),
            (1.0, 0.1, 20.0, 10.0)
        );
    }

    #[test]
    fn what_no_setup_models_is_named() {
        let text = Experiment::preset_toml("N3")
            .unwrap()
            .replace("friction = 0.8", "friction = 0.8\nat = [5.0, 0.0]");
        let e = Experiment::from_toml_str(&text, "n3.toml").unwrap();
        match e.model() {
            Err(FeError::InvalidConfig { field, .. }) => assert_eq!(field, "tool.at"),
            other => panic!("{:?}", other.map(|m| m.kind())),
        }
        let text = Experiment::preset_toml("R2")
            .unwrap()
            .replace("plane_stress", "plane_strain");
        let e = Experiment::from_toml_str(&text, "r2.toml").unwrap();
        match e.model() {
            Err(FeError::InvalidConfig { field, .. }) => assert_eq!(field, "specimen.kinematics"),
            other => panic!("{:?}", other.map(|m| m.kind())),
        }
    }

    #[test]
    fn the_protocols_loadings() {
        let l = Experiment::preset("N1")
            .unwrap()
            .loading()
            .unwrap()
            .unwrap();
        assert_eq!(l.drive_kind, Drive::DisplacementMm);
        assert_eq!(l.len(), 41);
        assert!((l.drive[1] - 0.25).abs() < 1e-12 && l.drive[40] == 10.0);
        assert!(l.time.is_none());
        let l = Experiment::preset("Q1")
            .unwrap()
            .loading()
            .unwrap()
            .unwrap();
        assert_eq!(l.len(), 301);
        let t = l.time.as_ref().unwrap();
        assert_eq!((t[100], l.drive[100]), (0.5, 5.0));
        assert_eq!((t[300], l.drive[300]), (60.5, 5.0));
        assert!(l.validate().is_ok());
        let l = Experiment::preset("R2")
            .unwrap()
            .loading()
            .unwrap()
            .unwrap();
        assert_eq!(l.drive_kind, Drive::PositionMm);
        assert_eq!(l.len(), 261);
        assert_eq!((l.drive[0], l.drive[1], l.drive[260]), (10.0, 10.5, 140.0));
        let mut e = Experiment::preset("C1").unwrap();
        e.protocol.segments.clear();
        e.protocol.samples = None;
        assert_eq!(e.loading().unwrap(), None);
    }
}

#[test]
fn a_gmsh_specimen_is_checked_against_its_groups_and_not_built_yet() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/inclusion_quad4.msh"
    );
    let text = format!(
        r#"
[specimen]
shape = "mesh"
file = "{file}"
kinematics = "plane_strain"
support = {{ group = "bottom", kind = "bonded" }}
contact_surface = "top"

[materials.matrix]
law = "neo-hookean"

[materials.inclusion]
law = "neo-hookean"

[tool]
shape = "sphere"
radius = 0.2
"#
    );
    let e = Experiment::from_toml_str(&text, "slice.toml").unwrap();
    match e.model() {
        Err(FeError::InvalidConfig { field, reason }) => {
            assert_eq!(field, "specimen.file");
            assert!(
                reason.contains("inclusion_quad4.msh") && reason.contains("not supported"),
                "{reason}"
            );
        }
        other => panic!("{:?}", other.map(|m| m.kind())),
    }
    let (field, reason) = field_of_named(&text.replace("\"top\"", "\"lid\""), "slice.toml");
    assert_eq!(field, "specimen.contact_surface", "{reason}");
    assert!(reason.contains("top"), "{reason}");
    let (field, reason) = field_of_named(
        &text.replace("[materials.inclusion]", "[materials.tumour]"),
        "slice.toml",
    );
    assert_eq!(field, "materials.tumour", "{reason}");
    assert!(reason.contains("inclusion_quad4.msh"), "{reason}");
    let (field, _) = field_of_named(&text.replace("plane_strain", "3d"), "slice.toml");
    assert_eq!(field, "specimen.kinematics");
}

fn field_of_named(text: &str, file: &str) -> (String, String) {
    match Experiment::from_toml_str(text, file) {
        Err(FeError::InvalidConfig { field, reason }) => (field, reason),
        other => panic!("expected InvalidConfig, got {other:?}"),
    }
}
