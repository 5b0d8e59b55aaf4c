//! Reading data files as testing machines write them: metadata lines before
//! the header (kept: specimen size, speed, machine), column names with their
//! units in brackets (`Load (N)`, `Engineering Stress (kPa)`, `Strain [%]`),
//! tab-, semicolon- or comma-separated fields (trailing separators and a
//! decimal comma with `;` or tab separators tolerated), and columns chosen by
//! name ([`ColumnMap`]). The result is the [`Table`] of palpate's own column
//! names and units (`time_s`, `displacement_mm`, `force_N`, `strain`,
//! `true_strain`, `stretch`, `stress_kPa`, ...) that [`super::columns`] and
//! [`super::TestData`] read, and the file's [`Metadata`].
//!
//! A file in palpate's own format (one header line of palpate column names,
//! `#` comments) reads to exactly the table [`Table::parse`] gives.
//!
//! Errors name the file and line and say what would be valid.

use palpate_core::data::{Column, Table};
use std::path::Path;

/// What a column of a data file measures, as a `--data` option names it
/// (`force=Load`, `displacement=Compression`, `stress=Engineering Stress`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    Time,
    Displacement,
    Force,
    Stretch,
    Strain,
    TrueStrain,
    Stress,
    TrueStress,
}

impl Role {
    /// Every role, in the order messages list them.
    pub const ALL: [Role; 8] = [
        Role::Time,
        Role::Displacement,
        Role::Force,
        Role::Stretch,
        Role::Strain,
        Role::TrueStrain,
        Role::Stress,
        Role::TrueStress,
    ];

