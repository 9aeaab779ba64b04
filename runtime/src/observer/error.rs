//! What can go wrong in an observer update.

use core::fmt;

use crate::lcp::LcpError;

/// Why an observer refused an update (or a construction, or a gain
/// estimate). Whenever an update returns one of these, the observer's state
/// is unchanged: the next update starts from the last good estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ObserverError<T> {
    /// A setting is out of its range or not finite.
    InvalidParams {
        /// The setting's name (`"l_d"`, `"velocity_bound"`, `"lambda"`, ...).
        name: &'static str,
        /// Its value (for a matrix: the offending entry or eigenvalue).
        value: T,
    },
    /// A measured coordinate is NaN or infinite.
    NonFiniteMeasurement {
        /// Which measurement: `"q"` for an update, `"q0"`, `"v0"` or
        /// `"q_hat0"` for the initial data.
        which: &'static str,
        /// The coordinate.
        index: usize,
    },
    /// The measurement time is not finite, or not after the last one.
    InvalidTime {
        /// The time given.
        t: T,
        /// The time of the last measurement.
        last: T,
    },
    /// An input is NaN or infinite.
    NonFiniteInput {
        /// The input's index.
        index: usize,
    },
    /// A model parameter is NaN or infinite.
    NonFiniteParameter {
        /// Its index in `ModelInfo::parameters`.
        index: usize,
    },
    /// A restitution coefficient (the model's, or the observer's `ê`) is
    /// outside `[0, 1]` or NaN.
    InvalidRestitution {
        /// The constraint.
        constraint: usize,
        /// Its coefficient.
        value: T,
    },
    /// `M(q)` is not positive definite where the observer evaluated it.
    MassNotPositiveDefinite,
    /// The model returned a NaN or an infinity (`"M"`, `"F"`, `"h"`, `"J"`,
    /// `"C"`, `"dF/dv"`).
    NonFiniteModel {
        /// Which term.
        which: &'static str,
    },
    /// An impact or contact problem could not be solved.
    Lcp(LcpError<T>),
    /// The update produced a non-finite estimate (overflow).
    NonFiniteResult,
}

impl<T> From<LcpError<T>> for ObserverError<T> {
    fn from(e: LcpError<T>) -> Self {
        ObserverError::Lcp(e)
    }
}

impl<T: fmt::Display> fmt::Display for ObserverError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidParams { name, value } => {
                write!(f, "invalid observer setting: {name} = {value}")
            }
            Self::NonFiniteMeasurement { which, index } => {
                write!(f, "the measurement is not finite: {which}[{index}]")
            }
            Self::InvalidTime { t, last } => write!(
                f,
                "measurement time {t} is not finite or not after the last one, {last}"
            ),
            Self::NonFiniteInput { index } => write!(f, "input {index} is not finite"),
            Self::NonFiniteParameter { index } => {
                write!(f, "model parameter {index} is not finite")
            }
            Self::InvalidRestitution { constraint, value } => write!(
                f,
                "restitution of constraint {constraint} is {value}, outside [0, 1]"
            ),
            Self::MassNotPositiveDefinite => {
                f.write_str("the mass matrix is not positive definite at this configuration")
            }
            Self::NonFiniteModel { which } => {
                write!(f, "the model evaluated {which} to a non-finite value")
            }
            Self::Lcp(e) => write!(f, "impact problem: {e}"),
            Self::NonFiniteResult => f.write_str("the update produced a non-finite estimate"),
        }
    }
}

#[cfg(feature = "std")]
impl<T: fmt::Debug + fmt::Display> std::error::Error for ObserverError<T> {}
