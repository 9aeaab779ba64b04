//! The scaled complementarity residual of a candidate LCP solution.

use nalgebra::{RealField, SMatrix, SVector};

use super::IndexSet;

/// The scale of `w`: `Ω = β = max_i |b_i|`, the size of the velocities; or,
/// when `b = 0`, `max_i ω_i |λ_i|`.
#[inline]
pub(crate) fn w_scale<T: RealField + Copy>(beta: T, lambda: &[T], col: &[T]) -> T {
    if beta > T::zero() {
        return beta;
    }
    lambda
        .iter()
        .zip(col)
        .fold(T::zero(), |m, (&l, &c)| m.max(c * l.abs()))
}

/// `x / scale`, or `0` when `scale == 0` (then `x == 0` too).
#[inline]
pub(crate) fn scaled<T: RealField + Copy>(x: T, scale: T) -> T {
    if scale > T::zero() {
        x / scale
    } else {
        T::zero()
    }
}

/// `max_i |min(ω_i λ_i, w_i)| / Ω` over the given entries, with `ω_i =
/// col[i]` and `Ω` from [`w_scale`].
pub(crate) fn natural_residual<T: RealField + Copy>(
    lambda: &[T],
    w: &[T],
    col: &[T],
    beta: T,
) -> T {
    let omega_w = w_scale(beta, lambda, col);
    let mut r = T::zero();
    for ((&l, &wi), &c) in lambda.iter().zip(w).zip(col) {
        let x = c * l;
        let m = if x < wi { x } else { wi };
        r = r.max(m.abs());
    }
    scaled(r, omega_w)
}

/// The scaled complementarity residual of `λ` for the LCP
/// `w = Wλ + b, 0 ≤ λ ⊥ w ≥ 0` on the active rows `A`:
///
/// $$r = \frac{1}{\Omega} \max_{i \in A} \left| \min(\omega_i \lambda_i,\ w_i) \right|,
/// \qquad w_i = b_i + \sum_{j \in A} W_{ij} \lambda_j,$$
///
/// in units of `w`: `ω_i = max_{j∈A} |W_ji|` turns the impulse `λ_i` into the
/// largest change of `w` it makes, and `Ω = β = max_{i∈A} |b_i|` is the size
/// of the velocities (or `max_i ω_i |λ_i|` when `b_A = 0`; `r = 0` when
/// `Ω = 0`). `r = 0` exactly when `λ_A` solves the LCP, and `r` bounds
/// `−ω_i λ_i / Ω`, `−w_i / Ω` and `min(ω_i λ_i, w_i) / Ω`. It is the measure
/// of [`LcpSolution::residual`](crate::LcpSolution) and of the solver's
/// tolerances. `w` is measured against the velocities, not against the terms
/// `W_ij λ_j` it sums: nearly singular multipliers that cancel show as a
/// large residual.
///
/// Only active rows and columns of `W`, and active entries of `b` and
/// `lambda`, are read (inactive `λ_j` count as `0`). The result is NaN when
/// a read entry is not finite.
///
/// ```
/// use moreau_runtime::{lcp_residual, IndexSet};
/// use nalgebra::{Matrix2, Vector2};
///
/// let W = Matrix2::new(2.0, 1.0, 1.0, 2.0);
/// let b = Vector2::new(-1.0, 1.0);
/// let all = IndexSet::full(2);
/// // λ = (½, 0) gives w = (0, 3/2): a solution.
/// assert_eq!(lcp_residual(&W, &b, all, &Vector2::new(0.5, 0.0)), 0.0);
/// // λ = 0 leaves w₀ = b₀ = −1 < 0: violated by |b₀| / β = 1.
/// assert_eq!(lcp_residual(&W, &b, all, &Vector2::zeros()), 1.0);
/// ```
#[must_use]
pub fn lcp_residual<T: RealField + Copy, const K: usize>(
    W: &SMatrix<T, K, K>,
    b: &SVector<T, K>,
    active: IndexSet<K>,
    lambda: &SVector<T, K>,
) -> T {
    let mut lam = [T::zero(); K];
    let mut w = [T::zero(); K];
    let mut col = [T::zero(); K];
    let mut beta = T::zero();
    let mut finite = true;
    let mut m = 0;
    for i in active.iter() {
        let mut wi = b[i];
        for j in active.iter() {
            wi += W[(i, j)] * lambda[j];
            col[m] = col[m].max(W[(j, i)].abs());
            finite &= W[(i, j)].is_finite();
        }
        beta = beta.max(b[i].abs());
        finite &= b[i].is_finite() && lambda[i].is_finite() && wi.is_finite();
        lam[m] = lambda[i];
        w[m] = wi;
        m += 1;
    }
    if !finite {
        return T::zero() / T::zero();
    }
    natural_residual(&lam[..m], &w[..m], &col[..m], beta)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Vector2};

    #[test]
    fn residual_measures_each_kind_of_violation() {
        let W = Matrix2::new(1.0, 0.0, 0.0, 1.0);
        let b = Vector2::new(-1.0, 2.0);
        let all = IndexSet::full(2);
        // exact solution λ = (1, 0), w = (0, 2)
        assert_eq!(lcp_residual(&W, &b, all, &Vector2::new(1.0, 0.0)), 0.0);
        // negative multiplier: ω₁ λ₁ = −½, Ω = β = 2
        let r = lcp_residual(&W, &b, all, &Vector2::new(1.0, -0.5));
        assert_eq!(r, 0.25);
        // not complementary: ω₁ λ₁ = 1, w₁ = 3 → min = 1, Ω = 2
        let r = lcp_residual(&W, &b, all, &Vector2::new(1.0, 1.0));
        assert_eq!(r, 0.5);
        // b = 0: Ω = max ω_i |λ_i| = 2
        let r = lcp_residual(&W, &Vector2::zeros(), all, &Vector2::new(2.0, 0.0));
        assert_eq!(r, 1.0);
    }

    #[test]
    fn residual_reads_only_active_entries_and_flags_non_finite() {
        let W = Matrix2::new(1.0, f64::NAN, f64::NAN, f64::NAN);
        let b = Vector2::new(-1.0, f64::NAN);
        let first = IndexSet::full(1);
        assert_eq!(lcp_residual(&W, &b, first, &Vector2::new(1.0, 7.0)), 0.0);
        assert!(lcp_residual(&W, &b, IndexSet::full(2), &Vector2::new(1.0, 0.0)).is_nan());
        // an index ≥ K cannot be in the set at all
        assert_eq!(IndexSet::<2>::from_indices(&[0, 5]), None);
    }

    #[test]
    fn residual_of_zero_problem_is_zero() {
        let W = Matrix2::<f64>::zeros();
        let b = Vector2::zeros();
        let r = lcp_residual(&W, &b, IndexSet::full(2), &Vector2::zeros());
        assert_eq!(r, 0.0);
    }
}
