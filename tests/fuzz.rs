//! Fuzz suite (issue 9): random, extreme and non-finite inputs mixed into
//! valid streams for the plant stepper, both observers and the saltation
//! Kalman filter, on every shipped model. The filter runs twice: with its
//! defaults on the plant's exact samples, and told the plant (its step,
//! on its grid) on the samples with noise `σ = 1e-4`, where an impact's
//! likely steps are kept apart as a sum of Gaussians (the count of
//! updates that held more than one is printed). Asserted, for every input:
//!
//! - no panic (the test would fail), and no non-finite output: every `Ok`
//!   state or estimate is finite, every estimate within `C_v`;
//! - every refusal leaves the state bit-identical (plant state; observer
//!   estimate and report);
//! - recovery after every finite glitch within the documented number of
//!   samples, which is 0 for a glitch beyond the outlier bound (module docs
//!   of `runtime/src/observer/mod.rs`, "Bad samples, bad states, long
//!   gaps"): after each refused sample the observer goes on bit-identical
//!   to a twin that never saw it.
//!
//! Bounded for CI (a few seconds in release). For longer local runs:
//! `MOREAU_FUZZ_SEED=7 MOREAU_FUZZ_ITERATIONS=50 cargo test --release --test fuzz`
//! (iterations: plant episodes of 300 steps, and 250 samples of the
//! observer stream, per model; default 20, 0.4 s in release).

use moreau::{
    FullOrder, FullOrderGains, KalmanParams, Model, MoreauJean, Observer, ObserverError,
    ObserverParams, ReducedOrder, SaltationKalman, Sensitivities, State, StepParams, UpdateReport,
};
use moreau_models::{Arm3, Billiard, DoublePendulum, Parabola, ThreeBalls};
use nalgebra::SVector;

/// The reference plant's step; it keeps every tenth state (1 kHz).
const PLANT_STEP: f64 = 1e-4;

/// SplitMix64: a small, deterministic generator (no dependency).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
    /// Log-uniform in `[lo, hi]`, random sign.
    fn magnitude(&mut self, lo: f64, hi: f64) -> f64 {
        let x = (lo.ln() + (hi.ln() - lo.ln()) * self.unit()).exp();
        if self.chance(0.5) { x } else { -x }
    }
    /// A value no model can take: a NaN, an infinity, or (`finite`) an
    /// extreme finite number.
    fn extreme(&mut self, finite: bool) -> f64 {
        let pool = [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            -f64::MAX,
            1e300,
            -1e150,
            f64::MIN_POSITIVE,
            5e-324,
        ];
        let start = if finite { 3 } else { 0 };
        pool[start + self.below(pool.len() - start)]
    }
}

impl Rng {
    /// A NaN or an infinity.
    fn non_finite(&mut self) -> f64 {
        [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][self.below(3)]
    }
    /// Standard normal (Box–Muller).
    fn normal(&mut self) -> f64 {
        let u = 1.0 - self.unit();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * self.unit()).cos()
    }
}

