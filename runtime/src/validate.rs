//! The one validation of data the stepper and the observers share: every
//! check returns a [`DataError`] naming what is wrong, and none changes
//! anything.

use nalgebra::{RealField, SMatrix, SVector};

use crate::error::DataError;
use crate::linalg::Ldlt;
use crate::model::Model;

/// Rejects a vector of the state or of a measurement that holds a NaN or
/// an infinity, naming it `which`.
pub(crate) fn finite_vector<T: RealField + Copy, const N: usize>(
    x: &SVector<T, N>,
    which: &'static str,
) -> Result<(), DataError<T>> {
    match x.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(DataError::NonFinite { which, index }),
        None => Ok(()),
    }
}

/// Rejects a non-finite model term `which` (`"M"`, `"F"`, `"h"`, `"J"`, ...).
pub(crate) fn finite_model<T: RealField + Copy, const R: usize, const C: usize>(
    m: &SMatrix<T, R, C>,
    which: &'static str,
) -> Result<(), DataError<T>> {
    if m.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(DataError::NonFiniteModel { which })
    }
}

/// Factors `M`, rejecting a non-finite or indefinite one.
#[inline]
pub(crate) fn factor_mass<T: RealField + Copy, const N: usize>(
    mass: &SMatrix<T, N, N>,
) -> Result<Ldlt<T, N>, DataError<T>> {
    finite_model(mass, "M")?;
    Ldlt::new(mass).ok_or(DataError::MassNotPositiveDefinite)
}

/// The diagonal of a diagonal `M`, rejecting a non-finite or indefinite
/// one with the errors of [`factor_mass`] (for a model whose structure
/// proves `M` diagonal).
pub(crate) fn diagonal_mass<T: RealField + Copy, const N: usize>(
    mass: &SMatrix<T, N, N>,
) -> Result<SVector<T, N>, DataError<T>> {
    finite_model(mass, "M")?;
    let d = mass.diagonal();
    if d.iter().all(|x| *x > T::zero()) {
        Ok(d)
    } else {
        Err(DataError::MassNotPositiveDefinite)
    }
}

/// Rejects restitution coefficients outside `[0, 1]` (or NaN).
pub(crate) fn restitution<T: RealField + Copy, const K: usize>(
    e: &SVector<T, K>,
) -> Result<(), DataError<T>> {
    for (constraint, &value) in e.iter().enumerate() {
        if !(value >= T::zero() && value <= T::one()) {
            return Err(DataError::InvalidRestitution { constraint, value });
        }
    }
    Ok(())
}

/// What a step and an update both check of the model and the known input:
/// every parameter finite, every input finite.
pub(crate) fn model_and_input<M, T, const N: usize, const K: usize>(
    model: &M,
    u: &M::Input,
) -> Result<(), DataError<T>>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    let mut index = 0;
    while let Some(p) = model.parameter(index) {
        if !p.is_finite() {
            return Err(DataError::NonFiniteParameter { index });
        }
        index += 1;
    }
    if let Some(index) = u.as_ref().iter().position(|x| !x.is_finite()) {
        return Err(DataError::NonFiniteInput { index });
    }
    Ok(())
}
