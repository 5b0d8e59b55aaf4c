//! Cost and answers of the gap diagnosis with explanations made of several
//! effects, on the two-effect development records of
//! `studies/data/gap-dev2/` (goal: a C1 or homogeneous diagnosis in under
//! 2 s of CPU). Diagnoses the records one after the other and prints, for
//! each, the planted set, the explanation, the remainder over the noise and
//! the CPU seconds of that diagnosis (user + system of the process,
//! `/proc/self/stat`, all threads).
//!
//! `cargo run -p palpate-tests --example bench_gap_sets [-- PREFIX]`
//! (PREFIX: `c1-`, `uni-`, `null-`; default all).

use palpate_analytic::{C1Compression, Homogeneous, Mode};
use palpate_core::{Drive, ForwardModel, Loading, Table};
use palpate_material::Law;
use palpate_uq::gap::{diagnose, GapOptions};
use std::path::Path;
use std::time::Instant;

fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let fields: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/data/gap-dev2");
    let prefix = std::env::args().nth(1).unwrap_or_default();
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("truth.json")).expect("truth"))
            .expect("truth.json");
    let mut names: Vec<&String> = truth
        .as_object()
        .expect("object")
        .keys()
        .filter(|k| k.starts_with(&prefix))
        .collect();
    names.sort();
    let (mut right, mut cpu_total, mut cpu_max) = (0, 0.0, 0.0f64);
    println!("record,planted,explanation,remainder_over_noise,cpu_s,wall_s[,form]");
    for name in &names {
        let table = Table::read(dir.join(format!("{name}.csv"))).expect("record");
        let t = table.column("time_s").expect("time").to_vec();
        let (base, loading, y): (Box<dyn ForwardModel>, Loading, Vec<f64>) =
            match table.column("stretch") {
                Ok(s) => (
                    Box::new(Homogeneous::new(Law::NeoHookean, Mode::Uniaxial)),
                    Loading::timed(Drive::Stretch, t, s.to_vec()),
                    table.column("stress_MPa").expect("stress").to_vec(),
                ),
                Err(_) => (
                    Box::new(C1Compression::new(Law::NeoHookean)),
                    Loading::timed(
                        Drive::DisplacementMm,
                        t,
                        table.column("displacement_mm").expect("d").to_vec(),
                    ),
                    table.column("force_N").expect("force").to_vec(),
                ),
            };
        let (cpu0, wall0) = (cpu_seconds(), Instant::now());
        let r = diagnose(base.as_ref(), &loading, &y, &GapOptions::default()).expect("diagnosis");
        let (cpu, wall) = (cpu_seconds() - cpu0, wall0.elapsed().as_secs_f64());
        let mut planted: Vec<String> = truth[name.as_str()]["expected"]
            .as_array()
            .expect("expected")
            .iter()
            .map(|e| e.as_str().unwrap_or("").to_string())
            .collect();
        planted.sort();
        let mut found: Vec<String> = r
            .explanation_set
            .iter()
            .map(|m| m.effect.name().to_string())
            .collect();
        found.sort();
        if found == planted {
            right += 1;
        }
        cpu_total += cpu;
        cpu_max = cpu_max.max(cpu);
        let forms: Vec<String> = r
            .explanation_set
            .iter()
            .filter_map(|m| m.form.clone())
            .collect();
        println!(
            "{name},{},{},{:.2},{cpu:.2},{wall:.2}{}",
            planted.join("+"),
            found.join("+"),
            r.remainder.misfit_over_noise,
            if forms.is_empty() {
                String::new()
            } else {
                format!(",form {}", forms.join(" "))
            }
        );
    }
    println!(
        "# {right} of {} right; CPU per diagnosis: mean {:.2} s, max {cpu_max:.2} s",
        names.len(),
        cpu_total / names.len().max(1) as f64
    );
}
