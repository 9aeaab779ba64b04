//! What a step tells its caller.

use nalgebra::{RealField, SVector};

use crate::lcp::IndexSet;

/// One impact: constraint `constraint` received the impulse `impulse` (the
/// LCP multiplier `λ > 0`, in the units of `Jᵀλ`, momentum) during the step
/// that ended at time `t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Impact<T> {
    /// End time of the step in which the impulse acted.
    pub t: T,
    /// The constraint's index.
    pub constraint: usize,
    /// The impulse `λ_constraint > 0`.
    pub impulse: T,
}

/// What happened in one step: `no_std` has no clock, so the stages are
/// counted rather than timed, and tests assert on the counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport<T: RealField + Copy, const K: usize> {
    /// End time of the step, `t_{k+1}`.
    pub t: T,
    /// The index set of the step (γ-prediction at the start).
    pub active: IndexSet<K>,
    /// The LCP multipliers `λ` of the last Newton iteration (zero off the
    /// index set).
    pub impulses: SVector<T, K>,
    /// Complementary sets the LCP tried, summed over Newton iterations.
    pub lcp_trials: u32,
    /// Scaled complementarity residual of the last LCP (0 when no
    /// constraint is active).
    pub lcp_residual: T,
    /// Newton iterations done.
    pub newton_iterations: u32,
    /// Final Newton residual `‖R_free − Jᵀλ‖₂`.
    pub newton_residual: T,
    /// Whether the Newton residual met the tolerance (when it did not, the
    /// step still returns the last iterate, as Siconos does).
    pub converged: bool,
}

impl<T: RealField + Copy, const K: usize> StepReport<T, K> {
    /// A report for the step ending at `t` with index set `active`, before
    /// any iteration.
    pub(super) fn new(t: T, active: IndexSet<K>) -> Self {
        Self {
            t,
            active,
            impulses: SVector::zeros(),
            lcp_trials: 0,
            lcp_residual: T::zero(),
            newton_iterations: 0,
            newton_residual: T::zero(),
            converged: false,
        }
    }

    /// Counts one Newton iteration whose impacts were `impulse`.
    pub(super) fn record<const N: usize>(&mut self, impulse: &super::Impulse<T, N, K>) {
        self.impulses = impulse.lambda;
        self.lcp_trials += impulse.trials;
        self.lcp_residual = impulse.residual;
        self.newton_iterations += 1;
    }

    /// The constraints that received an impulse (`λ > 0`) in this step.
    pub fn impacting(&self) -> IndexSet<K> {
        let mut set = IndexSet::new();
        for i in self.active {
            if self.impulses[i] > T::zero() {
                set.insert(i);
            }
        }
        set
    }

    /// The impulses of this step as [`Impact`]s, in constraint order.
    pub fn impacts(&self) -> impl Iterator<Item = Impact<T>> + '_ {
        self.impacting().into_iter().map(move |i| Impact {
            t: self.t,
            constraint: i,
            impulse: self.impulses[i],
        })
    }
}
