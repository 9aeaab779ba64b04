//! The Moreau–Jean plant stepper against Siconos, analytic impact outcomes
//! and conserved or dissipated quantities.
//!
//! Run with `--nocapture` to see the measured figures.

mod common;

use moreau::{
    ApproachVelocity, DataError, LcpError, Model, MoreauJean, State, StepError, StepParams,
};
use moreau_models::{Billiard, DoublePendulum, Parabola, ThreeBalls};
use nalgebra::{SVector, Vector2, Vector3, Vector4};

/// A Siconos trajectory: rows `k, t, q..., v...`.
fn siconos<const N: usize>(stem: &str) -> Vec<State<f64, N>> {
    let path = common::root().join(format!("tests/fixtures/siconos/{stem}.csv"));
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('k'))
        .map(|l| {
            let x: Vec<f64> = l.split(',').map(|v| v.parse().expect("a number")).collect();
            assert_eq!(x.len(), 2 + 2 * N, "row {l}");
            State::new(
                x[1],
                SVector::from_column_slice(&x[2..2 + N]),
                SVector::from_column_slice(&x[2 + N..]),
            )
        })
        .collect()
}

fn distance<const N: usize>(a: &State<f64, N>, b: &State<f64, N>) -> f64 {
    (a.q - b.q).amax().max((a.v - b.v).amax())
}

/// Every step from a Siconos state lands on Siconos' next state, and the
/// whole trajectory stays on Siconos' to 1e-9.
///
/// Tolerances. One step: the two implementations differ in `h` (Siconos
/// steps by `t_{k+1} − t_k` with `t_j = jτ`, which differs from `τ` by up
/// to one ulp of `t`, 1.8e-15 at t = 10 s, times forces of about 10) and in
/// the order of their sums (LAPACK LU and Lemke against ours: a few ulps of
/// states of size 10); an impact maps such differences through the LCP at
/// the same order. Observed worst: 3.3e-13 (Example 1), 4.0e-15 (double
/// pendulum); the bound 1e-11 leaves a factor of 30. Whole run: Example 1
/// amplifies a difference at each impact (about tenfold at the strongest,
/// per `tests/reference/siconos_notes.md`), so the whole-run bound is the
/// 1e-9 the issue asks about; observed 8.2e-12 and 1.4e-14.
fn agrees_with_siconos<M, const N: usize, const K: usize>(stem: &str, approach: ApproachVelocity)
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, 0>> + Default,
{
    let reference = siconos::<N>(stem);
    let model = M::default();
    let params = StepParams::new(1e-3).with_approach_velocity(approach);
    let stepper = MoreauJean::new(params).unwrap();
    let u = SVector::zeros();
    let mut worst_step = (0.0_f64, 0);
    for k in 0..reference.len() - 1 {
        let mut state = reference[k];
        stepper.step(&model, &mut state, &u).unwrap();
        let d = distance(&state, &reference[k + 1]);
        if d > worst_step.0 {
            worst_step = (d, k);
        }
    }
    let mut state = reference[0];
    let mut worst_run = 0.0_f64;
    for expected in &reference[1..] {
        stepper.step(&model, &mut state, &u).unwrap();
        worst_run = worst_run.max(distance(&state, expected));
    }
    eprintln!(
        "{stem} ({approach:?}): {} steps; one step from Siconos' state: worst {:.1e} (step {}); whole run: worst {worst_run:.1e}",
        reference.len() - 1,
        worst_step.0,
        worst_step.1
    );
    assert!(
        worst_step.0 <= 1e-11,
        "{stem}: one-step difference {:e}",
        worst_step.0
    );
    assert!(
        worst_run <= 1e-9,
        "{stem}: whole-run difference {worst_run:e}"
    );
}

/// Siconos' own Newton's law (`e J(q_k) v_k`) on Example 1.
#[test]
fn example_1_agrees_with_siconos_step_by_step() {
    agrees_with_siconos::<Parabola, 2, 2>("parabola", ApproachVelocity::Start);
}

