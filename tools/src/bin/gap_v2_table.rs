//! Diagnoses the C1 development records of `tests/data/gap-v2/` (written by
//! `make_gap_v2`) and the gap-dev cases under the stratified folds of v2 and
//! under the contiguous blocks of v1, and prints a table: verdict, misfit /
//! noise before and after the best effect, immaterial and undetectable
//! effects, and the time per record.
//!
//! `cargo run --release -p palpate-tools --bin gap_v2_table`

use palpate_analytic::C1Compression;
use palpate_core::{Drive, Loading, Table};
use palpate_material::Law;
use palpate_uq::gap::{diagnose, FoldLayout, GapOptions};
use std::time::Instant;

fn main() {
    let mut files: Vec<(String, std::path::PathBuf, String)> = Vec::new();
    for (dir, truth) in [
        (palpate_tools::repo("tests/data/gap-v2"), "truth.json"),
        (palpate_tools::repo("studies/data/gap-dev/c1"), "truth.json"),
    ] {
        let Ok(text) = std::fs::read_to_string(dir.join(truth)) else {
            continue;
        };
        let t: serde_json::Value = serde_json::from_str(&text).expect("truth.json");
        for (name, case) in t.as_object().expect("object") {
            if case["benchmark"].as_str() == Some("N1") {
                continue;
            }
            let expected = case["expected"].as_str().unwrap_or("?").to_string();
            files.push((name.clone(), dir.join(format!("{name}.csv")), expected));
        }
    }
    let base = C1Compression::new(Law::NeoHookean);
    println!(
        "| record | expected | layout | verdict | misfit/noise before -> after | immaterial | undetectable (C10 at ends) | s |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for (name, path, expected) in &files {
        let table = Table::read(path).expect("record");
        let d = table.column("displacement_mm").unwrap().to_vec();
        let f = table.column("force_N").unwrap().to_vec();
        let loading = match table.column("time_s") {
            Ok(t) => Loading::timed(Drive::DisplacementMm, t.to_vec(), d),
            Err(_) => Loading::quasi_static(Drive::DisplacementMm, d),
        };
        for layout in [FoldLayout::Stratified, FoldLayout::Contiguous] {
            let options = GapOptions {
                fold_layout: layout,
                ..GapOptions::default()
            };
            let start = Instant::now();
            let r = diagnose(&base, &loading, &f, &options).expect("diagnosis");
            let secs = start.elapsed().as_secs_f64();
            let best = r.ranking.first();
            let immaterial: Vec<&str> = r.immaterial.iter().map(|e| e.name()).collect();
            let undetectable: Vec<String> = r
                .undetectable
                .iter()
                .map(|u| {
                    let c10 = u.base_params["C10"];
                    format!("{} {:.3e}..{:.3e}", u.effect, c10[0], c10[1])
                })
                .collect();
            println!(
                "| {name} | {expected} | {layout:?} | {}{} | {} | {} | {} | {secs:.1} |",
                r.verdict,
                if r.partly_explained.is_some() {
                    " (partly)"
                } else {
                    ""
                },
                best.map_or(String::new(), |b| format!(
                    "{} {:.3} -> {:.3} (held-out gain {:.1}, earns {})",
                    b.effect,
                    b.practical.misfit_over_noise_before,
                    b.practical.misfit_over_noise_after,
                    b.heldout_gain,
                    b.earns
                )),
                immaterial.join(", "),
                undetectable.join(", ")
            );
        }
    }
}
