//! The linear complementarity problem of one Moreau–Jean step:
//!
//! $$w = W\lambda + b, \qquad 0 \le \lambda \perp w \ge 0,$$
//!
//! on the step's index set `A` of active constraints, with `W = J M⁻¹ Jᵀ`
//! symmetric positive semidefinite and `K ≤ 8` in practice.
//!
//! # Algorithm: principal pivoting, completed by enumeration
//!
//! A *complementary set* `F ⊆ A` asks for `w_F = 0` and `λ_{A∖F} = 0`, i.e.
//! `W_FF λ_F = −b_F`; it solves the LCP when `λ_F ≥ 0` and `w_{A∖F} ≥ 0`.
//! Every *trial* factors `W_FF` afresh from the data and tests the signs, so
//! the answer is exact up to one backward-stable solve: nothing is updated
//! in place from trial to trial, as a pivoting tableau (Lemke,
//! Cottle–Dantzig) would be, so no rounding error accumulates and no
//! anti-cycling rule with tolerances of its own is needed. The factorization
//! is `LDLᵀ` with diagonal pivoting on the unit-diagonal scaling of `W_FF`,
//! which finds the rank of a singular `W_FF` (dependent constraints, such as
//! the four corners of a box resting on a plane: four rows of rank three);
//! the trial is then of the independent subset it eliminated.
//!
//! 1. [`pivot`]: Murty's least-index principal pivoting from the first guess
//!    `F₀ = {i : b_i < 0}` (the constraints that zero impulse would leave
//!    approaching), at most `2m + 2` trials. A row entering a set is
//!    eliminated first, so that a row it depends on leaves (an exchange).
//!    Finite for positive definite `W`; in a time step it usually stops at
//!    `F₀` or one pivot later. Measured (`f64`, release, one core of this
//!    project's machine): 40 ns for one constraint, 150–250 ns for three,
//!    about 1–2 µs for eight in general position.
//! 2. [`enumerate`]: when phase 1 runs out of pivots (semidefinite `W` may
//!    cycle) or meets a nearly singular set, every complementary set of the
//!    non-zero active rows, by Hamming distance from the least violating set
//!    of phase 1, in a fixed order: at most `2^m` trials, `m ≤ 16`
//!    ([`Lcp::MAX_ENUMERATED`]).
//!
//! Why this finds a solution whenever one exists: `W = GGᵀ` for some `G`,
//! and `Gᵀλ` is the same for every solution (the LCP is the KKT system of the
//! convex QP `min ½ zᵀWz + bᵀz, z ≥ 0`, whose optimal `Wz` and `zᵀWz` are
//! unique). Carathéodory's theorem writes `Gᵀλ` as a non-negative
//! combination of linearly independent rows of `G` within the support of
//! `λ`: a solution whose `W_FF` is non-singular, which phase 2 reaches. So
//! the multipliers of dependent constraints (two equal rows of `J`, a zero
//! row) are not unique, the one returned is the first in the fixed order,
//! and `w` (and the post-impact velocity `v + M⁻¹Jᵀλ`, through `Jᵀλ`) is the
//! unique one.
//!
//! Why not pivoting alone: with dependent constraints and ties in `b`
//! (resting contact makes both common), a pivoting rule needs degeneracy
//! resolution that is hard to make both finite and tolerance-robust; for
//! `m ≤ 8` the `2^m ≤ 256` sets of phase 2 are an affordable guarantee that
//! a time step rarely pays. Why not enumeration alone: `2^m` trials in the
//! worst order where pivoting usually needs one or two.
//!
//! Same input, same sequence of trials, same bits out: nothing depends on
//! earlier calls, addresses or threads. Everything lives in `[T; K]` arrays
//! on the stack; nothing allocates and nothing panics on data.
//!
//! # Files
//!
//! `trial.rs` gathers and checks the active block and solves one set,
//! `search.rs` counts trials and keeps the least violating one, `pivot.rs`
//! and `enumerate.rs` are the two phases, `residual.rs` the residual, and
//! `index_set.rs` the [`IndexSet`] the stepper and observers share.

#![allow(non_snake_case)] // W, as in the equations

use nalgebra::{RealField, SMatrix, SVector};

