//! Sign conventions of records, and how a file's are turned into palpate's.
//!
//! palpate's conventions (docs/guide/installing-and-data.md, "Sign
//! conventions"):
//!
//! * homogeneous tests: strains and stresses are **negative in
//!   compression** (a stretch below 1, a nominal stress below 0), positive
//!   in tension;
//! * force records (a tool or platen pressing on a specimen): the
//!   displacement into the body and the reaction force are **positive in
//!   compression**.
//!
//! Testing machines write compression either way. The `compression` option
//! of a record ([`Compression`]) says how its file writes it, or only that
//! the record is a compression test (`yes`); without it, the record's sign
//! is read from its data. Strain and stress both negative: compression.
//! Both positive: tension, unless the file says it is a compression test
//! (a metadata line or a column named `Compression`) and its curve
//! stiffens as every elastomer's does in compression ([`Bend`]): then
//! compression written positive, converted, and the report says why. A
//! file that says compression but whose curve does not tell is refused as
//! ambiguous, naming the option to set. A record whose data contradict the
//! declared convention is refused: strain and stress of the wrong sign, a
//! declared compression with a strain of 1 or more, or one whose curve
//! softens as the strain grows, as a tension test's does.

use super::machine::Metadata;
use super::TestKind;
use palpate_core::data::{Column, Table};

/// How a file writes compression (the `compression` option of a record).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compression {
    /// Strains and stresses negative in compression (palpate's own for
    /// homogeneous tests); displacement and force negative (the opposite of
    /// palpate's for force records).
    Negative,
    /// Strains and stresses positive in compression (converted); for force
    /// records, palpate's own.
    Positive,
    /// The record is a tension test: positive strains and stresses.
    None,
    /// The record is a compression test, whichever sign its file writes
    /// (read from the data; refused when the curve softens as a tension
    /// test's does).
    Yes,
}

impl Compression {
    /// Parses `negative`, `positive` or `none` (a tension test).
    pub fn parse(s: &str) -> anyhow::Result<Compression> {
        match s.trim().to_ascii_lowercase().as_str() {
            "negative" => Ok(Compression::Negative),
            "positive" => Ok(Compression::Positive),
            "none" | "tension" => Ok(Compression::None),
            "yes" => Ok(Compression::Yes),
            other => anyhow::bail!(
                "compression `{other}`: expected negative (the file writes compression as negative strain and stress), \
                 positive (as positive values), yes (a compression test, whichever sign: read from the data) or none \
                 (a tension test)"
            ),
        }
    }

    /// The option's value (`negative`, `positive`, `none`, `yes`).
    pub fn key(self) -> &'static str {
        match self {
            Compression::Negative => "negative",
            Compression::Positive => "positive",
            Compression::None => "none",
            Compression::Yes => "yes",
        }
    }
}

/// How a homogeneous record's curve bends: twice the area under the
/// stress-strain curve of its loading (up to the largest strain) over the
/// triangle of that end point, magnitudes only. Below 1 the curve stiffens
/// (every elastomer in compression: a neo-Hookean solid gives 0.96 at 10 %
/// compression, 0.53 at 67 %), above 1 it softens (rubber in moderate
/// tension: 1.03 at 10 %, 1.12 at 67 %). Tissues in tension stiffen too,
/// so stiffening alone never makes a record a compression test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bend {
    /// The area ratio.
    pub ratio: f64,
    /// The largest strain magnitude.
    pub strain: f64,
}

impl Bend {
    /// Softer than this ratio: softens as tension does (a neo-Hookean
    /// solid stretched by 20 % gives 1.05).
    const SOFTENS: f64 = 1.05;
    /// Stiffer than this ratio: stiffens as compression does (neo-Hookean
    /// at 8 % compression).
    const STIFFENS: f64 = 0.97;

    /// The bend of the signed strains `e` and stresses `p` (one row each);
    /// `None` when the record does not leave zero.
    pub fn of(e: &[f64], p: &[f64]) -> Option<Bend> {
        let (k, e_max) = extreme(e);
        let mut pts: Vec<(f64, f64)> = e[..=k]
            .iter()
            .zip(&p[..=k])
            .map(|(e, p)| (e.abs(), p.abs()))
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let end = p[k].abs();
        if e_max == 0.0 || end == 0.0 {
            return None;
        }
        // The trapezoidal rule: a closed form, no quadrature crate needed.
        let area: f64 = pts
            .windows(2)
            .map(|w| 0.5 * (w[1].0 - w[0].0) * (w[1].1 + w[0].1))
            .sum();
        Some(Bend {
            ratio: 2.0 * area / (e_max.abs() * end),
            strain: e_max.abs(),
        })
    }

