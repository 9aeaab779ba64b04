//! One update of the saltation Kalman filter beside one update of the
//! reduced-order observer (38), of the full-order observer (36) and of a
//! backward finite difference of the samples (the estimators of the noise
//! sweep's table), in one run, on Example 1 sampled at 1 kHz
//! with σ = 1e-4: in free flight, with an impact inside the interval, and
//! sliding; and, where the filter told the plant's step keeps the steps an
//! impact may have been taken into apart (`KalmanParams::plant_step_mixture`),
//! the impact that splits and the next interval without an impact that
//! carries them. The filter runs with its defaults, told the plant's step
//! (`KalmanParams::with_plant_step`, which takes one step of the plant
//! at each impact), and told Siconos's law (`KalmanParams::with_plant`
//! with `StepParams::siconos`, which also takes two plant steps on each
//! piece of a slide, its law's drag there). Each estimator is first run over the record up to the
//! interval, so it starts from its own converged state; the copy of it
//! that each timed update starts from is made outside the timed region.
//!
//! `cargo bench -p moreau-bench --bench kalman`

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use moreau::{
    FullOrder, FullOrderGains, KalmanParams, MoreauJean, Observer, ObserverParams, ReducedOrder,
    SaltationKalman, State, StepParams,
};
use moreau_models::Parabola;
use nalgebra::{SVector, Vector2};
use std::hint::black_box;

/// Example 1 from the model file's state: samples every 1 ms of the plant
/// at τ = 1e-5 with a deterministic noise of about 1e-4, and the number of
/// plant impacts in each interval.
fn record() -> Vec<(f64, Vector2<f64>, usize)> {
    let model = Parabola::<f64>::default();
    let (q0, v0) = Parabola::<f64>::initial_state();
    let stepper = MoreauJean::new(StepParams::new(1e-5)).unwrap();
    let mut state = State::new(0.0, q0, v0);
    let u = SVector::zeros();
    let mut out = vec![(0.0, q0, 0)];
    let mut impacts = 0;
    let mut x = 0.5_f64;
    for k in 1..=800_000 {
        let report = stepper.step(&model, &mut state, &u).unwrap();
        impacts += report.impacts().count();
        if k % 100 == 0 {
            let mut noise = || {
                x = (x * 7.31 + 0.13).fract();
                (x - 0.5) * 3.4e-4
            };
            let q = state.q + Vector2::new(noise(), noise());
            out.push((k as f64 * 1e-5, q, impacts));
            impacts = 0;
        }
    }
    out
}

