//! One time step of the plant stepper, and one update of each observer, on
//! each shipped model, in free flight and with active constraints (impacts,
//! persistent contact).
//!
//! `cargo bench -p moreau-bench --bench step`

use criterion::{Criterion, criterion_group, criterion_main};
use moreau::{
    Discretization, FullOrder, FullOrderGains, Model, MoreauJean, Observer, ObserverParams,
    ReducedOrder, State, StepParams,
};
use moreau_models::{Arm3, Billiard, DoublePendulum, Parabola, ThreeBalls};
use nalgebra::SVector;
use std::hint::black_box;

/// A free-flight state, and the state with the most active constraints
/// with their number.
type Cases<const N: usize> = (Option<State<f64, N>>, Option<(State<f64, N>, usize)>);

/// Runs the model from its initial state and keeps the first state whose
/// step has no active constraint (free flight; the three balls have none:
/// balls 2 and 3 stay in contact) and the state whose step has the most
/// active constraints.
fn states<M, const N: usize, const K: usize, const NU: usize>(
    model: &M,
    q0: SVector<f64, N>,
    v0: SVector<f64, N>,
) -> Cases<N>
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>>,
{
    let stepper = MoreauJean::new(StepParams::new(1e-3)).unwrap();
    let u = SVector::zeros();
    let mut state = State::new(0.0, q0, v0);
    let mut free = None;
    let mut busiest: Option<(State<f64, N>, usize)> = None;
    for _ in 0..5000 {
        let before = state;
        let report = stepper.step(model, &mut state, &u).unwrap();
        let active = report.active.len();
        if active == 0 && free.is_none() {
            free = Some(before);
        }
        if active > 0 && busiest.is_none_or(|(_, n)| active > n) {
            busiest = Some((before, active));
        }
    }
    (free, busiest)
}

fn bench_model<M, const N: usize, const K: usize, const NU: usize>(
    c: &mut Criterion,
    name: &str,
    model: M,
    q0: SVector<f64, N>,
    v0: SVector<f64, N>,
) where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>>,
{
    let stepper = MoreauJean::new(StepParams::new(1e-3)).unwrap();
    let u = SVector::<f64, NU>::zeros();
    let (free, busiest) = states::<M, N, K, NU>(&model, q0, v0);
    let mut group = c.benchmark_group(format!("step/{name}"));
    if let Some(free) = free {
        group.bench_function("free flight", |b| {
            b.iter(|| {
                let mut s = black_box(free);
                stepper.step(&model, &mut s, &u).unwrap();
                s
            })
        });
    }
    if let Some((contact, active)) = busiest {
        group.bench_function(format!("{active} active"), |b| {
            b.iter(|| {
                let mut s = black_box(contact);
                stepper.step(&model, &mut s, &u).unwrap();
                s
            })
        });
    }
    group.finish();

    // observers: one update from a converged estimate, 1 ms after the state
    let mut group = c.benchmark_group(format!("observer/{name}"));
    let mut cases: Vec<(&str, State<f64, N>)> =
        free.map(|f| ("free flight", f)).into_iter().collect();
    if let Some((contact, active)) = busiest {
        cases.push((if active > 1 { "contacts" } else { "contact" }, contact));
    }
    for (label, start) in cases {
        let mut next = start;
        stepper.step(&model, &mut next, &u).unwrap();
        for scheme in [Discretization::ImpactAware, Discretization::SectionVii] {
            let params = ObserverParams::new(10.0, 50.0).with_scheme(scheme);
            let tag = match scheme {
                Discretization::ImpactAware => "impact-aware",
                Discretization::SectionVii => "section-vii",
            };
            let reduced =
                ReducedOrder::<f64, N, K>::new(params, start.t, start.q, start.v).unwrap();
            group.bench_function(format!("reduced {tag}, {label}"), |b| {
                b.iter(|| {
                    let mut o = black_box(reduced);
                    o.update(&model, next.t, &next.q, &u).unwrap()
                })
            });
            let gains = FullOrderGains::scalar(10.0, 10.0);
            let full =
                FullOrder::<f64, N, K>::new(params, gains, start.t, start.q, start.v).unwrap();
            group.bench_function(format!("full {tag}, {label}"), |b| {
                b.iter(|| {
                    let mut o = black_box(full);
                    o.update(&model, next.t, &next.q, &u).unwrap()
                })
            });
        }
    }
    group.finish();
}

fn steps(c: &mut Criterion) {
    let (q, v) = Parabola::<f64>::initial_state();
    bench_model::<_, 2, 2, 0>(c, "parabola", Parabola::<f64>::default(), q, v);
    let (q, v) = ThreeBalls::<f64>::initial_state();
    bench_model::<_, 3, 4, 0>(c, "three_balls", ThreeBalls::<f64>::default(), q, v);
    let (q, v) = Billiard::<f64>::initial_state();
    bench_model::<_, 2, 4, 0>(c, "billiard", Billiard::<f64>::default(), q, v);
    let (q, v) = DoublePendulum::<f64>::initial_state();
    bench_model::<_, 2, 2, 0>(c, "double_pendulum", DoublePendulum::<f64>::default(), q, v);
    let (q, v) = Arm3::<f64>::initial_state();
    bench_model::<_, 3, 1, 3>(c, "arm3", Arm3::<f64>::default(), q, v);
}

criterion_group!(benches, steps);
criterion_main!(benches);
