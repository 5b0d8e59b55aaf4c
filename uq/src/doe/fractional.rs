//! Two-level fractional factorials: generators, defining relation, resolution
//! and alias structure.
//!
//! Factors of a two-level design are named by letters A, B, C, ... in the
//! order they are listed, skipping `I` (which denotes the identity), as in
//! Montgomery, *Design and Analysis of Experiments*, ch. 8. A generator such
//! as `D = ABC` sets the coded level of D to the product of the coded levels
//! of A, B and C (`D = -ABC` to minus that product). It contributes the word
//! `I = ABCD` to the defining relation; the defining relation is the group of
//! all products of the generator words (p generators give 2^p - 1 words,
//! letters multiplying modulo 2). The resolution is the length of the shortest
//! word. The aliases of an effect are its products with every word of the
//! defining relation (Box, Hunter & Hunter, *Statistics for Experimenters*,
//! 2nd ed., ch. 6).

use super::DoeError;
use serde::Serialize;
use std::fmt;

/// Letters naming factors in a two-level design (`I` is the identity).
pub(crate) const LETTERS: &[u8] = b"ABCDEFGHJKLMNOPQRSTUVWXYZ";

/// A signed product of factors (an effect or a word of the defining
/// relation), as a bit set over factor positions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Word {
    pub mask: u64,
    pub negative: bool,
}

impl Word {
    /// The word of the given factor positions, positive.
    pub fn of(factors: &[usize]) -> Word {
        Word {
            mask: factors.iter().fold(0, |m, &f| m | (1u64 << f)),
            negative: false,
        }
    }

    /// Number of letters (the order of the effect).
    pub fn len(&self) -> usize {
        self.mask.count_ones() as usize
    }

    /// True for the identity I.
    pub fn is_empty(&self) -> bool {
        self.mask == 0
    }

    /// Product of two words: letters multiply modulo 2, signs multiply.
    pub fn times(&self, other: &Word) -> Word {
        Word {
            mask: self.mask ^ other.mask,
            negative: self.negative != other.negative,
        }
    }

    /// Factor positions in increasing order.
    pub fn factors(&self) -> Vec<usize> {
        (0..64).filter(|b| self.mask & (1u64 << b) != 0).collect()
    }

    /// Sort key: order first, then letters.
    fn key(&self) -> (usize, Vec<usize>) {
        (self.len(), self.factors())
    }
}

impl fmt::Display for Word {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.negative {
            f.write_str("-")?;
        }
        if self.mask == 0 {
            return f.write_str("I");
        }
        for b in self.factors() {
            match LETTERS.get(b) {
                Some(&c) => write!(f, "{}", c as char)?,
                None => write!(f, "[{b}]")?,
            }
        }
        Ok(())
    }
}

impl Serialize for Word {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.to_string())
    }
}

/// A generator `X = [-]WORD`: the generated factor and the signed word of
/// base factors that defines it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Generator {
    /// Position of the generated factor.
    pub factor: usize,
    /// The signed product of base factors it equals.
    pub word: Word,
}

impl Generator {
    /// Parses `D=ABC`, `E = -ABD`, `F=+BCD` for a design of `k` factors.
    pub fn parse(text: &str, k: usize) -> Result<Generator, DoeError> {
        let bad = |reason: &str| DoeError::BadGenerator {
            text: text.to_string(),
            reason: reason.to_string(),
        };
        let letter = |c: char| -> Result<usize, DoeError> {
            let u = c.to_ascii_uppercase();
            LETTERS
                .iter()
                .position(|&l| l as char == u)
                .filter(|&p| p < k)
                .ok_or_else(|| {
                    bad(&format!(
                        "`{c}` is not one of the factor letters of a {k}-factor design"
                    ))
                })
        };
        let (lhs, rhs) = text
            .split_once('=')
            .ok_or_else(|| bad("expected the form `D=ABC`"))?;
        let lhs: Vec<char> = lhs.trim().chars().collect();
        if lhs.len() != 1 {
            return Err(bad("the left side must be a single factor letter"));
        }
        let factor = letter(lhs[0])?;
        let rhs = rhs.trim();
        let (negative, letters) = match rhs.strip_prefix('-') {
            Some(r) => (true, r.trim()),
            None => (false, rhs.strip_prefix('+').unwrap_or(rhs).trim()),
        };
        let mut mask = 0u64;
        for c in letters.chars() {
            let p = letter(c)?;
            if mask & (1u64 << p) != 0 {
                return Err(bad(&format!("letter `{c}` appears twice")));
            }
            mask |= 1u64 << p;
        }
        if mask.count_ones() < 2 {
            return Err(bad("the right side needs at least two factor letters"));
        }
        if mask & (1u64 << factor) != 0 {
            return Err(bad("a factor cannot generate itself"));
        }
        Ok(Generator {
            factor,
            word: Word { mask, negative },
        })
    }

