//! Experiment design: which of several candidate experiments would best
//! determine the parameters, before any is run (`palpate plan`, and the
//! `plan` step of a study manifest).
//!
//! The candidates are an experiment description (a file or a preset) with
//! some of its fields varied: `tool.tip_radius=1,2.5,5`,
//! `protocol.segments[0].ramp_to=2:10:5` (start:stop:count). Every
//! combination of the values is a candidate; each is checked as a
//! description is ([`Experiment::check`]: a tool larger than the specimen is
//! refused naming the field), built, and its Fisher information computed at
//! the prior guess (the description's starts, or `guess`) by
//! [`palpate_inverse::design`]: one run with the exact sensitivities of the
//! FE model. The free parameters are the description's fitted ones
//! (`{ start = .. }`); its fixed ones are held.
//!
//! ```toml
//! [[steps]]
//! [steps.plan]
//! name = "needle-design"
//! experiment = "N1"                # a preset, or a file relative to the manifest
//! vary = ["tool.tip_radius=1,2.5", "protocol.segments[0].ramp_to=2,5,10"]
//! noise = "0.002"                  # N per sample, or "1%" of each candidate's peak
//! criterion = "worst-relative"     # | d-optimal | a parameter's name
//! ```

use crate::model::experiment::{resolve, ExperimentSpec};
use crate::records::{TestData, TestKind};
use crate::run::step::{At, Run, Step, StepResult, Study};
use anyhow::{anyhow, bail, ensure, Context};
use palpate_core::fd::FdRule;
use palpate_fe::experiment::Experiment;
use palpate_inverse::design::{information, rank, Criterion, Information, Noise};
use rayon::prelude::*;
use serde::Serialize;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// One varied field and its candidate values (`FIELD=V1,V2,..` or
/// `FIELD=START:STOP:COUNT`).
#[derive(Debug, Clone, PartialEq)]
pub struct Vary {
    /// A dotted path into the description, `[i]` for a list's entry.
    pub field: String,
    pub values: Vec<Value>,
}

/// The syntax of `--vary`, for messages.
pub const VARY_SYNTAX: &str =
    "FIELD=V1,V2,.. or FIELD=START:STOP:COUNT, e.g. tool.tip_radius=1,2.5 or protocol.segments[0].ramp_to=2:10:5";

impl FromStr for Vary {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> anyhow::Result<Vary> {
        let (field, values) = s
            .split_once('=')
            .ok_or_else(|| anyhow!("`{s}`: expected {VARY_SYNTAX}"))?;
        let field = field.trim();
        ensure!(!field.is_empty(), "`{s}`: no field before `=`; expected {VARY_SYNTAX}");
        path(field).map_err(|e| anyhow!("`{s}`: {e}"))?;
        let values = values.trim();
        let parts: Vec<&str> = values.split(':').collect();
        let values: Vec<Value> = if parts.len() == 3 {
            let num = |t: &str, what: &str| -> anyhow::Result<f64> {
                t.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| anyhow!("`{s}`: {what} `{t}` is not a finite number; expected {VARY_SYNTAX}"))
            };
            let (a, b) = (num(parts[0], "start")?, num(parts[1], "stop")?);
            let n: usize = parts[2].trim().parse().ok().filter(|&n| n >= 2).ok_or_else(|| {
                anyhow!("`{s}`: count `{}` must be a whole number >= 2", parts[2].trim())
            })?;
            ensure!(n <= 1000, "`{s}`: {n} values; at most 1000");
            (0..n)
                .map(|k| number(a + (b - a) * k as f64 / (n - 1) as f64))
                .collect()
        } else {
            values
                .split(',')
                .map(|t| {
                    let t = t.trim();
                    ensure!(!t.is_empty(), "`{s}`: an empty value; expected {VARY_SYNTAX}");
                    Ok(match serde_json::from_str::<Value>(t) {
                        Ok(v @ Value::Number(_)) | Ok(v @ Value::Bool(_)) => v,
                        _ => Value::String(t.to_string()),
                    })
                })
                .collect::<anyhow::Result<_>>()?
        };
        Ok(Vary {
            field: field.to_string(),
            values,
        })
    }
}

/// A number as JSON: an integer when it is one (so that a count field
/// such as `protocol.samples` takes it).
fn number(v: f64) -> Value {
    let rounded = (v * 1e12).round() / 1e12;
    if rounded.fract() == 0.0 && rounded.abs() < 1e15 {
        Value::from(rounded as i64)
    } else {
        Value::from(v)
    }
}