/// Siconos' own Newton's law on the double pendulum.
#[test]
fn double_pendulum_agrees_with_siconos_step_by_step() {
    agrees_with_siconos::<DoublePendulum, 2, 2>("double_pendulum", ApproachVelocity::Start);
}

/// The law `Slower` takes the slower of `J(q_k) v_k` and `J(q̃) v_k`. On
/// Example 1 (a convex domain: the normal turns towards the mass) that is
/// Siconos' `J(q_k) v_k` at every impact, and the θ-method with this law
/// agrees with Siconos to 1e-9 over the whole run.
#[test]
fn slower_law_agrees_with_siconos_on_example_1() {
    agrees_with_siconos::<Parabola, 2, 2>("parabola", ApproachVelocity::Slower);
}

/// On the double pendulum the floor, seen in joint space, turns the other
/// way at some impacts: there the law `Slower` measures a slower approach
/// than Siconos, and the two part. They part at the first step whose
/// laws differ, and not before.
#[test]
fn slower_law_leaves_siconos_where_the_laws_differ() {
    let reference = siconos::<2>("double_pendulum");
    let model = DoublePendulum::<f64>::default();
    let params = StepParams::new(1e-3).with_approach_velocity(ApproachVelocity::Slower);
    let stepper = MoreauJean::new(params).unwrap();
    let mut state = reference[0];
    let mut first_departure = None;
    for (k, expected) in reference[1..].iter().enumerate() {
        stepper.step(&model, &mut state, &SVector::zeros()).unwrap();
        if distance(&state, expected) > 1e-9 {
            first_departure = Some(k);
            break;
        }
    }
    // the first step at which the two approach velocities differ on an
    // active constraint, along Siconos' trajectory
    let laws_differ = |s: &State<f64, 2>| {
        let (h, j) = model.contact(&s.q);
        let jv = j * s.v;
        let predicted = s.q + s.v * 1e-3;
        let jv_iterate = model.gap_jacobian(&predicted) * s.v;
        (0..2).any(|i| h[i] + 0.5e-3 * jv[i] <= 0.0 && jv_iterate[i] > jv[i])
    };
    let first_difference = reference.iter().position(laws_differ);
    eprintln!(
        "double pendulum, law Slower: laws first differ at step {first_difference:?}, trajectories first part (1e-9) at step {first_departure:?}"
    );
    assert!(first_departure.is_some());
    assert!(first_departure >= first_difference);
}

/// On a dispersing obstacle with e = 1 Siconos' law gains energy at every
/// impact and runs away, which the default law does not (see
/// `billiard_with_e_1_keeps_its_energy`): the one place where the two
/// laws part.
#[test]
fn siconos_law_gains_energy_on_a_dispersing_billiard() {
    let model = Billiard::<f64> {
        g: 0.0,
        restitution: Vector4::repeat(1.0),
        ..Default::default()
    };
    let params = StepParams::siconos(1e-3);
    let stepper = MoreauJean::new(params).unwrap();
    let mut state = State::new(0.0, Vector2::new(0.05, 0.1), Vector2::new(1.5, 0.7));
    let e0 = 0.5 * state.v.norm_squared();
    while state.t < 10.0 {
        stepper.step(&model, &mut state, &SVector::zeros()).unwrap();
    }
    let gain = 0.5 * state.v.norm_squared() / e0;
    eprintln!("billiard, e = 1, Siconos' law: energy x{gain:.3} after 10 s");
    assert!(gain > 1.1, "{gain}");
}

