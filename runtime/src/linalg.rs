//! Small dense factorizations for any `const N`, on the stack.
//!
//! nalgebra's `LU`, `Cholesky` and `SymmetricEigen` ask, for a generic
//! `Const<N>`, for `DimMin`/`DimSub`/typenum bounds that const-generic code
//! cannot state; these are the few lines a time step and the observers'
//! gain selection need, for the sizes of a mechanical model (N up to a few
//! tens).

use nalgebra::{RealField, SMatrix, SVector};

/// `ε^⅓` of the scalar type: the step of central differences and the LCP's
/// default tolerance. The correctly rounded values for `f64` and `f32` are
/// constants (the same bits `ε.cbrt()` gives, see the test below); a
/// software `cbrt` costs about 20 ns on targets without one in hardware,
/// paid at every call.
#[inline]
pub(crate) fn cbrt_epsilon<T: RealField + Copy>() -> T {
    let eps = T::default_epsilon();
    if eps == nalgebra::convert(f64::EPSILON) {
        nalgebra::convert(6.055_454_452_393_339_5e-6)
    } else if eps == nalgebra::convert(f64::from(f32::EPSILON)) {
        nalgebra::convert(f64::from(0.004_921_566_7_f32))
    } else {
        eps.cbrt()
    }
}

/// `A = Pᵀ L U` with partial (row) pivoting.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lu<T: RealField + Copy, const N: usize> {
    /// `L` (unit diagonal, below) and `U` (on and above the diagonal).
    lu: SMatrix<T, N, N>,
    /// Row `i` of `P A` is row `perm[i]` of `A`.
    perm: [usize; N],
}

impl<T: RealField + Copy, const N: usize> Lu<T, N> {
    /// Factors `a`; `None` when a pivot is zero or below `N ε` times the
    /// largest entry (numerically singular), or `a` is not finite.
    pub fn new(a: &SMatrix<T, N, N>) -> Option<Self> {
        let scale = a.amax();
        if !scale.is_finite() {
            return None;
        }
        let tiny = T::default_epsilon() * nalgebra::convert(N as f64) * scale;
        let mut lu = *a;
        let mut perm = [0; N];
        for (i, p) in perm.iter_mut().enumerate() {
            *p = i;
        }
        for k in 0..N {
            let (mut pivot, mut best) = (k, lu[(k, k)].abs());
            for i in k + 1..N {
                if lu[(i, k)].abs() > best {
                    (pivot, best) = (i, lu[(i, k)].abs());
                }
            }
            if best <= tiny {
                return None;
            }
            if pivot != k {
                lu.swap_rows(k, pivot);
                perm.swap(k, pivot);
            }
            let d = lu[(k, k)];
            for i in k + 1..N {
                let l = lu[(i, k)] / d;
                lu[(i, k)] = l;
                for j in k + 1..N {
                    let u = lu[(k, j)];
                    lu[(i, j)] -= l * u;
                }
            }
        }
        Some(Self { lu, perm })
    }

    /// `A⁻¹ b`, column by column.
    pub fn solve<const C: usize>(&self, b: &SMatrix<T, N, C>) -> SMatrix<T, N, C> {
        let mut x = SMatrix::<T, N, C>::zeros();
        for c in 0..C {
            for i in 0..N {
                let mut s = b[(self.perm[i], c)];
                for j in 0..i {
                    s -= self.lu[(i, j)] * x[(j, c)];
                }
                x[(i, c)] = s;
            }
            for i in (0..N).rev() {
                let mut s = x[(i, c)];
                for j in i + 1..N {
                    s -= self.lu[(i, j)] * x[(j, c)];
                }
                x[(i, c)] = s / self.lu[(i, i)];
            }
        }
        x
    }
}

/// `A = L D Lᵀ` for symmetric positive definite `A` (the lower triangle
/// is read): `L` unit lower triangular, `D` diagonal and positive.
///
/// The square-root-free form of Cholesky's factorization, as backward
/// stable for a positive definite `A`, and shorter where a model's update
/// waits for it: a factorization and one solve of a 2 × 2 `M` is a chain of
/// two divisions (`l₂₁ = a₂₁/d₁`, then `x₂ = y₂/d₂` after `d₂ = a₂₂ −
/// l₂₁a₂₁`), where `L Lᵀ` chains two square roots and five divisions
/// (`l₁₁`, `l₂₁`, `l₂₂`, then `y₂ = …/l₂₂`, `x₂ = y₂/l₂₂`, `x₁ = …/l₁₁`).
/// The divisions of a solve by `D` are independent of each other; a
/// diagonal `A` is solved by one correctly rounded division per entry.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ldlt<T: RealField + Copy, const N: usize> {
    /// `L` strictly below the diagonal, `D` on it, `L D` (`l_ij d_j`,
    /// transposed) above it.
    f: SMatrix<T, N, N>,
}

