//! Reference runs for the estimators' tests: a plant trajectory sampled
//! for an estimator, seeded Gaussian measurement noise, and the error
//! figures (`tests/observer.rs`, `tests/kalman.rs`).

use moreau::{
    Estimate, KalmanParams, Model, MoreauJean, Observer, ObserverError, State, StepParams,
};
use moreau_models::Parabola;
use nalgebra::{SVector, Vector2};
use std::any::Any;
use std::collections::HashMap;
use std::fmt::Debug;
use std::sync::{Arc, Mutex, OnceLock};

#[path = "gauss.rs"]
mod gauss;
pub use gauss::Gauss;

/// A plant trajectory sampled for an observer.
#[derive(Clone)]
pub struct Reference<const N: usize> {
    /// The plant state at each sample time `t_j = j τ_s`.
    pub samples: Vec<State<f64, N>>,
    /// Plant impacts: (time, constraint, normal approach speed) for every
    /// plant step whose LCP gave an impulse to a constraint approaching
    /// faster than `min_impact_speed` (slower ones are resting contact).
    pub impacts: Vec<(f64, usize, f64)>,
}

/// Runs the plant from `(q0, v0)` at step `tau` for `t_end` and keeps every
/// `every`-th state.
pub fn reference<M, const N: usize, const K: usize>(
    model: &M,
    start: (SVector<f64, N>, SVector<f64, N>),
    tau: f64,
    every: usize,
    t_end: f64,
    u: &M::Input,
) -> Reference<N>
where
    M: Model<N, K, Scalar = f64> + Debug + 'static,
{
    reference_with(model, start, StepParams::new(tau), every, t_end, u)
}

/// [`reference`] for a plant with other settings than the defaults
/// (Siconos's law, for one: [`StepParams::siconos`]).
///
/// A run of at most [`KEPT_SAMPLES`] samples is made once per test binary
/// and handed out again as a copy: the tests of one binary score their
/// estimators on many of the same runs (in `tests/kalman.rs`, 215 of 743
/// plant runs, a third of its 6.1e8 plant steps, were runs another test
/// had made; its tests took 60 s instead of 71 on two threads). A run is
/// a pure function of what the key holds, so the copy is the run, to the
/// bit: the four binaries that print their figures (`kalman`, `observer`,
/// `noise`, `robots`) printed the same lines, sorted, before and after.
pub fn reference_with<M, const N: usize, const K: usize>(
    model: &M,
    start: (SVector<f64, N>, SVector<f64, N>),
    params: StepParams<f64>,
    every: usize,
    t_end: f64,
    u: &M::Input,
) -> Reference<N>
where
    M: Model<N, K, Scalar = f64> + Debug + 'static,
{
    // the samples `plant_run` keeps: the start and every `every`-th step
    let samples = (t_end / params.tau).round() as usize / every + 1;
    if samples > KEPT_SAMPLES {
        return plant_run(model, start, params, every, t_end, u);
    }
    // everything the run depends on: the model's type and its values
    // (parameters included: `Debug` writes every field, each float to the
    // digits that give it back), the start, the settings, the sampling and
    // the input
    let key = format!(
        "{} {N} {K} {model:?} {:?} {:?} {params:?} {every} {t_end:?} {:?}",
        std::any::type_name::<M>(),
        start.0.as_slice(),
        start.1.as_slice(),
        u.as_ref()
    );
    let cell = {
        let mut runs = RUNS
            .get_or_init(Mutex::default)
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        Arc::clone(runs.entry(key).or_insert_with(|| {
            Arc::new(OnceLock::<Reference<N>>::new()) as Arc<dyn Any + Send + Sync>
        }))
    };
    // a test that asks for a run another is making waits for it
    let cell = cell
        .downcast_ref::<OnceLock<Reference<N>>>()
        .expect("the key names N, so the cell holds a Reference<N>");
    cell.get_or_init(|| plant_run(model, start, params, every, t_end, u))
        .clone()
}

/// The largest run [`reference_with`] keeps for the binary's other tests:
/// 20 s at 1 kHz. Longer records (the plant's every step, for one) are
/// made each time: kept too, the runs of `tests/kalman.rs` would hold
/// 477 MB, against 124 MB with this bound.
const KEPT_SAMPLES: usize = 20_001;

/// The runs made so far in this test binary, by [`reference_with`]'s key:
/// each a `OnceLock<Reference<N>>`.
type Runs = Mutex<HashMap<String, Arc<dyn Any + Send + Sync>>>;
static RUNS: OnceLock<Runs> = OnceLock::new();

