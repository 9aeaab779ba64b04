//! The error core the stepper and the observers share.

use core::fmt;

use crate::lcp::LcpError;

/// What is wrong with the data a step or an observer update was given, or
/// with what the model made of it: the part of
/// [`StepError`](crate::StepError) and [`ObserverError`](crate::ObserverError)
/// that both share (they wrap it as their `Data` variant).
///
/// ```
/// use moreau_runtime::{DataError, ObserverError, StepError};
///
/// let e = DataError::<f64>::NonFinite { which: "q", index: 1 };
/// // the same words whichever of the two wraps it
/// assert_eq!(e.to_string(), "q[1] is not finite");
/// assert_eq!(StepError::from(e).to_string(), e.to_string());
/// assert_eq!(ObserverError::from(e).to_string(), e.to_string());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DataError<T> {
    /// A setting is out of its range or not finite.
    InvalidParams {
        /// The setting's name (`"tau"`, `"theta"`, `"l_d"`,
        /// `"velocity_bound"`, `"lambda"`, ...).
        name: &'static str,
        /// Its value (for a matrix: the offending entry or eigenvalue).
        value: T,
    },
    /// A vector of the state or a measurement holds a NaN or an infinity.
    NonFinite {
        /// Which vector: `"t"`, `"q"`, `"v"` for a step or an update;
        /// `"q0"`, `"v0"`, `"q_hat0"` for an observer's initial data.
        which: &'static str,
        /// The entry (0 for a scalar).
        index: usize,
    },
    /// A model parameter is NaN or infinite.
    NonFiniteParameter {
        /// Its index in `ModelInfo::parameters`.
        index: usize,
    },
    /// An input is NaN or infinite.
    NonFiniteInput {
        /// The input's index.
        index: usize,
    },
    /// A restitution coefficient (the model's, or an observer's `ê`) is
    /// outside `[0, 1]` or NaN.
    InvalidRestitution {
        /// The constraint.
        constraint: usize,
        /// Its coefficient.
        value: T,
    },
    /// `M(q)` is not positive definite where it was evaluated (a pivot of its
    /// `L D Lᵀ` factorization is not positive).
    MassNotPositiveDefinite,
    /// The model returned a NaN or an infinity (overflow, or a function
    /// outside its domain, such as `sqrt` of a negative number).
    NonFiniteModel {
        /// Which term: `"M"`, `"F"`, `"h"`, `"J"`, `"W"`, ...
        which: &'static str,
    },
    /// An impact or contact problem could not be solved.
    Lcp(LcpError<T>),
    /// The result was not finite (overflow).
    NonFiniteResult,
}

impl<T> From<LcpError<T>> for DataError<T> {
    fn from(e: LcpError<T>) -> Self {
        DataError::Lcp(e)
    }
}

impl<T: fmt::Display> fmt::Display for DataError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidParams { name, value } => write!(f, "invalid setting: {name} = {value}"),
            Self::NonFinite { which, index } => write!(f, "{which}[{index}] is not finite"),
            Self::NonFiniteParameter { index } => {
                write!(f, "model parameter {index} is not finite")
            }
            Self::NonFiniteInput { index } => write!(f, "input {index} is not finite"),
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
            Self::NonFiniteResult => f.write_str("the result is not finite"),
        }
    }
}

#[cfg(feature = "std")]
impl<T: fmt::Debug + fmt::Display> std::error::Error for DataError<T> {}
