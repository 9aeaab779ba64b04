//! An impact located from a noisy start, timed again from the sample that
//! ends its interval (the reduced-order observer (38) under noise).
//!
//! The predicted motion of an interval starts at the smoothed position
//! `q̄_k`; the root of a gap along it times an impact, and the start's
//! error `x` along the normal moves that root by `x / |J_i w⁻|` and the
//! rebound by `(1 + e_i) A_i x / |J_i w⁻|` (`A_i` the normal acceleration
//! of the free motion): the larger, the slower the approach. The sample
//! that ends the interval was taken after the impact, and sees the same
//! error: the measured displacement minus the predicted one, `d`, is
//! `−(1 + e_i) x` along the normal (the start as much lower, the rebound
//! `e_i x` higher), plus the noise of two samples, `√2 σ` per coordinate.
//!
//! [`Interval::retime`] combines the two as independent Gaussian
//! estimates of `x`: the start's, `0` with the standard deviation `σ̄` of
//! `q̄`, and the end's, `−J_i d / (1 + e_i)` with `√2 σ |J_i| / (1 + e_i)`.
//! The weight of the end's is `σ̄² / (σ̄² + 2σ²/(1 + e_i)²)` (about a
//! tenth for `σ̄ = σ/4`, `e = 0.9`), and the impact moves by
//! `δ = x̂ / |J_i w⁻|`, held inside the interval. The rebound then changes
//! by `−(1 + e_i) α_i δ` along the normal (`α_i = J_i a + J̇_i w` the
//! signed normal acceleration), applied as Newton's law applies an
//! impulse: `Δw = M⁻¹J_iᵀ Δ / (J_i M⁻¹J_iᵀ)`.
//!
//! Only a single restituted impact in the interval is timed again (on
//! one constraint, a first-order correction); the injection is the same,
//! and so is the observer's error equation: the estimated impulse `η̂`
//! still acts inside the interval, at a time the samples agree with better.

use nalgebra::{RealField, SMatrix, SVector};

use crate::lcp::IndexSet;
use crate::model::Model;

use super::{Flight, Free, Interval, Jump, Result, Tracer};

/// A restituted impact on one constraint.
#[derive(Clone, Copy)]
struct Impact<T: RealField + Copy, const N: usize> {
    /// Local time `s`.
    s: T,
    /// The configuration there.
    p: SVector<T, N>,
    /// The pre-impact velocity `w⁻`.
    w: SVector<T, N>,
    /// The constraint `i` and its restitution `e_i`.
    i: usize,
    e: T,
    /// `J_i(p)` and the free motion there, as the prediction had them.
    row: SMatrix<T, 1, N>,
    free: Free<T, N>,
}

/// What (38) under noise needs of the predicted motion of an interval, as
/// a [`Tracer`] records it: for [`Interval::retime`], the restituted
/// impacts, counted, and the last one; for
/// [`Interval::read_on_contacts`], the contacts the predicted end lies on.
pub(crate) struct Events<T: RealField + Copy, const N: usize, const K: usize> {
    /// The restituted impacts seen (one on several constraints at once
    /// counts twice: it is not timed again).
    count: u32,
    last: Option<Impact<T, N>>,
    /// The constraints held along the last piece, pushing or resting, if
    /// no impact law followed it (as the filter's propagation has them).
    pub(crate) held: IndexSet<K>,
}

impl<T: RealField + Copy, const N: usize, const K: usize> Events<T, N, K> {
    /// No impact seen yet.
    pub(crate) fn new() -> Self {
        Self {
            count: 0,
            last: None,
            held: IndexSet::EMPTY,
        }
    }
}

impl<T: RealField + Copy, const N: usize, const K: usize> Tracer<T, N, K> for Events<T, N, K> {
    fn flight(&mut self, piece: &Flight<'_, T, N, K>) -> Result<(), T> {
        self.held = piece.held();
        Ok(())
    }

    fn jump(&mut self, jump: &Jump<'_, T, N, K>) -> Result<(), T> {
        self.held = IndexSet::EMPTY;
        let mut hit = IndexSet::<K>::EMPTY;
        for i in jump.elastic {
            if jump.lambda[i] > T::zero() && jump.restitution[i] > T::zero() {
                hit.insert(i);
            }
        }
        let mut constraints = hit.into_iter();
        match (constraints.next(), constraints.next()) {
            (None, _) => {}
            (Some(i), None) => {
                self.count += 1;
                self.last = Some(Impact {
                    s: jump.s,
                    p: *jump.p,
                    w: *jump.w_minus,
                    i,
                    e: jump.restitution[i],
                    row: jump.jac.row(i).into_owned(),
                    free: *jump.free,
                });
            }
            (Some(_), Some(_)) => self.count += 2,
        }
        Ok(())
    }
}

impl<M, T, const N: usize, const K: usize> Interval<'_, M, T, N, K>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    /// The change of the end velocity when the one restituted impact of
    /// the interval (`events`) is timed again with the measured minus the
    /// predicted displacement `d` (see the module docs); `sigma` is the
    /// noise of a sample and `sigma_start` that of the start `q̄_k`. `None`
    /// without noise, without exactly one restituted impact, or where the
    /// approach or the normal acceleration does not close the gap.
    pub(crate) fn retime(
        &self,
        events: &Events<T, N, K>,
        d: &SVector<T, N>,
        (sigma, sigma_start): (T, T),
    ) -> Result<Option<SVector<T, N>>, T> {
        let Impact {
            s,
            p,
            w,
            i,
            e,
            row,
            free,
        } = match events.last {
            Some(last) if events.count == 1 && sigma > T::zero() => last,
            _ => return Ok(None),
        };
        let approach = row.dot(&w.transpose());
        let normal_accel = row.dot(&free.accel.transpose()) + self.jacobian_rate(&p, &w)?[i];
        if approach >= T::zero() || normal_accel >= T::zero() {
            return Ok(None);
        }
        let one = T::one();
        let two: T = nalgebra::convert(2.0);
        let start = sigma_start * sigma_start;
        let end = two * sigma * sigma / ((one + e) * (one + e));
        let weight = start / (start + end);
        // the start's error along the normal, and the impact's shift
        let x = -weight * row.dot(&d.transpose()) / (one + e);
        let shift = (x / -approach).max(-s).min(self.tau - s);
        let delta = -(one + e) * normal_accel * shift;
        let minv_jt = free.chol.solve(&row.transpose());
        let delassus = row.dot(&minv_jt.transpose());
        Ok(Some(minv_jt * (delta / delassus)))
    }
}
