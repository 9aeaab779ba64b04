//! What can go wrong in a step.

use core::fmt;

use crate::error::DataError;
use crate::lcp::LcpError;

/// Why a step was refused. The caller's state is unchanged whenever a step
/// returns one of these.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StepError<T> {
    /// Bad data, or a model that failed on it (the core shared with
    /// [`ObserverError`](crate::ObserverError)): a setting out of its range
    /// (`τ ≤ 0`, `θ ∉ (0, 1]`, `γ ∉ [0, 1]`, a negative Newton tolerance,
    /// zero Newton iterations, a NaN), a non-finite state (`"t"`, `"q"`,
    /// `"v"`), parameter or input, a restitution outside `[0, 1]`, a mass
    /// matrix that is not positive definite, a non-finite model term, an
    /// unsolvable impact problem, an overflow.
    Data(DataError<T>),
    /// The iteration matrix `W = M + τθ ∂F/∂v + τ²θ² ∂F/∂q` is singular.
    SingularIterationMatrix,
    /// Time cannot be kept: the scalar type resolves `τ` at `t` too coarsely,
    /// `16 ε |t| ≥ τ` (which includes `t + τ == t`; in `f32` with `τ = 1` ms,
    /// from `t ≈ 524` s on). See [`MoreauJean::step`](crate::MoreauJean::step)
    /// on running long with a moving epoch.
    TimeDoesNotAdvance {
        /// The state's time.
        t: T,
        /// The step `τ`.
        tau: T,
    },
}

impl<T> From<DataError<T>> for StepError<T> {
    fn from(e: DataError<T>) -> Self {
        StepError::Data(e)
    }
}

impl<T> From<LcpError<T>> for StepError<T> {
    fn from(e: LcpError<T>) -> Self {
        StepError::Data(DataError::Lcp(e))
    }
}

impl<T: fmt::Display> fmt::Display for StepError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StepError::Data(e) => e.fmt(f),
            StepError::SingularIterationMatrix => {
                f.write_str("the iteration matrix M + τθ ∂F/∂v + τ²θ² ∂F/∂q is singular")
            }
            StepError::TimeDoesNotAdvance { t, tau } => write!(
                f,
                "time does not advance: t + τ rounds to t = {t} (τ = {tau}); \
                 count time from a nearer epoch"
            ),
        }
    }
}

#[cfg(feature = "std")]
impl<T: fmt::Debug + fmt::Display> std::error::Error for StepError<T> {}
