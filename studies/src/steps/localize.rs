//! The `localize` step of a study: the R2 tumour-localisation analysis
//! (`crate::apps::localize`) at each rolling depth.
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
//! sampler = "nuts"                     # or "ensemble"
//! ```
//!
//! The noise of each RD's record is its own seeded stream, from the study's
//! seed and the RD ([`noise_stream`]), so the RDs are independent
//! experiments (with one noise pattern for all, a nodule misread by one
//! realisation would be misread alike at every RD).
//!
//! Per RD: the localisation model (the scan surrogate + the nodule-free
//! pass, `crate::apps::localize`), the FE record of the nodules at the finer
//! mesh with seeded noise, the posterior; written as `<name>-rd<RD>.json`
//! (the `palpate localize --json` form), `<name>-rd<RD>.svg` (force against
//! position with the fit, the true and located nodules, and each nodule's
//! posterior), `<name>-rd<RD>-record.csv` and report rows; plus the peak
//! force against depth of one nodule (R2-1, the scan surrogate at offset 0)
//! and the quadratic depth = a F^2 + b F + c per RD (Table III).
//!
//! Units (shards, [`crate::run::shard`]), as in a sample step: first every FE
//! run of every RD in RD order (per RD the nodule-free pass, each scan of
//! the surrogate's design, [`ModelUnits`], then the record), cached in the
//! run folder as its result under a key of its inputs and the code version;
//! then each RD's posterior (cached as its result, plot and evaluation
//! count), which needs all of that RD's FE runs: a shard lacking some
//! counts it as waiting ([`Run::units_when`]), and a second pass of the
//! shards or the merge computes it. Every process that needs an RD's model
//! assembles it from the cached runs (the surrogate's GP fit: well under a
//! second beside the FE runs). The FE runs do not use the surrogate cache
//! of `palpate localize`: a study's units live in its run folder.

use crate::apps::localize::plot::plot_svg;
use crate::apps::localize::posterior::{localize, LocOptions, LocSampler, Localisation};
use crate::apps::localize::record::Record;
use crate::apps::localize::units::{ModelRun, ModelUnits};
use crate::apps::localize::{LocModel, LocSetup};
use crate::run::output::{write_atomic, write_json};
use crate::run::run_folder::RunFolder;
use crate::run::step::{At, Run, Step, StepResult, Study};
use crate::run::surrogate::code_version;
use palpate_fe::r2::check_model;
use palpate_fe::r2_scan::R2NoduleScan;
use palpate_fe::{Nodule, R2Rolling};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};
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

/// R2-1's depths (docs/benchmarks.md).
pub const R2_1_DEPTHS: [f64; 8] = [8.0, 10.0, 12.0, 15.0, 18.0, 20.0, 22.0, 24.0];

/// Which localisation model a localize step builds per RD.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LocScan {
    /// [`LocSetup::r2_lean`].
    #[default]
    Lean,
    /// [`LocSetup::r2`].
    Centre,
}

impl LocScan {
    /// The setup of this model at `rd`.
    pub fn setup(self, rd: f64) -> LocSetup {
        match self {
            LocScan::Lean => LocSetup::r2_lean(rd),
            LocScan::Centre => LocSetup::r2(rd),
        }
    }
}

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
    /// The posterior's sampler (`nuts`, default, or `ensemble`).
    #[serde(default)]
    pub sampler: LocSampler,
    /// The localisation model: `lean` (default, the centre scans plus the
    /// end lean's 16 FE scans, `LocSetup::r2_lean`) or `centre`
    /// (`LocSetup::r2`: translation invariance assumed, shallow nodules
    /// near the ends read towards them).
    #[serde(default)]
    pub scan: LocScan,
    /// Refused with the reason (the FE runs are units of the run folder);
    /// kept so that a manifest of an earlier palpate that set it is told
    /// why rather than "unknown field".
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
    pub(crate) fn check(&self, _m: &Study, i: usize, where_: &str) -> anyhow::Result<()> {
        let at = format!("{where_}: steps[{i}].localize (\"{}\")", self.name);
        anyhow::ensure!(!self.rds.is_empty(), "{at}.rds = []: give at least one RD");
        if let Some(c) = &self.cache {
            anyhow::bail!(
                "{at}.cache = {:?}: a study caches its FE runs in its run folder \
                 (RUN_DIR/.palpate/cache, where its shards share them), not in a surrogate cache; \
                 remove the field",
                c.display().to_string()
            );
        }
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
            self.scan
                .setup(rd)
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

/// One FE run of the step, as cached: a unit of an RD's localisation
/// model, or the RD's FE record (the force at each position).
#[derive(Debug, Clone, Serialize, Deserialize)]
enum FeRun {
    Model(ModelRun),
    Record(Vec<f64>),
}

/// The posterior of one RD, as cached: what the results, the plot and the
/// report take from it.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct PosteriorRun {
    result: Localisation,
    /// `<name>-rd<RD>.svg`.
    svg: String,
    /// Log-density evaluations of the sampler.
    evaluations: u64,
}

