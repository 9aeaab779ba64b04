//! Phase 1: Murty's least-index principal pivoting from the first guess.
//!
//! Starting from `F₀ = {i : b_i < 0}`, solve the complementary set; if it is
//! not a solution, flip the smallest violated position (`λ_i < 0` leaves `F`,
//! `w_i < 0` enters it) and repeat. For positive definite `W` (a P-matrix)
//! this terminates at the solution (Murty 1974); in a time step it usually
//! does so within one or two pivots, because `F₀` is already the set of
//! approaching contacts.
//!
//! For merely semidefinite `W`, a set with dependent rows (a box resting on
//! four corners: four rows of rank three) is solved on the independent
//! subset its pivoted factorization finds, and the next flip starts from
//! that subset; a row entering such a set is eliminated first, so the row it
//! depends on is the one left out (an exchange, as in the simplex method).
//! The rule may then cycle: phase 1 stops after `2m + 2` trials, or at an
//! inaccurate (nearly singular) set, and hands over to
//! [`enumerate`](super::enumerate).

use nalgebra::RealField;

use super::search::Search;
use super::trial::{Problem, Trial};

/// At most `2m + 2` trials for `m` active rows.
#[inline]
pub(crate) fn max_pivots(m: usize) -> usize {
    2 * m + 2
}

/// Runs Murty's least-index rule from [`Problem::first_guess`]; the solving
/// trial, or `None` when a set was singular or inaccurate (nearly singular)
/// or the pivot budget ran out.
pub(crate) fn principal_pivoting<T: RealField + Copy, const K: usize>(
    problem: &Problem<T, K>,
    search: &mut Search<T, K>,
) -> Option<Trial<T, K>> {
    let mut set = problem.first_guess();
    let mut entering = None;
    for _ in 0..max_pivots(problem.m) {
        let trial = search.evaluate(problem, set, entering)?;
        if !trial.accurate {
            return None;
        }
        let Some(p) = trial.first_violated else {
            return Some(trial);
        };
        // flip p in the independent subset actually solved; an entering
        // row is eliminated first, so that a row it depends on leaves
        set = trial.set ^ (1 << p);
        entering = Some(p).filter(|&p| (set >> p) & 1 == 1);
    }
    None
}