/// One step of a field's path.
#[derive(Debug, Clone, PartialEq)]
enum Key {
    Name(String),
    Index(usize),
}

/// `a.b[2].c` (or `a.b.2.c`) as keys.
fn path(field: &str) -> anyhow::Result<Vec<Key>> {
    let mut keys = Vec::new();
    for part in field.split('.') {
        let (name, mut rest) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if name.is_empty() && keys.is_empty() {
            bail!("field `{field}`: starts with no name");
        }
        if !name.is_empty() {
            match name.parse::<usize>() {
                Ok(i) => keys.push(Key::Index(i)),
                Err(_) => keys.push(Key::Name(name.to_string())),
            }
        }
        while !rest.is_empty() {
            let close = rest
                .find(']')
                .ok_or_else(|| anyhow!("field `{field}`: `[` without `]`"))?;
            let i: usize = rest[1..close]
                .trim()
                .parse()
                .map_err(|_| anyhow!("field `{field}`: `{}` is not an index", &rest[1..close]))?;
            keys.push(Key::Index(i));
            rest = &rest[close + 1..];
            ensure!(
                rest.is_empty() || rest.starts_with('['),
                "field `{field}`: unexpected `{rest}`"
            );
        }
    }
    ensure!(!keys.is_empty(), "field `{field}`: empty");
    Ok(keys)
}

/// The description with `field` set to `value`, checked; errors name the
/// field (and what the description's check says about the value).
pub fn set_field(e: &Experiment, field: &str, value: &Value) -> anyhow::Result<Experiment> {
    let keys = path(field)?;
    let mut json = serde_json::to_value(e)?;
    let mut at = &mut json;
    let mut walked = String::new();
    for (i, key) in keys.iter().enumerate() {
        let last = i + 1 == keys.len();
        at = match key {
            Key::Name(n) => {
                let Value::Object(map) = at else {
                    bail!("field `{field}`: `{walked}` has no fields (it is {at})");
                };
                if !map.contains_key(n) {
                    ensure!(
                        last,
                        "field `{field}`: `{}` has no `{n}`; it has {}",
                        if walked.is_empty() { "the description" } else { &walked },
                        map.keys().cloned().collect::<Vec<_>>().join(", ")
                    );
                    // a field the description leaves at its default
                    map.insert(n.clone(), Value::Null);
                }
                walked = if walked.is_empty() {
                    n.clone()
                } else {
                    format!("{walked}.{n}")
                };
                map.get_mut(n).expect("present")
            }
            Key::Index(k) => {
                let Value::Array(list) = at else {
                    bail!("field `{field}`: `{walked}` is not a list");
                };
                let len = list.len();
                walked = format!("{walked}[{k}]");
                list.get_mut(*k).ok_or_else(|| {
                    anyhow!("field `{field}`: `{walked}` is past the end of a list of {len}")
                })?
            }
        };
    }
    *at = value.clone();
    let out: Experiment = serde_json::from_value(json)
        .map_err(|err| anyhow!("{field}={value}: not a valid value there: {err}"))?;
    out.check().map_err(|err| anyhow!("{field}={value}: {err}"))?;
    Ok(out)
}

/// One candidate: the settings that make it and its description.
#[derive(Debug, Clone)]
pub struct Candidate {
    /// `(field, value)` in the order of the varied fields.
    pub settings: Vec<(String, Value)>,
    pub experiment: Experiment,
}

