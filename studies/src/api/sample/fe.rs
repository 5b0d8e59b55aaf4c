//! Sampling a finite-element record (`--benchmark N1|N3|Q1`, or an
//! experiment): the record's FE model behind a surrogate
//! (`palpate_uq::surrogate`, cached by [`crate::run::surrogate::load_or_build`]),
//! whose held-out error is added to the likelihood as a variance
//! ([`palpate_uq::likelihood::Posterior::with_model_error`]).
//!
//! The surrogate is trained on the record's own loading history (its
//! displacement samples, and times for Q1), inside the box given by `--box`
//! for every law parameter: the box is the posterior's support, since the
//! surrogate does not extrapolate.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use palpate_uq::surrogate::{ParamBox, Surrogate, SurrogateOptions};
use serde_json::{json, Value};

use super::SampleOptions;
use crate::api::Observer;
use crate::model::{ModelSpec, N1NeedleSpec, N3NeedleSpec, Q1Spec};
use crate::records::arrays::{record_for, ArrayRecord};
use crate::records::{ReadOptions, TestData, TestKind};
use crate::run::surrogate::{default_cache_dir, load_or_build, parse_box, CacheStatus};

/// The benchmarks sampled through a surrogate.
pub const FE_BENCHMARKS: [&str; 3] = ["N1", "N3", "Q1"];

/// The FE benchmark named by `benchmark`, upper case, if it is one.
pub fn fe_benchmark(benchmark: Option<&str>) -> Option<&'static str> {
    let b = benchmark?;
    FE_BENCHMARKS
        .iter()
        .find(|k| k.eq_ignore_ascii_case(b))
        .copied()
}

/// Refuses an FE option without an FE benchmark, or one of another FE
/// benchmark, and a model option with an experiment, naming it.
pub(super) fn check_options(o: &SampleOptions) -> anyhow::Result<()> {
    if o.experiment.is_some() {
        // the model's settings have their place in the description
        let model_options: [(bool, &str, &str); 5] = [
            (o.mesh.is_some(), "--mesh", "[mesh] level and element"),
            (o.bulk.is_some(), "--bulk", "materials.NAME.bulk"),
            (o.friction.is_some(), "--friction", "tool.friction"),
            (o.prony.is_some(), "--prony", "materials.NAME.prony"),
            (
                o.edge_radius.is_some(),
                "--edge-radius",
                "tool.edge_radius of a flat punch",
            ),
        ];
        if let Some((_, name, place)) = model_options.iter().find(|x| x.0) {
            anyhow::bail!(
                "{name}: not an option with --experiment: the description holds the model (give its {place} there)"
            );
        }
        return Ok(());
    }
    let kind = fe_benchmark(o.benchmark.as_deref());
    let given: [(bool, &str, &[&str]); 9] = [
        (!o.boxes.is_empty(), "--box", &FE_BENCHMARKS),
        (o.mesh.is_some(), "--mesh", &FE_BENCHMARKS),
        (o.design.is_some(), "--design", &FE_BENCHMARKS),
        (o.holdout.is_some(), "--holdout", &FE_BENCHMARKS),
        (o.cache.is_some(), "--cache", &FE_BENCHMARKS),
        (o.bulk.is_some(), "--bulk", &FE_BENCHMARKS),
        (o.friction.is_some(), "--friction", &["N1", "N3"]),
        (o.prony.is_some(), "--prony", &["Q1"]),
        (o.edge_radius.is_some(), "--edge-radius", &["Q1"]),
    ];
    for (on, name, users) in given {
        if on && !kind.is_some_and(|k| users.contains(&k)) {
            anyhow::bail!(
                "{name}: an option of --benchmark {} (sampled through a finite-element surrogate); {}",
                users.join(", "),
                match kind {
                    Some(k) => format!("--benchmark {k} does not use it"),
                    None => "give one of them".into(),
                }
            );
        }
    }
    Ok(())
}

/// The model spec of the record: the docs/benchmarks.md set-up with the
/// options given (mesh coarse unless `mesh`).
pub fn model_spec(kind: &str, o: &SampleOptions) -> anyhow::Result<ModelSpec> {
    // a setting's text parsed, the error naming the option (`--mesh 0: ...`)
    fn opt<T: crate::model::Setting>(text: &Option<String>) -> anyhow::Result<Option<T>> {
        crate::model::parse_setting::<T>("sample", text.as_deref())
            .map_err(|e| anyhow::anyhow!("{}", e.as_option()))
    }
    let mesh = Some(opt(&o.mesh)?.unwrap_or(crate::model::Mesh::Level(1)));
    Ok(match kind {
        "N1" => ModelSpec::N1Needle(N1NeedleSpec {
            law: o.law.clone().unwrap_or_default(),
            friction: o.friction,
            mesh,
            bulk: opt(&o.bulk)?,
            ..Default::default()
        }),
        "N3" => ModelSpec::N3Needle(N3NeedleSpec {
            law: o.law.clone().unwrap_or_default(),
            friction: o.friction,
            mesh,
            bulk: opt(&o.bulk)?,
            ..Default::default()
        }),
        _ => ModelSpec::Q1(Q1Spec {
            law: o.law.clone().unwrap_or_default(),
            mesh,
            bulk: opt(&o.bulk)?,
            prony: opt(&o.prony)?,
            edge_radius: o.edge_radius,
            ..Default::default()
        }),
    })
}