impl<T: RealField + Copy, const N: usize> Ldlt<T, N> {
    /// Factors `a`; `None` when `a` is not (numerically) positive definite
    /// (a pivot `d_j` not positive) or not finite.
    pub fn new(a: &SMatrix<T, N, N>) -> Option<Self> {
        let mut f = SMatrix::<T, N, N>::zeros();
        for j in 0..N {
            let mut d = a[(j, j)];
            for k in 0..j {
                d -= f[(j, k)] * f[(k, j)];
            }
            if !(d > T::zero() && d.is_finite()) {
                return None;
            }
            f[(j, j)] = d;
            for i in j + 1..N {
                // `s = l_ij d_j`
                let mut s = a[(i, j)];
                for k in 0..j {
                    s -= f[(i, k)] * f[(k, j)];
                }
                f[(j, i)] = s;
                f[(i, j)] = s / d;
            }
        }
        Some(Self { f })
    }

    /// `xᵀ A x` from the factor, `Σ d_i (Lᵀ x)_i²`: the kinetic energy
    /// (twice it) of a velocity when `A` is the mass matrix, without
    /// evaluating `M` again.
    pub fn quadratic_form(&self, x: &SVector<T, N>) -> T {
        let mut sum = T::zero();
        for i in 0..N {
            let mut y = x[i];
            for k in i + 1..N {
                y += self.f[(k, i)] * x[k];
            }
            sum += self.f[(i, i)] * y * y;
        }
        sum
    }

    /// `A⁻¹ b`, column by column: `L y = b`, `z = D⁻¹ y`, `Lᵀ x = z`.
    pub fn solve<const C: usize>(&self, b: &SMatrix<T, N, C>) -> SMatrix<T, N, C> {
        let mut x = *b;
        for c in 0..C {
            for i in 0..N {
                let mut s = x[(i, c)];
                for k in 0..i {
                    s -= self.f[(i, k)] * x[(k, c)];
                }
                x[(i, c)] = s;
            }
            for i in 0..N {
                x[(i, c)] /= self.f[(i, i)];
            }
            for i in (0..N).rev() {
                let mut s = x[(i, c)];
                for k in i + 1..N {
                    s -= self.f[(k, i)] * x[(k, c)];
                }
                x[(i, c)] = s;
            }
        }
        x
    }
}

/// The eigenvalues of a symmetric `A`, by the cyclic Jacobi method.
///
/// Each rotation `Pᵀ A P` in the plane `(p, q)` zeroes `A_pq` (the angle
/// from `θ = (A_qq − A_pp) / (2 A_pq)`, `t = sgn θ / (|θ| + √(θ² + 1))`, the
/// smaller root, so that the rotation is at most 45° and stable); a sweep
/// visits every `p < q` once, and sweeps repeat until the off-diagonal
/// part is at round-off of the Frobenius norm (quadratic convergence: about
/// six sweeps for the sizes of a mechanical model). Eigenvalues come to
/// round-off of `‖A‖` each, with no ordering; nothing allocates.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SymmetricEigen<T: RealField + Copy, const N: usize> {
    /// The eigenvalues `λ`, in no particular order.
    pub values: SVector<T, N>,
}

impl<T: RealField + Copy, const N: usize> SymmetricEigen<T, N> {
    /// Largest number of sweeps (never reached for finite input: Jacobi
    /// converges quadratically once the off-diagonal part is small).
    const MAX_SWEEPS: usize = 64;

