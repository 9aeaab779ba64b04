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
//! - each sample the filter uses while the contact is held measures it
//!   with the state (below, "A level is a state"; the first sample after
//!   the impact, before the state carries the level, by a scalar update
//!   `z_i = h_i(q)` with the variance `J_i R J_iᵀ`); the level is kept at
//!   or below `0` (a contact held open would
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
//! the level.
//!
//! # A level is a state
//!
//! The projection takes every variance across the contact and puts the
//! state where the level is: `x ← B x + G ℓ`, the manifold moving with
//! each level by `J⁺ δℓ` in position and `−J⁺ D J⁺ δℓ` in velocity (`G`,
//! with `J⁺` and `D` of the projection). So the levels are part of the
//! state, `(q, v, ℓ)`, and the filter keeps the augmented covariance
//! `[[P, X], [Xᵀ, S]]`: the levels' covariance `S` and their correlation
//! `X` with `(q, v)`. The prediction maps `X` with the state (`X ← Φ X`
//! along a piece, `Ξ X` at an impact) and the projection is the
//! congruence by `[B G]` ([`Levels::project`]); a sample updates the
//! state and the levels together, `H = [I 0 0]`, in Joseph form
//! ([`Levels::update`]). The levels are random constants: nothing but an
//! impact adds to `S`.
//!
//! The correlation is what the filter needs where a held body moves fast.
//! A level that is off bends every prediction along the slide the same
//! way (the held configuration sits `J⁺ δℓ` across the contact, and the
//! dynamics along it change with it); an error drawn afresh at each
//! projection, as the level's variance was put into `P` before,
//! `P += G S Gᵀ` uncorrelated with anything, averages out over the
//! samples, and the filter believed its slide better than it was. On a
//! plastic UR5 whose arm slides its tool at 10 to 21 rad/s the velocity
//! NEES medians of six starts were 2.4 to 11.6 with the defaults (χ² median
//! 5.35) and 1.9 to 22 told the plant's step; smaller Runge–Kutta pieces
//! made them worse (11.6 to 14.2 on start 5 at 0.1 ms pieces: each
//! projection removed more of what the previous one had put back). With
//! the level a state they are 0.9 to 3.6 and 0.8 to 2.6, and the medians
//! 1.3e-5 to 3.6e-5 rad/s instead of 2.1e-5 to 5.9e-5
//! (`tests/robots/kalman.rs`,
//! `the_filter_follows_a_plastic_ur5_onto_and_off_a_table`). Before the
//! level had any variance in `P` the filter claimed the tool's gap to
//! 7e-11 m while its level was 1e-6 m off the plant's, and the velocity
//! NEES medians were 4.2 to 25.

use nalgebra::{RealField, SMatrix, SVector};

use crate::lcp::IndexSet;

use super::Blocks;
use super::saltation::Projection;

/// The held contacts' levels, their covariance and its correlation with
/// the state (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Levels<T: RealField + Copy, const N: usize, const K: usize> {
    /// `ℓ_i`: `0` for a contact not held.
    pub mean: SVector<T, K>,
    /// The covariance of the levels' errors, `S` (`s_i²` on its diagonal);
    /// zero rows and columns for the contacts not held, or held without
    /// an impact.
    covariance: SMatrix<T, K, K>,
    /// The covariance of the state's error with the levels', `X = (X_q,
    /// X_v)` (module docs, "A level is a state").
    cross: (SMatrix<T, N, K>, SMatrix<T, N, K>),
    /// The deepest level the impacts into each contact can have left,
    /// `−Σ max(δ̄ + 4 σ_δ, 0) |ḣ|`.
    deepest: SVector<T, K>,
    /// The contacts held at the end of the last update.
    held: IndexSet<K>,
}

impl<T: RealField + Copy, const N: usize, const K: usize> Levels<T, N, K> {
    /// No contact held: every level at the surface.
    pub fn surface() -> Self {
        Self {
            mean: SVector::zeros(),
            covariance: SMatrix::zeros(),
            cross: (SMatrix::zeros(), SMatrix::zeros()),
            deepest: SVector::zeros(),
            held: IndexSet::EMPTY,
        }
    }

    /// `s_i²`: `0` for a contact not held, or held without an impact.
    #[cfg(test)]
    pub fn variance(&self) -> SVector<T, K> {
        self.covariance.diagonal()
    }

    /// Whether some level has a variance: the only case in which the
    /// levels take part in the covariance's propagation and update.
    pub fn uncertain(&self) -> bool {
        self.covariance.diagonal().iter().any(|&s| s > T::zero())
    }

