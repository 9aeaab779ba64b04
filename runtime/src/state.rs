//! The state `(t, q, v)` the plant stepper advances and the observers
//! estimate.

use nalgebra::{RealField, SVector};

/// The state of a mechanical system at one time: what
/// [`MoreauJean::step`](crate::MoreauJean::step) advances, and (as
/// [`Estimate`]) what an [`Observer`](crate::Observer) returns.
///
/// ```
/// use moreau_runtime::{Estimate, State};
/// use nalgebra::Vector2;
///
/// let s = State::new(0.5, Vector2::new(1.0, 2.0), Vector2::zeros());
/// // an estimate is a state: the same type, the same fields
/// let e: Estimate<f64, 2> = s;
/// assert_eq!((e.t, e.q[1]), (0.5, 2.0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State<T: RealField + Copy, const N: usize> {
    /// Time `t` (for an estimate, the time of the last measurement).
    pub t: T,
    /// Generalized coordinates `q` (for an estimate, `q̂`: for the
    /// reduced-order observer, the measurement `q` itself).
    pub q: SVector<T, N>,
    /// Generalized velocities `v` (right limits: post-impact values; for an
    /// estimate, `v̂`).
    pub v: SVector<T, N>,
}

impl<T: RealField + Copy, const N: usize> State<T, N> {
    /// The state `(t, q, v)`.
    pub fn new(t: T, q: SVector<T, N>, v: SVector<T, N>) -> Self {
        Self { t, q, v }
    }
}

/// An observer's estimate `(t, q̂, v̂)`: a [`State`] (the same type; the
/// name says what it holds).
pub type Estimate<T, const N: usize> = State<T, N>;