impl Candidate {
    /// `field=value, ...` (`the description` when nothing is varied).
    pub fn label(&self) -> String {
        if self.settings.is_empty() {
            return "the description".into();
        }
        self.settings
            .iter()
            .map(|(f, v)| format!("{f}={}", plain(v)))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

fn plain(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// Every combination of the varied values (the first field varies
/// slowest), each checked; an error names the candidate and the field.
pub fn candidates(base: &Experiment, vary: &[Vary]) -> anyhow::Result<Vec<Candidate>> {
    let mut out = vec![Candidate {
        settings: Vec::new(),
        experiment: base.clone(),
    }];
    for v in vary {
        ensure!(!v.values.is_empty(), "{}: no values", v.field);
        let mut next = Vec::with_capacity(out.len() * v.values.len());
        for c in &out {
            for value in &v.values {
                let experiment = set_field(&c.experiment, &v.field, value).map_err(|e| {
                    if c.settings.is_empty() {
                        anyhow!("candidate {e}")
                    } else {
                        anyhow!("candidate {}, {e}", c.label())
                    }
                })?;
                let mut settings = c.settings.clone();
                settings.push((v.field.clone(), value.clone()));
                next.push(Candidate {
                    settings,
                    experiment,
                });
            }
        }
        out = next;
    }
    ensure!(
        out.len() <= 10_000,
        "{} candidates: at most 10000 (fewer values per field)",
        out.len()
    );
    Ok(out)
}

/// How to plan.
#[derive(Debug, Clone)]
pub struct PlanOptions {
    pub vary: Vec<Vary>,
    pub noise: Noise,
    pub criterion: Criterion,
    /// Prior guesses replacing the description's starts, by name.
    pub guess: Vec<(String, f64)>,
}

/// One candidate's result.
#[derive(Debug, Clone, Serialize)]
pub struct PlannedCandidate {
    /// 1 = best by the criterion.
    pub rank: usize,
    pub label: String,
    pub settings: serde_json::Map<String, Value>,
    /// The criterion's value (smaller is better; null when infinite: a
    /// parameter it needs is not identifiable).
    pub score: Option<f64>,
    pub not_identifiable: Vec<String>,
    pub information: Information,
}

/// The plan: every candidate, ranked.
#[derive(Debug, Clone, Serialize)]
pub struct Plan {
    pub experiment: String,
    pub criterion: String,
    /// What the criterion measures, in words.
    pub criterion_meaning: String,
    pub noise: String,
    /// Free parameters and their guesses.
    pub free: Vec<String>,
    pub guess: Vec<f64>,
    /// Parameters held at the description's values.
    pub fixed: Vec<(String, f64)>,
    /// Best first.
    pub candidates: Vec<PlannedCandidate>,
}

/// What a criterion measures.
pub fn criterion_meaning(c: &Criterion) -> String {
    match c {
        Criterion::WorstRelative => {
            "the largest relative standard error SE/|guess| among the free parameters".into()
        }
        Criterion::DOptimal => {
            "-ln det of the Fisher information (D-optimal: the smallest joint confidence region)"
                .into()
        }
        Criterion::Parameter(p) => format!("the standard error of {p}"),
    }
}

/// Plans over the candidates of `spec` (module doc).
pub fn plan(spec: &ExperimentSpec, options: &PlanOptions) -> anyhow::Result<Plan> {
    let source = spec.source.to_string();
    let base = &spec.experiment;
    let params = base
        .parameters()
        .map_err(|e| anyhow!("{source}: {e}"))?;
    let names: Vec<String> = params.iter().map(|p| p.spec.name.clone()).collect();
    let free: Vec<usize> = (0..params.len()).filter(|&k| params[k].fit).collect();
    if free.is_empty() {
        bail!(
            "{source}: no free parameter to plan for: every parameter is fixed ({}); give the ones to estimate as {{ start = .. }} (e.g. C10 = {{ start = 1e-3 }})",
            if names.is_empty() { "none declared".to_string() } else { names.join(", ") }
        );
    }
    let mut theta: Vec<f64> = params.iter().map(|p| p.spec.initial).collect();
    for (n, v) in &options.guess {
        let k = names.iter().position(|m| m == n).ok_or_else(|| {
            anyhow!(
                "guess {n}={v}: the experiment has no parameter `{n}`; its parameters: {}",
                names.join(", ")
            )
        })?;
        let s = &params[k].spec;
        ensure!(
            v.is_finite() && *v >= s.lower && *v <= s.upper,
            "guess {n}={v}: outside {n}'s bounds [{}, {}]",
            s.lower,
            s.upper
        );
        theta[k] = *v;
    }
    if let Criterion::Parameter(p) = &options.criterion {
        let free_names: Vec<&str> = free.iter().map(|&k| names[k].as_str()).collect();
        ensure!(
            free_names.contains(&p.as_str()),
            "criterion `{p}`: not a free parameter; free: {}; or worst-relative, d-optimal",
            free_names.join(", ")
        );
    }
    let cands = candidates(base, &options.vary)?;
    let fd = FdRule::default();
    let infos: Vec<Information> = cands
        .par_iter()
        .map(|c| {
            let built = c
                .experiment
                .model()
                .map_err(|e| anyhow!("candidate {}: {e}", c.label()))?;
            let loading = built.loading().ok_or_else(|| {
                anyhow!(
                    "{source}: its protocol is a record's; plan needs protocol.segments (e.g. [{{ ramp_to = 5.0 }}]) to know the loading"
                )
            })?;
            let model = built.as_forward();
            ensure!(
                model.space().names() == names,
                "candidate {}: its parameters {:?} differ from the description's {:?}",
                c.label(),
                model.space().names(),
                names
            );
            information(model, &theta, &loading, &free, options.noise, &fd)
                .map_err(|e| anyhow!("candidate {}: {e}", c.label()))
        })
        .collect::<anyhow::Result<_>>()?;
    let order = rank(&infos, &options.criterion).map_err(|e| anyhow!("{e}"))?;
    let candidates = order
        .iter()
        .enumerate()
        .map(|(r, &(i, score))| {
            let c = &cands[i];
            PlannedCandidate {
                rank: r + 1,
                label: c.label(),
                settings: c.settings.iter().cloned().collect(),
                score: score.is_finite().then_some(score),
                not_identifiable: infos[i].not_identifiable(),
                information: infos[i].clone(),
            }
        })
        .collect();
    Ok(Plan {
        experiment: source,
        criterion: options.criterion.to_string(),
        criterion_meaning: criterion_meaning(&options.criterion),
        noise: match options.noise {
            Noise::Sd(s) => format!("SD {s} per sample (the model's unit)"),
            Noise::FractionOfPeak(r) => format!("SD {} % of each candidate's peak", 100.0 * r),
        },
        free: free.iter().map(|&k| names[k].clone()).collect(),
        guess: free.iter().map(|&k| theta[k]).collect(),
        fixed: params
            .iter()
            .zip(&theta)
            .filter(|(p, _)| !p.fit)
            .map(|(p, &v)| (p.spec.name.clone(), v))
            .collect(),
        candidates,
    })
}

/// The noise SD of a record (`displacement_mm`, `force_N` columns, as an
/// indentation record), from its second differences
/// ([`palpate_uq::gap::difference_noise_sd`]: a smooth force curve's
/// curvature removed, so what is left is the noise).
pub fn noise_from_record(path: &Path) -> anyhow::Result<f64> {
    let d = TestData::read("noise", TestKind::N1, path)?;
    let e = palpate_uq::gap::difference_noise_sd(&d.observed, d.loading.time.as_deref())
        .map_err(|e| anyhow!("{}: {e}", path.display()))?;
    ensure!(
        e.sd > 0.0 && e.sd.is_finite(),
        "{}: the force has no noise to measure (SD {}); give the noise with a number",
        path.display(),
        e.sd
    );
    Ok(e.sd)
}

/// Parses a noise level: `0.002` (an SD in N) or `1%` (of each
/// candidate's peak force).
pub fn parse_noise(s: &str) -> anyhow::Result<Noise> {
    let t = s.trim();
    let (v, pct) = match t.strip_suffix('%') {
        Some(v) => (v.trim(), true),
        None => (t, false),
    };
    let x: f64 = v
        .parse()
        .ok()
        .filter(|x: &f64| x.is_finite() && *x > 0.0)
        .ok_or_else(|| {
            anyhow!("`{s}`: expected a positive noise SD in N (e.g. 0.002) or a percentage of the peak force (e.g. 1%)")
        })?;
    Ok(if pct {
        Noise::FractionOfPeak(x / 100.0)
    } else {
        Noise::Sd(x)
    })
}

/// The plan as a table: one row per candidate, best first.
pub fn table(p: &Plan) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(s, "experiment: {}", p.experiment);
    let guess: Vec<String> = p
        .free
        .iter()
        .zip(&p.guess)
        .map(|(n, g)| format!("{n} = {g:.6e}"))
        .collect();
    let _ = writeln!(s, "free parameters at the guess: {}", guess.join(", "));
    if !p.fixed.is_empty() {
        let fixed: Vec<String> = p.fixed.iter().map(|(n, v)| format!("{n} = {v}")).collect();
        let _ = writeln!(s, "held: {}", fixed.join(", "));
    }
    let _ = writeln!(s, "noise: {}", p.noise);
    let _ = writeln!(
        s,
        "ranked by {}: {} (smaller is better)\n",
        p.criterion, p.criterion_meaning
    );
    let label_w = p
        .candidates
        .iter()
        .map(|c| c.label.len())
        .max()
        .unwrap_or(9)
        .max(9);
    let mut head = format!("{:>4}  {:<label_w$}  {:>7}  {:>9}", "rank", "candidate", "samples", "noise SD");
    for n in &p.free {
        let _ = write!(head, "  {:>20}", format!("SE {n} (rel)"));
    }
    if p.free.len() > 1 {
        let _ = write!(head, "  {:>9}", "max|corr|");
    }
    let _ = write!(head, "  {:>10}  identifiable", "score");
    let _ = writeln!(s, "{head}");
    for c in &p.candidates {
        let i = &c.information;
        let mut row = format!(
            "{:>4}  {:<label_w$}  {:>7}  {:>9.3e}",
            c.rank, c.label, i.samples, i.noise_sd
        );
        for (se, rel) in i.standard_errors.iter().zip(&i.relative_standard_errors) {
            let cell = match (*se, *rel) {
                (Some(se), Some(r)) => format!("{se:.3e} ({:.2}%)", 100.0 * r),
                (Some(se), None) => format!("{se:.3e}"),
                _ => "-".into(),
            };
            let _ = write!(row, "  {cell:>20}");
        }
        if i.names.len() > 1 {
            let mut worst: Option<f64> = None;
            for (a, row) in i.correlation.iter().enumerate() {
                for &v in &row[a + 1..] {
                    if v.is_finite() {
                        worst = Some(worst.map_or(v.abs(), |w: f64| w.max(v.abs())));
                    }
                }
            }
            let _ = write!(
                row,
                "  {:>9}",
                worst.map_or("-".to_string(), |w| format!("{w:.4}"))
            );
        }
        let score = c.score.map_or("inf".to_string(), |v| format!("{v:.4e}"));
        let ident = if c.not_identifiable.is_empty() {
            "all".to_string()
        } else {
            format!("not {}", c.not_identifiable.join(", "))
        };
        let _ = write!(row, "  {score:>10}  {ident}");
        let _ = writeln!(s, "{row}");
    }
    s
}

/// A study step (`[[steps]] plan = {...}`): [`plan`] over a description's
/// candidates, written as `NAME.json` and a table in the report.
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanStep {
    pub name: String,
    /// A preset's name or an experiment file relative to the manifest.
    pub experiment: String,
    /// Fields varied, each `FIELD=V1,V2,..` or `FIELD=START:STOP:COUNT`.
    #[serde(default)]
    pub vary: Vec<String>,
    /// `0.002` (N) or `1%` of each candidate's peak; or `noise_from`.
    #[serde(default)]
    pub noise: Option<String>,
    /// A record (relative to the manifest) whose noise SD is estimated.
    #[serde(default)]
    pub noise_from: Option<String>,
    /// `worst-relative` (default), `d-optimal` or a parameter's name.
    #[serde(default)]
    pub criterion: Option<String>,
    /// Prior guesses replacing the description's starts.
    #[serde(default)]
    pub guess: std::collections::BTreeMap<String, f64>,
}

impl PlanStep {
    /// The description and the options; errors name the field.
    pub fn resolve(&self, dir: &Path) -> anyhow::Result<(ExperimentSpec, PlanOptions)> {
        let spec = resolve(&self.experiment, dir).context("experiment")?;
        spec.check().context("experiment")?;
        let vary = self
            .vary
            .iter()
            .map(|v| v.parse::<Vary>().context("vary"))
            .collect::<anyhow::Result<_>>()?;
        let noise = match (&self.noise, &self.noise_from) {
            (Some(n), None) => parse_noise(n).context("noise")?,
            (None, Some(f)) => Noise::Sd(noise_from_record(&dir.join(f)).context("noise_from")?),
            (Some(_), Some(_)) => bail!("noise and noise_from: give one"),
            (None, None) => bail!("noise: missing; give noise = \"0.002\" (N), \"1%\" or noise_from = \"record.csv\""),
        };
        let criterion = self
            .criterion
            .as_deref()
            .unwrap_or("worst-relative")
            .parse::<Criterion>()
            .map_err(|e| anyhow!("criterion: {e}"))?;
        Ok((
            spec,
            PlanOptions {
                vary,
                noise,
                criterion,
                guess: self.guess.iter().map(|(k, v)| (k.clone(), *v)).collect(),
            },
        ))
    }
}

impl Step for PlanStep {
    fn name(&self) -> &str {
        &self.name
    }

    fn validate(&self, study: &Study, at: &At) -> anyhow::Result<()> {
        let _ = study;
        let (spec, options) = self
            .resolve(at.dir)
            .map_err(|e| anyhow!("{}: {}.{e:#}", at.file, at.step(&self.name)))?;
        candidates(&spec.experiment, &options.vary)
            .map_err(|e| anyhow!("{}: {}.vary: {e}", at.file, at.step(&self.name)))?;
        Ok(())
    }

    fn inputs(&self) -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = self.noise_from.iter().map(PathBuf::from).collect();
        if Path::new(&self.experiment).extension().is_some() {
            v.push(PathBuf::from(&self.experiment));
        }
        v
    }

    fn run(
        &self,
        run: &Run,
        done: &[StepResult],
        report: &mut String,
    ) -> anyhow::Result<serde_json::Value> {
        use std::fmt::Write;
        let _ = done;
        let (spec, options) = self.resolve(run.manifest_dir)?;
        let inputs = (
            "plan",
            format!("{self:?}"),
            spec.experiment.to_toml(),
            crate::run::surrogate::code_version(),
        );
        let label = format!("{}: plan over {}", self.name, spec.source);
        let Some(unit): Option<PlanUnit> = run.unit(&label, &inputs, || {
            let p = plan(&spec, &options)?;
            Ok(PlanUnit {
                table: table(&p),
                result: serde_json::to_value(&p)?,
            })
        })?
        else {
            // Another shard's unit: the runner defers the step.
            return Ok(serde_json::json!({ "name": self.name.clone(), "result": Value::Null }));
        };
        let _ = writeln!(
            report,
            "## {} (experiment design)\n\n```\n{}```\n",
            self.name, unit.table
        );
        let result = unit.result;
        crate::run::output::write_atomic(
            &run.out.join(format!("{}.json", self.name)),
            serde_json::to_string_pretty(&result)?.as_bytes(),
        )?;
        Ok(serde_json::json!({ "name": self.name.clone(), "result": result }))
    }
}

/// A plan as cached: the result as JSON and its table.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
struct PlanUnit {
    result: serde_json::Value,
    table: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// N1 on its coarse mesh, a short ramp, the reduced polynomial law with
    /// C10 and C20 fitted.
    fn n1_rp2(depth: f64) -> Experiment {
        let text = Experiment::preset_toml("N1")
            .unwrap()
            .replace("law = \"neo-hookean\"", "law = \"reduced-polynomial:2\"")
            .replace(
                "C10 = { start = 1.101295e-3 }",
                "C10 = { start = 1.1e-3 }\nC20 = { start = 2e-4 }",
            )
            .replace("ramp_to = 10.0", &format!("ramp_to = {depth:?}"))
            .replace("samples = 40", "samples = 6")
            .replace("level = 2", "level = 1");
        Experiment::from_toml_str(&text, "test").unwrap()
    }

