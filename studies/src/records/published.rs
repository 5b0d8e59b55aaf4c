//! Published tables of fitted parameters, read into palpate's laws and
//! conventions so that a fit can be compared with them like for like.
//!
//! One format is known: the phantom database of Dawood et al. 2026
//! (`hyperelastic_parameters.json`: `{measure: {material: {law: {parameters,
//! S, SSE, AIC, order, stress_unit}}}}`, measure `engineering` or `true`,
//! stresses in kPa). Its laws and parameter conventions, identified by
//! evaluating its parameters on its own data (docs/validation/laws/README.md,
//! docs/validation/phantom-database.md), in palpate's terms:
//!
//! | database | parameters | palpate |
//! |---|---|---|
//! | `Neo Hookean` | `[mu]` | `neo-hookean`, `C10 = mu / 2` |
//! | `Mooney Rivlin_o1` | `[C10, C01]` | `mooney-rivlin` |
//! | `Mooney Rivlin_o2` | `[C10, C01, C20]` | none (W1 = C10 + 2 C20 (I1 - 3), W2 = C01) |
//! | `Yeoh_oN` | `[C10 ... CN0]` | `reduced-polynomial:N` |
//! | `Ogden_oN` | `[mu_1..mu_N, alpha_1..alpha_N]`, `W = sum mu_i / alpha_i (...)` | `ogden:N`, `mu_i' = mu_i alpha_i / 2` (palpate's `W = sum 2 mu_i / alpha_i^2 (...)`) |
//! | `Veronda Westmann` | `[C1, C2]` | `veronda-westmann` |
//! | `Humphrey` | `[C1, C2]` | `humphrey` |
//!
//! Its `SSE` is the sum of squared residuals in kPa^2 over the `n` points
//! of the curve it fitted, `S = sqrt(SSE / (n - k - 1))` and
//! `AIC = n ln(SSE / n) + 2 k` with `k` parameters (`n` = 1000 for every
//! material of the database).

use anyhow::Context;
use palpate_material::Law;
use serde::Serialize;
use std::path::Path;

/// One published fit.
#[derive(Debug, Clone, Serialize)]
pub struct PublishedFit {
    /// The law as the table names it (`Ogden_o2`).
    pub name: String,
    /// palpate's law, `None` when palpate has no such law.
    #[serde(serialize_with = "law_text")]
    pub law: Option<Law>,
    /// The parameters as published (the table's units and order).
    pub published: Vec<f64>,
    /// The parameters in palpate's convention and order, MPa (`None` with
    /// `law`).
    pub params: Option<Vec<f64>>,
    /// Sum of squared residuals, in the table's stress unit squared.
    pub sse: f64,
    pub aic: Option<f64>,
    /// The table's stress unit, in MPa per unit (kPa: 1e-3).
    pub stress_unit: f64,
}

fn law_text<S: serde::Serializer>(law: &Option<Law>, s: S) -> Result<S::Ok, S::Error> {
    match law {
        Some(l) => s.serialize_str(&l.to_string()),
        None => s.serialize_none(),
    }
}

/// The published formats.
pub const FORMATS: [&str; 1] = ["dawood2026"];

/// Reads the fits a published table gives for `material` under `measure`
/// (`engineering` or `true`), in the table's order. `format` is one of
/// [`FORMATS`]. Errors name the file and say which materials or measures
/// the table has.
pub fn read(
    path: &Path,
    format: &str,
    material: &str,
    measure: &str,
) -> anyhow::Result<Vec<PublishedFit>> {
    anyhow::ensure!(
        FORMATS.contains(&format),
        "published table format `{format}`: unknown; expected one of {}",
        FORMATS.join(", ")
    );
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read the published table", path.display()))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let measures = json
        .as_object()
        .with_context(|| format!("{}: expected an object of measures", path.display()))?;
    let by_material = measures
        .get(measure)
        .and_then(|m| m.as_object())
        .with_context(|| {
            format!(
                "{}: no measure `{measure}` (it has {})",
                path.display(),
                measures.keys().cloned().collect::<Vec<_>>().join(", ")
            )
        })?;
    let laws = by_material
        .get(material)
        .and_then(|m| m.as_object())
        .with_context(|| {
            let names: Vec<&str> = by_material.keys().map(String::as_str).collect();
            format!(
                "{}: no material `{material}` under `{measure}` (it has {})",
                path.display(),
                names.join(", ")
            )
        })?;
    let mut out = Vec::new();
    for (name, entry) in laws {
        let at = || format!("{}: {measure}.{material}.\"{name}\"", path.display());
        let published: Vec<f64> = entry
            .get("parameters")
            .and_then(|p| p.as_array())
            .with_context(|| format!("{}: no `parameters` list", at()))?
            .iter()
            .map(|v| v.as_f64())
            .collect::<Option<_>>()
            .with_context(|| format!("{}: `parameters` are not all numbers", at()))?;
        let sse = entry
            .get("SSE")
            .and_then(|v| v.as_f64())
            .with_context(|| format!("{}: no number `SSE`", at()))?;
        let aic = entry.get("AIC").and_then(|v| v.as_f64());
        let stress_unit = match entry.get("stress_unit").and_then(|v| v.as_str()) {
            None | Some("kPa") => 1e-3,
            Some("MPa") => 1.0,
            Some("Pa") => 1e-6,
            Some(u) => anyhow::bail!("{}: stress_unit `{u}`: expected kPa, MPa or Pa", at()),
        };
        let (law, params) = dawood_law(name, &published, stress_unit)
            .with_context(at)?
            .map_or((None, None), |(l, p)| (Some(l), Some(p)));
        out.push(PublishedFit {
            name: name.clone(),
            law,
            published,
            params,
            sse,
            aic,
            stress_unit,
        });
    }
    Ok(out)
}