    /// Decomposes the symmetric part `(A + Aᵀ)/2` of `a`; `None` when `a` is
    /// not finite.
    pub fn new(a: &SMatrix<T, N, N>) -> Option<Self> {
        if !a.iter().all(|x| x.is_finite()) {
            return None;
        }
        let half: T = nalgebra::convert(0.5);
        let mut a = (a + a.transpose()) * half;
        let norm = a.norm();
        let tiny = T::default_epsilon() * norm;
        for _ in 0..Self::MAX_SWEEPS {
            let mut off = T::zero();
            for p in 0..N {
                for q in p + 1..N {
                    off += a[(p, q)] * a[(p, q)];
                }
            }
            if off.sqrt() <= tiny {
                break;
            }
            for p in 0..N {
                for q in p + 1..N {
                    let apq = a[(p, q)];
                    if apq == T::zero() {
                        continue;
                    }
                    let theta = (a[(q, q)] - a[(p, p)]) / (apq + apq);
                    let t = if theta.abs() > nalgebra::convert(1e100) {
                        half / theta
                    } else {
                        let t = T::one() / (theta.abs() + (theta * theta + T::one()).sqrt());
                        if theta < T::zero() { -t } else { t }
                    };
                    let c = T::one() / (t * t + T::one()).sqrt();
                    let s = t * c;
                    for k in 0..N {
                        let (akp, akq) = (a[(k, p)], a[(k, q)]);
                        a[(k, p)] = c * akp - s * akq;
                        a[(k, q)] = s * akp + c * akq;
                    }
                    for k in 0..N {
                        let (apk, aqk) = (a[(p, k)], a[(q, k)]);
                        a[(p, k)] = c * apk - s * aqk;
                        a[(q, k)] = s * apk + c * aqk;
                    }
                }
            }
        }
        Some(Self {
            values: a.diagonal(),
        })
    }

    /// The smallest eigenvalue (`0` for `N = 0`).
    pub fn min(&self) -> T {
        self.values
            .iter()
            .copied()
            .reduce(T::min)
            .unwrap_or_else(T::zero)
    }

    /// The largest eigenvalue (`0` for `N = 0`).
    pub fn max(&self) -> T {
        self.values
            .iter()
            .copied()
            .reduce(T::max)
            .unwrap_or_else(T::zero)
    }
}

