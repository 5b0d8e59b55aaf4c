//! Factor columns and their sum-to-zero contrast coding.

use super::{AnovaError, Term};
use serde::Serialize;

/// One factor's level per run: level names (in order of first appearance
/// unless given) and the level index of each run.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct FactorColumn {
    pub name: String,
    pub levels: Vec<String>,
    pub codes: Vec<usize>,
}

impl FactorColumn {
    /// From the level name of each run; levels are numbered in order of first
    /// appearance (so the first level seen is the "low" level of a two-level factor).
    pub fn from_names<S: AsRef<str>>(name: impl Into<String>, values: &[S]) -> FactorColumn {
        let mut levels: Vec<String> = Vec::new();
        let codes = values
            .iter()
            .map(|v| {
                let v = v.as_ref();
                match levels.iter().position(|l| l == v) {
                    Some(i) => i,
                    None => {
                        levels.push(v.to_string());
                        levels.len() - 1
                    }
                }
            })
            .collect();
        FactorColumn {
            name: name.into(),
            levels,
            codes,
        }
    }

    /// Contrast columns of this factor (L - 1 of them for L levels), sum-to-zero
    /// ("effect") coding with the first level as reference: column j (j = 1..L-1)
    /// is +1 at level j, -1 at level 0 and 0 elsewhere. For two levels this is
    /// the usual -1 (low, first level) / +1 (high) coding, so that twice the
    /// coefficient is the effect mean(high) - mean(low) of a balanced design.
    pub(crate) fn contrasts(&self) -> Vec<Vec<f64>> {
        (1..self.levels.len())
            .map(|j| {
                self.codes
                    .iter()
                    .map(|&c| {
                        if c == j {
                            1.0
                        } else if c == 0 {
                            -1.0
                        } else {
                            0.0
                        }
                    })
                    .collect()
            })
            .collect()
    }
}

/// Columns of the model matrix for `term`: all products of one contrast
/// column of each of its factors (first factor's index varying slowest).
pub(crate) fn term_columns(factors: &[FactorColumn], term: &Term) -> Vec<Vec<f64>> {
    let n = factors[0].codes.len();
    let mut cols: Vec<Vec<f64>> = vec![vec![1.0; n]];
    for &f in &term.factors {
        let c = factors[f].contrasts();
        cols = cols
            .iter()
            .flat_map(|a| {
                c.iter()
                    .map(move |b| a.iter().zip(b).map(|(x, y)| x * y).collect::<Vec<f64>>())
            })
            .collect();
    }
    cols
}

/// Checks the factor columns against a response of length `n`.
pub(crate) fn check_factors(factors: &[FactorColumn], n: usize) -> Result<(), AnovaError> {
    if factors.is_empty() {
        return Err(AnovaError::NoFactors);
    }
    for (k, f) in factors.iter().enumerate() {
        if f.codes.len() != n {
            return Err(AnovaError::LengthMismatch {
                factor: f.name.clone(),
                got: f.codes.len(),
                expected: n,
            });
        }
        if f.levels.len() < 2 {
            return Err(AnovaError::SingleLevel {
                factor: f.name.clone(),
                level: f.levels.first().cloned().unwrap_or_default(),
            });
        }
        if factors[..k].iter().any(|g| g.name == f.name) {
            return Err(AnovaError::DuplicateFactor {
                factor: f.name.clone(),
            });
        }
    }
    Ok(())
}

/// Groups the runs into cells (one per combination of levels of all
/// `factors` that occurs), in order of first appearance; each cell lists run indices.
pub fn cells(factors: &[FactorColumn]) -> Vec<Vec<usize>> {
    let n = factors.first().map_or(0, |f| f.codes.len());
    let mut keys: Vec<Vec<usize>> = Vec::new();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in 0..n {
        let key: Vec<usize> = factors.iter().map(|f| f.codes[i]).collect();
        match keys.iter().position(|k| *k == key) {
            Some(g) => groups[g].push(i),
            None => {
                keys.push(key);
                groups.push(vec![i]);
            }
        }
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coding_and_interaction_columns() {
        let a = FactorColumn::from_names("a", &["x", "y", "z", "x"]);
        assert_eq!(a.levels, vec!["x", "y", "z"]);
        assert_eq!(a.codes, vec![0, 1, 2, 0]);
        assert_eq!(
            a.contrasts(),
            vec![vec![-1.0, 1.0, 0.0, -1.0], vec![-1.0, 0.0, 1.0, -1.0]]
        );
        let b = FactorColumn::from_names("b", &["lo", "hi", "hi", "lo"]);
        let cols = term_columns(
            &[a, b],
            &Term {
                factors: vec![0, 1],
            },
        );
        assert_eq!(
            cols,
            vec![vec![1.0, 1.0, 0.0, 1.0], vec![1.0, 0.0, 1.0, 1.0]]
        );
    }
}