fn updates(c: &mut Criterion) {
    let model = Parabola::<f64>::default();
    let u = SVector::zeros();
    let data = record();
    // the intervals: free flight at 0.5 s, the first impact inside an
    // interval after 0.1 s, sliding at 6 s
    let free = 500;
    let impact = (100..data.len()).find(|&k| data[k].2 > 0).unwrap();
    let sliding = 6000;
    let (split, kept) = kept_apart(&data);
    let mut group = c.benchmark_group("kalman/parabola");
    for (label, k) in [
        ("free flight", free),
        ("impact", impact),
        ("impact, steps kept apart", split),
        ("free flight, steps kept apart", kept),
        ("sliding", sliding),
    ] {
        let kalman_params = KalmanParams::new(20.0, 1e-4);
        let mut kalman =
            SaltationKalman::<f64, 2, 2>::new(kalman_params, 0.0, data[0].1, Vector2::zeros())
                .unwrap();
        let mut stepped = SaltationKalman::<f64, 2, 2>::new(
            kalman_params.with_plant_step(1e-5),
            0.0,
            data[0].1,
            Vector2::zeros(),
        )
        .unwrap();
        let mut siconos = SaltationKalman::<f64, 2, 2>::new(
            kalman_params.with_plant(StepParams::siconos(1e-5)),
            0.0,
            data[0].1,
            Vector2::zeros(),
        )
        .unwrap();
        let observer_params = ObserverParams::new(10.0, 20.0).with_noise(1e-4);
        let mut reduced =
            ReducedOrder::<f64, 2, 2>::new(observer_params, 0.0, data[0].1, Vector2::zeros())
                .unwrap();
        let gains = FullOrderGains::scalar(5.0, 25.0);
        let mut full =
            FullOrder::<f64, 2, 2>::new(observer_params, gains, 0.0, data[0].1, Vector2::zeros())
                .unwrap();
        for (t, q, _) in &data[1..k] {
            kalman.update(&model, *t, q, &u).unwrap();
            stepped.update(&model, *t, q, &u).unwrap();
            siconos.update(&model, *t, q, &u).unwrap();
            reduced.update(&model, *t, q, &u).unwrap();
            full.update(&model, *t, q, &u).unwrap();
        }
        let previous = Difference {
            t: data[k - 1].0,
            q: data[k - 1].1,
        };
        let (t, q, _) = data[k];
        // what the interval holds for each, checked before timing
        let mut probe = kalman;
        probe.update(&model, t, &q, &u).unwrap();
        let mut probe_38 = reduced;
        probe_38.update(&model, t, &q, &u).unwrap();
        let mut probe_stepped = stepped;
        probe_stepped.update(&model, t, &q, &u).unwrap();
        eprintln!(
            "{label} (interval ending at {t:.3} s): filter impacts {}, saltations {}, contacts {:?}; told the plant's step, steps kept apart before {} and after {}; (38) impacts {}, contacts {:?}",
            probe.report().impacts,
            probe.kalman_report().saltations,
            probe.report().contacts,
            stepped.kalman_report().alternatives,
            probe_stepped.kalman_report().alternatives,
            probe_38.report().impacts,
            probe_38.report().contacts
        );
        // the estimator as it was before the update is copied outside the
        // timed region: a user updates in place and never copies it
        group.bench_function(format!("saltation Kalman, {label}"), |b| {
            b.iter_batched_ref(
                || kalman,
                |f| f.update(&model, black_box(t), &q, &u).unwrap(),
                BatchSize::SmallInput,
            )
        });
        group.bench_function(
            format!("saltation Kalman told the plant's step, {label}"),
            |b| {
                b.iter_batched_ref(
                    || stepped,
                    |f| f.update(&model, black_box(t), &q, &u).unwrap(),
                    BatchSize::SmallInput,
                )
            },
        );
        group.bench_function(
            format!("saltation Kalman told Siconos's law, {label}"),
            |b| {
                b.iter_batched_ref(
                    || siconos,
                    |f| f.update(&model, black_box(t), &q, &u).unwrap(),
                    BatchSize::SmallInput,
                )
            },
        );
        group.bench_function(format!("reduced (38), {label}"), |b| {
            b.iter_batched_ref(
                || reduced,
                |o| o.update(&model, black_box(t), &q, &u).unwrap(),
                BatchSize::SmallInput,
            )
        });
        group.bench_function(format!("full (36), {label}"), |b| {
            b.iter_batched_ref(
                || full,
                |o| o.update(&model, black_box(t), &q, &u).unwrap(),
                BatchSize::SmallInput,
            )
        });
        group.bench_function(format!("finite difference, {label}"), |b| {
            b.iter_batched_ref(
                || previous,
                |d| d.update(black_box(t), &q),
                BatchSize::SmallInput,
            )
        });
    }
    group.finish();
}

/// The intervals after 0.1 s where the filter told the plant's step
/// first splits an impact into the steps it may have been taken into (an
/// impact inside, none kept apart before it, some after), and then first
/// carries them through an interval without an impact
/// (`KalmanParams::plant_step_mixture`).
fn kept_apart(data: &[(f64, Vector2<f64>, usize)]) -> (usize, usize) {
    let model = Parabola::<f64>::default();
    let u = SVector::zeros();
    let params = KalmanParams::new(20.0, 1e-4).with_plant_step(1e-5);
    let mut f =
        SaltationKalman::<f64, 2, 2>::new(params, 0.0, data[0].1, Vector2::zeros()).unwrap();
    let mut split = None;
    let mut before = 0;
    for (k, (t, q, impacts)) in data.iter().enumerate().skip(1) {
        f.update(&model, *t, q, &u).unwrap();
        let now = f.kalman_report().alternatives;
        if k > 100 {
            match split {
                None if *impacts > 0 && before == 0 && now > 0 => split = Some(k),
                Some(s) if *impacts == 0 && before > 0 && now > 0 => return (s, k),
                _ => {}
            }
        }
        before = now;
    }
    panic!("no impact split on the record")
}

/// The backward difference of the samples, `(q_k − q_{k−1}) / (t_k −
/// t_{k−1})`, kept as an estimator with the last sample as its state.
#[derive(Clone, Copy)]
struct Difference {
    t: f64,
    q: Vector2<f64>,
}

impl Difference {
    fn update(&mut self, t: f64, q: &Vector2<f64>) -> Vector2<f64> {
        let v = (q - self.q) / (t - self.t);
        (self.t, self.q) = (t, *q);
        v
    }
}

criterion_group!(benches, updates);
criterion_main!(benches);
