//! The synthetic C1 record of the MCMC validation
//! (`docs/validation/mcmc_c1_rp2_data.csv`, written by `tests/integration/mcmc_c1.rs`),
//! shared by the MCMC tests and `examples/bench_samplers.rs`.

use palpate_core::{Drive, Loading, Table};
use std::path::{Path, PathBuf};

/// Path of the record.
pub fn c1_rp2_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/validation/mcmc_c1_rp2_data.csv")
}

/// The record: loading (displacement), forces (N) and the noise SD of its
/// `sigma_N = ...` comment line.
pub fn c1_rp2_record() -> (Loading, Vec<f64>, f64) {
    let t = Table::read(c1_rp2_path()).expect("MCMC data file");
    let sigma: f64 = t
        .comments
        .iter()
        .find_map(|c| {
            c.split_once("sigma_N = ")
                .and_then(|(_, v)| v.trim().parse().ok())
        })
        .expect("a `sigma_N = ` comment");
    let d = t
        .column("displacement_mm")
        .expect("displacement_mm")
        .to_vec();
    let f = t.column("force_N").expect("force_N").to_vec();
    (Loading::quasi_static(Drive::DisplacementMm, d), f, sigma)
}
