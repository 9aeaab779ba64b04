//! Phase 2: every complementary set, in a fixed order.
//!
//! The sets `F ⊆ P` of the non-zero active positions `P` are visited by
//! Hamming distance from a centre set (the least violating set of phase 1),
//! and within one distance in increasing order of the flipped positions'
//! bit pattern (Gosper's next-combination). Each set is visited once; the
//! first that solves the LCP is returned. For positive semidefinite `W` a
//! solution whose `W_FF` is non-singular exists whenever any solution does
//! (see the module docs of `lcp`), so the enumeration is complete.

use nalgebra::RealField;

use super::search::Search;
use super::trial::{Problem, Trial};

/// Scatters the low bits of `compact` onto the set bits of `mask`, lowest
/// first (a software `pdep`).
#[inline]
fn deposit(mut compact: u32, mut mask: u32) -> u32 {
    let mut out = 0;
    while mask != 0 && compact != 0 {
        let low = mask & mask.wrapping_neg();
        if compact & 1 == 1 {
            out |= low;
        }
        compact >>= 1;
        mask &= mask - 1;
    }
    out
}

/// The next larger `u32` with as many set bits as `x > 0` (Gosper's hack);
/// callers keep `x < 2^16`, so nothing overflows.
#[inline]
fn next_combination(x: u32) -> u32 {
    let low = x & x.wrapping_neg();
    let ripple = x + low;
    (((ripple ^ x) >> 2) / low) | ripple
}

/// Tries every set at Hamming distance `1..=|P|` from `centre` (distance 0,
/// the centre itself, was tried in phase 1); the first solving trial.
/// Callers keep `|P| ≤ Lcp::MAX_ENUMERATED`.
pub(crate) fn enumerate<T: RealField + Copy, const K: usize>(
    problem: &Problem<T, K>,
    search: &mut Search<T, K>,
    centre: u32,
) -> Option<Trial<T, K>> {
    let free = problem.all() & !problem.zero;
    let n = free.count_ones();
    for distance in 1..=n {
        let mut flips: u32 = (1 << distance) - 1;
        while flips < 1 << n {
            let set = centre ^ deposit(flips, free);
            if let Some(trial) = search.evaluate(problem, set, None) {
                if trial.solves() {
                    return Some(trial);
                }
            }
            flips = next_combination(flips);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::{deposit, next_combination};

    #[test]
    fn deposit_scatters_onto_mask() {
        assert_eq!(deposit(0b101, 0b1011_0010), 0b0010_0010);
        assert_eq!(deposit(0b1111, 0b1011_0010), 0b1011_0010);
        assert_eq!(deposit(0, 0b111), 0);
    }

    #[test]
    fn combinations_of_two_in_four() {
        let mut x = 0b11;
        let mut seen = [0u32; 6];
        for s in &mut seen {
            *s = x;
            x = next_combination(x);
        }
        assert_eq!(seen, [0b0011, 0b0101, 0b0110, 0b1001, 0b1010, 0b1100]);
        assert!(x >= 1 << 4);
    }
}