    #[test]
    fn vary_reads_lists_and_ranges_and_names_what_is_wrong() {
        let v: Vary = "tool.tip_radius=1,2.5".parse().unwrap();
        assert_eq!(v.field, "tool.tip_radius");
        assert_eq!(v.values, [Value::from(1), Value::from(2.5)]);
        let v: Vary = "protocol.segments[0].ramp_to=2:10:5".parse().unwrap();
        assert_eq!(
            v.values,
            [2, 4, 6, 8, 10].map(Value::from).to_vec(),
            "{v:?}"
        );
        let v: Vary = "tool.shape=sphere".parse().unwrap();
        assert_eq!(v.values, [Value::from("sphere")]);
        for (bad, says) in [
            ("tool.radius", "expected FIELD="),
            ("=1,2", "no field"),
            ("tool.radius=1,,2", "an empty value"),
            ("tool.radius=1:5:1", "count `1`"),
            ("tool.radius=a:5:3", "start `a`"),
            ("protocol.segments[x].ramp_to=1", "not an index"),
        ] {
            let err = bad.parse::<Vary>().unwrap_err().to_string();
            assert!(err.contains(says), "{bad}: {err}");
        }
    }

    #[test]
    fn a_field_is_set_or_refused_by_name() {
        let e = n1_rp2(2.0);
        let deeper = set_field(&e, "protocol.segments[0].ramp_to", &Value::from(3)).unwrap();
        assert_eq!(deeper.protocol.segments[0].ramp_to, Some(3.0));
        // a tool as large as the specimen: the description's check names it
        let err = set_field(&e, "tool.tip_radius", &Value::from(40.0))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("tool.tip_radius") && err.contains("as large as the specimen"),
            "{err}"
        );
        let err = set_field(&e, "tool.tip_radiuss", &Value::from(1.0))
            .unwrap_err()
            .to_string();
        assert!(err.contains("tip_radiuss"), "{err}");
        let err = set_field(&e, "tools.radius", &Value::from(1.0))
            .unwrap_err()
            .to_string();
        assert!(err.contains("has no `tools`") && err.contains("specimen"), "{err}");
        let err = set_field(&e, "protocol.segments[3].ramp_to", &Value::from(1.0))
            .unwrap_err()
            .to_string();
        assert!(err.contains("past the end of a list of 1"), "{err}");
        let err = set_field(&e, "tool.tip_radius", &Value::from("big"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("tool.tip_radius=\"big\"") && err.contains("not a valid value"), "{err}");
        // a candidate's error names the candidate
        let vary = vec![
            "mesh.level=1".parse().unwrap(),
            "tool.tip_radius=1,35".parse().unwrap(),
        ];
        let err = candidates(&e, &vary).unwrap_err().to_string();
        assert!(err.contains("candidate mesh.level=1, tool.tip_radius=35"), "{err}");
        let ok = candidates(&e, &vary[..1]).unwrap();
        assert_eq!(ok.len(), 1);
        assert_eq!(ok[0].label(), "mesh.level=1");
    }

