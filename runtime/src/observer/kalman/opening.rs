//! A held contact that the samples show opening, by a little at each
//! sample: the case they build against it below the gate.
//!
//! The contact rule holds a closed constraint whose normal speed is within
//! the noise, and the projection onto its manifold leaves no variance
//! across it (module `propagate`). Where a force presses the contact on,
//! that is what the rigid model says. Where none does (bodies that an
//! accumulation of impacts left touching in free flight), it is the
//! likeliest reading of samples that cannot yet tell resting from leaving
//! slowly, and the plant may be leaving. Three balls on a line with
//! restitution 0.3 end an inelastic collapse against a wall with the
//! plant's balls drifting apart at 1e-4 to 4e-4 m/s, and the filter's
//! glued (start 11 of `tests/kalman.rs`,
//! `balls_left_touching_by_a_collapse_part_as_the_samples_show`). No
//! sample could move the estimate off the contacts, and none is past the
//! gate: 2.5 s later the wall contact, held, was 2.6 deviations open in
//! every sample, the balls beside it were 0.07 m/s off, and the velocity
//! NEES was 1e5.
//!
//! So each held contact `i` keeps a one-sided cumulative sum (Page's
//! CUSUM) of its samples' standardised gaps above the level it is held at,
//! `z = (h_i(q) − ℓ_i) / √(J_i R J_iᵀ + |J_i|² f)` (`f` the floor under
//! `R`, so that exact samples are read to their rounding), each held to
//! the gate's deviations `√gate` so that no glitch builds the case alone:
//! `s ← max(0, s + z − κ)`, `κ = 1/2`. Where `s` passes `H = 16` the
//! samples have shown the contact open: a contact that sits at its level
//! gives `z` a mean of zero, and the sum then passes `H` about once in
//! 5e7 samples (Siegmund's approximation of the run length, `(e^{2κb} −
//! 2κb − 1)/(2κ²)`, `b = H + 1.166`: 16 hours at 1 kHz), while a gap held
//! one deviation open passes it in about 34 samples. The contact is then
//! released as the gate's release does one (module docs, step 2): its
//! normal position and speed are made uncertain again, by the gap the run
//! shows (twice the run's mean, at least what a gap opening at a steady
//! speed since the run began reaches now; a single sample's gap is as
//! noisy as the measurement) and by that gap over the time the contact
//! has been held (a run is as short as the noise that ends it early
//! makes it: the gap over the run alone gave 25 times the plant's speed
//! in the unit test below) ([`KalmanReport::released`](super::KalmanReport::released)).
//! The sum starts again from zero, and so does that of a contact not held.

use nalgebra::{RealField, SMatrix, SVector};

use crate::lcp::IndexSet;

/// The drift `κ` the sum takes off each standardised gap (module docs).
const DRIFT: f64 = 0.5;

/// The sum `H` past which the samples have shown a held contact open.
const THRESHOLD: f64 = 16.0;

/// Each held contact's cumulative sum, and when its run began (module
/// docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Openings<T: RealField + Copy, const K: usize> {
    /// `s_i`: `0` for a contact not held.
    sum: SVector<T, K>,
    /// The samples in the run that `s_i` has summed since it was last `0`.
    count: SVector<T, K>,
    /// The first sample at which each contact of `held` was held.
    since: SVector<T, K>,
    /// The contacts held at the last sample weighed.
    held: IndexSet<K>,
}

/// The contacts the samples have shown open (the set), each with the gap
/// the run shows and the time it has been held.
pub(crate) type Opened<T, const K: usize> = (IndexSet<K>, SVector<T, K>, SVector<T, K>);

impl<T: RealField + Copy, const K: usize> Openings<T, K> {
    /// No case against any contact.
    pub fn none() -> Self {
        Self {
            sum: SVector::zeros(),
            count: SVector::zeros(),
            since: SVector::zeros(),
            held: IndexSet::EMPTY,
        }
    }

    /// Whether no contact was held at the last sample weighed (none has
    /// a case against it).
    pub fn is_none(&self) -> bool {
        self.held.is_empty()
    }

