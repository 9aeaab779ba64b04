//! The reduced-order observer (38) under measurement noise: Gaussian
//! noise of standard deviation `σ = 1e-4` m on each measured coordinate at
//! 1 kHz, the observer told `σ` (`ObserverParams::with_noise`), on plant
//! runs at τ = 1e-5 (`tests/common/runs.rs`), `v̂(0) = 0`, scored over
//! `t ∈ [2, 10]` s.
//!
//! Run with `cargo test --release --test noise -- --nocapture` to see every
//! figure.

use moreau::{Estimate, Model, Observer, ObserverParams, ReducedOrder};
mod common;

use common::runs::{
    Reference, Scored, brackets, errors, example_1_runs, example_1_starts, first_at_or_after,
    measure, reference, score,
};
use moreau_models::{DoublePendulum, Parabola, ThreeBalls};
use nalgebra::{SMatrix, SVector};

/// (38) with `l_d = 10`, `C_v = 20`, told `σ`, from the first measurement
/// and `v̂(0) = 0`; returns the estimates, the initial one first.
fn run<M, const N: usize, const K: usize>(
    model: &M,
    data: &Reference<N>,
    measured: &[SVector<f64, N>],
    sigma: f64,
) -> Vec<Estimate<f64, N>>
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, 0>>,
{
    let u = SVector::zeros();
    let params = ObserverParams::new(10.0, 20.0).with_noise(sigma);
    let mut o = ReducedOrder::<f64, N, K>::new(params, 0.0, measured[0], SVector::zeros()).unwrap();
    let mut out = vec![o.estimate()];
    for (s, q) in data.samples.iter().zip(measured).skip(1) {
        out.push(o.update(model, s.t, q, &u).unwrap());
    }
    out
}

fn show(name: &str, s: &Scored) {
    eprintln!(
        "{name}: median {:.2e} p90 {:.2e} max {:.2e}, without the bracketing samples max {:.2e}; samples to |ṽ| < 1e-2 after each impact: worst {} of {:?}",
        s.all.median,
        s.all.p90,
        s.all.max,
        s.clean.max,
        s.recover.iter().max().unwrap_or(&0),
        s.recover
    );
}

/// `√2 l_d σ`: the scale of the noise the injection passes (see
/// `noise_sets_the_error_level` in `tests/observer.rs`).
const NOISE_SCALE: f64 = std::f64::consts::SQRT_2 * 10.0 * 1e-4;

/// Runs one model on the seeds and checks every run's figures: median at
/// most `median` × √2 l_d σ, 90th percentile at most `p90` ×, and without
/// the samples bracketing a plant impact a maximum of at most `clean`.
/// Prints every run first, then asserts.
fn check<M, const N: usize, const K: usize>(
    name: &str,
    model: &M,
    start: (SVector<f64, N>, SVector<f64, N>),
    seeds: &[u64],
    (median, p90, clean): (f64, f64, f64),
) where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, 0>> + std::fmt::Debug + 'static,
{
    let sigma = 1e-4;
    let data = reference(model, start, 1e-5, 100, 10.0, &SVector::zeros());
    let mut failed = Vec::new();
    for &seed in seeds {
        let measured = measure(&data, sigma, seed);
        let est = run::<_, N, K>(model, &data, &measured, sigma);
        let s = score(&data, &est, (2.0, 10.0 + 1e-3));
        show(&format!("{name}, seed {seed}"), &s);
        if s.all.median > median * NOISE_SCALE
            || s.all.p90 > p90 * NOISE_SCALE
            || s.clean.max > clean
        {
            failed.push((seed, s));
        }
    }
    assert!(failed.is_empty(), "{name}: {failed:?}");
}

