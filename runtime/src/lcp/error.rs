//! What can go wrong in an LCP solve.

use core::fmt;

/// Why [`Lcp::solve`](crate::Lcp::solve) returned no solution of
/// `w = Wλ + b, 0 ≤ λ ⊥ w ≥ 0`.
///
/// Indices are row/column indices of `W` and `b` (not positions within the
/// active set). Scaled quantities are dimensionless, measured as
/// [Tolerances](crate::Lcp#tolerances) describes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LcpError<T> {
    /// An active index is not a row of the `K × K` problem: `index ≥ K`.
    IndexOutOfRange {
        /// The offending active index.
        index: usize,
        /// The problem size `K`.
        dim: usize,
    },
    /// `W[(row, col)]` (`row`, `col` active) is NaN or infinite.
    NonFiniteMatrix {
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
    },
    /// `b[index]` (`index` active) is NaN or infinite.
    NonFiniteVector {
        /// Index of the entry.
        index: usize,
    },
    /// `|W[(row, col)] − W[(col, row)]| > τ ω`: `W` is not symmetric
    /// (`row > col`).
    NotSymmetric {
        /// Row of the entry below the diagonal.
        row: usize,
        /// Its column.
        col: usize,
    },
    /// `W[(index, index)] < −τ ω`: `W` is not positive semidefinite.
    NotPositiveSemidefinite {
        /// The row with the negative diagonal entry.
        index: usize,
    },
    /// No `λ ≥ 0` gives `Wλ + b ≥ 0`: the problem has no solution (or `W` is
    /// not positive semidefinite, or so ill-conditioned that no
    /// complementary set passed within the tolerance).
    ///
    /// When row `index` of `W` is zero (within tolerance) while `b[index] <
    /// 0`, that row alone proves it (`w_index = b_index` whatever `λ`);
    /// otherwise `index` is the most violated constraint of the least
    /// violating complementary set tried.
    Infeasible {
        /// A constraint that can't be satisfied (see above).
        index: usize,
        /// How much it is violated, in units of `w`: `−w_index / Ω`, or
        /// `−ω_index λ_index / Ω` for a negative multiplier.
        violation: T,
    },
    /// More than [`Lcp::MAX_ENUMERATED`](crate::Lcp::MAX_ENUMERATED) active
    /// rows, and principal pivoting did not finish, so the complete
    /// enumeration was not attempted.
    TooManyActive {
        /// The number of active, non-zero rows.
        active: usize,
        /// The largest number enumerated.
        max: usize,
    },
    /// More than [`Lcp::MAX_ACTIVE`](crate::Lcp::MAX_ACTIVE) rows active in
    /// one problem (a model may have any number of constraints; this many
    /// at once is refused, never cut short).
    ActiveSetTooLarge {
        /// The number of active rows.
        active: usize,
        /// The most one problem takes.
        max: usize,
    },
    /// A complementary set was found, but the complementarity residual of the
    /// returned `(λ, w)` exceeds the tolerance (ill-conditioned `W`).
    ResidualTooLarge {
        /// The residual `r` (see the module docs).
        residual: T,
        /// The tolerance `τ` it exceeds.
        tolerance: T,
    },
}

impl<T: fmt::Display> fmt::Display for LcpError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::IndexOutOfRange { index, dim } => {
                write!(
                    f,
                    "active index {index} is out of range for a {dim}×{dim} LCP"
                )
            }
            Self::NonFiniteMatrix { row, col } => {
                write!(f, "LCP matrix entry W[({row}, {col})] is not finite")
            }
            Self::NonFiniteVector { index } => {
                write!(f, "LCP vector entry b[{index}] is not finite")
            }
            Self::NotSymmetric { row, col } => write!(
                f,
                "LCP matrix is not symmetric: W[({row}, {col})] differs from W[({col}, {row})]"
            ),
            Self::NotPositiveSemidefinite { index } => write!(
                f,
                "LCP matrix is not positive semidefinite: W[({index}, {index})] is negative"
            ),
            Self::Infeasible { index, violation } => write!(
                f,
                "LCP is infeasible: constraint {index} stays violated (scaled violation {violation})"
            ),
            Self::TooManyActive { active, max } => write!(
                f,
                "LCP with {active} active rows was not solved by pivoting and is too large to enumerate (at most {max})"
            ),
            Self::ActiveSetTooLarge { active, max } => write!(
                f,
                "LCP with {active} active rows at once: at most {max} are solved"
            ),
            Self::ResidualTooLarge {
                residual,
                tolerance,
            } => write!(
                f,
                "LCP residual {residual} exceeds the tolerance {tolerance}"
            ),
        }
    }
}

#[cfg(feature = "std")]
impl<T: fmt::Debug + fmt::Display> std::error::Error for LcpError<T> {}
