//! The level a held contact sits at: where the samples put a contact
//! that a struck body stays on, when a rigid model says `h = 0`.
//!
//! A rigid contact holds the body on its surface. A machine's contact
//! gives under a steady force, and a time-stepping plant leaves a body
//! that a plastic impact stopped where its step left it: inside the
//! constraint by about `δ |ḣ|`, the step's delay `δ` times the approach
//! speed (Example 1 with `e = 0`, struck at 15 m/s by `MoreauJean` at `τ =
//! 10 µs`: 94 µm inside, `0.63 τ |ḣ|`), and it slides along that level
//! set, which its velocity-level law keeps. Held at `h = 0`, the estimate
//! slides along a neighbouring curve. Its tangent at the point nearest the
//! sample turns by the curvature times the distance, and the samples,
//! read on the wrong curve, no longer fit the model's motion along it: on
//! eight random starts of that model the filter's median error was 9.1e-6
//! to 2.2e-4 m/s, over the 3e-5 on six, and on the exact samples
//! 2.4e-6 to 7.6e-5 (`tests/kalman.rs`,
//! `a_plastic_impact_leaves_the_slide_where_the_plant_put_it`; 5.0e-6 to
//! 2.0e-5, and 2.3e-10 to 3.6e-9, with the levels below).
//!
//! So each held contact `i` has a level `ℓ_i`, the gap it is held at,
//! with a variance `s_i²`:
//!
//! - where a contact comes to be held without an impact (a closure the
//!   contact rule makes at the end of micro-bounces), `ℓ_i = 0`, `s_i² =
//!   0`: the rigid model's, and no sample moves it;
//! - an impact into it at the approach speed `|ḣ|` adds the penetration
//!   that a delayed impact leaves, `ℓ_i −= max(δ̄, 0) |ḣ|` and `s_i² +=
//!   σ_δ² |ḣ|²`, with the delay and spread the filter already has for an
//!   impact's instant
//!   ([`KalmanParams::impact_delay`](super::KalmanParams::impact_delay)
//!   and
//!   [`KalmanParams::impact_time_sigma`](super::KalmanParams::impact_time_sigma),
//!   plus a plant's step, `τ_p/2` and `τ_p/√12`): a slow impact leaves the
//!   level at the surface, a fast one lets the samples say where it is;
//! - each sample the filter uses while the contact is held measures it,
//!   `z_i = h_i(q)` with the variance `J_i R J_iᵀ`, by a scalar Kalman
//!   update; the level is kept at or below `0` (a contact held open would
//!   read as no contact) and no deeper than the impacts can have left it,
//!   `−Σ max(δ̄ + 4 σ_δ, 0) |ḣ|`: the level is the trace of delayed
//!   impacts, not a model of a compliant contact, which samples pressed in
//!   by a steady force would otherwise teach it (those are read on the
//!   contact, [`Interval::read_on_contacts`](crate::observer::interval)).
//!   Four deviations, not three: the bound is to stop a steady force's
//!   creep, not to cut the delays the prior admits, and at three it cut
//!   delays past 9 µs, which a Moreau–Jean plant at `τ` = 10 µs makes at
//!   about one impact in ten (it delays an impact by up to a whole step;
//!   the defaults' `σ_δ` is 3 µs): a plastic UR5's tool struck at 3.4 m/s,
//!   which the plant held 9.3 µs deep (3.15e-5 m), was held 1.1e-6 m too
//!   shallow, and on exact samples the filter's medians on two of six
//!   starts were 1.5e-8 and 2.6e-8 rad/s (4.7e-9 and 1.4e-9 at four);
//! - a contact no longer held forgets its level;
//! - a struck contact whose level a sample contradicts past the gate
//!   (the filter widened its prediction) starts again from that sample
//!   ([`Levels::restart`]): the plant can move a held contact's depth
//!   without striking it.
//!
//! The projection onto the contact at the end of a held piece
//! ([`project_onto_contact`](super::saltation::project_onto_contact)) then
//! moves the state onto `h_S = ℓ_S`, and a sample is read on the contact
//! ([`Interval::read_on_contacts`](crate::observer::interval)) relative to
//! the level. The projection takes every variance across the contact,
//! and the level's own is put back: the manifold moves with each level,
//! by `J⁺ δℓ` in position and `−J⁺ D J⁺ δℓ` in velocity (`J⁺` and `D` of
//! the projection), so `P` gains `C diag(s²) Cᵀ` along those directions
//! (`level_spread` in module `propagate`). A sample then moves the state
//! across the contact by about what it moves the level, and the next
//! projection finds the state where the level now is. Without it the
//! filter held a plastic UR5's tool on a level 1e-6 m off the plant's
//! while it claimed the gap to 7e-11 m, the velocity NEES median over the
//! held samples was 3.6 to 23 on six starts (χ² median 5.35), and after
//! lift-off the claim went on into the flight (NEES medians up to 59);
//! with it 2.7 to 12 held and 0.95 to 14 in flight, and medians 2.1e-5
//! to 5.9e-5 rad/s instead of 2.6e-5 to 5.9e-5 (`tests/robots/kalman.rs`,
//! `the_filter_follows_a_plastic_ur5_onto_and_off_a_table`).

