//! Properties of the study-manifest reader (`Manifest::parse` and
//! `validate`) and of the data-file reader behind it, on generated input:
//!
//! * arbitrary bytes, and a good manifest with random damage, never panic:
//!   they are read or refused with an error that names the manifest, and a
//!   TOML error names a line inside the file;
//! * a generated valid manifest reads back to what was written;
//! * a data file of arbitrary bytes is read or refused naming the file.

use palpate_studies::records::{TestData, TestKind};
use palpate_studies::steps::calibrate::CalibrateStep;
use palpate_studies::study::manifest::{
    DataSpec, Manifest, ModelEntry, ModelForm, StepEntry, StudyMeta,
};
use proptest::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;

const GOOD: &str = r#"[study]
name = "t"
description = "a study"
seed = 3

[data.uni]
file = "x.csv"
test = "uniaxial"

[models.nh]
law = "neo-hookean"

[models.mr]
law = "mooney-rivlin"
fixed = { C01 = 0.0 }

[[steps]]
[steps.calibrate]
name = "fit"
models = ["nh", "mr"]
fits = { u = ["uni"] }
residuals = ["absolute", "relative"]
"#;

/// The line a TOML error names ("... at line N, column M").
fn toml_line(message: &str) -> Option<usize> {
    let at = message.find("at line ")?;
    let digits: String = message[at + 8..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    digits.parse().ok()
}

/// Parses and (if it parses) validates `text` as the manifest `dir/s.toml`;
/// checks what every error must carry.
fn check_any(dir: &Path, text: &str) -> Result<(), TestCaseError> {
    let path = dir.join("s.toml");
    let lines = text.lines().count().max(1);
    match Manifest::parse(&path, text) {
        Err(e) => {
            let m = e.to_string();
            prop_assert!(m.contains("s.toml"), "no manifest name: {m}");
            if let Some(l) = toml_line(&m) {
                prop_assert!(l >= 1 && l <= lines + 1, "line {l} of {lines}: {m}");
            }
        }
        Ok(manifest) => {
            if let Err(e) = manifest.validate(&path) {
                let m = e.to_string();
                prop_assert!(m.contains("s.toml"), "no manifest name: {m}");
            }
        }
    }
    Ok(())
}

fn data_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("x.csv"),
        "stretch,stress_MPa\n1,0\n1.5,0.2\n",
    )
    .unwrap();
    dir
}

/// A damaged copy of a text: characters deleted, duplicated or replaced.
fn damaged() -> impl Strategy<Value = String> {
    proptest::collection::vec(
        (
            any::<prop::sample::Index>(),
            0u8..4,
            prop_oneof![
                Just('"'),
                Just('['),
                Just(']'),
                Just('='),
                Just('\n'),
                Just(','),
                Just('0'),
                Just('-'),
                Just('x'),
                Just('{'),
                any::<char>()
            ],
        ),
        1..8,
    )
    .prop_map(|edits| {
        let mut chars: Vec<char> = GOOD.chars().collect();
        for (at, what, c) in edits {
            if chars.is_empty() {
                break;
            }
            let i = at.index(chars.len());
            match what {
                0 => {
                    chars.remove(i);
                }
                1 => chars.insert(i, chars[i]),
                2 => chars[i] = c,
                _ => chars.insert(i, c),
            }
        }
        chars.into_iter().collect()
    })
}

fn name() -> impl Strategy<Value = String> {
    "[a-z][a-z0-9_-]{0,8}"
}