/// The plant's run itself (see [`reference_with`]).
fn plant_run<M, const N: usize, const K: usize>(
    model: &M,
    (q0, v0): (SVector<f64, N>, SVector<f64, N>),
    params: StepParams<f64>,
    every: usize,
    t_end: f64,
    u: &M::Input,
) -> Reference<N>
where
    M: Model<N, K, Scalar = f64>,
{
    let min_impact_speed = 1e-2;
    assert!(
        model.gaps(&q0).iter().all(|&h| h >= 0.0),
        "infeasible start {q0}"
    );
    let tau = params.tau;
    let stepper = MoreauJean::new(params).unwrap();
    let mut state = State::new(0.0, q0, v0);
    let mut samples = vec![state];
    let mut impacts = Vec::new();
    let steps = (t_end / tau).round() as usize;
    for k in 1..=steps {
        let before = state;
        let report = stepper.step(model, &mut state, u).unwrap();
        let jac = model.gap_jacobian(&before.q);
        for i in report.impacting() {
            let approach = -jac.row(i).dot(&before.v.transpose());
            if approach > min_impact_speed {
                impacts.push((state.t, i, approach));
            }
        }
        if k % every == 0 {
            // the stepper keeps t on its grid kτ: no round-off to correct
            samples.push(state);
        }
    }
    Reference { samples, impacts }
}

/// The measured positions: the plant's, plus Gaussian noise of standard
/// deviation `sigma` on each coordinate (none for `sigma = 0`).
pub fn measure<const N: usize>(
    reference: &Reference<N>,
    sigma: f64,
    seed: u64,
) -> Vec<SVector<f64, N>> {
    let mut gauss = Gauss::new(seed);
    reference
        .samples
        .iter()
        .map(|s| s.q + SVector::from_fn(|_, _| sigma * gauss.normal()))
        .collect()
}

/// Every update of `estimator` over the run, the estimate held on a
/// sample it refuses as an outlier; counts its restarts
/// (`UpdateReport::restart`) and the refused samples, and hands the
/// estimator after each accepted update, with the sample's index, to
/// `each`. Any other error fails the test.
pub fn observe_counting<O, M, const N: usize, const K: usize>(
    estimator: &mut O,
    model: &M,
    (data, measured): (&Reference<N>, &[SVector<f64, N>]),
    u: &M::Input,
    mut each: impl FnMut(usize, &O),
) -> (Vec<Estimate<f64, N>>, usize, usize)
where
    O: Observer<M, N, K>,
    M: Model<N, K, Scalar = f64>,
{
    let mut estimates = vec![estimator.estimate()];
    let (mut restarts, mut refused) = (0, 0);
    for (j, (s, q)) in data.samples.iter().zip(measured).enumerate().skip(1) {
        match estimator.update(model, s.t, q, u) {
            Ok(e) => {
                restarts += usize::from(estimator.report().restart.is_some());
                estimates.push(e);
                each(j, estimator);
            }
            Err(ObserverError::Outlier { .. }) => {
                refused += 1;
                estimates.push(estimator.estimate());
            }
            Err(e) => panic!("{}, t = {}: {e:?}", M::INFO.name, s.t),
        }
    }
    (estimates, restarts, refused)
}

/// `|v − v̂|` at every sample.
pub fn errors<const N: usize>(
    reference: &Reference<N>,
    estimates: &[Estimate<f64, N>],
) -> Vec<f64> {
    reference
        .samples
        .iter()
        .zip(estimates)
        .map(|(s, e)| (s.v - e.v).norm())
        .collect()
}

/// Median, 90th percentile and maximum.
#[derive(Clone, Copy, Debug)]
pub struct Figures {
    pub median: f64,
    pub p90: f64,
    pub max: f64,
}

pub fn figures(errors: &[f64]) -> Figures {
    let mut sorted = errors.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    Figures {
        median: sorted[n / 2],
        p90: sorted[(n * 9) / 10],
        max: sorted[n - 1],
    }
}

/// The error figures of one run over `t ∈ [from, to)`: all samples, the
/// samples that do not bracket a plant impact (the last before it and the
/// first after it), and after each plant impact at `t ≥ from` the samples
/// until `|v − v̂| < 1e-2` (`usize::MAX` for never).
#[derive(Clone, Debug)]
pub struct Scored {
    pub all: Figures,
    pub clean: Figures,
    pub recover: Vec<usize>,
}

/// The first sample at or after time `t` (the number of samples if none).
pub fn first_at_or_after<const N: usize>(data: &Reference<N>, t: f64) -> usize {
    data.samples
        .iter()
        .position(|s| s.t >= t - 1e-12)
        .unwrap_or(data.samples.len())
}

/// The samples that bracket a plant impact: the last before it and the
/// first after it.
pub fn brackets<const N: usize>(data: &Reference<N>) -> Vec<bool> {
    let len = data.samples.len();
    let mut bracket = vec![false; len];
    for &(t, _, _) in &data.impacts {
        let first = first_at_or_after(data, t);
        if first < len {
            bracket[first] = true;
        }
        if first > 0 {
            bracket[first - 1] = true;
        }
    }
    bracket
}

/// Whether the sample `s` lies in the scoring window `[from, to)`.
fn in_window<const N: usize>(s: &State<f64, N>, (from, to): (f64, f64)) -> bool {
    s.t >= from - 1e-9 && s.t < to - 1e-9
}

