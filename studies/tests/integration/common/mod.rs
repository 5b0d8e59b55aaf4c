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