/// Fig. 1a: ball 1 hits balls 2 and 3 at rest in contact. With both
/// contacts active, the LCP `W λ + (1 + e) J v⁻ ⊥ λ` with
/// `W = [[2, −1], [−1, 2]]`, `J v⁻ = (−v₀, 0)` has the positive solution
/// `λ = (1 + e) v₀ (2/3, 1/3)`: both contacts stay closed in the law, so
/// balls 2 and 3 leave glued with `(1 + e) v₀ / 3` and ball 1 keeps
/// `(1 − 2e) v₀ / 3`.
#[test]
fn three_balls_leave_the_impact_as_the_lcp_predicts() {
    let model = ThreeBalls::<f64>::default();
    let (q0, v0) = ThreeBalls::<f64>::initial_state();
    let (speed, e) = (v0[0], 0.9);
    let stepper = MoreauJean::new(StepParams::new(1e-3)).unwrap();
    let mut state = State::new(0.0, q0, v0);
    let report = loop {
        let report = stepper.step(&model, &mut state, &SVector::zeros()).unwrap();
        if report.impacts().count() > 0 {
            break report;
        }
        assert!(state.t < 1.0, "no impact");
    };
    let glued = (1.0 + e) * speed / 3.0;
    let expected = Vector3::new((1.0 - 2.0 * e) * speed / 3.0, glued, glued);
    assert_eq!(report.impacting().iter().collect::<Vec<_>>(), [1, 2]);
    assert!(
        (state.v - expected).amax() < 1e-14,
        "{} vs {expected}",
        state.v
    );
    let lambda = Vector4::new(0.0, 2.0 / 3.0, 1.0 / 3.0, 0.0) * (1.0 + e) * speed;
    assert!(
        (report.impulses - lambda).amax() < 1e-14,
        "{}",
        report.impulses
    );
    // glued: the gap between 2 and 3 stays closed while they travel
    for _ in 0..50 {
        stepper.step(&model, &mut state, &SVector::zeros()).unwrap();
        assert!(model.gaps(&state.q)[2].abs() < 1e-14);
    }
}

/// With e = 1 and no gravity, a ball in the nonconvex billiard keeps its
/// kinetic energy over 100 s and hundreds of impacts (the default law
/// reflects exactly in the kinetic metric; flight conserves it).
#[test]
fn billiard_with_e_1_keeps_its_energy() {
    let model = Billiard::<f64> {
        g: 0.0,
        restitution: Vector4::repeat(1.0),
        ..Default::default()
    };
    let stepper = MoreauJean::new(StepParams::new(1e-3)).unwrap();
    let mut state = State::new(0.0, Vector2::new(0.05, 0.1), Vector2::new(1.5, 0.7));
    let energy = |s: &State<f64, 2>| 0.5 * model.m * s.v.norm_squared();
    let e0 = energy(&state);
    let (mut impacts, mut drift) = (0, 0.0_f64);
    while state.t < 100.0 {
        let report = stepper.step(&model, &mut state, &SVector::zeros()).unwrap();
        impacts += report.impacts().count();
        drift = drift.max((energy(&state) - e0).abs() / e0);
    }
    eprintln!(
        "billiard, e = 1, no gravity, 100 s: {impacts} impacts, relative energy drift {drift:.1e}"
    );
    assert!(impacts > 300);
    assert!(drift < 1e-10, "energy drift {drift:e}");
}

/// With e < 1 and no other force, no step increases the kinetic energy
/// (flight keeps it, an impact loses it): the billiard without gravity and
/// the three balls, every step, to round-off.
#[test]
fn kinetic_energy_never_increases_at_an_impact() {
    let billiard = Billiard::<f64> {
        g: 0.0,
        ..Default::default()
    };
    let stepper = MoreauJean::new(StepParams::new(1e-3)).unwrap();
    let mut state = State::new(0.0, Vector2::new(0.05, 0.1), Vector2::new(1.5, 0.7));
    let mut impacts = 0;
    while state.t < 20.0 {
        let before = 0.5 * state.v.norm_squared();
        let report = stepper
            .step(&billiard, &mut state, &SVector::zeros())
            .unwrap();
        impacts += report.impacts().count();
        let after = 0.5 * state.v.norm_squared();
        assert!(
            after <= before * (1.0 + 1e-14),
            "t = {}: {before} -> {after}",
            state.t
        );
    }
    assert!(impacts > 10, "{impacts}");

    let balls = ThreeBalls::<f64>::default();
    let (q0, v0) = ThreeBalls::<f64>::initial_state();
    let mut state = State::new(0.0, q0, v0);
    let kinetic = |s: &State<f64, 3>| 0.5 * (balls.mass(&s.q) * s.v).dot(&s.v);
    while state.t < 20.0 {
        let before = kinetic(&state);
        stepper.step(&balls, &mut state, &SVector::zeros()).unwrap();
        assert!(kinetic(&state) <= before * (1.0 + 1e-14));
    }
}