    /// The word this generator adds to the defining relation (`D=ABC` -> `I=ABCD`).
    pub fn defining_word(&self) -> Word {
        Word {
            mask: self.word.mask | (1u64 << self.factor),
            negative: self.word.negative,
        }
    }
}

impl fmt::Display for Generator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let l = LETTERS.get(self.factor).map(|&c| c as char).unwrap_or('?');
        write!(f, "{l} = {}", self.word)
    }
}

/// All words of the defining relation generated by `generators` (identity
/// excluded), sorted by length then letters.
pub(crate) fn defining_relation(generators: &[Generator]) -> Vec<Word> {
    let p = generators.len();
    let mut words: Vec<Word> = (1u64..(1u64 << p))
        .map(|subset| {
            generators
                .iter()
                .enumerate()
                .filter(|(i, _)| subset & (1u64 << i) != 0)
                .fold(
                    Word {
                        mask: 0,
                        negative: false,
                    },
                    |w, (_, g)| w.times(&g.defining_word()),
                )
        })
        .collect();
    words.sort_by_key(Word::key);
    words
}

/// One alias chain: an effect and the effects it cannot be told apart from.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct AliasChain {
    /// The lowest-order member (the effect the chain is named after).
    pub effect: Word,
    /// The other members, signed relative to `effect`, by order then letters.
    pub aliases: Vec<Word>,
}

impl fmt::Display for AliasChain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.effect)?;
        for a in &self.aliases {
            if a.negative {
                write!(
                    f,
                    " - {}",
                    Word {
                        negative: false,
                        ..*a
                    }
                )?;
            } else {
                write!(f, " + {a}")?;
            }
        }
        Ok(())
    }
}

/// Alias chains of every effect of order <= `max_order` among `k` factors,
/// each chain listed once under its lowest-order member.
pub(crate) fn alias_chains(k: usize, relation: &[Word], max_order: usize) -> Vec<AliasChain> {
    let mut effects: Vec<Word> = (1u64..(1u64 << k))
        .map(|mask| Word {
            mask,
            negative: false,
        })
        .filter(|w| w.len() <= max_order && !relation.iter().any(|d| d.mask == w.mask))
        .collect();
    effects.sort_by_key(Word::key);
    let mut seen = std::collections::HashSet::new();
    let mut chains = Vec::new();
    for e in effects {
        if !seen.insert(e.mask) {
            continue;
        }
        let mut aliases: Vec<Word> = relation.iter().map(|d| e.times(d)).collect();
        aliases.sort_by_key(Word::key);
        for a in &aliases {
            seen.insert(a.mask);
        }
        chains.push(AliasChain { effect: e, aliases });
    }
    chains
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_prints_generators() {
        let g = Generator::parse("D = -abc", 4).unwrap();
        assert_eq!(g.factor, 3);
        assert_eq!(g.to_string(), "D = -ABC");
        assert_eq!(g.defining_word().to_string(), "-ABCD");
        for bad in ["D", "DE=AB", "D=A", "D=ABD", "E=ABC", "D=AAB", "J=AB"] {
            assert!(Generator::parse(bad, 4).is_err(), "{bad}");
        }
        // Letters skip I: the ninth factor is J.
        assert_eq!(Generator::parse("J=AB", 9).unwrap().factor, 8);
    }

    #[test]
    fn two_generators_give_three_words() {
        // 2^(5-2) with D = AB, E = AC: I = ABD = ACE = BCDE (resolution III).
        let g = [
            Generator::parse("D=AB", 5).unwrap(),
            Generator::parse("E=AC", 5).unwrap(),
        ];
        let words: Vec<String> = defining_relation(&g).iter().map(Word::to_string).collect();
        assert_eq!(words, vec!["ABD", "ACE", "BCDE"]);
    }
}
