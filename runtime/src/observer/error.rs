//! What can go wrong in an observer update.

use core::fmt;

use crate::error::DataError;
use crate::lcp::LcpError;

/// Why an observer refused an update (or a construction, or a gain
/// estimate). Whenever an update returns one of these, the observer's state
/// is unchanged: the next update starts from the last good estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ObserverError<T> {
    /// Bad data, or a model that failed on it (the core shared with
    /// [`StepError`](crate::StepError)): a setting out of its range (`"l_d"`,
    /// `"velocity_bound"`, `"lambda"`, ...), a non-finite measurement
    /// (`"q"`; `"q0"`, `"v0"`, `"q_hat0"` for the initial data), parameter
    /// or input, a restitution outside `[0, 1]`, a mass matrix that is not
    /// positive definite, a non-finite model term (`"M"`, `"F"`, `"h"`,
    /// `"J"`, `"C"`, `"dF/dv"`), an unsolvable impact or contact problem,
    /// an overflow.
    Data(DataError<T>),
    /// The measurement time is not finite, or not after the last one.
    InvalidTime {
        /// The time given.
        t: T,
        /// The time of the last measurement.
        last: T,
    },
    /// The measurement is farther from the last accepted one than the
    /// system can move in the interval
    /// ([`ObserverParams::outlier_bound`](crate::ObserverParams::outlier_bound)):
    /// skipped, the estimate kept. The observer counts it (the next
    /// accepted update reports the count), and after
    /// [`max_outliers`](crate::ObserverParams::max_outliers) in a row it
    /// restarts from the measurement instead.
    Outlier {
        /// `|q − q_k|`.
        distance: T,
        /// The bound it exceeds.
        bound: T,
    },
}

impl<T> From<DataError<T>> for ObserverError<T> {
    fn from(e: DataError<T>) -> Self {
        ObserverError::Data(e)
    }
}

impl<T> From<LcpError<T>> for ObserverError<T> {
    fn from(e: LcpError<T>) -> Self {
        ObserverError::Data(DataError::Lcp(e))
    }
}

impl<T: fmt::Display> fmt::Display for ObserverError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Data(e) => e.fmt(f),
            Self::InvalidTime { t, last } => write!(
                f,
                "measurement time {t} is not finite or not after the last one, {last}"
            ),
            Self::Outlier { distance, bound } => write!(
                f,
                "outlier: the measurement is {distance} from the last accepted one, more than the system moves ({bound})"
            ),
        }
    }
}

#[cfg(feature = "std")]
impl<T: fmt::Debug + fmt::Display> std::error::Error for ObserverError<T> {}
