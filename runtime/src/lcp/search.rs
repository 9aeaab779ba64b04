//! Book-keeping shared by both phases: the trial count and the least
//! violating trial so far.

use nalgebra::RealField;

use super::trial::{Problem, Trial};

/// Trials made so far and the least violating one.
pub(crate) struct Search<T, const K: usize> {
    /// Complementary sets solved (singular ones included).
    pub trials: u32,
    /// The non-singular trial of least violation; the earliest on ties.
    pub best: Option<Trial<T, K>>,
}

impl<T: RealField + Copy, const K: usize> Search<T, K> {
    pub fn new() -> Self {
        Self {
            trials: 0,
            best: None,
        }
    }

    /// Solves the complementary set `set` (its independent subset, `first`
    /// eliminated first: see [`Problem::trial`]), counts it and remembers it
    /// if it is the least violating so far. `None` when `λ` overflowed.
    pub fn evaluate(
        &mut self,
        problem: &Problem<T, K>,
        set: u32,
        first: Option<usize>,
    ) -> Option<Trial<T, K>> {
        self.trials = self.trials.saturating_add(1);
        let trial = problem.trial(set, first)?;
        if self
            .best
            .is_none_or(|best| trial.violation < best.violation)
        {
            self.best = Some(trial);
        }
        Some(trial)
    }
}
