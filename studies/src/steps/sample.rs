//! The `sample` step of a study: the Bayesian posterior of a model's
//! parameters by MCMC (as `palpate sample`), with its chains as units of
//! the run folder, and, for a finite-element model, the FE runs that train
//! its surrogate as units too.
//!
//! ```toml
//! [[steps]]
//! [steps.sample]
//! name = "posterior"
//! model = "nh"                 # a [models.NAME] entry
//! data = ["compression"]       # records sampled jointly
//! sampler = "nuts"             # nuts (default), demc or ensemble
//! draws = 500                  # stored draws per chain (default: the sampler's)
//! tune = 500                   # warm-up iterations (default: the sampler's)
//! chains = 4                   # NUTS chains, DE-MCz populations or ensembles
//! sigma = 0.5                  # known noise SD (N or MPa); inferred when absent
//! # FE models (c1_fe, n1_needle, n3_needle, q1), one record, through a surrogate:
//! box = { C10 = [0.0005, 0.002] }   # the surrogate's box for every parameter
//! design = 30                  # training FE runs (default max(30, 15 x parameters))
//! holdout = 8                  # held-out FE runs (default max(8, 3 x parameters))
//! ```
//!
//! Units (shards, [`crate::run::shard`]): first, for an FE model, each run of the
//! surrogate's design (a Halton point of the box, [`Surrogate::design`]),
//! cached as its outputs (or the reason it failed); then each independent
//! unit of the sampler ([`Sampler::run_unit`]: a NUTS chain, a DE-MCz
//! population, an ensemble), seeded by the study's seed and its index, so
//! any process computes the same draws. The surrogate is assembled from the
//! cached runs ([`Surrogate::from_runs`]) and the least-squares start from
//! the data by every process that needs them (both deterministic and cheap
//! beside the units). A shard that lacks some design runs cannot start the
//! chains: it counts them as waiting, and a second pass of the shards or the
//! merge computes them.
//!
//! The draws per chain are fixed (no extension until converged, unlike
//! `palpate sample`, whose extension needs every chain at once): the
//! results say whether R-hat < 1.01 and bulk ESS >= 400 hold.

use crate::records::TestData;
use crate::model::ModelForm;
use crate::model::ModelSpec;
use crate::run::run_folder::RunFolder;
use crate::run::step::{At, Run, Step, StepResult, Study};
use anyhow::Context;
use palpate_core::ForwardModel;
use palpate_uq::likelihood::{fit_and_laplace, DataSet, NoiseModel, NoiseSd, Posterior, Prior};
use palpate_uq::mcmc::{summarize, DemcSettings, EnsembleSettings, NutsSettings, Sampler, UnitRun};
use palpate_uq::surrogate::{Surrogate, SurrogateOptions, SurrogateRequest};
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::sync::Arc;

/// `[steps.sample]`: the posterior of one model's parameters.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SampleStep {
    pub name: String,
    /// The model (a `[models.NAME]` entry).
    pub model: String,
    /// Records sampled jointly (one for an FE model).
    pub data: Vec<String>,
    /// `nuts`, `demc` or `ensemble`.
    #[serde(default = "default_sampler")]
    pub sampler: String,
    /// Stored draws per chain (default: the sampler's).
    pub draws: Option<usize>,
    /// Warm-up iterations (default: the sampler's).
    pub tune: Option<usize>,
    /// Independent units: NUTS chains, DE-MCz populations or ensembles.
    pub chains: Option<usize>,
    /// Known noise SD of every record (N or MPa); inferred when absent.
    pub sigma: Option<f64>,
    /// FE models: the surrogate's box, `NAME = [LO, HI]` for every parameter.
    #[serde(default, rename = "box")]
    pub bounds: BTreeMap<String, Vec<f64>>,
    /// FE models: training runs of the surrogate.
    pub design: Option<usize>,
    /// FE models: held-out runs measuring the surrogate's error.
    pub holdout: Option<usize>,
}

fn default_sampler() -> String {
    "nuts".into()
}

/// Whether a model kind is a finite-element model (sampled through a surrogate).
fn is_fe(spec: &ModelSpec) -> bool {
    matches!(
        spec,
        ModelSpec::C1Fe(_)
            | ModelSpec::N1Needle(_)
            | ModelSpec::N3Needle(_)
            | ModelSpec::Q1(_)
            | ModelSpec::Experiment(_)
    )
}