/// The spectral norm `‖A‖₂ = √λ_max(AᵀA)`; `None` when `a` is not finite.
pub(crate) fn spectral_norm<T: RealField + Copy, const R: usize, const C: usize>(
    a: &SMatrix<T, R, C>,
) -> Option<T> {
    let ata = a.transpose() * a;
    SymmetricEigen::new(&ata).map(|e| e.max().max(T::zero()).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix3, Matrix4, Vector3};

    #[test]
    fn cbrt_epsilon_is_the_bits_of_cbrt() {
        assert_eq!(
            cbrt_epsilon::<f64>().to_bits(),
            f64::EPSILON.cbrt().to_bits()
        );
        assert_eq!(
            cbrt_epsilon::<f32>().to_bits(),
            f32::EPSILON.cbrt().to_bits()
        );
        // and it is the cube root: ε to within an ulp or two
        let c = cbrt_epsilon::<f64>();
        assert!((c * c * c / f64::EPSILON - 1.0).abs() < 4.0 * f64::EPSILON);
    }

    #[test]
    fn lu_solves_a_system_that_needs_pivoting() {
        let a = Matrix3::new(0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0);
        let x = Vector3::new(1.0, -2.0, 0.5);
        let lu = Lu::new(&a).unwrap();
        let solved = lu.solve(&(a * x));
        assert!((solved - x).amax() < 1e-14);
    }

    #[test]
    fn lu_rejects_a_singular_matrix() {
        let a = Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 1.0, 1.0);
        assert!(Lu::new(&a).is_none());
        assert!(Lu::new(&Matrix3::from_element(f64::NAN)).is_none());
    }

    #[test]
    fn ldlt_solves_and_rejects_indefinite() {
        let a = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0);
        let x = Vector3::new(0.3, -1.0, 2.0);
        let c = Ldlt::new(&a).unwrap();
        assert!((c.solve(&(a * x)) - x).amax() < 1e-14);
        let indefinite = Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert!(Ldlt::new(&indefinite).is_none());
        assert!(Ldlt::new(&Matrix3::from_element(f64::NAN)).is_none());
    }

    #[test]
    fn ldlt_agrees_with_nalgebras_cholesky() {
        // `A = Bᵀ B + I` for a fixed, ill-scaled `B`: positive definite,
        // condition number about 1e4
        let b = SMatrix::<f64, 6, 6>::from_fn(|i, j| {
            ((i * 7 + j * 3) as f64 * 0.37).sin() * 10f64.powi(i as i32 % 3 - 1)
        });
        let a = b.transpose() * b + SMatrix::<f64, 6, 6>::identity();
        let rhs = SMatrix::<f64, 6, 2>::from_fn(|i, j| (i as f64 - 2.5) * (j as f64 + 1.0));
        let ours = Ldlt::new(&a).unwrap().solve(&rhs);
        let theirs = nalgebra::Cholesky::new(a).unwrap().solve(&rhs);
        assert!((ours - theirs).amax() <= 1e-12 * theirs.amax());
    }

    #[test]
    fn ldlt_quadratic_form_is_x_a_x() {
        let b = SMatrix::<f64, 5, 5>::from_fn(|i, j| ((i * 5 + j * 2) as f64 * 0.41).cos());
        let a = b.transpose() * b + SMatrix::<f64, 5, 5>::identity() * 0.1;
        let x = SVector::<f64, 5>::from_fn(|i, _| i as f64 - 1.7);
        let direct = x.dot(&(a * x));
        let ours = Ldlt::new(&a).unwrap().quadratic_form(&x);
        assert!((ours - direct).abs() <= 1e-13 * direct, "{ours} {direct}");
    }

    #[test]
    fn ldlt_of_a_diagonal_divides_once() {
        let a = Matrix3::from_diagonal(&Vector3::new(3.0, 7.0, 0.1));
        let b = Vector3::new(1.0, -2.0, 0.3);
        let x = Ldlt::new(&a).unwrap().solve(&b);
        assert_eq!(x, Vector3::new(1.0 / 3.0, -2.0 / 7.0, 0.3 / 0.1));
    }

    #[test]
    fn zero_sized_systems_are_trivial() {
        let a = SMatrix::<f64, 0, 0>::zeros();
        assert!(Lu::new(&a).is_some());
        assert!(Ldlt::new(&a).is_some());
    }

    #[test]
    fn jacobi_agrees_with_nalgebra_on_fixed_sizes() {
        // deterministic pseudo-random symmetric matrices
        let mut x = 0.5_f64;
        let mut next = || {
            x = (x * 3.7 + 0.1).fract();
            2.0 * x - 1.0
        };
        for _ in 0..20 {
            let b = Matrix4::from_fn(|_, _| next());
            let a = b + b.transpose();
            let ours = SymmetricEigen::new(&a).unwrap();
            let theirs = a.symmetric_eigen();
            let mut o: Vec<f64> = ours.values.iter().copied().collect();
            let mut t: Vec<f64> = theirs.eigenvalues.iter().copied().collect();
            o.sort_by(f64::total_cmp);
            t.sort_by(f64::total_cmp);
            for (o, t) in o.iter().zip(&t) {
                assert!((o - t).abs() < 1e-13 * a.norm(), "{o} vs {t}");
            }
        }
    }

    #[test]
    fn jacobi_on_known_matrices() {
        // [[2, 1], [1, 2]]: eigenvalues 1 and 3
        let e = SymmetricEigen::new(&Matrix2::new(2.0_f64, 1.0, 1.0, 2.0)).unwrap();
        assert!((e.min() - 1.0).abs() < 1e-15 && (e.max() - 3.0).abs() < 1e-15);
        // already diagonal: no rotation at all
        let d = Matrix3::from_diagonal(&Vector3::new(3.0, -1.0, 2.0));
        let e = SymmetricEigen::new(&d).unwrap();
        assert_eq!(e.values, Vector3::new(3.0, -1.0, 2.0));
        // the off-diagonal sweep of a tiny entry: a rotation of ~1e-150
        let e = SymmetricEigen::new(&Matrix2::new(1.0_f64, 1e-150, 1e-150, 2.0)).unwrap();
        assert_eq!((e.min(), e.max()), (1.0, 2.0));
        assert!(SymmetricEigen::new(&Matrix2::from_element(f64::NAN)).is_none());
        let empty = SymmetricEigen::new(&SMatrix::<f64, 0, 0>::zeros()).unwrap();
        assert_eq!((empty.min(), empty.max()), (0.0, 0.0));
    }

    #[test]
    fn spectral_norm_of_a_rectangular_matrix() {
        // singular values of [[3, 0], [4, 5]] are √45 and √5
        let a = Matrix2::new(3.0, 0.0, 4.0, 5.0);
        assert!((spectral_norm(&a).unwrap() - 45.0_f64.sqrt()).abs() < 1e-14);
        let r = nalgebra::SMatrix::<f64, 1, 3>::new(1.0, 2.0, 2.0);
        assert!((spectral_norm(&r).unwrap() - 3.0).abs() < 1e-15);
    }
}
