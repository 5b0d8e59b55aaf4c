//! What the bad-input suites share: running the built binary in a scratch
//! folder, and the two verdicts (refused cleanly with the locator, accepted).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn palpate_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_palpate"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run palpate")
}

pub fn treloar(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/treloar")
        .join(name)
        .display()
        .to_string()
}

/// A temporary folder with files in it.
pub struct Scratch(pub tempfile::TempDir);

impl Scratch {
    pub fn new() -> Scratch {
        Scratch(tempfile::tempdir().unwrap())
    }
    pub fn path(&self, name: &str) -> PathBuf {
        self.0.path().join(name)
    }
    pub fn file(&self, name: &str, text: &str) -> String {
        let p = self.path(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    }
    pub fn run(&self, args: &[&str]) -> Output {
        palpate_in(self.0.path(), args)
    }
}

/// With `BAD_INPUT_LOG=FILE` set, each verdict appends a line to FILE, so
/// the suite's cases can be counted (docs/validation/reliability.md).
#[track_caller]
fn log_case(verdict: &str) {
    if let Some(path) = std::env::var_os("BAD_INPUT_LOG") {
        use std::io::Write;
        let at = std::panic::Location::caller();
        if let Ok(mut f) = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
        {
            let _ = writeln!(f, "{verdict} {}:{}", at.file(), at.line());
        }
    }
}

/// Fails cleanly (non-zero exit, no panic) with every needle in stderr.
#[track_caller]
pub fn refused(o: &Output, needles: &[&str]) {
    log_case("refused");
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "exit 0 for bad input; stderr: {e}");
    assert_ne!(o.status.code(), None, "killed by a signal: {e}");
    assert!(!e.contains("panicked"), "panic: {e}");
    for n in needles {
        assert!(e.contains(n), "`{n}` not in: {e}");
    }
}

#[track_caller]
pub fn accepted(o: &Output) {
    log_case("accepted");
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{e}");
}

/// The forces of the experiment description `text` at `theta` on the
/// displacements `depths` (mm).
pub fn experiment_forces(text: &str, theta: &[f64], depths: &[f64]) -> Vec<f64> {
    let e: palpate_fe::experiment::Experiment =
        toml::from_str(text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    e.model()
        .unwrap()
        .as_forward()
        .predict(
            theta,
            &palpate_core::Loading::quasi_static(
                palpate_core::Drive::DisplacementMm,
                depths.to_vec(),
            ),
        )
        .unwrap()
}

/// A record `displacement_mm,force_N` of the description `text` at
/// `theta` on the depths, with Gaussian noise of `noise` times the largest
/// force (seeded).
pub fn experiment_record(
    text: &str,
    theta: &[f64],
    depths: &[f64],
    noise: f64,
    seed: u64,
) -> String {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    let f = experiment_forces(text, theta, depths);
    let top = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    let normal = Normal::new(0.0, noise * top).unwrap();
    let mut csv = String::from("displacement_mm,force_N\n");
    for (d, f) in depths.iter().zip(&f) {
        csv += &format!("{d},{:.12e}\n", f + normal.sample(&mut rng));
    }
    csv
}