/// What one RD needs: its model's units, the record's FE model and
/// positions.
struct RdPlan {
    rd: f64,
    model: ModelUnits<R2NoduleScan>,
    record: R2Rolling,
    positions: Vec<f64>,
}

/// Runs the step.
pub(crate) fn run_localize(
    run: &Run,
    step: &LocalizeStep,
    report: &mut String,
) -> anyhow::Result<serde_json::Value> {
    let at = format!("step `{}`", step.name);
    let seed = run.manifest.study.seed;
    let plans: Vec<RdPlan> = step
        .rds
        .iter()
        .map(|&rd| -> anyhow::Result<RdPlan> {
            let model =
                ModelUnits::r2(&step.scan.setup(rd)).map_err(|e| anyhow::anyhow!("{at}: {e}"))?;
            let record = step
                .record_model(rd)
                .map_err(|e| anyhow::anyhow!("{at}: {e}"))?;
            let positions = record.pass_positions(step.record_step_mm);
            Ok(RdPlan {
                rd,
                model,
                record,
                positions,
            })
        })
        .collect::<anyhow::Result<_>>()?;
    // First level: every FE run of every RD (the model's units, then the
    // record), in RD order.
    let mut which: Vec<(usize, Option<usize>)> = Vec::new();
    let mut keys: Vec<String> = Vec::new();
    for (i, p) in plans.iter().enumerate() {
        for k in 0..p.model.len() {
            which.push((i, Some(k)));
            keys.push(RunFolder::key(&(
                "localize FE run",
                p.model.inputs(k),
                code_version(),
            )));
        }
        which.push((i, None));
        keys.push(RunFolder::key(&(
            "localize FE record",
            format!("{:?}", p.record),
            &p.positions,
            code_version(),
        )));
    }
    let label = format!("{}: FE runs", step.name);
    let runs: Vec<Option<FeRun>> = run.units(&keys, &label, |u| {
        let (i, k) = which[u];
        let p = &plans[i];
        Ok(match k {
            Some(k) => FeRun::Model(
                p.model
                    .compute(k)
                    .map_err(|e| anyhow::anyhow!("{at}: {e}"))?,
            ),
            None => FeRun::Record(record_force(p)?),
        })
    })?;
    // The models and records of the RDs whose FE runs are all there.
    let mut parts: Vec<Option<(LocModel, Vec<f64>)>> = Vec::new();
    for (i, p) in plans.iter().enumerate() {
        let mine: Vec<&Option<FeRun>> = which
            .iter()
            .zip(&runs)
            .filter(|((j, _), _)| *j == i)
            .map(|(_, r)| r)
            .collect();
        if mine.iter().any(|r| r.is_none()) {
            parts.push(None);
            continue;
        }
        let mut model_runs = Vec::new();
        let mut force = Vec::new();
        for r in mine.into_iter().flatten() {
            match r {
                FeRun::Model(m) => model_runs.push(m.clone()),
                FeRun::Record(f) => force = f.clone(),
            }
        }
        let model = p
            .model
            .assemble(model_runs)
            .map_err(|e| anyhow::anyhow!("{at}: {e}"))?;
        parts.push(Some((model, force)));
    }
    // Second level: each RD's posterior, once its FE runs are all there.
    let post_keys: Vec<String> = plans
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let fe: Vec<&String> = which
                .iter()
                .zip(&keys)
                .filter(|((j, _), _)| *j == i)
                .map(|(_, k)| k)
                .collect();
            RunFolder::key(&(
                "localize posterior (noise per RD)",
                &step.name,
                p.rd,
                fe,
                step.noise.to_bits(),
                seed,
                step.sampler,
            ))
        })
        .collect();
    let ready: Vec<bool> = parts.iter().map(Option::is_some).collect();
    let label = format!("{}: posteriors (one per RD)", step.name);
    let posteriors: Vec<Option<PosteriorRun>> =
        run.units_when(&post_keys, &ready, &label, |i| {
            let (model, force) = parts[i].as_ref().ok_or_else(|| {
                anyhow::anyhow!(
                    "{at}: the posterior at RD {} before its FE runs",
                    plans[i].rd
                )
            })?;
            posterior(step, &plans[i], model, force, seed)
        })?;
    if posteriors.iter().any(Option::is_none) {
        // Units of other shards: the runner defers the step.
        return Ok(serde_json::json!({
            "name": step.name.clone(),
            "results": Vec::<serde_json::Value>::new(),
        }));
    }

    let mut results = Vec::new();
    let _ = writeln!(report, "## Localisation `{}`\n", step.name);
    let _ = writeln!(
        report,
        "FE records of the nodules `{}` at h = {} mm every {} mm, Gaussian noise SD {} % of the peak force (seed {seed}); posterior on the localisation model (studies/src/apps/localize), {}.\n",
        step.nodules,
        step.record_h_mm,
        step.record_step_mm,
        100.0 * step.noise,
        match step.scan {
            LocScan::Lean => "its excess shifted by the end lean measured on FE scans near the end (`scan = \"lean\"`)",
            LocScan::Centre => "translation invariance assumed (`scan = \"centre\"`)",
        }
    );
    let _ = writeln!(
        report,
        "| RD mm | nodule (true x:depth) | x mm mean [94 % HDI] | depth mm mean [94 % HDI] | identifiable | R-hat max | posterior evaluations |\n|---|---|---|---|---|---|---|"
    );
    let mut leans = String::new();
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
    for ((p, part), post) in plans.iter().zip(parts).zip(posteriors) {
        let rd = p.rd;
        let (Some((model, force)), Some(post)) = (part, post) else {
            anyhow::bail!("{at}: the results at RD {rd} before its FE runs and posterior");
        };
        let record = noisy_record(step, p, &force, seed)?;
        let mut csv = String::from("position_mm,force_N,force_fe_N\n");
        for ((x, y), f) in record.positions.iter().zip(&record.force).zip(&force) {
            let _ = writeln!(csv, "{x},{y:.9e},{f:.9e}");
        }
        write_atomic(&run.out.join(&record.file), csv.as_bytes())?;
        write_json(
            &run.out.join(format!("{}-rd{rd}.json", step.name)),
            &post.result,
        )?;
        write_atomic(
            &run.out.join(format!("{}-rd{rd}.svg", step.name)),
            post.svg.as_bytes(),
        )?;
        for (e, t) in post.result.nodules.iter().zip(&p.record.nodules) {
            let _ = writeln!(
                report,
                "| {rd} | {}:{} | {:.2} [{:.2}, {:.2}] | {:.2} [{:.2}, {:.2}] | {} | {:.3} | {} |",
                t.x,
                t.depth,
                e.x_mm.mean,
                e.x_mm.hdi_3,
                e.x_mm.hdi_97,
                e.depth_mm.mean,
                e.depth_mm.hdi_3,
                e.depth_mm.hdi_97,
                if e.identifiable { "yes" } else { "NI" },
                post.result.rhat_max,
                post.evaluations
            );
        }
        // Table III from the scan surrogate at offset 0
        let mut f = Vec::new();
        for d in R2_1_DEPTHS {
            f.push(model.peak_force(d)?);
        }
        let q = quadratic(&f, &R2_1_DEPTHS);
        let _ = write!(table3, "| {rd} |");
        for v in &f {
            let _ = write!(table3, " {v:.4} |");
        }
        let _ = writeln!(table3, " {:.5} | {:.5} | {:.4} |", q[0], q[1], q[2]);
        results.push(serde_json::json!({
            "rd_mm": rd,
            "localisation": post.result,
            "peak_force_vs_depth": { "depth_mm": R2_1_DEPTHS, "force_N": f, "quadratic_abc": q },
            "surrogate_max_rel_error": model.max_rel_error(),
            "end_lean": model.lean,
        }));
        if let Some(l) = &model.lean {
            let _ = write!(
                leans,
                "\nEnd lean at RD {rd} (mm, + towards the nearer end; rows: the nodule's distance from the end, columns: depth), from FE scans near the end:\n\n| distance mm |"
            );
            for d in &l.depth {
                let _ = write!(leans, " {d} mm |");
            }
            leans.push_str("\n|---|");
            leans.push_str(&"---|".repeat(l.depth.len()));
            leans.push('\n');
            for (e, row) in l.distance.iter().zip(&l.shift) {
                let _ = write!(leans, "| {e} |");
                for v in row {
                    let _ = write!(leans, " {v:+.3} |");
                }
                leans.push('\n');
            }
        }
    }
    report.push_str(&table3);
    report.push_str(&leans);
    report.push('\n');
    Ok(serde_json::json!({
        "name": step.name.clone(),
        "results": results,
    }))
}