impl SampleStep {
    /// The sampler with the step's settings, or an error naming the field.
    pub fn sampler(&self, at: &str) -> anyhow::Result<Sampler> {
        let mut s = match self.sampler.to_ascii_lowercase().as_str() {
            "nuts" => Sampler::Nuts(NutsSettings::default()),
            "demc" => Sampler::Demc(DemcSettings::default()),
            "ensemble" => Sampler::Ensemble(EnsembleSettings::default()),
            other => anyhow::bail!("{at}.sampler = \"{other}\": expected nuts, demc or ensemble"),
        };
        if let Some(d) = self.draws {
            anyhow::ensure!(
                (4..=1_000_000).contains(&d),
                "{at}.draws = {d}: between 4 (for the diagnostics) and 1000000 draws per chain"
            );
        }
        if let Some(t) = self.tune {
            anyhow::ensure!(
                t <= 1_000_000,
                "{at}.tune = {t}: at most 1000000 warm-up iterations"
            );
        }
        if let Some(c) = self.chains {
            anyhow::ensure!(
                (1..=1024).contains(&c),
                "{at}.chains = {c}: between 1 and 1024 independent units"
            );
        }
        match &mut s {
            Sampler::Nuts(n) => {
                n.draws = self.draws.unwrap_or(n.draws);
                n.tune = self.tune.unwrap_or(n.tune);
                n.chains = self.chains.unwrap_or(n.chains);
            }
            Sampler::Demc(n) => {
                n.draws = self.draws.unwrap_or(n.draws);
                n.tune = self.tune.unwrap_or(n.tune);
                n.populations = self.chains.unwrap_or(n.populations);
            }
            Sampler::Ensemble(n) => {
                n.draws = self.draws.unwrap_or(n.draws);
                n.tune = self.tune.unwrap_or(n.tune);
                n.ensembles = self.chains.unwrap_or(n.ensembles);
            }
        }
        Ok(s)
    }

    /// Checks the step (step `i` of `manifest`); errors name the manifest
    /// file (`where_`) and the field.
    pub(crate) fn check(&self, manifest: &Study, i: usize, where_: &str) -> anyhow::Result<()> {
        let at = format!("steps[{i}].sample (\"{}\")", self.name);
        self.sampler(&format!("{where_}: {at}"))?;
        let entry = manifest.models.get(&self.model).with_context(|| {
            format!(
                "{where_}: {at}.model: unknown model \"{}\" (defined: {})",
                self.model,
                crate::run::step::keys(manifest.models)
            )
        })?;
        anyhow::ensure!(
            !self.data.is_empty(),
            "{where_}: {at}.data = []: give at least one record"
        );
        for (k, d) in self.data.iter().enumerate() {
            anyhow::ensure!(
                manifest.data.contains_key(d),
                "{where_}: {at}.data: unknown data set \"{d}\" (defined: {})",
                crate::run::step::keys(manifest.data)
            );
            anyhow::ensure!(
                !self.data[..k].contains(d),
                "{where_}: {at}.data: \"{d}\" is listed twice"
            );
        }
        if let Some(s) = self.sigma {
            anyhow::ensure!(
                s.is_finite() && s > 0.0,
                "{where_}: {at}.sigma = {s}: must be a positive number"
            );
        }
        let fe = matches!(&entry.model, ModelForm::Spec(s) if is_fe(s));
        if fe {
            anyhow::ensure!(
                self.data.len() == 1,
                "{where_}: {at}.data: an FE model is sampled on one record (through its surrogate), got {}",
                self.data.len()
            );
            anyhow::ensure!(
                !self.bounds.is_empty(),
                "{where_}: {at}.box: an FE model is sampled through a surrogate trained inside a box; give box = {{ NAME = [LO, HI], ... }} for every parameter"
            );
            for (name, b) in &self.bounds {
                anyhow::ensure!(
                    b.len() == 2,
                    "{where_}: {at}.box.{name}: expected [LO, HI], got {} numbers",
                    b.len()
                );
            }
        } else {
            for (field, given) in [
                ("box", !self.bounds.is_empty()),
                ("design", self.design.is_some()),
                ("holdout", self.holdout.is_some()),
            ] {
                anyhow::ensure!(
                    !given,
                    "{where_}: {at}.{field}: for FE models (sampled through a surrogate); model \"{}\" is analytic",
                    self.model
                );
            }
        }
        Ok(())
    }
}

/// One FE run of a surrogate's design as cached.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct DesignRun {
    /// The model's outputs along the record's loading, or why it failed.
    outputs: Result<Vec<f64>, String>,
}

