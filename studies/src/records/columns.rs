//! The columns of a homogeneous-test data file: which deformation measure
//! and which stress a file gives, in which unit, turned into the stretch (or
//! amount of shear) and the nominal stress in MPa that the models predict.
//!
//! Conventions (docs/guide/installing-and-data.md, "Homogeneous tests"):
//!
//! * deformation: `stretch` (lambda), `strain` (engineering, lambda = 1 + e)
//!   or `true_strain` (logarithmic, lambda = exp(e)); general biaxial
//!   `lambda1`, `lambda2` (or `stretch1`/`stretch2`, `strain1`/`strain2`);
//!   simple shear `amount_of_shear` (or `shear_strain`, the same gamma);
//! * stress: nominal (first Piola, force over undeformed area) `stress_MPa`,
//!   `nominal_stress_MPa`, `stress1_MPa`/`stress2_MPa`, `shear_stress_MPa`;
//!   true (Cauchy) `true_stress_MPa` (= `cauchy_stress_MPa`),
//!   `true_stress1_MPa`, `true_shear_stress_MPa`. Units `_MPa`, `_kPa` or
//!   `_Pa`; converted to nominal MPa with `P = sigma / lambda` along the
//!   loading direction (incompressible), `P12 = sigma12 / lambda_axial`.
//!
//! When a file gives the same quantity twice (stretch and strain, nominal
//! and true stress, MPa and kPa), the columns must agree row by row: a
//! disagreement is an error naming the file, line and column (the usual
//! cause is a mislabelled unit).

use crate::records::TestKind;
use palpate_core::data::Table;
use palpate_core::Drive;

/// The deformation and stress of a homogeneous record, ready for a model.
#[derive(Debug, Clone)]
pub struct Homogeneous {
    /// The test, possibly refined from the columns (`biaxial` with two
    /// stretch columns is general biaxial).
    pub test: TestKind,
    pub drive_kind: Drive,
    /// Stretch (or amount of shear) per sample; general biaxial: pairs.
    pub drive: Vec<f64>,
    /// Nominal stress in MPa per sample.
    pub stress: Vec<f64>,
    /// Source line of each sample (general biaxial: each line twice).
    pub lines: Vec<usize>,
    /// The columns used, for reports: e.g. `strain -> stretch`, `true_stress_MPa -> nominal`.
    pub used: Vec<String>,
}

/// A stress column: its quantity and unit factor to MPa.
struct StressColumn {
    name: String,
    /// `true`: Cauchy stress; `false`: nominal.
    true_stress: bool,
    to_mpa: f64,
}

const UNITS: [(&str, f64); 3] = [("MPa", 1.0), ("kPa", 1e-3), ("Pa", 1e-6)];

/// Splits `base_UNIT` into `(base, factor to MPa)`; `None` when the suffix
/// is not a known stress unit.
fn unit_of(name: &str) -> Option<(&str, f64)> {
    UNITS
        .iter()
        .find_map(|(u, f)| name.strip_suffix(u)?.strip_suffix('_').map(|b| (b, *f)))
}

/// Stress columns of `table` whose base name is one of `nominal` or `true_`
/// (e.g. `["stress", "nominal_stress"]`, `["true_stress", "cauchy_stress"]`).
fn stress_columns(
    table: &Table,
    nominal: &[&str],
    true_: &[&str],
    unit_override: Option<f64>,
) -> anyhow::Result<Vec<StressColumn>> {
    let mut out = Vec::new();
    for name in &table.names {
        let all = nominal.iter().chain(true_);
        if let Some((base, f)) = unit_of(name) {
            if nominal.contains(&base) || true_.contains(&base) {
                out.push(StressColumn {
                    name: name.clone(),
                    true_stress: true_.contains(&base),
                    to_mpa: unit_override.unwrap_or(f),
                });
            }
        } else if let Some(b) = all.into_iter().find(|b| {
            name.as_str() == **b || (name.starts_with(**b) && name[b.len()..].starts_with('_'))
        }) {
            anyhow::bail!(
                "{}:{}: column `{name}`: a stress needs its unit in the name: `{b}_MPa`, `{b}_kPa` or `{b}_Pa`",
                table.file.display(),
                table.header_line,
            );
        }
    }
    Ok(out)
}

/// Relative agreement required between two columns of the same quantity
/// (1 %, plus 0.2 % of the column's largest magnitude for values near zero,
/// where digitised or offset-corrected records disagree in sign).
fn agree(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 0.01 * a.abs().max(b.abs()) + 2e-3 * scale
}

