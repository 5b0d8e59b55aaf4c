//! The `localize` step of a study: the R2 tumour-localisation analysis
//! (`crate::localize`) at each rolling depth.
//!
//! ```toml
//! [[steps]]
//! [steps.localize]
//! name = "r2"
//! rds = [3, 6]
//! nodules = "37.5:10,75:15,112.5:20"   # the record's nodules (default R2's)
//! record_h_mm = 1.5                    # its FE mesh, finer than the surrogate's 2 mm
//! record_step_mm = 1.0
//! noise = 0.01                         # Gaussian noise SD, x the record's peak force
//! ```
//!
//! Per RD: the localisation model (surrogate + nodule-free pass, from the
//! surrogate cache, built on a miss), the FE record of the nodules at the
//! finer mesh (cached likewise) with seeded noise, the posterior; written
//! as `<name>-rd<RD>.json` (the `palpate localize --json` form),
//! `<name>-rd<RD>.svg` (force against position with the fit, the true and
//! located nodules, and each nodule's posterior) and report rows; plus the
//! peak force against depth of one nodule (R2-1, the scan surrogate at
//! offset 0) and the quadratic depth = a F^2 + b F + c per RD (Table III).

use crate::cli::localize::plot_svg;
use crate::localize::posterior::{localize, LocOptions};
use crate::localize::record::Record;
use crate::localize::{LocModel, LocSetup};
use crate::manifest::Manifest;
use crate::output::{write_atomic, write_json};
use crate::runner::{Run, StepResult};
use crate::surrogate::{default_cache_dir, load_or_compute};
use palpate_fe::r2::check_model;
use palpate_fe::{Nodule, R2Rolling};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use serde::Deserialize;
use std::fmt::Write;
use std::path::PathBuf;

fn default_nodules() -> String {
    "37.5:10,75:15,112.5:20".into()
}
fn default_h() -> f64 {
    1.5
}
fn default_step() -> f64 {
    1.0
}
fn default_noise() -> f64 {
    0.01
}

/// R2-1's depths (BENCHMARKS.md).
pub const R2_1_DEPTHS: [f64; 8] = [8.0, 10.0, 12.0, 15.0, 18.0, 20.0, 22.0, 24.0];

/// `[steps.localize]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LocalizeStep {
    pub name: String,
    /// Rolling depths (mm), one analysis each.
    pub rds: Vec<f64>,
    #[serde(default = "default_nodules")]
    pub nodules: String,
    #[serde(default = "default_h")]
    pub record_h_mm: f64,
    #[serde(default = "default_step")]
    pub record_step_mm: f64,
    #[serde(default = "default_noise")]
    pub noise: f64,
    /// Surrogate cache folder (default: as `palpate localize`).
    #[serde(default)]
    pub cache: Option<PathBuf>,
}

impl LocalizeStep {
    fn record_model(&self, rd: f64) -> Result<R2Rolling, String> {
        let nodules = Nodule::parse_list(&self.nodules).map_err(|e| format!("nodules: {e}"))?;
        let mut m = R2Rolling::new(
            palpate_material::Law::ArrudaBoyce,
            palpate_material::Law::ArrudaBoyce,
            rd,
        )
        .with_nodules(nodules);
        m.element_size = Some(self.record_h_mm);
        check_model(&m).map_err(|(f, r)| {
            if f == "rd" {
                format!("rds: {rd}: {r}")
            } else {
                format!("{f}: {r}")
            }
        })?;
        Ok(m)
    }

    /// Checks the step (step `i`); errors name the manifest and the field.
    pub fn validate(&self, _m: &Manifest, i: usize, where_: &str) -> anyhow::Result<()> {
        let at = format!("{where_}: steps[{i}].localize (\"{}\")", self.name);
        anyhow::ensure!(!self.rds.is_empty(), "{at}.rds = []: give at least one RD");
        anyhow::ensure!(
            self.record_h_mm > 0.0 && self.record_h_mm.is_finite() && self.record_h_mm <= 30.0,
            "{at}.record_h_mm = {}: an element size in (0, 30] mm",
            self.record_h_mm
        );
        anyhow::ensure!(
            self.record_step_mm >= 0.1 && self.record_step_mm <= 10.0,
            "{at}.record_step_mm = {}: a spacing in [0.1, 10] mm",
            self.record_step_mm
        );
        anyhow::ensure!(
            self.noise >= 0.0 && self.noise <= 0.5,
            "{at}.noise = {}: a fraction of the peak force in [0, 0.5]",
            self.noise
        );
        for &rd in &self.rds {
            LocSetup::r2(rd)
                .check()
                .map_err(|(_, r)| anyhow::anyhow!("{at}.rds: {rd}: {r}"))?;
            let m = self
                .record_model(rd)
                .map_err(|e| anyhow::anyhow!("{at}.{e}"))?;
            anyhow::ensure!(
                !m.nodules.is_empty() && m.nodules.len() <= 8,
                "{at}.nodules: give 1 to 8 nodules"
            );
        }
        Ok(())
    }
}

