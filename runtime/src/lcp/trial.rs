//! The active part of an LCP, gathered and checked once, and the test of one
//! complementary set on it.
//!
//! A complementary set `F` (positions within the active set, as the bits of a
//! `u32`) asks for `λ_F` free and `w_F = 0`, `λ_C = 0` on the rest `C`:
//!
//! $$W_{FF}\,\lambda_F = -b_F, \qquad w = W_{\cdot F}\,\lambda_F + b,$$
//!
//! and `F` solves the LCP when `λ_F ≥ 0` and `w_C ≥ 0`. `W_FF` is factored
//! afresh from the data for every set, so no rounding error carries from one
//! set to the next: `LDLᵀ` with diagonal pivoting on the unit-diagonal
//! scaling of `W_FF` (the next pivot is the row furthest, in angle, from the
//! span of the rows already eliminated), which reveals the rank of a
//! semidefinite `W_FF` whatever the order and scale of its rows.

use nalgebra::{RealField, SMatrix, SVector};

use super::residual::{scaled, w_scale};
use super::{IndexSet, LcpError};

/// `256 (m + 1) ε`: the round-off level of an `m × m` problem (see the
/// module docs of `lcp`).
pub(crate) fn roundoff<T: RealField + Copy>(m: usize) -> T {
    nalgebra::convert::<f64, T>(256.0 * (m as f64 + 1.0)) * T::default_epsilon()
}

/// The LCP restricted to its active rows and columns, in compact storage:
/// position `p < m` holds active index `index[p]`.
pub(crate) struct Problem<T, const K: usize> {
    /// Number of active rows.
    pub m: usize,
    /// Active index of each position.
    pub index: [usize; K],
    /// `W` on the active block.
    pub W: [[T; K]; K],
    /// `b` on the active rows.
    pub b: [T; K],
    /// Positions whose row of `W` is zero within round-off (`W_ii ≤ τ₀ ω`):
    /// they never enter a complementary set.
    pub zero: u32,
    /// `β = max_i |b_i|`.
    pub beta: T,
    /// `ω_i = max_j |W_ji|` by position: the largest change of `w` per unit
    /// of `λ_i`.
    pub col: [T; K],
    /// `1 / W_ii` by position (`0` for zero rows).
    pub inv_diag: [T; K],
    /// `τ₀`: round-off level, for signs, pivots and zero rows.
    pub tol_exact: T,
}

/// One complementary set, solved.
#[derive(Clone, Copy)]
pub(crate) struct Trial<T, const K: usize> {
    /// The set `F` (positions).
    pub set: u32,
    /// `λ` by position: `λ_F` as solved (not clamped), `0` elsewhere.
    pub lambda: [T; K],
    /// Largest scaled sign violation, `max(0, −ω_i λ_i/Ω (i ∈ F), −w_i/Ω (i ∉ F))`.
    pub sign_violation: T,
    /// Largest violation of any kind: the sign violation, or the scaled
    /// inaccuracy `|w_i|/Ω` (`i ∈ F`) of the solve.
    pub violation: T,
    /// Position of the largest violation.
    pub worst: usize,
    /// Smallest position whose sign is violated beyond `τ₀` (the Murty pivot).
    pub first_violated: Option<usize>,
    /// Whether the solve is accurate: `|w_i| ≤ τ₀ Ω` for `i ∈ F`. It is
    /// not when `W_FF` is nearly singular and the `W_ij λ_j` cancel.
    pub accurate: bool,
}

impl<T: RealField + Copy, const K: usize> Trial<T, K> {
    /// Whether this set solves the LCP within round-off.
    #[inline]
    pub fn solves(&self) -> bool {
        self.accurate && self.first_violated.is_none()
    }
}

