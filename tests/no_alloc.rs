//! Zero heap allocation per step, proven with a counting global allocator:
//! every model's evaluation, the LCP, the plant stepper and the observers
//! through impacts, accumulations and sliding allocate nothing.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use moreau::{
    Discretization, FullOrder, FullOrderGains, KalmanParams, Model, MoreauJean, Observer,
    ObserverParams, ReducedOrder, SaltationKalman, Sensitivities, State, StepParams,
    tune_process_noise,
};
use moreau_models::{Arm3, Billiard, DoublePendulum, Parabola, ThreeBalls};
use nalgebra::SVector;

// A URDF robot, whose dynamics the recursions over its tree build.
moreau::model!(file = "tests/robots/ur5.yaml");

/// Counts allocations made on a thread while it is armed.
struct Counting;

thread_local! {
    static ARMED: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if ARMED.with(Cell::get) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if ARMED.with(Cell::get) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Allocations made by `f` on this thread.
fn allocations(f: impl FnOnce()) -> usize {
    COUNT.with(|c| c.set(0));
    ARMED.with(|a| a.set(true));
    f();
    ARMED.with(|a| a.set(false));
    COUNT.with(Cell::get)
}

/// Steps a shipped model from its initial state for `steps` steps of 1 ms.
fn run<M, const N: usize, const K: usize, const NU: usize>(
    model: &M,
    q0: SVector<f64, N>,
    v0: SVector<f64, N>,
    steps: usize,
) -> usize
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>>,
{
    let stepper = MoreauJean::new(StepParams::new(1e-3)).unwrap();
    let mut state = State::new(0.0, q0, v0);
    let u = SVector::<f64, NU>::repeat(0.1);
    let mut impacts = 0;
    let count = allocations(|| {
        for _ in 0..steps {
            let report = stepper.step(model, &mut state, &u).unwrap();
            impacts += report.impacts().count();
            let terms = model.eval(state.t, &state.q, &state.v, &u);
            std::hint::black_box(terms);
        }
    });
    assert!(impacts > 0, "{}: no impact in the run", M::INFO.name);
    count
}

#[test]
fn stepping_every_shipped_model_allocates_nothing() {
    let (q, v) = Parabola::<f64>::initial_state();
    assert_eq!(
        run::<_, 2, 2, 0>(&Parabola::<f64>::default(), q, v, 6000),
        0
    );
    let (q, v) = ThreeBalls::<f64>::initial_state();
    assert_eq!(
        run::<_, 3, 4, 0>(&ThreeBalls::<f64>::default(), q, v, 2000),
        0
    );
    let (q, v) = Billiard::<f64>::initial_state();
    assert_eq!(
        run::<_, 2, 4, 0>(&Billiard::<f64>::default(), q, v, 2000),
        0
    );
    let (q, v) = DoublePendulum::<f64>::initial_state();
    assert_eq!(
        run::<_, 2, 2, 0>(&DoublePendulum::<f64>::default(), q, v, 4000),
        0
    );
    let (q, v) = Arm3::<f64>::initial_state();
    assert_eq!(run::<_, 3, 1, 3>(&Arm3::<f64>::default(), q, v, 2000), 0);
}

/// A robot from its URDF (the UR5 falling onto its table from the zero
/// configuration): stepping, evaluating and observing allocate nothing.
#[test]
fn a_urdf_robot_allocates_nothing() {
    let (q, v) = (SVector::zeros(), SVector::zeros());
    let ur5 = Ur5::<f64>::new();
    assert_eq!(run::<_, 6, 6, 0>(&ur5, q, v, 2000), 0);
    let (count, impacts) = observe::<_, 6, 6, 0>(&ur5, q, v, 20_000);
    assert_eq!((count, impacts > 0), (0, true));
}

/// Runs a shipped model's plant for `steps` steps of 0.1 ms, then feeds
/// every tenth position (with a little deterministic noise) to both
/// observers under both discretizations; returns the allocations the
/// observers made and the impacts they located.
fn observe<M, const N: usize, const K: usize, const NU: usize>(
    model: &M,
    q0: SVector<f64, N>,
    v0: SVector<f64, N>,
    steps: usize,
) -> (usize, u32)
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>>,
{
    let stepper = MoreauJean::new(StepParams::new(1e-4)).unwrap();
    let mut state = State::new(0.0, q0, v0);
    let u = SVector::<f64, NU>::repeat(0.1);
    let mut samples = Vec::with_capacity(steps / 10 + 1);
    for k in 1..=steps {
        stepper.step(model, &mut state, &u).unwrap();
        if k % 10 == 0 {
            let wiggle = 1e-7 * ((k / 10) % 7) as f64;
            samples.push((state.t, state.q.add_scalar(wiggle)));
        }
    }
    let mut impacts = 0;
    let count = allocations(|| {
        for scheme in [Discretization::ImpactAware, Discretization::SectionVii] {
            let params = ObserverParams::new(10.0, 50.0)
                .with_noise(1e-7)
                .with_scheme(scheme);
            let mut reduced =
                ReducedOrder::<f64, N, K>::new(params, 0.0, q0, SVector::zeros()).unwrap();
            let gains = FullOrderGains::scalar(5.0, 25.0);
            let mut full =
                FullOrder::<f64, N, K>::new(params, gains, 0.0, q0, SVector::zeros()).unwrap();
            for (t, q) in &samples {
                std::hint::black_box(reduced.update(model, *t, q, &u).unwrap());
                impacts += reduced.report().impacts;
                std::hint::black_box(full.update(model, *t, q, &u).unwrap());
            }
        }
    });
    (count, impacts)
}

#[test]
fn observing_every_shipped_model_allocates_nothing() {
    let (q, v) = Parabola::<f64>::initial_state();
    let (count, impacts) = observe::<_, 2, 2, 0>(&Parabola::<f64>::default(), q, v, 60_000);
    assert_eq!((count, impacts > 0), (0, true));
    let (q, v) = ThreeBalls::<f64>::initial_state();
    let (count, impacts) = observe::<_, 3, 4, 0>(&ThreeBalls::<f64>::default(), q, v, 20_000);
    assert_eq!((count, impacts > 0), (0, true));
    let (q, v) = Billiard::<f64>::initial_state();
    let (count, impacts) = observe::<_, 2, 4, 0>(&Billiard::<f64>::default(), q, v, 20_000);
    assert_eq!((count, impacts > 0), (0, true));
    let (q, v) = DoublePendulum::<f64>::initial_state();
    let (count, impacts) = observe::<_, 2, 2, 0>(&DoublePendulum::<f64>::default(), q, v, 40_000);
    assert_eq!((count, impacts > 0), (0, true));
    let (q, v) = Arm3::<f64>::initial_state();
    let (count, _) = observe::<_, 3, 1, 3>(&Arm3::<f64>::default(), q, v, 20_000);
    assert_eq!(count, 0);
}

/// The saltation Kalman filter through the same runs (impacts,
/// accumulations, sliding, several contacts), with its defaults and told
/// the plant (`with_plant_step`: one plant step at each impact; and
/// Siconos's law, `with_plant(StepParams::siconos(…))`: two more on each
/// piece of a slide), and the likelihood helper's evaluations over a
/// record: nothing allocates.
fn filter<M, const N: usize, const K: usize, const NU: usize>(
    model: &M,
    q0: SVector<f64, N>,
    v0: SVector<f64, N>,
    steps: usize,
) -> (usize, u32)
where
    M: Sensitivities<N, K, Scalar = f64, Input = SVector<f64, NU>>,
{
    let stepper = MoreauJean::new(StepParams::new(1e-4)).unwrap();
    let mut state = State::new(0.0, q0, v0);
    let u = SVector::<f64, NU>::repeat(0.1);
    let mut t = vec![0.0];
    let mut q = vec![q0];
    for k in 1..=steps {
        stepper.step(model, &mut state, &u).unwrap();
        if k % 10 == 0 {
            let wiggle = 1e-7 * ((k / 10) % 7) as f64;
            t.push(state.t);
            q.push(state.q.add_scalar(wiggle));
        }
    }
    let mut saltations = 0;
    let params = KalmanParams::new(50.0, 1e-7);
    let count = allocations(|| {
        for knobs in [
            params,
            params.with_plant_step(1e-4),
            params.with_plant(StepParams::siconos(1e-4)),
        ] {
            let mut f =
                SaltationKalman::<f64, N, K>::new(knobs, 0.0, q0, SVector::zeros()).unwrap();
            for (tk, qk) in t.iter().zip(&q).skip(1) {
                std::hint::black_box(f.update(model, *tk, qk, &u).unwrap());
                saltations += f.kalman_report().saltations;
            }
        }
        let record = (&t[..t.len().min(200)], &q[..q.len().min(200)]);
        std::hint::black_box(
            tune_process_noise::<_, _, N, K>(
                model,
                params,
                record.0,
                record.1,
                &SVector::zeros(),
                &u,
                (-2.0, 2.0),
            )
            .unwrap(),
        );
    });
    (count, saltations)
}

#[test]
fn filtering_every_shipped_model_allocates_nothing() {
    let (q, v) = Parabola::<f64>::initial_state();
    let (count, saltations) = filter::<_, 2, 2, 0>(&Parabola::<f64>::default(), q, v, 60_000);
    assert_eq!((count, saltations > 0), (0, true));
    let (q, v) = ThreeBalls::<f64>::initial_state();
    let (count, saltations) = filter::<_, 3, 4, 0>(&ThreeBalls::<f64>::default(), q, v, 20_000);
    assert_eq!((count, saltations > 0), (0, true));
    let (q, v) = Billiard::<f64>::initial_state();
    let (count, saltations) = filter::<_, 2, 4, 0>(&Billiard::<f64>::default(), q, v, 20_000);
    assert_eq!((count, saltations > 0), (0, true));
    let (q, v) = DoublePendulum::<f64>::initial_state();
    let (count, saltations) = filter::<_, 2, 2, 0>(&DoublePendulum::<f64>::default(), q, v, 40_000);
    assert_eq!((count, saltations > 0), (0, true));
    let (q, v) = Arm3::<f64>::initial_state();
    let (count, _) = filter::<_, 3, 1, 3>(&Arm3::<f64>::default(), q, v, 20_000);
    assert_eq!(count, 0);
}

/// The counter does count: a `Vec` allocates.
#[test]
fn the_counter_sees_an_allocation() {
    assert_eq!(allocations(|| drop(std::hint::black_box(vec![1u8; 16]))), 1);
}