    /// The option key of the role (`time`, `displacement`, ..., `true_stress`).
    pub fn key(self) -> &'static str {
        match self {
            Role::Time => "time",
            Role::Displacement => "displacement",
            Role::Force => "force",
            Role::Stretch => "stretch",
            Role::Strain => "strain",
            Role::TrueStrain => "true_strain",
            Role::Stress => "stress",
            Role::TrueStress => "true_stress",
        }
    }

    /// The role of an option key, `None` when `key` names no role.
    pub fn parse(key: &str) -> Option<Role> {
        let k = key.trim().to_ascii_lowercase().replace('-', "_");
        Role::ALL.into_iter().find(|r| r.key() == k)
    }

    /// Roles that give the same quantity in another measure: choosing one
    /// of them by name turns off the recognition of the others.
    fn family(self) -> u8 {
        match self {
            Role::Time => 0,
            Role::Displacement => 1,
            Role::Force => 2,
            Role::Stretch | Role::Strain | Role::TrueStrain => 3,
            Role::Stress | Role::TrueStress => 4,
        }
    }

    /// The role a column name (without its unit) says, e.g. `Load` or
    /// `Engineering Stress`; `None` for a name palpate does not know.
    fn recognise(base: &str) -> Option<Role> {
        let b: String = base
            .to_ascii_lowercase()
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { ' ' })
            .collect();
        let b = b.split_whitespace().collect::<Vec<_>>().join(" ");
        let b = b.as_str();
        Some(match b {
            "time" | "test time" | "elapsed time" | "total time" | "running time" => Role::Time,
            "compression"
            | "displacement"
            | "extension"
            | "deflection"
            | "crosshead"
            | "crosshead displacement"
            | "compressive extension"
            | "compressive displacement"
            | "indentation"
            | "indentation depth"
            | "depth" => Role::Displacement,
            "load" | "force" | "compressive load" | "compressive force" | "tensile load"
            | "tensile force" | "standard force" => Role::Force,
            "stretch" | "stretch ratio" | "lambda" => Role::Stretch,
            "strain" | "engineering strain" | "eng strain" | "nominal strain"
            | "compressive strain" | "tensile strain" => Role::Strain,
            "true strain" | "logarithmic strain" | "log strain" | "hencky strain" => {
                Role::TrueStrain
            }
            "stress" | "engineering stress" | "eng stress" | "nominal stress"
            | "compressive stress" | "tensile stress" => Role::Stress,
            "true stress" | "cauchy stress" => Role::TrueStress,
            _ => return None,
        })
    }

    /// The palpate column this role becomes with the unit `unit` written in
    /// the header (`None`: no unit given), and the factor from the file's
    /// values to that column's; `Err` says which units are valid.
    fn column(self, unit: Option<&str>) -> Result<(String, f64), String> {
        let u = unit.map(|u| u.trim()).unwrap_or("");
        let lower = u.to_ascii_lowercase();
        let bad = |valid: &str| Err(format!("unit `{u}` is not one of {valid}"));
        match self {
            Role::Time => match lower.as_str() {
                "" | "s" | "sec" => Ok((Column::TIME.into(), 1.0)),
                "ms" => Ok((Column::TIME.into(), 1e-3)),
                "min" => Ok((Column::TIME.into(), 60.0)),
                "h" => Ok((Column::TIME.into(), 3600.0)),
                _ => bad("s, ms, min, h"),
            },
            Role::Displacement => match u {
                "mm" => Ok((Column::DISPLACEMENT.into(), 1.0)),
                "m" => Ok((Column::DISPLACEMENT.into(), 1e3)),
                "cm" => Ok((Column::DISPLACEMENT.into(), 10.0)),
                "um" | "µm" | "μm" => Ok((Column::DISPLACEMENT.into(), 1e-3)),
                "in" => Ok((Column::DISPLACEMENT.into(), 25.4)),
                "" => Err(
                    "a displacement needs its unit in the header, e.g. `Compression (mm)`".into(),
                ),
                _ => bad("mm, m, cm, um, in"),
            },
            Role::Force => match u {
                "N" => Ok((Column::FORCE.into(), 1.0)),
                "kN" => Ok((Column::FORCE.into(), 1e3)),
                "mN" => Ok((Column::FORCE.into(), 1e-3)),
                "lbf" => Ok((Column::FORCE.into(), 4.448_221_615_260_5)),
                "" => Err("a force needs its unit in the header, e.g. `Load (N)`".into()),
                _ => bad("N, kN, mN, lbf"),
            },
            Role::Stretch => match lower.as_str() {
                "" | "-" | "1" => Ok((Column::STRETCH.into(), 1.0)),
                _ => bad("- (a stretch has no unit)"),
            },
            Role::Strain | Role::TrueStrain => {
                let name = if self == Role::Strain {
                    "strain"
                } else {
                    "true_strain"
                };
                match lower.as_str() {
                    "" | "-" | "1" | "mm/mm" | "m/m" => Ok((name.into(), 1.0)),
                    "%" => Ok((name.into(), 0.01)),
                    _ => bad("-, mm/mm, %"),
                }
            }
            Role::Stress | Role::TrueStress => {
                let base = if self == Role::Stress {
                    "stress"
                } else {
                    "true_stress"
                };
                let compact: String = u.chars().filter(|c| !c.is_whitespace()).collect();
                let (unit, factor) = match compact.as_str() {
                    "MPa" | "N/mm^2" | "N/mm2" | "N/mm²" => ("MPa", 1.0),
                    "kPa" => ("kPa", 1.0),
                    "Pa" | "N/m^2" | "N/m2" | "N/m²" => ("Pa", 1.0),
                    "GPa" => ("MPa", 1e3),
                    "psi" => ("MPa", 6.894_757_293_168e-3),
                    "" => return Err(
                        "a stress needs its unit in the header (e.g. `stress_MPa` or `Stress (kPa)`) or the data option `stress_unit=kPa`".into(),
                    ),
                    _ => return bad("Pa, kPa, MPa, GPa, N/mm^2, psi"),
                };
                Ok((format!("{base}_{unit}"), factor))
            }
        }
    }
}

/// Columns chosen by name: `(role, header name)` pairs. A header name
/// matches a column whose whole text or whose name without its unit is
/// the same, ignoring case (`force=Load` matches `Load (N)`).
pub type ColumnMap = Vec<(Role, String)>;

