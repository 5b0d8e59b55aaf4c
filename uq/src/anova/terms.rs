//! Model terms: main effects and interactions, in hierarchical order.

use serde::Serialize;

/// A model term: the set of factors (positions, increasing) whose interaction
/// it is; one factor is a main effect.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Term {
    pub factors: Vec<usize>,
}

impl Term {
    /// The term's name from factor names, joined by `:` (`material:space`).
    pub fn name(&self, factor_names: &[String]) -> String {
        self.factors
            .iter()
            .map(|&f| factor_names[f].as_str())
            .collect::<Vec<_>>()
            .join(":")
    }

    /// Order of the term (1 = main effect, 2 = two-factor interaction...).
    pub fn order(&self) -> usize {
        self.factors.len()
    }
}

/// All terms among `k` factors up to order `max_order`, in the hierarchical
/// order of R's and statsmodels' `a*b*c` expansion: main effects in factor
/// order, then two-factor interactions in lexicographic order, and so on.
pub fn hierarchical_terms(k: usize, max_order: usize) -> Vec<Term> {
    let mut terms = Vec::new();
    for order in 1..=max_order.min(k) {
        let mut combo: Vec<usize> = (0..order).collect();
        loop {
            terms.push(Term {
                factors: combo.clone(),
            });
            // Next combination in lexicographic order.
            let mut i = order;
            while i > 0 && combo[i - 1] == k - order + i - 1 {
                i -= 1;
            }
            if i == 0 {
                break;
            }
            combo[i - 1] += 1;
            for j in i..order {
                combo[j] = combo[j - 1] + 1;
            }
        }
    }
    terms
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_factors_full_model() {
        let names: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
        let t: Vec<String> = hierarchical_terms(3, 3)
            .iter()
            .map(|t| t.name(&names))
            .collect();
        assert_eq!(t, vec!["a", "b", "c", "a:b", "a:c", "b:c", "a:b:c"]);
        assert_eq!(hierarchical_terms(4, 2).len(), 4 + 6);
    }
}