/// Checks that two derived columns agree; the error names the second column.
fn check_agree(
    table: &Table,
    first: (&str, &[f64]),
    second: (&str, &[f64]),
    what: &str,
) -> anyhow::Result<()> {
    let scale = first.1.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (k, (a, b)) in first.1.iter().zip(second.1).enumerate() {
        if !agree(*a, *b, scale) {
            anyhow::bail!(
                "{}:{}: column `{}` gives {what} {b}, column `{}` gives {a}: the two columns disagree \
                 (inconsistent units or conventions?); keep one of them or correct the unit in its name",
                table.file.display(),
                table.lines[k],
                second.0,
                first.0,
            );
        }
    }
    Ok(())
}

/// Turns a deformation column's value into a stretch.
type ToStretch = fn(f64) -> f64;

/// One stretch from whichever of `stretch`, `strain`, `true_strain` (with
/// the given suffix, e.g. `1`) the table has; all present must agree.
fn stretch_from(table: &Table, suffix: &str, alt: &[&str]) -> anyhow::Result<(String, Vec<f64>)> {
    let mut found: Vec<(String, Vec<f64>)> = Vec::new();
    let candidates: Vec<(String, ToStretch)> = [
        (format!("stretch{suffix}"), (|v| v) as fn(f64) -> f64),
        (format!("strain{suffix}"), |v| 1.0 + v),
        (format!("true_strain{suffix}"), |v: f64| v.exp()),
    ]
    .into_iter()
    .chain(
        alt.iter()
            .map(|a| (a.to_string(), (|v| v) as fn(f64) -> f64)),
    )
    .collect();
    for (name, to_stretch) in &candidates {
        if table.has(name) {
            let v: Vec<f64> = table.column(name)?.iter().map(|&x| to_stretch(x)).collect();
            if let Some(k) = v.iter().position(|&s| s.is_nan() || s <= 0.0) {
                let raw = table.column(name)?[k];
                anyhow::bail!(
                    "{}:{}: column `{name}`: {raw} gives the stretch {}; a stretch must be positive (the specimen cannot be compressed to zero length)",
                    table.file.display(),
                    table.lines[k],
                    v[k]
                );
            }
            found.push((name.clone(), v));
        }
    }
    let Some(first) = found.first().cloned() else {
        anyhow::bail!(
            "{}:{}: no deformation column: expected `stretch{suffix}`, `strain{suffix}` or `true_strain{suffix}`{} (header has: {})",
            table.file.display(),
            table.header_line,
            if alt.is_empty() { String::new() } else { format!(" or `{}`", alt.join("`, `")) },
            table.names.join(",")
        );
    };
    for other in &found[1..] {
        check_agree(
            table,
            (&first.0, &first.1),
            (&other.0, &other.1),
            "the stretch",
        )?;
    }
    Ok(first)
}

/// Nominal stress in MPa from the stress columns (all must agree); `lambda`
/// converts a true stress (`P = sigma / lambda`).
fn nominal_stress(
    table: &Table,
    columns: &[StressColumn],
    lambda: &[f64],
    expected: &str,
) -> anyhow::Result<(String, Vec<f64>)> {
    let mut found: Vec<(String, Vec<f64>)> = Vec::new();
    for c in columns {
        let raw = table.column(&c.name)?;
        let v: Vec<f64> = raw
            .iter()
            .zip(lambda)
            .map(|(&s, &l)| {
                let s = s * c.to_mpa;
                if c.true_stress {
                    s / l
                } else {
                    s
                }
            })
            .collect();
        found.push((c.name.clone(), v));
    }
    let Some(first) = found.first().cloned() else {
        anyhow::bail!(
            "{}:{}: no stress column: expected {expected} (header has: {})",
            table.file.display(),
            table.header_line,
            table.names.join(",")
        );
    };
    for other in &found[1..] {
        check_agree(
            table,
            (&first.0, &first.1),
            (&other.0, &other.1),
            "the nominal stress (MPa)",
        )?;
    }
    Ok(first)
}

/// Refuses columns of another test kind (e.g. a stretch in a shear file).
fn refuse(table: &Table, names: &[&str], why: &str) -> anyhow::Result<()> {
    if let Some(n) = table.names.iter().find(|n| names.contains(&n.as_str())) {
        anyhow::bail!(
            "{}:{}: column `{n}`: {why} (header has: {})",
            table.file.display(),
            table.header_line,
            table.names.join(",")
        );
    }
    Ok(())
}