/// Penetration is O(τ): across τ = 1e-3 and 1e-4 the deepest penetration
/// of Example 1 (through its accumulation and sliding), of the billiard
/// (thousands of impacts, wedged in a corner at the end) and of the double
/// pendulum (sliding on the floor) shrinks at least fivefold, and at
/// τ = 1e-3 it is less than one step of travel, `τ max|J v|`.
#[test]
fn penetration_is_of_order_tau() {
    fn run<M, const N: usize, const K: usize>(
        model: &M,
        q0: SVector<f64, N>,
        v0: SVector<f64, N>,
        tau: f64,
        seconds: f64,
    ) -> (f64, f64)
    where
        M: Model<N, K, Scalar = f64, Input = SVector<f64, 0>>,
    {
        let stepper = MoreauJean::new(StepParams::new(tau)).unwrap();
        let mut state = State::new(0.0, q0, v0);
        let (mut deepest, mut travel) = (0.0_f64, 0.0_f64);
        while state.t < seconds {
            let (_, jac) = model.contact(&state.q);
            travel = travel.max((jac * state.v).amax() * tau);
            stepper.step(model, &mut state, &SVector::zeros()).unwrap();
            deepest = deepest.min(model.gaps(&state.q).min());
        }
        (-deepest, travel)
    }
    fn check<M, const N: usize, const K: usize>(name: &str, model: &M, seconds: f64)
    where
        M: Model<N, K, Scalar = f64, Input = SVector<f64, 0>>,
        M: Initial<N>,
    {
        let (q0, v0) = M::initial();
        let (coarse, travel) = run(model, q0, v0, 1e-3, seconds);
        let (fine, _) = run(model, q0, v0, 1e-4, seconds);
        eprintln!(
            "{name}: deepest penetration {coarse:.2e} (τ = 1e-3, one step of travel {travel:.2e}), {fine:.2e} (τ = 1e-4)"
        );
        assert!(coarse <= travel, "{name}: {coarse} > {travel}");
        assert!(fine <= coarse / 5.0, "{name}: {fine} vs {coarse}");
    }
    check("Example 1", &Parabola::<f64>::default(), 10.0);
    check("billiard", &Billiard::<f64>::default(), 5.0);
    check("double pendulum", &DoublePendulum::<f64>::default(), 5.0);
}

/// The initial state of a shipped model.
trait Initial<const N: usize> {
    fn initial() -> (SVector<f64, N>, SVector<f64, N>);
}

impl Initial<2> for Parabola<f64> {
    fn initial() -> (SVector<f64, 2>, SVector<f64, 2>) {
        Parabola::<f64>::initial_state()
    }
}

impl Initial<2> for Billiard<f64> {
    fn initial() -> (SVector<f64, 2>, SVector<f64, 2>) {
        Billiard::<f64>::initial_state()
    }
}

impl Initial<2> for DoublePendulum<f64> {
    fn initial() -> (SVector<f64, 2>, SVector<f64, 2>) {
        DoublePendulum::<f64>::initial_state()
    }
}