/// One line before the header: `key: value` (or `key,value`, `key;value`,
/// `key<TAB>value`, `key = value`), or a note with no value (`Compression
/// test`, a sample name).
#[derive(Debug, Clone, PartialEq)]
pub struct MetaEntry {
    /// Line in the file (1-based).
    pub line: usize,
    pub key: String,
    /// Empty for a note.
    pub value: String,
}

/// The lines of a data file before its header, in order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Metadata {
    pub entries: Vec<MetaEntry>,
}

/// The specimen size a file's metadata states (mm), for an experiment
/// description (a cylinder's radius and height).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpecimenSize {
    /// Diameter (or twice a stated radius), mm.
    pub diameter_mm: Option<f64>,
    /// Height (or thickness), mm.
    pub height_mm: Option<f64>,
}

impl SpecimenSize {
    /// Half the diameter, mm.
    pub fn radius_mm(&self) -> Option<f64> {
        self.diameter_mm.map(|d| d / 2.0)
    }
}

impl Metadata {
    /// Whether the file had no lines before its header.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The value of the first entry whose key contains `word` (ignoring case).
    pub fn get(&self, word: &str) -> Option<&str> {
        let w = word.to_ascii_lowercase();
        self.entries
            .iter()
            .find(|e| !e.value.is_empty() && e.key.to_ascii_lowercase().contains(&w))
            .map(|e| e.value.as_str())
    }

    /// The line of the first entry (key or note) mentioning `word`.
    pub fn mentions(&self, word: &str) -> Option<&MetaEntry> {
        let w = word.to_ascii_lowercase();
        self.entries.iter().find(|e| {
            e.key.to_ascii_lowercase().contains(&w) || e.value.to_ascii_lowercase().contains(&w)
        })
    }

    /// A length stated by the entry whose key contains `word`, in mm
    /// (`Cylinder Diameter: 50mm`, `Height (mm),30`, `Diameter: 5 cm`; a
    /// number with no unit is in mm). `Err` names the line when the value
    /// is not a length.
    fn length(&self, word: &str) -> Result<Option<(f64, usize)>, String> {
        let w = word.to_ascii_lowercase();
        let Some(e) = self
            .entries
            .iter()
            .find(|e| !e.value.is_empty() && e.key.to_ascii_lowercase().contains(&w))
        else {
            return Ok(None);
        };
        let (_, key_unit) = split_unit(&e.key);
        let v = e.value.trim();
        let end = v
            .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E')))
            .unwrap_or(v.len());
        // `e` of a unit (none of mm, cm, m, um starts with e) cannot be cut off.
        let (num, unit) = v.split_at(end);
        let unit = unit.trim();
        let unit = if unit.is_empty() {
            key_unit.unwrap_or("mm").trim()
        } else {
            unit
        };
        let factor = match unit {
            "mm" => 1.0,
            "cm" => 10.0,
            "m" => 1e3,
            "um" | "µm" | "μm" => 1e-3,
            "in" => 25.4,
            _ => f64::NAN,
        };
        match num.parse::<f64>() {
            Ok(x) if x > 0.0 && x.is_finite() && factor.is_finite() => Ok(Some((x * factor, e.line))),
            _ => Err(format!(
                "line {}: `{}: {}` is not a length (expected a positive number with mm, cm, m or um, e.g. `50mm`)",
                e.line, e.key, e.value
            )),
        }
    }

    /// The specimen's diameter (or radius) and height (or thickness) when
    /// the metadata states them; `None` when it states neither.
    pub fn specimen(&self) -> Result<Option<SpecimenSize>, String> {
        let diameter = match self.length("diameter")? {
            Some((d, _)) => Some(d),
            None => self.length("radius")?.map(|(r, _)| 2.0 * r),
        };
        let height = match self.length("height")? {
            Some((h, _)) => Some(h),
            None => self.length("thickness")?.map(|(t, _)| t),
        };
        Ok(
            (diameter.is_some() || height.is_some()).then_some(SpecimenSize {
                diameter_mm: diameter,
                height_mm: height,
            }),
        )
    }
}

