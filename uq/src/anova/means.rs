//! Data of the main-effects and interaction plots: means of the response at
//! each level of a factor, and at each pair of levels of two factors.

use super::FactorColumn;
use serde::Serialize;

/// Mean response at each level of one factor.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MainEffectMeans {
    pub factor: String,
    pub levels: Vec<String>,
    pub means: Vec<f64>,
    pub counts: Vec<usize>,
}

/// Mean response in each cell of two factors (`means[a][b]`, NaN where empty).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InteractionMeans {
    pub factor_a: String,
    pub factor_b: String,
    pub levels_a: Vec<String>,
    pub levels_b: Vec<String>,
    pub means: Vec<Vec<f64>>,
}

/// Level means of every factor. Inputs must have equal lengths (as checked by [`super::anova`]).
pub fn main_effect_means(factors: &[FactorColumn], y: &[f64]) -> Vec<MainEffectMeans> {
    factors
        .iter()
        .map(|f| {
            let mut sum = vec![0.0; f.levels.len()];
            let mut counts = vec![0usize; f.levels.len()];
            for (&c, &v) in f.codes.iter().zip(y) {
                sum[c] += v;
                counts[c] += 1;
            }
            let means = sum
                .iter()
                .zip(&counts)
                .map(|(s, &n)| if n > 0 { s / n as f64 } else { f64::NAN })
                .collect();
            MainEffectMeans {
                factor: f.name.clone(),
                levels: f.levels.clone(),
                means,
                counts,
            }
        })
        .collect()
}

/// Cell means of every pair of factors (a before b in factor order).
pub fn interaction_means(factors: &[FactorColumn], y: &[f64]) -> Vec<InteractionMeans> {
    let mut out = Vec::new();
    for (i, a) in factors.iter().enumerate() {
        for b in &factors[i + 1..] {
            let mut sum = vec![vec![0.0; b.levels.len()]; a.levels.len()];
            let mut n = vec![vec![0usize; b.levels.len()]; a.levels.len()];
            for ((&ca, &cb), &v) in a.codes.iter().zip(&b.codes).zip(y) {
                sum[ca][cb] += v;
                n[ca][cb] += 1;
            }
            let means = sum
                .iter()
                .zip(&n)
                .map(|(s, c)| {
                    s.iter()
                        .zip(c)
                        .map(|(s, &c)| if c > 0 { s / c as f64 } else { f64::NAN })
                        .collect()
                })
                .collect();
            out.push(InteractionMeans {
                factor_a: a.name.clone(),
                factor_b: b.name.clone(),
                levels_a: a.levels.clone(),
                levels_b: b.levels.clone(),
                means,
            });
        }
    }
    out
}
