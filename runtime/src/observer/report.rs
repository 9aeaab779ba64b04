//! What an observer update tells its caller.

use nalgebra::{RealField, SVector};

use crate::lcp::IndexSet;

/// What happened in one update: `no_std` has no clock, so the stages are
/// counted, as the plant's [`StepReport`](crate::StepReport) does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateReport<T: RealField + Copy, const N: usize, const K: usize> {
    /// Time of the measurement, `t_{k+1}`.
    pub t: T,
    /// The sampling interval `τ = t_{k+1} − t_k`.
    pub tau: T,
    /// Impacts located inside the interval. With
    /// [`ImpactAware`](super::Discretization::ImpactAware): each Newton's
    /// law that gave an impulse to a constraint approaching faster than its
    /// resting speed (at a root of a gap along the predicted motion, at a
    /// closed constraint met approaching, or at the end of the interval);
    /// the plastic closure of a slower approach counts as a contact. With
    /// [`SectionVii`](super::Discretization::SectionVii): `1` when its LCP
    /// gave an impulse.
    pub impacts: u32,
    /// Time of the first impact in the interval, if any.
    pub first_impact: Option<T>,
    /// Constraints that received an impulse at an impact.
    pub impacted: IndexSet<K>,
    /// Constraints treated as persistent contacts during the interval (the
    /// mass sliding along them).
    pub contacts: IndexSet<K>,
    /// Every constraint that took part in a complementarity problem.
    pub active: IndexSet<K>,
    /// Sum over the interval of the multipliers per constraint: impulses `λ`
    /// of the impacts plus the integral `∫ λ dt` of the contact forces
    /// (momentum units, as `Jᵀλ`).
    pub impulses: SVector<T, K>,
    /// Complementarity problems solved.
    pub lcp_solves: u32,
    /// Complementary sets they tried, in total.
    pub lcp_trials: u32,
    /// The largest scaled complementarity residual among them.
    pub lcp_residual: T,
    /// The innovation `q_{k+1} − q_pred`: the measured end position minus
    /// the position predicted from `q_k` and the estimate (for
    /// `SectionVii`, `q_{k+1} − q_k − τ v̂_k`).
    pub innovation: SVector<T, N>,
    /// The injection gain `(1 − e^{−l_d τ}) / τ` the update used (the
    /// velocity correction is this times the innovation; `0` for the
    /// [`SaltationKalman`](crate::SaltationKalman) filter, which corrects
    /// with its Kalman gain instead).
    pub gain: T,
    /// Points at which the model's dynamics `(M, F̄)` were needed (for a
    /// model with constant `M` and `F`, the memo of one evaluation serves
    /// them all).
    pub evaluations: u32,
    /// Measurements skipped as outliers between the previous accepted
    /// update and this one.
    pub outliers: u32,
    /// `Some` when this update did not integrate the interval but restarted
    /// the estimate from the measurement, and why.
    pub restart: Option<Restart>,
    /// Whether the velocity estimate was held to the bound `C_v`
    /// ([`ObserverParams::velocity_bound`](super::ObserverParams::velocity_bound))
    /// at the end of this update (its norm would have exceeded it), or, at
    /// a [`restart`](Self::restart), whether the samples moved faster than
    /// `C_v` over the interval (the mean velocity past it). The estimators
    /// take the true velocity to be within `C_v` (Assumption 1; their
    /// forces are evaluated at `sat(v̂)`, and a sample farther than `C_v`
    /// lets the system move is refused as an outlier): a run of updates
    /// with this set says the machine moves faster than the bound they
    /// were given (or the sensor jumped), and that the estimate
    /// understates its speed: raise `C_v`. A refused sample leaves the
    /// report of the update before it.
    pub at_velocity_bound: bool,
}

/// Why an update restarted the estimate from the measurement (`q̂ = q`,
/// `v̂` held to `C_v`) instead of integrating the interval (see "Bad
/// samples, bad states, long gaps" in the module docs of
/// `runtime/src/observer/mod.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Restart {
    /// [`max_outliers`](super::ObserverParams::max_outliers) outliers in a
    /// row: the estimate, not the samples, was off. `v̂` is kept.
    Outliers,
    /// The interval is longer than
    /// [`max_interval`](super::ObserverParams::max_interval): `v̂` is the
    /// mean velocity over it, an extrapolation.
    LongInterval,
    /// Integrating the interval from the observer's own state failed (the
    /// model or an impact problem failed along the predicted motion): `v̂` is
    /// the mean velocity over the interval.
    Infeasible,
}

impl<T: RealField + Copy, const N: usize, const K: usize> UpdateReport<T, N, K> {
    /// An empty report for the interval ending at `t`, of length `tau`.
    pub(crate) fn new(t: T, tau: T) -> Self {
        Self {
            t,
            tau,
            impacts: 0,
            first_impact: None,
            impacted: IndexSet::EMPTY,
            contacts: IndexSet::EMPTY,
            active: IndexSet::EMPTY,
            impulses: SVector::zeros(),
            lcp_solves: 0,
            lcp_trials: 0,
            lcp_residual: T::zero(),
            innovation: SVector::zeros(),
            gain: T::zero(),
            evaluations: 0,
            outliers: 0,
            restart: None,
            at_velocity_bound: false,
        }
    }

    /// The velocity correction the last update's innovation made,
    /// `|d| (1 − e^{−l_d τ}) / τ` (0 before the first update): how much the
    /// estimate still moves, so how well it knows the velocity.
    pub(crate) fn uncertainty(&self) -> T {
        self.innovation.norm() * self.gain
    }
}