/// Reads the one record of the FE benchmark `kind` (`FILE` or
/// `KIND=FILE`, or `<array:K>`; columns displacement_mm, force_N, and
/// time_s for Q1).
pub(super) fn read_record(
    kind: &str,
    data: &[String],
    arrays: &[ArrayRecord],
) -> anyhow::Result<TestData> {
    anyhow::ensure!(
        data.len() == 1,
        "--benchmark {kind}: give one record (--data FILE), got {}",
        data.len()
    );
    let d = &data[0];
    let path = d
        .split_once('=')
        .filter(|(t, _)| t.eq_ignore_ascii_case(kind))
        .map_or(d.as_str(), |(_, p)| p);
    let data = match record_for(path, arrays)? {
        Some(r) => TestData::from_table(
            kind,
            TestKind::N1,
            r.table(&format!("{kind} arrays"))?,
            ReadOptions::default(),
        )?,
        None => TestData::read(kind, TestKind::N1, Path::new(path))?,
    };
    if kind == "Q1" && data.loading.time.is_none() {
        anyhow::bail!(
            "{}: a Q1 record is a timed ramp-and-hold: it needs a time_s column (as `palpate simulate --benchmark Q1 --csv` writes)",
            path
        );
    }
    Ok(data)
}

/// The record, its surrogate and where it came from.
pub(super) struct FeRecord {
    pub data: TestData,
    pub spec: ModelSpec,
    pub surrogate: Arc<Surrogate>,
    pub status: CacheStatus,
}

/// The surrogate of `spec`'s model on the record's loading, built or read
/// from the cache; its build and held-out error to `observer`.
pub(super) fn surrogate(
    data: TestData,
    spec: ModelSpec,
    o: &SampleOptions,
    observer: &dyn Observer,
) -> anyhow::Result<FeRecord> {
    let model = spec
        .validate()
        .map_err(|e| match &spec {
            ModelSpec::Experiment(_) => anyhow::anyhow!("{}", e.expected),
            _ => anyhow::anyhow!("{}", e.as_option()),
        })?
        .into_forward();
    let bounds = parse_box(&o.boxes, model.as_ref())?;
    let mut options = SurrogateOptions::for_dimension(bounds.len());
    if let Some(n) = o.design {
        anyhow::ensure!(
            n >= bounds.len() + 2,
            "--design {n}: at least {} training runs are needed for {} parameters",
            bounds.len() + 2,
            bounds.len()
        );
        options.training_runs = n;
    }
    if let Some(n) = o.holdout {
        anyhow::ensure!(n >= 1, "--holdout {n}: at least 1 held-out run is needed");
        options.validation_runs = n;
    }
    let cache: PathBuf = o.cache.clone().unwrap_or_else(default_cache_dir);
    let t0 = std::time::Instant::now();
    let (s, status) = load_or_build(
        model.as_ref(),
        &data.loading,
        bounds,
        options,
        &format!("{spec:?}"),
        &cache,
        &format!("surrogate of {}", model.name()),
    )?;
    let v = s.validation();
    observer.message(&match &status {
        CacheStatus::Hit(p) => format!(
            "surrogate loaded from the cache {} in {:.2} s (built from {} FE runs in {:.1} s)",
            p.display(),
            t0.elapsed().as_secs_f64(),
            s.fe_runs,
            s.build_time_s
        ),
        CacheStatus::Built(p) => format!(
            "surrogate built from {} FE runs in {:.1} s wall{}, stored in {}",
            s.fe_runs,
            s.build_time_s,
            s.build_cpu_s
                .map(|c| format!(" ({c:.1} s CPU, {} threads)", rayon::current_num_threads()))
                .unwrap_or_default(),
            p.display()
        ),
    });
    observer.message(&format!(
        "surrogate error on {} held-out FE runs: max {:.3e}, RMS {:.3e} of the peak force ({} basis vectors); added to the likelihood as a variance",
        v.points,
        v.max_relative_error,
        v.rms_relative_error,
        s.basis_size()
    ));
    if !s.failed.is_empty() {
        observer.message(&format!(
            "warning: {} FE runs of the design failed and were left out (first at {:?}: {})",
            s.failed.len(),
            s.failed[0].theta,
            s.failed[0].reason
        ));
    }
    Ok(FeRecord {
        data,
        spec,
        surrogate: Arc::new(s),
        status,
    })
}

/// The parameters whose 94 % HDI reaches within 1 % of the box width of a
/// box bound: the box truncates their posterior.
pub fn truncated(bounds: &ParamBox, summary: &[palpate_uq::mcmc::ParamSummary]) -> Vec<String> {
    (0..bounds.len())
        .filter(|&k| {
            let w = bounds.upper[k] - bounds.lower[k];
            summary[k].hdi_3 - bounds.lower[k] < 0.01 * w
                || bounds.upper[k] - summary[k].hdi_97 < 0.01 * w
        })
        .map(|k| bounds.names[k].clone())
        .collect()
}

/// The `surrogate` section of the report.
pub(super) fn report(fe: &FeRecord, summary: &[palpate_uq::mcmc::ParamSummary]) -> Value {
    let s = &fe.surrogate;
    let val = s.validation();
    let b = s.bounds();
    json!({
        "model": format!("{:?}", fe.spec),
        "fe_runs": s.fe_runs,
        "training_runs": s.options().training_runs,
        "held_out_runs": val.points,
        "failed_runs": s.failed.len(),
        "basis_size": s.basis_size(),
        "max_rel_error": val.max_relative_error,
        "rms_rel_error": val.rms_relative_error,
        "max_abs_error_N": val.max_abs_error.first(),
        "box": (0..b.len()).map(|k| json!({"name": b.names[k], "lower": b.lower[k], "upper": b.upper[k]})).collect::<Vec<_>>(),
        "box_truncates": truncated(b, summary),
        "build_time_s": s.build_time_s,
        "build_cpu_s": s.build_cpu_s,
        "cache": fe.status.word(),
        "cache_file": fe.status.path().display().to_string(),
        "key": s.key(),
    })
}
