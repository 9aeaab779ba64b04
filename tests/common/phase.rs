//! What the reference plant's step hides from an estimator: a Bayes
//! estimate of Example 1's velocity by an oracle that knows the plant's
//! state at the last sample before each impact, and the plant itself
//! (Moreau–Jean at `τ = 1e-5`), but not where the plant's step grid falls
//! against the impact.
//!
//! The plant resolves an impact at the end of the step that contains it,
//! so its velocity after an impact on the curved floor depends on the
//! phase of its grid against the contact (`the_plants_impacts_are_exact_impacts_delayed`).
//! A real system has no grid, and an estimator cannot know it: for the
//! estimator the phase is uniform over a step, anew at every impact.
//!
//! The oracle's family: from the plant's state at the last sample `t_s`
//! before an interval with an impulse, moved along the free flight by
//! `u ∈ [0, τ)` (by `u − τ` when the impulse comes within two steps of
//! `t_s`), the plant run at its own step until the first sample after,
//! then flown freely (the plant's free flight at `θ = ½` is the exact
//! parabola) to every later sample of the segment, up to the next
//! interval with an impulse. Phase `u = 0` is the plant itself, so the
//! family holds the truth; the phases are a circle (`u = τ` is `u = 0`
//! one step on), so the truth is not at an edge of the prior. The
//! estimate at a sample is the posterior mean of the phases' velocities,
//! each weighed by the likelihood of the noisy samples since the impact.
//!
//! The oracle knows more than any estimator can (the exact state before
//! each impact); where it meets a target, the step's phase alone does not
//! rule the target out. Samples where the plant slides (a gap under 1e-7
//! m with a normal speed under 1e-4 m/s), and those before the first
//! impulse, it is given for free (error 0), and the rest of a segment
//! after the plant starts to slide is not scored as flight.

use moreau::{
    Blocks, KalmanParams, Model, MoreauJean, Observer, ObserverError, SaltationKalman, State,
    StepParams,
};
use moreau_models::Parabola;

use super::exact::flow;
use nalgebra::{Matrix2, SVector, Vector2};

/// The plant's step and the samples' period (1 kHz: every 100th step).
pub const TAU: f64 = 1e-5;
const EVERY: usize = 100;

/// A run of the plant with, for each sample, whether a step of the
/// interval that ends at it gave any impulse (and the end of the first
/// such step). Not [`super::runs::reference`]: that records impacts
/// approached faster than 1 cm/s, and the oracle's segments must end at
/// every impulse, the slow bounces and resting contacts included.
pub struct StepRun {
    pub samples: Vec<State<f64, 2>>,
    pub impulse: Vec<Option<f64>>,
}

/// Example 1 from `start` for `t_end`, at `τ = 1e-5`, sampled at 1 kHz.
pub fn plant(start: (Vector2<f64>, Vector2<f64>), t_end: f64) -> StepRun {
    let model = Parabola::<f64>::new();
    let stepper = MoreauJean::new(StepParams::new(TAU)).unwrap();
    let mut state = State::new(0.0, start.0, start.1);
    let (mut samples, mut impulse) = (vec![state], vec![None]);
    let mut first = None;
    for k in 1..=(t_end / TAU).round() as usize {
        let report = stepper.step(&model, &mut state, &SVector::zeros()).unwrap();
        if first.is_none() && report.impulses.iter().any(|&p| p > 0.0) {
            first = Some(state.t);
        }
        if k % EVERY == 0 {
            samples.push(state);
            impulse.push(first.take());
        }
    }
    StepRun { samples, impulse }
}

fn sliding(model: &Parabola<f64>, s: &State<f64, 2>) -> bool {
    let (h, jac) = (model.gaps(&s.q), model.gap_jacobian(&s.q));
    (0..2).any(|i| h[i] < 1e-7 && jac.row(i).dot(&s.v.transpose()).abs() < 1e-4)
}

/// The oracle's errors `|v̂ − v|` at every sample, which samples it scored
/// in flight after an impulse, and how far phase `u = 0` came from the
/// plant's positions (the family's check: it holds the truth).
pub struct Oracle {
    pub errors: Vec<f64>,
    pub flight: Vec<bool>,
    pub phase_zero_off: f64,
}