    fn softens(&self) -> bool {
        self.ratio > Self::SOFTENS
    }

    fn stiffens(&self) -> bool {
        self.ratio < Self::STIFFENS
    }

    /// `area ratio 0.42 to strain 0.67` for messages and reports.
    pub fn describe(&self) -> String {
        format!(
            "area ratio {:.2} to strain {:.3}, 1 for a straight line",
            self.ratio, self.strain
        )
    }
}

/// The row of largest magnitude of `v`, and that value.
fn extreme(v: &[f64]) -> (usize, f64) {
    v.iter().enumerate().fold(
        (0, 0.0),
        |(k, m), (i, &x)| if x.abs() > m.abs() { (i, x) } else { (k, m) },
    )
}

/// Why the file may be a compression test: a metadata line or a column name.
fn compression_evidence(table: &Table, meta: &Metadata, header: &[String]) -> Option<String> {
    if let Some(e) = meta
        .mentions("compression")
        .or_else(|| meta.mentions("compressive"))
    {
        let text = if e.value.is_empty() {
            e.key.clone()
        } else {
            format!("{}: {}", e.key, e.value)
        };
        return Some(format!("line {} says `{text}`", e.line));
    }
    header
        .iter()
        .chain(&table.names)
        .find(|h| {
            let h = h.to_ascii_lowercase();
            h.contains("compression") || h.contains("compressive")
        })
        .map(|h| format!("it has a column `{h}`"))
}

/// Names of the strain and stress columns of a homogeneous table (palpate
/// names), in the order [`super::columns`] prefers them.
fn strain_and_stress(table: &Table) -> (Vec<String>, Vec<String>) {
    let strain = ["strain", "true_strain"]
        .iter()
        .filter(|n| table.has(n))
        .map(|n| n.to_string())
        .collect();
    let stress = table
        .names
        .iter()
        .filter(|n| {
            [
                "stress_",
                "true_stress_",
                "nominal_stress_",
                "cauchy_stress_",
            ]
            .iter()
            .any(|p| n.starts_with(p))
                && ["MPa", "kPa", "Pa"].iter().any(|u| n.ends_with(u))
        })
        .cloned()
        .collect();
    (strain, stress)
}