    /// Weighs the sample at time `t`, for the contacts `held` at the
    /// predicted end at `levels`: the sample's gaps `h(q)`, its Jacobian
    /// `J(q)`, the measurement covariance `R` with the floor `f` under it,
    /// and the gate's deviations `√gate`. Returns the contacts it shows
    /// open ([`Opened`]), whose sums start again.
    ///
    /// A contact's time held counts from the first sample it was held at,
    /// not from its last impact: inside an accumulation each impact on a
    /// held contact would start it again, and a released speed of the run's
    /// gap over a few milliseconds took the scratch sweep's `ThreeBallsE3`
    /// start 4 from 1.4e-4 to 4.2e-2 m/s off the brackets.
    pub fn weigh<const N: usize>(
        &mut self,
        (t, held, levels): (T, IndexSet<K>, &SVector<T, K>),
        (h, jac): (&SVector<T, K>, &SMatrix<T, K, N>),
        (measurement, floor, deviations): (&SMatrix<T, N, N>, T, T),
    ) -> Opened<T, K> {
        let drift: T = nalgebra::convert(DRIFT);
        let threshold: T = nalgebra::convert(THRESHOLD);
        let mut opened = (IndexSet::EMPTY, SVector::zeros(), SVector::zeros());
        for i in 0..K {
            if !held.contains(i) {
                (self.sum[i], self.count[i]) = (T::zero(), T::zero());
                continue;
            }
            if !self.held.contains(i) {
                self.since[i] = t;
            }
            let row = jac.row(i);
            let variance = (row * measurement).dot(&row) + row.norm_squared() * floor;
            let gap = h[i] - levels[i];
            if variance <= T::zero() || !variance.is_finite() || !gap.is_finite() {
                continue;
            }
            let deviation = variance.sqrt();
            let z = (gap / deviation).min(deviations);
            let sum = self.sum[i] + z - drift;
            if sum <= T::zero() {
                (self.sum[i], self.count[i]) = (T::zero(), T::zero());
                continue;
            }
            self.sum[i] = sum;
            self.count[i] += T::one();
            if sum > threshold {
                // the run's mean standardised gap: Σ z = s + κ n
                let mean = (sum + drift * self.count[i]) / self.count[i];
                let two: T = nalgebra::convert(2.0);
                opened.0.insert(i);
                opened.1[i] = two * mean * deviation;
                opened.2[i] = t - self.since[i];
                (self.sum[i], self.count[i]) = (T::zero(), T::zero());
            }
        }
        self.held = held;
        opened
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix1, Vector1};

    /// A contact held at its level: samples of pure noise about it do not
    /// build a case in 100 000 samples; a gap opening at a steady speed
    /// does, within the samples the sum's drift and threshold allow.
    #[test]
    fn a_contact_opening_slowly_is_shown_open_and_one_at_rest_is_not() {
        let sigma = 1e-4;
        let r = Matrix1::new(sigma * sigma);
        let jac = Matrix1::new(1.0);
        let held = IndexSet::<1>::full(1);
        let level = Vector1::zeros();
        // a uniform generator of fixed seed, summed to a near-Gaussian
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut gauss = || {
            let mut s = 0.0;
            for _ in 0..12 {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                s += (state >> 11) as f64 / (1u64 << 53) as f64;
            }
            s - 6.0
        };
        let mut at_rest = Openings::<f64, 1>::none();
        for k in 0..100_000 {
            let h = Vector1::new(sigma * gauss());
            let opened = at_rest.weigh((k as f64 * 1e-3, held, &level), (&h, &jac), (&r, 0.0, 4.7));
            assert!(opened.0.is_empty(), "sample {k}");
        }
        // 2e-4 m/s from t = 0: the gap reaches κ σ at 0.25 s, about
        // where the sum passes H with the noise's help (measured: 0.251 s)
        let mut opening = Openings::<f64, 1>::none();
        let speed = 2e-4;
        let found = (1..1000).find_map(|k| {
            let t = k as f64 * 1e-3;
            let h = Vector1::new(speed * t + sigma * gauss());
            let opened = opening.weigh((t, held, &level), (&h, &jac), (&r, 0.0, 4.7));
            (!opened.0.is_empty()).then_some((t, opened.1[0], opened.2[0]))
        });
        let (t, gap, span) = found.expect("shown open within a second");
        eprintln!(
            "shown open at {t} s, gap {gap:e} (plant {:e}), run {span} s",
            speed * t
        );
        assert!((0.15..0.6).contains(&t), "{t}");
        // the gap it reports is at least the plant's, within the
        // selection of a run that noise helped end early; held from the
        // first sample, 1 ms
        assert!(gap > speed * t && gap < 5.0 * speed * t, "{gap}");
        assert!((span - (t - 1e-3)).abs() < 1e-12, "{span}");
        // a contact no longer held starts again
        let h = Vector1::new(1.0);
        let opened = opening.weigh((1.0, IndexSet::EMPTY, &level), (&h, &jac), (&r, 0.0, 4.7));
        assert!(opened.0.is_empty());
        assert!(opening.is_none());
    }
}
