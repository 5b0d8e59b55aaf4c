//! `palpate diagnose --experiment FILE --data force=RECORD.csv` end to end:
//! the base is the description's FE model and the candidates are the
//! effects it offers. A synthetic sphere record of a bonded gel layer
//! 10 mm thick, diagnosed with a description of a specimen 40 mm thick
//! (as a lab that took its disc for a large block would write it), names
//! `boundary_condition` with the fitted thickness near 10 mm, not
//! `material_form`; with the right description the verdict is `none`.
//! Coarse meshes (4-node elements at level 1) and a 0.8 mm record; every
//! candidate is fitted by FE runs (the thickness by finite differences),
//! so the two tests are ignored by default. Measured: the thickness
//! 9.73 +- 0.88 mm for the planted 10 mm, `material_form` second (misfit
//! 1.08 x noise against 0.77).

use std::path::Path;
use std::process::{Command, Output};

fn palpate(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_palpate"))
        .args(args)
        .output()
        .expect("run palpate")
}

/// A 2.5 mm sphere on the axis of a bonded gel cylinder 20 mm in radius
/// and `height` mm high, neo-Hookean (C10 fitted), meshed coarse.
fn gel(height: f64) -> String {
    format!(
        "[specimen]\nshape = \"cylinder\"\nradius = 20.0\nheight = {height}\nsupport = \"bonded\"\n\n\
         [materials.gel]\nlaw = \"neo-hookean\"\nC10 = {{ start = 2e-3 }}\n\n\
         [tool]\nshape = \"sphere\"\nradius = 2.5\n\n\
         [mesh]\nlevel = 1\nelement = \"quad4\"\n"
    )
}

const DEPTH: f64 = 0.8;
const SAMPLES: usize = 20;

/// The record `displacement_mm,force_N` of `text` (its protocol a ramp to
/// [`DEPTH`], the mesh a fit of such a record gets) at `theta`, with
/// Gaussian noise of `noise` times the largest force (seeded).
fn record(text: &str, theta: &[f64], noise: f64, seed: u64) -> String {
    let text = format!("{text}\n[protocol]\nsegments = [{{ ramp_to = {DEPTH} }}]\n");
    let depths: Vec<f64> = (1..=SAMPLES)
        .map(|k| DEPTH * k as f64 / SAMPLES as f64)
        .collect();
    crate::common::experiment_record(&text, theta, &depths, noise, seed)
}

/// `palpate diagnose --experiment` on `description` and `record` in
/// `dir`; the JSON it writes.
fn diagnose(dir: &Path, description: &str, record: &str, extra: &[&str]) -> serde_json::Value {
    let (file, data, json) = (
        dir.join("experiment.toml"),
        dir.join("record.csv"),
        dir.join("gap.json"),
    );
    std::fs::write(&file, description).unwrap();
    std::fs::write(&data, record).unwrap();
    let mut args = vec![
        "diagnose",
        "--experiment",
        file.to_str().unwrap(),
        "--data",
        data.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let t = std::time::Instant::now();
    let o = palpate(&args);
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert!(o.status.success(), "diagnose failed:\n{out}\n{err}");
    eprintln!("{out}\n({:.1} s)", t.elapsed().as_secs_f64());
    serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap()
}

const TRUTH: f64 = 5.0e-3;
const THICKNESS: f64 = 10.0;

/// The 10 mm layer diagnosed as a 40 mm block: the layer's thickness is
/// the candidate that explains the stiffening, and it is found.
#[test]
#[ignore = "a diagnosis of four FE candidates with sets: 195-285 s wall on a loaded 2-core machine; the mechanism's fast test is experiment_thickness.rs; run: cargo test -p palpate-studies --test integration experiment_diagnose:: -- --ignored"]
fn a_thin_layer_taken_for_a_thick_block_is_its_boundary_condition() {
    let rec = record(&gel(THICKNESS), &[TRUTH], 0.005, 11);
    let dir = tempfile::tempdir().unwrap();
    let gap = diagnose(dir.path(), &gel(40.0), &rec, &[]);
    assert_eq!(gap["verdict"], "boundary_condition", "{gap:#}");
    let best = &gap["ranking"][0];
    let h = best["params"]["thickness_mm"].as_f64().unwrap();
    assert!(
        (h - THICKNESS).abs() < 0.15 * THICKNESS,
        "fitted thickness {h} mm, planted {THICKNESS} mm"
    );
}

/// The same record with the right description: nothing to explain.
#[test]
#[ignore = "a diagnosis of four FE candidates with sets: 195-285 s wall on a loaded 2-core machine; the mechanism's fast test is experiment_thickness.rs; run: cargo test -p palpate-studies --test integration experiment_diagnose:: -- --ignored"]
fn the_layer_with_its_own_thickness_has_no_gap() {
    let rec = record(&gel(THICKNESS), &[TRUTH], 0.005, 11);
    let dir = tempfile::tempdir().unwrap();
    let gap = diagnose(dir.path(), &gel(THICKNESS), &rec, &[]);
    assert_eq!(gap["verdict"], "none", "{gap:#}");
}
