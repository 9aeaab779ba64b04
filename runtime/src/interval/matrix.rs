//! Proven bounds on the eigenvalues and the spectral norm of every matrix
//! in an interval matrix (`[row][col]`, as [`Enclosure`](crate::Enclosure)
//! returns them).
//!
//! **Eigenvalues of a symmetric family** (the mass matrix; entry `(i, j)`
//! is first intersected with `(j, i)`, both enclosing the same real):
//!
//! 1. the midpoint `A_c` is diagonalised approximately by cyclic Jacobi,
//!    `A_c ≈ V Λ Vᵀ`, columns ordered by decreasing eigenvalue;
//! 2. `B = Vᵀ A V` is enclosed in interval arithmetic, for the family in
//!    mean-value form ([`MeanValueMatrix`]: `A(q) ∈ A(c) + Σ_m ∂A/∂q_m (Q)
//!    (Q_m − c_m)`) by applying the congruence to the centre and to each
//!    slope separately, so that entries keep their correlations to first
//!    order;
//! 3. `λ_min(B) ≥ s` is **proven** when the interval Cholesky factorization
//!    of `B − sI` succeeds (every pivot's lower bound `> 0`: then every
//!    symmetric real matrix of the interval matrix is positive definite).
//!    The smallest eigenvalue is eliminated last, so its pivot is the
//!    Schur complement, second order in the off-diagonal widths. `s` starts
//!    at `λ̃_min − w` (`w` the width of `B`'s last diagonal entry), backs off
//!    by doubling, then is refined by six bisections;
//! 4. `V` is orthogonal only to rounding: with `ε ≥ ‖VᵀV − I‖₂` (row sums
//!    of the interval matrix `VᵀV − I`, rounded up), Ostrowski's theorem
//!    gives `λ_min(A) ≥ s/(1 + ε)` for `s ≥ 0` and `s/(1 − ε)` otherwise;
//! 5. Gershgorin's `min_i (a_ii − Σ_{j≠i} |a_ij|)` (rounded down) on the
//!    interval matrix is a fallback, and the larger of the proven bounds is
//!    kept (for the mean-value family, also the bound of the plain
//!    interval matrix, which is often the tighter for `λ_max`).
//!
//! `λ_max(A) = −λ_min(−A)`.
//!
//! **Norms** (`C(q, d)`, `∂F/∂v`): with the midpoint `A_c` and the radius
//! `R ≥ 0` rounded up, every `A` of `[A]` is `A_c + E`, `|E_ij| ≤ R_ij`, so
//! `‖A‖₂ ≤ ‖A_c‖₂ + ‖R‖₂` (`‖E‖₂ ≤ ‖ |E| ‖₂ ≤ ‖R‖₂`, Perron–Frobenius),
//! with `‖A_c‖₂ = √λ_max(A_cᵀA_c)` (the Gram matrix in interval arithmetic,
//! bounded as above) and `‖R‖₂ ≤ min(‖R‖_F, √(‖R‖₁‖R‖_∞))`.

// index loops read as the formulas they implement
#![allow(clippy::needless_range_loop)]

use super::{Interval, add_down, add_up, mul_up, sqrt_up};
use crate::enclosure::Enclose;

/// An interval matrix, rows of entries.
pub(crate) type IMat<const N: usize> = [[Interval; N]; N];

/// A square `f64` matrix, rows of entries.
type FMat<const N: usize> = [[f64; N]; N];

/// Midpoint and radius (rounded up) of each entry.
fn mid_rad<const N: usize>(a: &IMat<N>) -> (FMat<N>, FMat<N>) {
    let mut c = [[0.0; N]; N];
    let mut r = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            let x = a[i][j];
            let m = x.mid();
            c[i][j] = m;
            r[i][j] = add_up(x.hi(), -m).max(add_up(m, -x.lo()));
        }
    }
    (c, r)
}