fn setting(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

fn seed() -> u64 {
    setting("MOREAU_FUZZ_SEED", 0x5EED_2026)
}

fn iterations() -> usize {
    setting("MOREAU_FUZZ_ITERATIONS", 20) as usize
}

fn state_bits<const N: usize>(s: &State<f64, N>) -> Vec<u64> {
    std::iter::once(s.t)
        .chain(s.q.iter().copied())
        .chain(s.v.iter().copied())
        .map(f64::to_bits)
        .collect()
}

fn finite<const N: usize>(s: &State<f64, N>) -> bool {
    s.t.is_finite() && s.q.iter().chain(s.v.iter()).all(|x| x.is_finite())
}

/// A model with one parameter set to `value`.
fn with_parameter<M: Model<N, K, Scalar = f64> + Clone, const N: usize, const K: usize>(
    model: &M,
    index: usize,
    value: f64,
) -> M {
    let mut bad = model.clone();
    if let Some(p) = bad.parameter_mut(index) {
        *p = value;
    }
    bad
}

fn parameter_count<M: Model<N, K, Scalar = f64>, const N: usize, const K: usize>(m: &M) -> usize {
    (0..).take_while(|&i| m.parameter(i).is_some()).count()
}

/// The plant: episodes of valid steps from the model's initial state with
/// bad steps mixed in (non-finite or extreme state entries, inputs and
/// parameters, a time the scalar cannot advance); every refusal leaves the
/// state bit-identical, every success is finite, and the valid stream goes
/// on.
fn fuzz_plant<M, const N: usize, const K: usize, const NU: usize>(
    name: &str,
    model: &M,
    start: (SVector<f64, N>, SVector<f64, N>),
    rng: &mut Rng,
) -> (usize, usize)
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>> + Clone,
{
    let stepper = MoreauJean::new(StepParams::new(1e-3)).unwrap();
    let (mut refused, mut extreme_ok) = (0, 0);
    let params = parameter_count(model);
    for _ in 0..iterations() {
        let mut state = State::new(0.0, start.0, start.1);
        let u = SVector::<f64, NU>::zeros();
        for _ in 0..300 {
            if rng.chance(0.2) {
                // a bad or extreme step, tried on a copy
                let mut bad = state;
                let mut bad_u = u;
                let mut bad_model = model.clone();
                match rng.below(5) {
                    0 => {
                        let finite = rng.chance(0.5);
                        bad.q[rng.below(N)] = rng.extreme(finite);
                    }
                    1 => {
                        let finite = rng.chance(0.5);
                        bad.v[rng.below(N)] = rng.extreme(finite);
                    }
                    2 => bad.t = [f64::NAN, f64::INFINITY, 1e17, 1e300][rng.below(4)],
                    3 if NU > 0 => {
                        let x = rng.extreme(false);
                        bad_u[rng.below(NU)] = x;
                    }
                    _ if params > 0 => {
                        bad_model = with_parameter(model, rng.below(params), rng.extreme(false));
                    }
                    _ => bad.q[0] = f64::NAN,
                }
                let before = bad;
                match stepper.step(&bad_model, &mut bad, &bad_u) {
                    Err(e) => {
                        assert_eq!(state_bits(&bad), state_bits(&before), "{name}: {e}");
                        refused += 1;
                    }
                    Ok(_) => {
                        assert!(finite(&bad), "{name}: non-finite output {bad:?}");
                        extreme_ok += 1;
                    }
                }
            }
            // the valid stream goes on
            let before = state;
            if let Err(e) = stepper.step(model, &mut state, &u) {
                panic!("{name}: a valid step failed at {before:?}: {e}");
            }
            assert!(finite(&state), "{name}");
        }
    }
    (refused, extreme_ok)
}

/// One sampled reference run of the model (plant `τ = 1e-4`, 1 kHz
/// samples, `T` s): `(t, q)` and the largest speed.
fn reference<M, const N: usize, const K: usize, const NU: usize>(
    model: &M,
    start: (SVector<f64, N>, SVector<f64, N>),
    seconds: f64,
) -> (Vec<(f64, SVector<f64, N>)>, f64)
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>>,
{
    let stepper = MoreauJean::new(StepParams::new(PLANT_STEP)).unwrap();
    let mut state = State::new(0.0, start.0, start.1);
    let u = SVector::zeros();
    let (mut samples, mut speed) = (Vec::new(), 0.0_f64);
    let n = (seconds * 1e3).round() as usize;
    for _ in 0..n {
        for _ in 0..10 {
            stepper.step(model, &mut state, &u).unwrap();
            speed = speed.max(state.v.norm());
        }
        samples.push((state.t, state.q));
    }
    (samples, speed)
}

fn report_bits<const N: usize, const K: usize>(r: &UpdateReport<f64, N, K>) -> String {
    // every field, outliers excepted (a twin that never saw a refused
    // sample has not counted it)
    let r = UpdateReport { outliers: 0, ..*r };
    format!("{r:?}")
}

/// One observer against its twin on a stream with bad samples mixed in;
/// `each` sees the observer after every valid sample.
fn fuzz_observer<M, O, const N: usize, const K: usize, const NU: usize>(
    name: &str,
    model: &M,
    mut observer: O,
    samples: &[(f64, SVector<f64, N>)],
    velocity_bound: f64,
    rng: &mut Rng,
    mut each: impl FnMut(&O),
) -> [usize; 3]
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>> + Clone,
    O: Observer<M, N, K> + Clone,
{
    let mut twin = observer.clone();
    let u = SVector::<f64, NU>::zeros();
    let params = parameter_count(model);
    let [mut outliers, mut refused, mut extreme] = [0; 3];
    let mut offset = 0.0;
    for &(t, q) in samples {
        let t = t + offset;
        // bad samples before this valid one: each must be refused and
        // leave the observer as it was
        while rng.chance(0.15) {
            let before = (
                state_bits(&observer.estimate()),
                report_bits(observer.report()),
            );
            let last = observer.estimate().t;
            let (mut bt, mut bq, mut bu, mut bm) = (t, q, u, model.clone());
            let glitch = rng.below(6);
            match glitch {
                // a finite glitch of 1 m to 1e6 m, or an extreme finite
                // position: an outlier
                0 | 1 => {
                    for x in bq.iter_mut() {
                        *x += rng.magnitude(1.0, 1e6);
                    }
                    if glitch == 1 {
                        bq[rng.below(N)] = rng.extreme(true).copysign(1.0) * 1e-8 * f64::MAX;
                    }
                }
                2 => bq[rng.below(N)] = rng.non_finite(),
                3 => bt = [f64::NAN, f64::INFINITY, last, last - 1.0][rng.below(4)],
                4 if NU > 0 => bu[rng.below(NU)] = rng.non_finite(),
                _ if params > 0 => bm = with_parameter(model, rng.below(params), f64::NAN),
                _ => bq[0] = f64::NAN,
            }
            match observer.update(&bm, bt, &bq, &bu) {
                Ok(e) => panic!("{name}: bad sample {glitch} accepted: {e:?}"),
                Err(e) => {
                    if matches!(e, ObserverError::Outlier { .. }) {
                        outliers += 1;
                    } else {
                        refused += 1;
                    }
                }
            }
            let after = (
                state_bits(&observer.estimate()),
                report_bits(observer.report()),
            );
            assert_eq!(after, before, "{name}: a refused sample changed the state");
        }
        // a valid but extreme sample now and then, given to both: a long
        // gap (a restart) or a very short interval
        let t = if rng.chance(0.01) {
            extreme += 1;
            offset += 10.0;
            t + 10.0
        } else {
            t
        };
        let a = observer.update(model, t, &q, &u);
        let b = twin.update(model, t, &q, &u);
        match (&a, &b) {
            (Ok(a), Ok(b)) => {
                assert!(finite(a), "{name}: non-finite estimate {a:?}");
                assert!(
                    a.v.norm() <= velocity_bound * (1.0 + 1e-12),
                    "{name}: {a:?}"
                );
                // recovery in 0 samples: as if no bad sample had come
                assert_eq!(state_bits(a), state_bits(b), "{name} at t = {t}");
                assert_eq!(report_bits(observer.report()), report_bits(twin.report()));
                each(&observer);
            }
            _ => panic!("{name}: a valid sample at t = {t} gave {a:?} (twin {b:?})"),
        }
    }
    [outliers, refused, extreme]
}

fn fuzz_model<M, const N: usize, const K: usize, const NU: usize>(
    name: &str,
    model: M,
    start: (SVector<f64, N>, SVector<f64, N>),
    rng: &mut Rng,
) where
    M: Sensitivities<N, K, Scalar = f64, Input = SVector<f64, NU>> + Clone,
{
    let (refused, extreme_ok) = fuzz_plant::<_, N, K, NU>(name, &model, start, rng);
    let (samples, speed) = reference::<_, N, K, NU>(&model, start, 0.25 * iterations() as f64);
    let velocity_bound = 2.0 * speed + 1.0;
    let params = ObserverParams::new(10.0, velocity_bound);
    let (t0, q0) = (0.0, start.0);
    let v0 = SVector::<f64, N>::zeros();
    let reduced = ReducedOrder::<f64, N, K>::new(params, t0, q0, v0).unwrap();
    let gains = FullOrderGains::scalar(5.0, 25.0);
    let full = FullOrder::<f64, N, K>::new(params, gains, t0, q0, v0).unwrap();
    let r = fuzz_observer::<_, _, N, K, NU>(
        name,
        &model,
        reduced,
        &samples,
        velocity_bound,
        rng,
        |_| (),
    );
    let f =
        fuzz_observer::<_, _, N, K, NU>(name, &model, full, &samples, velocity_bound, rng, |_| ());
    let kalman =
        SaltationKalman::<f64, N, K>::new(KalmanParams::new(velocity_bound, 1e-4), t0, q0, v0)
            .unwrap();
    let k = fuzz_observer::<_, _, N, K, NU>(
        name,
        &model,
        kalman,
        &samples,
        velocity_bound,
        rng,
        |_| (),
    );
    // the filter told the plant (its step and grid: the samples are every
    // tenth state), on noisy samples: the path that keeps an impact's
    // likely steps apart (`plant_step_mixture`)
    let sigma = 1e-4;
    let noisy: Vec<_> = samples
        .iter()
        .map(|&(t, q)| (t, q + SVector::from_fn(|_, _| sigma * rng.normal())))
        .collect();
    let told = KalmanParams::new(velocity_bound, sigma).with_plant(StepParams::new(PLANT_STEP));
    let told = SaltationKalman::<f64, N, K>::new(told, t0, noisy[0].1, v0).unwrap();
    let mut kept = 0;
    let each =
        |f: &SaltationKalman<f64, N, K>| kept += usize::from(f.kalman_report().alternatives > 0);
    let p = fuzz_observer::<_, _, N, K, NU>(name, &model, told, &noisy, velocity_bound, rng, each);
    eprintln!(
        "{name}: plant {refused} refused, {extreme_ok} extreme accepted; {} samples, reduced {} outliers / {} refused / {} long gaps, full {} / {} / {}, Kalman {} / {} / {}, told the plant {} / {} / {} ({kept} updates with steps kept apart)",
        samples.len(),
        r[0],
        r[1],
        r[2],
        f[0],
        f[1],
        f[2],
        k[0],
        k[1],
        k[2],
        p[0],
        p[1],
        p[2],
    );
    assert!(r[0] > 0 && f[0] > 0 && k[0] > 0 && p[0] > 0 && refused > 0);
}

#[test]
fn fuzz_parabola() {
    let mut rng = Rng(seed() ^ (1 << 40));
    fuzz_model::<_, 2, 2, 0>(
        "Parabola",
        Parabola::<f64>::new(),
        Parabola::<f64>::initial_state(),
        &mut rng,
    );
}

#[test]
fn fuzz_three_balls() {
    let mut rng = Rng(seed() ^ (2 << 40));
    fuzz_model::<_, 3, 4, 0>(
        "ThreeBalls",
        ThreeBalls::<f64>::new(),
        ThreeBalls::<f64>::initial_state(),
        &mut rng,
    );
}

#[test]
fn fuzz_billiard() {
    let mut rng = Rng(seed() ^ (3 << 40));
    fuzz_model::<_, 2, 4, 0>(
        "Billiard",
        Billiard::<f64>::new(),
        Billiard::<f64>::initial_state(),
        &mut rng,
    );
}

#[test]
fn fuzz_double_pendulum() {
    let mut rng = Rng(seed() ^ (4 << 40));
    fuzz_model::<_, 2, 2, 0>(
        "DoublePendulum",
        DoublePendulum::<f64>::new(),
        DoublePendulum::<f64>::initial_state(),
        &mut rng,
    );
}

#[test]
fn fuzz_arm3() {
    let mut rng = Rng(seed() ^ (5 << 40));
    fuzz_model::<_, 3, 1, 3>(
        "Arm3",
        Arm3::<f64>::new(),
        Arm3::<f64>::initial_state(),
        &mut rng,
    );
}