    /// Whether no contact was held at the end of the last update (every
    /// level then at the surface).
    pub fn at_surface(&self) -> bool {
        self.held.is_empty()
    }

    /// `X ← A X`: the state's error mapped by `map` (a piece's transition
    /// `Φ`, an impact's saltation matrix `Ξ`), the levels' unchanged.
    pub fn map_state(&mut self, map: &Blocks<T, N>) {
        if self.uncertain() {
            let (xq, xv) = self.cross;
            self.cross = (map.qq * xq + map.qv * xv, map.vq * xq + map.vv * xv);
        }
    }

    /// The state moved onto the manifold `h_S = ℓ_S` by `projection`,
    /// `x ← B x + G ℓ` (`G` its `level` columns): what `P` gains beyond
    /// `B P Bᵀ`, `B X Gᵀ + G Xᵀ Bᵀ + G S Gᵀ`, and `X ← B X + G S`. With
    /// `B P Bᵀ` it is the congruence of the augmented covariance
    /// `[[P, X], [Xᵀ, S]]` by `[B G]`, positive semi-definite with it.
    pub fn project(&mut self, projection: &Projection<T, N, K>) -> Blocks<T, N> {
        let b = &projection.map;
        let (gq, gv) = projection.level;
        let (xq, xv) = self.cross;
        // B X, and the new cross Y = B X + G S
        let (bq, bv) = (b.qq * xq + b.qv * xv, b.vq * xq + b.vv * xv);
        let (yq, yv) = (bq + gq * self.covariance, bv + gv * self.covariance);
        // B X Gᵀ + G Xᵀ Bᵀ + G S Gᵀ = Y Gᵀ + G (B X)ᵀ
        let qv = yq * gv.transpose() + gq * bv.transpose();
        self.cross = (yq, yv);
        Blocks {
            qq: yq * gq.transpose() + gq * bq.transpose(),
            qv,
            vq: qv.transpose(),
            vv: yv * gv.transpose() + gv * bv.transpose(),
        }
    }

    /// The levels measured by a sample through their correlation with the
    /// state: the Kalman update of the augmented state `(q, v, ℓ)` with
    /// `H = [I 0 0]`, in Joseph form. `prior` is the state's predicted
    /// covariance, `(k_q, k_v)` its gains, `r` the measurement covariance
    /// the update used, `solve` applies `(P_qq + r)⁻¹` and `y` is the
    /// innovation. The levels' gain is `K_ℓ = X_qᵀ (P_qq + r)⁻¹`; then
    /// `X ← (I − K_x H)(X − P Hᵀ K_ℓᵀ) + K_x r K_ℓᵀ` and
    /// `S ← S − K_ℓ X_q − X_qᵀ K_ℓᵀ + K_ℓ (P_qq + r) K_ℓᵀ`.
    pub fn update(
        &mut self,
        prior: &Blocks<T, N>,
        (k_q, k_v): (&SMatrix<T, N, N>, &SMatrix<T, N, N>),
        r: &SMatrix<T, N, N>,
        solve: impl Fn(&SMatrix<T, N, K>) -> SMatrix<T, N, K>,
        y: &SVector<T, N>,
    ) {
        if !self.uncertain() {
            return;
        }
        let (xq0, xv0) = self.cross;
        // K_ℓᵀ = (P_qq + r)⁻¹ X_q
        let gain_t = solve(&xq0);
        let gain = gain_t.transpose();
        self.mean += gain * y;
        let xq = xq0 - prior.qq * gain_t;
        let xv = xv0 - prior.vq * gain_t;
        let rk = r * gain_t;
        self.cross = (xq - k_q * xq + k_q * rk, xv - k_v * xq + k_v * rk);
        let xk = gain * xq0;
        let s = self.covariance - xk - xk.transpose() + gain * (prior.qq + r) * gain_t;
        self.covariance = (s + s.transpose()) * nalgebra::convert::<f64, T>(0.5);
        // a level the samples have pinned down to rounding: known, with no
        // correlation left (a negative variance would take `P`'s
        // definiteness with it at the next projection)
        for i in 0..K {
            let positive = self.covariance[(i, i)].partial_cmp(&T::zero())
                == Some(core::cmp::Ordering::Greater);
            if !positive {
                self.decorrelate(i);
            }
        }
    }

    /// Contact `i` forgets its level: no mean, no variance, no correlation.
    fn forget(&mut self, i: usize) {
        self.decorrelate(i);
        self.mean[i] = T::zero();
        self.deepest[i] = T::zero();
    }