/// `‖R‖₂` of a non-negative matrix, rounded up:
/// `min(‖R‖_F, √(‖R‖₁ ‖R‖_∞))`.
fn norm_nonneg_up<const N: usize>(r: &FMat<N>) -> f64 {
    let mut frob = 0.0;
    let mut row_max: f64 = 0.0;
    let mut col_max: f64 = 0.0;
    for i in 0..N {
        let mut row = 0.0;
        let mut col = 0.0;
        for j in 0..N {
            frob = add_up(frob, mul_up(r[i][j], r[i][j]));
            row = add_up(row, r[i][j]);
            col = add_up(col, r[j][i]);
        }
        row_max = row_max.max(row);
        col_max = col_max.max(col);
    }
    sqrt_up(frob).min(sqrt_up(mul_up(row_max, col_max)))
}

/// Whether the interval Cholesky factorization of `a` succeeds: then every
/// symmetric real matrix in `a` is positive definite.
fn cholesky_succeeds<const N: usize>(a: &IMat<N>) -> bool {
    let mut l = [[Interval::point(0.0); N]; N];
    for j in 0..N {
        let mut d = a[j][j];
        for k in 0..j {
            d = d - l[j][k].powi(2);
        }
        if d.lo() <= 0.0 || !d.is_finite() {
            return false;
        }
        let ljj = d.sqrt();
        l[j][j] = ljj;
        for i in j + 1..N {
            let mut s = a[i][j];
            for k in 0..j {
                s = s - l[i][k] * l[j][k];
            }
            l[i][j] = s / ljj;
        }
    }
    true
}

/// Cyclic Jacobi on the symmetric `c`: approximate eigenvalues and
/// eigenvectors (column `k` of the second result is vector `k`).
fn jacobi<const N: usize>(c: &FMat<N>) -> ([f64; N], FMat<N>) {
    let mut a = *c;
    let mut v = [[0.0; N]; N];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    let norm = a.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    for _ in 0..50 {
        let mut off = 0.0;
        for p in 0..N {
            for q in p + 1..N {
                off += a[p][q] * a[p][q];
            }
        }
        if off.sqrt() <= 1e-17 * norm || off == 0.0 {
            break;
        }
        for p in 0..N {
            for q in p + 1..N {
                let apq = a[p][q];
                if apq == 0.0 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
                let t = if theta.abs() > 1e100 {
                    0.5 / theta
                } else {
                    let t = 1.0 / (theta.abs() + (theta * theta + 1.0).sqrt());
                    if theta < 0.0 { -t } else { t }
                };
                let cs = 1.0 / (t * t + 1.0).sqrt();
                let sn = t * cs;
                for k in 0..N {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = cs * akp - sn * akq;
                    a[k][q] = sn * akp + cs * akq;
                }
                for k in 0..N {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = cs * apk - sn * aqk;
                    a[q][k] = sn * apk + cs * aqk;
                }
                for row in v.iter_mut() {
                    let (vkp, vkq) = (row[p], row[q]);
                    row[p] = cs * vkp - sn * vkq;
                    row[q] = sn * vkp + cs * vkq;
                }
            }
        }
    }
    (core::array::from_fn(|i| a[i][i]), v)
}

/// `Vᵀ A V` in interval arithmetic.
fn congruence<const N: usize>(a: &IMat<N>, v: &IMat<N>) -> IMat<N> {
    let av: IMat<N> = core::array::from_fn(|i| {
        core::array::from_fn(|k| (0..N).fold(Interval::point(0.0), |s, j| s + a[i][j] * v[j][k]))
    });
    core::array::from_fn(|k| {
        core::array::from_fn(|l| (0..N).fold(Interval::point(0.0), |s, i| s + v[i][k] * av[i][l]))
    })
}

/// A symmetric matrix family in mean-value form over a box `Q`:
/// `A(q) ∈ centre + Σ_m slopes[m] · delta[m]` for every `q ∈ Q`, with
/// `centre ⊇ A(c)`, `slopes[m] ⊇ ∂A/∂q_m (Q)` and `delta[m] = Q_m − c_m`,
/// and `plain ⊇ A(Q)` (the same family, without the form).
#[derive(Clone, Copy, Debug)]
pub(crate) struct MeanValueMatrix<const N: usize> {
    pub centre: IMat<N>,
    pub slopes: [IMat<N>; N],
    pub delta: [Interval; N],
    pub plain: IMat<N>,
}