/// Example 1 on four starts (the model file's, whose impacts accumulate
/// at 4.456 s before it slides, and three more), each with the noise seed
/// the observer was developed on (`11 + n`, as in `tests/kalman.rs`) and
/// two seeds it never saw (`7001 + n`, `9001 + n`).
///
/// Baseline, measured on main before the smoothed position (the observer
/// predicting from the raw `q_k`) on these twelve runs: median 1.21e-3 to
/// 1.95e-3 (0.86 to 1.38 × √2 l_d σ), 90th percentile 2.19e-3 to 4.23e-3
/// (1.55 to 2.99 ×), maximum 4.8e-3 to 3.8 m/s, and without the two
/// samples that bracket each plant impact 4.8e-3 to 0.40 m/s (worst per
/// start over the seeds: 0.40, 0.17, 0.0056, 0.31), with the error above
/// 1e-2 for up to 94 samples after an impact of the accumulation.
///
/// With the impacts confirmed by the sample after them and slow
/// separations no longer held as contacts (measured on these twelve runs):
/// median 1.23e-3 to 1.36e-3 (0.87 to 0.96 ×), 90th percentile 2.30e-3
/// to 2.89e-3 (1.63 to 2.04 ×), maximum 4.8e-3 to 1.03 m/s, and without
/// the bracketing samples 4.8e-3 to 0.098 m/s (worst per start 0.098,
/// 0.051, 0.0055, 0.054), with the error above 1e-2 for up to 47 samples
/// after an impact of the accumulation. Before these two changes (the
/// smoothed position alone): median 1.23e-3 to 1.90e-3, 90th percentile
/// 2.31e-3 to 3.59e-3, and without the bracketing samples up to 0.27 m/s
/// (above 0.1 on 5 runs of 12). Since held contacts start each piece
/// settled (`Interval::settled`): median 1.10e-3 to 1.25e-3 (0.78 to
/// 0.88 ×), 90th percentile 2.30e-3 to 2.61e-3 (1.63 to 1.85 ×), and
/// without the bracketing samples the same 4.8e-3 to 0.098 m/s (worst per
/// start 0.098, 0.050, 0.0055, 0.054). Since `q̄` is held within four of
/// its deviations of each sample instead of `n_σ σ` (`smoothed` in
/// `runtime/src/observer/reduced_order.rs`): median 1.10e-3 to 1.24e-3,
/// the rest as before.
///
/// Asserted on every run: median and 90th percentile within the baseline's
/// worst (`1.4` and `3` × √2 l_d σ), and without the bracketing samples a
/// maximum of at most `0.1` m/s, the target (the worst run, the
/// file's start with seed 11, is at 0.098: this is a bound met, not one
/// with room to spare).
#[test]
fn example_1_under_noise() {
    let model = Parabola::<f64>::new();
    for (n, start) in example_1_starts().into_iter().enumerate() {
        let seeds = [11, 7001, 9001].map(|s| s + n as u64);
        check::<_, 2, 2>(
            &format!("Example 1, start {n}"),
            &model,
            start,
            &seeds,
            (1.4, 3.0, 0.1),
        );
    }
}

/// The same on models the smoothing was not developed on, with seeds it
/// never saw: the three balls (a glued pair, simultaneous impacts) and the
/// double pendulum (configuration-dependent `M`, damping, a tip hitting a
/// wall and a floor).
///
/// Baseline on main (these seeds): three balls median 1.94e-3 to 1.98e-3,
/// 90th percentile 3.43e-3 to 3.51e-3, without the bracketing samples max
/// 5.3e-2; double pendulum median 2.30e-3 to 2.34e-3 (1.65 ×), 90th
/// percentile 3.90e-3 to 4.02e-3 (2.84 ×), without the bracketing samples
/// max 0.11 to 0.18. With the impacts confirmed by the sample after them
/// (measured): three balls unchanged (median 1.94e-3 to 1.98e-3, 90th
/// percentile 3.43e-3 to 3.52e-3, max 5.3e-2); double pendulum median
/// 1.32e-3 to 1.38e-3 (0.98 ×; 2.19e-3 to 2.24e-3 with the smoothed
/// position alone), 90th percentile 2.78e-3 to 2.87e-3 (2.03 ×; 3.73e-3
/// to 3.81e-3), without the bracketing samples max 2.6e-2. Asserted: median
/// and 90th percentile within `1.7` and `3` × √2 l_d σ, and without the
/// bracketing samples a maximum of at most `0.1` m/s.
#[test]
fn other_models_under_noise() {
    let balls = ThreeBalls::<f64>::new();
    let start = ThreeBalls::<f64>::initial_state();
    check::<_, 3, 4>("three balls", &balls, start, &[7001, 9001], (1.7, 3.0, 0.1));
    let pendulum = DoublePendulum::<f64>::new();
    let start = DoublePendulum::<f64>::initial_state();
    check::<_, 2, 2>(
        "double pendulum",
        &pendulum,
        start,
        &[7001, 9001],
        (1.7, 3.0, 0.1),
    );
}