impl<T: RealField + Copy, const K: usize> Problem<T, K> {
    /// Gathers the active block and checks it: indices in range, entries
    /// finite, `W` symmetric and with non-negative diagonal within `τ ω`,
    /// zero rows with `b_i ≥ −τ₀ β`.
    pub fn gather(
        W: &SMatrix<T, K, K>,
        b: &SVector<T, K>,
        active: IndexSet<K>,
        tolerance: T,
    ) -> Result<Self, LcpError<T>> {
        let mut problem = Self {
            m: 0,
            index: [0; K],
            W: [[T::zero(); K]; K],
            b: [T::zero(); K],
            zero: 0,
            beta: T::zero(),
            col: [T::zero(); K],
            inv_diag: [T::zero(); K],
            tol_exact: T::zero(),
        };
        if active.len() > super::Lcp::<T>::MAX_ACTIVE {
            return Err(LcpError::ActiveSetTooLarge {
                active: active.len(),
                max: super::Lcp::<T>::MAX_ACTIVE,
            });
        }
        for i in active.iter() {
            if i >= K {
                return Err(LcpError::IndexOutOfRange { index: i, dim: K });
            }
            problem.index[problem.m] = i;
            problem.m += 1;
        }
        let m = problem.m;
        let (mut beta, mut omega) = (T::zero(), T::zero());
        for p in 0..m {
            let i = problem.index[p];
            if !b[i].is_finite() {
                return Err(LcpError::NonFiniteVector { index: i });
            }
            problem.b[p] = b[i];
            beta = beta.max(b[i].abs());
            for q in 0..m {
                let j = problem.index[q];
                let x = W[(i, j)];
                if !x.is_finite() {
                    return Err(LcpError::NonFiniteMatrix { row: i, col: j });
                }
                problem.W[p][q] = x;
                omega = omega.max(x.abs());
                problem.col[q] = problem.col[q].max(x.abs());
            }
        }
        problem.beta = beta;
        let tol_exact = roundoff::<T>(m);
        problem.tol_exact = tol_exact;
        for p in 0..m {
            let i = problem.index[p];
            for q in 0..p {
                if (problem.W[p][q] - problem.W[q][p]).abs() > tolerance * omega {
                    return Err(LcpError::NotSymmetric {
                        row: i,
                        col: problem.index[q],
                    });
                }
            }
            let d = problem.W[p][p];
            if d < -tolerance * omega {
                return Err(LcpError::NotPositiveSemidefinite { index: i });
            }
            if d > tol_exact * omega {
                problem.inv_diag[p] = T::one() / d;
            } else {
                problem.zero |= 1 << p;
                if problem.b[p] < -tol_exact * beta {
                    return Err(LcpError::Infeasible {
                        index: i,
                        violation: -problem.b[p] / beta,
                    });
                }
            }
        }
        Ok(problem)
    }

    /// All positions `{0, …, m − 1}`.
    #[inline]
    pub fn all(&self) -> u32 {
        // m ≤ Lcp::MAX_ACTIVE = 32 (gather checks it)
        if self.m == 0 {
            0
        } else {
            u32::MAX >> (32 - self.m)
        }
    }

    /// The first guess: `F₀ = {i : b_i < 0}` (the constraints that zero
    /// impulse would leave violated), zero rows excepted.
    #[inline]
    pub fn first_guess(&self) -> u32 {
        let mut set = 0;
        for p in 0..self.m {
            if self.b[p] < T::zero() {
                set |= 1 << p;
            }
        }
        set & !self.zero
    }

