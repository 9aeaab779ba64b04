//! Observer updates in free flight as a user makes them: a stretch of
//! consecutive updates on the samples of a real run (no copy of the
//! observer per update, as `--bench step` has to make), and a loop to
//! profile under `perf`.
//!
//! For each case the plant runs 2000 steps of 1 ms; the observer follows
//! the run, and the stretch is the first 50 consecutive updates after the
//! first 20 in which it reports no impact, no contact and no active
//! constraint. One sample is 20 passes over the stretch from the same
//! warmed observer (a copy per pass, one per 50 updates); 400 samples, and
//! the minimum and median per update are printed (the minimum is the
//! figure least disturbed by other processes on a shared machine).
//!
//! `cargo bench -p moreau-bench --bench profile` prints the table;
//! `cargo bench -p moreau-bench --bench profile -- loop NAME` runs the case
//! `NAME` (e.g. `"parabola reduced impact-aware"`) for about ten seconds,
//! for `perf record`.

use moreau::{
    Discretization, FullOrder, FullOrderGains, Model, MoreauJean, Observer, ObserverParams,
    ReducedOrder, State, StepParams,
};
use moreau_models::{Arm3, Billiard, DoublePendulum, Parabola};
use nalgebra::{RealField, SVector};
use std::hint::black_box;
use std::time::Instant;

/// Updates in a stretch.
const STRETCH: usize = 50;
/// Updates before a stretch may start.
const WARM: usize = 20;

/// The plant's run of 2000 steps of 1 ms.
fn run<M, T, const N: usize, const K: usize, const NU: usize>(
    model: &M,
    (q0, v0): (SVector<T, N>, SVector<T, N>),
) -> Vec<State<T, N>>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T, Input = SVector<T, NU>>,
{
    let stepper = MoreauJean::new(StepParams::new(nalgebra::convert(1e-3))).unwrap();
    let mut state = State::new(T::zero(), q0, v0);
    let mut states = vec![state];
    for _ in 0..2000 {
        stepper.step(model, &mut state, &SVector::zeros()).unwrap();
        states.push(state);
    }
    states
}

/// The observer before the first free stretch, and the stretch.
fn stretch<'a, M, O, T, const N: usize, const K: usize, const NU: usize>(
    model: &M,
    states: &'a [State<T, N>],
    mut observer: O,
) -> Option<(O, &'a [State<T, N>])>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T, Input = SVector<T, NU>>,
    O: Observer<M, N, K> + Copy,
{
    let u = SVector::zeros();
    let (mut start, mut first) = (observer, WARM + 1);
    for (k, next) in states.iter().enumerate().skip(1) {
        let before = observer;
        observer.update(model, next.t, &next.q, &u).ok()?;
        let r = observer.report();
        let free = r.impacts == 0 && r.contacts.is_empty() && r.active.is_empty();
        if k <= WARM || !free {
            first = k + 1;
            continue;
        }
        if k == first {
            start = before;
        }
        if k + 1 - first == STRETCH {
            return Some((start, &states[first..=k]));
        }
    }
    None
}

/// Times (or, with `looping`, loops on) one case.
fn case<M, O, T, const N: usize, const K: usize, const NU: usize>(
    name: &str,
    model: &M,
    states: &[State<T, N>],
    observer: O,
    looping: Option<&str>,
) where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T, Input = SVector<T, NU>>,
    O: Observer<M, N, K> + Copy,
{
    if looping.is_some_and(|l| l != name) {
        return;
    }
    let Some((start, stretch)) = stretch::<M, O, T, N, K, NU>(model, states, observer) else {
        println!("{name}: no free stretch");
        return;
    };
    let u = SVector::zeros();
    let pass = || {
        let mut o = black_box(start);
        for s in stretch {
            black_box(o.update(model, s.t, &s.q, &u).unwrap());
        }
    };
    if looping.is_some() {
        let t0 = Instant::now();
        while t0.elapsed().as_secs() < 10 {
            for _ in 0..1000 {
                pass();
            }
        }
        return;
    }
    let mut samples: Vec<f64> = (0..400)
        .map(|_| {
            let t0 = Instant::now();
            for _ in 0..20 {
                pass();
            }
            t0.elapsed().as_nanos() as f64 / (20 * stretch.len()) as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    println!(
        "| {name} | {:.1} | {:.1} |",
        samples[0],
        samples[samples.len() / 2]
    );
}

/// Every observer and scheme on one model.
fn model<M, T, const N: usize, const K: usize, const NU: usize>(
    name: &str,
    model: &M,
    start: (SVector<T, N>, SVector<T, N>),
    looping: Option<&str>,
) where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T, Input = SVector<T, NU>>,
{
    let states = run::<M, T, N, K, NU>(model, start);
    let s0 = states[0];
    let l_d: T = nalgebra::convert(10.0);
    for scheme in [Discretization::ImpactAware, Discretization::SectionVii] {
        let tag = match scheme {
            Discretization::ImpactAware => "impact-aware",
            Discretization::SectionVii => "section-vii",
        };
        let params = ObserverParams::new(l_d, nalgebra::convert(50.0)).with_scheme(scheme);
        let reduced = ReducedOrder::<T, N, K>::new(params, s0.t, s0.q, s0.v).unwrap();
        let label = format!("{name} reduced {tag}");
        case::<M, _, T, N, K, NU>(&label, model, &states, reduced, looping);
        let gains = FullOrderGains::scalar(l_d, l_d);
        let full = FullOrder::<T, N, K>::new(params, gains, s0.t, s0.q, s0.v).unwrap();
        let label = format!("{name} full {tag}");
        case::<M, _, T, N, K, NU>(&label, model, &states, full, looping);
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let looping = args
        .iter()
        .position(|a| a == "loop")
        .and_then(|i| args.get(i + 1))
        .map(String::as_str);
    if looping.is_none() {
        println!("| case | min ns | median ns |\n|---|---|---|");
    }
    let p = Parabola::<f64>::default();
    model::<_, _, 2, 2, 0>("parabola", &p, Parabola::<f64>::initial_state(), looping);
    let p = Parabola::<f32>::default();
    model::<_, _, 2, 2, 0>(
        "parabola-f32",
        &p,
        Parabola::<f32>::initial_state(),
        looping,
    );
    let b = Billiard::<f64>::default();
    model::<_, _, 2, 4, 0>("billiard", &b, Billiard::<f64>::initial_state(), looping);
    let d = DoublePendulum::<f64>::default();
    let start = DoublePendulum::<f64>::initial_state();
    model::<_, _, 2, 2, 0>("double_pendulum", &d, start, looping);
    let a = Arm3::<f64>::default();
    model::<_, _, 3, 1, 3>("arm3", &a, Arm3::<f64>::initial_state(), looping);
}