/// Runs a sample step.
pub(crate) fn run_sample(
    run: &Run,
    step: &SampleStep,
    report: &mut String,
) -> anyhow::Result<serde_json::Value> {
    let at = format!("step `{}`", step.name);
    let sampler = step.sampler(&at)?;
    let entry = &run.manifest.models[&step.model];
    let records: Vec<&TestData> = step.data.iter().map(|d| &run.data[d]).collect();
    let seed = run.manifest.study.seed;
    let noise = |observed: &[f64]| NoiseModel {
        sd: match step.sigma {
            Some(s) => NoiseSd::Known(s),
            None => NoiseSd::Inferred(Prior::HalfNormal {
                sd: observed
                    .iter()
                    .fold(0.0f64, |m, v| m.max(v.abs()))
                    .max(1e-12),
            }),
        },
        correlation: palpate_uq::likelihood::Correlation::Independent,
    };
    // What every unit of the step depends on (the step's name aside).
    let basis = (
        ("sample", entry, &records, &step.model),
        (
            &step.sampler,
            step.draws,
            step.tune,
            step.chains,
            step.sigma,
        ),
        (&step.bounds, step.design, step.holdout),
        seed,
        // FE models: the chains depend on the FE code through the surrogate.
        match &entry.model {
            ModelForm::Spec(spec) if is_fe(spec) => crate::run::surrogate::code_version(),
            _ => "",
        },
    );
    let mut surrogate_info = serde_json::Value::Null;
    let mut surrogate: Option<Arc<Surrogate>> = None;
    let sets: Option<Vec<DataSet>> = match &entry.model {
        ModelForm::Spec(spec) if is_fe(spec) => {
            let rec = records[0];
            let model = crate::model::build(spec)
                .map_err(|e| anyhow::anyhow!("models.{}.{e}", step.model))?;
            let boxes: Vec<String> = step
                .bounds
                .iter()
                .map(|(n, b)| format!("{n}={},{}", b[0], b[1]))
                .collect();
            let bounds = crate::run::surrogate::parse_box(&boxes, model.as_ref())
                .with_context(|| format!("{at}: box"))?;
            let mut options = SurrogateOptions::for_dimension(bounds.len());
            options.training_runs = step.design.unwrap_or(options.training_runs);
            options.validation_runs = step.holdout.unwrap_or(options.validation_runs);
            let req = SurrogateRequest {
                model: model.as_ref(),
                loading: &rec.loading,
                bounds,
                options,
                description: format!("{spec:?}"),
            };
            let points = Surrogate::design(&req).map_err(|e| anyhow::anyhow!("{at}: {e}"))?;
            let keys: Vec<String> = points
                .iter()
                .map(|theta| {
                    RunFolder::key(&(
                        "surrogate run",
                        spec,
                        &rec.loading,
                        theta,
                        crate::run::surrogate::code_version(),
                    ))
                })
                .collect();
            let label = format!("{}: FE runs of the surrogate", step.name);
            let runs: Vec<Option<DesignRun>> = run.units(&keys, &label, |k| {
                Ok(DesignRun {
                    outputs: Surrogate::run_point(model.as_ref(), &rec.loading, &points[k]),
                })
            })?;
            if runs.iter().all(Option::is_some) {
                let results = runs.into_iter().flatten().map(|r| r.outputs).collect();
                let s = Surrogate::from_runs(&req, results).map_err(|e| {
                    anyhow::anyhow!("{at}: building the surrogate of {}: {e}", model.name())
                })?;
                let v = s.validation();
                surrogate_info = json!({
                    "training_runs": s.options().training_runs,
                    "held_out_runs": v.points,
                    "failed_runs": s.failed.len(),
                    "basis_size": s.basis_size(),
                    "max_rel_error": v.max_relative_error,
                    "rms_rel_error": v.rms_relative_error,
                });
                let s = Arc::new(s);
                surrogate = Some(s.clone());
                Some(vec![DataSet {
                    name: rec.name.clone(),
                    model: s,
                    loading: rec.loading.clone(),
                    observed: rec.observed.clone(),
                    noise: noise(&rec.observed),
                }])
            } else {
                None
            }
        }
        form => Some(
            records
                .iter()
                .map(|r| -> anyhow::Result<DataSet> {
                    let spec = match form {
                        ModelForm::Law(law) => crate::model::record_spec(
                            r,
                            law.parse()
                                .map_err(|e| anyhow::anyhow!("models.{}.law: {e}", step.model))?,
                            None,
                        ),
                        ModelForm::Spec(s) => s.clone(),
                    };
                    let model: Arc<dyn ForwardModel> = crate::model::build(&spec)
                        .map_err(|e| anyhow::anyhow!("models.{}.{e}", step.model))?
                        .into();
                    Ok(DataSet {
                        name: r.name.clone(),
                        model,
                        loading: r.loading.clone(),
                        observed: r.observed.clone(),
                        noise: noise(&r.observed),
                    })
                })
                .collect::<anyhow::Result<_>>()?,
        ),
    };
    let chain_keys: Vec<String> = (0..sampler.unit_count())
        .map(|c| RunFolder::key(&(&basis, "chain", c)))
        .collect();
    let Some(sets) = sets else {
        // Design runs of other shards are missing: the chains wait for them.
        for k in &chain_keys {
            run.wait(k);
        }
        return Ok(empty(step));
    };
    let priors = vec![Prior::Flat; sets[0].model.space().len()];
    let mut post = Posterior::new(sets, priors).map_err(|e| anyhow::anyhow!("{at}: {e}"))?;
    if let Some(s) = &surrogate {
        post = post
            .with_model_error(0, s.error_variance(0))
            .map_err(|e| anyhow::anyhow!("{at}: {e}"))?;
    }
    let start = fit_and_laplace(&post)
        .map_err(|e| anyhow::anyhow!("{at}: finding the start of the chains: {e}"))?;
    let label = format!("{}: {} chains", step.name, sampler.unit_count());
    let chains: Vec<Option<UnitRun>> = run.units(&chain_keys, &label, |c| {
        sampler
            .run_unit(&post, &start.start, seed, c)
            .map_err(|e| anyhow::anyhow!("{at}: chain {c}: {e}"))
    })?;
    if chains.iter().any(Option::is_none) {
        return Ok(empty(step)); // chains of other shards: the runner defers the step
    }
    let whole = sampler.assemble(chains.into_iter().flatten().collect());
    let names = post.names();
    let x = whole.chains.map(|z| post.space().from_unbounded(z));
    let summary = summarize(&x, &names);
    let mut params = serde_json::Map::new();
    for s in &summary {
        params.insert(
            s.name.clone(),
            json!({
                "mean": s.mean, "sd": s.sd, "hdi_3": s.hdi_3, "hdi_97": s.hdi_97,
                "rhat": s.rhat, "ess_bulk": s.ess_bulk, "ess_tail": s.ess_tail,
                "mcse_mean": s.mcse_mean,
            }),
        );
    }
    let converged = summary.iter().all(|s| s.rhat < 1.01 && s.ess_bulk >= 400.0);
    let result = json!({
        "model": step.model,
        "data": step.data,
        "sampler": whole.sampler,
        "seed": seed,
        "chains": x.n_chains,
        "draws_per_chain": x.n_draws,
        "params": params,
        "converged": converged,
        "acceptance": whole.acceptance,
        "divergences": whole.divergences,
        "evaluations": whole.evaluations,
        "surrogate": surrogate_info,
    });
    write_report(step, &summary, x.n_chains, x.n_draws, converged, report);
    for (file, svg) in crate::report::posterior_plots(&post, &x, seed)? {
        let path = run.out.join("plots").join(format!("{}-{file}", step.name));
        crate::run::output::write_atomic(&path, svg.as_bytes())?;
    }
    let _ = writeln!(
        report,
        "Plots: `plots/{0}-corner.svg` (marginals and pairs of the draws), `plots/{0}-predictive_<data>.svg` (94 % bands and the data).\n",
        step.name
    );
    Ok(serde_json::json!({
        "name": step.name.clone(),
        "result": result,
    }))
}

