//! What can go wrong in a step.

use core::fmt;

use crate::lcp::LcpError;

/// Why a step was refused. The caller's state is unchanged whenever a step
/// returns one of these.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StepError<T> {
    /// A setting is out of its range: `τ ≤ 0`, `θ ∉ (0, 1]`, `γ ∉ [0, 1]`,
    /// a negative Newton tolerance, zero Newton iterations, or a NaN.
    InvalidParams {
        /// The setting's name (`"tau"`, `"theta"`, ...).
        name: &'static str,
        /// Its value.
        value: T,
    },
    /// The state holds a NaN or an infinity.
    NonFiniteState {
        /// `"t"`, `"q"` or `"v"`.
        which: &'static str,
        /// The entry (0 for `t`).
        index: usize,
    },
    /// A model parameter is NaN or infinite.
    NonFiniteParameter {
        /// Its index in `ModelInfo::parameters`.
        index: usize,
    },
    /// A restitution coefficient is outside `[0, 1]` (or NaN).
    InvalidRestitution {
        /// The constraint.
        constraint: usize,
        /// Its coefficient.
        value: T,
    },
    /// An input is NaN or infinite.
    NonFiniteInput {
        /// The input's index.
        index: usize,
    },
    /// `M(q)` is not positive definite at the step's configuration (its
    /// Cholesky factorization failed).
    MassNotPositiveDefinite,
    /// The iteration matrix `W = M + τθ ∂F/∂v + τ²θ² ∂F/∂q` is singular.
    SingularIterationMatrix,
    /// The model returned a NaN or an infinity (overflow, or a function
    /// outside its domain, such as `sqrt` of a negative number).
    NonFiniteModel {
        /// Which term: `"M"`, `"F"`, `"h"`, `"J"`, ...
        which: &'static str,
    },
    /// The impact problem could not be solved.
    Lcp(LcpError<T>),
    /// The step produced a non-finite state (overflow).
    NonFiniteResult,
}

impl<T> From<LcpError<T>> for StepError<T> {
    fn from(e: LcpError<T>) -> Self {
        StepError::Lcp(e)
    }
}

impl<T: fmt::Display> fmt::Display for StepError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StepError::InvalidParams { name, value } => {
                write!(f, "invalid step setting: {name} = {value}")
            }
            StepError::NonFiniteState { which, index } => {
                write!(f, "the state is not finite: {which}[{index}]")
            }
            StepError::NonFiniteParameter { index } => {
                write!(f, "model parameter {index} is not finite")
            }
            StepError::InvalidRestitution { constraint, value } => write!(
                f,
                "restitution of constraint {constraint} is {value}, outside [0, 1]"
            ),
            StepError::NonFiniteInput { index } => write!(f, "input {index} is not finite"),
            StepError::MassNotPositiveDefinite => {
                f.write_str("the mass matrix is not positive definite at this configuration")
            }
            StepError::SingularIterationMatrix => {
                f.write_str("the iteration matrix M + τθ ∂F/∂v + τ²θ² ∂F/∂q is singular")
            }
            StepError::NonFiniteModel { which } => {
                write!(f, "the model evaluated {which} to a non-finite value")
            }
            StepError::Lcp(e) => write!(f, "impact problem: {e}"),
            StepError::NonFiniteResult => f.write_str("the step produced a non-finite state"),
        }
    }
}

#[cfg(feature = "std")]
impl<T: fmt::Debug + fmt::Display> std::error::Error for StepError<T> {}