mod enumerate;
mod error;
mod index_set;
mod on_set;
mod pivot;
mod residual;
mod search;
mod trial;

pub use error::LcpError;
pub use index_set::{IndexSet, Iter as IndexSetIter};
pub(crate) use on_set::OnSet;
pub use residual::lcp_residual;

use residual::natural_residual;
use search::Search;
use trial::{Problem, Trial, roundoff};

/// Solver settings for `w = Wλ + b, 0 ≤ λ ⊥ w ≥ 0`; [`Lcp::solve`] solves.
///
/// `Lcp::default()` is what a time step wants; keep one (its default
/// tolerance costs a cube root to make). The solver is principal pivoting
/// (Murty's least-index rule from `F₀ = {i : b_i < 0}`), completed, when that
/// does not finish, by the enumeration of every complementary set in a fixed
/// order, each solved afresh from the data by a rank-revealing `LDLᵀ`: exact
/// up to round-off, deterministic, and sure to find a solution of a feasible
/// positive semidefinite problem (the source of the `lcp` module says why).
///
/// # Tolerances
///
/// All tests are relative to the scales of the active problem, so scaling
/// `W` or `b` changes no decision. With `ε` the machine epsilon of `T`,
/// `m = |A|`, and over active `i, j`:
///
/// - `β = max |b_i|`, the scale of the velocities, is the scale `Ω` of `w`
///   (if `b = 0`, `Ω = max_i ω_i |λ_i|`); `ω_i = max_j |W_ji|` turns `λ_i`
///   into the largest change of `w` it makes; `ω = max_i ω_i`.
/// - `τ₀ = 256 (m + 1) ε` is round-off. A complementary set `F` is accepted
///   when `ω_i λ_i ≥ −τ₀ Ω` on it, `w_i ≥ −τ₀ Ω` off it, and the solve is
///   accurate, `|w_i| ≤ τ₀ Ω` on it. The factorization of `W_FF` stops at
///   its rank when every remaining pivot has `d_j ≤ τ₀ W_jj` (those rows lie
///   within an angle `≈ √τ₀` of the span of the others, in the `M⁻¹`
///   metric). Row `i` is zero when `W_ii ≤ τ₀ ω`, and then `b_i < −τ₀ β` is
///   infeasible.
/// - `τ =` [`tolerance`](Self::tolerance) (default `ε^⅓`, at least `τ₀`)
///   bounds the returned [`residual`](LcpSolution::residual)
///   `r = max_i |min(ω_i λ_i, w_i)| / Ω` (see [`lcp_residual`]). If no set is
///   accepted at `τ₀` (ill-conditioned `W`), the least violating set is
///   returned when its violation is at most `τ`. `τ ω` also bounds the
///   asymmetry `|W_ij − W_ji|` and `−W_ii`.
///
/// `w` is measured against the velocities, not against the terms `W_ij λ_j`
/// it sums: a nearly singular set whose huge multipliers cancel to a `w`
/// with no correct digits is rejected, not returned as a solution. So `w_i ≥
/// −τ β` for the returned solution: no active constraint is left approaching
/// faster than `τ` times the velocity scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lcp<T> {
    /// `τ`: the largest scaled residual accepted (default `ε^⅓`; values below
    /// the round-off level `τ₀`, and NaN, mean `τ₀`). See
    /// [Tolerances](Self#tolerances).
    pub tolerance: T,
}

impl<T: RealField + Copy> Default for Lcp<T> {
    fn default() -> Self {
        Self {
            tolerance: Self::default_tolerance(),
        }
    }
}