/// Example 1 through its accumulation of impacts (t ≈ 4.4 s) and sliding
/// to 10 s: no blow-up (the energy never rises above its initial value) and,
/// once sliding, the mass stays on the parabola to O(τ) with the floor in
/// the index set at every step.
#[test]
fn example_1_accumulates_then_slides() {
    let model = Parabola::<f64>::default();
    let tau = 1e-3;
    let stepper = MoreauJean::new(StepParams::new(tau)).unwrap();
    let (q0, v0) = Parabola::<f64>::initial_state();
    let mut state = State::new(0.0, q0, v0);
    let energy = |s: &State<f64, 2>| 0.5 * s.v.norm_squared() + model.g * s.q[1];
    let e0 = energy(&state);
    let mut last_free_step = 0.0;
    while state.t < 10.0 - tau / 2.0 {
        let report = stepper.step(&model, &mut state, &SVector::zeros()).unwrap();
        if !report.active.contains(0) {
            last_free_step = state.t;
        }
        assert!(energy(&state) <= e0 * (1.0 + 1e-12));
        if state.t > 5.0 {
            assert!(
                model.gaps(&state.q)[0].abs() <= tau,
                "gap {}",
                model.gaps(&state.q)[0]
            );
        }
    }
    eprintln!("Example 1: floor active at every step from t = {last_free_step:.3} s");
    assert!((4.0..5.0).contains(&last_free_step), "{last_free_step}");
}

/// A point between two walls that coincide: `x ≥ 0` with e = 0 and `x ≤ 0`
/// with e = 1. Both active at x = 0 with v ≠ 0, Newton's law asks for
/// `v⁺ ≥ 0` and `−v⁺ ≥ e v`: no impulse satisfies both.
mod pinched {
    moreau::model! {
        pub struct Pinched;
        coordinates { x: v }
        kinetic = 0.5 * v^2;
        constraints {
            #[restitution = 0]
            left: x >= 0,
            #[restitution = 1]
            right: x <= 0,
        }
    }
}

/// Bad input is an error value naming the problem, and the state is left
/// exactly as it was.
#[test]
fn bad_input_is_an_error_and_leaves_the_state_alone() {
    fn refused<M, const N: usize, const K: usize>(
        model: &M,
        stepper: &MoreauJean<f64>,
        state: State<f64, N>,
    ) -> StepError<f64>
    where
        M: Model<N, K, Scalar = f64, Input = SVector<f64, 0>>,
    {
        let mut after = state;
        let error = stepper
            .step(model, &mut after, &SVector::zeros())
            .unwrap_err();
        // bit for bit, NaNs included
        let bits = |s: &State<f64, N>| {
            let mut b = vec![s.t.to_bits()];
            b.extend(s.q.iter().chain(s.v.iter()).map(|x| x.to_bits()));
            b
        };
        assert_eq!(
            bits(&after),
            bits(&state),
            "state changed by a refused step"
        );
        eprintln!("refused: {error}");
        error
    }
    let stepper = MoreauJean::new(StepParams::new(1e-3)).unwrap();
    let parabola = Parabola::<f64>::default();
    let (q0, v0) = Parabola::<f64>::initial_state();

    let mut nan_q = q0;
    nan_q[1] = f64::NAN;
    let e = refused(&parabola, &stepper, State::new(0.0, nan_q, v0));
    assert_eq!(
        e,
        StepError::Data(DataError::NonFinite {
            which: "q",
            index: 1
        })
    );

    let e = refused(&parabola, &stepper, State::new(f64::INFINITY, q0, v0));
    assert_eq!(
        e,
        StepError::Data(DataError::NonFinite {
            which: "t",
            index: 0
        })
    );

    let mut bad = parabola;
    bad.g = f64::NAN;
    let e = refused(&bad, &stepper, State::new(0.0, q0, v0));
    assert_eq!(
        e,
        StepError::Data(DataError::NonFiniteParameter { index: 1 })
    );

    let mut bad = parabola;
    bad.restitution[0] = 1.5;
    let e = refused(&bad, &stepper, State::new(0.0, q0, v0));
    assert_eq!(
        e,
        StepError::Data(DataError::InvalidRestitution {
            constraint: 0,
            value: 1.5
        })
    );

    let balls = ThreeBalls::<f64> {
        m2: -1.0,
        ..Default::default()
    };
    let (q0, v0) = ThreeBalls::<f64>::initial_state();
    let e = refused(&balls, &stepper, State::new(0.0, q0, v0));
    assert_eq!(e, StepError::Data(DataError::MassNotPositiveDefinite));

    // under the θ-method's laws (here `Slower`) the pinched point has no
    // impulse; the midpoint law (the default) asks `v⁺ + v ≥ 0` of the
    // receding left wall only, and reflects the point off the right one:
    // `v⁺ = −1`, the energy kept, the state back on the grid
    let pinched_state = State::new(
        0.0,
        SVector::<f64, 1>::new(0.0),
        SVector::<f64, 1>::new(1.0),
    );
    let mut params = StepParams::new(1e-3);
    params.gamma = 0.0;
    let mut after = pinched_state;
    MoreauJean::new(params)
        .unwrap()
        .step(
            &pinched::Pinched::<f64>::default(),
            &mut after,
            &SVector::zeros(),
        )
        .unwrap();
    assert_eq!((after.q[0], after.v[0]), (0.0, -1.0));
    params.approach_velocity = ApproachVelocity::Slower;
    let stepper = MoreauJean::new(params).unwrap();
    let e = refused(
        &pinched::Pinched::<f64>::default(),
        &stepper,
        State::new(
            0.0,
            SVector::<f64, 1>::new(0.0),
            SVector::<f64, 1>::new(1.0),
        ),
    );
    assert!(
        matches!(
            e,
            StepError::Data(DataError::Lcp(LcpError::Infeasible { .. }))
        ),
        "{e:?}"
    );

    for (name, tau) in [("tau", 0.0), ("tau", -1e-3), ("tau", f64::NAN)] {
        let e = MoreauJean::new(StepParams::new(tau)).unwrap_err();
        assert!(
            matches!(e, StepError::Data(DataError::InvalidParams { name: n, .. }) if n == name),
            "{e:?}"
        );
    }
    let mut params = StepParams::new(1e-3);
    params.theta = 0.0;
    assert!(MoreauJean::new(params).is_err());
}