    /// Level `i` taken as known: no variance and no correlation with the
    /// state or the other levels, its mean and bound kept.
    fn decorrelate(&mut self, i: usize) {
        self.covariance.row_mut(i).fill(T::zero());
        self.covariance.column_mut(i).fill(T::zero());
        self.cross.0.column_mut(i).fill(T::zero());
        self.cross.1.column_mut(i).fill(T::zero());
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
    pub fn restart(
        &mut self,
        (h, jac, measurement): (&SVector<T, K>, &SMatrix<T, K, N>, &SMatrix<T, N, N>),
    ) {
        for i in self.held {
            // (`deepest < 0`: struck since it was last released)
            if self.deepest[i] < T::zero() && h[i].is_finite() {
                let row = jac.row(i);
                self.decorrelate(i);
                self.mean[i] = h[i].max(self.deepest[i]).min(T::zero());
                self.covariance[(i, i)] = (row * measurement).dot(&row);
            }
        }
    }

    /// The levels after an update that ended with the contacts `held`,
    /// struck in its interval at the approach speeds `struck` (`0` where
    /// none), under the impact delay `delay` with the variance `timing`;
    /// `sample`, when the update used its sample, holds the sample's gaps
    /// `h(q)`, its Jacobian `J(q)` and the measurement covariance `R`.
    pub fn follow(
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
                self.forget(i);
            }
            if !held.contains(i) {
                continue;
            }
            let speed = struck[i];
            if speed > T::zero() {
                self.mean[i] -= late * speed;
                self.covariance[(i, i)] += timing * speed * speed;
                self.deepest[i] -= reach * speed;
            }
            // a level not yet correlated with the state (struck in this
            // interval: the projection that correlates them comes with
            // the next piece held) is measured by the sample alone,
            // `z_i = h_i(q)` with the variance `J_i R J_iᵀ`; one the state
            // carries was measured with it ([`Levels::update`])
            let correlated = self.cross.0.column(i).iter().any(|&x| x != T::zero());
            let variance = self.covariance[(i, i)];
            if let Some((h, jac, measurement)) = sample
                && variance > T::zero()
                && !correlated
            {
                let row = jac.row(i);
                let r = (row * measurement).dot(&row);
                let s = variance + r;
                if s > T::zero() && h[i].is_finite() {
                    let gain = variance / s;
                    let innovation = h[i] - self.mean[i];
                    self.mean[i] += gain * innovation;
                    self.covariance[(i, i)] *= T::one() - gain;
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
    use nalgebra::{Matrix1x2, Matrix2, Vector1, Vector2};

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
        let mut levels = Levels::<f64, 2, 1>::surface();
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
        levels.follow(IndexSet::EMPTY, &Vector1::zeros(), (delay, timing), None);
        levels.follow(
            held,
            &Vector1::zeros(),
            (delay, timing),
            Some((&gap, &jac, &r)),
        );
        assert_eq!(levels.mean[0], 0.0);
        // impacts early on average (a signed delay, as a tuned one may
        // be): nothing inside, however deep the samples
        let mut early = Levels::<f64, 2, 1>::surface();
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
        let mut levels = Levels::<f64, 2, 1>::surface();
        let deep = Vector1::new(-1.2e-8);
        levels.follow(
            held,
            &Vector1::new(0.01),
            (0.0, 9e-12),
            Some((&deep, &jac, &exact)),
        );
        assert_eq!((levels.mean[0], levels.variance()[0]), (-1.2e-8, 0.0));
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
        let mut closed = Levels::<f64, 2, 1>::surface();
        closed.follow(held, &Vector1::zeros(), (0.0, 9e-12), None);
        closed.follow(held, &Vector1::zeros(), (0.0, 9e-12), None);
        closed.restart((&deep, &jac, &exact));
        assert_eq!(closed.mean[0], 0.0);
    }

    /// The augmented covariance `[[P, X], [Xᵀ, S]]` over `(q, v, ℓ)` with
    /// `N = 2`, `K = 2`, as one dense `6 × 6` matrix `L Lᵀ`, and the
    /// `Blocks`, cross and level parts it splits into.
    fn augmented() -> (nalgebra::DMatrix<f64>, Blocks<f64, 2>, Levels<f64, 2, 2>) {
        let l = nalgebra::DMatrix::<f64>::from_fn(6, 6, |i, j| {
            if j > i {
                0.0
            } else {
                let x = (i * 7 + j * 3) as f64;
                (0.3 + x.sin().abs()) * if i == j { 1.0 } else { 0.5 }
            }
        });
        let full = &l * l.transpose();
        let at = |r: usize, c: usize| Matrix2::from_fn(|i, j| full[(r + i, c + j)]);
        let p = Blocks {
            qq: at(0, 0),
            qv: at(0, 2),
            vq: at(2, 0),
            vv: at(2, 2),
        };
        let mut levels = Levels::<f64, 2, 2>::surface();
        levels.covariance = at(4, 4);
        levels.cross = (at(0, 4), at(2, 4));
        levels.held = IndexSet::full(2);
        (full, p, levels)
    }

    /// The dense matrix's blocks against the state's, the cross's and the
    /// levels' parts, entry by entry within `tol`.
    fn agrees(
        full: &nalgebra::DMatrix<f64>,
        (p, levels): (&Blocks<f64, 2>, &Levels<f64, 2, 2>),
        tol: f64,
    ) {
        for i in 0..6 {
            for j in 0..6 {
                let ours = match (i < 4, j < 4) {
                    (true, true) => p.entry(i, j),
                    (true, false) if i < 2 => levels.cross.0[(i, j - 4)],
                    (true, false) => levels.cross.1[(i - 2, j - 4)],
                    (false, true) if j < 2 => levels.cross.0[(j, i - 4)],
                    (false, true) => levels.cross.1[(j - 2, i - 4)],
                    (false, false) => levels.covariance[(i - 4, j - 4)],
                };
                let scale = full[(i, i)].sqrt() * full[(j, j)].sqrt();
                assert!(
                    (ours - full[(i, j)]).abs() <= tol * scale,
                    "({i}, {j}): {ours} against {}",
                    full[(i, j)]
                );
            }
        }
    }

    /// The projection of a state that carries levels is the congruence of
    /// the augmented covariance by `[B G; 0 I]`: `P`'s gain and the new
    /// cross against the dense product.
    #[test]
    fn a_projection_maps_the_augmented_covariance() {
        let (full, p, mut levels) = augmented();
        let b = Blocks {
            qq: Matrix2::new(0.6, -0.2, 0.1, 0.9),
            qv: Matrix2::zeros(),
            vq: Matrix2::new(0.3, 0.05, -0.4, 0.2),
            vv: Matrix2::new(0.7, 0.1, -0.3, 0.8),
        };
        let g = (
            Matrix2::new(0.5, 0.0, -0.2, 1.1),
            Matrix2::new(-0.3, 0.4, 0.6, 0.0),
        );
        let projection = Projection {
            p: b.congruence(&p),
            map: b,
            dq: SVector::zeros(),
            dv: SVector::zeros(),
            level: g,
        };
        let gained = levels.project(&projection);
        let projected = projection.p.add(&gained);
        let mut a = nalgebra::DMatrix::<f64>::identity(6, 6);
        for i in 0..4 {
            for j in 0..4 {
                a[(i, j)] = b.entry(i, j);
            }
            for j in 0..2 {
                a[(i, 4 + j)] = if i < 2 { g.0[(i, j)] } else { g.1[(i - 2, j)] };
            }
        }
        let expected = &a * &full * a.transpose();
        agrees(&expected, (&projected, &levels), 1e-13);
    }

    /// The levels' update with the state's is the Kalman update of the
    /// augmented state `(q, v, ℓ)` from a sample of `q`, in Joseph form
    /// and in the mean, against the dense formulas.
    #[test]
    fn a_sample_updates_the_levels_as_the_augmented_state() {
        let (full, p, mut levels) = augmented();
        let r = Matrix2::new(0.4, 0.1, 0.1, 0.3);
        let y = Vector2::new(0.25, -0.6);
        let mut h = nalgebra::DMatrix::<f64>::zeros(2, 6);
        h[(0, 0)] = 1.0;
        h[(1, 1)] = 1.0;
        let r_dense = nalgebra::DMatrix::from_fn(2, 2, |i, j| r[(i, j)]);
        let s = &h * &full * h.transpose() + &r_dense;
        let gain = &full * h.transpose() * s.clone().try_inverse().unwrap();
        let a = nalgebra::DMatrix::<f64>::identity(6, 6) - &gain * &h;
        let expected = &a * &full * a.transpose() + &gain * &r_dense * gain.transpose();
        let y_dense = nalgebra::DVector::from_column_slice(y.as_slice());
        let moved = &gain * &y_dense;
        // the filter's way: the state's gains, its Joseph update, the levels'
        let chol = (p.qq + r).cholesky().unwrap();
        let k_q = chol.solve(&p.qq).transpose();
        let k_v = chol.solve(&p.qv).transpose();
        levels.update(&p, (&k_q, &k_v), &r, |x| chol.solve(x), &y);
        let updated = p.joseph_position_update(&k_q, &k_v, &r);
        agrees(&expected, (&updated, &levels), 1e-12);
        for i in 0..2 {
            assert!((levels.mean[i] - moved[4 + i]).abs() <= 1e-13, "{i}");
        }
    }
}