/// A solution of `w = Wλ + b, 0 ≤ λ ⊥ w ≥ 0` on the active set, from
/// [`Lcp::solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LcpSolution<T: RealField + Copy, const K: usize> {
    /// The multipliers (impulses) `λ`: `λ_i ≥ 0` on active rows (exactly:
    /// round-off negatives are set to `0`), `λ_i = 0` on inactive ones.
    pub lambda: SVector<T, K>,
    /// `w = Wλ + b` on active rows, computed from the returned `λ` (so
    /// `w_i ≥ −τ β`, `β = max_{i∈A} |b_i|`); `0` on inactive rows, which are
    /// never read.
    pub w: SVector<T, K>,
    /// The scaled complementarity residual `r = max_i |min(ω_i λ_i, w_i)| / Ω`
    /// of the returned `(λ, w)`, in `[0, τ]` (see [`lcp_residual`]).
    pub residual: T,
    /// The complementary set chosen: the rows where `λ` was solved for
    /// (`w_i = 0` there), `λ_i = 0` on the other active rows. Its rows of `W`
    /// are linearly independent.
    pub support: IndexSet<K>,
    /// Complementary sets tried (factorizations), `0` for an empty active
    /// set. `1` when the first guess `{i : b_i < 0}` solved it; in phase 1
    /// each further trial is one principal pivot.
    pub trials: u32,
}

impl<T: RealField + Copy> Lcp<T> {
    /// Largest number of non-zero active rows whose `2^m` complementary sets
    /// are enumerated when pivoting does not finish.
    pub const MAX_ENUMERATED: usize = 16;

    /// Largest number of rows active in one problem (the solver names its
    /// complementary sets by the bits of a `u32`); more is
    /// [`LcpError::ActiveSetTooLarge`]. A model may have any number of
    /// constraints `K`: this bounds only how many take part in one impact.
    pub const MAX_ACTIVE: usize = 32;

    /// Settings with the default tolerance `τ = ε^⅓`.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Settings with tolerance `τ = tolerance` (see
    /// [Tolerances](Self#tolerances)).
    #[must_use]
    pub fn with_tolerance(tolerance: T) -> Self {
        Self { tolerance }
    }

    /// The default tolerance `τ = ε^⅓` (`6.1e-6` for `f64`, `4.9e-3` for
    /// `f32`): `w` right to about five (two) digits of the velocities `b`
    /// even when `W` is ill-conditioned (nearly dependent constraints need
    /// multipliers `ω λ` up to `τ / ε ≈ 10¹⁰` times `b`, and cancellation
    /// costs that many digits). Well-conditioned problems are solved to
    /// round-off whatever `τ` is.
    #[must_use]
    pub fn default_tolerance() -> T {
        crate::linalg::cbrt_epsilon()
    }