/// Runs the step.
pub(crate) fn run_localize(
    run: &Run,
    step: &LocalizeStep,
    report: &mut String,
) -> anyhow::Result<StepResult> {
    let cache = step.cache.clone().unwrap_or_else(default_cache_dir);
    let mut results = Vec::new();
    let _ = writeln!(report, "## Localisation `{}`\n", step.name);
    let _ = writeln!(
        report,
        "FE records of the nodules `{}` at h = {} mm every {} mm, Gaussian noise SD {} % of the peak force (seed {}); posterior on the localisation model (studies/src/localize).\n",
        step.nodules,
        step.record_h_mm,
        step.record_step_mm,
        100.0 * step.noise,
        run.manifest.study.seed
    );
    let _ = writeln!(
        report,
        "| RD mm | nodule (true x:depth) | x mm mean [94 % HDI] | depth mm mean [94 % HDI] | identifiable | R-hat max | posterior s |\n|---|---|---|---|---|---|---|"
    );
    let mut table3 = String::from(
        "\nPeak force of one nodule against depth (R2-1, the scan surrogate at offset 0), and depth = a F^2 + b F + c:\n\n| RD mm |",
    );
    for d in R2_1_DEPTHS {
        let _ = write!(table3, " {d} mm |");
    }
    table3.push_str(" a | b | c |\n|---|");
    for _ in 0..R2_1_DEPTHS.len() + 3 {
        table3.push_str("---|");
    }
    table3.push('\n');
    for &rd in &step.rds {
        let model = LocModel::load_or_build(&LocSetup::r2(rd), &cache)?;
        let fe = step.record_model(rd).map_err(|e| anyhow::anyhow!("{e}"))?;
        let positions = fe.pass_positions(step.record_step_mm);
        let desc = format!("{fe:?}; positions {positions:?}");
        let (force, _): (Vec<f64>, _) = load_or_compute("r2-record", &desc, &cache, || {
            let bar = crate::limits::Progress::new(
                positions.len() as u64,
                &format!("FE record, RD {rd}"),
                "{msg} [{bar:40}] {pos}/{len} positions ({elapsed}, eta {eta})",
            );
            let tick = || bar.inc(1);
            let r = fe.rolled_pass(&R2Rolling::BENCHMARK_PARAMS, &positions, 2, Some(&tick));
            bar.finish();
            Ok(
                r.map_err(|e| anyhow::anyhow!("the FE record at RD {rd}: {e}"))?
                    .0
                    .iter()
                    .map(|r| r[0])
                    .collect(),
            )
        })?;
        let peak = force.iter().cloned().fold(0.0, f64::max);
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(run.manifest.study.seed);
        let normal = Normal::new(0.0, (step.noise * peak).max(1e-300))?;
        let y: Vec<f64> = force.iter().map(|f| f + normal.sample(&mut rng)).collect();
        let record = Record {
            file: PathBuf::from(format!("{}-rd{rd}-record.csv", step.name)),
            positions: positions.clone(),
            force: y.clone(),
        };
        let mut csv = String::from("position_mm,force_N,force_fe_N\n");
        for i in 0..positions.len() {
            let _ = writeln!(csv, "{},{:.9e},{:.9e}", positions[i], y[i], force[i]);
        }
        write_atomic(&run.out.join(&record.file), csv.as_bytes())?;
        let truth: Vec<(f64, f64)> = fe.nodules.iter().map(|n| (n.x, n.depth)).collect();
        let opts = LocOptions {
            nodules: truth.len(),
            seed: run.manifest.study.seed,
            ..Default::default()
        };
        let loc = localize(&model, &positions, &y, &opts, None)?;
        write_json(
            &run.out.join(format!("{}-rd{rd}.json", step.name)),
            &loc.result,
        )?;
        write_atomic(
            &run.out.join(format!("{}-rd{rd}.svg", step.name)),
            plot_svg(&model, &record, &loc, Some(&truth)).as_bytes(),
        )?;
        for (e, t) in loc.result.nodules.iter().zip(&truth) {
            let _ = writeln!(
                report,
                "| {rd} | {}:{} | {:.2} [{:.2}, {:.2}] | {:.2} [{:.2}, {:.2}] | {} | {:.3} | {:.2} |",
                t.0,
                t.1,
                e.x_mm.mean,
                e.x_mm.hdi_3,
                e.x_mm.hdi_97,
                e.depth_mm.mean,
                e.depth_mm.hdi_3,
                e.depth_mm.hdi_97,
                if e.identifiable { "yes" } else { "NI" },
                loc.result.rhat_max,
                loc.wall_s
            );
        }
        // Table III from the scan surrogate at offset 0
        let mut grid = vec![0.0; model.scan.loading().len()];
        let mut f = Vec::new();
        for d in R2_1_DEPTHS {
            model
                .scan
                .predict_outputs(&[d], &mut grid)
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            f.push(grid[0]);
        }
        let q = quadratic(&f, &R2_1_DEPTHS);
        let _ = write!(table3, "| {rd} |");
        for v in &f {
            let _ = write!(table3, " {v:.4} |");
        }
        let _ = writeln!(table3, " {:.5} | {:.5} | {:.4} |", q[0], q[1], q[2]);
        results.push(serde_json::json!({
            "rd_mm": rd,
            "localisation": loc.result,
            "peak_force_vs_depth": { "depth_mm": R2_1_DEPTHS, "force_N": f, "quadratic_abc": q },
            "surrogate_max_rel_error": model.scan.validation().max_relative_error,
        }));
    }
    report.push_str(&table3);
    report.push('\n');
    Ok(StepResult::Localize {
        name: step.name.clone(),
        results,
    })
}

/// Least squares depth = a F^2 + b F + c (normal equations, 3 x 3).
pub fn quadratic(f: &[f64], d: &[f64]) -> [f64; 3] {
    let mut a = nalgebra::Matrix3::<f64>::zeros();
    let mut r = nalgebra::Vector3::<f64>::zeros();
    for (&fi, &di) in f.iter().zip(d) {
        let row = nalgebra::Vector3::new(fi * fi, fi, 1.0);
        a += row * row.transpose();
        r += row * di;
    }
    a.lu()
        .solve(&r)
        .map_or([f64::NAN; 3], |s| [s[0], s[1], s[2]])
}
