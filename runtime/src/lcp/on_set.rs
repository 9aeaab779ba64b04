//! The constraints of a set, as Newton's law and the contact projections
//! see them: the rows `J_S`, `M⁻¹J_Sᵀ` and the factor of the Delassus
//! matrix `J_S M⁻¹J_Sᵀ` (the LCP's `W` restricted to the set).
//!
//! It lives beside the LCP, not in `linalg`, so that the factorizations
//! stay a leaf that knows nothing of constraint sets.

use nalgebra::{RealField, SMatrix};

use super::IndexSet;
use crate::linalg::Ldlt;

/// Newton's law and the contact projections restricted to the
/// constraints of `set`: the rows `J_S` of `jac` on `set` (zero elsewhere),
/// `M⁻¹J_Sᵀ` from the factor `mass` of `M`, and the factor of the
/// Delassus matrix `J_S M⁻¹J_Sᵀ` on `set`, with `1` on the diagonal off it
/// and symmetrized (`None` when its rows on `set` are dependent).
pub(crate) struct OnSet<T: RealField + Copy, const N: usize, const K: usize> {
    pub rows: SMatrix<T, K, N>,
    pub minv_jt: SMatrix<T, N, K>,
    pub delassus: Option<Ldlt<T, K>>,
}

impl<T: RealField + Copy, const N: usize, const K: usize> OnSet<T, N, K> {
    /// [`OnSet`] for `jac`, `M`'s factor `mass` and `set`.
    pub(crate) fn new(jac: &SMatrix<T, K, N>, mass: &Ldlt<T, N>, set: IndexSet<K>) -> Self {
        let mut rows = SMatrix::<T, K, N>::zeros();
        for i in set {
            rows.set_row(i, &jac.row(i));
        }
        let minv_jt = mass.solve(&rows.transpose());
        let jmj = rows * minv_jt;
        let mut w = SMatrix::<T, K, K>::identity();
        for a in set {
            for b in set {
                w[(a, b)] = jmj[(a, b)];
            }
        }
        let w = (w + w.transpose()) * nalgebra::convert::<f64, T>(0.5);
        Self {
            rows,
            minv_jt,
            delassus: Ldlt::new(&w),
        }
    }
}
