//! The model the options of a benchmark run describe, and the refusal of
//! another benchmark's options by name.

use anyhow::{anyhow, bail};

use super::SimulateOptions;
use crate::model::{
    parse_setting, C1FeSpec, Mesh, ModelSpec, N1NeedleSpec, N3NeedleSpec, Q1Spec, R2Spec, Setting,
};

/// The model the options describe: N1 -> `n1_needle`, N3 -> `n3_needle`,
/// C1 -> `c1_fe`, Q1 -> `q1`; an option of another benchmark is refused by name, since it
/// would be neither used nor visible in the result.
pub fn model_spec(o: &SimulateOptions) -> anyhow::Result<ModelSpec> {
    let kind = if o.is_q1() {
        "Q1"
    } else if o.benchmark().eq_ignore_ascii_case("r2") {
        "R2"
    } else if o.benchmark().eq_ignore_ascii_case("n3") {
        "N3"
    } else if o.benchmark().eq_ignore_ascii_case("n1") {
        "N1"
    } else {
        "C1"
    };
    // (option, value shown, the benchmarks that use it)
    let options: [(bool, &str, String, &[&str]); 14] = [
        (
            o.rd.is_some(),
            "--rd",
            o.rd.map(|f| f.to_string()).unwrap_or_default(),
            &["R2"],
        ),
        (
            o.nodules.is_some(),
            "--nodules",
            o.nodules.clone().unwrap_or_default(),
            &["R2"],
        ),
        (
            o.nodule_law.is_some(),
            "--nodule-law",
            o.nodule_law.clone().unwrap_or_default(),
            &["R2"],
        ),
        (
            !o.nodule_params.is_empty(),
            "--nodule-param",
            o.nodule_params
                .iter()
                .map(|(n, v)| format!("{n}={v}"))
                .collect::<Vec<_>>()
                .join(" "),
            &["R2"],
        ),
        (
            o.depth.is_some(),
            "--depth",
            format!("{:?}", o.depth.unwrap_or(0.0)),
            &["N1", "N3", "C1", "Q1"],
        ),
        (o.bonded, "--bonded", String::new(), &["C1"]),
        (
            o.prony.is_some(),
            "--prony",
            o.prony.clone().unwrap_or_default(),
            &["N1", "C1", "Q1"],
        ),
        (
            o.ramp.is_some(),
            "--ramp",
            format!("{:?}", o.ramp.unwrap_or(0.0)),
            &["N1", "C1", "Q1"],
        ),
        (
            o.hold.is_some(),
            "--hold",
            format!("{:?}", o.hold.unwrap_or(0.0)),
            &["N1", "C1", "Q1"],
        ),
        (
            o.friction.is_some(),
            "--friction",
            o.friction.map(|f| f.to_string()).unwrap_or_default(),
            &["N1", "N3", "R2"],
        ),
        (o.sliding_base, "--sliding-base", String::new(), &["N1"]),
        (
            o.tool.is_some(),
            "--tool",
            o.tool.clone().unwrap_or_default(),
            &["N1", "N3"],
        ),
        (
            o.element.is_some(),
            "--element",
            o.element.clone().unwrap_or_default(),
            &["N1", "Q1", "N3"],
        ),
        (
            o.edge_radius.is_some(),
            "--edge-radius",
            format!("{:?}", o.edge_radius.unwrap_or(0.0)),
            &["Q1"],
        ),
    ];
    if let Some((_, name, value, users)) = options
        .iter()
        .find(|(given, _, _, users)| *given && !users.contains(&kind))
    {
        bail!(
            "{name}{}{value}: an option of benchmark {}; --benchmark {kind} does not use it",
            if value.is_empty() { "" } else { " " },
            users.join(" and ")
        );
    }
    // a setting's text parsed, the error naming the option (`--mesh 0: ...`)
    fn opt<T: Setting>(text: &Option<String>) -> anyhow::Result<Option<T>> {
        parse_setting::<T>("simulate", text.as_deref()).map_err(|e| anyhow!("{}", e.as_option()))
    }
    if kind == "R2" {
        let rd = o.rd.ok_or_else(|| {
            anyhow!("--benchmark R2 needs --rd RD (the rolling depth in mm, e.g. 6)")
        })?;
        return Ok(ModelSpec::R2(R2Spec {
            law: o.law.clone().unwrap_or_else(|| "arruda-boyce".into()),
            nodule_law: o.nodule_law.clone(),
            rd,
            nodules: opt(&o.nodules)?,
            friction: o.friction,
            mesh: opt::<Mesh>(&o.mesh)?,
            bulk: opt(&o.bulk)?,
        }));
    }
    let law = o
        .law
        .clone()
        .ok_or_else(|| anyhow!("--benchmark {kind} needs --law (e.g. --law neo-hookean)"))?;
    Ok(if kind == "Q1" {
        ModelSpec::Q1(Q1Spec {
            law: law.clone(),
            mesh: opt::<Mesh>(&o.mesh)?,
            bulk: opt(&o.bulk)?,
            element: opt(&o.element)?,
            prony: opt(&o.prony)?,
            edge_radius: o.edge_radius,
        })
    } else if kind == "N3" {
        ModelSpec::N3Needle(N3NeedleSpec {
            law: law.clone(),
            friction: o.friction,
            mesh: opt::<Mesh>(&o.mesh)?,
            bulk: opt(&o.bulk)?,
            tool: opt(&o.tool)?,
            element: opt(&o.element)?,
        })
    } else if kind == "N1" {
        ModelSpec::N1Needle(N1NeedleSpec {
            law: law.clone(),
            friction: o.friction,
            mesh: opt::<Mesh>(&o.mesh)?,
            bulk: opt(&o.bulk)?,
            base: o.sliding_base.then_some(palpate_fe::Support::Sliding),
            tool: opt(&o.tool)?,
            element: opt(&o.element)?,
            prony: opt(&o.prony)?,
        })
    } else {
        ModelSpec::C1Fe(C1FeSpec {
            law,
            platens: o.bonded.then_some(palpate_fe::Platens::Bonded),
            mesh: opt::<Mesh>(&o.mesh)?,
            bulk: opt(&o.bulk)?,
            prony: opt(&o.prony)?,
        })
    })
}
