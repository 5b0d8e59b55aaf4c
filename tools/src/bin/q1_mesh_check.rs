//! The mesh check of a stored Q1 estimate (`palpate calibrate --benchmark Q1
//! ... --mesh-check MM` without refitting the stages): the 5 mm record's
//! polish corrected to a mesh of `MM` from `THETA`, round by round, with
//! the fit mesh of the manifest `studies/two-stage-q1-5mm.toml` (0.3 mm,
//! punch edge 0.6 mm) and its standard errors `SE` (comma-separated, as
//! THETA):
//!
//!   cargo run --release -p palpate-tools --bin q1_mesh_check -- \
//!       0.06666666666666667 0.0015885,0.31586,0.41229,0.19992,9.6813 \
//!       1.16e-5,7.56e-3,2.85e-2,7.36e-3,1.02 [ROUNDS]
use palpate_material::Law;
use palpate_studies::apps::two_stage::mesh_check::{check_estimate, report};
use palpate_studies::apps::two_stage::{Q1Record, TwoStageOptions};

fn list(s: &str) -> Vec<f64> {
    s.split(',').map(|x| x.parse().expect("a number")).collect()
}

fn main() -> anyhow::Result<()> {
    let a: Vec<String> = std::env::args().collect();
    anyhow::ensure!(a.len() >= 4, "usage: q1_mesh_check MM THETA SE [ROUNDS]");
    let h: f64 = a[1].parse()?;
    let theta = list(&a[2]);
    let se: Vec<Option<f64>> = list(&a[3]).into_iter().map(Some).collect();
    let mut o = TwoStageOptions::new(Law::NeoHookean);
    o.set_correct_mesh(0.1).map_err(anyhow::Error::msg)?;
    o.set_fit_edge_radius(0.6).map_err(anyhow::Error::msg)?;
    o.set_mesh_check(h).map_err(anyhow::Error::msg)?;
    if let Some(r) = a.get(4) {
        o.correction_rounds = r.parse()?;
    }
    let record = Q1Record::read(&palpate_tools::repo(
        "tests/data/two-stage-q1-5mm/record.csv",
    ))?;
    let check = check_estimate(&record, &o, &theta, &se, &|s| eprintln!("{s}"))?;
    let names: Vec<String> = ["C10", "g1", "tau1_s", "g2", "tau2_s"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    println!("{}", report(&check, &names, Some(0.1)));
    println!("{}", serde_json::to_string(&check)?);
    Ok(())
}