/// A data file read as a testing machine wrote it.
#[derive(Debug, Clone)]
pub struct MachineFile {
    /// The table in palpate's column names and units.
    pub table: Table,
    pub metadata: Metadata,
    /// How each column of the file was read, e.g. `Load (N) -> force_N`,
    /// `Strain (%) -> strain (x 0.01)`; only columns that were renamed or
    /// converted.
    pub renamed: Vec<String>,
    /// The file's original column names, in order.
    pub header: Vec<String>,
}

/// How to read a machine file (see [`super::ReadOptions`]).
#[derive(Debug, Clone, Default)]
pub struct Layout<'a> {
    /// Columns chosen by name.
    pub columns: &'a [(Role, String)],
    /// Lines at the top of the file that come before the header (all kept
    /// as metadata); `None`: the header is found (the first line of names
    /// followed by a row of numbers).
    pub skip_rows: Option<usize>,
    /// The stress unit stated where the file is read, for stress columns
    /// with no unit in their names.
    pub stress_unit: Option<f64>,
}

/// Splits `Load (N)` / `Strain [%]` into (`Load`, `Some("N")`).
fn split_unit(field: &str) -> (&str, Option<&str>) {
    let f = field.trim();
    for (open, close) in [('(', ')'), ('[', ']')] {
        if let Some(inner) = f.strip_suffix(close) {
            if let Some(i) = inner.rfind(open) {
                return (inner[..i].trim(), Some(&inner[i + 1..]));
            }
        }
    }
    (f, None)
}

fn unquote(s: &str) -> &str {
    let s = s.trim();
    if s.len() >= 2 && s.starts_with('"') && s.ends_with('"') {
        &s[1..s.len() - 1]
    } else {
        s
    }
}

/// Fields of a line, trailing empty fields (a trailing separator) removed.
fn fields(line: &str, sep: char) -> Vec<&str> {
    let mut f: Vec<&str> = line.split(sep).map(unquote).collect();
    while f.len() > 1 && f.last().is_some_and(|s| s.is_empty()) {
        f.pop();
    }
    f
}

/// A number, also with a decimal comma when the separator is not a comma.
fn number(field: &str, sep: char) -> Option<f64> {
    field.parse::<f64>().ok().or_else(|| {
        (sep != ',' && field.matches(',').count() == 1)
            .then(|| field.replace(',', ".").parse::<f64>().ok())
            .flatten()
    })
}

/// palpate's own column names, which pass through unchanged.
fn is_palpate_name(name: &str) -> bool {
    const EXACT: [&str; 14] = [
        "time_s",
        "displacement_mm",
        "position_mm",
        "force_N",
        "stretch",
        "strain",
        "true_strain",
        "lambda1",
        "lambda2",
        "stretch1",
        "stretch2",
        "amount_of_shear",
        "shear_strain",
        "true_strain1",
    ];
    EXACT.contains(&name)
        || ["_MPa", "_kPa", "_Pa"].iter().any(|u| name.ends_with(u))
        || (name.starts_with("strain") || name.starts_with("true_strain"))
            && name.ends_with(|c: char| c.is_ascii_digit())
}

/// The metadata entry of a line before the header.
fn meta_entry(line: usize, text: &str) -> MetaEntry {
    let t = text.trim();
    let t = t.trim_end_matches([';', ',', '\t']).trim();
    let t = unquote(t);
    // `key: value` first (a value may hold commas), then `key = value`,
    // then the first separator.
    let split = t
        .split_once(':')
        .or_else(|| t.split_once('='))
        .or_else(|| t.split_once('\t'))
        .or_else(|| t.split_once(';'))
        .or_else(|| t.split_once(','));
    let (key, value) = match split {
        Some((k, v)) if !k.trim().is_empty() => (k, v),
        _ => (t, ""),
    };
    let clean = |s: &str| {
        unquote(s.trim().trim_matches([';', ',', '\t']).trim())
            .trim()
            .to_string()
    };
    MetaEntry {
        line,
        key: clean(key),
        value: clean(value),
    }
}