/// How well the noise lets a sample time an impact: the bound `B` on the
/// velocity error an impact leaves at the sample after the two that
/// bracket it, when its instant is known only from noisy positions.
///
/// Gap `i` closes at `ḣ_i = J_i v` with the normal acceleration `ḧ_i =
/// J_i a + J̇_i v` (`a = −M⁻¹F`, the free motion; `J̇_i v` by a central
/// difference of `J` along `v`). A position known to `σ` along the normal
/// times the impact to `δ = σ |J_i| / |ḣ_i|`; Newton's law then restitutes
/// a normal velocity `(1 + e_i) ḧ_i δ` off, a velocity error of that over
/// `|J_i|` (unit mass along the normal): `B = (1 + e_i) |ḧ_i| σ / |ḣ_i|`.
fn timing_bound(model: &Parabola<f64>, state: &moreau::State<f64, 2>, i: usize, sigma: f64) -> f64 {
    let (q, v) = (state.q, state.v);
    let (mass, forces) = model.dynamics(state.t, &q, &v, &SVector::zeros());
    let a = -mass.try_inverse().expect("M invertible") * forces;
    let eps = 1e-6;
    let jac_rate: SMatrix<f64, 2, 2> =
        (model.gap_jacobian(&(q + v * eps)) - model.gap_jacobian(&(q - v * eps))) / (2.0 * eps);
    let row = model.gap_jacobian(&q).row(i).into_owned();
    let (hd, hdd) = (
        row.dot(&v.transpose()),
        row.dot(&a.transpose()) + jac_rate.row(i).dot(&v.transpose()),
    );
    (1.0 + model.restitution()[i]) * hdd.abs() * sigma / hd.abs()
}

/// An impact (38) placed from noisy samples is placed again by the sample
/// after it (`interval/retime.rs`), and one it missed is applied in the
/// next interval: at the sample after the two that bracket it, the error
/// is what the noise leaves undecided, and no more. Example 1, the four
/// starts (noise seed `11 + n`) and the 48 random starts of
/// `tests/kalman.rs` (seeds 555, 777, 999, 1234; noise seed `100 + n`),
/// every plant impact in `[2, 10]` s that the noise can place within one
/// sample (approached at `|ḣ|/|J| ≥ 2σ/τ_s`, 0.2 m/s; slower ones are
/// undecided for more than the bracketing samples, as the issue says) and
/// that comes to an estimate within 1e-2 of the truth (the errors (38)
/// carries through an accumulation decay at `l_d`, not at a sample), with
/// no other impact in the interval after it.
///
/// Asserted: at the first sample after the brackets, the error is at most
/// 1e-2 or at most `2 B` (two deviations of the instant, [`timing_bound`]).
/// Measured: 1111 such impacts; 10 leave more than 1e-2 there, at most
/// 0.87 `B` (0.012 m/s, `B` = 0.014, approached at 0.31 m/s along the
/// normal). On 24 more random starts (seeds 31 and 42; scratch run), 538
/// impacts, none above `2 B`. Beyond the test, the impacts approached
/// slower than 0.2 m/s (all 72 random starts and the four): 14 left more
/// than 1e-2 at that sample, 12 of them below `B` and two above it (1.4
/// and 4.7 `B`, approached at 0.047 and 0.050 m/s, where `σ/|v|` is two
/// sampling periods).
#[test]
fn an_impact_is_timed_as_well_as_the_noise_allows() {
    let model = Parabola::<f64>::new();
    let (sigma, period) = (1e-4, 1e-3);
    let runs = example_1_runs();
    let (mut checked, mut above, mut worst) = (0, 0, (0.0_f64, 0.0, 0.0, 0.0));
    let mut failed = Vec::new();
    for (name, start, seed) in runs {
        let data = reference(&model, start, 1e-5, 100, 10.0, &SVector::zeros());
        let measured = measure(&data, sigma, seed);
        let error = errors(&data, &run::<_, 2, 2>(&model, &data, &measured, sigma));
        let bracket = brackets(&data);
        for &(t, i, approach) in &data.impacts {
            let first = first_at_or_after(&data, t);
            let next = first + 1;
            if t < 2.0 || next >= error.len() || bracket[next] || error[first - 1] >= 1e-2 {
                continue;
            }
            let before = &data.samples[first - 1];
            let normal = model.gap_jacobian(&before.q).row(i).norm();
            if approach / normal < 2.0 * sigma / period {
                continue;
            }
            let bound = timing_bound(&model, before, i, sigma);
            checked += 1;
            if error[next] > 1e-2 {
                above += 1;
                let ratio = error[next] / bound;
                if ratio > worst.0 {
                    worst = (ratio, error[next], bound, approach / normal);
                }
                if error[next] > 2.0 * bound {
                    failed.push((name.clone(), t, error[next], bound));
                }
            }
        }
    }
    eprintln!(
        "{checked} impacts; {above} leave more than 1e-2 at the sample after the brackets, at most {:.2} B ({:.3} m/s, B = {:.3}, approached at {:.3} m/s)",
        worst.0, worst.1, worst.2, worst.3
    );
    assert!(checked > 1000, "{checked} impacts");
    assert!(failed.is_empty(), "{failed:?}");
}
