//! One random stream per chain, derived from one seed (STYLE.md 11).
//!
//! Chain `c` uses `Xoshiro256PlusPlus::seed_from_u64(seed)` advanced by `c`
//! long jumps (2^192 steps each), so streams never overlap and a chain's
//! draws depend only on the seed and its index, never on which thread runs
//! it or how many threads there are.

use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

/// The random-number generator every sampler uses.
pub type ChainRng = Xoshiro256PlusPlus;

/// The stream of chain (or population) `index` for `seed`.
pub fn chain_rng(seed: u64, index: usize) -> ChainRng {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    for _ in 0..index {
        rng.long_jump();
    }
    rng
}

/// A standard normal draw (Box-Muller would waste half; `rand_distr`'s
/// ziggurat is exact and fast).
pub(crate) fn std_normal(rng: &mut ChainRng) -> f64 {
    use rand::Rng;
    rng.sample(rand_distr::StandardNormal)
}

/// A uniform draw in [0, 1).
pub(crate) fn uniform(rng: &mut ChainRng) -> f64 {
    use rand::Rng;
    rng.random::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngCore;

    #[test]
    fn streams_differ_and_repeat() {
        let a: Vec<u64> = (0..4).map(|_| chain_rng(7, 0).next_u64()).collect();
        assert!(a.iter().all(|&x| x == a[0]));
        assert_ne!(chain_rng(7, 0).next_u64(), chain_rng(7, 1).next_u64());
        assert_ne!(chain_rng(7, 1).next_u64(), chain_rng(8, 1).next_u64());
    }
}