    #[test]
    fn a_plan_without_free_parameters_says_so() {
        let text = Experiment::preset_toml("N1")
            .unwrap()
            .replace("C10 = { start = 1.101295e-3 }", "C10 = 1.1e-3");
        let e = Experiment::from_toml_str(&text, "test").unwrap();
        let options = PlanOptions {
            vary: Vec::new(),
            noise: Noise::Sd(0.01),
            criterion: Criterion::WorstRelative,
            guess: Vec::new(),
        };
        let err = plan(&ExperimentSpec::inline(e), &options)
            .unwrap_err()
            .to_string();
        assert!(err.contains("no free parameter") && err.contains("C10"), "{err}");
        let err = plan(
            &ExperimentSpec::inline(n1_rp2(2.0)),
            &PlanOptions {
                criterion: Criterion::Parameter("C30".into()),
                ..options.clone()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("criterion `C30`") && err.contains("C10, C20"), "{err}");
        let err = plan(
            &ExperimentSpec::inline(n1_rp2(2.0)),
            &PlanOptions {
                guess: vec![("C10".into(), -1.0)],
                ..options
            },
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("guess C10=-1") && err.contains("bounds"), "{err}");
        assert!(parse_noise("0").is_err());
        assert_eq!(parse_noise("1%").unwrap(), Noise::FractionOfPeak(0.01));
    }

    /// On N1 (coarse, reduced polynomial) a deeper ramp tells C20 (the
    /// large-strain term) better: its standard error falls, the ranking by
    /// C20 puts the deeper candidate first, and each candidate costs one
    /// run with exact sensitivities.
    #[test]
    fn deeper_indentation_determines_c20_better() {
        let options = PlanOptions {
            vary: vec!["protocol.segments[0].ramp_to=1,3".parse().unwrap()],
            noise: Noise::Sd(1e-3),
            criterion: Criterion::Parameter("C20".into()),
            guess: Vec::new(),
        };
        let p = plan(&ExperimentSpec::inline(n1_rp2(1.0)), &options).unwrap();
        assert_eq!(p.free, ["C10", "C20"]);
        assert_eq!(p.candidates.len(), 2);
        let best = &p.candidates[0];
        assert_eq!(best.label, "protocol.segments[0].ramp_to=3", "{}", table(&p));
        let se = |c: &PlannedCandidate, j: usize| c.information.standard_errors[j].unwrap();
        assert!(se(best, 1) < se(&p.candidates[1], 1), "{}", table(&p));
        for c in &p.candidates {
            assert_eq!(c.information.runs, 1);
            assert_eq!(
                c.information.jacobian,
                palpate_inverse::design::JacobianSource::Exact
            );
            assert!(c.not_identifiable.is_empty(), "{}", table(&p));
        }
        let text = table(&p);
        assert!(text.contains("SE C20 (rel)") && text.contains("max|corr|"), "{text}");
        let json = serde_json::to_value(&p).unwrap();
        assert_eq!(json["candidates"][0]["rank"], 1);
    }
}