/// The oracle on `run`'s samples `measured` (noise `sigma` per
/// coordinate), with `phases` phases evenly spread over a step.
pub fn oracle(run: &StepRun, measured: &[Vector2<f64>], sigma: f64, phases: usize) -> Oracle {
    let model = Parabola::<f64>::new();
    let stepper = MoreauJean::new(StepParams::new(TAU)).unwrap();
    let n = run.samples.len();
    let slide: Vec<bool> = run.samples.iter().map(|s| sliding(&model, s)).collect();
    let mut out = Oracle {
        errors: vec![0.0; n],
        flight: vec![false; n],
        phase_zero_off: 0.0,
    };
    let mut j = 1;
    while j < n {
        let Some(t_impulse) = run.impulse[j] else {
            j += 1;
            continue;
        };
        let start = run.samples[j - 1];
        // the segment: samples j..=end, up to the next interval with an impulse
        let mut end = j;
        while end + 1 < n && run.impulse[end + 1].is_none() {
            end += 1;
        }
        let back = t_impulse - start.t <= 2.0 * TAU;
        // each phase's state at each sample of the segment
        let mut at = vec![Vec::with_capacity(phases); end - j + 1];
        for m in 0..phases {
            let u = m as f64 * TAU / phases as f64 - if back { TAU } else { 0.0 };
            let (q, v) = flow(start.q, start.v, u);
            let mut state = State::new(0.0, q, v);
            let to = run.samples[j].t - start.t - u;
            let steps = ((to + 1e-12) / TAU).floor() as usize;
            for _ in 0..steps {
                stepper.step(&model, &mut state, &SVector::zeros()).unwrap();
            }
            let first = flow(state.q, state.v, to - steps as f64 * TAU);
            for (k, row) in at.iter_mut().enumerate() {
                let dt = run.samples[j + k].t - run.samples[j].t;
                row.push(flow(first.0, first.1, dt));
            }
        }
        let mut log_w = vec![0.0; phases];
        for (k, row) in at.iter().enumerate() {
            let s = &run.samples[j + k];
            if slide[j + k] {
                break;
            }
            if !back {
                out.phase_zero_off = out.phase_zero_off.max((row[0].0 - s.q).norm());
            }
            for (w, (q, _)) in log_w.iter_mut().zip(row) {
                *w -= (measured[j + k] - q).norm_squared() / (2.0 * sigma * sigma);
            }
            let top = log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let (mut total, mut mean) = (0.0, Vector2::zeros());
            for (w, (_, v)) in log_w.iter().zip(row) {
                let w = (w - top).exp();
                total += w;
                mean += v * w;
            }
            out.errors[j + k] = (mean / total - s.v).norm();
            out.flight[j + k] = true;
        }
        j = end + 1;
    }
    out
}

/// The filter with `params`, started afresh from the plant's exact state
/// (covariance `1e-16 I`) at the last sample before every interval with
/// an impulse, as the oracle is: its errors `|v̂ − v|` at every sample (0
/// before the first impulse).
pub fn restarted(
    run: &StepRun,
    measured: &[Vector2<f64>],
    params: KalmanParams<f64, 2>,
) -> Vec<f64> {
    let model = Parabola::<f64>::new();
    let tiny = Matrix2::identity() * 1e-16;
    let mut errors = vec![0.0; run.samples.len()];
    let mut filter: Option<SaltationKalman<f64, 2, 2>> = None;
    for j in 1..run.samples.len() {
        if run.impulse[j].is_some() {
            let s = &run.samples[j - 1];
            let p0 = Blocks::diagonal(tiny, tiny);
            filter = Some(SaltationKalman::with_covariance(params, s.t, s.q, s.v, p0).unwrap());
        }
        if let Some(f) = filter.as_mut() {
            // a sample the gate skips leaves the estimate where it was
            let v = match f.update(&model, run.samples[j].t, &measured[j], &SVector::zeros()) {
                Ok(e) => e.v,
                Err(ObserverError::Outlier { .. }) => f.estimate().v,
                Err(e) => panic!("t = {}: {e:?}", run.samples[j].t),
            };
            errors[j] = (v - run.samples[j].v).norm();
        }
    }
    errors
}