    /// Solves `w = Wλ + b, 0 ≤ λ ⊥ w ≥ 0` on the rows and columns in
    /// `active`; inactive rows get `λ_i = 0` and are not constrained.
    ///
    /// `W` must be symmetric positive semidefinite (as `J M⁻¹ Jᵀ` is); it
    /// may be singular. Only the active rows and columns of `W` (both
    /// triangles) and the active entries of `b` are read. Non-finite read
    /// entries, an index `≥ K`, asymmetry or a negative diagonal beyond the
    /// tolerance, and infeasibility are errors, never panics; see
    /// [`LcpError`] and [Tolerances](Self#tolerances).
    ///
    /// Where `W` is singular `λ` is not unique; the one returned is
    /// deterministic (the first solving set in a fixed order), and `w` is
    /// the unique one.
    ///
    /// ```
    /// use moreau_runtime::{IndexSet, Lcp, LcpError};
    /// use nalgebra::{Matrix3, Vector3};
    ///
    /// let W = Matrix3::new(
    ///     2.0, 1.0, f64::NAN, // row and column 2 are inactive: never read
    ///     1.0, 2.0, f64::NAN,
    ///     f64::NAN, f64::NAN, f64::NAN,
    /// );
    /// let b = Vector3::new(-1.0, 1.0, f64::NAN);
    /// let active = IndexSet::from_indices(&[0, 1]).unwrap();
    ///
    /// let s = Lcp::default().solve(&W, &b, active)?;
    /// assert_eq!(s.lambda, Vector3::new(0.5, 0.0, 0.0));
    /// assert_eq!(s.w, Vector3::new(0.0, 1.5, 0.0));
    /// assert_eq!(s.support, IndexSet::from_indices(&[0]).unwrap());
    /// assert_eq!((s.residual, s.trials), (0.0, 1));
    ///
    /// // A zero row with b < 0 can't be satisfied:
    /// let err = Lcp::default().solve(&Matrix3::zeros(), &Vector3::new(1.0, -1.0, 0.0), IndexSet::full(3));
    /// assert!(matches!(err, Err(LcpError::Infeasible { index: 1, .. })));
    /// # Ok::<(), LcpError<f64>>(())
    /// ```
    pub fn solve<const K: usize>(
        &self,
        W: &SMatrix<T, K, K>,
        b: &SVector<T, K>,
        active: IndexSet<K>,
    ) -> Result<LcpSolution<T, K>, LcpError<T>> {
        let tolerance = self.effective_tolerance(active.len());
        // CHECK: gather the active block, reject bad data.
        let problem = Problem::gather(W, b, active, tolerance)?;
        if problem.m == 0 {
            return Ok(LcpSolution {
                lambda: SVector::zeros(),
                w: SVector::zeros(),
                residual: T::zero(),
                support: IndexSet::EMPTY,
                trials: 0,
            });
        }
        // SOLVE: phase 1, then phase 2 around the least violating set.
        let mut search = Search::new();
        let mut found = pivot::principal_pivoting(&problem, &mut search);
        let free = (problem.all() & !problem.zero).count_ones() as usize;
        let enumerable = free <= Self::MAX_ENUMERATED;
        if found.is_none() && enumerable {
            let centre = search
                .best
                .map_or_else(|| problem.first_guess(), |best| best.set);
            found = enumerate::enumerate(&problem, &mut search, centre);
        }
        let trial = match (found, search.best) {
            (Some(trial), _) => trial,
            (None, Some(best)) if best.violation <= tolerance => best,
            (None, _) if !enumerable => {
                return Err(LcpError::TooManyActive {
                    active: free,
                    max: Self::MAX_ENUMERATED,
                });
            }
            (None, Some(best)) if best.sign_violation <= tolerance => {
                return Err(LcpError::ResidualTooLarge {
                    residual: best.violation,
                    tolerance,
                });
            }
            (None, best) => {
                // `best` is `Some`: the empty set is never singular and was tried
                let (worst, violation) = best.map_or((0, T::one()), |b| (b.worst, b.violation));
                return Err(LcpError::Infeasible {
                    index: problem.index[worst],
                    violation,
                });
            }
        };
        // WRITEBACK
        finish(&problem, &trial, search.trials, tolerance)
    }

    /// `τ`, at least the round-off level `τ₀` of an `m`-row problem.
    fn effective_tolerance(&self, m: usize) -> T {
        let floor = roundoff::<T>(m);
        if self.tolerance > floor {
            self.tolerance
        } else {
            floor
        }
    }
}

/// Solves `w = Wλ + b, 0 ≤ λ ⊥ w ≥ 0` on `active` with the default
/// settings: `Lcp::default().solve(W, b, active)` (see [`Lcp::solve`]).
///
/// ```
/// use moreau_runtime::{solve_lcp, IndexSet};
/// use nalgebra::{Matrix1, Vector1};
///
/// // one constraint: λ = max(0, −b/W)
/// let s = solve_lcp(&Matrix1::new(4.0), &Vector1::new(-2.0), IndexSet::full(1)).unwrap();
/// assert_eq!((s.lambda[0], s.w[0]), (0.5, 0.0));
/// ```
pub fn solve_lcp<T: RealField + Copy, const K: usize>(
    W: &SMatrix<T, K, K>,
    b: &SVector<T, K>,
    active: IndexSet<K>,
) -> Result<LcpSolution<T, K>, LcpError<T>> {
    Lcp::default().solve(W, b, active)
}