impl<const N: usize> MeanValueMatrix<N> {
    fn neg(&self) -> Self {
        let n = |a: &IMat<N>| a.map(|row| row.map(|x| -x));
        Self {
            centre: n(&self.centre),
            slopes: self.slopes.map(|a| n(&a)),
            delta: self.delta,
            plain: n(&self.plain),
        }
    }

    /// `Vᵀ A V` for every `A` of the family: the congruence applied to the
    /// centre and to each slope, so that the entries keep their
    /// correlations to first order.
    fn congruence(&self, v: &IMat<N>) -> IMat<N> {
        let mut b = congruence(&self.centre, v);
        for m in 0..N {
            let bm = congruence(&self.slopes[m], v);
            for k in 0..N {
                for l in 0..N {
                    b[k][l] = b[k][l] + bm[k][l] * self.delta[m];
                }
            }
        }
        b
    }

    /// The variable the eigenvalue at the end `smallest` (else the largest)
    /// of the spectrum depends on most over the box: the largest
    /// `Σ_ij |u_i| |slope_m,ij| |u_j| · width(delta_m)`, `u` the midpoint's
    /// eigenvector there. Where to bisect.
    pub fn smear(&self, smallest: bool) -> usize {
        let (c, _) = mid_rad(&self.centre);
        let (values, vectors) = jacobi(&c);
        let mut k = 0;
        for j in 1..N {
            if (values[j] < values[k]) == smallest {
                k = j;
            }
        }
        let u: [f64; N] = core::array::from_fn(|i| vectors[i][k].abs());
        let mut best = (f64::NEG_INFINITY, 0);
        for m in 0..N {
            let mut s = 0.0;
            for i in 0..N {
                for j in 0..N {
                    s += u[i] * self.slopes[m][i][j].mag() * u[j];
                }
            }
            let s = s * self.delta[m].width();
            if s > best.0 {
                best = (s, m);
            }
        }
        best.1
    }

    /// The enclosure as one interval matrix: the mean-value form
    /// intersected with the plain one.
    fn hull(&self) -> IMat<N> {
        core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                let mut x = self.centre[i][j];
                for m in 0..N {
                    x = x + self.slopes[m][i][j] * self.delta[m];
                }
                x.intersect(self.plain[i][j]).unwrap_or(x)
            })
        })
    }
}

/// A proven lower bound on `λ_min` of every symmetric matrix in `a`
/// (already a symmetric hull with finite entries); see the module docs.
fn eig_min<const N: usize>(a: &IMat<N>) -> f64 {
    eig_min_by(a, |v| congruence(a, v))
}

