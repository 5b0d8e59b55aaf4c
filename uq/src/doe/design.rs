//! Factorial designs: the runs, their standard and randomised order.

use super::fractional::{alias_chains, defining_relation, LETTERS};
use super::{AliasChain, DoeError, Factor, Generator, Word};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Serialize;

/// Largest design this module builds (runs including replicates).
pub const MAX_RUNS: usize = 1 << 20;

/// One run of a design.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Run {
    /// Position in standard (Yates) order, 1-based, counting replicates
    /// (replicate r of standard run i has `(r - 1) * runs_per_replicate + i`).
    pub standard_order: usize,
    /// Position in the order the runs are to be carried out, 1-based.
    pub run_order: usize,
    /// Replicate number, 1-based.
    pub replicate: usize,
    /// Level index of each factor (index into `Factor::levels`).
    pub levels: Vec<usize>,
}

/// A factorial design: factors, runs (stored in run order), and for a
/// fractional design its generators.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Design {
    pub factors: Vec<Factor>,
    pub runs: Vec<Run>,
    /// Generators of a fractional design (empty for a full factorial).
    pub generators: Vec<Generator>,
    /// The seed the run order was randomised with (`None`: standard order).
    pub seed: Option<u64>,
}

fn validate_factors(factors: &[Factor]) -> Result<(), DoeError> {
    if factors.is_empty() {
        return Err(DoeError::NoFactors);
    }
    for (k, f) in factors.iter().enumerate() {
        f.validate()?;
        if factors[..k].iter().any(|g| g.name == f.name) {
            return Err(DoeError::DuplicateFactor {
                factor: f.name.clone(),
            });
        }
    }
    Ok(())
}

fn replicate(base: Vec<Vec<usize>>, replicates: usize) -> Result<Vec<Run>, DoeError> {
    if replicates == 0 {
        return Err(DoeError::NoReplicates { got: 0 });
    }
    let per = base.len();
    let total = per.checked_mul(replicates).filter(|&t| t <= MAX_RUNS);
    let total = total.ok_or(DoeError::TooManyRuns {
        runs: per.saturating_mul(replicates),
        max: MAX_RUNS,
    })?;
    let mut runs = Vec::with_capacity(total);
    for r in 0..replicates {
        for (i, levels) in base.iter().enumerate() {
            let so = r * per + i + 1;
            runs.push(Run {
                standard_order: so,
                run_order: so,
                replicate: r + 1,
                levels: levels.clone(),
            });
        }
    }
    Ok(runs)
}

impl Design {
    /// Full factorial: every combination of levels, `replicates` times, in
    /// standard order with the first factor changing fastest (Yates order for
    /// two-level factors).
    pub fn full_factorial(factors: Vec<Factor>, replicates: usize) -> Result<Design, DoeError> {
        validate_factors(&factors)?;
        let mut cells = 1usize;
        for f in &factors {
            cells = cells
                .checked_mul(f.levels.len())
                .filter(|&c| c <= MAX_RUNS)
                .ok_or(DoeError::TooManyRuns {
                    runs: usize::MAX,
                    max: MAX_RUNS,
                })?;
        }
        let base: Vec<Vec<usize>> = (0..cells)
            .map(|mut i| {
                factors
                    .iter()
                    .map(|f| {
                        let l = i % f.levels.len();
                        i /= f.levels.len();
                        l
                    })
                    .collect()
            })
            .collect();
        Ok(Design {
            runs: replicate(base, replicates)?,
            factors,
            generators: Vec::new(),
            seed: None,
        })
    }

    /// Two-level fractional factorial 2^(k-p): the full factorial in the
    /// base factors (those no generator defines), in Yates order, with each
    /// generated factor set by its generator (`"D=ABC"`, see
    /// [`Generator::parse`]). All factors need exactly two levels
    /// (first = low = -1).
    pub fn fractional(
        factors: Vec<Factor>,
        generators: &[&str],
        replicates: usize,
    ) -> Result<Design, DoeError> {
        validate_factors(&factors)?;
        let k = factors.len();
        if k > LETTERS.len() {
            return Err(DoeError::TooManyFactors {
                got: k,
                max: LETTERS.len(),
            });
        }
        for f in &factors {
            if f.levels.len() != 2 {
                return Err(DoeError::NotTwoLevel {
                    factor: f.name.clone(),
                    got: f.levels.len(),
                });
            }
        }
        let gens: Vec<Generator> = generators
            .iter()
            .map(|g| Generator::parse(g, k))
            .collect::<Result<_, _>>()?;
        let generated: u64 = gens.iter().fold(0, |m, g| m | (1u64 << g.factor));
        for (i, g) in gens.iter().enumerate() {
            if gens[..i].iter().any(|h| h.factor == g.factor) {
                return Err(DoeError::BadGenerator {
                    text: generators[i].to_string(),
                    reason: "this factor is already generated".into(),
                });
            }
            if g.word.mask & generated != 0 {
                return Err(DoeError::BadGenerator {
                    text: generators[i].to_string(),
                    reason:
                        "the right side may only use base factors (factors no generator defines)"
                            .into(),
                });
            }
        }
        let base_factors: Vec<usize> = (0..k).filter(|f| generated & (1u64 << f) == 0).collect();
        let n = 1usize << base_factors.len();
        let base: Vec<Vec<usize>> = (0..n)
            .map(|i| {
                let mut coded = vec![0.0f64; k];
                for (b, &f) in base_factors.iter().enumerate() {
                    coded[f] = if i & (1 << b) != 0 { 1.0 } else { -1.0 };
                }
                for g in &gens {
                    let prod: f64 = g.word.factors().iter().map(|&f| coded[f]).product();
                    coded[g.factor] = if g.word.negative { -prod } else { prod };
                }
                coded.iter().map(|&c| usize::from(c > 0.0)).collect()
            })
            .collect();
        Ok(Design {
            runs: replicate(base, replicates)?,
            factors,
            generators: gens,
            seed: None,
        })
    }