/// The stepper is generic over the scalar: Example 1 in `f32` follows the
/// `f64` trajectory through its first impacts (to single-precision
/// accuracy, amplified by the impacts, 1e-3 m over 1.5 s).
#[test]
fn example_1_runs_in_f32() {
    let m64 = Parabola::<f64>::default();
    let m32 = Parabola::<f32>::default();
    let s64 = MoreauJean::new(StepParams::new(1e-3)).unwrap();
    let s32 = MoreauJean::new(StepParams::new(1e-3_f32)).unwrap();
    let (q0, v0) = Parabola::<f64>::initial_state();
    let (q1, v1) = Parabola::<f32>::initial_state();
    let mut a = State::new(0.0, q0, v0);
    let mut b = State::new(0.0_f32, q1, v1);
    let mut impacts = 0;
    for _ in 0..1500 {
        impacts += s64
            .step(&m64, &mut a, &SVector::zeros())
            .unwrap()
            .impacts()
            .count();
        s32.step(&m32, &mut b, &SVector::zeros()).unwrap();
        assert!(
            (a.q - b.q.cast::<f64>()).amax() < 1e-3,
            "{} vs {}",
            a.q,
            b.q
        );
    }
    assert!(impacts >= 3, "{impacts}");
}

/// Issue 9, defect 3: a step whose time cannot advance in the scalar type
/// is refused before anything changes (it used to return `Ok` with `q` and
/// `v` moved and `t` stuck, so a `while t < t_end` loop never ended).
#[test]
fn time_that_cannot_advance_is_an_error() {
    // f32 at t = 32768 s with τ = 1 ms: t + τ == t
    let m32 = Parabola::<f32>::default();
    let (q, v) = Parabola::<f32>::initial_state();
    let s32 = MoreauJean::new(StepParams::new(1e-3_f32)).unwrap();
    assert_eq!(32768.0_f32 + 1e-3, 32768.0);
    let before = State::new(32768.0_f32, q, v);
    let mut state = before;
    let e = s32.step(&m32, &mut state, &SVector::zeros()).unwrap_err();
    assert_eq!(
        e,
        StepError::TimeDoesNotAdvance {
            t: 32768.0,
            tau: 1e-3
        }
    );
    assert_eq!(state, before);
    // f64 at t = 1e17 s
    let m64 = Parabola::<f64>::default();
    let (q, v) = Parabola::<f64>::initial_state();
    let s64 = MoreauJean::new(StepParams::new(1e-3)).unwrap();
    assert_eq!(1e17 + 1e-3, 1e17);
    let before = State::new(1e17, q, v);
    let mut state = before;
    let e = s64.step(&m64, &mut state, &SVector::zeros()).unwrap_err();
    assert!(
        matches!(e, StepError::TimeDoesNotAdvance { t, .. } if t == 1e17),
        "{e:?}"
    );
    assert_eq!(state, before);
    // τ = f64::MIN_POSITIVE: τ²θ² underflows, and 1 + τ == 1
    let e = MoreauJean::new(StepParams::new(f64::MIN_POSITIVE)).unwrap_err();
    assert!(
        matches!(
            e,
            StepError::Data(DataError::InvalidParams { name: "tau", .. })
        ),
        "{e:?}"
    );
    // the limit: 16 ε |t| < τ steps, 16 ε |t| ≥ τ does not (f32, τ = 1 ms:
    // 524.3 s); at 8192 s, where adding τ rounds to 0.977 ms and summed
    // time ran 2.3 % slow, the step is refused
    let limit = 1e-3_f32 / (16.0 * f32::EPSILON);
    let mut state = State::new(limit * 0.999, q.cast(), v.cast());
    assert!(s32.step(&m32, &mut state, &SVector::zeros()).is_ok());
    for t in [limit * 1.001, 8192.0] {
        let mut state = State::new(t, q.cast(), v.cast());
        assert!(matches!(
            s32.step(&m32, &mut state, &SVector::zeros()),
            Err(StepError::TimeDoesNotAdvance { .. })
        ));
    }
}