/// `λ_min` from below: `a` encloses the family, `transform(V)` encloses
/// `VᵀAV` over it.
fn eig_min_by<const N: usize>(a: &IMat<N>, transform: impl Fn(&IMat<N>) -> IMat<N>) -> f64 {
    if N == 0 {
        return 0.0;
    }
    let (c, r) = mid_rad(a);
    let scale = c.iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
    if scale == 0.0 && r.iter().flatten().all(|&x| x == 0.0) {
        return 0.0;
    }
    let (values, vectors) = jacobi(&c);
    // eigenvectors ordered by decreasing eigenvalue: the smallest is
    // eliminated last, so its Schur complement is second order in the
    // off-diagonal widths
    let mut order: [usize; N] = core::array::from_fn(|k| k);
    order.sort_by(|&x, &y| values[y].total_cmp(&values[x]));
    let v: [[Interval; N]; N] =
        core::array::from_fn(|i| core::array::from_fn(|k| Interval::point(vectors[i][order[k]])));
    let b = transform(&v);
    let b = symmetric_hull(&b).unwrap_or(b);
    // ε ≥ ‖VᵀV − I‖₂ (row sums of the symmetric interval matrix)
    let mut eps: f64 = 0.0;
    for k in 0..N {
        let mut row = 0.0;
        for l in 0..N {
            let g = (0..N).fold(Interval::point(0.0), |s, i| s + v[i][k] * v[i][l]);
            let g = if k == l { g - Interval::point(1.0) } else { g };
            row = add_up(row, g.mag());
        }
        eps = eps.max(row);
    }
    let lam = values[order[N - 1]];
    let last = b[N - 1][N - 1];
    let width = last.width();
    let holds = |s: f64| {
        let shifted: IMat<N> = core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                if i == j {
                    b[i][j] - Interval::point(s)
                } else {
                    b[i][j]
                }
            })
        });
        cholesky_succeeds(&shifted)
    };
    let mut proven = None;
    let mut t = width + 1e-14 * scale + f64::MIN_POSITIVE;
    let mut failed = None;
    for _ in 0..40 {
        let s = lam - t;
        if holds(s) {
            proven = Some(s);
            break;
        }
        failed = Some(s);
        t *= 2.0;
    }
    if let (Some(mut ok), Some(mut bad)) = (proven, failed) {
        for _ in 0..6 {
            let mid = 0.5 * (ok + bad);
            if holds(mid) {
                ok = mid;
            } else {
                bad = mid;
            }
        }
        proven = Some(ok);
    }
    let from_b = match proven {
        // λ_i(VᵀAV) = θ_i λ_i(A), θ_i ∈ [1 − ε, 1 + ε] (Ostrowski)
        Some(s) if eps < 0.5 => {
            let theta = if s >= 0.0 {
                add_up(1.0, eps)
            } else {
                add_down(1.0, -eps)
            };
            (Interval::point(s) / Interval::point(theta)).lo()
        }
        _ => f64::NEG_INFINITY,
    };
    from_b.max(gershgorin(a))
}

/// Gershgorin's `min_i (a_ii − Σ_{j≠i} |a_ij|)`, rounded down.
fn gershgorin<const N: usize>(a: &IMat<N>) -> f64 {
    let mut lower = f64::INFINITY;
    for i in 0..N {
        let mut off = 0.0;
        for j in 0..N {
            if j != i {
                off = add_up(off, a[i][j].mag());
            }
        }
        lower = lower.min(add_down(a[i][i].lo(), -off));
    }
    lower
}

/// The entry-wise intersection of `a` and `aᵀ` (for an enclosure of a
/// symmetric matrix both contain the same reals), or `None` when empty
/// (then `a` encloses no symmetric matrix: a broken enclosure).
fn symmetric_hull<const N: usize>(a: &IMat<N>) -> Option<IMat<N>> {
    let mut s = *a;
    for i in 0..N {
        for j in 0..i {
            let x = a[i][j].intersect(a[j][i])?;
            s[i][j] = x;
            s[j][i] = x;
        }
    }
    Some(s)
}

/// Proven `(lower bound of λ_min, upper bound of λ_max)` over every
/// symmetric matrix in `a` (`(−∞, ∞)` for unbounded entries).
pub(crate) fn symmetric_eigen_bounds<const N: usize>(a: &IMat<N>) -> (f64, f64) {
    let Some(s) = symmetric_hull(a) else {
        return (f64::NEG_INFINITY, f64::INFINITY);
    };
    if !s.iter().flatten().all(|x| x.is_finite()) {
        return (f64::NEG_INFINITY, f64::INFINITY);
    }
    let neg: IMat<N> = s.map(|row| row.map(|x| -x));
    (eig_min(&s), -eig_min(&neg))
}