/// A valid manifest as values.
fn manifest() -> impl Strategy<Value = Manifest> {
    (
        name(),
        "[ -~]{0,30}",
        any::<u64>(),
        proptest::collection::btree_map(
            name(),
            prop_oneof![
                Just("uniaxial"),
                Just("biaxial"),
                Just("planar"),
                Just("C1"),
                Just("N1")
            ],
            1..4,
        ),
        proptest::collection::btree_map(
            name(),
            (
                prop_oneof![
                    Just("neo-hookean"),
                    Just("mooney-rivlin"),
                    Just("yeoh"),
                    Just("ogden:2"),
                    Just("arruda-boyce"),
                    Just("reduced-polynomial:4"),
                ],
                proptest::option::of(-1e3f64..1e3),
            ),
            1..4,
        ),
        1usize..4,
        proptest::sample::subsequence(vec!["absolute", "relative", "normalised"], 1..=3),
        prop_oneof![Just("lm"), Just("bfgs"), Just("lbfgs")],
    )
        .prop_map(
            |(study, description, seed, data, models, steps, residuals, estimator)| {
                let data: BTreeMap<String, DataSpec> = data
                    .into_iter()
                    .map(|(n, t)| {
                        (
                            n.clone(),
                            DataSpec {
                                file: format!("data/{n}.csv").into(),
                                test: t.to_string(),
                                weight: None,
                                axial_stretch: None,
                                stress_unit: None,
                                ..DataSpec::default()
                            },
                        )
                    })
                    .collect();
                let models: BTreeMap<String, ModelEntry> = models
                    .into_iter()
                    .map(|(n, (law, fixed))| {
                        let fixed = fixed.map(|v| ("C01".to_string(), v)).into_iter().collect();
                        (
                            n,
                            ModelEntry {
                                model: ModelForm::Law(law.to_string()),
                                fixed,
                                viscoelastic: None,
                            },
                        )
                    })
                    .collect();
                let sets: Vec<String> = data.keys().cloned().collect();
                let steps = (0..steps)
                    .map(|k| {
                        StepEntry::Calibrate(CalibrateStep {
                            name: format!("step-{k}"),
                            models: models.keys().cloned().collect(),
                            fits: [("all".to_string(), sets.clone())].into_iter().collect(),
                            residuals: residuals.iter().map(|r| r.to_string()).collect(),
                            estimator: estimator.to_string(),
                            predict: sets[..1].to_vec(),
                        })
                    })
                    .collect();
                Manifest {
                    study: StudyMeta {
                        name: study,
                        description,
                        seed,
                    },
                    data,
                    models,
                    experiments: Default::default(),
                    steps,
                }
            },
        )
}

/// The manifest written as TOML, as a user would.
fn to_toml(m: &Manifest) -> String {
    let q = |s: &str| toml::Value::String(s.to_string()).to_string();
    let list = |v: &[String]| {
        let items: Vec<String> = v.iter().map(|s| q(s)).collect();
        format!("[{}]", items.join(", "))
    };
    let mut t = format!(
        "[study]\nname = {}\ndescription = {}\nseed = {}\n\n",
        q(&m.study.name),
        q(&m.study.description),
        m.study.seed
    );
    for (n, d) in &m.data {
        t += &format!(
            "[data.{}]\nfile = {}\ntest = {}\n\n",
            q(n),
            q(&d.file.display().to_string()),
            q(&d.test)
        );
    }
    for (n, e) in &m.models {
        t += &format!("[models.{}]\nlaw = {}\n", q(n), q(e.law_text()));
        for (p, v) in &e.fixed {
            t += &format!("fixed = {{ {p} = {v:?} }}\n");
        }
        t += "\n";
    }
    for s in &m.steps {
        let StepEntry::Calibrate(c) = s else { continue };
        let fits: Vec<String> = c
            .fits
            .iter()
            .map(|(g, sets)| format!("{} = {}", q(g), list(sets)))
            .collect();
        t += &format!(
            "[[steps]]\n[steps.calibrate]\nname = {}\nmodels = {}\nfits = {{ {} }}\nresiduals = {}\nestimator = {}\npredict = {}\n\n",
            q(&c.name),
            list(&c.models),
            fits.join(", "),
            list(&c.residuals),
            q(&c.estimator),
            list(&c.predict)
        );
    }
    t
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        let dir = data_dir();
        check_any(dir.path(), &String::from_utf8_lossy(&bytes))?;
    }

    #[test]
    fn a_damaged_manifest_is_refused_by_its_line_or_read(text in damaged()) {
        let dir = data_dir();
        check_any(dir.path(), &text)?;
    }

    #[test]
    fn a_valid_manifest_reads_back_to_what_was_written(m in manifest()) {
        let text = to_toml(&m);
        let back = Manifest::parse(Path::new("s.toml"), &text)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(format!("{:?}", back), format!("{:?}", m), "{}", text);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn a_data_file_of_arbitrary_bytes_is_read_or_named(
        bytes in proptest::collection::vec(any::<u8>(), 0..300),
        test in prop_oneof![Just("uniaxial"), Just("C1")],
    ) {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("d.csv");
        std::fs::write(&f, &bytes).unwrap();
        let kind = TestKind::parse(test).unwrap();
        if let Err(e) = TestData::read("d", kind, &f) {
            let m = format!("{e:#}");
            prop_assert!(m.contains("d.csv"), "{m}");
        }
    }
}
