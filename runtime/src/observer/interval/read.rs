//! A sample read on the contacts the prediction holds at the end of its
//! interval: the filter's and, under noise, the reduced-order observer's.
//!
//! A rigid contact holds the predicted motion on its surface, and nothing
//! in a rigid model has a state for a position inside it. A sample there
//! says two things: where the body is along the contact, which the
//! estimators track, and how deep it lies inside, which is the machine's
//! compliance under a steady force (or a time-stepping plant's drift along
//! a curved constraint: 1.3e-9 m outside a circle on exact samples) when it
//! is deeper than the noise explains. [`Interval::read_on_contacts`] keeps
//! the first and drops the second: each held constraint whose gap the
//! sample shows closed by more than `d` deviations of the measurement along
//! its normal (`h_i(q) − ℓ_i < −d √(J_i R J_iᵀ)`, `ℓ_i` the level the
//! contact is held at: `0` for the observers, the filter's own for it,
//! module `kalman::level`) is read on the contact: the sample is moved
//! onto `h_V = ℓ_V` for that set `V` by the least step that leaves the
//! gaps of the other held contacts as they are, `−J_Sᵀ (J_S J_Sᵀ)⁻¹ g`
//! with `g` the sample's `h_i − ℓ_i` on `V` and `0` on the rest of the
//! held set `S` (along `V`'s normals alone where those of `S` are
//! dependent). A sample outside a held contact is left as it is: that is
//! how the samples show a contact opening.
//!
//! What each estimator does with a sample inside, unread:
//! - the filter's projection onto the contact left its covariance almost
//!   nothing across it, so its gate skipped the sample, and the next, and
//!   inflated `P` on the third: on samples 10 σ inside a held rim it used
//!   one in three and its median error grew 200-fold;
//! - (38) smooths its position from the sample, held within four of the
//!   smoothing's deviations of it, so its predicted motion started inside
//!   the rim every interval and its median error doubled on the same
//!   samples (`tests/kalman.rs`, `a_sample_inside_a_held_contact_is_read_on_it`
//!   runs both).

use nalgebra::{RealField, SMatrix, SVector};

use crate::lcp::IndexSet;
use crate::model::Model;

use super::{Interval, Result};

impl<M, T, const N: usize, const K: usize> Interval<'_, M, T, N, K>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    /// The sample `q` read on the constraints of `held` that it lies
    /// deeper inside their levels `levels` than `deviations` standard
    /// deviations of the measurement (covariance `measurement`) along
    /// their normals (see the module docs); `q` itself when none does,
    /// when `deviations` is not finite (no test), or when those normals are
    /// dependent. `at_sample` is `(h(q), J(q))` where the caller has them
    /// (evaluated here otherwise).
    ///
    /// # Errors
    ///
    /// A non-finite `h(q)` or `J(q)` ([`Interval::contact`]).
    pub(crate) fn read_on_contacts(
        &self,
        q: &SVector<T, N>,
        at_sample: Option<&(SVector<T, K>, SMatrix<T, K, N>)>,
        (held, levels): (IndexSet<K>, &SVector<T, K>),
        (measurement, deviations): (&SMatrix<T, N, N>, T),
    ) -> Result<SVector<T, N>, T> {
        if held.is_empty() || !deviations.is_finite() {
            return Ok(*q);
        }
        let (h, jac) = match at_sample {
            Some(&contact) => contact,
            None => self.contact(q)?,
        };
        let h = h - levels;
        let mut inside = IndexSet::<K>::EMPTY;
        for i in held {
            let row = jac.row(i);
            let sigma = (row * measurement).dot(&row).max(T::zero()).sqrt();
            if row.norm_squared() > T::zero() && h[i] < -deviations * sigma {
                inside.insert(i);
            }
        }
        if inside.is_empty() {
            return Ok(*q);
        }
        // the least step that puts the sample on `h_V = ℓ_V` and leaves
        // the other held gaps as they are (a step along the normals of
        // `V` alone moves those too where the normals are not orthogonal,
        // as a box's two corners' are: the sample then left a held corner
        // by as much as it read the other on, and the gate skipped it); on
        // `V` alone where the held normals are dependent
        let step = |set: IndexSet<K>| {
            // J_S J_Sᵀ on the rows and columns of `S`, the identity
            // elsewhere
            let mut gram = SMatrix::<T, K, K>::identity();
            let mut gaps = SVector::<T, K>::zeros();
            for i in set.iter() {
                if inside.contains(i) {
                    gaps[i] = h[i];
                }
                for j in set.iter() {
                    gram[(i, j)] = jac.row(i).dot(&jac.row(j));
                }
            }
            nalgebra::linalg::Cholesky::new(gram).map(|chol| chol.solve(&gaps))
        };
        let Some(x) = step(held).or_else(|| step(inside)) else {
            return Ok(*q);
        };
        Ok(q - jac.transpose() * x)
    }
}
