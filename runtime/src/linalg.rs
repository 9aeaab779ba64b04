//! Small dense factorizations for any `const N`, on the stack.
//!
//! nalgebra's `LU` and `Cholesky` ask, for a generic `Const<N>`, for
//! `DimMin`/typenum bounds that const-generic code cannot state; these two
//! are the few lines a time step needs, for the sizes of a mechanical model
//! (N up to a few tens).

use nalgebra::{RealField, SMatrix};

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

/// `A = L Lᵀ` for symmetric positive definite `A` (the lower triangle is
/// read).
#[derive(Clone, Copy, Debug)]
#[allow(dead_code)] // `solve` serves the observers, which land next
pub(crate) struct Cholesky<T: RealField + Copy, const N: usize> {
    l: SMatrix<T, N, N>,
}

impl<T: RealField + Copy, const N: usize> Cholesky<T, N> {
    /// Factors `a`; `None` when `a` is not (numerically) positive definite
    /// or not finite.
    pub fn new(a: &SMatrix<T, N, N>) -> Option<Self> {
        let mut l = SMatrix::<T, N, N>::zeros();
        for j in 0..N {
            let mut d = a[(j, j)];
            for k in 0..j {
                d -= l[(j, k)] * l[(j, k)];
            }
            if !(d > T::zero() && d.is_finite()) {
                return None;
            }
            let d = d.sqrt();
            l[(j, j)] = d;
            for i in j + 1..N {
                let mut s = a[(i, j)];
                for k in 0..j {
                    s -= l[(i, k)] * l[(j, k)];
                }
                l[(i, j)] = s / d;
            }
        }
        Some(Self { l })
    }

    /// `A⁻¹ b`, column by column.
    #[allow(dead_code)] // the observers solve with it; they land next
    pub fn solve<const C: usize>(&self, b: &SMatrix<T, N, C>) -> SMatrix<T, N, C> {
        let mut x = *b;
        for c in 0..C {
            for i in 0..N {
                let mut s = x[(i, c)];
                for k in 0..i {
                    s -= self.l[(i, k)] * x[(k, c)];
                }
                x[(i, c)] = s / self.l[(i, i)];
            }
            for i in (0..N).rev() {
                let mut s = x[(i, c)];
                for k in i + 1..N {
                    s -= self.l[(k, i)] * x[(k, c)];
                }
                x[(i, c)] = s / self.l[(i, i)];
            }
        }
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Vector3};

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
    fn cholesky_solves_and_rejects_indefinite() {
        let a = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0);
        let x = Vector3::new(0.3, -1.0, 2.0);
        let c = Cholesky::new(&a).unwrap();
        assert!((c.solve(&(a * x)) - x).amax() < 1e-14);
        let indefinite = Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert!(Cholesky::new(&indefinite).is_none());
    }

    #[test]
    fn zero_sized_systems_are_trivial() {
        let a = SMatrix::<f64, 0, 0>::zeros();
        assert!(Lu::new(&a).is_some());
        assert!(Cholesky::new(&a).is_some());
    }
}