use nalgebra::{RealField, SMatrix, SVector};

use crate::lcp::IndexSet;

/// The held contacts' levels and their variances (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Levels<T: RealField + Copy, const K: usize> {
    /// `ℓ_i`: `0` for a contact not held.
    pub mean: SVector<T, K>,
    /// `s_i²`.
    variance: SVector<T, K>,
    /// The deepest level the impacts into each contact can have left,
    /// `−Σ max(δ̄ + 4 σ_δ, 0) |ḣ|`.
    deepest: SVector<T, K>,
    /// The contacts held at the end of the last update.
    held: IndexSet<K>,
}

impl<T: RealField + Copy, const K: usize> Levels<T, K> {
    /// No contact held: every level at the surface.
    pub fn surface() -> Self {
        Self {
            mean: SVector::zeros(),
            variance: SVector::zeros(),
            deepest: SVector::zeros(),
            held: IndexSet::EMPTY,
        }
    }

    /// `s_i²`: `0` for a contact not held, or held without an impact.
    pub fn variance(&self) -> SVector<T, K> {
        self.variance
    }

    /// Whether no contact was held at the end of the last update (every
    /// level then at the surface).
    pub fn at_surface(&self) -> bool {
        self.held.is_empty()
    }

    /// The levels of the struck contacts held at the end of an update
    /// (those [`Levels::follow`] has just taken) started again from its
    /// sample, `ℓ_i = h_i(q)` within its bounds,
    /// `s_i² = J_i R J_iᵀ` (`sample` as for [`Levels::follow`]), for an
    /// update whose prediction the sample contradicted past the gate;
    /// called after [`Levels::follow`] (the sample then counts once, and
    /// an impact of the interval is not added below the level the sample
    /// measures after it).
    ///
    /// The plant may move a held contact's depth without striking it: an
    /// impact on another contact held with it (a mass struck into the
    /// corner of a floor and a ramp while it rests on the floor) lifted the
    /// floor contact from 1.2e-8 to 7.5e-10 m inside. A level learned from
    /// exact samples has no variance left, and the filter then skipped
    /// every sample but the one in three that its inflation let through:
    /// 1 940 of 10 001 (`tests/kalman.rs`,
    /// `a_contact_that_another_contacts_force_pulls_away_lifts_off`).
    pub fn restart<const N: usize>(
        &mut self,
        (h, jac, measurement): (&SVector<T, K>, &SMatrix<T, K, N>, &SMatrix<T, N, N>),
    ) {
        for i in self.held {
            // (`deepest < 0`: struck since it was last released)
            if self.deepest[i] < T::zero() && h[i].is_finite() {
                let row = jac.row(i);
                self.mean[i] = h[i].max(self.deepest[i]).min(T::zero());
                self.variance[i] = (row * measurement).dot(&row);
            }
        }
    }

    /// The levels after an update that ended with the contacts `held`,
    /// struck in its interval at the approach speeds `struck` (`0` where
    /// none), under the impact delay `delay` with the variance `timing`;
    /// `sample`, when the update used its sample, holds the sample's gaps
    /// `h(q)`, its Jacobian `J(q)` and the measurement covariance `R`.
    pub fn follow<const N: usize>(
        &mut self,
        held: IndexSet<K>,
        struck: &SVector<T, K>,
        (delay, timing): (T, T),
        sample: Option<(&SVector<T, K>, &SMatrix<T, K, N>, &SMatrix<T, N, N>)>,
    ) {
        // (an early impact, `δ̄ < 0`, leaves nothing inside)
        let late = delay.max(T::zero());
        let reach = (delay + timing.sqrt() * nalgebra::convert(4.0)).max(T::zero());
        for i in 0..K {
            if !held.contains(i) || !self.held.contains(i) {
                self.mean[i] = T::zero();
                self.variance[i] = T::zero();
                self.deepest[i] = T::zero();
            }
            if !held.contains(i) {
                continue;
            }
            let speed = struck[i];
            if speed > T::zero() {
                self.mean[i] -= late * speed;
                self.variance[i] += timing * speed * speed;
                self.deepest[i] -= reach * speed;
            }
            if let Some((h, jac, measurement)) = sample
                && self.variance[i] > T::zero()
            {
                let row = jac.row(i);
                let r = (row * measurement).dot(&row);
                let s = self.variance[i] + r;
                if s > T::zero() && h[i].is_finite() {
                    let gain = self.variance[i] / s;
                    let innovation = h[i] - self.mean[i];
                    self.mean[i] += gain * innovation;
                    self.variance[i] *= T::one() - gain;
                }
            }
            self.mean[i] = self.mean[i].max(self.deepest[i]).min(T::zero());
        }
        self.held = held;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix1x2, Matrix2, Vector1};