/// A law of the Dawood 2026 table in palpate's terms (module table);
/// `Ok(None)` for a law palpate does not have.
fn dawood_law(name: &str, p: &[f64], unit: f64) -> anyhow::Result<Option<(Law, Vec<f64>)>> {
    let count = |n: usize| -> anyhow::Result<()> {
        anyhow::ensure!(
            p.len() == n,
            "{} parameters where this law has {n}",
            p.len()
        );
        Ok(())
    };
    let order =
        |prefix: &str| -> Option<usize> { name.strip_prefix(prefix).and_then(|n| n.parse().ok()) };
    let out = if name == "Neo Hookean" {
        count(1)?;
        Some((Law::NeoHookean, vec![p[0] / 2.0 * unit]))
    } else if name == "Mooney Rivlin_o1" {
        count(2)?;
        Some((Law::MooneyRivlin, vec![p[0] * unit, p[1] * unit]))
    } else if name.starts_with("Mooney Rivlin_o") {
        None
    } else if let Some(n) = order("Yeoh_o") {
        count(n)?;
        Some((
            Law::ReducedPolynomial(n),
            p.iter().map(|c| c * unit).collect(),
        ))
    } else if let Some(n) = order("Ogden_o") {
        count(2 * n)?;
        let (mu, alpha) = p.split_at(n);
        let params = mu
            .iter()
            .zip(alpha)
            .flat_map(|(m, a)| [m * a / 2.0 * unit, *a])
            .collect();
        Some((Law::Ogden(n), params))
    } else if name == "Veronda Westmann" {
        count(2)?;
        Some((Law::VerondaWestmann, vec![p[0] * unit, p[1]]))
    } else if name == "Humphrey" {
        count(2)?;
        Some((Law::Humphrey, vec![p[0] * unit, p[1]]))
    } else {
        None
    };
    Ok(out)
}

/// The database's AIC of a fit with `k` parameters and sum of squares
/// `sse` over `n` points: `n ln(sse / n) + 2 k`.
pub fn aic(sse: f64, n: usize, k: usize) -> f64 {
    let n = n as f64;
    n * (sse / n).ln() + 2.0 * k as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conventions_convert_to_palpate() {
        let (l, p) = dawood_law("Neo Hookean", &[20.0], 1e-3).unwrap().unwrap();
        assert_eq!(l, Law::NeoHookean);
        assert!((p[0] - 0.01).abs() < 1e-15);
        let (l, p) = dawood_law("Ogden_o2", &[1.0, 2.0, 4.0, -2.0], 1e-3)
            .unwrap()
            .unwrap();
        assert_eq!(l, Law::Ogden(2));
        // mu_i alpha_i / 2, interleaved with alpha_i
        let want = [2e-3, 4.0, -2e-3, -2.0];
        for (a, b) in p.iter().zip(want) {
            assert!((a - b).abs() < 1e-15, "{p:?}");
        }
        assert!(dawood_law("Mooney Rivlin_o2", &[1.0, 2.0, 3.0], 1e-3)
            .unwrap()
            .is_none());
        let e = dawood_law("Yeoh_o3", &[1.0, 2.0], 1e-3).unwrap_err();
        assert!(
            e.to_string().contains("2 parameters where this law has 3"),
            "{e}"
        );
    }

    /// The database's own AIC of its EF10_0T neo-Hookean fit.
    #[test]
    fn aic_is_the_databases() {
        let a = aic(169_811.882_924_829_73, 1000, 1);
        assert!((a - 5_136.691_253_318_085).abs() < 1e-9, "{a}");
    }
}