/// Reads the text of a data file (as if read from `file`) as a testing
/// machine wrote it; [`Layout`] chooses columns and where the header is.
pub fn parse(file: &Path, text: &str, layout: &Layout) -> anyhow::Result<MachineFile> {
    let shown = file.display();
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let unified;
    let text = if text.contains('\r') {
        unified = text.replace("\r\n", "\n").replace('\r', "\n");
        unified.as_str()
    } else {
        text
    };
    // (line number, text) of every line that is not blank; `#` lines are comments.
    let mut comments = Vec::new();
    let mut lines: Vec<(usize, &str)> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let s = raw.trim();
        if s.is_empty() {
            continue;
        }
        if let Some(c) = s.strip_prefix('#') {
            comments.push(c.trim().to_string());
            continue;
        }
        lines.push((i + 1, s));
    }
    let Some(&(_, last)) = lines.last() else {
        anyhow::bail!(
            "{shown}: no header line (expected column names such as `time_s,displacement_mm,force_N` or `Time (s),Compression (mm),Load (N)`)"
        );
    };
    // The separator of the data rows: the last line is a row.
    let sep = if last.contains('\t') {
        '\t'
    } else if last.contains(';') {
        ';'
    } else {
        ','
    };
    let sep_name = match sep {
        '\t' => "tab",
        ';' => "semicolon",
        _ => "comma",
    };
    let numeric = |f: &str| number(f, sep).is_some();
    // The header: the first line of two or more names (no field a number)
    // followed by a line of as many fields, some of them numbers; or the
    // line after `skip_rows`.
    let header_at = match layout.skip_rows {
        Some(n) => lines.iter().position(|&(l, _)| l > n).ok_or_else(|| {
            anyhow::anyhow!(
                "{shown}: skip_rows = {n} skips every line of the file (it has {} lines)",
                text.lines().count()
            )
        })?,
        // A row of numbers only is preferred (`Sample,Thickness` over
        // `S1,3.2` is metadata); a header followed by a row with a bad
        // field is still found, so that the error names that field.
        None => [Some(true), Some(false), None]
            .into_iter()
            .find_map(|all| {
                (0..lines.len()).find(|&i| {
                    let h = fields(lines[i].1, sep);
                    h.len() >= 2
                        && !h.iter().any(|f| numeric(f))
                        && match (all, lines.get(i + 1)) {
                            // Last resort: the first line of names, whatever
                            // follows (the rows' errors then name their lines).
                            (None, _) => true,
                            (Some(_), None) => false,
                            (Some(all), Some(&(_, next))) => {
                                let r = fields(next, sep);
                                r.len() == h.len()
                                    && if all {
                                        r.iter().all(|f| numeric(f))
                                    } else {
                                        r.iter().any(|f| numeric(f))
                                    }
                            }
                        }
                })
            })
            .ok_or_else(|| {
                let first = lines[0];
                anyhow::anyhow!(
                    "{shown}: no header found: expected a line of column names followed by rows of numbers, \
                     all separated by {sep_name}s (from the last line), e.g. `Time (s){s}Compression (mm){s}Load (N)`; \
                     line {} is `{}`. Lines before the header are kept as metadata; if the header is on line N+1, set skip_rows=N",
                    first.0,
                    first.1,
                    s = if sep == '\t' { "\\t".to_string() } else { sep.to_string() }
                )
            })?,
    };
    let metadata = Metadata {
        entries: lines[..header_at]
            .iter()
            .map(|&(l, t)| meta_entry(l, t))
            .collect(),
    };
    let (header_line, header_text) = lines[header_at];
    let header: Vec<String> = fields(header_text, sep)
        .iter()
        .map(|s| s.to_string())
        .collect();
    if header.len() < 2 && header.iter().all(|h| !is_palpate_name(h)) {
        anyhow::bail!(
            "{shown}:{header_line}: `{header_text}` is not a header of column names separated by {sep_name}s \
             (the separator of the last line); set skip_rows={} if the header is the next line",
            header_line
        );
    }
    // Roles chosen by name.
    let mut chosen: Vec<Option<Role>> = vec![None; header.len()];
    for (role, name) in layout.columns {
        let want = name.trim().to_ascii_lowercase();
        let k = header
            .iter()
            .position(|h| {
                h.to_ascii_lowercase() == want || split_unit(h).0.to_ascii_lowercase() == want
            })
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "{shown}:{header_line}: {}={name}: no column `{name}` (header has: {})",
                    role.key(),
                    header.join(", ")
                )
            })?;
        if let Some(other) = chosen[k] {
            anyhow::bail!(
                "{shown}:{header_line}: column `{}` is chosen twice ({}= and {}=)",
                header[k],
                other.key(),
                role.key()
            );
        }
        chosen[k] = Some(*role);
    }
    let families: Vec<u8> = layout.columns.iter().map(|(r, _)| r.family()).collect();
    // Each column's palpate name and factor.
    let mut names = Vec::with_capacity(header.len());
    let mut factors = Vec::with_capacity(header.len());
    let mut renamed = Vec::new();
    for (k, h) in header.iter().enumerate() {
        let role = chosen[k].or_else(|| {
            if is_palpate_name(h) {
                return None;
            }
            Role::recognise(split_unit(h).0).filter(|r| !families.contains(&r.family()))
        });
        let (name, factor) = match role {
            None => (h.clone(), 1.0),
            Some(role) => {
                let (_, unit) = split_unit(h);
                let unit = match (unit, role, layout.stress_unit) {
                    (None, Role::Stress | Role::TrueStress, Some(_)) => Some("MPa"),
                    (u, _, _) => u,
                };
                // A palpate name chosen by role keeps its unit suffix.
                if is_palpate_name(h) && unit.is_none() {
                    (h.clone(), 1.0)
                } else {
                    role.column(unit).map_err(|why| {
                        anyhow::anyhow!(
                            "{shown}:{header_line}: column `{h}` ({}): {why}",
                            role.key()
                        )
                    })?
                }
            }
        };
        if let Some(j) = names.iter().position(|n| *n == name) {
            if header[j] == *h {
                anyhow::bail!("{shown}:{header_line}: the header names column `{h}` twice");
            }
            anyhow::bail!(
                "{shown}:{header_line}: columns `{}` and `{h}` are both read as `{name}`; choose one by name (e.g. `{}={}`)",
                header[j],
                role.map_or("column", |r| r.key()),
                split_unit(&header[j]).0
            );
        }
        if name != *h || factor != 1.0 {
            renamed.push(if factor == 1.0 {
                format!("{h} -> {name}")
            } else {
                format!("{h} -> {name} (x {factor})")
            });
        }
        names.push(name);
        factors.push(factor);
    }
    // Rows.
    let mut columns: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    let mut row_lines = Vec::new();
    for &(line, t) in &lines[header_at + 1..] {
        let f = fields(t, sep);
        if f.len() != names.len() {
            anyhow::bail!(
                "{shown}:{line}: expected {} fields separated by {sep_name}s (as the header on line {header_line}: {}), found {}",
                names.len(),
                header.join(", "),
                f.len()
            );
        }
        for (k, field) in f.iter().enumerate() {
            let v = number(field, sep).ok_or_else(|| {
                anyhow::anyhow!(
                    "{shown}:{line}: column `{}`: `{field}` is not a number",
                    header[k]
                )
            })? * factors[k];
            if !v.is_finite() {
                anyhow::bail!(
                    "{shown}:{line}: column `{}`: value is NaN or infinite",
                    header[k]
                );
            }
            if names[k] == Column::TIME {
                if let Some(&prev) = columns[k].last() {
                    if v < prev {
                        anyhow::bail!(
                            "{shown}:{line}: column `{}` is not monotonic ({prev} then {v})",
                            header[k]
                        );
                    }
                }
            }
            columns[k].push(v);
        }
        row_lines.push(line);
    }
    if row_lines.is_empty() {
        anyhow::bail!("{shown}: no data rows after the header on line {header_line}");
    }
    Ok(MachineFile {
        table: Table {
            file: file.to_path_buf(),
            names,
            header_line,
            columns,
            lines: row_lines,
            comments,
        },
        metadata,
        renamed,
        header,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> MachineFile {
        parse(Path::new("f.csv"), text, &Layout::default()).unwrap()
    }

    fn err(text: &str, layout: &Layout) -> String {
        format!("{:#}", parse(Path::new("f.csv"), text, layout).unwrap_err())
    }

    const PHANTOM: &str = "EF10_0T_A_sample_1\nCompression test;\nCylinder Diameter: 50mm;\nCylinder Height: 30mm;\nSpeed (mm/min): 10;\nMachine: INSTRON 5900;\n\nTime (s),Compression (mm),Load (N),Engineering Strain [-],Engineering Stress (kPa),True Strain [-],True Stress (kPa)\n0.0,0.0,0.01,-0.0,-0.001,0.0,-0.001\n0.1,3.0,2.0,-0.1,-1.0,-0.10536,-0.9\n";

    #[test]
    fn a_machine_file_reads_its_metadata_and_units() {
        let m = read(PHANTOM);
        assert_eq!(
            m.table.names,
            [
                "time_s",
                "displacement_mm",
                "force_N",
                "strain",
                "stress_kPa",
                "true_strain",
                "true_stress_kPa"
            ]
        );
        assert_eq!(m.table.header_line, 8);
        assert_eq!(m.table.lines, [9, 10]);
        assert_eq!(m.table.column("stress_kPa").unwrap(), [-0.001, -1.0]);
        let e = &m.metadata.entries;
        assert_eq!(e.len(), 6);
        assert_eq!(
            (e[0].key.as_str(), e[0].value.as_str()),
            ("EF10_0T_A_sample_1", "")
        );
        assert_eq!(
            (e[1].key.as_str(), e[1].value.as_str()),
            ("Compression test", "")
        );
        assert_eq!(e[4].key, "Speed (mm/min)");
        assert_eq!(e[4].value, "10");
        assert_eq!(m.metadata.get("machine"), Some("INSTRON 5900"));
        let s = m.metadata.specimen().unwrap().unwrap();
        assert_eq!(s.diameter_mm, Some(50.0));
        assert_eq!(s.radius_mm(), Some(25.0));
        assert_eq!(s.height_mm, Some(30.0));
    }

    #[test]
    fn a_palpate_file_reads_as_table_parse_reads_it() {
        let text = "# source\nstretch,stress_MPa\n1,0\n\n1.5,0.25\n";
        let m = read(text);
        assert_eq!(m.table, Table::parse("f.csv", text).unwrap());
        assert!(m.metadata.is_empty() && m.renamed.is_empty());
    }

    #[test]
    fn separators_units_and_decimal_commas() {
        let tab = read("Time (min)\tLoad (kN)\tStrain (%)\t\n0\t0,5\t10\t\n1\t1\t20\t\n");
        assert_eq!(tab.table.column("time_s").unwrap(), [0.0, 60.0]);
        assert_eq!(tab.table.column("force_N").unwrap(), [500.0, 1000.0]);
        let strain = tab.table.column("strain").unwrap();
        assert!((strain[0] - 0.1).abs() < 1e-15 && (strain[1] - 0.2).abs() < 1e-15);
        let semi = read("Diameter;20 mm;\nStretch;Stress (N/mm^2);\n1;0;\n1,5;0,25;\n");
        assert_eq!(semi.table.names, ["stretch", "stress_MPa"]);
        assert_eq!(semi.table.column("stretch").unwrap(), [1.0, 1.5]);
        assert_eq!(
            semi.metadata.specimen().unwrap().unwrap().diameter_mm,
            Some(20.0)
        );
        let comma = read("\u{feff}Compression (mm),Load (N),\r\n0,0,\r\n1,2,\r\n");
        assert_eq!(comma.table.column("force_N").unwrap(), [0.0, 2.0]);
    }

    #[test]
    fn columns_chosen_by_name_turn_off_the_others_of_their_quantity() {
        let cols = vec![
            (Role::Strain, "True Strain".to_string()),
            (Role::Stress, "Nominal".to_string()),
        ];
        let layout = Layout {
            columns: &cols,
            ..Layout::default()
        };
        let m = parse(
            Path::new("f.csv"),
            "Engineering Strain [-],True Strain [-],Nominal (MPa),Engineering Stress (kPa)\n-0.1,-0.2,-1,-3\n0,0,0,0\n",
            &layout,
        )
        .unwrap();
        assert_eq!(
            m.table.names,
            [
                "Engineering Strain [-]",
                "strain",
                "stress_MPa",
                "Engineering Stress (kPa)"
            ]
        );
        let e = err(
            "Time (s),Load (N)\n0,1\n",
            &Layout {
                columns: &[(Role::Force, "Force".into())],
                ..Layout::default()
            },
        );
        assert!(
            e.contains("f.csv:1: force=Force: no column `Force` (header has: Time (s), Load (N))"),
            "{e}"
        );
    }

    #[test]
    fn bad_files_name_the_line_and_what_is_valid() {
        let none = Layout::default();
        let e = err("Time (s),Load (furlong)\n0,1\n", &none);
        assert!(
            e.contains(
                "f.csv:1: column `Load (furlong)` (force): unit `furlong` is not one of N, kN"
            ),
            "{e}"
        );
        let e = err("Time (s),Stress\n0,1\n", &none);
        assert!(
            e.contains("a stress needs its unit") && e.contains("stress_unit"),
            "{e}"
        );
        let e = err("a\nTime (s),Load (N)\n0,1\n0,1,2\n", &none);
        assert!(
            e.contains("f.csv:4: expected 2 fields separated by commas (as the header on line 2"),
            "{e}"
        );
        let e = err("sample 1\nno numbers here\n", &none);
        assert!(
            e.contains("no header found") && e.contains("skip_rows"),
            "{e}"
        );
        let e = err("Time (s),Load (N)\n0,x\n", &none);
        assert!(
            e.contains("f.csv:2: column `Load (N)`: `x` is not a number"),
            "{e}"
        );
        let e = err("Time (s),Time (min)\n0,1\n", &none);
        assert!(e.contains("are both read as `time_s`"), "{e}");
        let m = read("Height: tall\nTime (s),Load (N)\n0,1\n");
        let e = m.metadata.specimen().unwrap_err();
        assert!(e.contains("line 1: `Height: tall` is not a length"), "{e}");
    }

    #[test]
    fn metadata_as_a_table_and_skip_rows() {
        // `Sample,Thickness` / `S1,3.2` look like a header and a row; the
        // header is the line followed by numbers only.
        let text = "Sample,Thickness (mm)\nS1,3.2\nTime (s),Load (N)\n0,1\n2,3\n";
        let m = read(text);
        assert_eq!(m.table.header_line, 3);
        assert_eq!(m.metadata.entries[1].key, "S1");
        // A metadata table (names on one line, values on the next) is kept
        // line by line, not read as keys.
        assert_eq!(m.metadata.specimen().unwrap(), None);
        let m = parse(
            Path::new("f.csv"),
            text,
            &Layout {
                skip_rows: Some(2),
                ..Layout::default()
            },
        )
        .unwrap();
        assert_eq!(m.table.header_line, 3);
        let e = err(
            text,
            &Layout {
                skip_rows: Some(9),
                ..Layout::default()
            },
        );
        assert!(e.contains("skip_rows = 9 skips every line"), "{e}");
    }
}