/// The FE record of an RD: the force of the nodules' model at the record's
/// positions (2 segments whatever the thread count, as the baseline).
fn record_force(p: &RdPlan) -> anyhow::Result<Vec<f64>> {
    let rd = p.rd;
    let r = p
        .record
        .rolled_pass(&R2Rolling::BENCHMARK_PARAMS, &p.positions, 2, None);
    Ok(
        r.map_err(|e| anyhow::anyhow!("the FE record at RD {rd}: {e}"))?
            .0
            .iter()
            .map(|r| r[0])
            .collect(),
    )
}

/// The seed of the noise of the record at `rd`: the study's seed mixed with
/// the RD (in micrometres) by the golden-ratio multiplier of SplitMix64, so
/// each RD draws its own stream (`seed_from_u64` then scrambles it further).
pub fn noise_stream(seed: u64, rd: f64) -> u64 {
    let rd_um = (rd * 1000.0).round() as u64;
    seed ^ rd_um.wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

/// The record with the study's seeded noise (SD `noise` x its peak force),
/// drawn from the RD's own stream ([`noise_stream`]).
fn noisy_record(
    step: &LocalizeStep,
    p: &RdPlan,
    force: &[f64],
    seed: u64,
) -> anyhow::Result<Record> {
    let peak = force.iter().cloned().fold(0.0, f64::max);
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(noise_stream(seed, p.rd));
    let normal = Normal::new(0.0, (step.noise * peak).max(1e-300))?;
    Ok(Record {
        file: PathBuf::from(format!("{}-rd{}-record.csv", step.name, p.rd)),
        positions: p.positions.clone(),
        force: force.iter().map(|f| f + normal.sample(&mut rng)).collect(),
    })
}

/// The posterior of an RD's nodules on its model, given the FE record.
fn posterior(
    step: &LocalizeStep,
    p: &RdPlan,
    model: &LocModel,
    force: &[f64],
    seed: u64,
) -> anyhow::Result<PosteriorRun> {
    let record = noisy_record(step, p, force, seed)?;
    let truth: Vec<(f64, f64)> = p.record.nodules.iter().map(|n| (n.x, n.depth)).collect();
    let opts = LocOptions {
        nodules: truth.len(),
        seed,
        sampler: step.sampler,
        ..Default::default()
    };
    let loc = localize(model, &record.positions, &record.force, &opts, None)?;
    Ok(PosteriorRun {
        svg: plot_svg(model, &record, &loc, Some(&truth)),
        result: loc.result,
        evaluations: loc.evaluations,
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


impl Step for LocalizeStep {
    fn name(&self) -> &str {
        &self.name
    }

    fn validate(&self, study: &Study, at: &At) -> anyhow::Result<()> {
        self.check(study, at.index, &at.file)
    }

    fn run(
        &self,
        run: &Run,
        done: &[StepResult],
        report: &mut String,
    ) -> anyhow::Result<serde_json::Value> {
        let _ = done;
        run_localize(run, self, report)
    }
}

#[cfg(test)]
mod tests {
    use super::noise_stream;

    /// Each RD draws its own noise: different RDs (and seeds) give
    /// different streams, the same (seed, RD) the same one.
    #[test]
    fn every_rd_has_its_own_noise_stream() {
        let s: Vec<u64> = [3.0, 4.0, 5.0, 6.0]
            .iter()
            .map(|&rd| noise_stream(11, rd))
            .collect();
        for i in 0..s.len() {
            for j in i + 1..s.len() {
                assert_ne!(s[i], s[j], "RDs {i} and {j}");
            }
        }
        assert_eq!(noise_stream(11, 6.0), noise_stream(11, 6.0));
        assert_ne!(noise_stream(11, 6.0), noise_stream(12, 6.0));
        assert_ne!(noise_stream(11, 6.0), noise_stream(11, 6.001));
    }
}
