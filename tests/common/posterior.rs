//! What the samples of an Example 1 run can tell about its velocity at
//! all: the Gaussian posterior of the velocity under the reference
//! plant's own noise, and the quantiles of the error it allows.
//!
//! The plant (`MoreauJean` at `τ`) adds two things to the exact motion:
//! the measurement noise `σ` of its samples, and at each impact the phase
//! of its step grid against the contact, uniform over a step and unknown
//! to any estimator (`tests/common/phase.rs`). Its flight is exact and
//! its jumps follow the model's law through its step. The filter told the
//! plant (`KalmanParams::with_plant_step`) with no acceleration and no
//! contact noise is the extended Kalman recursion of exactly that noise;
//! run on the exact samples (told `σ`), it is linearised along the truth,
//! and its covariance `P_vv` at each sample is the posterior covariance
//! of the velocity given the noisy samples up to it, to first order and
//! with the uniform phase taken as Gaussian of the same variance (the
//! filter restarted from the plant's state before each impact does as
//! well as the exact posterior over the phase:
//! `what_the_plants_step_alone_hides`). The sliding plant's drift along
//! the curved floor, which the filter's contact noise stands for, is left
//! out, so the posterior claims at least as much as the samples hold.
//!
//! Given the data, the velocity is `N(m, P_vv)`; by Anderson's lemma no
//! estimate is within `r` of it with a higher probability than the mean
//! `m`, `F(r; P_vv) = P(|z| ≤ r)` for `z ~ N(0, P_vv)`. Averaged over a
//! run's samples, `F` is the largest fraction of them that any estimator
//! can expect to have within `r`, and the `r` at which that fraction is
//! one half (nine tenths) is the smallest median (90th percentile) it can
//! expect over the run. A given noise draw lands on either side of it.

use moreau::{KalmanParams, Observer, SaltationKalman};
use moreau_models::Parabola;
use nalgebra::{Matrix2, SVector, Vector2};
use std::sync::OnceLock;

use super::runs::{Reference, measure};

/// The posterior covariance of the velocity at each sample of `data` in
/// `[from, to)`, for samples with noise `sigma` of the plant at step
/// `tau` (module docs).
pub fn velocity_covariances(
    data: &Reference<2>,
    sigma: f64,
    tau: f64,
    (from, to): (f64, f64),
) -> Vec<Matrix2<f64>> {
    let mut params = KalmanParams::new(20.0, sigma)
        .with_plant_step(tau)
        .with_plant_step_mixture(false);
    params.accel_noise = SVector::zeros();
    params.contact_noise = 0.0;
    let exact = measure(data, 0.0, 0);
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let mut filter =
        SaltationKalman::<f64, 2, 2>::new(params, 0.0, exact[0], Vector2::zeros()).unwrap();
    let mut covariances = Vec::new();
    for (s, q) in data.samples.iter().zip(&exact).skip(1) {
        filter
            .update(&model, s.t, q, &u)
            .unwrap_or_else(|e| panic!("t = {}: {e:?}", s.t));
        if (from..to).contains(&s.t) {
            covariances.push(filter.covariance().vv);
        }
    }
    covariances
}

/// `P(|z| ≤ r)` for `z ~ N(0, p)`: with `p`'s eigenvalues `λ₁, λ₂`,
/// the mean over the direction `θ` of `1 − exp(−r²/(2(λ₁cos²θ +
/// λ₂sin²θ)))` (the radius of a standard normal pair is Rayleigh), by
/// the trapezoidal rule over a half turn at 64 points (the integrand is
/// smooth and periodic; on these runs' covariances the quantiles below
/// moved by under 0.1 % from 64 to 1024 points).
pub fn within(p: &Matrix2<f64>, r: f64) -> f64 {
    within_spread(spread(p), r)
}

/// The eigenvalues of `p`, held at zero from below: all [`within`] needs
/// of it, computed once per covariance by [`quantile`].
fn spread(p: &Matrix2<f64>) -> (f64, f64) {
    let eig = p.symmetric_eigenvalues();
    (eig[0].max(0.0), eig[1].max(0.0))
}

/// The trapezoidal rule's points over a half turn, for [`within`].
const POINTS: usize = 64;

/// `(cos²θ, sin²θ)` at each of the [`POINTS`] directions `θ`: the same for
/// every covariance and radius, so taken once rather than at each of the
/// bisection's evaluations (which spent most of their time in `sin_cos`).
fn directions() -> &'static [(f64, f64); POINTS] {
    static DIRECTIONS: OnceLock<[(f64, f64); POINTS]> = OnceLock::new();
    DIRECTIONS.get_or_init(|| {
        std::array::from_fn(|j| {
            let theta = std::f64::consts::PI * (j as f64 + 0.5) / POINTS as f64;
            (theta.cos().powi(2), theta.sin().powi(2))
        })
    })
}

/// [`within`] from the eigenvalues `(λ₁, λ₂)` ([`spread`]).
fn within_spread((l1, l2): (f64, f64), r: f64) -> f64 {
    let mut sum = 0.0;
    for &(cos2, sin2) in directions() {
        let s = l1 * cos2 + l2 * sin2;
        sum += if s > 0.0 {
            1.0 - (-r * r / (2.0 * s)).exp()
        } else {
            1.0
        };
    }
    sum / POINTS as f64
}

/// The fraction of samples an estimator can expect within `r` over a
/// run whose posterior covariances are `covariances`: the mean of
/// [`within`] (module docs).
pub fn coverage(covariances: &[Matrix2<f64>], r: f64) -> f64 {
    covariances.iter().map(|p| within(p, r)).sum::<f64>() / covariances.len() as f64
}

/// The radius `r` at which the fraction of samples an estimator can
/// expect within `r`, the mean of [`within`] over `covariances`, is
/// `fraction` (module docs), by bisection in `log r` over 1e-9 to 1 m/s.
pub fn quantile(covariances: &[Matrix2<f64>], fraction: f64) -> f64 {
    let spreads: Vec<_> = covariances.iter().map(spread).collect();
    let expected =
        |r: f64| spreads.iter().map(|&l| within_spread(l, r)).sum::<f64>() / spreads.len() as f64;
    let (mut lo, mut hi) = (1e-9_f64, 1.0_f64);
    for _ in 0..30 {
        let mid = (lo * hi).sqrt();
        if expected(mid) < fraction {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}