/// `|v − v̂|` at the samples in the window `[from, to)`, as [`score`]
/// scores them.
pub fn errors_in_window<const N: usize>(
    data: &Reference<N>,
    estimates: &[Estimate<f64, N>],
    window: (f64, f64),
) -> Vec<f64> {
    data.samples
        .iter()
        .zip(errors(data, estimates))
        .filter(|(s, _)| in_window(s, window))
        .map(|(_, e)| e)
        .collect()
}

pub fn score<const N: usize>(
    data: &Reference<N>,
    estimates: &[Estimate<f64, N>],
    (from, to): (f64, f64),
) -> Scored {
    let errors = errors(data, estimates);
    let bracket = brackets(data);
    let mut recover = Vec::new();
    for &(t, _, _) in &data.impacts {
        let first = first_at_or_after(data, t);
        if t >= from {
            let back = (first..errors.len())
                .find(|&j| errors[j] < 1e-2)
                .map_or(usize::MAX, |j| j - first);
            recover.push(back);
        }
    }
    let pick = |skip_brackets: bool| -> Vec<f64> {
        data.samples
            .iter()
            .zip(&errors)
            .zip(&bracket)
            .filter(|((s, _), b)| in_window(s, (from, to)) && !(skip_brackets && **b))
            .map(|((_, &e), _)| e)
            .collect()
    };
    Scored {
        all: figures(&pick(false)),
        clean: figures(&pick(true)),
        recover,
    }
}

/// Example 1 from the model file's initial state to `t_end`: the plant at
/// `τ = 1e-5`, sampled every 1 ms.
pub fn example_1_run(t_end: f64) -> Reference<2> {
    reference(
        &Parabola::<f64>::new(),
        Parabola::<f64>::initial_state(),
        1e-5,
        100,
        t_end,
        &SVector::zeros(),
    )
}

/// Example 1's initial states: the model file's (impacts accumulate at
/// 4.456 s and the mass slides on), and three more.
pub fn example_1_starts() -> Vec<(SVector<f64, 2>, SVector<f64, 2>)> {
    vec![
        Parabola::<f64>::initial_state(),
        (Vector2::new(-1.0, 3.0), Vector2::new(-2.0, 5.0)),
        (Vector2::new(0.5, 6.0), Vector2::new(4.0, 0.0)),
        (Vector2::new(0.2, 1.0), Vector2::new(1.0, -2.0)),
    ]
}

/// `count` Example 1 initial states drawn with the seed `seed`, none
/// picked: `x` uniform in [−1, 1], `y` uniform between 0.5 and 6.5 above
/// the floor `y = x²` (at most 7.9, below the ceiling at 8), `v_x`
/// uniform in [−4, 4] and `v_y` in [−5, 5] m/s.
pub fn random_example_1_starts(seed: u64, count: usize) -> Vec<(SVector<f64, 2>, SVector<f64, 2>)> {
    let mut g = Gauss::new(seed);
    (0..count)
        .map(|_| {
            let x = 2.0 * g.uniform() - 1.0;
            let y = (x * x + 0.5 + 6.0 * g.uniform()).min(7.9);
            let v = Vector2::new(8.0 * g.uniform() - 4.0, 10.0 * g.uniform() - 5.0);
            (Vector2::new(x, y), v)
        })
        .collect()
}

/// An initial state `(q0, v0)` of a two-coordinate model.
pub type Start2 = (SVector<f64, 2>, SVector<f64, 2>);

/// The 52 Example 1 runs the tests score the numbers on, each
/// with its name and its noise seed: the four of [`example_1_starts`]
/// (noise seeds 11 to 14), then twelve [`random_example_1_starts`] of
/// each of the seeds 555, 777, 999 and 1234 (noise seeds `100 + n`).
pub fn example_1_runs() -> Vec<(String, Start2, u64)> {
    let mut runs: Vec<_> = example_1_starts()
        .into_iter()
        .enumerate()
        .map(|(n, start)| (format!("start {n}"), start, 11 + n as u64))
        .collect();
    for seed in [555, 777, 999, 1234] {
        for (n, start) in random_example_1_starts(seed, 12).into_iter().enumerate() {
            runs.push((format!("seed {seed}, start {n}"), start, 100 + n as u64));
        }
    }
    runs
}

/// The plants a record may have come from, for `pick_by_likelihood`: no
/// plant (`base`, a rigid model right about the machine), the crate's law
/// at 5, 10 and 20 µs on the samples' grid, and 10 µs off it; with
/// their names.
pub fn plant_candidates<const N: usize>(
    base: KalmanParams<f64, N>,
) -> [(&'static str, KalmanParams<f64, N>); 5] {
    [
        ("no plant", base),
        ("5 µs", base.with_plant_step(5e-6)),
        ("10 µs", base.with_plant_step(1e-5)),
        (
            "10 µs off the grid",
            base.with_plant_step(1e-5).with_plant_grid(false),
        ),
        ("20 µs", base.with_plant_step(2e-5)),
    ]
}