    /// Solves the complementary set `set`: `W_FF λ_F = −b_F` by pivoted
    /// `LDLᵀ`, then `w = Wλ + b`.
    ///
    /// Position `first` (if in `set`) is eliminated first, the others in
    /// order of their scaled pivots `d_j / W_jj`. When `W_FF` is singular,
    /// elimination stops where every remaining scaled pivot is `≤ τ₀` (those
    /// rows lie within an angle `≈ √τ₀` of the span of the eliminated ones)
    /// and the trial is of the independent subset eliminated so far: its
    /// [`set`](Trial::set) is then smaller than `set`. `None` when `λ_F`
    /// overflowed.
    #[allow(clippy::needless_range_loop)] // triangular loops read best indexed
    pub fn trial(&self, set: u32, first: Option<usize>) -> Option<Trial<T, K>> {
        let zero = T::zero();
        // positions in F, increasing
        let mut f = [0usize; K];
        let mut n = 0;
        for p in 0..self.m {
            if (set >> p) & 1 == 1 {
                f[n] = p;
                n += 1;
            }
        }
        // a = the lower triangle of W_FF, then of its factors: L below the
        // diagonal, d on it. perm[k] = the position in f eliminated k-th.
        let mut a = [[zero; K]; K];
        let mut perm = [0usize; K];
        for r in 0..n {
            perm[r] = r;
            for c in 0..=r {
                a[r][c] = self.W[f[r]][f[c]];
            }
        }
        let mut rank = 0;
        while rank < n {
            let k = rank;
            // pivot: `first`, then the largest d_j / W_jj, the earliest on ties
            let ratio = |r: usize| a[r][r] * self.inv_diag[f[perm[r]]];
            let forced = first
                .filter(|_| k == 0)
                .and_then(|p| (0..n).find(|&r| f[r] == p))
                .filter(|&r| ratio(r) > self.tol_exact);
            let (mut pivot, mut best) = (k, ratio(k));
            if let Some(r) = forced {
                (pivot, best) = (r, ratio(r));
            } else {
                for r in k + 1..n {
                    if ratio(r) > best {
                        (pivot, best) = (r, ratio(r));
                    }
                }
            }
            // written so that NaN stops too
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            if !(best > self.tol_exact) {
                break;
            }
            rank += 1;
            if pivot != k {
                swap_symmetric(&mut a, n, k, pivot);
                perm.swap(k, pivot);
            }
            // Schur complement, lower triangle: a_ij −= a_ik a_jk / d_k
            let dk = a[k][k];
            for i in k + 1..n {
                let lik = a[i][k] / dk;
                for j in k + 1..=i {
                    a[i][j] -= lik * a[j][k];
                }
            }
            for row in &mut a[k + 1..n] {
                row[k] /= dk;
            }
        }
        // from here F is the independent subset: f[perm[0..rank]]
        let n = rank;
        let f = perm.map(|q| f[q]);
        let mut set = 0;
        for &p in &f[..n] {
            set |= 1 << p;
        }
        // L D Lᵀ x = −b_F, forward then backward
        let mut x = [zero; K];
        for k in 0..n {
            let mut s = -self.b[f[k]];
            for q in 0..k {
                s -= a[k][q] * x[q];
            }
            x[k] = s;
        }
        for k in (0..n).rev() {
            let mut s = x[k] / a[k][k];
            for q in k + 1..n {
                s -= a[q][k] * x[q];
            }
            x[k] = s;
        }
        let mut lambda = [zero; K];
        for k in 0..n {
            if !x[k].is_finite() {
                return None;
            }
            lambda[f[k]] = x[k];
        }
        let m = self.m;
        let omega_w = w_scale(self.beta, &lambda[..m], &self.col[..m]);
        let tol = self.tol_exact * omega_w;
        let mut trial = Trial {
            set,
            lambda,
            sign_violation: zero,
            violation: zero,
            worst: 0,
            first_violated: None,
            accurate: true,
        };
        for p in 0..m {
            let mut w = self.b[p];
            for &q in &f[..n] {
                w += self.W[p][q] * lambda[q];
            }
            // the sign to test: ω_p λ_p on F, w_p off it; and |w_p| on F
            let (signed, off) = if (set >> p) & 1 == 1 {
                trial.accurate &= w.abs() <= tol;
                (self.col[p] * lambda[p], w.abs())
            } else {
                (w, zero)
            };
            if signed < -tol && trial.first_violated.is_none() {
                trial.first_violated = Some(p);
            }
            let sign = scaled(-signed, omega_w);
            trial.sign_violation = trial.sign_violation.max(sign);
            let v = sign.max(scaled(off, omega_w));
            if v > trial.violation {
                trial.violation = v;
                trial.worst = p;
            }
        }
        Some(trial)
    }
}

/// Swaps rows and columns `k < p` of the symmetric `n × n` matrix whose lower
/// triangle is `a`, below an elimination at step `k` (columns `< k` hold `L`,
/// whose rows `k` and `p` swap too), as LAPACK's `dsytf2` does.
#[allow(clippy::needless_range_loop)] // triangular loops read best indexed
fn swap_symmetric<T: Copy, const K: usize>(a: &mut [[T; K]; K], n: usize, k: usize, p: usize) {
    for j in 0..k {
        let t = a[k][j];
        a[k][j] = a[p][j];
        a[p][j] = t;
    }
    let t = a[k][k];
    a[k][k] = a[p][p];
    a[p][p] = t;
    for i in k + 1..p {
        let t = a[i][k];
        a[i][k] = a[p][i];
        a[p][i] = t;
    }
    for row in &mut a[p + 1..n] {
        row.swap(k, p);
    }
}