    /// Randomises the run order (all runs, across replicates) with a
    /// Fisher-Yates shuffle driven by Xoshiro256++ seeded with `seed`:
    /// the same seed gives the same order on every platform.
    pub fn randomised(mut self, seed: u64) -> Design {
        self.runs.sort_by_key(|r| r.standard_order);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        self.runs.shuffle(&mut rng);
        for (i, r) in self.runs.iter_mut().enumerate() {
            r.run_order = i + 1;
        }
        self.seed = Some(seed);
        self
    }

    /// Number of runs (including replicates).
    pub fn len(&self) -> usize {
        self.runs.len()
    }

    /// True for a design with no run (never, for a constructed design).
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// Level name of `factor` in `run`.
    pub fn level_name(&self, run: &Run, factor: usize) -> &str {
        &self.factors[factor].levels[run.levels[factor]]
    }

    /// Coded level (-1 low, +1 high) of a two-level factor in `run`; for
    /// factors with more levels, the level index.
    pub fn coded(&self, run: &Run, factor: usize) -> f64 {
        if self.factors[factor].levels.len() == 2 {
            if run.levels[factor] == 0 {
                -1.0
            } else {
                1.0
            }
        } else {
            run.levels[factor] as f64
        }
    }

    /// Words of the defining relation (empty for a full factorial).
    pub fn defining_relation(&self) -> Vec<Word> {
        defining_relation(&self.generators)
    }

    /// Resolution: the length of the shortest word of the defining relation
    /// (`None` for a full factorial, whose resolution is unbounded).
    pub fn resolution(&self) -> Option<usize> {
        self.defining_relation().iter().map(Word::len).min()
    }

    /// Alias chains of the effects of order <= `max_order` (empty for a full
    /// factorial or a design with factors of more than two levels).
    pub fn alias_chains(&self, max_order: usize) -> Vec<AliasChain> {
        if self.generators.is_empty() {
            return Vec::new();
        }
        alias_chains(self.factors.len(), &self.defining_relation(), max_order)
    }

    /// Factor letter (A, B, ..., skipping I) of position `factor`.
    pub fn letter(factor: usize) -> Option<char> {
        LETTERS.get(factor).map(|&c| c as char)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two(name: &str) -> Factor {
        Factor::new(name, ["lo", "hi"])
    }

    #[test]
    fn full_factorial_counts_and_order() {
        let d =
            Design::full_factorial(vec![Factor::new("a", ["1", "2", "3"]), two("b")], 2).unwrap();
        assert_eq!(d.len(), 12);
        assert_eq!(d.runs[0].levels, vec![0, 0]);
        assert_eq!(d.runs[1].levels, vec![1, 0]);
        assert_eq!(d.runs[3].levels, vec![0, 1]);
        assert_eq!(d.runs[6].replicate, 2);
        assert_eq!(d.runs[6].levels, vec![0, 0]);
        assert!(Design::full_factorial(vec![Factor::new("a", ["x"])], 1).is_err());
        assert!(Design::full_factorial(vec![two("a"), two("a")], 1).is_err());
        assert!(Design::full_factorial(vec![two("a")], 0).is_err());
    }

    #[test]
    fn randomisation_is_a_seeded_permutation() {
        let d = Design::full_factorial(vec![two("a"), two("b"), two("c")], 2).unwrap();
        let r1 = d.clone().randomised(7);
        let r2 = d.clone().randomised(7);
        let r3 = d.clone().randomised(8);
        assert_eq!(r1, r2);
        assert_ne!(r1.runs, r3.runs);
        let mut so: Vec<usize> = r1.runs.iter().map(|r| r.standard_order).collect();
        assert_ne!(so, (1..=16).collect::<Vec<_>>());
        so.sort();
        assert_eq!(so, (1..=16).collect::<Vec<_>>());
        assert!(r1
            .runs
            .iter()
            .enumerate()
            .all(|(i, r)| r.run_order == i + 1));
    }
}