    /// A contact held from a fast impact learns the level its samples sit
    /// at, as the mean of a Gaussian prior and the samples, between the
    /// surface and the deepest the impact can have left; one held without
    /// an impact stays at the surface whatever the samples say; one
    /// released forgets.
    #[test]
    fn a_struck_contact_learns_its_level_and_a_closed_one_keeps_the_surface() {
        let (jac, r) = (Matrix1x2::new(0.0, 1.0), Matrix2::identity() * 1e-8);
        let held = IndexSet::<1>::full(1);
        let (delay, timing) = (0.0, 9e-12);
        // struck at 15 m/s: prior 0 ± 4.5e-5; samples at −9.4e-5 exactly
        let mut levels = Levels::<f64, 1>::surface();
        let gap = Vector1::new(-9.4e-5);
        levels.follow(
            held,
            &Vector1::new(15.0),
            (delay, timing),
            Some((&gap, &jac, &r)),
        );
        let (s0, r0) = (timing * 225.0, 1e-8);
        let first = s0 / (s0 + r0) * -9.4e-5;
        assert!((levels.mean[0] - first).abs() <= 1e-18);
        for _ in 0..99 {
            levels.follow(
                held,
                &Vector1::zeros(),
                (delay, timing),
                Some((&gap, &jac, &r)),
            );
        }
        // a hundred samples of variance r against the prior: the
        // precision-weighted mean
        let expected = (100.0 / r0) * -9.4e-5 / (100.0 / r0 + 1.0 / s0);
        assert!(
            (levels.mean[0] - expected).abs() <= 1e-12,
            "{}",
            levels.mean[0]
        );
        // a sample outside never lifts the level above the surface
        levels.follow(
            held,
            &Vector1::zeros(),
            (delay, timing),
            Some((&Vector1::new(1.0), &jac, &r)),
        );
        assert_eq!(levels.mean[0], 0.0);
        // nor a sample far inside sinks it deeper than the impact can
        // have left it, 4 σ_δ |ḣ| = 1.8e-4
        for _ in 0..10_000 {
            levels.follow(
                held,
                &Vector1::zeros(),
                (delay, timing),
                Some((&Vector1::new(-1.0), &jac, &r)),
            );
        }
        assert!(
            (levels.mean[0] + 1.8e-4).abs() <= 1e-15,
            "{}",
            levels.mean[0]
        );
        // released, then held again without an impact: the surface, which
        // no sample moves
        levels.follow::<2>(IndexSet::EMPTY, &Vector1::zeros(), (delay, timing), None);
        levels.follow(
            held,
            &Vector1::zeros(),
            (delay, timing),
            Some((&gap, &jac, &r)),
        );
        assert_eq!(levels.mean[0], 0.0);
        // impacts early on average (a signed delay, as a tuned one may
        // be): nothing inside, however deep the samples
        let mut early = Levels::<f64, 1>::surface();
        for k in 0..100 {
            let speed = if k == 0 { 15.0 } else { 0.0 };
            early.follow(
                held,
                &Vector1::new(speed),
                (-2e-5, timing),
                Some((&gap, &jac, &r)),
            );
            assert_eq!(early.mean[0], 0.0);
        }
    }

    /// A struck contact's level, learned from exact samples (no variance
    /// left), starts again from a sample that contradicts it, within its
    /// bounds; a contact held without an impact keeps the surface.
    #[test]
    fn a_contradicted_level_starts_again_from_the_sample() {
        let (jac, exact) = (Matrix1x2::new(0.0, 1.0), Matrix2::zeros());
        let held = IndexSet::<1>::full(1);
        let mut levels = Levels::<f64, 1>::surface();
        let deep = Vector1::new(-1.2e-8);
        levels.follow(
            held,
            &Vector1::new(0.01),
            (0.0, 9e-12),
            Some((&deep, &jac, &exact)),
        );
        assert_eq!((levels.mean[0], levels.variance[0]), (-1.2e-8, 0.0));
        // a later exact sample nearer the surface no longer moves it
        let shallow = Vector1::new(-7.5e-10);
        levels.follow(
            held,
            &Vector1::zeros(),
            (0.0, 9e-12),
            Some((&shallow, &jac, &exact)),
        );
        assert_eq!(levels.mean[0], -1.2e-8);
        // restarted from it, it sits there
        levels.restart((&shallow, &jac, &exact));
        assert_eq!(levels.mean[0], -7.5e-10);
        // and no deeper than the impact can have left it, 4 σ_δ |ḣ| = 1.2e-7
        levels.restart((&Vector1::new(-1.0), &jac, &exact));
        assert!(
            (levels.mean[0] + 1.2e-7).abs() <= 1e-20,
            "{}",
            levels.mean[0]
        );
        // held without an impact: the surface, restart or not
        let mut closed = Levels::<f64, 1>::surface();
        closed.follow::<2>(held, &Vector1::zeros(), (0.0, 9e-12), None);
        closed.follow::<2>(held, &Vector1::zeros(), (0.0, 9e-12), None);
        closed.restart((&deep, &jac, &exact));
        assert_eq!(closed.mean[0], 0.0);
    }
}