/// Reads the deformation and stress of a homogeneous record of `test`.
/// `stress_unit` overrides the unit written in the stress columns' names
/// (a file whose header is known to be wrong; `None`: as named).
pub fn read(
    table: &Table,
    test: TestKind,
    axial_stretch: f64,
    stress_unit: Option<f64>,
) -> anyhow::Result<Homogeneous> {
    let two_stretches = ["lambda1", "stretch1", "strain1", "true_strain1"]
        .iter()
        .any(|c| table.has(c));
    let test = match test {
        TestKind::Homogeneous(palpate_analytic::Mode::Equibiaxial) if two_stretches => {
            TestKind::GeneralBiaxial
        }
        t => t,
    };
    match test {
        TestKind::SimpleShear => {
            refuse(
                table,
                &["stretch", "strain", "true_strain", "lambda1", "lambda2", "stress_MPa"],
                "a simple-shear file gives the amount of shear (`amount_of_shear`) and the shear stress \
                 (`shear_stress_MPa`); a shear superposed on an axial stretch states that stretch as \
                 `simple_shear[axial_stretch=L]=FILE` (manifest: `axial_stretch = L`), not as a column",
            )?;
            let gamma_col = ["amount_of_shear", "shear_strain"]
                .into_iter()
                .find(|c| table.has(c))
                .ok_or_else(|| {
                    anyhow::anyhow!(
                        "{}:{}: no deformation column: a simple-shear file needs `amount_of_shear` (or `shear_strain`) (header has: {})",
                        table.file.display(),
                        table.header_line,
                        table.names.join(",")
                    )
                })?;
            let gamma = table.column(gamma_col)?.to_vec();
            let cols = stress_columns(
                table,
                &["shear_stress", "nominal_shear_stress"],
                &["true_shear_stress", "cauchy_shear_stress"],
                stress_unit,
            )?;
            let lam = vec![axial_stretch; gamma.len()];
            let (scol, stress) = nominal_stress(
                table,
                &cols,
                &lam,
                "`shear_stress_MPa` (nominal) or `true_shear_stress_MPa`",
            )?;
            Ok(Homogeneous {
                test,
                drive_kind: Drive::AmountOfShear,
                drive: gamma,
                stress,
                lines: table.lines.clone(),
                used: vec![gamma_col.into(), scol],
            })
        }
        TestKind::GeneralBiaxial => {
            refuse(
                table,
                &["amount_of_shear"],
                "a biaxial file has no amount of shear",
            )?;
            let (c1, l1) = stretch_from(table, "1", &["lambda1"])?;
            let (c2, l2) = stretch_from(table, "2", &["lambda2"])?;
            let s1 = stress_columns(
                table,
                &["stress1", "nominal_stress1"],
                &["true_stress1", "cauchy_stress1"],
                stress_unit,
            )?;
            let s2 = stress_columns(
                table,
                &["stress2", "nominal_stress2"],
                &["true_stress2", "cauchy_stress2"],
                stress_unit,
            )?;
            let (sc1, p1) = nominal_stress(
                table,
                &s1,
                &l1,
                "`stress1_MPa` (nominal) or `true_stress1_MPa`",
            )?;
            let (sc2, p2) = nominal_stress(
                table,
                &s2,
                &l2,
                "`stress2_MPa` (nominal) or `true_stress2_MPa`",
            )?;
            let n = l1.len();
            let mut drive = Vec::with_capacity(2 * n);
            let mut stress = Vec::with_capacity(2 * n);
            let mut lines = Vec::with_capacity(2 * n);
            for k in 0..n {
                drive.extend([l1[k], l2[k]]);
                stress.extend([p1[k], p2[k]]);
                lines.extend([table.lines[k], table.lines[k]]);
            }
            Ok(Homogeneous {
                test,
                drive_kind: Drive::Stretch,
                drive,
                stress,
                lines,
                used: vec![c1, c2, sc1, sc2],
            })
        }
        TestKind::Homogeneous(mode) => {
            refuse(
                table,
                &["amount_of_shear", "shear_stress_MPa"],
                &format!("a {mode} file has a stretch and a normal stress; this looks like a simple-shear record (--data simple_shear=FILE)"),
            )?;
            let (c, stretch) = stretch_from(table, "", &[])?;
            let cols = stress_columns(
                table,
                &["stress", "nominal_stress"],
                &["true_stress", "cauchy_stress"],
                stress_unit,
            )?;
            let (sc, stress) = nominal_stress(
                table,
                &cols,
                &stretch,
                "`stress_MPa` (nominal) or `true_stress_MPa`",
            )?;
            Ok(Homogeneous {
                test,
                drive_kind: Drive::Stretch,
                drive: stretch,
                stress,
                lines: table.lines.clone(),
                used: vec![c, sc],
            })
        }
        TestKind::C1 | TestKind::N1 => unreachable!("force records are not homogeneous tests"),
    }
}