/// Issue 9, defect 3: time is counted on the grid `kτ`, so it does not
/// drift over long runs: in `f64` over 10⁵ steps `t_k` is `kτ` rounded,
/// bit for bit (summing `τ` is off by 1e-10 s after these steps); in `f32`
/// from `t = 500` s, where adding `τ = 1` ms rounds by up to 1.5 % of it,
/// 1000 steps advance 1 s to within an ulp.
#[test]
fn time_stays_on_the_grid_over_long_runs() {
    let model = Parabola::<f64>::default();
    let (q0, v0) = Parabola::<f64>::initial_state();
    let tau = 1e-3;
    let stepper = MoreauJean::new(StepParams::new(tau)).unwrap();
    let mut state = State::new(0.0, q0, v0);
    let mut summed = 0.0_f64;
    for k in 1..=100_000_u32 {
        stepper.step(&model, &mut state, &SVector::zeros()).unwrap();
        summed += tau;
        assert_eq!(state.t, f64::from(k) * tau, "step {k}");
    }
    eprintln!(
        "f64, 1e5 steps of 1 ms: t = {}, a sum of τ = {summed} (off by {:.1e})",
        state.t,
        (summed - state.t).abs()
    );
    assert!((summed - state.t).abs() > 1e-12);

    let model = Parabola::<f32>::default();
    let (q0, v0) = Parabola::<f32>::initial_state();
    let stepper = MoreauJean::new(StepParams::new(1e-3_f32)).unwrap();
    let mut state = State::new(500.0_f32, q0, v0);
    let mut summed = 500.0_f32;
    for _ in 0..1000 {
        stepper.step(&model, &mut state, &SVector::zeros()).unwrap();
        summed += 1e-3;
    }
    let ulp = 501.0_f32 * f32::EPSILON;
    eprintln!(
        "f32 from 500 s, 1000 steps of 1 ms: t = {}, a sum of τ = {summed}",
        state.t
    );
    assert!((state.t - 501.0).abs() <= ulp, "{}", state.t);
    assert!((summed - 501.0).abs() > 100.0 * ulp);
}