/// Applies the convention of `declared` (or the one the data show) to
/// `table`, in place, for a record of `test`; returns how the record was
/// read, for reports (`compression, written negative as palpate's`).
/// `header` is the file's original column names (for the evidence that a
/// file is a compression test).
pub fn resolve(
    table: &mut Table,
    test: TestKind,
    meta: &Metadata,
    header: &[String],
    declared: Option<Compression>,
) -> anyhow::Result<String> {
    let shown = table.file.display().to_string();
    let set = "set `compression` (--data TEST[compression=positive]=FILE or --compression positive; in a manifest `compression = \"positive\"`)";
    match test {
        TestKind::SimpleShear | TestKind::GeneralBiaxial => {
            if declared.is_some() {
                anyhow::bail!(
                    "{shown}: the compression option is for uniaxial, equibiaxial, planar and force records, not {test:?}"
                );
            }
            Ok(String::new())
        }
        TestKind::Homogeneous(_) => {
            let (strains, stresses) = strain_and_stress(table);
            let negate = |table: &mut Table| {
                for n in strains.iter().chain(&stresses) {
                    let k = table.names.iter().position(|x| x == n).expect("present");
                    table.columns[k].iter_mut().for_each(|v| *v = -*v);
                }
            };
            // The deformation as a signed strain (stretch - 1) and the
            // stress, as the file writes them.
            let strain: Option<(String, Vec<f64>)> = strains
                .first()
                .map(|n| (n.clone(), table.column(n).expect("present").to_vec()))
                .or_else(|| {
                    table.has(Column::STRETCH).then(|| {
                        (
                            Column::STRETCH.to_string(),
                            table
                                .column(Column::STRETCH)
                                .expect("present")
                                .iter()
                                .map(|l| l - 1.0)
                                .collect(),
                        )
                    })
                });
            let (Some((sname, e)), Some(pname)) = (strain, stresses.first()) else {
                // Missing columns are reported by the column reader.
                if declared == Some(Compression::Positive) {
                    negate(table);
                }
                return Ok(String::new());
            };
            let says_compression =
                matches!(declared, Some(Compression::Positive | Compression::Yes));
            if sname == Column::STRETCH {
                if declared == Some(Compression::Positive) {
                    anyhow::bail!(
                        "{shown}: compression=positive converts strains, but the file gives a stretch, which is below 1 in compression \
                         whatever the machine's convention; leave compression unset (or negative)"
                    );
                }
            } else if sname != "true_strain" {
                if e.iter().any(|&x| x <= -1.0 || x.is_nan()) {
                    // A stretch of zero or below: the column reader names it.
                    if declared == Some(Compression::Positive) {
                        negate(table);
                    }
                    return Ok(String::new());
                }
                if let (true, Some(k)) = (says_compression, e.iter().position(|&x| x >= 1.0)) {
                    anyhow::bail!(
                        "{shown}:{}: `{sname}` is {} but the record is declared a compression test (compression={}): an engineering \
                         strain of magnitude 1 or more is a stretch of 2 or more, which only tension reaches; if this is a tension \
                         test set compression=none",
                        table.lines[k],
                        e[k],
                        declared.expect("declared").key()
                    );
                }
            }
            let p = table.column(pname).expect("present").to_vec();
            let (k, e_max) = extreme(&e);
            let p_at = p[k];
            let line = table.lines[k];
            let p_scale = p.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let e_min = e.iter().cloned().fold(f64::INFINITY, f64::min);
            let e_top = e.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let both_ways = e_min < -0.05 * e_max.abs() && e_top > 0.05 * e_max.abs();
            if e_max == 0.0 || p_scale == 0.0 {
                if declared == Some(Compression::Positive) {
                    negate(table);
                }
                return Ok(String::new());
            }
            // The stress follows the strain where the record goes furthest.
            if p_at * e_max < 0.0 && p_at.abs() > 0.05 * p_scale {
                anyhow::bail!(
                    "{shown}:{line}: column `{sname}` is {e_max} and `{pname}` is {p_at}: opposite signs. palpate takes \
                     strain and stress both negative in compression and both positive in tension; one of the two \
                     columns is written in another convention (negate it, or choose the columns by name)"
                );
            }
            if both_ways {
                if declared == Some(Compression::Positive) {
                    negate(table);
                }
                let written = match declared {
                    Some(Compression::Positive) => "written positive in the file, converted",
                    _ => "written negative as palpate's",
                };
                if declared == Some(Compression::None) {
                    anyhow::bail!(
                        "{shown}:{line}: compression=none (a tension test), but the record also goes into compression \
                         (`{sname}` from {e_min} to {e_top}); leave compression unset for a tension-compression record"
                    );
                }
                return Ok(format!("tension and compression, compression {written}"));
            }
            // How the curve bends, read as a compression (engineering
            // strain and stress only: a true pair bends otherwise).
            let bend = (sname == "strain").then(|| Bend::of(&e, &p)).flatten();
            let compressed = e_max < 0.0;
            if sname == Column::STRETCH && !compressed && declared == Some(Compression::Yes) {
                anyhow::bail!(
                    "{shown}:{line}: declared a compression test (compression=yes), but `stretch` is {}: above 1, which is \
                     tension whatever the machine's convention; if this is a tension test, set compression=none",
                    1.0 + e_max
                );
            }
            match (declared, compressed) {
                (Some(Compression::Negative | Compression::Yes), true) | (None, true) => {
                    Ok("compression, written negative as palpate's".into())
                }
                (Some(Compression::Positive), true) => anyhow::bail!(
                    "{shown}:{line}: compression=positive, but `{sname}` is {e_max} in the file: negative, so the file writes \
                     compression as negative (palpate's convention) or the record is a tension test written negative; \
                     set compression=negative (or leave it unset)"
                ),
                (Some(Compression::Negative), false) => anyhow::bail!(
                    "{shown}:{line}: compression=negative, but `{sname}` is {e_max} and `{pname}` {p_at}: positive, so \
                     this record is a tension test or its file writes compression as positive; set compression=positive \
                     or compression=none (a tension test)"
                ),
                (Some(Compression::Positive | Compression::Yes), false) => {
                    if let Some(b) = bend.filter(|b| b.softens()) {
                        anyhow::bail!(
                            "{shown}:{line}: declared a compression test written positive (compression={}), but its curve softens as \
                             the strain grows ({}), as a tension test does: every elastomer stiffens in compression. If this is a \
                             tension test, set compression=none",
                            declared.expect("declared").key(),
                            b.describe()
                        );
                    }
                    negate(table);
                    Ok("compression, written positive in the file, converted".into())
                }
                (Some(Compression::None), true) => anyhow::bail!(
                    "{shown}:{line}: compression=none (a tension test), but `{sname}` is {e_max}: negative, which is \
                     compression in palpate's convention; set compression=negative if this is a compression test"
                ),
                (Some(Compression::None), false) => Ok("tension, as declared".into()),
                (None, false) => match compression_evidence(table, meta, header) {
                    Some(why) => match bend {
                        Some(b) if b.stiffens() => {
                            negate(table);
                            Ok(format!(
                                "compression, written positive in the file ({why}; the curve stiffens as a compression \
                                 does: {}), converted",
                                b.describe()
                            ))
                        }
                        b => anyhow::bail!(
                            "{shown}:{line}: the sign of this record is ambiguous: the file looks like a compression test \
                             ({why}), but `{sname}` ({e_max}) and `{pname}` ({p_at}) are positive, which palpate reads as \
                             tension{}. If the machine writes compression as positive, {set}; if this is a tension test, set \
                             compression=none",
                            match b {
                                Some(b) => format!(", and the curve {}", b.describe()),
                                None => String::new(),
                            }
                        ),
                    },
                    None => Ok("tension".into()),
                },
            }
        }
        TestKind::C1 | TestKind::N1 => {
            if !(table.has(Column::DISPLACEMENT) && table.has(Column::FORCE)) {
                return Ok(String::new());
            }
            match declared {
                Some(Compression::None) => anyhow::bail!(
                    "{shown}: compression=none (a tension test) does not apply to a {test:?} force record, which presses on the specimen"
                ),
                Some(Compression::Negative) => {
                    for n in [Column::DISPLACEMENT, Column::FORCE] {
                        let k = table.names.iter().position(|x| x == n).expect("present");
                        table.columns[k].iter_mut().for_each(|v| *v = -*v);
                    }
                }
                _ => {}
            }
            let d = table
                .column(Column::DISPLACEMENT)
                .expect("present")
                .to_vec();
            let f = table.column(Column::FORCE).expect("present").to_vec();
            let (k, d_max) = extreme(&d);
            let f_at = f[k];
            let f_scale = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let line = table.lines[k];
            let file_sign = if declared == Some(Compression::Negative) {
                -1.0
            } else {
                1.0
            };
            if d_max < 0.0 {
                let hint = if declared.is_none() && f_at < 0.0 {
                    "if the machine writes compression as negative, set compression=negative \
                     (--data TEST[compression=negative]=FILE, --compression negative or `compression = \"negative\"`)"
                        .to_string()
                } else {
                    "check the sign of the displacement column".to_string()
                };
                anyhow::bail!(
                    "{shown}:{line}: `{}` is {} in the file: palpate takes the displacement into the body and the force \
                     on the tool positive in compression; {hint}",
                    Column::DISPLACEMENT,
                    file_sign * d_max
                );
            }
            if f_at < 0.0 && f_at.abs() > 0.05 * f_scale {
                anyhow::bail!(
                    "{shown}:{line}: `{}` is {} in the file where the displacement is largest ({}): palpate takes the \
                     force on the tool positive in compression; negate the force column",
                    Column::FORCE,
                    file_sign * f_at,
                    file_sign * d_max
                );
            }
            Ok(match declared {
                Some(Compression::Negative) => {
                    "compression, written negative in the file, converted".into()
                }
                _ => "compression, written positive as palpate's".into(),
            })
        }
    }
}
