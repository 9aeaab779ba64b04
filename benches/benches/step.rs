//! One time step of the plant stepper, and one update of each observer, on
//! each shipped model (and Example 1 in `f32`), in free flight and with
//! active constraints, from states of a real run.
//!
//! The plant runs 5000 steps of 1 ms from the model's initial state. Its
//! benchmark cases are the first step with no active constraint (free
//! flight) and the step with the most. Each observer (reduced and full
//! order, impact-aware and Section VII) follows the same run sample by
//! sample; its cases are its own updates after the first 20 (a warmed,
//! converged estimate with its memos, as a user's observer has them): the
//! first in free flight (no impact, no contact), the first with an impact
//! located in the interval, the first with a persistent contact and no
//! impact. Each measurement copies the observer as it was before that
//! update (outside the timed region, as criterion's `iter_batched_ref`
//! does: a user updates the observer in place and never copies it) and
//! runs the update.
//!
//! `cargo bench -p moreau-bench --bench step`

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use moreau::{
    Discretization, FullOrder, FullOrderGains, Model, MoreauJean, Observer, ObserverParams,
    ReducedOrder, State, StepParams,
};
use moreau_models::{Arm3, Billiard, DoublePendulum, Parabola, ThreeBalls};
use nalgebra::{RealField, SVector};
use std::hint::black_box;

/// Steps in the run the cases are taken from.
const STEPS: usize = 5000;
/// Updates an observer makes before its cases are taken.
const WARM: usize = 20;

/// The plant's run: every state, and the index of the free-flight step and
/// of the busiest step with its number of active constraints.
struct Run<T: RealField + Copy, const N: usize> {
    states: Vec<State<T, N>>,
    free: Option<usize>,
    busiest: Option<(usize, usize)>,
}

fn run<M, T, const N: usize, const K: usize, const NU: usize>(
    model: &M,
    stepper: &MoreauJean<T>,
    (q0, v0): (SVector<T, N>, SVector<T, N>),
) -> Run<T, N>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T, Input = SVector<T, NU>>,
{
    let u = SVector::zeros();
    let mut state = State::new(T::zero(), q0, v0);
    let mut run = Run {
        states: vec![state],
        free: None,
        busiest: None,
    };
    for k in 0..STEPS {
        let report = stepper.step(model, &mut state, &u).unwrap();
        run.states.push(state);
        let active = report.active.len();
        if active == 0 && run.free.is_none() {
            run.free = Some(k);
        }
        if active > 0 && run.busiest.is_none_or(|(_, n)| active > n) {
            run.busiest = Some((k, active));
        }
    }
    run
}

/// An observer following the run; returns it as it was before its first
/// update (after `WARM`) in free flight, with an impact, and in contact.
fn observer_cases<M, O, T, const N: usize, const K: usize, const NU: usize>(
    model: &M,
    states: &[State<T, N>],
    mut observer: O,
) -> Vec<(&'static str, O, State<T, N>)>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T, Input = SVector<T, NU>>,
    O: Observer<M, N, K> + Copy,
{
    let u = SVector::zeros();
    let mut cases: Vec<(&'static str, O, State<T, N>)> = Vec::new();
    for (k, next) in states.iter().enumerate().skip(1) {
        let before = observer;
        observer.update(model, next.t, &next.q, &u).unwrap();
        if k <= WARM {
            continue;
        }
        let report = observer.report();
        let label = if report.impacts > 0 {
            "impact"
        } else if !report.contacts.is_empty() || !report.active.is_empty() {
            "contact"
        } else {
            "free flight"
        };
        if cases.iter().all(|(l, _, _)| *l != label) {
            cases.push((label, before, *next));
        }
    }
    cases.sort_by_key(|(l, _, _)| match *l {
        "free flight" => 0,
        "impact" => 1,
        _ => 2,
    });
    cases
}

fn bench_model<M, T, const N: usize, const K: usize, const NU: usize>(
    c: &mut Criterion,
    name: &str,
    model: M,
    start: (SVector<T, N>, SVector<T, N>),
) where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T, Input = SVector<T, NU>>,
{
    let tau: T = nalgebra::convert(1e-3);
    let stepper = MoreauJean::new(StepParams::new(tau)).unwrap();
    let u = SVector::<T, NU>::zeros();
    let run = run::<M, T, N, K, NU>(&model, &stepper, start);
    let mut group = c.benchmark_group(format!("step/{name}"));
    if let Some(k) = run.free {
        let state = run.states[k];
        group.bench_function("free flight", |b| {
            b.iter(|| {
                let mut s = black_box(state);
                stepper.step(&model, &mut s, &u).unwrap();
                s
            })
        });
    }
    if let Some((k, active)) = run.busiest {
        let state = run.states[k];
        group.bench_function(format!("{active} active"), |b| {
            b.iter(|| {
                let mut s = black_box(state);
                stepper.step(&model, &mut s, &u).unwrap();
                s
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group(format!("observer/{name}"));
    let (l_d, bound): (T, T) = (nalgebra::convert(10.0), nalgebra::convert(50.0));
    let s0 = run.states[0];
    for scheme in [Discretization::ImpactAware, Discretization::SectionVii] {
        let params = ObserverParams::new(l_d, bound).with_scheme(scheme);
        let tag = match scheme {
            Discretization::ImpactAware => "impact-aware",
            Discretization::SectionVii => "section-vii",
        };
        let reduced = ReducedOrder::<T, N, K>::new(params, s0.t, s0.q, s0.v).unwrap();
        for (label, observer, next) in
            observer_cases::<M, _, T, N, K, NU>(&model, &run.states, reduced)
        {
            group.bench_function(format!("reduced {tag}, {label}"), |b| {
                b.iter_batched_ref(
                    || observer,
                    |o| o.update(&model, black_box(next.t), &next.q, &u).unwrap(),
                    BatchSize::SmallInput,
                )
            });
        }
        let gains = FullOrderGains::scalar(l_d, l_d);
        let full = FullOrder::<T, N, K>::new(params, gains, s0.t, s0.q, s0.v).unwrap();
        for (label, observer, next) in
            observer_cases::<M, _, T, N, K, NU>(&model, &run.states, full)
        {
            group.bench_function(format!("full {tag}, {label}"), |b| {
                b.iter_batched_ref(
                    || observer,
                    |o| o.update(&model, black_box(next.t), &next.q, &u).unwrap(),
                    BatchSize::SmallInput,
                )
            });
        }
    }
    group.finish();
}

fn steps(c: &mut Criterion) {
    bench_model::<_, _, 2, 2, 0>(
        c,
        "parabola",
        Parabola::<f64>::default(),
        Parabola::<f64>::initial_state(),
    );
    bench_model::<_, _, 2, 2, 0>(
        c,
        "parabola-f32",
        Parabola::<f32>::default(),
        Parabola::<f32>::initial_state(),
    );
    bench_model::<_, _, 3, 4, 0>(
        c,
        "three_balls",
        ThreeBalls::<f64>::default(),
        ThreeBalls::<f64>::initial_state(),
    );
    bench_model::<_, _, 2, 4, 0>(
        c,
        "billiard",
        Billiard::<f64>::default(),
        Billiard::<f64>::initial_state(),
    );
    bench_model::<_, _, 2, 2, 0>(
        c,
        "double_pendulum",
        DoublePendulum::<f64>::default(),
        DoublePendulum::<f64>::initial_state(),
    );
    bench_model::<_, _, 3, 1, 3>(
        c,
        "arm3",
        Arm3::<f64>::default(),
        Arm3::<f64>::initial_state(),
    );
}

criterion_group!(benches, steps);
criterion_main!(benches);