/// Clamps `λ_F ≥ 0`, recomputes `w = Wλ + b` on the active rows, checks the
/// residual against `τ` and scatters back to full size.
fn finish<T: RealField + Copy, const K: usize>(
    problem: &Problem<T, K>,
    trial: &Trial<T, K>,
    trials: u32,
    tolerance: T,
) -> Result<LcpSolution<T, K>, LcpError<T>> {
    let m = problem.m;
    let mut lambda = [T::zero(); K];
    for (l, &x) in lambda.iter_mut().zip(&trial.lambda).take(m) {
        *l = x.max(T::zero());
    }
    let in_support = |p: usize| (trial.set >> p) & 1 == 1;
    let mut w = [T::zero(); K];
    for ((wp, &bp), row) in w.iter_mut().zip(&problem.b).zip(&problem.W).take(m) {
        *wp = (0..m)
            .filter(|&q| in_support(q))
            .fold(bp, |s, q| s + row[q] * lambda[q]);
    }
    let residual = natural_residual(&lambda[..m], &w[..m], &problem.col[..m], problem.beta);
    // written so that a NaN residual fails too
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(residual <= tolerance) {
        return Err(LcpError::ResidualTooLarge {
            residual,
            tolerance,
        });
    }
    let mut solution = LcpSolution {
        lambda: SVector::zeros(),
        w: SVector::zeros(),
        residual,
        support: IndexSet::EMPTY,
        trials,
    };
    for p in 0..m {
        let i = problem.index[p];
        solution.lambda[i] = lambda[p];
        solution.w[i] = w[p];
        if (trial.set >> p) & 1 == 1 {
            solution.support.insert(i);
        }
    }
    Ok(solution)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

    #[test]
    fn empty_problem_k0() {
        let W = SMatrix::<f64, 0, 0>::zeros();
        let b = SVector::<f64, 0>::zeros();
        let s = solve_lcp(&W, &b, IndexSet::EMPTY).unwrap();
        assert_eq!((s.residual, s.trials, s.support), (0.0, 0, IndexSet::EMPTY));
        // an index out of range cannot be asked for: the set of a K = 0
        // problem holds none
        assert!(IndexSet::<0>::full(1).is_empty());
        assert_eq!(IndexSet::<0>::from_indices(&[0]), None);
    }

    #[test]
    fn empty_active_set_reads_nothing() {
        let W = Matrix2::from_element(f64::NAN);
        let b = Vector2::from_element(f64::NAN);
        let s = solve_lcp(&W, &b, IndexSet::EMPTY).unwrap();
        assert_eq!((s.lambda, s.w), (Vector2::zeros(), Vector2::zeros()));
    }

    #[test]
    fn one_constraint_closed_form() {
        // λ = max(0, −b/W), w = max(0, b)
        for (W, b) in [
            (2.0, -3.0),
            (2.0, 3.0),
            (0.5, 0.0),
            (1e-9, -1e-3),
            (7.0, -0.0),
        ] {
            let s = solve_lcp(&Matrix1(W), &Vector1(b), IndexSet::full(1)).unwrap();
            assert_eq!(s.lambda[0], (-b / W).max(0.0), "W = {W}, b = {b}");
            assert_eq!(s.w[0], b.max(0.0), "W = {W}, b = {b}");
            assert_eq!(s.residual, 0.0);
            assert_eq!(s.trials, 1);
        }
    }

    fn Matrix1(x: f64) -> nalgebra::Matrix1<f64> {
        nalgebra::Matrix1::new(x)
    }

    fn Vector1(x: f64) -> nalgebra::Vector1<f64> {
        nalgebra::Vector1::new(x)
    }

    #[test]
    fn known_two_by_two_problems() {
        let W = Matrix2::new(2.0, 1.0, 1.0, 2.0);
        // both approach, both stay in contact: λ = W⁻¹(1, 1) = (1/3, 1/3)
        let s = solve_lcp(&W, &Vector2::new(-1.0, -1.0), IndexSet::full(2)).unwrap();
        assert!((s.lambda - Vector2::new(1.0 / 3.0, 1.0 / 3.0)).amax() < 1e-15);
        assert!(s.w.amax() < 1e-15);
        assert_eq!(s.support, IndexSet::full(2));
        // the second one is pushed off by the first: λ = (2, 0), w = (0, 1)
        let s = solve_lcp(&W, &Vector2::new(-4.0, 3.0), IndexSet::full(2)).unwrap();
        assert_eq!(
            (s.lambda, s.w),
            (Vector2::new(2.0, 0.0), Vector2::new(0.0, 5.0))
        );
        // the guess {0, 1} gives λ₁ < 0; one Murty pivot drops it: λ = (2, 0), w = (0, 1)
        let s = solve_lcp(&W, &Vector2::new(-4.0, -1.0), IndexSet::full(2)).unwrap();
        assert_eq!(
            (s.lambda, s.w),
            (Vector2::new(2.0, 0.0), Vector2::new(0.0, 1.0))
        );
        assert_eq!(s.trials, 2);
        assert_eq!(s.support, IndexSet::full(1));
        // only row 1 active: row 0 is ignored and gets λ₀ = 0, w₀ = 0
        let s = solve_lcp(
            &W,
            &Vector2::new(-4.0, -1.0),
            IndexSet::from_bits(0b10).unwrap(),
        )
        .unwrap();
        assert_eq!((s.lambda, s.w), (Vector2::new(0.0, 0.5), Vector2::zeros()));
    }

    #[test]
    fn equal_rows_give_a_valid_deterministic_multiplier() {
        // two identical constraints (singular W): the guess {0, 1} is singular,
        // so enumeration takes over; either multiplier alone solves it.
        let W = Matrix2::new(1.0, 1.0, 1.0, 1.0);
        let b = Vector2::new(-2.0, -2.0);
        let s = solve_lcp(&W, &b, IndexSet::full(2)).unwrap();
        assert_eq!(s.lambda.sum(), 2.0);
        assert_eq!(s.w, Vector2::zeros());
        let again = solve_lcp(&W, &b, IndexSet::full(2)).unwrap();
        assert_eq!(s, again);
        // the less approaching one must not get the impulse
        let s = solve_lcp(&W, &Vector2::new(-1.0, -2.0), IndexSet::full(2)).unwrap();
        assert_eq!(
            (s.lambda, s.w),
            (Vector2::new(0.0, 2.0), Vector2::new(1.0, 0.0))
        );
    }

    #[test]
    fn zero_row_with_negative_b_is_infeasible() {
        let W = Matrix2::new(1.0, 0.0, 0.0, 0.0);
        let err = solve_lcp(&W, &Vector2::new(-1.0, -0.5), IndexSet::full(2)).unwrap_err();
        assert_eq!(
            err,
            LcpError::Infeasible {
                index: 1,
                violation: 0.5
            }
        );
        // a zero row with b ≥ 0 is fine: λ₁ = 0, w₁ = b₁
        let s = solve_lcp(&W, &Vector2::new(-1.0, 0.5), IndexSet::full(2)).unwrap();
        assert_eq!(
            (s.lambda, s.w),
            (Vector2::new(1.0, 0.0), Vector2::new(0.0, 0.5))
        );
    }

    #[test]
    fn opposed_constraints_with_no_room_are_infeasible() {
        // w₀ + w₁ = −2 whatever λ: no zero row, yet no solution.
        let W = Matrix2::new(1.0, -1.0, -1.0, 1.0);
        let err = solve_lcp(&W, &Vector2::new(-1.0, -1.0), IndexSet::full(2)).unwrap_err();
        assert!(matches!(err, LcpError::Infeasible { violation, .. } if violation > 0.5));
    }

    #[test]
    fn non_finite_input_names_the_entry() {
        let mut W = Matrix3::identity();
        let b = Vector3::new(-1.0, f64::INFINITY, 0.0);
        let err = solve_lcp(&W, &b, IndexSet::full(3)).unwrap_err();
        assert_eq!(err, LcpError::NonFiniteVector { index: 1 });
        W[(2, 0)] = f64::NAN;
        let b = Vector3::new(-1.0, 0.0, 0.0);
        let err = solve_lcp(&W, &b, IndexSet::full(3)).unwrap_err();
        assert_eq!(err, LcpError::NonFiniteMatrix { row: 2, col: 0 });
        // not read when row and column 2 are inactive
        assert!(solve_lcp(&W, &b, IndexSet::full(2)).is_ok());
    }

    #[test]
    fn asymmetric_or_indefinite_matrix_is_rejected() {
        let W = Matrix2::new(1.0, 0.5, 0.0, 1.0);
        let err = solve_lcp(&W, &Vector2::new(-1.0, 1.0), IndexSet::full(2)).unwrap_err();
        assert_eq!(err, LcpError::NotSymmetric { row: 1, col: 0 });
        let W = Matrix2::new(1.0, 0.0, 0.0, -1.0);
        let err = solve_lcp(&W, &Vector2::new(-1.0, 1.0), IndexSet::full(2)).unwrap_err();
        assert_eq!(err, LcpError::NotPositiveSemidefinite { index: 1 });
    }

    #[test]
    fn f32_problem() {
        let W = Matrix2::new(2.0f32, 1.0, 1.0, 2.0);
        let s = Lcp::<f32>::default()
            .solve(&W, &Vector2::new(-1.0, -1.0), IndexSet::full(2))
            .unwrap();
        assert!((s.lambda - Vector2::new(1.0 / 3.0, 1.0 / 3.0)).amax() < 1e-6);
        assert!(s.residual <= Lcp::<f32>::default_tolerance());
        let err = solve_lcp(&W, &Vector2::new(f32::NAN, 0.0), IndexSet::full(2)).unwrap_err();
        assert_eq!(err, LcpError::NonFiniteVector { index: 0 });
    }

    #[test]
    fn scaling_the_problem_changes_no_decision() {
        let W = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, 1.0, 0.5, 1.0, 2.0);
        let b = Vector3::new(-1.0, 2.0, -3.0);
        let s = solve_lcp(&W, &b, IndexSet::full(3)).unwrap();
        for scale in [1e-200, 1e-8, 1e8, 1e200] {
            let t = solve_lcp(&(W * scale), &(b * scale), IndexSet::full(3)).unwrap();
            assert_eq!((s.support, s.trials), (t.support, t.trials));
            assert!((t.lambda - s.lambda).amax() <= 1e-14 * s.lambda.amax());
        }
        // scaling W alone scales λ inversely
        let t = solve_lcp(&(W * 1e6), &b, IndexSet::full(3)).unwrap();
        assert!((t.lambda * 1e6 - s.lambda).amax() <= 1e-14 * s.lambda.amax());
    }

    #[test]
    fn tolerance_below_roundoff_or_nan_means_roundoff() {
        let lcp = Lcp::with_tolerance(f64::NAN);
        assert_eq!(lcp.effective_tolerance(2), roundoff::<f64>(2));
        let lcp = Lcp::with_tolerance(0.0);
        assert_eq!(lcp.effective_tolerance(2), roundoff::<f64>(2));
        assert_eq!(
            Lcp::<f64>::new().effective_tolerance(2),
            f64::EPSILON.cbrt()
        );
    }

    #[test]
    fn many_copies_of_one_constraint_take_one_trial() {
        // 16 copies of one constraint, approaching equally fast: the first
        // guess is singular, its pivoted factorization keeps one row, and the
        // other fifteen then have w = 0.
        let W = SMatrix::<f64, 16, 16>::from_element(1.0);
        let b = SVector::<f64, 16>::from_element(-1.0);
        let s = solve_lcp(&W, &b, IndexSet::full(16)).unwrap();
        assert_eq!(s.lambda.sum(), 1.0);
        assert_eq!(s.w, SVector::<f64, 16>::zeros());
        assert_eq!((s.support, s.trials), (IndexSet::full(1), 1));
    }

    #[test]
    fn too_many_active_rows_when_pivoting_fails() {
        // 17 rows alternately a and −a, all approaching: infeasible, pivoting
        // exchanges rows until its budget runs out, and 2^17 sets are too many.
        let W = SMatrix::<f64, 17, 17>::from_fn(|i, j| if (i + j) % 2 == 0 { 1.0 } else { -1.0 });
        let b = SVector::<f64, 17>::from_element(-1.0);
        let err = solve_lcp(&W, &b, IndexSet::full(17)).unwrap_err();
        assert_eq!(
            err,
            LcpError::TooManyActive {
                active: 17,
                max: 16
            }
        );
        // with 16 rows, enumeration proves it infeasible
        let W = SMatrix::<f64, 16, 16>::from_fn(|i, j| if (i + j) % 2 == 0 { 1.0 } else { -1.0 });
        let b = SVector::<f64, 16>::from_element(-1.0);
        let err = solve_lcp(&W, &b, IndexSet::full(16)).unwrap_err();
        assert!(matches!(err, LcpError::Infeasible { .. }), "{err:?}");
    }
}