/// The result of a step whose units are not all there (never written:
/// the runner defers the step).
fn empty(step: &SampleStep) -> serde_json::Value {
    serde_json::json!({
        "name": step.name.clone(),
        "result": serde_json::Value::Null,
    })
}

fn write_report(
    step: &SampleStep,
    summary: &[palpate_uq::mcmc::ParamSummary],
    chains: usize,
    draws: usize,
    converged: bool,
    r: &mut String,
) {
    let _ = writeln!(
        r,
        "## Posterior `{}`
",
        step.name
    );
    let _ = writeln!(
        r,
        "Model `{}` on {}; sampler `{}`, {chains} chains x {draws} draws{}.
",
        step.model,
        step.data.join(", "),
        step.sampler,
        if converged {
            ""
        } else {
            " (**not converged**: R-hat >= 1.01 or bulk ESS < 400 for some parameter; raise draws)"
        }
    );
    let _ = writeln!(
        r,
        "| parameter | mean | sd | hdi 3% | hdi 97% | R-hat | bulk ESS |"
    );
    let _ = writeln!(r, "|---|---|---|---|---|---|---|");
    for s in summary {
        let _ = writeln!(
            r,
            "| {} | {:.5e} | {:.3e} | {:.5e} | {:.5e} | {:.4} | {:.0} |",
            s.name, s.mean, s.sd, s.hdi_3, s.hdi_97, s.rhat, s.ess_bulk
        );
    }
    let _ = writeln!(r);
}