/// Proven `(lower bound of λ_min, upper bound of λ_max)` over a symmetric
/// family in mean-value form (the mass matrix over a box of
/// configurations): the congruence by the midpoint's eigenvectors is
/// applied to the centre and to each slope (see
/// [`MeanValueMatrix`]).
pub(crate) fn mean_value_eigen_bounds<const N: usize>(m: &MeanValueMatrix<N>) -> (f64, f64) {
    let hull = m.hull();
    let Some(a) = symmetric_hull(&hull) else {
        return (f64::NEG_INFINITY, f64::INFINITY);
    };
    if !a.iter().flatten().all(|x| x.is_finite()) {
        return (f64::NEG_INFINITY, f64::INFINITY);
    }
    let neg = m.neg();
    let a_neg: IMat<N> = a.map(|row| row.map(|x| -x));
    // the mean-value congruence is the tighter for the small eigenvalue,
    // the plain one often for the large: both are proofs, keep the better
    let lo = eig_min_by(&a, |v| m.congruence(v)).max(eig_min(&a));
    let hi = -eig_min_by(&a_neg, |v| neg.congruence(v)).max(eig_min(&a_neg));
    (lo, hi)
}

/// A proven upper bound on `‖A‖₂` over every `A` in `a` (`∞` for
/// unbounded entries; `0` for the zero matrix).
pub(crate) fn norm_bound<const N: usize>(a: &IMat<N>) -> f64 {
    if !a.iter().flatten().all(|x| x.is_finite()) {
        return f64::INFINITY;
    }
    let (c, r) = mid_rad(a);
    let gram: IMat<N> = core::array::from_fn(|i| {
        core::array::from_fn(|j| {
            (0..N).fold(Interval::point(0.0), |acc, k| {
                acc + Interval::point(c[k][i]) * Interval::point(c[k][j])
            })
        })
    });
    let (_, top) = symmetric_eigen_bounds(&gram);
    add_up(sqrt_up(top), norm_nonneg_up(&r))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point<const N: usize>(m: [[f64; N]; N]) -> IMat<N> {
        m.map(|row| row.map(Interval::point))
    }

    #[test]
    fn eigenvalue_bounds_enclose_the_eigenvalues() {
        // eigenvalues 1 and 3
        let (lo, hi) = symmetric_eigen_bounds(&point([[2.0, 1.0], [1.0, 2.0]]));
        assert!(lo <= 1.0 && lo > 1.0 - 1e-12, "{lo}");
        assert!((3.0..3.0 + 1e-12).contains(&hi), "{hi}");
        // diagonal: exact up to the verification shift
        let (lo, hi) = symmetric_eigen_bounds(&point([[2.0, 0.0], [0.0, 5.0]]));
        assert!(lo <= 2.0 && lo > 2.0 - 1e-12 && (5.0..5.0 + 1e-12).contains(&hi));
        // a radius: [1 ± 0.1] on the diagonal
        let w = Interval::new(0.9, 1.1).unwrap();
        let z = Interval::point(0.0);
        let (lo, hi) = symmetric_eigen_bounds(&[[w, z], [z, w]]);
        assert!(lo <= 0.9 && lo > 0.9 - 1e-12 && (1.1..1.1 + 1e-12).contains(&hi));
        // indefinite
        let (lo, _) = symmetric_eigen_bounds(&point([[1.0, 2.0], [2.0, 1.0]]));
        assert!(lo <= -1.0 && lo > -1.0 - 1e-12);
        assert_eq!(symmetric_eigen_bounds(&point([[0.0; 3]; 3])), (0.0, 0.0));
    }

    #[test]
    fn norm_bounds() {
        assert_eq!(norm_bound(&point([[0.0; 2]; 2])), 0.0);
        // ‖[[0, −1], [1, 0]]‖ = 1; ‖[[1, 1], [0, 1]]‖ = golden ratio
        let n = norm_bound(&point([[0.0, -1.0], [1.0, 0.0]]));
        assert!((1.0..1.0 + 1e-12).contains(&n));
        let phi = (1.0 + 5f64.sqrt()) / 2.0;
        let n = norm_bound(&point([[1.0, 1.0], [0.0, 1.0]]));
        assert!(n >= phi && n < phi + 1e-12);
        let n = norm_bound(&[[Interval::new(-1.0, 1.0).unwrap()]]);
        assert!((1.0..1.0 + 1e-15).contains(&n));
        assert_eq!(norm_bound(&[[Interval::ENTIRE]]), f64::INFINITY);
    }
}