impl Step for SampleStep {
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
        run_sample(run, self, report)
    }
}

#[cfg(test)]
mod tests {
    use crate::study::manifest::Manifest;

    /// The manifest of one sample step with `fields` (TOML lines), its
    /// refusal (parse or validation) as text, or "" when accepted.
    fn refusal(fields: &str) -> String {
        let dir = tempfile::tempdir().unwrap();
        let rec = "displacement_mm,force_N\n0,0\n0.5,0.2\n1,0.5\n";
        std::fs::write(dir.path().join("c1.csv"), rec).unwrap();
        std::fs::write(dir.path().join("n1.csv"), rec).unwrap();
        let text = format!(
            "[study]\nname = \"s\"\n\n[data.c1]\nfile = \"c1.csv\"\ntest = \"C1\"\n\n\
             [data.n1]\nfile = \"n1.csv\"\ntest = \"N1\"\n\n[models.nh]\nlaw = \"neo-hookean\"\n\n\
             [models.fe.n1_needle]\nlaw = \"neo-hookean\"\nmesh = \"coarse\"\n\n\
             [[steps]]\n[steps.sample]\nname = \"p\"\n{fields}\n"
        );
        let path = dir.path().join("s.toml");
        std::fs::write(&path, &text).unwrap();
        match Manifest::parse(&path, &text).and_then(|m| m.validate(&path)) {
            Ok(_) => String::new(),
            Err(e) => format!("{e:#}"),
        }
    }

    #[test]
    fn bad_fields_are_refused_naming_the_field() {
        assert_eq!(refusal("model = \"nh\"\ndata = [\"c1\"]"), "");
        assert_eq!(
            refusal("model = \"fe\"\ndata = [\"n1\"]\nbox = { C10 = [0.001, 0.002] }"),
            ""
        );
        let at = "steps[0].sample (\"p\")";
        for (fields, says) in [
            (
                "model = \"nh\"\ndata = [\"c1\"]\nsampler = \"gibbs\"",
                format!("{at}.sampler = \"gibbs\": expected nuts, demc or ensemble"),
            ),
            (
                "model = \"nh\"\ndata = [\"c1\"]\ndraws = 2",
                format!("{at}.draws = 2: between 4"),
            ),
            (
                "model = \"nh\"\ndata = [\"c1\"]\nchains = 0",
                format!("{at}.chains = 0: between 1 and 1024"),
            ),
            (
                "model = \"nope\"\ndata = [\"c1\"]",
                format!("{at}.model: unknown model \"nope\" (defined: fe, nh)"),
            ),
            (
                "model = \"nh\"\ndata = []",
                format!("{at}.data = []: give at least one record"),
            ),
            (
                "model = \"nh\"\ndata = [\"c2\"]",
                format!("{at}.data: unknown data set \"c2\""),
            ),
            (
                "model = \"nh\"\ndata = [\"c1\", \"c1\"]",
                format!("{at}.data: \"c1\" is listed twice"),
            ),
            (
                "model = \"nh\"\ndata = [\"c1\"]\nsigma = -1.0",
                format!("{at}.sigma = -1: must be a positive number"),
            ),
            (
                "model = \"nh\"\ndata = [\"c1\"]\nbox = { C10 = [1.0, 2.0] }",
                format!("{at}.box: for FE models"),
            ),
            (
                "model = \"nh\"\ndata = [\"c1\"]\ndesign = 4",
                format!("{at}.design: for FE models"),
            ),
            (
                "model = \"fe\"\ndata = [\"n1\"]",
                format!("{at}.box: an FE model is sampled through a surrogate"),
            ),
            (
                "model = \"fe\"\ndata = [\"n1\", \"c1\"]\nbox = { C10 = [1.0, 2.0] }",
                format!("{at}.data: an FE model is sampled on one record"),
            ),
            (
                "model = \"fe\"\ndata = [\"n1\"]\nbox = { C10 = [1.0] }",
                format!("{at}.box.C10: expected [LO, HI], got 1 numbers"),
            ),
            (
                "model = \"nh\"\ndata = [\"c1\"]\nwalkers = 3",
                "unknown field `walkers`".to_string(),
            ),
        ] {
            let e = refusal(fields);
            assert!(e.contains(&says), "{fields}:\n{e}\nexpected: {says}");
        }
    }
}
