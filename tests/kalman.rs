//! The saltation Kalman filter end to end, beside the observers (36) and
//! (38): reference trajectories from the plant `MoreauJean` (a step a
//! hundred times finer than the sampling period for Example 1), sampled,
//! with seeded Gaussian noise where stated; the true velocity is the
//! plant's at the sample times, and no estimator ever sees it.
//!
//! Run with `cargo test --release --test kalman -- --nocapture` to see
//! every measured figure.

use moreau::{
    Blocks, DataError, Estimate, IndexSet, KalmanParams, Lcp, Model, Observer, ObserverError,
    ObserverParams, ReducedOrder, SaltationKalman, Sensitivities, State, StepParams,
    pick_by_likelihood, saltation, tune_process_noise,
};
mod common;

use common::runs::{
    Gauss, Reference, Scored, brackets, example_1_run, example_1_starts, figures,
    first_at_or_after, measure, observe_counting, random_example_1_starts, reference, score,
};
use moreau_models::{Arm3, Billiard, Chain4, DoublePendulum, Parabola, ThreeBalls};
use nalgebra::{DMatrix, DVector, SMatrix, SVector, Vector2, Vector3};

// ---------------------------------------------------------------------------
// Reference data (as in tests/observer.rs)

/// Feeds the measurements (from the second on) to any estimator (the
/// filter and the observers alike, through the one `Observer` trait) and
/// returns the estimates, the initial one first.
fn run<O, M, const N: usize, const K: usize>(
    estimator: &mut O,
    model: &M,
    reference: &Reference<N>,
    measured: &[SVector<f64, N>],
    u: &M::Input,
) -> Vec<Estimate<f64, N>>
where
    O: Observer<M, N, K>,
    M: Model<N, K, Scalar = f64>,
{
    let mut estimates = vec![estimator.estimate()];
    for (s, q) in reference.samples.iter().zip(measured).skip(1) {
        estimates.push(
            estimator
                .update(model, s.t, q, u)
                .unwrap_or_else(|e| panic!("t = {}: {e:?} {:?}", s.t, estimator.report())),
        );
    }
    estimates
}

/// The window every Example 1 run here is scored over: `t ∈ [2, 10]` s.
const WINDOW: (f64, f64) = (2.0, 10.0 + 1e-3);

/// [`run`], then its figures over [`WINDOW`].
fn scored<O, M, const N: usize, const K: usize>(
    estimator: &mut O,
    model: &M,
    reference: &Reference<N>,
    measured: &[SVector<f64, N>],
    u: &M::Input,
) -> Scored
where
    O: Observer<M, N, K>,
    M: Model<N, K, Scalar = f64>,
{
    score(
        reference,
        &run(estimator, model, reference, measured, u),
        WINDOW,
    )
}

/// The filter on Example 1 with its defaults for `σ`, from `v̂(0) = 0`,
/// scored as [`scored`] scores it.
fn with_defaults(reference: &Reference<2>, measured: &[Vector2<f64>], sigma: f64) -> Scored {
    with_params(reference, measured, KalmanParams::new(20.0, sigma))
}

/// The filter on Example 1 with `params`, from `v̂(0) = 0`, scored as
/// [`scored`] scores it.
fn with_params(
    reference: &Reference<2>,
    measured: &[Vector2<f64>],
    params: KalmanParams<f64, 2>,
) -> Scored {
    let mut f =
        SaltationKalman::<f64, 2, 2>::new(params, 0.0, measured[0], Vector2::zeros()).unwrap();
    let model = Parabola::<f64>::new();
    scored(&mut f, &model, reference, measured, &SVector::zeros())
}

/// The reduced-order observer (38) on Example 1 with `l_d = 10`, `C_v =
/// 20`, told `σ`, from `v̂(0) = 0`, scored as [`scored`] scores it.
fn reduced_order(reference: &Reference<2>, measured: &[Vector2<f64>], sigma: f64) -> Scored {
    let params = ObserverParams::new(10.0, 20.0).with_noise(sigma);
    let mut o = ReducedOrder::<f64, 2, 2>::new(params, 0.0, measured[0], Vector2::zeros()).unwrap();
    let model = Parabola::<f64>::new();
    scored(&mut o, &model, reference, measured, &SVector::zeros())
}

/// The filter's figures `filter` within the range of the hand-written
/// Python saltation filter the issue measured (median ≤ 1e-4, 90th
/// percentile ≤ 4e-4) and its median ten times below that of (38),
/// `observer`, on the same samples; `at` names the run.
fn assert_beside_python_and_38(filter: &Scored, observer: &Scored, at: &str) {
    assert!(
        filter.all.median <= 1e-4 && filter.all.p90 <= 4e-4,
        "{at}: median {:e}, p90 {:e}",
        filter.all.median,
        filter.all.p90
    );
    assert!(filter.all.median * 10.0 <= observer.all.median, "{at}");
}

// ---------------------------------------------------------------------------
// Saltation matrices against finite differences of flow–impact–flow

/// The state `(q, v)` as one vector of length `2N` (a `DVector`: the test
/// may allocate).
fn stack<const N: usize>(q: &SVector<f64, N>, v: &SVector<f64, N>) -> DVector<f64> {
    DVector::from_iterator(2 * N, q.iter().chain(v.iter()).copied())
}

fn unstack<const N: usize>(x: &DVector<f64>) -> (SVector<f64, N>, SVector<f64, N>) {
    (
        SVector::from_fn(|i, _| x[i]),
        SVector::from_fn(|i, _| x[N + i]),
    )
}

/// `A⁻¹ B` by a dense LU (tests may allocate).
fn solve<const N: usize, const C: usize>(
    a: &SMatrix<f64, N, N>,
    b: &SMatrix<f64, N, C>,
) -> SMatrix<f64, N, C> {
    let x = DMatrix::from_fn(N, N, |i, j| a[(i, j)])
        .lu()
        .solve(&DMatrix::from_fn(N, C, |i, j| b[(i, j)]))
        .unwrap();
    SMatrix::from_fn(|i, j| x[(i, j)])
}

/// One classical Runge–Kutta step of the free dynamics.
fn rk4_step<M, const N: usize, const K: usize>(
    model: &M,
    u: &M::Input,
    x: &DVector<f64>,
    h: f64,
) -> DVector<f64>
where
    M: Model<N, K, Scalar = f64>,
{
    let f = |x: &DVector<f64>| {
        let (q, v) = unstack::<N>(x);
        let (m, force) = model.dynamics(0.0, &q, &v, u);
        let a = solve(&m, &(-force));
        stack(&v, &a)
    };
    let k1 = f(x);
    let k2 = f(&(x + &k1 * (h / 2.0)));
    let k3 = f(&(x + &k2 * (h / 2.0)));
    let k4 = f(&(x + &k3 * h));
    x + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
}

/// The free flow over `t` (either sign) in steps of at most `1e-5`.
fn flow<M, const N: usize, const K: usize>(
    model: &M,
    u: &M::Input,
    x: &DVector<f64>,
    t: f64,
) -> DVector<f64>
where
    M: Model<N, K, Scalar = f64>,
{
    let steps = (t.abs() / 1e-5).ceil().max(1.0) as usize;
    let h = t / steps as f64;
    (0..steps).fold(x.clone(), |x, _| rk4_step::<M, N, K>(model, u, &x, h))
}

/// Free flow from `x0` until the gap `guard` closes: returns the state
/// there and the time taken (root to round-off by the secant method on the
/// length of the last Runge–Kutta step).
fn flow_to_guard<M, const N: usize, const K: usize>(
    model: &M,
    u: &M::Input,
    x0: &DVector<f64>,
    guard: usize,
) -> (DVector<f64>, f64)
where
    M: Model<N, K, Scalar = f64>,
{
    let gap = |x: &DVector<f64>| model.gaps(&unstack::<N>(x).0)[guard];
    let h = 1e-5;
    let (mut x, mut t) = (x0.clone(), 0.0);
    loop {
        let next = rk4_step::<M, N, K>(model, u, &x, h);
        if gap(&next) <= 0.0 {
            let (mut a, mut fa, mut b, mut fb) = (0.0, gap(&x), h, gap(&next));
            for _ in 0..60 {
                if fb == fa || (b - a).abs() < 1e-18 {
                    break;
                }
                let c = b - fb * (b - a) / (fb - fa);
                let fc = gap(&rk4_step::<M, N, K>(model, u, &x, c));
                (a, fa, b, fb) = (b, fb, c, fc);
            }
            return (rk4_step::<M, N, K>(model, u, &x, b), t + b);
        }
        (x, t) = (next, t + h);
        assert!(t < 1.0, "the guard never closes");
    }
}

/// Newton's law by the LCP on `set`, `e` as applied.
fn newton_reset<M, const N: usize, const K: usize>(
    model: &M,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
    set: IndexSet<K>,
    e: &SVector<f64, K>,
) -> (SVector<f64, N>, SVector<f64, K>)
where
    M: Model<N, K, Scalar = f64>,
{
    let m = model.mass(q);
    let jac = model.gap_jacobian(q);
    let minv_jt = solve(&m, &jac.transpose());
    let w = jac * minv_jt;
    let b = jac * v + e.component_mul(&(jac * v));
    let lambda = Lcp::default().solve(&w, &b, set).unwrap().lambda;
    (v + minv_jt * lambda, lambda)
}

/// Flow from `x0` through the impact on `guard` (Newton's law on `set`),
/// then on to `t_end` in all; with `delay ≠ 0` the impact comes `delay`
/// after the gap's root, the free motion continuing into the constraint
/// until then (a late impact, as the plant's).
fn flow_impact_flow<M, const N: usize, const K: usize>(
    model: &M,
    u: &M::Input,
    x0: &DVector<f64>,
    guard: usize,
    (set, e): (IndexSet<K>, &SVector<f64, K>),
    (delay, t_end): (f64, f64),
) -> DVector<f64>
where
    M: Model<N, K, Scalar = f64>,
{
    let (x, t) = flow_to_guard::<M, N, K>(model, u, x0, guard);
    let x = if delay == 0.0 {
        x
    } else {
        flow::<M, N, K>(model, u, &x, delay)
    };
    let (q, v) = unstack::<N>(&x);
    let (v_plus, _) = newton_reset::<M, N, K>(model, &q, &v, set, e);
    flow::<M, N, K>(model, u, &stack(&q, &v_plus), t_end - t - delay)
}

/// Jacobian of `f` at `x` by central differences.
fn jacobian_fd(f: impl Fn(&DVector<f64>) -> DVector<f64>, x: &DVector<f64>) -> DMatrix<f64> {
    let n = x.len();
    let mut jac = DMatrix::zeros(n, n);
    for j in 0..n {
        let step = 1e-6 * x[j].abs().max(1.0);
        let mut plus = x.clone();
        plus[j] += step;
        let mut minus = x.clone();
        minus[j] -= step;
        jac.set_column(j, &((f(&plus) - f(&minus)) / (2.0 * step)));
    }
    jac
}

fn dense<const N: usize>(b: &Blocks<f64, N>) -> DMatrix<f64> {
    DMatrix::from_fn(2 * N, 2 * N, |i, j| b.entry(i, j))
}

/// Moves `q` onto `h_guard = 0` along the gradient (Newton).
fn onto<M, const N: usize, const K: usize>(
    model: &M,
    mut q: SVector<f64, N>,
    guard: usize,
) -> SVector<f64, N>
where
    M: Model<N, K, Scalar = f64>,
{
    for _ in 0..50 {
        let (h, jac) = model.contact(&q);
        let g = jac.row(guard).transpose();
        q -= g * (h[guard] / g.norm_squared());
    }
    q
}

/// The saltation matrix at `(q*, v*)` (`q*` on `h_guard = 0`, `v*`
/// approaching) against finite differences: with `δ = 1 ms` of free flow
/// before and after, the Jacobian of flow–impact–flow from `x(−δ)` equals
/// `Φ_after · Ξ · Φ_before`, both flows' Jacobians by finite differences
/// too. Returns the relative error.
fn saltation_error<M, const N: usize, const K: usize>(
    model: &M,
    u: &M::Input,
    q_star: SVector<f64, N>,
    v_star: SVector<f64, N>,
    guard: usize,
    set: IndexSet<K>,
    e: SVector<f64, K>,
) -> (f64, usize)
where
    M: Sensitivities<N, K, Scalar = f64>,
{
    saltation_error_of(model, u, (q_star, v_star), guard, set, (e, e))
}

/// [`saltation_error`] with the law of the flow (Newton's on `set` with
/// `e_flow`) and the restitutions the saltation matrix is computed with
/// (`e_saltation`, on the constraints the flow's impulse acts on) told
/// apart.
fn saltation_error_of<M, const N: usize, const K: usize>(
    model: &M,
    u: &M::Input,
    (q_star, v_star): (SVector<f64, N>, SVector<f64, N>),
    guard: usize,
    set: IndexSet<K>,
    (e, e_saltation): (SVector<f64, K>, SVector<f64, K>),
) -> (f64, usize)
where
    M: Sensitivities<N, K, Scalar = f64>,
{
    let delta = 1e-3;
    let x_star = stack(&q_star, &v_star);
    let x0 = flow::<M, N, K>(model, u, &x_star, -delta);
    // the impact the finite differences see: the LCP's active set
    let (x_minus, t_hit) = flow_to_guard::<M, N, K>(model, u, &x0, guard);
    let (q_hit, v_hit) = unstack::<N>(&x_minus);
    let (v_plus, lambda) = newton_reset::<M, N, K>(model, &q_hit, &v_hit, set, &e);
    assert!(
        lambda.iter().any(|&l| l > 0.0),
        "{}: no impulse, no impact",
        M::INFO.name
    );
    let active =
        IndexSet::from_indices(&(0..K).filter(|&i| lambda[i] > 0.0).collect::<Vec<_>>()).unwrap();
    let salt = saltation(
        model,
        0.0,
        &q_hit,
        &v_hit,
        u,
        active,
        &e_saltation,
        Some(guard),
    )
    .unwrap();
    let x_plus = stack(&q_hit, &v_plus);
    let total = jacobian_fd(
        |x| flow_impact_flow::<M, N, K>(model, u, x, guard, (set, &e), (0.0, 2.0 * delta)),
        &x0,
    );
    let before = jacobian_fd(|x| flow::<M, N, K>(model, u, x, t_hit), &x0);
    let after = jacobian_fd(
        |x| flow::<M, N, K>(model, u, x, 2.0 * delta - t_hit),
        &x_plus,
    );
    let predicted = &after * dense(&salt.matrix) * &before;
    let error = (&total - &predicted).abs().max() / total.abs().max();
    // the check can fail: the reset's Jacobian alone, without the moving
    // impact time, is far off
    let reset = Blocks {
        qq: SMatrix::identity(),
        qv: SMatrix::zeros(),
        vq: salt.reset_dq,
        vv: salt.reset_dv,
    };
    let without_time = (&total - &after * dense(&reset) * &before).abs().max() / total.abs().max();
    assert!(
        without_time > 1e-2,
        "{} without the time term: {without_time:e}",
        M::INFO.name
    );
    (error, active.len())
}

/// Every shipped model, every kind of impact it has: a single constraint
/// on a flat or curved surface (Parabola's floor and ceiling, the
/// billiard's inward-curving wall, the double pendulum's wall and floor,
/// the arm's wall with its configuration-dependent mass), and the three
/// balls' simultaneous impact (ball 1 hits the resting pair 2–3: the LCP
/// ends with two active constraints, one elastic and one plastic).
#[test]
fn saltation_matrices_match_finite_differences_of_flow_impact_flow() {
    let mut worst: f64 = 0.0;
    let mut check = |name: &str, (err, active): (f64, usize)| {
        eprintln!("saltation {name}: {active} active, relative error {err:.2e}");
        // the balls' impact ends with both contacts active; every other
        // case with its one constraint
        assert_eq!(active, if name.contains("pair") { 2 } else { 1 }, "{name}");
        assert!(err < 1e-5, "{name}: {err:e}");
        worst = worst.max(err);
    };
    let p = Parabola::<f64>::new();
    let u0 = SVector::<f64, 0>::zeros();
    check(
        "Parabola floor",
        saltation_error(
            &p,
            &u0,
            Vector2::new(1.0, 1.0),
            Vector2::new(-1.0, -5.0),
            0,
            IndexSet::from_indices(&[0]).unwrap(),
            Vector2::new(0.9, 0.0),
        ),
    );
    check(
        "Parabola floor, plastic",
        saltation_error(
            &p,
            &u0,
            Vector2::new(-0.5, 0.25),
            Vector2::new(-2.0, -1.5),
            0,
            IndexSet::from_indices(&[0]).unwrap(),
            Vector2::new(0.0, 0.0),
        ),
    );
    check(
        "Parabola ceiling",
        saltation_error(
            &p,
            &u0,
            Vector2::new(0.5, 8.0),
            Vector2::new(1.0, 3.0),
            1,
            IndexSet::from_indices(&[1]).unwrap(),
            Vector2::new(0.0, 0.9),
        ),
    );
    let b = Billiard::<f64>::new();
    check(
        "Billiard right wall",
        saltation_error(
            &b,
            &u0,
            Vector2::new(0.2, 0.0),
            Vector2::new(1.0, 0.5),
            0,
            IndexSet::from_indices(&[0]).unwrap(),
            SVector::<f64, 4>::repeat(0.8),
        ),
    );
    let d = DoublePendulum::<f64>::new();
    let q = onto::<_, 2, 2>(&d, Vector2::new(0.5, 0.7), 0);
    check(
        "DoublePendulum wall",
        saltation_error(
            &d,
            &u0,
            q,
            Vector2::new(1.0, 2.0),
            0,
            IndexSet::from_indices(&[0]).unwrap(),
            Vector2::new(0.8, 0.0),
        ),
    );
    let q = onto::<_, 2, 2>(&d, Vector2::new(0.3, 0.87), 1);
    check(
        "DoublePendulum floor",
        saltation_error(
            &d,
            &u0,
            q,
            Vector2::new(-1.0, -1.0),
            1,
            IndexSet::from_indices(&[1]).unwrap(),
            Vector2::new(0.0, 0.8),
        ),
    );
    let a = Arm3::<f64>::new();
    let u3 = SVector::<f64, 3>::zeros();
    let q = onto::<_, 3, 1>(&a, Vector3::new(0.9, -0.6, -0.4), 0);
    let grad = a.gap_jacobian(&q).row(0).transpose();
    let v = -grad * 2.0 + Vector3::new(0.3, -0.2, 0.1);
    assert!(a.gap_jacobian(&q).row(0).dot(&v.transpose()) < 0.0);
    check(
        "Arm3 wall",
        saltation_error(
            &a,
            &u3,
            q,
            v,
            0,
            IndexSet::full(1),
            SVector::<f64, 1>::new(0.5),
        ),
    );
    let t = ThreeBalls::<f64>::new();
    let r = 0.125;
    let q = Vector3::new(1.0, 1.0 + 2.0 * r, 1.0 + 4.0 * r);
    check(
        "ThreeBalls 1 on the resting pair",
        saltation_error(
            &t,
            &u0,
            q,
            Vector3::new(2.0, 0.0, 0.0),
            1,
            IndexSet::from_indices(&[1, 2]).unwrap(),
            SVector::<f64, 4>::new(0.0, 0.9, 0.0, 0.0),
        ),
    );
    check(
        "ThreeBalls left wall",
        saltation_error(
            &t,
            &u0,
            Vector3::new(r, 1.0, 1.5),
            Vector3::new(-1.5, 0.3, 0.0),
            0,
            IndexSet::from_indices(&[0]).unwrap(),
            SVector::<f64, 4>::new(0.7, 0.0, 0.0, 0.0),
        ),
    );
    eprintln!("worst {worst:.2e}");
}

/// Where Newton's law with each constraint's own restitution would put
/// energy in, the contact rule applies Moreau's law with the least
/// restitution of the set instead (`runtime/src/observer/interval.rs`,
/// `gains_energy`), and the filter maps its covariance through Newton's
/// saltation with that least restitution on every constraint the impulse
/// acts on (`runtime/src/observer/kalman/propagate.rs`, `Law::Moreau`):
/// Moreau's law `w⁺ = w_p + e (w_p − w⁻)` is Newton's with one `e` on the
/// set. Checked against finite differences of flow–Moreau–flow on the
/// three balls: ball 1 runs into ball 2 at 1 m/s while 2 and 3 touch and
/// part at 0.3 m/s; the contact rule gives the approach `e` = 0.9 and
/// the closed, separating contact 0 (a plastic closure). Newton's law with
/// those gains energy here (asserted), Moreau's with the least, 0, takes
/// its place, and its saltation matches to 1e-5; Newton's saltation with
/// each constraint's own restitution, which the filter used there before
/// the interval told it the law, is off by more than 10 %.
#[test]
fn moreaus_law_has_the_saltation_of_newtons_with_the_least_restitution() {
    let t = ThreeBalls::<f64>::new();
    let u = SVector::<f64, 0>::zeros();
    let r = 0.125;
    let q = Vector3::new(1.0, 1.0 + 2.0 * r, 1.0 + 4.0 * r);
    let v = Vector3::new(1.0, 0.0, 0.3);
    let set = IndexSet::from_indices(&[1, 2]).unwrap();
    let own = SVector::<f64, 4>::new(0.0, 0.9, 0.0, 0.0);
    let least = SVector::<f64, 4>::zeros();
    let energy = |w: &Vector3<f64>| 0.5 * w.norm_squared();
    let (newton, _) = newton_reset::<_, 3, 4>(&t, &q, &v, set, &own);
    eprintln!(
        "three balls: kinetic energy {:.4} before, {:.4} after Newton's law with each constraint's own restitution",
        energy(&v),
        energy(&newton)
    );
    assert!(energy(&newton) > energy(&v) + 1e-3);
    let (moreau, active) = saltation_error_of(&t, &u, (q, v), 1, set, (least, least));
    let (approximation, _) = saltation_error_of(&t, &u, (q, v), 1, set, (least, own));
    eprintln!(
        "Moreau's law, {active} active: saltation with the least restitution {moreau:.2e}, with each constraint's own {approximation:.2e}"
    );
    assert_eq!(active, 2);
    assert!(moreau < 1e-5, "{moreau:e}");
    assert!(approximation > 0.1, "{approximation:e}");
}

// ---------------------------------------------------------------------------
// Consistency where the noise model is true

/// Why [`KalmanParams::impact_delay`] exists, measured on the plant the
/// figures use: `MoreauJean` at `τ = 10 µs` takes an impact into the step
/// in which the γ-prediction sees it and resolves it at the step's end, so
/// against the exact event-driven solution ([`common::exact`]) its impacts
/// come late by about `τ/2` on average, spread about as a uniform delay
/// over a step is (`τ/√12`). Example 1, the first impact of each of 60
/// random starts, read 0.2 ms after it: the plant's position below the
/// exact one along the normal, divided by `(1 + e)` times the approach
/// speed, is the delay. Measured: mean 0.47 τ, standard deviation 0.27 τ;
/// asserted within four standard errors of the mean of `τ/2` (the mean of
/// 60 draws of a uniform delay has a standard error of 0.037 τ).
#[test]
fn the_plants_impacts_come_half_a_step_late() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let tau = 1e-5;
    let e = model.restitution()[0];
    let mut g = Gauss::new(4242);
    let mut delays = Vec::new();
    for _ in 0..60 {
        let x = 2.0 * g.uniform() - 1.0;
        let y = x * x + 0.5 + 4.0 * g.uniform();
        let v = Vector2::new(6.0 * g.uniform() - 3.0, 6.0 * g.uniform() - 3.0);
        let start = (Vector2::new(x, y), v);
        let Some(exact) = common::exact::parabola(start, 3.0, 1e-4) else {
            continue;
        };
        let plant = reference(&model, start, tau, 10, 3.0, &u);
        let Some(&(t_impact, 0, approach)) = exact.impacts.first() else {
            continue;
        };
        let k = (t_impact / 1e-4).ceil() as usize + 2;
        if exact
            .impacts
            .get(1)
            .is_some_and(|next| next.0 < k as f64 * 1e-4)
        {
            continue;
        }
        let (a, b) = (&exact.samples[k], &plant.samples[k]);
        assert!((a.t - b.t).abs() < 1e-12);
        let normal = Vector2::new(-2.0 * a.q[0], 1.0).normalize();
        delays.push(-normal.dot(&(b.q - a.q)) / ((1.0 + e) * approach));
    }
    let n = delays.len() as f64;
    let mean = delays.iter().sum::<f64>() / n;
    let sd = (delays.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / n).sqrt();
    eprintln!(
        "plant's impact delay over {n} first impacts: mean {:.3} τ, standard deviation {:.3} τ",
        mean / tau,
        sd / tau
    );
    assert!(n >= 40.0, "{n} impacts");
    assert!((mean / tau - 0.5).abs() < 0.15, "mean {:e}", mean / tau);
    assert!(
        (sd / tau - 0.289).abs() < 0.1,
        "standard deviation {:e}",
        sd / tau
    );
}

/// What the plant's impact error is: an exact impact, delayed. For a
/// Moreau–Jean step at `θ = 1/2` that resolves the impact at the end of
/// the step whose γ-prediction sees it, a first-order expansion (a gap
/// with constant normal acceleration, the root at `s` into the step)
/// gives the end state of an exact impact delayed by `τ/2 − s` in
/// position and by `τ/(1 + e) − s` in velocity: one delay, up to the
/// constant `τ (1/(1 + e) − 1/2)` (0.026 τ at `e = 0.9`). Example 1 from
/// (0.2, 1), every plant impact in its first 6.6 s with no other within
/// 0.3 ms before it or 0.3 ms after (approach speeds from about 0.1 to
/// 5 m/s): the exact flow–impact–flow from three plant steps before the
/// impact, compared 0.2 ms after it with the plant; the delay read from
/// the position along the normal and from the velocity along its shift
/// per unit of delay (both shifts by a finite difference of that flow).
/// Measured: the two delays differ by the constant to 0.009 τ, and the
/// velocity error left once the position's delay is taken out is 3e-6 to
/// 1.6e-5 m/s, against 8e-6 to 4.5e-4 m/s of error. So the delay, not
/// some other error of the plant's law, is what the filter's
/// `impact_time_sigma` and `impact_delay` describe, with the velocity's
/// constant on top, which [`KalmanParams::plant`] takes from the plant's
/// own step at each impact; what a run's samples cannot tell is each
/// impact's own delay, spread over a step.
#[test]
fn the_plants_impacts_are_exact_impacts_delayed() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let tau = 1e-5;
    let e = model.restitution();
    let offset = 1.0 / (1.0 + e[0]) - 0.5;
    let start = (Vector2::new(0.2, 1.0), Vector2::new(1.0, -2.0));
    let plant = reference(&model, start, tau, 1, 6.6, &u);
    let impacts = &plant.impacts;
    let (mut checked, mut worst_offset, mut worst_left) = (0, 0.0_f64, 0.0_f64);
    for (j, &(t_hit, i, _)) in impacts.iter().enumerate() {
        let isolated = impacts.get(j + 1).is_none_or(|n| n.0 > t_hit + 3e-4)
            && (j == 0 || impacts[j - 1].0 < t_hit - 3e-4);
        if i != 0 || t_hit < 0.01 || !isolated {
            continue;
        }
        let before = plant.samples[(t_hit / tau).round() as usize - 3];
        let after = plant.samples[((t_hit + 2e-4) / tau).round() as usize];
        let x0 = stack(&before.q, &before.v);
        let floor = IndexSet::from_indices(&[0]).unwrap();
        let exact = |delay: f64| -> (SVector<f64, 2>, SVector<f64, 2>) {
            let t_end = after.t - before.t;
            unstack::<2>(&flow_impact_flow::<Parabola<f64>, 2, 2>(
                &model,
                &u,
                &x0,
                0,
                (floor, &e),
                (delay, t_end),
            ))
        };
        let (q, v) = exact(0.0);
        let (q1, v1) = exact(1e-6);
        let (dq, dv) = ((q1 - q) / 1e-6, (v1 - v) / 1e-6);
        let (eq, ev) = (after.q - q, after.v - v);
        let normal = Vector2::new(-2.0 * q[0], 1.0).normalize();
        let from_position = normal.dot(&eq) / normal.dot(&dq);
        let from_velocity = dv.dot(&ev) / dv.dot(&dv);
        let left = (ev - dv * from_position).norm();
        eprintln!(
            "impact at {t_hit:.5} s: delay from the position {:.3} τ, from the velocity {:.3} τ; velocity error {:.2e}, {left:.2e} once the position's delay is taken out",
            from_position / tau,
            from_velocity / tau,
            ev.norm()
        );
        checked += 1;
        worst_offset = worst_offset.max(((from_velocity - from_position) / tau - offset).abs());
        worst_left = worst_left.max(left);
    }
    eprintln!(
        "{checked} impacts: the delays differ from τ (1/(1 + e) − 1/2) by at most {worst_offset:.3} τ; velocity error left at most {worst_left:.2e}"
    );
    assert!(checked >= 20, "{checked} impacts");
    assert!(worst_offset < 0.02, "{worst_offset}");
    assert!(worst_left < 3e-5, "{worst_left:e}");
}

/// Told the plant on its grid, the filter takes each impact into the
/// step the plant takes it into (module `grid` of the filter). Example 1,
/// 24 random starts (seed 4242), the plant at `τ = 10 µs` sampled at
/// 1 kHz: every impact approached faster than 0.5 m/s alone in its
/// sampling interval, with none in the 2 ms before. From the plant's
/// exact state at the sample before it, with a covariance of 1e-16 (the
/// predicted instant's deviation a few nanoseconds, so the step is
/// known) and the sample after it all but ignored (`R = I` m²), the
/// filter's velocity at that sample against the plant's. On the grid the
/// filter takes the plant's own step from the plant's own state there
/// (Example 1's free flight is exact for both), so only rounding is left;
/// off it (`with_plant_grid(false)`) it takes the step from the impact
/// (the mean of a uniform phase), off by the impact's own phase times
/// the velocity's shift per unit of delay. Measured: 106 impacts, on the
/// grid at most 6.7e-14 m/s, off it a median of 5.1e-5 m/s (at most
/// 1.1e-3).
#[test]
fn on_the_plants_grid_the_filter_takes_each_impact_into_the_plants_step() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let tau = 1e-5;
    let (mut on, mut off) = (Vec::new(), Vec::new());
    for start in random_example_1_starts(4242, 24) {
        let plant = reference(&model, start, tau, 100, 3.0, &u);
        let times: Vec<f64> = plant.impacts.iter().map(|i| i.0).collect();
        for &(t, _, approach) in &plant.impacts {
            let k = plant.samples.iter().rposition(|s| s.t < t - 1e-12).unwrap();
            let (before, after) = (&plant.samples[k], &plant.samples[k + 1]);
            let alone = times
                .iter()
                .filter(|&&o| o > before.t - 2e-3 && o <= after.t + 1e-12)
                .count()
                == 1;
            if approach < 0.5 || !alone || k == 0 {
                continue;
            }
            let predicted = |grid: bool| {
                let params = KalmanParams {
                    measurement: SMatrix::identity(),
                    ..KalmanParams::new(20.0, 1e-6)
                        .with_plant_step(tau)
                        .with_plant_grid(grid)
                };
                let p0 = Blocks::diagonal(SMatrix::identity() * 1e-16, SMatrix::identity() * 1e-16);
                let mut f = SaltationKalman::<f64, 2, 2>::with_covariance(
                    params, before.t, before.q, before.v, p0,
                )
                .unwrap();
                let e = f.update(&model, after.t, &after.q, &u).unwrap();
                (e.v - after.v).norm()
            };
            on.push(predicted(true));
            off.push(predicted(false));
        }
    }
    let n = on.len();
    let (on, off) = (figures(&on), figures(&off));
    eprintln!(
        "{} impacts: velocity off the plant's on its grid at most {:.1e} m/s; off the grid median {:.1e}, at most {:.1e}",
        n, on.max, off.median, off.max
    );
    assert!(on.max <= 1e-10, "on the grid {:e}", on.max);
    assert!(off.median >= 1e-5, "off the grid {:e}", off.median);
}

/// What the plant's step alone hides, measured against a Bayes estimate
/// that knows everything else (`tests/common/phase.rs`): the plant's
/// state at the last sample before each impact, and the plant itself, but
/// not where its step grid falls against the impact (200 phases over a
/// step, weighed by the likelihood of the noisy samples since). On the
/// twelve random starts of seed 555 at σ = 1e-4 (noise seeds as in
/// `example_1_random_starts_beside_the_reduced_order_observer`):
///
/// - phase 0 of the oracle's family is the plant (positions within 1e-9
///   m): the family holds the truth;
/// - the oracle meets the issue's median (3e-5) and 90th percentile
///   (2e-4) on every run, so the plant's step, unknown at each impact,
///   does not by itself put them out of reach (the filter meets both on
///   four of these twelve with its defaults, on ten told the plant): what
///   an estimator does not know before the impact adds the rest
///   (`the_filter_beside_the_gaussian_posterior`);
/// - the filter, restarted as the oracle is from the exact state before
///   each impact and told the plant's step off its grid
///   ([`KalmanParams::with_plant_step`] with
///   [`KalmanParams::with_plant_grid`] `false`: the plant's own step at
///   each impact, the spread `τ/√12` of a uniform phase, exact jumps), is
///   a Gaussian stand-in for that posterior and as good as it: its median
///   error in flight is within 1.5 times the oracle's in the median over
///   the runs and within 2.5 times on each (measured 0.95 to 1.71, median
///   1.08). On the grid (the default), it knows what the oracle does not,
///   the step each impact falls in, and from the exact state is all but
///   exact: 0.02 times the oracle in the median over the runs (0.00 to
///   0.27; asserted within a quarter). Told `τ/2` as one delay of position and velocity alike, with
///   the default relative error of a jump (`ρ_i = 1e-5`, about 1e-4 m/s
///   on these jumps), it is 1.81 (printed): the jump's error costs that
///   much here, while the velocity's own delay matters inside
///   accumulations, which a restart at every impact does not let build up
///   (`a_single_delay_drifts_inside_an_accumulation`). With the defaults
///   (no mean delay) it is 2.58 (printed).
///
/// `cargo test --release --test kalman -- --nocapture step_alone` (30 s)
#[test]
fn what_the_plants_step_alone_hides() {
    use common::phase::{TAU, oracle, plant, restarted};
    let sigma = 1e-4;
    let on_grid = KalmanParams::new(20.0, sigma).with_plant_step(TAU);
    let told = on_grid.with_plant_grid(false);
    let single = one_delay(TAU, sigma);
    let (mut ratios, mut ratios_single, mut ratios_defaults) = (Vec::new(), Vec::new(), Vec::new());
    let mut ratios_grid = Vec::new();
    for (n, start) in random_example_1_starts(555, 12).into_iter().enumerate() {
        let run = plant(start, 10.0);
        let noisy = Reference {
            samples: run.samples.clone(),
            impacts: Vec::new(),
        };
        let measured = measure(&noisy, sigma, 100 + n as u64);
        let bound = oracle(&run, &measured, sigma, 200);
        assert!(
            bound.phase_zero_off < 1e-9,
            "start {n}: {:e}",
            bound.phase_zero_off
        );
        let scored = |errors: &[f64], flight_only: bool| {
            let picked: Vec<f64> = run
                .samples
                .iter()
                .zip(errors)
                .zip(&bound.flight)
                .filter(|((s, _), f)| (2.0..10.0 - 1e-9).contains(&s.t) && (**f || !flight_only))
                .map(|((_, &e), _)| e)
                .collect();
            figures(&picked)
        };
        let (all, in_flight) = (scored(&bound.errors, false), scored(&bound.errors, true));
        let with_told = scored(&restarted(&run, &measured, told), true);
        let with_grid = scored(&restarted(&run, &measured, on_grid), true);
        let with_single = scored(&restarted(&run, &measured, single), true);
        let with_defaults = scored(
            &restarted(&run, &measured, KalmanParams::new(20.0, sigma)),
            true,
        );
        eprintln!(
            "seed 555, start {n}: the oracle's median {:.2e}, p90 {:.2e} (in flight {:.2e}); the filter restarted as the oracle, in flight: told the step off its grid {:.2e} ({:.2}×), on it {:.2e} ({:.2}×), told τ/2 as one delay {:.2e} ({:.2}×), defaults {:.2e} ({:.2}×)",
            all.median,
            all.p90,
            in_flight.median,
            with_told.median,
            with_told.median / in_flight.median,
            with_grid.median,
            with_grid.median / in_flight.median,
            with_single.median,
            with_single.median / in_flight.median,
            with_defaults.median,
            with_defaults.median / in_flight.median,
        );
        assert!(all.median <= 3e-5 && all.p90 <= 2e-4, "start {n}: {all:?}");
        let ratio = with_told.median / in_flight.median;
        assert!(ratio <= 2.5, "start {n}: {ratio}");
        ratios.push(ratio);
        ratios_grid.push(with_grid.median / in_flight.median);
        ratios_single.push(with_single.median / in_flight.median);
        ratios_defaults.push(with_defaults.median / in_flight.median);
    }
    let (told_median, grid_median, single_median, defaults_median) = (
        figures(&ratios).median,
        figures(&ratios_grid).median,
        figures(&ratios_single).median,
        figures(&ratios_defaults).median,
    );
    eprintln!(
        "restarted filter over the oracle in flight, median over the runs: told the step off its grid {told_median:.2}, on it {grid_median:.2}, told τ/2 as one delay {single_median:.2}, defaults {defaults_median:.2}"
    );
    assert!(told_median <= 1.5, "{told_median}");
    assert!(grid_median <= 0.25, "{grid_median}");
}

/// [`KalmanParams::impact_delay`]: a mean delay `δ̄` of each impact moves
/// the predicted end of the interval as a flow–impact–flow whose impact
/// comes `δ̄` after the gap closes (the motion continuing into the
/// constraint for `δ̄`, then Newton's law, then the flow to the end),
/// to first order in `δ̄`. Example 1 from just above the floor: the impact
/// after about 1.1 ms, the interval 200 ms long, so that the velocity
/// part of the delay's shift (the change of acceleration the jump makes,
/// and the normal's turn along the curved floor) has time to show in the
/// position as well. The predicted position is the sample minus the
/// innovation, whatever the sample.
#[test]
fn a_mean_impact_delay_moves_the_prediction_as_a_delayed_impact_does() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let (q0, v0) = (Vector2::new(0.3, 0.09 + 4e-3), Vector2::new(1.0, -3.0));
    let t_end = 0.2;
    let e = model.restitution();
    // the truth, the impact delayed by `delay` past the gap's root
    let floor = IndexSet::from_indices(&[0]).unwrap();
    let truth = |delay: f64| -> SVector<f64, 2> {
        let x0 = stack(&q0, &v0);
        let x = flow_impact_flow::<Parabola<f64>, 2, 2>(
            &model,
            &u,
            &x0,
            0,
            (floor, &e),
            (delay, t_end),
        );
        unstack::<2>(&x).0
    };
    let predicted = |delay: f64| -> SVector<f64, 2> {
        // a filter sure of its velocity, as after its first samples (a
        // fresh one, `C_v` unsure, cannot tell an impact from a closure)
        let params = KalmanParams {
            impact_delay: delay,
            initial_velocity_sigma: 1e-3,
            ..KalmanParams::new(20.0, 1e-4)
        };
        let mut f = SaltationKalman::<f64, 2, 2>::new(params, 0.0, q0, v0).unwrap();
        let sample = truth(0.0);
        Observer::<Parabola<f64>, 2, 2>::update(&mut f, &model, t_end, &sample, &u).unwrap();
        assert_eq!(f.kalman_report().saltations, 1);
        sample - Observer::<Parabola<f64>, 2, 2>::report(&f).innovation
    };
    let (base, exact) = (predicted(0.0), truth(0.0));
    for delay in [2e-6, -2e-6, 5e-6] {
        let moved = predicted(delay) - base;
        let expected = truth(delay) - exact;
        let err = (moved - expected).norm() / expected.norm();
        eprintln!(
            "δ̄ = {delay:e}: prediction moved {:?}, the delayed impact {:?}: relative error {err:.2e}",
            moved.as_slice(),
            expected.as_slice()
        );
        // first order: the error is O(δ̄) relative to the shift (measured
        // 1e-5 to 3e-5; without the velocity part of the shift, carried
        // over the 200 ms, it would be 0.6)
        assert!(err < 1e-3, "δ̄ = {delay:e}: {err:e}");
    }
}

/// The filter's defaults for `σ`, told a plant's step of `tau` as one
/// delay of position and velocity alike: `impact_delay` = τ/2 and
/// `impact_time_sigma` = τ/√12, the moments of a delay uniform over a step
/// (what `with_plant_step` replaced).
fn one_delay(tau: f64, sigma: f64) -> KalmanParams<f64, 2> {
    KalmanParams {
        impact_delay: tau / 2.0,
        impact_time_sigma: tau / 12f64.sqrt(),
        ..KalmanParams::new(20.0, sigma)
    }
}

/// Why [`KalmanParams::plant`] takes the plant's own step at each impact
/// instead of delaying it by `τ/2`: the plant's impacts are exact impacts
/// delayed by `τ/2 − s` in position but by `τ/(1 + e) − s` in velocity
/// (`the_plants_impacts_are_exact_impacts_delayed`), and inside an
/// accumulation of impacts a mean error in the velocity's delay builds up
/// bounce by bounce into an error the samples hardly see.
/// The model file's start, the 22 bounces from 4.36 s to 4.44 s
/// (approached at 1.0 down to 0.06 m/s, 2 to 10 ms apart, while the mass
/// slides along the curved floor), the normal velocity's error
/// `∇h·(v̂ − v)/|∇h|` on the samples that bracket no plant impact, on the
/// plant's exact positions (the filter told `σ = 1e-4`: no noise to blur
/// the model's part) and on noisy ones (`σ = 1e-4`, seed 11):
///
/// - told `τ/2` as one delay of position and velocity (`impact_delay`,
///   `impact_time_sigma = τ/√12`), the filter's normal velocity falls
///   behind by a little more at each bounce: its bounces come earlier and
///   earlier, while its positions stay within a few micrometres of the
///   plant's;
/// - told the plant (`with_plant_step`), whose own step at each impact
///   carries the velocity's later delay, it holds, as the defaults (no
///   mean delay at all) do.
///
/// Asserted: told the plant's step, the largest such error is at most a
/// quarter of the one-delay filter's and at most 1e-2, on both sample
/// sets. Measured: exact samples 3.95e-3 against 2.0e-2 (defaults 3.8e-3;
/// means over the window 2.2e-3 against 5.7e-3), noisy samples 2.7e-3
/// against 1.75e-2 (defaults 2.8e-3; 2.7e-3 as one Gaussian over the
/// plant's steps, `with_plant_step_mixture(false)`). In a scratch run on the exact
/// samples, the one-delay filter's `∇h·(v̂ − v)` at 4.434 s moved
/// linearly with the delay, by 6.5e-3 to 6.9e-3 m/s per microsecond
/// (−3.3e-2 at `τ/2`); with only the velocity's part of the offset
/// scaled by `2/(1 + e)` (1.053, the plant's ratio of mean delays) it was
/// −1.0e-3, and scaled by 1.1, +2.8e-2.
#[test]
fn a_single_delay_drifts_inside_an_accumulation() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let (tau, sigma) = (1e-5, 1e-4);
    let data = reference(&model, example_1_starts()[0], tau, 100, 4.6, &u);
    let bracket = common::runs::brackets(&data);
    let single = one_delay(tau, sigma);
    let knobs = [
        ("one delay", single),
        (
            "the plant's step",
            KalmanParams::new(20.0, sigma).with_plant_step(tau),
        ),
        ("defaults", KalmanParams::new(20.0, sigma)),
    ];
    for (samples, measured) in [
        ("exact", measure(&data, 0.0, 0)),
        ("noisy", measure(&data, sigma, 11)),
    ] {
        let worst = knobs.map(|(label, params)| {
            let mut f =
                SaltationKalman::<f64, 2, 2>::new(params, 0.0, measured[0], Vector2::zeros())
                    .unwrap();
            let estimates = run(&mut f, &model, &data, &measured, &u);
            let errors: Vec<f64> = data
                .samples
                .iter()
                .zip(&estimates)
                .zip(&bracket)
                .filter(|((s, _), b)| (4.36..4.44).contains(&s.t) && !**b)
                .map(|((s, e), _)| {
                    let normal = model.gap_jacobian(&s.q).row(0).transpose();
                    (normal.dot(&(e.v - s.v)) / normal.norm()).abs()
                })
                .collect();
            let mean = errors.iter().sum::<f64>() / errors.len() as f64;
            let worst = errors.iter().copied().fold(0.0, f64::max);
            eprintln!(
                "{samples} samples, {label}: normal-velocity error in the accumulation, mean {mean:.2e}, largest {worst:.2e}"
            );
            (mean, worst)
        });
        let [(_, one_delay), (_, step), _] = worst;
        assert!(
            step <= 0.25 * one_delay && step <= 1e-2,
            "{samples}: {step:e} against {one_delay:e}"
        );
    }
}

/// [`KalmanParams::plant`] takes the plant's own step, whatever its law:
/// samples of Siconos's law (`StepParams::siconos`, the approach velocity
/// at the step's start, as Siconos's `MoreauJeanOSI` takes it; the
/// crate's plant agrees with Siconos step by step, `tests/plant.rs`) on
/// Example 1's four starts (noise seeds 11 to 14) and seed 555's twelve
/// random starts (noise seeds `100 + n`), σ = 1e-4, scored over [2, 10]
/// s. The filter runs with its defaults, told the crate's default law
/// (`with_plant_step(1e-5)`, the wrong plant here) and told Siconos's
/// (`with_plant(StepParams::siconos(1e-5))`).
///
/// Siconos's law drags along a slide on the curved floor (up to 4.5e-6
/// m/s per millisecond at the valley's bottom, where the default law
/// keeps to 1e-8): told the plant, the filter takes that drag too, two
/// plant steps on each piece of a slide (module docs of
/// `runtime/src/observer/kalman/propagate.rs`, "A plant's law along a
/// slide"). Without it, seed 555's start 6, which slides from 5.3 s on,
/// lost 5e-4 m/s against the filter at each pass through the bottom and
/// its NEES median was 31.
///
/// Told Siconos's law, the filter runs twice: as one Gaussian over the
/// plant's steps at each impact (`with_plant_step_mixture(false)`), and
/// as it is, keeping the likely steps of an impact near a step's edge
/// apart (`KalmanParams::plant_step_mixture`). Where it keeps them apart
/// its estimate is a sum of Gaussians, whose NEES is not χ² distributed
/// (an estimate between two modes is mostly nearer the right one than
/// their spread says), so the NEES is asserted on the one Gaussian, and
/// printed for the other over the samples where it holds one Gaussian.
///
/// Asserted: told Siconos's law, either way, the maximum off the samples
/// that bracket a plant impact is within the issue's 1e-2 and the median
/// error no larger than with the defaults; as one Gaussian, the velocity
/// NEES median within twice the χ²₂ median (1.39) on every run, and the
/// median over the runs of those NEES medians within a factor of two of
/// it; keeping the steps apart, the issue's median and 90th percentile
/// met on at least as many runs as one Gaussian; told the wrong law, the
/// NEES median over the runs more than ten times the χ² median.
/// Measured, told Siconos's law: as one Gaussian, medians 1.1e-5 to
/// 3.3e-5 (defaults 2.4e-5 to 1.3e-4), maxima off the brackets at most
/// 8.2e-3 (defaults 1.23e-2 on the file's start), NEES 0.39 to 1.57 per
/// run and 0.79 over the runs, the issue's median and 90th percentile
/// together on 14 of the 16 (the defaults on none); keeping the steps
/// apart, medians 9.9e-6 to 2.3e-5, maxima at most 8.2e-3, both numbers
/// on all 16, NEES 0.40 to 1.11 per run and 0.73 over the runs on the
/// samples with one Gaussian (73 to 2 513 of the 8 000 samples per run
/// hold more); told the wrong law, NEES 333 and none met. A formula for
/// one law would have been wrong here as the default law is.
///
/// `cargo test --release --test kalman -- --nocapture siconos` (1 s)
#[test]
fn a_plant_with_siconoss_law_is_told_its_own_step() {
    use common::runs::reference_with;
    use moreau::StepParams;
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let sigma = 1e-4;
    let siconos = StepParams::siconos(1e-5);
    let knobs = [
        ("defaults", KalmanParams::new(20.0, sigma)),
        (
            "told the default law",
            KalmanParams::new(20.0, sigma).with_plant_step(1e-5),
        ),
        (
            "told Siconos's law, one Gaussian",
            KalmanParams::new(20.0, sigma)
                .with_plant(siconos)
                .with_plant_step_mixture(false),
        ),
        (
            "told Siconos's law",
            KalmanParams::new(20.0, sigma).with_plant(siconos),
        ),
    ];
    // the four starts and seed 555's twelve: the first 16 of the 52
    let runs: Vec<_> = common::runs::example_1_runs()
        .into_iter()
        .take(16)
        .collect();
    let chi2_median = 2.0 * std::f64::consts::LN_2;
    let mut nees_medians = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    let mut met = [0; 4];
    for (at, start, noise_seed) in &runs {
        let data = reference_with(&model, *start, siconos, 100, 10.0, &u);
        let measured = measure(&data, sigma, *noise_seed);
        let mut line = format!("{at}:");
        let mut scores = Vec::new();
        for (k, (label, params)) in knobs.iter().enumerate() {
            let mut filter =
                SaltationKalman::<f64, 2, 2>::new(*params, 0.0, measured[0], Vector2::zeros())
                    .unwrap();
            let mut nees = Vec::new();
            let mut mixed = 0;
            let counted = run_counting(
                &mut filter,
                &model,
                (&data, &measured),
                &u,
                WINDOW,
                |j, f| {
                    let s = &data.samples[j];
                    if (WINDOW.0..WINDOW.1).contains(&s.t) {
                        // (where the filter keeps a plant's steps apart its
                        // estimate is a sum of Gaussians, whose NEES is not
                        // χ²: counted, not scored)
                        if f.kalman_report().alternatives > 0 {
                            mixed += 1;
                            return;
                        }
                        let error = f.estimate().v - s.v;
                        let p = f.covariance().vv.cholesky().unwrap();
                        nees.push(error.dot(&p.solve(&error)));
                    }
                },
            );
            let sc = counted.scored;
            let nees_median = figures(&nees).median;
            met[k] += usize::from(sc.all.median <= 3e-5 && sc.all.p90 <= 2e-4);
            nees_medians[k].push(nees_median);
            line += &format!(
                " {label}: median {:.2e} p90 {:.2e} max off the brackets {:.2e} NEES {nees_median:.2} ({mixed} samples kept apart);",
                sc.all.median, sc.all.p90, sc.clean.max
            );
            scores.push(sc);
        }
        eprintln!("{line}");
        let defaults = &scores[0];
        for told in &scores[2..] {
            assert!(told.clean.max <= 1e-2, "{at}: {:e}", told.clean.max);
            assert!(told.all.median <= defaults.all.median, "{at}");
        }
        let told_nees = nees_medians[2].last().copied().unwrap_or(f64::NAN);
        assert!(told_nees <= 2.0 * chi2_median, "{at}: NEES {told_nees}");
    }
    let over_runs = nees_medians.map(|m| figures(&m).median);
    eprintln!(
        "median over the runs of the NEES medians: defaults {:.2}, told the default law {:.2}, told Siconos's as one Gaussian {:.2}, told Siconos's {:.2} (χ²₂ median {chi2_median:.2}); the issue's median and p90 met on {}, {}, {} and {} of {}",
        over_runs[0],
        over_runs[1],
        over_runs[2],
        over_runs[3],
        met[0],
        met[1],
        met[2],
        met[3],
        runs.len()
    );
    assert!((0.5 * chi2_median..=2.0 * chi2_median).contains(&over_runs[2]));
    assert!(over_runs[1] > 10.0 * chi2_median);
    // keeping the plant's likely steps apart loses no run
    assert!(met[3] >= met[2]);
}

/// `χ²` with `dof` degrees of freedom, `z` standard deviations out
/// (Wilson–Hilferty, accurate to a few 1e-3 relative from 100 degrees of
/// freedom up).
fn chi_square(dof: f64, z: f64) -> f64 {
    let c = 2.0 / (9.0 * dof);
    dof * (1.0 - c + z * c.sqrt()).powi(3)
}

/// The Cholesky factor `(l11, l21, l22)` of one coordinate's white
/// acceleration noise integrated exactly over `τ` (unit density):
/// `[[τ³/3, τ²/2], [τ²/2, τ]]`. A draw `(z1, z2)` of two standard normals
/// moves the position by `q_a l11 z1` and the velocity by `q_a (l21 z1 +
/// l22 z2)`.
fn white_noise_factor(tau: f64) -> (f64, f64, f64) {
    let (a, b, c) = (tau.powi(3) / 3.0, tau * tau / 2.0, tau);
    let l11 = a.sqrt();
    let l21 = b / l11;
    (l11, l21, (c - l21 * l21).sqrt())
}

/// Runs where the filter's noise model is the truth: Example 1's mass with
/// gravity switched off (the parameter `g = 0`) driven by white
/// acceleration noise of density `q_a` on each coordinate, drawn exactly
/// for each sampling interval `τ_k` (`[[τ³/3, τ²/2], [τ²/2, τ]] q_a²` per
/// coordinate), away from the walls; positions sampled with Gaussian
/// noise `σ`. Over 100 independent runs (seeded), the sums of the
/// normalised innovation squared (2 degrees of freedom) and of the
/// normalised estimation error squared `x̃ᵀP⁻¹x̃` (4) at a fixed time are
/// `χ²` with 200 and 400 degrees of freedom; both must lie inside their
/// two-sided 99.9 % bounds at each of three times (0.5, 1 and 2 s).
///
/// The filter takes samples at any rate, so the same holds at 1 kHz, at
/// 100 Hz, at 10 kHz, and with intervals jittered over [0.5, 1.5] ms (a
/// deterministic sequence, `0.5 + frac(k φ)` ms with the golden ratio
/// `φ`).
#[test]
fn nis_and_nees_are_chi_square_where_the_noise_model_is_true() {
    let golden = (5f64.sqrt() - 1.0) / 2.0;
    let jittered = move |k: usize| 1e-3 * (0.5 + (k as f64 * golden).fract());
    let schedules: [(&str, &dyn Fn(usize) -> f64); 4] = [
        ("1 kHz", &|_| 1e-3),
        ("100 Hz", &|_| 1e-2),
        ("10 kHz", &|_| 1e-4),
        ("jittered 0.5 to 1.5 ms", &jittered),
    ];
    for (label, interval) in schedules {
        chi_square_where_the_noise_model_is_true(label, interval);
    }
}

/// One sampling schedule of
/// [`nis_and_nees_are_chi_square_where_the_noise_model_is_true`]: sample
/// `k` (from 1) ends an interval of `interval(k)` seconds.
fn chi_square_where_the_noise_model_is_true(label: &str, interval: &dyn Fn(usize) -> f64) {
    let mut model = Parabola::<f64>::new();
    *model
        .parameter_mut(Parabola::<f64>::parameter_index("g").unwrap())
        .unwrap() = 0.0;
    let u = SVector::zeros();
    let (q_a, sigma, runs): (f64, f64, usize) = (0.05, 1e-4, 100);
    let times = [0.5, 1.0, 2.0];
    // the sample each check takes: the first at or after its time
    let mut checks = Vec::new();
    let mut t = 0.0;
    for k in 1.. {
        t += interval(k);
        if checks.len() < times.len() && t >= times[checks.len()] - 1e-9 {
            checks.push(k);
        }
        if checks.len() == times.len() {
            break;
        }
    }
    let mut nis = vec![0.0; checks.len()];
    let mut nees = vec![0.0; checks.len()];
    for run in 0..runs {
        let mut gauss = Gauss::new(1 + run as u64);
        let mut q = Vector2::new(0.0, 4.0);
        let mut v = Vector2::new(0.1, -0.1);
        let measured0 = q + Vector2::from_fn(|_, _| sigma * gauss.normal());
        let params = KalmanParams::new(20.0, sigma).with_accel_noise(q_a);
        let p0 = Blocks::diagonal(
            SMatrix::identity() * sigma * sigma,
            SMatrix::identity() * 1.0,
        );
        let mut filter = SaltationKalman::<f64, 2, 2>::with_covariance(
            params,
            0.0,
            measured0,
            Vector2::zeros(),
            p0,
        )
        .unwrap();
        let mut t = 0.0;
        for k in 1..=checks[checks.len() - 1] {
            let tau = interval(k);
            let (l11, l21, l22) = white_noise_factor(tau);
            for i in 0..2 {
                let (z1, z2) = (gauss.normal(), gauss.normal());
                q[i] += v[i] * tau + q_a * l11 * z1;
                v[i] += q_a * (l21 * z1 + l22 * z2);
            }
            t += tau;
            let y = q + Vector2::from_fn(|_, _| sigma * gauss.normal());
            let e = filter.update(&model, t, &y, &u).unwrap();
            assert_eq!(
                filter.report().contacts,
                IndexSet::EMPTY,
                "{label}: the walls are far"
            );
            if let Some(j) = checks.iter().position(|&c| c == k) {
                nis[j] += filter.kalman_report().nis;
                let p = dense(filter.covariance());
                let err =
                    DVector::from_iterator(4, (q - e.q).iter().chain((v - e.v).iter()).copied());
                nees[j] += (err.transpose() * p.lu().solve(&err).unwrap())[0];
            }
        }
    }
    let z = 3.29; // two-sided 99.9 %
    for (j, &k) in checks.iter().enumerate() {
        let (lo_nis, hi_nis) = (
            chi_square(2.0 * runs as f64, -z),
            chi_square(2.0 * runs as f64, z),
        );
        let (lo_nees, hi_nees) = (
            chi_square(4.0 * runs as f64, -z),
            chi_square(4.0 * runs as f64, z),
        );
        eprintln!(
            "{label}, t = {} s (sample {k}): Σ NIS {:.1} in [{lo_nis:.1}, {hi_nis:.1}], Σ NEES {:.1} in [{lo_nees:.1}, {hi_nees:.1}]",
            times[j], nis[j], nees[j]
        );
        assert!(
            nis[j] > lo_nis && nis[j] < hi_nis,
            "{label}: NIS at {k}: {}",
            nis[j]
        );
        assert!(
            nees[j] > lo_nees && nees[j] < hi_nees,
            "{label}: NEES at {k}: {}",
            nees[j]
        );
    }
}

/// The filter on the plant's runs of every shipped model, sampled at 4
/// kHz, 1 kHz and 100 Hz with noise `σ` = 1e-6, 1e-4 and 1e-3 (81 runs:
/// Example 1's four starts, the three balls, the billiard, the double
/// pendulum, the three-link arm and the 4-link chain, each from its own
/// start, plant at `τ = 1e-5`, noise seed 5, `v̂(0) = 0`, scored over [2,
/// 6] s), with its defaults beside (38) (`l_d = 10`), both told `σ`; `C_v
/// = 50`.
///
/// Asserted on every run: neither estimator restarts, and neither's
/// physical screen refuses a sample (nothing in the data is wrong:
/// samples at any rate are data, not faults); the filter's median is
/// below (38)'s (measured: 1.6 to 1700 times); and the filter's
/// innovation gate skips (holds the estimate at the prediction) at most
/// 1 % of the samples (measured: none on 72 runs, 1 to 9 on the others,
/// at most 0.33 %). The last failed on the three-link arm at 100 Hz and
/// σ = 1e-6, 34 of 600 skipped, while one Runge–Kutta step covered each
/// 10 ms interval: its error there is larger than such a sample allows.
/// Steps of at most `ObserverParams::max_step` (2 ms) leave none.
/// At `σ ≤ 1e-4` the filter's maximum off the samples that bracket a
/// plant impact is within the issue's bound for (38), 0.1
/// (measured at most 3.0e-2, the double pendulum at 1 kHz, σ = 1e-6; the
/// file's start at 4 kHz reaches 1.5e-2 and the billiard at 1 kHz 1.06e-2,
/// above the 1e-2 the issue asks of the filter on its runs).
#[test]
fn the_filter_takes_samples_at_any_rate_on_every_shipped_model() {
    fn runs<M, const N: usize, const K: usize>(
        model: &M,
        name: &str,
        start: (SVector<f64, N>, SVector<f64, N>),
    ) where
        M: Sensitivities<N, K, Scalar = f64, Input: Default> + std::fmt::Debug + 'static,
    {
        let u = M::Input::default();
        for every in [25, 100, 1000] {
            let data = reference::<_, N, K>(model, start, 1e-5, every, 6.0, &u);
            for sigma in [1e-6, 1e-4, 1e-3] {
                let measured = measure(&data, sigma, 5);
                let window = (2.0, 6.0);
                let (c, skipped) =
                    filter_counting(model, (&data, &measured), &u, (50.0, sigma), window);
                let params = ObserverParams::new(10.0, 50.0).with_noise(sigma);
                let mut observer =
                    ReducedOrder::<f64, N, K>::new(params, 0.0, measured[0], SVector::zeros())
                        .unwrap();
                let o = run_counting(
                    &mut observer,
                    model,
                    (&data, &measured),
                    &u,
                    window,
                    |_, _| {},
                );
                let (sc, so) = (&c.scored, &o.scored);
                let at = format!("{name}, {} Hz, σ = {sigma:e}", 100_000 / every);
                eprintln!(
                    "{at}: filter median {:.2e} p90 {:.2e} max off the brackets {:.2e}, {skipped} of {} samples skipped by its gate; (38) median {:.2e} max off the brackets {:.2e}",
                    sc.all.median,
                    sc.all.p90,
                    sc.clean.max,
                    measured.len() - 1,
                    so.all.median,
                    so.clean.max
                );
                assert_eq!(
                    (c.restarts, c.refused, o.restarts, o.refused),
                    (0, 0, 0, 0),
                    "{at}"
                );
                assert!(sc.all.median < so.all.median, "{at}");
                assert!(100 * skipped < measured.len(), "{at}: {skipped} skipped");
                if sigma <= 1e-4 {
                    assert!(sc.clean.max <= 0.1, "{at}: {:e}", sc.clean.max);
                }
            }
        }
    }
    for (n, start) in example_1_starts().into_iter().enumerate() {
        runs::<_, 2, 2>(
            &Parabola::<f64>::new(),
            &format!("Example 1, start {n}"),
            start,
        );
    }
    runs::<_, 3, 4>(
        &ThreeBalls::<f64>::new(),
        "three balls",
        ThreeBalls::<f64>::initial_state(),
    );
    runs::<_, 2, 4>(
        &Billiard::<f64>::new(),
        "billiard",
        Billiard::<f64>::initial_state(),
    );
    runs::<_, 2, 2>(
        &DoublePendulum::<f64>::new(),
        "double pendulum",
        DoublePendulum::<f64>::initial_state(),
    );
    runs::<_, 3, 1>(&Arm3::<f64>::new(), "arm", Arm3::<f64>::initial_state());
    runs::<_, 4, 4>(
        &Chain4::<f64>::new(),
        "4-link chain",
        Chain4::<f64>::initial_state(),
    );
}

mod slope {
    moreau::model! {
        /// A unit point mass under gravity above the tilted floor
        /// `y = 0.3 x`, restitution 0.8.
        pub struct Slope;
        coordinates { x: vx, y: vy }
        parameters { g: 9.81 }
        kinetic = 0.5 * (vx^2 + vy^2);
        potential = g * y;
        constraints { floor: y - 0.3 * x >= 0 }
        restitution = 0.8;
    }
}

/// The same check through impacts: a point mass bouncing on the tilted
/// floor `y = 0.3 x` (restitution 0.8) under gravity and white
/// acceleration noise of density `q_a`, simulated exactly (ballistic arcs
/// over 10 µs substeps, each impact at the root of the gap's quadratic,
/// Newton's law, then the substep's exact noise increment), sampled at 1
/// kHz with noise `σ`; the filter told `q_a` and `σ`, with no impact or
/// contact noise of its own (the truth has none). At the first sample
/// after every impact of every run (about four per run, 100 runs, where
/// the saltation matrix has just mapped `P`) the sums of NIS and NEES
/// must lie inside the two-sided 99.9 % bounds of `χ²` with 2 and 4
/// degrees of freedom per impact; so must the sums ten samples later.
#[test]
fn nis_and_nees_are_chi_square_through_impacts() {
    use slope::Slope;
    let model = Slope::<f64>::new();
    let u = SVector::zeros();
    let (tau, sub, q_a, sigma, runs, e, g) = (1e-3, 100usize, 0.05, 1e-4, 100, 0.8, 9.81);
    let h = tau / sub as f64;
    let n = Vector2::new(-0.3, 1.0);
    let (l11, l21, l22) = white_noise_factor(h);
    // [at the first sample after an impact, ten samples later]: (Σ NIS, Σ NEES, terms)
    let mut sums = [(0.0, 0.0, 0usize); 2];
    for run in 0..runs {
        let mut gauss = Gauss::new(500 + run as u64);
        let (mut q, mut v) = (Vector2::new(0.0, 1.0), Vector2::new(0.5, 0.0));
        let params = KalmanParams {
            impact_noise: 0.0,
            impact_time_sigma: 0.0,
            contact_noise: 0.0,
            ..KalmanParams::new(20.0, sigma).with_accel_noise(q_a)
        };
        let v0 = v + Vector2::from_fn(|_, _| 0.1 * gauss.normal());
        let p0 = Blocks::diagonal(
            SMatrix::identity() * sigma * sigma,
            SMatrix::identity() * 0.01,
        );
        let measured0 = q + Vector2::from_fn(|_, _| sigma * gauss.normal());
        let mut filter =
            SaltationKalman::<f64, 2, 1>::with_covariance(params, 0.0, measured0, v0, p0).unwrap();
        let mut since: Option<usize> = None;
        for k in 1..=2000 {
            let mut impacted = false;
            for _ in 0..sub {
                // the ballistic arc over h, cut at the floor
                let mut left = h;
                let gap = |q: &Vector2<f64>| n.dot(q);
                let arc = |q: &Vector2<f64>, v: &Vector2<f64>, s: f64| {
                    (
                        q + v * s + Vector2::new(0.0, -0.5 * g * s * s),
                        v + Vector2::new(0.0, -g * s),
                    )
                };
                loop {
                    let (q1, _) = arc(&q, &v, left);
                    if gap(&q1) >= 0.0 {
                        (q, v) = arc(&q, &v, left);
                        break;
                    }
                    // gap(s) = h0 + d s − ½ g n_y s², first root in [0, left]
                    // (a start a rounding below the floor, from the noise,
                    // meets it at once)
                    let (h0, d, c2) = (gap(&q).max(0.0), n.dot(&v), 0.5 * g * n[1]);
                    let s = (2.0 * h0 / ((d * d + 4.0 * c2 * h0).sqrt() - d)).clamp(0.0, left);
                    let (qc, vc) = arc(&q, &v, s);
                    let vn = n.dot(&vc) / n.norm_squared();
                    assert!(
                        vn < 0.0,
                        "run {run}, sample {k}: the floor is met while leaving it"
                    );
                    (q, v) = (qc, vc - n * ((1.0 + e) * vn));
                    impacted = true;
                    left -= s;
                    if left <= 0.0 {
                        break;
                    }
                }
                for i in 0..2 {
                    let (z1, z2) = (gauss.normal(), gauss.normal());
                    q[i] += q_a * l11 * z1;
                    v[i] += q_a * (l21 * z1 + l22 * z2);
                }
            }
            let y = q + Vector2::from_fn(|_, _| sigma * gauss.normal());
            let est = filter.update(&model, k as f64 * tau, &y, &u).unwrap();
            if impacted {
                since = Some(0);
            }
            let slot = match since {
                Some(0) => Some(0),
                Some(10) => Some(1),
                _ => None,
            };
            if let Some(j) = slot {
                let p = dense(filter.covariance());
                let err = DVector::from_iterator(
                    4,
                    (q - est.q).iter().chain((v - est.v).iter()).copied(),
                );
                sums[j].0 += filter.kalman_report().nis;
                sums[j].1 += (err.transpose() * p.lu().solve(&err).unwrap())[0];
                sums[j].2 += 1;
            }
            since = since.map(|s| s + 1);
        }
    }
    let z = 3.29; // two-sided 99.9 %
    for (label, (nis, nees, terms)) in ["first sample after", "ten samples after"].iter().zip(sums)
    {
        let m = terms as f64;
        let (lo_nis, hi_nis) = (chi_square(2.0 * m, -z), chi_square(2.0 * m, z));
        let (lo_nees, hi_nees) = (chi_square(4.0 * m, -z), chi_square(4.0 * m, z));
        eprintln!(
            "{label} {terms} impacts: Σ NIS {nis:.1} in [{lo_nis:.1}, {hi_nis:.1}], Σ NEES {nees:.1} in [{lo_nees:.1}, {hi_nees:.1}]"
        );
        assert!(terms >= 2 * runs, "{terms} impacts");
        assert!(nis > lo_nis && nis < hi_nis, "{label}: Σ NIS {nis}");
        assert!(nees > lo_nees && nees < hi_nees, "{label}: Σ NEES {nees}");
    }
}

// ---------------------------------------------------------------------------
// Example 1 under noise

/// The four knobs [`tune_process_noise`] picks for Example 1 from one
/// record `data`, sampled with noise `sigma` (seed `seed`), printed.
fn tuned_on(data: &Reference<2>, sigma: f64, seed: u64) -> KalmanParams<f64, 2> {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let measured = measure(data, sigma, seed);
    let t: Vec<f64> = data.samples.iter().map(|s| s.t).collect();
    let tuned = tune_process_noise::<_, _, 2, 2>(
        &model,
        KalmanParams::new(20.0, sigma),
        &t,
        &measured,
        &Vector2::zeros(),
        &u,
        (-4.0, 2.0),
    )
    .unwrap();
    eprintln!(
        "tuned on one record: q_a {:.3e}, ρ_i {:.3e}, σ_t {:.3e}, δ̄ {:.3e}, ρ_c {:.3e}, log-likelihood {:.1}, {} runs",
        tuned.params.accel_noise[0],
        tuned.params.impact_noise,
        tuned.params.impact_time_sigma,
        tuned.params.impact_delay,
        tuned.params.contact_noise,
        tuned.log_likelihood,
        tuned.evaluations
    );
    tuned.params
}

/// The process noise for Example 1 picked by [`tune_process_noise`] from
/// one recorded noisy run (the model file's initial state, its own noise
/// seed), used unchanged on every other run.
fn tuned_example_1(sigma: f64) -> KalmanParams<f64, 2> {
    tuned_on(&example_1_run(10.0), sigma, 1000)
}

/// Example 1 on four initial states (the model file's, whose impacts
/// accumulate at 4.456 s before it slides, and three more), `v̂(0) = 0`,
/// 1 kHz samples of the plant at `τ = 1e-5`, scored over `[2, 10]` s;
/// the filter with its default process noise, with the four knobs
/// picked once by the likelihood helper from another noisy run (the model
/// file's start, its own noise seed), and told the plant's step
/// ([`KalmanParams::with_plant_step`]: the plant's own Moreau–Jean step
/// of 10 µs at each impact and its spread, nothing picked from a run).
///
/// Asserted: with exact samples the median is at most 1e-8 (the issue's
/// figure); with `σ = 1e-4` the median is at most 1e-4 and the 90th
/// percentile at most 4e-4 (the hand-written Python saltation filter the
/// issue measured on such data: median 5e-5 to 1e-4, 90th percentile 2e-4
/// to 7e-4), with the defaults the median below that filter's best
/// (5e-5) and the maximum off the samples that bracket a plant impact
/// at most the issue's 1e-2 (with a one-deviation contact band the filter
/// follows the last bounces of an accumulation instead of sliding early,
/// `KalmanParams::band_sigmas`), and the median at least ten times below
/// that of the reduced-order observer (38), told `σ`, on the same
/// samples. The issue's median and 90th-percentile targets (3e-5, 2e-4)
/// are printed, not asserted, for the defaults: they are met on three
/// starts of four (the plant places each impact somewhere in its 10 µs
/// step; see the README). Told the plant's step, the filter meets all
/// three of the issue's targets on all four starts, asserted (measured:
/// medians 1.30e-5 to 2.29e-5, 90th percentiles 8.0e-5 to 1.64e-4,
/// maxima off the brackets 3.0e-4 to 5.7e-3).
#[test]
fn example_1_figures_beside_the_reduced_order_observer() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let tuned = tuned_example_1(1e-4);
    let knobs = [
        ("defaults", KalmanParams::new(20.0, 1e-4)),
        ("tuned", tuned),
        (
            "told the plant's step",
            KalmanParams::new(20.0, 1e-4).with_plant_step(1e-5),
        ),
    ];
    for ((n, start), (label, params)) in example_1_starts()
        .into_iter()
        .enumerate()
        .flat_map(|s| knobs.map(|k| (s, k)))
    {
        let data = reference(&model, start, 1e-5, 100, 10.0, &u);
        for sigma in [1e-4, 0.0] {
            let measured = measure(&data, sigma, 11 + n as u64);
            let params = KalmanParams {
                measurement: SMatrix::identity() * sigma * sigma,
                observer: ObserverParams {
                    noise: sigma,
                    ..params.observer
                },
                ..params
            };
            let mut f =
                SaltationKalman::<f64, 2, 2>::new(params, 0.0, measured[0], Vector2::zeros())
                    .unwrap();
            let sc = scored(&mut f, &model, &data, &measured, &u);
            let so = reduced_order(&data, &measured, sigma);
            eprintln!(
                "Example 1, start {n}, σ = {sigma:e}, knobs {label}: filter median {:.2e} p90 {:.2e} max {:.2e} (without the bracketing samples: max {:.2e}; samples to recover, worst {}), (38) median {:.2e} p90 {:.2e} max {:.2e}",
                sc.all.median,
                sc.all.p90,
                sc.all.max,
                sc.clean.max,
                sc.recover.iter().max().unwrap_or(&0),
                so.all.median,
                so.all.p90,
                so.all.max
            );
            eprintln!(
                "  samples after each plant impact past 2 s until |v − v̂| < 1e-2: {:?}",
                sc.recover
            );
            if sigma == 0.0 {
                assert!(
                    sc.all.median <= 1e-8,
                    "start {n}, {label}: {:e}",
                    sc.all.median
                );
            } else {
                assert_beside_python_and_38(&sc, &so, &format!("start {n}, {label}"));
                if label == "defaults" {
                    assert!(sc.all.median <= 5e-5, "start {n}: {:e}", sc.all.median);
                    assert!(sc.clean.max <= 1e-2, "start {n}: {:e}", sc.clean.max);
                }
                if label == "told the plant's step" {
                    assert!(
                        sc.all.median <= 3e-5 && sc.all.p90 <= 2e-4 && sc.clean.max <= 1e-2,
                        "start {n}: {:?}",
                        sc.all
                    );
                }
            }
        }
    }
}

/// Example 1 from 48 initial states drawn, not picked
/// ([`random_example_1_starts`], seeds 555, 777, 999 and 1234, twelve
/// each), run as the four starts above: plant at `τ = 1e-5`, 1 kHz, `σ =
/// 1e-4` (noise seed `100 + n`), `v̂(0) = 0`, scored over `[2, 10]` s;
/// the filter with its defaults and told the plant's step
/// ([`KalmanParams::with_plant_step`]) beside (38) told `σ`, then the
/// filter on the exact samples.
///
/// Asserted on every run, for the filter with either knobs: its maximum off the samples that
/// bracket a plant impact at most the issue's 1e-2, its median at most
/// 1e-4 and its 90th percentile at most 4e-4 (the hand-written Python
/// saltation filter the issue measured: median 5e-5 to 1e-4, 90th
/// percentile 2e-4 to 7e-4), ten times below (38)'s median, and on the
/// exact samples the issue's median of 1e-8; (38)'s median and 90th
/// percentile within `1.4` and `3` × √2 l_d σ (as `tests/noise.rs`
/// asserts on the four starts).
///
/// Printed, not asserted, because they do not hold on every draw (this
/// test prints them; README "Under noise"): the filter's median ≤ 3e-5 and
/// 90th percentile ≤ 2e-4 together hold on 15 of the 48 (median 1.1e-5
/// to 7.3e-5, 90th percentile 8.5e-5 to 3.4e-4; 13 before held contacts
/// stopped doing work on a separating estimate); told the plant's step,
/// on 42 of the 48, keeping the likely steps of an impact near a step's
/// edge apart (asserted: on at least as many as the same filter as one
/// Gaussian over its steps, `with_plant_step_mixture(false)`, which meets
/// them on 37; 33 before it took each impact into the plant's own step
/// on the samples' grid). The Gaussian posterior of the plant's own noise
/// puts 5 of the 48 beyond the issue's numbers, and the filter meets both
/// on 4 of them (`the_filter_beside_the_gaussian_posterior`). A throw-away run of the
/// same 48 against the plant at `τ = 1e-6`, with `σ_t` set to that
/// plant's `τ/√12 = 0.29 µs`, met both on 40 of 48 (median up to 4.0e-5,
/// 90th percentile up to 2.3e-4 on the others): most of the gap is the
/// reference plant's own impact error (see
/// `example_1_targets_hold_on_a_plant_ten_times_finer`), the rest is
/// what the noise leaves unknown after fast impacts on the curved floor
/// (a position known to 3e-5 m before the impact is a normal known to
/// about 6e-5 rad, and a velocity after it uncertain by up to 1e-3 m/s
/// there). (38)'s maximum off the bracketing samples is at most 0.1 on 47
/// of the 48 (0.196 on seed 1234, start 5). There the mass micro-bounces
/// (3.6 to 5.0 ms apart, approached at 0.12 to 0.25 m/s, peaks of 1.6e-4
/// to 2.5e-4 m) while it slides fast along the curved floor, whose
/// curvature bends the normal velocity at 60 to 100 m/s²: an impact
/// located a millisecond off (one missed for an interval) leaves 0.07 to
/// 0.2 m/s on the samples between bounces. While the smoothed position
/// was held within `n_σ σ` of each sample, seed 1234, start 9, reached
/// 0.125 (three samples 2.4 to 3.8 σ low pulled it seven of its
/// deviations under the truth, and a bounce was located 1.3 ms early)
/// and seed 777, start 11, 0.143; held within four deviations of `q̄ − q`
/// they are at 0.089 and 0.084 (README "Under noise").
/// One random run of Example 1 as the random-starts tests make it: the
/// plant from `start` at `τ = 1e-5` for 10 s, its positions at 1 kHz with
/// `σ = 1e-4` (noise seed `100 + n`), and the filter's scores with the
/// defaults and told the plant's step.
fn random_start_run(
    start: (SVector<f64, 2>, SVector<f64, 2>),
    n: usize,
) -> (Reference<2>, Vec<Vector2<f64>>, Scored, Scored) {
    let sigma = 1e-4;
    let data = reference(
        &Parabola::<f64>::new(),
        start,
        1e-5,
        100,
        10.0,
        &SVector::zeros(),
    );
    let measured = measure(&data, sigma, 100 + n as u64);
    let defaults = with_defaults(&data, &measured, sigma);
    let told = with_params(
        &data,
        &measured,
        KalmanParams::new(20.0, sigma).with_plant_step(1e-5),
    );
    (data, measured, defaults, told)
}

/// The issue's maximum off the bracketing samples, 1e-2, with the
/// defaults and told the plant's step (`at` names the run).
fn assert_maximum_off_the_brackets((defaults, told): (&Scored, &Scored), at: &str) {
    assert!(defaults.clean.max <= 1e-2, "{at}: {:e}", defaults.clean.max);
    assert!(
        told.clean.max <= 1e-2,
        "{at}, the plant's step: {:e}",
        told.clean.max
    );
}

#[test]
fn example_1_random_starts_beside_the_reduced_order_observer() {
    let sigma = 1e-4;
    let noise_scale = std::f64::consts::SQRT_2 * 10.0 * sigma;
    let (mut met, mut met_step, mut met_38, mut runs) = (0, 0, 0, 0);
    let mut met_gauss = 0;
    let issue = |f: &Scored| f.all.median <= 3e-5 && f.all.p90 <= 2e-4;
    for seed in [555, 777, 999, 1234] {
        for (n, start) in random_example_1_starts(seed, 12).into_iter().enumerate() {
            let (data, measured, sc, sp) = random_start_run(start, n);
            let told = KalmanParams::new(20.0, sigma).with_plant_step(1e-5);
            let sg = with_params(&data, &measured, told.with_plant_step_mixture(false));
            let so = reduced_order(&data, &measured, sigma);
            let se = with_defaults(&data, &measure(&data, 0.0, 0), 0.0);
            (runs, met, met_step, met_38) = (
                runs + 1,
                met + usize::from(issue(&sc)),
                met_step + usize::from(issue(&sp)),
                met_38 + usize::from(so.clean.max <= 0.1),
            );
            met_gauss += usize::from(issue(&sg));
            let line = |f: &Scored| {
                format!(
                    "median {:.2e} p90 {:.2e} max off the brackets {:.2e}{}",
                    f.all.median,
                    f.all.p90,
                    f.clean.max,
                    if issue(f) {
                        ""
                    } else {
                        " (misses 3e-5 / 2e-4)"
                    }
                )
            };
            eprintln!(
                "seed {seed}, start {n} {start:?}: filter {}, exact samples median {:.2e}; told the plant's step {}; (38) median {:.2e} p90 {:.2e} max off the brackets {:.3}",
                line(&sc),
                se.all.median,
                line(&sp),
                so.all.median,
                so.all.p90,
                so.clean.max,
            );
            let at = format!("seed {seed}, start {n}");
            assert_maximum_off_the_brackets((&sc, &sp), &at);
            assert_beside_python_and_38(&sc, &so, &at);
            assert_beside_python_and_38(&sp, &so, &format!("{at}, the plant's step"));
            assert!(se.all.median <= 1e-8, "{at}: {:e}", se.all.median);
            assert!(
                so.all.median <= 1.4 * noise_scale && so.all.p90 <= 3.0 * noise_scale,
                "{at}: (38) median {:e}, p90 {:e}",
                so.all.median,
                so.all.p90
            );
        }
    }
    eprintln!(
        "the issue's median and 90th percentile met by the filter on {met} of {runs} runs (told the plant's step: {met_step}; as one Gaussian over its steps: {met_gauss}); (38)'s maximum off the brackets at most 0.1 on {met_38} of {runs}"
    );
    // keeping the plant's likely steps apart loses no run
    assert!(met_step >= met_gauss);
}

/// The issue's maximum on 96 more random starts of Example 1, drawn with
/// eight seeds that no other test uses and no knob was tuned on (7, 99,
/// 123, 2718, 31, 4242, 8080 and 1001; twelve starts each,
/// `random_example_1_starts`; the first four were an earlier scratch check
/// of the steps kept apart, module `mixture`, and 31 and 4242 part of the
/// design record's "The defaults on 144 random starts"), run as
/// `example_1_random_starts_beside_the_reduced_order_observer` runs its
/// 48: plant at `τ = 1e-5`, 1 kHz, `σ = 1e-4`, `v̂(0) = 0`, scored over
/// `[2, 10]` s, with the defaults and told the plant's step.
///
/// Asserted: the maximum off the samples that bracket a plant impact is
/// within the issue's 1e-2 on every start, both ways. Measured: at most
/// 6.7e-3 with the defaults and 8.8e-3 told the plant; the median and the
/// 90th percentile together meet the issue's on 31 and 82 of the 96.
/// Before the filter counted its velocity noise once in the contact rule
/// (`an_approach_the_filter_can_tell_from_rest_bounces`), seed 7, start 4
/// was 1.18e-2 off told the plant, at micro-bounces the rule closed
/// plastically, and fourteen starts' maxima were higher (none lower).
#[test]
fn example_1_maximum_holds_on_96_more_random_starts() {
    let issue = |f: &Scored| f.all.median <= 3e-5 && f.all.p90 <= 2e-4;
    let (mut met, mut met_step, mut runs) = (0, 0, 0);
    let (mut worst, mut worst_step) = (0.0_f64, 0.0_f64);
    for seed in [7, 99, 123, 2718, 31, 4242, 8080, 1001] {
        for (n, start) in random_example_1_starts(seed, 12).into_iter().enumerate() {
            let (_, _, sc, sp) = random_start_run(start, n);
            runs += 1;
            met += usize::from(issue(&sc));
            met_step += usize::from(issue(&sp));
            worst = worst.max(sc.clean.max);
            worst_step = worst_step.max(sp.clean.max);
            assert_maximum_off_the_brackets((&sc, &sp), &format!("seed {seed}, start {n}"));
        }
    }
    eprintln!(
        "{runs} more starts: maximum off the brackets at most {worst:.2e} with the defaults, {worst_step:.2e} told the plant's step; the issue's median and 90th percentile met on {met} and {met_step}"
    );
}

/// Where the filter keeps an impact's likely steps apart (a sum of
/// Gaussians, module `mixture`), the covariance it reports (`P` plus the
/// spread of the means) is not overconfident. The reference is a fact
/// that holds for any distribution, not only a Gaussian one: for the
/// true mean `μ` and covariance `Σ` of `x`, `E[(x − μ)ᵀ Σ⁻¹ (x − μ)] =
/// tr(I)`, 2 for the velocity of Example 1. So over the samples that hold
/// kept steps, off the brackets of the plant's impacts (where no
/// estimator can know the jump yet), the mean velocity NEES of a
/// calibrated filter is 2, whatever the sum's shape.
///
/// The twelve random starts of seed 1234, each with 20 noise seeds (1000
/// to 1019), told the plant (σ = 1e-4, 1 kHz, [2, 10] s). Each start's
/// mean is asserted at most 3: 2 and the spread of such a mean over 20
/// runs (0.79 to 2.08 over these starts). A step the samples made light
/// used to be dropped, and with it the covariance's room for it, when
/// the samples had dropped the right one: then the means of starts 2 and
/// 10 were 7.2 and 3.9. It now joins the state by moment matching.
#[test]
fn the_sum_is_not_overconfident_where_it_keeps_steps() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let sigma = 1e-4;
    let params = KalmanParams::new(20.0, sigma).with_plant_step(1e-5);
    let mut means = Vec::new();
    for (n, start) in random_example_1_starts(1234, 12).into_iter().enumerate() {
        let data = reference(&model, start, 1e-5, 100, 10.0, &u);
        let bracket = brackets(&data);
        let from = first_at_or_after(&data, WINDOW.0);
        let (mut sum, mut count) = (0.0, 0_usize);
        for seed in 1000..1020 {
            let measured = measure(&data, sigma, seed);
            let mut f =
                SaltationKalman::<f64, 2, 2>::new(params, 0.0, measured[0], Vector2::zeros())
                    .unwrap();
            let each = |j: usize, f: &SaltationKalman<f64, 2, 2>| {
                if j >= from && !bracket[j] && f.kalman_report().alternatives > 0 {
                    let d = data.samples[j].v - f.estimate().v;
                    let p = f.covariance().vv;
                    let nees = d.dot(&p.cholesky().expect("P_vv positive definite").solve(&d));
                    (sum, count) = (sum + nees, count + 1);
                }
            };
            let (_, restarts, refused) =
                observe_counting(&mut f, &model, (&data, &measured), &u, each);
            assert_eq!((restarts, refused), (0, 0), "start {n}, noise seed {seed}");
        }
        assert!(count > 0, "start {n}: no sample held kept steps");
        let mean = sum / count as f64;
        eprintln!(
            "seed 1234, start {n}: mean velocity NEES {mean:.2} over {count} samples holding kept steps (20 noise seeds)"
        );
        means.push(mean);
    }
    for (n, mean) in means.iter().enumerate() {
        assert!(*mean <= 3.0, "start {n}: mean NEES {mean}");
    }
}

/// What the samples hold by the Gaussian posterior, and what the filter
/// does beside it. The Gaussian posterior of the plant's own noise
/// (`tests/common/posterior.rs`: the measurement noise and the phase of
/// the plant's step at each impact, linearised along the truth, one
/// Gaussian over the steps) gives the fraction of samples an estimator
/// can expect within a radius, and so a median and 90th percentile to
/// expect over a run (`q50`, `q90`). On the 52 Example 1 runs of
/// `example_1_figures_beside_the_reduced_order_observer` (noise seeds 11
/// to 14) and `example_1_random_starts_beside_the_reduced_order_observer`
/// (seeds 555, 777, 999 and 1234, noise seeds `100 + n`), σ = 1e-4, the
/// filter told the plant (`with_plant_step(1e-5)`, which keeps the likely
/// steps apart, `KalmanParams::plant_step_mixture`):
///
/// - `within` is exact where the answer is known: for `P = λ I`, `1 −
///   exp(−r²/2λ)`;
/// - the filter's median and 90th percentile are within three times
///   `q50` and `q90` on every run, and within 1.25 times in the median
///   over the runs (measured 0.55 to 2.31 and 0.52 to 1.78; medians over
///   the runs 0.95 and 0.96);
/// - on 5 of the 48 random starts `q50` is above 3e-5 or `q90` above
///   2e-4 (printed; asserted: on at least one), and the filter meets both
///   of the issue's numbers on 4 of the 5 (asserted: on at least one).
///
/// So the Gaussian posterior is not a bound on what the samples hold. The
/// plant's outcome is a staircase of the impact's instant, and near a
/// step's edge the samples after the impact pick one of two outcomes a
/// step apart, which one Gaussian can only spread over; the filter keeps
/// the two apart. Before it did, the filter was this posterior's own
/// recursion, met both numbers on 37 of the 48 and on 3 of the 5, and
/// every run it missed had `q50` or `q90` within 1.61 times its target.
/// It now misses on 6 others: 5 within the posterior's reach (printed,
/// with the nearer quantile's fraction of its target: 0.65 to 0.97) and
/// one it puts beyond (seed 1234, start 11, `q50` 3.49e-5). Without the rule that takes a kept step
/// into its own window at a later impact (module `propagate`, "A
/// time-stepping plant"), the file's start was at 3.46 times `q90` and
/// failed the first assertion.
///
/// `cargo test --release --test kalman -- --nocapture posterior` (26 s)
#[test]
fn the_filter_beside_the_gaussian_posterior() {
    use common::posterior::{quantile, velocity_covariances, within};
    for (lambda, r) in [(1e-10_f64, 1e-5_f64), (4e-8, 3e-4), (1e-9, 1e-6)] {
        let exact = 1.0 - (-r * r / (2.0 * lambda)).exp();
        let p = nalgebra::Matrix2::identity() * lambda;
        assert!((within(&p, r) - exact).abs() < 1e-12, "{lambda:e} {r:e}");
    }
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let sigma = 1e-4;
    let told = KalmanParams::new(20.0, sigma).with_plant_step(1e-5);
    let runs = common::runs::example_1_runs();
    let (mut medians, mut p90s) = (Vec::new(), Vec::new());
    let (mut out_of_reach, mut missed, mut met_beyond) = (0, 0, 0);
    for (at, start, noise_seed) in &runs {
        let data = reference(&model, *start, 1e-5, 100, 10.0, &u);
        let filter = with_params(&data, &measure(&data, sigma, *noise_seed), told);
        let covariances = velocity_covariances(&data, sigma, 1e-5, WINDOW);
        let (q50, q90) = (quantile(&covariances, 0.5), quantile(&covariances, 0.9));
        let (median, p90) = (filter.all.median, filter.all.p90);
        let misses = median > 3e-5 || p90 > 2e-4;
        let beyond = q50 > 3e-5 || q90 > 2e-4;
        eprintln!(
            "{at}: posterior q50 {q50:.2e} q90 {q90:.2e}{}; filter median {median:.2e} ({:.2}×) p90 {p90:.2e} ({:.2}×){}",
            if beyond { " (beyond the issue's)" } else { "" },
            median / q50,
            p90 / q90,
            if misses { " (misses 3e-5 / 2e-4)" } else { "" },
        );
        assert!(median <= 3.0 * q50 && p90 <= 3.0 * q90, "{at}");
        if at.starts_with("seed") {
            out_of_reach += usize::from(beyond);
            missed += usize::from(misses);
            met_beyond += usize::from(beyond && !misses);
        }
        if misses && !beyond {
            eprintln!(
                "{at}: the filter misses within the posterior's reach, its nearer quantile at {:.2} of its target",
                (q50 / 3e-5).max(q90 / 2e-4)
            );
        }
        medians.push(median / q50);
        p90s.push(p90 / q90);
    }
    let (over_median, over_p90) = (figures(&medians).median, figures(&p90s).median);
    eprintln!(
        "the filter over the posterior, median over the runs: median {over_median:.2}, p90 {over_p90:.2}; of the 48 random starts, the posterior's expected quantiles beyond the issue's on {out_of_reach}, the filter meeting both there on {met_beyond}; the filter missing on {missed}"
    );
    assert!(over_median <= 1.25 && over_p90 <= 1.25);
    assert!(out_of_reach >= 1 && met_beyond >= 1);
}

/// Whether the filter's misses of the issue's median and 90th percentile
/// are the method's or the draw's. A miss on one noise draw says little:
/// a run's 90th percentile is set by a few stretches of correlated error
/// after fast impacts, and moves by a factor of two or more from one
/// draw of the noise to another. So each of the 52 Example 1 runs of
/// [`the_filter_beside_the_gaussian_posterior`] (the same starts) is run
/// on 20 fresh noise draws (noise seeds 60 000 to 60 019, which no other
/// test uses), told the plant (`with_plant_step(1e-5)`), σ = 1e-4, 1 kHz,
/// `[2, 10]` s, and its coverage, the fraction of samples within `r` of
/// the truth, is set beside the coverage the Gaussian posterior of the
/// plant's own noise allows any estimator in expectation
/// ([`common::posterior::coverage`], Anderson's lemma: module docs of
/// `tests/common/posterior.rs`), at the issue's two radii: `r` = 3e-5 (a
/// median within 3e-5 is a coverage of at least one half) and 2e-4 (a
/// 90th percentile within 2e-4, at least nine tenths).
///
/// Asserted, at both radii: on each start, the filter's mean coverage over
/// the 20 draws is within 0.05 (a twentieth of the samples) of the
/// posterior's or above it; in the mean over the 52 starts, within 0.01
/// or above (the posterior is first order and leaves out the acceleration
/// and contact noise the filter runs with, so it is a yardstick, not a
/// bound); and on every start the filter meets both of the issue's numbers
/// on at least one draw, so that no start is out of its reach. On the
/// same draws, the filter's maximum off the samples that bracket a plant
/// impact is within the issue's 1e-2 on every run, told the plant and
/// with its defaults (asserted; measured at most 6.05e-3 and 5.77e-3),
/// and the defaults meet both numbers on 403 of the 1040 runs (printed).
/// (38), told `σ`, is printed beside it: its maximum off the brackets is
/// above the issue's 0.1 on 31 of the 1040 (at most 0.199), seven of them
/// on the four starts of the issue's table (three on the file's start, one
/// on (−1, 3), three on (0.2, 1)); the worst draw of the file's start
/// (0.171) was traced to its accumulation on the curved floor (design
/// record, "Over noise draws: the draw, not the start"). Measured:
/// the filter minus the posterior −0.015 to +0.019 at 2e-4 and −0.025 to
/// +0.107 at 3e-5 (means over the starts +0.005 and +0.021); both numbers
/// met on 6 to 20 draws of 20 per start, 910 of the 1040 runs (832 of
/// the 960 on the 48 random starts). The starts met on fewest draws are
/// those whose posterior coverage is nearest the target (0.89 to 0.90 at
/// 2e-4: 6 to 13 of 20; 0.43 to 0.47 at 3e-5: 10 to 16 of 20), where any
/// estimator's figures land on either side of the issue's from one draw
/// to the next. The same starts on 20 other draws (noise seeds 5000 to
/// 5019, a scratch run) met both on 827 of the 960, each start on 5 to
/// 20: which draws of a start miss changes with the draws. The filter
/// with its defaults (not told the plant) fails the first assertion on
/// the first start: 0.74 of its samples within 3e-5, where the posterior
/// allows 0.83.
///
/// `cargo test --release --test kalman -- --nocapture over_noise_draws`
/// (30 s)
#[test]
fn the_filter_covers_what_the_posterior_allows_over_noise_draws() {
    use common::posterior::{coverage, velocity_covariances};
    const DRAWS: u64 = 20;
    let radii = [3e-5, 2e-4];
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let sigma = 1e-4;
    let told = KalmanParams::new(20.0, sigma).with_plant_step(1e-5);
    let issue = |f: &Scored| f.all.median <= 3e-5 && f.all.p90 <= 2e-4;
    let (mut gaps, mut met_runs, mut met_defaults, mut runs) = ([0.0; 2], 0, 0, 0);
    let (mut worst, mut worst_defaults, mut over_38, mut worst_38) = (0.0_f64, 0.0_f64, 0, 0.0_f64);
    let starts = common::runs::example_1_runs();
    for (at, start, _) in &starts {
        let data = reference(&model, *start, 1e-5, 100, 10.0, &u);
        let covariances = velocity_covariances(&data, sigma, 1e-5, WINDOW);
        let allowed = radii.map(|r| coverage(&covariances, r));
        let (mut covered, mut met) = ([0.0; 2], 0);
        for draw in 0..DRAWS {
            let measured = measure(&data, sigma, 60_000 + draw);
            let mut f = SaltationKalman::<f64, 2, 2>::new(told, 0.0, measured[0], Vector2::zeros())
                .unwrap();
            let estimates = run(&mut f, &model, &data, &measured, &u);
            let in_window = common::runs::errors_in_window(&data, &estimates, WINDOW);
            for (c, r) in covered.iter_mut().zip(radii) {
                let within = in_window.iter().filter(|&&e| e <= r).count();
                *c += within as f64 / in_window.len() as f64 / DRAWS as f64;
            }
            let scored = score(&data, &estimates, WINDOW);
            met += usize::from(issue(&scored));
            // the same draw with the defaults and beside (38)
            let defaults = with_defaults(&data, &measured, sigma);
            let observer = reduced_order(&data, &measured, sigma);
            let here = format!("{at}, draw {draw}");
            assert_maximum_off_the_brackets((&defaults, &scored), &here);
            met_defaults += usize::from(issue(&defaults));
            (worst, worst_defaults) = (
                worst.max(scored.clean.max),
                worst_defaults.max(defaults.clean.max),
            );
            (over_38, worst_38) = (
                over_38 + usize::from(observer.clean.max > 0.1),
                worst_38.max(observer.clean.max),
            );
        }
        eprintln!(
            "{at}: both numbers met on {met} of {DRAWS} draws; coverage within 3e-5: posterior {:.3}, filter {:.3}; within 2e-4: posterior {:.3}, filter {:.3}",
            allowed[0], covered[0], allowed[1], covered[1]
        );
        for k in 0..2 {
            assert!(
                covered[k] >= allowed[k] - 0.05,
                "{at}, r = {:e}: filter {} against the posterior's {}",
                radii[k],
                covered[k],
                allowed[k]
            );
            gaps[k] += (covered[k] - allowed[k]) / starts.len() as f64;
        }
        assert!(met >= 1, "{at}: the issue's numbers met on no draw");
        (met_runs, runs) = (met_runs + met, runs + DRAWS as usize);
    }
    eprintln!(
        "the filter's coverage minus the posterior's, mean over the {} starts: {:+.3} within 3e-5, {:+.3} within 2e-4; both numbers met on {met_runs} of {runs} runs (with the defaults: {met_defaults}); maximum off the brackets at most {worst:.2e} ({worst_defaults:.2e} with the defaults); (38)'s above 0.1 on {over_38} of {runs}, at most {worst_38:.3}",
        starts.len(),
        gaps[0],
        gaps[1]
    );
    assert!(gaps.iter().all(|&g| g >= -0.01), "{gaps:?}");
}

moreau::model! {
    /// A ball inside a round bowl (a circle of radius 1 in a vertical
    /// plane): it bounces off the inside of the rim, and slides along it
    /// once the bounces die out. Written for
    /// `the_issues_numbers_hold_on_models_written_for_the_test`.
    pub struct Bowl;
    coordinates { x: vx, y: vy }
    parameters { m: 1.0, g: 9.81, r: 1.0 }
    kinetic = 0.5 * m * (vx^2 + vy^2);
    potential = m * g * y;
    constraints { rim: x^2 + y^2 <= r^2 }
    restitution = 0.8;
}

moreau::model! {
    /// A cart carrying a pendulum between two walls, the pendulum's tip
    /// stopped by a third (its mass matrix depends on the angle, and the
    /// tip's constraint on both coordinates). Written for
    /// `the_issues_numbers_hold_on_models_written_for_the_test`.
    pub struct CartPole;
    coordinates { x: vx, th: w }
    parameters { mc: 1.0, mp: 0.3, l: 0.5, g: 9.81 }
    kinetic = 0.5 * (mc + mp) * vx^2 + mp * l * vx * w * cos(th) + 0.5 * mp * l^2 * w^2;
    potential = -mp * g * l * cos(th);
    constraints { right: x <= 0.5, left: x >= -0.5, tip: x + l * sin(th) <= 0.7 }
    restitution = 0.5;
}

/// The issue's numbers on two models written for this test, not shipped
/// and never tuned on: [`Bowl`] (a curved constraint seen from inside)
/// and [`CartPole`] (a configuration-dependent mass matrix, a constraint
/// on both coordinates), twelve initial states of each drawn with seed
/// 2027 (the bowl: a position uniform in the disc of radius 0.9, each
/// velocity component uniform in [−4, 4] m/s; the cart: `x` in [−0.45,
/// 0.45] m, `θ` in [−π, π] with the tip inside its wall, `ẋ` in [−2, 2]
/// m/s, `θ̇` in [−8, 8] rad/s). Run as Example 1's: plant at `τ = 1e-5`,
/// 1 kHz, `σ = 1e-4` (noise seed `100 + n`), `v̂(0) = 0`, scored over
/// `[2, 10]` s; the filter with its defaults, (38) with `l_d = 10`, `C_v
/// = 20`, told `σ`; then the filter on the exact samples.
///
/// Asserted on every run: the filter's median within the issue's 3e-5
/// and its maximum off the samples that bracket a plant impact within
/// 1e-2, its 90th percentile within 4e-4 (the hand-written Python
/// filter's range, as for Example 1's random starts), the exact samples'
/// median within 1e-8, (38)'s maximum off the brackets within the
/// issue's 0.1; no restart, no sample refused by either, and at most one
/// in a hundred skipped by the filter's gate, on the noisy samples and on
/// the exact ones. Measured: filter medians 5.6e-6 to 2.4e-5, 90th
/// percentiles 1.0e-5 to 2.65e-4 (the issue's 2e-4 missed on one bowl
/// start), maxima off the brackets 1.4e-5 to 2.5e-3, exact-sample medians
/// 4.9e-11 to 2.6e-9; (38)'s maxima 0.004 to 0.094; at most two noisy
/// samples and 32 exact ones skipped by the gate in a run (printed).
///
/// On the exact samples of the four bowl starts that end sliding along the
/// rim, the gate skipped 1861 to 5037 of the 10 000 before a sample inside
/// a held contact was read on it (the plant's sliding position sits 1.3e-9
/// m outside the circle; `a_sample_inside_a_held_contact_is_read_on_it`);
/// their medians were 9.5e-10 to 1.9e-9 then, 1.8e-9 to 2.6e-9 now.
#[test]
fn the_issues_numbers_hold_on_models_written_for_the_test() {
    let (bowl, cart) = drawn_starts();
    let met = issues_numbers_on(&Bowl::<f64>::default(), &bowl)
        + issues_numbers_on(&CartPole::<f64>::default(), &cart);
    eprintln!("the issue's 90th percentile (2e-4) met on {met} of 24 runs");
}

/// The starts of `the_issues_numbers_hold_on_models_written_for_the_test`,
/// drawn with seed 2027: twelve of [`Bowl`] (a position uniform in the disc
/// of radius 0.9, each velocity component uniform in [−4, 4] m/s), then
/// twelve of [`CartPole`] (`x` in [−0.45, 0.45] m, `θ` in [−π, π] with the
/// tip inside its wall, `ẋ` in [−2, 2] m/s, `θ̇` in [−8, 8] rad/s).
fn drawn_starts() -> (Vec<Start>, Vec<Start>) {
    let mut g = Gauss::new(2027);
    let bowl: Vec<_> = (0..12)
        .map(|_| {
            let r = 0.9 * g.uniform().sqrt();
            let a = std::f64::consts::TAU * g.uniform();
            let v = Vector2::new(8.0 * g.uniform() - 4.0, 8.0 * g.uniform() - 4.0);
            (Vector2::new(r * a.cos(), r * a.sin()), v)
        })
        .collect();
    let mut cart = Vec::new();
    while cart.len() < 12 {
        let x = 0.9 * g.uniform() - 0.45;
        let th = std::f64::consts::TAU * g.uniform() - std::f64::consts::PI;
        let v = Vector2::new(4.0 * g.uniform() - 2.0, 16.0 * g.uniform() - 8.0);
        if x + 0.5 * th.sin() <= 0.69 {
            cart.push((Vector2::new(x, th), v));
        }
    }
    (bowl, cart)
}

/// The runs and assertions of
/// `the_issues_numbers_hold_on_models_written_for_the_test` on one
/// model's `starts`; returns the runs whose filter meets the issue's 90th
/// percentile, 2e-4.
fn issues_numbers_on<M, const K: usize>(model: &M, starts: &[(Vector2<f64>, Vector2<f64>)]) -> usize
where
    M: Sensitivities<2, K, Scalar = f64, Input = SVector<f64, 0>> + std::fmt::Debug + 'static,
{
    let (u, sigma, window) = (SVector::zeros(), 1e-4, (2.0, 10.0));
    let name = M::INFO.name;
    let mut met = 0;
    for (n, &start) in starts.iter().enumerate() {
        let data = reference(model, start, 1e-5, 100, 10.0, &u);
        let measured = measure(&data, sigma, 100 + n as u64);
        let (filter, skipped) =
            filter_counting(model, (&data, &measured), &u, (20.0, sigma), window);
        let exact = measure(&data, 0.0, 0);
        let (exact, exact_skipped) =
            filter_counting(model, (&data, &exact), &u, (20.0, 0.0), window);
        let params = ObserverParams::new(10.0, 20.0).with_noise(sigma);
        let mut o =
            ReducedOrder::<f64, 2, K>::new(params, 0.0, measured[0], Vector2::zeros()).unwrap();
        let observer = run_counting(&mut o, model, (&data, &measured), &u, window, |_, _| {});
        let (fs, os) = (&filter.scored, &observer.scored);
        eprintln!(
            "{name}, start {n} ({} plant impacts): filter median {:.2e} p90 {:.2e} max off the brackets {:.2e}, {skipped} skipped by its gate; exact samples median {:.2e}, {exact_skipped} skipped; (38) median {:.2e} max off the brackets {:.3}",
            data.impacts.len(),
            fs.all.median,
            fs.all.p90,
            fs.clean.max,
            exact.scored.all.median,
            os.all.median,
            os.clean.max,
        );
        let at = format!("{name}, start {n}");
        assert!(
            fs.all.median <= 3e-5 && fs.all.p90 <= 4e-4,
            "{at}: median {:e}, p90 {:e}",
            fs.all.median,
            fs.all.p90
        );
        assert!(fs.clean.max <= 1e-2, "{at}: {:e}", fs.clean.max);
        assert!(
            exact.scored.all.median <= 1e-8,
            "{at}: {:e}",
            exact.scored.all.median
        );
        assert!(os.clean.max <= 0.1, "{at}: (38) {:e}", os.clean.max);
        let samples = measured.len();
        assert!(
            filter.restarts + filter.refused + observer.restarts + observer.refused == 0,
            "{at}"
        );
        assert!(100 * skipped < samples, "{at}: {skipped} of {samples}");
        assert!(
            100 * exact_skipped < samples,
            "{at}: exact samples, {exact_skipped} of {samples}"
        );
        met += usize::from(fs.all.p90 <= 2e-4);
    }
    met
}

/// The boxes' model, written for their tests: a uniform box, 0.4 m wide,
/// 0.2 m high and 1 kg, on a frictionless floor, each of its corners a
/// constraint (`c1`, `c2` the top corners when upright, `c3`, `c4` the
/// bottom ones), with the restitution `$e`.
macro_rules! a_box {
    ($(#[$doc:meta])* $name:ident, $e:tt) => {
        moreau::model! {
            $(#[$doc])*
            pub struct $name;
            coordinates { x: vx, y: vy, th: w }
            parameters { m: 1.0, a: 0.2, b: 0.1, g: 9.81, i: 0.016666666666666666 }
            kinetic = 0.5 * m * (vx^2 + vy^2) + 0.5 * i * w^2;
            potential = m * g * y;
            constraints {
                c1: y + a * sin(th) + b * cos(th) >= 0,
                c2: y - a * sin(th) + b * cos(th) >= 0,
                c3: y + a * sin(th) - b * cos(th) >= 0,
                c4: y - a * sin(th) - b * cos(th) >= 0,
            }
            restitution = $e;
        }
    };
}

a_box! {
    /// The box of `a_box!` with `e = 0.8`: landing, it rocks from corner
    /// to corner. Written for
    /// `a_box_rocking_onto_a_corner_keeps_the_other_law_in_reserve`.
    RockingBox, 0.8
}

a_box! {
    /// [`RockingBox`] with plastic impacts (`e = 0`): dropped, it lands on
    /// a corner, falls onto the next and rests on the two. Written for
    /// `a_plastic_box_rests_on_two_corners_each_at_its_own_level`.
    PlasticBox, 0.0
}

/// A box rocking onto a corner while the corner it rocks off micro-bounces
/// within the noise: the filter keeps the law in which that corner hovers
/// in reserve, and takes it when the samples refuse its own (module docs
/// of `runtime/src/observer/kalman/propagate.rs`, "A contact that may
/// hover").
///
/// [`RockingBox`] dropped from eight states drawn with seed 2028 (`θ`
/// uniform in [−π, π], the centre's height in [0.25, 1] m with every
/// corner above the floor, `ẋ` in [−1, 1] m/s, `ẏ` in [−2, 2] m/s, `θ̇` in
/// [−10, 10] rad/s); plant at `τ = 1e-5`, 1 kHz, `σ = 1e-4` (noise seed
/// `100 + n`), `v̂(0) = 0`, the filter's defaults with `C_v = 40`. The box
/// rocks to rest within 2.5 to 4 s of its 10. The error is the corners'
/// speed across the floor, `max_i |J_i (v − v̂)|`, from 0.05 s on, off the
/// samples that bracket a plant impact.
///
/// As the box settles, the corner it rocks off micro-bounces 10 to 70 µm
/// up, below what the samples resolve, and the filter holds it as a
/// contact. When the other corner strikes, the contact rule gives the pair
/// one law, the held corner plastic; the plant, which has it a hair open,
/// bounces it on its own once the strike drives it in. On start 6 at
/// 2.4045 s, `c4` strikes at 0.41 m/s beside a held `c3`: the plant's `θ̇`
/// goes from 1.05 to 0.32 rad/s, the held law's to −0.79.
///
/// Asserted: no restart and no sample refused by the filter on any start;
/// the corners' speed error within 0.15 m/s on every start, and within 0.1
/// m/s on start 6 at the three samples after the bracket of that strike.
/// Measured: 0.021 to 0.138 m/s over the starts, and 9.1e-3 on start 6's
/// three samples; 0 to 10 samples a run skipped by the gate. (Before the
/// filter counted its velocity noise once in the contact rule,
/// `an_approach_the_filter_can_tell_from_rest_bounces`: 0.020 to 0.117,
/// start 6 at 0.117 and start 1 at 0.020 where they are now 0.138 and
/// 0.036.) With the held
/// law alone (the code before the reserve): 0.020 to 0.310 m/s, above 0.15
/// on starts 2, 6 and 7 (0.211, 0.222 and 0.310), and 0.222 on start 6's
/// three samples, two of which the gate skipped (26 samples skipped on
/// that start). The reserve made start 0 worse, 0.035 to 0.090 m/s.
#[test]
fn a_box_rocking_onto_a_corner_keeps_the_other_law_in_reserve() {
    let model = RockingBox::<f64>::default();
    let (u, sigma, from) = (SVector::zeros(), 1e-4, 0.05);
    for (n, start) in dropped_boxes(&model).into_iter().enumerate() {
        let data = reference(&model, start, 1e-5, 100, 10.0, &u);
        let measured = measure(&data, sigma, 100 + n as u64);
        let params = KalmanParams::new(40.0, sigma);
        let mut filter =
            SaltationKalman::<f64, 3, 4>::new(params, 0.0, measured[0], Vector3::zeros()).unwrap();
        let mut skipped = 0;
        let (estimates, restarts, refused) =
            observe_counting(&mut filter, &model, (&data, &measured), &u, |_, f| {
                skipped += usize::from(f.kalman_report().outlier);
            });
        let corners: Vec<f64> = data
            .samples
            .iter()
            .zip(&estimates)
            .map(|(s, e)| (model.gap_jacobian(&s.q) * (s.v - e.v)).amax())
            .collect();
        let bracket = brackets(&data);
        let (mut worst, mut at) = (0.0_f64, 0.0);
        for ((s, &e), &b) in data.samples.iter().zip(&corners).zip(&bracket) {
            if s.t >= from && !b && e > worst {
                (worst, at) = (e, s.t);
            }
        }
        eprintln!(
            "box, start {n} ({} plant impacts, the last at {:.2} s): the corners' speed error at most {worst:.3e} m/s off the brackets (at {at:.3} s), {skipped} samples skipped by the gate",
            data.impacts.len(),
            data.impacts.last().map_or(0.0, |i| i.0),
        );
        assert!(restarts + refused == 0, "start {n}");
        assert!(worst <= 0.15, "start {n}: {worst:e} at {at}");
        if n == 6 {
            // the strike on `c4` at 2.4045 s, and the three samples after
            // its bracket
            let &(t, i, speed) = data
                .impacts
                .iter()
                .find(|&&(t, i, _)| i == 3 && (t - 2.4045).abs() < 1e-4)
                .expect("the strike");
            assert!(speed > 0.4, "{t} {i} {speed}");
            let after = first_at_or_after(&data, t) + 1;
            let three = corners[after..after + 3]
                .iter()
                .fold(0.0_f64, |m, &e| m.max(e));
            eprintln!(
                "box, start 6: the corners' speed error at most {three:.2e} m/s at the three samples after the strike at {t:.4} s"
            );
            assert!(three <= 0.1, "{three:e}");
        }
    }
}

moreau::model! {
    /// Example 1 with plastic impacts (`e = 0`): the mass stops on the
    /// parabola at its first impact and slides along it from then on,
    /// swinging as a pendulum does in a bowl. Written for
    /// `a_plastic_impact_leaves_the_slide_where_the_plant_put_it`.
    pub struct PlasticParabola;
    coordinates { x: vx, y: vy }
    parameters { m: 1.0, g: 9.81, c: 8.0 }
    kinetic = 0.5 * m * (vx^2 + vy^2);
    potential = m * g * y;
    constraints { floor: y - x^2 >= 0, ceiling: c - y >= 0 }
    restitution = 0.0;
}

moreau::model! {
    /// A two-link arm (point masses at the ends of unit links, absolute
    /// angles from the downward vertical, damped joints) whose tip leans
    /// on the wall `x = 0.5`, which its hanging pose would cross; impacts
    /// are plastic. Struck against the wall, the tip stays on it, pressed
    /// by gravity, while the elbow swings. Written for
    /// `a_plastic_impact_leaves_the_slide_where_the_plant_put_it`.
    pub struct LeaningArm;
    coordinates { th1: w1, th2: w2 }
    parameters { m1: 1.0, m2: 1.0, l1: 1.0, l2: 1.0, g: 9.81, b: 0.05 }
    kinetic = 0.5 * (m1 + m2) * l1^2 * w1^2 + 0.5 * m2 * l2^2 * w2^2
        + m2 * l1 * l2 * w1 * w2 * cos(th1 - th2);
    potential = -(m1 + m2) * g * l1 * cos(th1) - m2 * g * l2 * cos(th2);
    applied { th1: -b * w1 + b * (w2 - w1), th2: -b * (w2 - w1) }
    constraints { wall: l1 * sin(th1) + l2 * sin(th2) >= 0.5 }
    restitution = 0.0;
}

/// A plastic impact leaves the plant where its step put it, and the
/// filter holds the contact there (module docs of
/// `runtime/src/observer/kalman/level.rs`). A time-stepping plant stops a
/// body struck plastically inside the constraint, about `0.63 τ |ḣ|`
/// deep (94 µm at 15 m/s), and slides it along that level set: Example 1
/// with `e = 0` ([`PlasticParabola`]), held at `h = 0`, had the filter's
/// velocity 1e-4 to 4e-4 m/s off all along the slide.
///
/// The issue's numbers, as for the models of
/// `the_issues_numbers_hold_on_models_written_for_the_test` (plant at `τ =
/// 1e-5`, 1 kHz, `σ = 1e-4`, `v̂(0) = 0`, defaults, scored over `[2, 10]`
/// s; the same assertions: median within 3e-5, 90th percentile within
/// 4e-4, maximum off the bracketing samples within 1e-2, exact-sample
/// median within 1e-8, (38) within 0.1 off the brackets, no restart or
/// refusal, under 1 % skipped), on eight drawn starts of each of two
/// plastic models: [`PlasticParabola`] (Example 1's random starts, seed
/// 2029) and [`LeaningArm`] (seed 2029: both angles uniform in [−1.5,
/// 1.5] rad with the tip right of the wall, both rates in [−3, 3] rad/s).
///
/// Measured: on the parabola, filter medians 5.0e-6 to 2.0e-5, 90th
/// percentiles 1.3e-5 to 4.2e-5, maxima off the brackets 1.8e-5 to 2.3e-4,
/// exact-sample medians 2.3e-10 to 3.6e-9; on the arm, medians 5.0e-6 to
/// 1.3e-5, exact-sample medians 5.8e-11 to 2.9e-10; the issue's 90th
/// percentile met on all 16. With every contact held at `h = 0` (the code
/// before the levels, run by a scratch copy of this test without its
/// assertions): on the parabola, medians 9.1e-6 to 2.2e-4 (over 3e-5 on
/// six of the eight), 90th percentiles up to 7.5e-4, exact-sample medians
/// 2.4e-6 to 7.6e-5 (1 324 of the exact samples skipped by the gate on
/// start 0); on the arm, the noisy figures within 30 % of today's, and
/// exact-sample medians 3.8e-9 to 2.6e-6, over 1e-8 on six of the eight.
#[test]
fn a_plastic_impact_leaves_the_slide_where_the_plant_put_it() {
    let parabola = random_example_1_starts(2029, 8);
    let model = LeaningArm::<f64>::default();
    let mut g = Gauss::new(2029);
    let mut arm = Vec::new();
    while arm.len() < 8 {
        let q = Vector2::new(3.0 * g.uniform() - 1.5, 3.0 * g.uniform() - 1.5);
        let v = Vector2::new(6.0 * g.uniform() - 3.0, 6.0 * g.uniform() - 3.0);
        if model.gaps(&q)[0] > 0.0 {
            arm.push((q, v));
        }
    }
    let met = issues_numbers_on(&PlasticParabola::<f64>::default(), &parabola)
        + issues_numbers_on(&model, &arm);
    eprintln!("plastic impacts: the issue's 90th percentile (2e-4) met on {met} of 16 runs");
}

/// A box that lands plastically rests on two corners, each at its own
/// level, and every sample is read there. [`PlasticBox`] dropped from the
/// eight states of `a_box_rocking_onto_a_corner_keeps_the_other_law_in_reserve`
/// ([`dropped_boxes`]), plant at `τ = 1e-5`, 1 kHz, the filter's defaults
/// with `C_v = 40`, on samples with `σ = 1e-4` (noise seed `100 + n`) and
/// on the exact ones. The plant stops each corner where its impact step
/// left it (start 1: 3.5e-5 and 2.1e-5 m inside the floor), and the
/// filter holds each at
/// the level it learns (module docs of
/// `runtime/src/observer/kalman/level.rs`), no deeper than its impact can
/// have left it. Where a corner sits deeper than that bound, its exact
/// sample is read on the level; read along that corner's normal alone,
/// the sample then left the other held corner, whose normal is not
/// orthogonal to it, and the gate skipped 6 176 to 6 342 of the 10 001
/// exact samples on starts 1, 5 and 7, the estimate held at the
/// prediction (measured at 48ad173; `Interval::read_on_contacts` now
/// leaves the other held gaps as they are). With every contact held at
/// the surface (e0c692f) it skipped 3 to 5.
///
/// Asserted on every start, noisy and exact: no restart and no refusal,
/// the gate skipping under one sample in a hundred, and the corners'
/// speed error, `max_i |J_i (v − v̂)|` from 0.05 s off the samples that
/// bracket a plant impact, within 0.05 m/s. Measured: 3 to 6 exact
/// samples and at most one noisy one skipped in a run; the corners'
/// worst 6.3e-4 to 1.8e-3 m/s on the noisy samples and 5.4e-4 to 2.3e-2 on
/// the exact ones (start 7 at its last impact, 0.49 s; the same with
/// every contact held at the surface).
#[test]
fn a_plastic_box_rests_on_two_corners_each_at_its_own_level() {
    let model = PlasticBox::<f64>::default();
    let (u, from) = (SVector::zeros(), 0.05);
    for (n, start) in dropped_boxes(&model).into_iter().enumerate() {
        let data = reference(&model, start, 1e-5, 100, 10.0, &u);
        for sigma in [1e-4, 0.0] {
            let measured = measure(&data, sigma, 100 + n as u64);
            let params = KalmanParams::new(40.0, sigma);
            let mut filter =
                SaltationKalman::<f64, 3, 4>::new(params, 0.0, measured[0], Vector3::zeros())
                    .unwrap();
            let mut skipped = 0;
            let (estimates, restarts, refused) =
                observe_counting(&mut filter, &model, (&data, &measured), &u, |_, f| {
                    skipped += usize::from(f.kalman_report().outlier);
                });
            let bracket = brackets(&data);
            let worst = data
                .samples
                .iter()
                .zip(&estimates)
                .zip(&bracket)
                .filter(|((s, _), b)| s.t >= from && !**b)
                .map(|((s, e), _)| (model.gap_jacobian(&s.q) * (s.v - e.v)).amax())
                .fold(0.0_f64, f64::max);
            eprintln!(
                "plastic box, start {n}, σ = {sigma:e} ({} plant impacts): the corners' speed error at most {worst:.2e} m/s off the brackets, {skipped} samples skipped by the gate",
                data.impacts.len()
            );
            let at = format!("start {n}, σ = {sigma:e}");
            assert!(restarts + refused == 0, "{at}");
            assert!(100 * skipped < measured.len(), "{at}: {skipped} skipped");
            assert!(worst <= 0.05, "{at}: {worst:e}");
        }
    }
}

moreau::model! {
    /// Three balls on a line between two walls, as the shipped
    /// `ThreeBalls`, but plastic between the balls (`e = 0`; the walls
    /// 0.7): balls that meet glue, and the cluster bounces between the
    /// walls. Written for `glued_balls_are_each_held_at_their_own_level`.
    pub struct GluedBalls;
    coordinates { x1: v1, x2: v2, x3: v3 }
    parameters { r: 0.125, l: 2.5 }
    kinetic = 0.5 * (v1^2 + v2^2 + v3^2);
    potential = 0;
    constraints {
        #[restitution = 0.7] left_wall: x1 - r >= 0,
        balls_1_2: x2 - x1 - 2 * r >= 0,
        balls_2_3: x3 - x2 - 2 * r >= 0,
        #[restitution = 0.7] right_wall: l - r - x3 >= 0,
    }
    restitution = 0.0;
}

/// Balls glued by plastic impacts are each held at their own level: the
/// plant leaves each pair of [`GluedBalls`] pressed 2e-6 to 2.7e-5 m into
/// each other, a different depth for each pair, and the cluster keeps
/// them through its bounces off the walls. Eight starts drawn with seed 5
/// (each ball uniform in [0.2, 2.3] m with every gap at least 1 cm open,
/// each velocity in [−2, 2] m/s); plant at `τ = 1e-5`, 1 kHz, the filter's
/// defaults (`C_v = 20`) on samples with `σ = 1e-4` (noise seed `100 + n`)
/// and on the exact ones, scored over `[2, 10]` s; (38) with `l_d = 10`
/// told `σ`.
///
/// Asserted on every start: no restart and no refusal, under one sample
/// in a hundred skipped by the gate; the issue's median (3e-5) and
/// maximum off the brackets (1e-2) on the noisy samples, the exact-sample
/// median within 1e-8 and its maximum off the brackets within 1e-2; (38)
/// within 0.1 off the brackets. Measured: noisy medians 3.0e-6 to
/// 5.1e-6, 90th percentiles 7.3e-6 to 1.15e-5, maxima off the brackets at
/// most 2.6e-5; exact-sample medians 1.5e-13 to 1.4e-11, maxima at most
/// 3.6e-11; at most one sample skipped in a run; (38) at most 0.008. With
/// every contact held at the surface (the code at e0c692f, scratch): the
/// gate skipped 1 331 to 4 054 of the 10 001 exact samples on seven of
/// the eight starts, whose maxima off the brackets reached 4.3e-3 to 0.39
/// m/s; noisy 90th percentiles 9.9e-6 to 3.4e-5.
#[test]
fn glued_balls_are_each_held_at_their_own_level() {
    let model = GluedBalls::<f64>::default();
    let u = SVector::zeros();
    let mut g = Gauss::new(5);
    let mut starts = Vec::new();
    while starts.len() < 8 {
        let q = Vector3::from_fn(|_, _| 0.2 + 2.1 * g.uniform());
        let v = Vector3::from_fn(|_, _| 4.0 * g.uniform() - 2.0);
        if model.gaps(&q).iter().all(|&h| h >= 0.01) {
            starts.push((q, v));
        }
    }
    for (n, &start) in starts.iter().enumerate() {
        let data = reference(&model, start, 1e-5, 100, 10.0, &u);
        for sigma in [1e-4, 0.0] {
            let measured = measure(&data, sigma, 100 + n as u64);
            let (filter, skipped) =
                filter_counting(&model, (&data, &measured), &u, (20.0, sigma), (2.0, 10.0));
            let fs = &filter.scored;
            eprintln!(
                "glued balls, start {n}, σ = {sigma:e} ({} plant impacts): filter median {:.2e} p90 {:.2e} max off the brackets {:.2e}, {skipped} skipped by its gate",
                data.impacts.len(),
                fs.all.median,
                fs.all.p90,
                fs.clean.max
            );
            let at = format!("start {n}, σ = {sigma:e}");
            assert!(filter.restarts + filter.refused == 0, "{at}");
            assert!(100 * skipped < measured.len(), "{at}: {skipped} skipped");
            let median = if sigma > 0.0 { 3e-5 } else { 1e-8 };
            assert!(fs.all.median <= median, "{at}: {:e}", fs.all.median);
            assert!(fs.clean.max <= 1e-2, "{at}: {:e}", fs.clean.max);
            if sigma > 0.0 {
                let params = ObserverParams::new(10.0, 20.0).with_noise(sigma);
                let mut o =
                    ReducedOrder::<f64, 3, 4>::new(params, 0.0, measured[0], Vector3::zeros())
                        .unwrap();
                let observer = run_counting(
                    &mut o,
                    &model,
                    (&data, &measured),
                    &u,
                    (2.0, 10.0),
                    |_, _| {},
                );
                eprintln!(
                    "glued balls, start {n}: (38) max off the brackets {:.3}",
                    observer.scored.clean.max
                );
                assert!(observer.restarts + observer.refused == 0, "{at}: (38)");
                assert!(observer.scored.clean.max <= 0.1, "{at}: (38)");
            }
        }
    }
}

/// The eight starts of the boxes' tests, drawn with seed 2028: `θ`
/// uniform in [−π, π], the centre's height in [0.25, 1] m with every
/// corner above the floor, `ẋ` in [−1, 1] m/s, `ẏ` in [−2, 2] m/s, `θ̇` in
/// [−10, 10] rad/s.
fn dropped_boxes<M: Model<3, 4, Scalar = f64>>(model: &M) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let mut g = Gauss::new(2028);
    let mut starts = Vec::new();
    while starts.len() < 8 {
        let th = std::f64::consts::TAU * g.uniform() - std::f64::consts::PI;
        let q = Vector3::new(0.0, 0.25 + 0.75 * g.uniform(), th);
        let v = Vector3::new(
            2.0 * g.uniform() - 1.0,
            4.0 * g.uniform() - 2.0,
            20.0 * g.uniform() - 10.0,
        );
        if model.gaps(&q).iter().all(|&h| h >= 0.0) {
            starts.push((q, v));
        }
    }
    starts
}

/// What [`run_counting`] saw: the figures over its window, the restarts
/// (`UpdateReport::restart`) and the samples refused as outliers.
struct Counted {
    scored: Scored,
    restarts: usize,
    refused: usize,
}

/// Every update of `estimator` over the run, counting its restarts and
/// the samples it refused as outliers (the estimate held there), scored
/// over `window`; any other error fails the test. `each` sees the
/// estimator after each accepted update.
fn run_counting<O, M, const N: usize, const K: usize>(
    estimator: &mut O,
    model: &M,
    (data, measured): (&Reference<N>, &[SVector<f64, N>]),
    u: &M::Input,
    window: (f64, f64),
    each: impl FnMut(usize, &O),
) -> Counted
where
    O: Observer<M, N, K>,
    M: Model<N, K, Scalar = f64>,
{
    let (estimates, restarts, refused) =
        observe_counting(estimator, model, (data, measured), u, each);
    Counted {
        scored: score(data, &estimates, window),
        restarts,
        refused,
    }
}

/// The filter with its defaults for the velocity bound `C_v` and the
/// noise `σ`, from `v̂(0) = 0`, run over `measured` by
/// [`run_counting`], and the samples its innovation gate skipped (the
/// estimate held at the prediction; `Ok`, not refused).
fn filter_counting<M, const N: usize, const K: usize>(
    model: &M,
    (data, measured): (&Reference<N>, &[SVector<f64, N>]),
    u: &M::Input,
    (c_v, sigma): (f64, f64),
    window: (f64, f64),
) -> (Counted, usize)
where
    M: Sensitivities<N, K, Scalar = f64>,
{
    let params = KalmanParams::new(c_v, sigma);
    let mut filter =
        SaltationKalman::<f64, N, K>::new(params, 0.0, measured[0], SVector::zeros()).unwrap();
    let mut skipped = 0;
    let counted = run_counting(&mut filter, model, (data, measured), u, window, |_, f| {
        skipped += usize::from(f.kalman_report().outlier);
    });
    (counted, skipped)
}

/// Example 1's floor `y = x²` at `x0`: its unit tangent and its unit
/// normal into the domain.
fn floor_frame(x0: f64) -> (Vector2<f64>, Vector2<f64>) {
    (
        Vector2::new(1.0, 2.0 * x0).normalize(),
        Vector2::new(-2.0 * x0, 1.0).normalize(),
    )
}

/// A filter with the defaults at `σ` = 1e-4 started from `(q0, v0)` near
/// Example 1's floor at `x0`, knowing its position to `s_t` along the
/// floor and `s_n` across it (as a run of micro-bounces leaves it) and its
/// velocity to `s_v` in each coordinate.
fn filter_over_the_floor(
    x0: f64,
    (q0, v0): (Vector2<f64>, Vector2<f64>),
    (s_t, s_n, s_v): (f64, f64, f64),
) -> SaltationKalman<f64, 2, 2> {
    let (tangent, normal) = floor_frame(x0);
    let p0 = Blocks {
        qq: tangent * tangent.transpose() * (s_t * s_t) + normal * normal.transpose() * (s_n * s_n),
        qv: SMatrix::zeros(),
        vq: SMatrix::zeros(),
        vv: SMatrix::identity() * (s_v * s_v),
    };
    let params = KalmanParams::new(20.0, 1e-4);
    SaltationKalman::<f64, 2, 2>::with_covariance(params, 0.0, q0, v0, p0).expect("filter")
}

/// The filter's velocity error against `v1` after one update, at `tau`,
/// on the exact position `q1` of Example 1.
fn error_after_one_update(
    filter: &mut SaltationKalman<f64, 2, 2>,
    tau: f64,
    (q1, v1): (Vector2<f64>, Vector2<f64>),
) -> f64 {
    let estimate = filter
        .update(&Parabola::<f64>::new(), tau, &q1, &SVector::zeros())
        .expect("update");
    (estimate.v - v1).norm()
}

/// A bounce the filter can tell from sliding is followed, not held. The
/// mass has just left Example 1's floor at `x = −1` with 0.95 m/s along it
/// and `s` = 1e-2 m/s across it, and the filter knows its position 5.2e-6
/// m well along the floor but 1.2e-6 m across it (a covariance such as a
/// run of micro-bounces leaves). One update on the exact position 1 ms
/// on; the reference is the exact free flight (a parabola in time).
///
/// The contact rule holds a closed constraint that separates slower than
/// its resting speed, whose fall term `√(4 A |J| b)` grows with the band
/// `b`. With the gap's own deviation as band (1.2e-6 m) the rule's speed
/// is 6e-3 m/s across the floor and the bounce departs; with the largest
/// deviation of a coordinate (4.7e-6 m, in `y`: the band before) it was
/// 1.1e-2 m/s, the floor was held, and the settle took the normal speed
/// out of an estimate whose mass still flies (5.4e-3 m/s off after the
/// update, measured with that band patched back in).
///
/// Asserted: the floor is not in the update's contacts, and the velocity
/// is within 1e-3 m/s (a tenth of `s`) of the exact one (measured: equal
/// to the last bit, the prediction being exact).
#[test]
fn a_bounce_faster_than_its_gaps_band_is_followed_not_held() {
    let model = Parabola::<f64>::new();
    let g = 9.81;
    let (x0, tau) = (-1.0_f64, 1e-3);
    let q0 = Vector2::new(x0, x0 * x0);
    let (tangent, normal) = floor_frame(x0);
    let v0 = tangent * 0.95 + normal * 1e-2;
    let mut filter = filter_over_the_floor(x0, (q0, v0), (5.2e-6, 1.2e-6, 3.3e-4));
    // the exact flight: no force but gravity, and the floor not reached
    let q1 = q0 + v0 * tau + Vector2::new(0.0, -0.5 * g * tau * tau);
    let v1 = v0 + Vector2::new(0.0, -g * tau);
    assert!(model.gaps(&q1)[0] > 0.0);
    let error = error_after_one_update(&mut filter, tau, (q1, v1));
    eprintln!(
        "contacts {:?}, |v̂ − v| = {error:.2e} m/s",
        filter.report().contacts
    );
    assert!(filter.report().contacts.is_empty());
    assert!(error <= 1e-3, "{error:e}");
}

/// An approach the filter can tell from rest bounces. The mass flies onto
/// Example 1's floor near `x = −1` at `s` = 9e-3 m/s across it (0.3 m/s
/// along it; 9.9e-3 across at the impact), from 2e-6 m above it, and the filter knows its position 1e-6 m
/// well across the floor (5e-6 along it) and its velocity to `σ_v` =
/// 1e-3 m/s in each coordinate. One update on the exact position 1 ms on;
/// the reference is the exact motion: free flight to the gap's root
/// (bisection), Newton's law with the model's `e` = 0.9 on the unit
/// mass, free flight on.
///
/// The contact rule bounces a closed constraint only where it approaches
/// faster than its resting speed, `v_rest = ρ τ A + √(4 A |J| b) + |J| ν`
/// (module docs of `runtime/src/observer/mod.rs`), `ν` the estimate's
/// velocity noise; for the filter `ν = n_σ σ_v`, and here `v_rest` is
/// 7.6e-3 m/s across the floor. The filter counted that noise twice: its
/// bounce also needed `|J| n_σ σ_v` more, the observers' uncertainty (for
/// them the last update's correction, another quantity), 1.06e-2 m/s in
/// all. Slower, the approach was closed plastically and the estimate held
/// on the floor while the mass bounced off it at 8.9e-3 m/s (measured on
/// the code before: 5.5e-3 m/s off after the update, the floor held). In a
/// billiard's corner, where a wall turns the ball back onto the floor at a
/// few cm/s, the held estimate lifted off 2e-2 m/s off with a velocity
/// NEES of 1e9 (scratch).
///
/// Asserted: the velocity is within a tenth of `s` of the exact one
/// (measured: 1.3e-13 m/s), and the floor is not held as a contact.
#[test]
fn an_approach_the_filter_can_tell_from_rest_bounces() {
    let model = Parabola::<f64>::new();
    let (g, e) = (9.81, 0.9);
    let (x0, tau, s) = (-1.0_f64, 1e-3, 9e-3);
    let (tangent, normal) = floor_frame(x0);
    let q0 = Vector2::new(x0, x0 * x0) + normal * 2e-6;
    let v0 = tangent * 0.3 - normal * s;
    let mut filter = filter_over_the_floor(x0, (q0, v0), (5e-6, 1e-6, 1e-3));
    // the exact motion: flight, the floor's root, Newton's law, flight
    let accel = Vector2::new(0.0, -g);
    let fly = |q: Vector2<f64>, v: Vector2<f64>, t: f64| {
        (q + v * t + accel * (0.5 * t * t), v + accel * t)
    };
    let gap = |t: f64| model.gaps(&fly(q0, v0, t).0)[0];
    let (mut lo, mut hi) = (0.0, tau);
    assert!(gap(lo) > 0.0 && gap(hi) < 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if gap(mid) > 0.0 { lo = mid } else { hi = mid }
    }
    let (q_hit, v_minus) = fly(q0, v0, lo);
    let n = Vector2::new(-2.0 * q_hit.x, 1.0);
    let v_plus = v_minus - n * ((1.0 + e) * n.dot(&v_minus) / n.dot(&n));
    let (q1, v1) = fly(q_hit, v_plus, tau - lo);
    assert!(model.gaps(&q1)[0] > 0.0);
    let error = error_after_one_update(&mut filter, tau, (q1, v1));
    eprintln!(
        "impact at {:.3e} s, rebound {:.2e} m/s across; contacts {:?}, |v̂ − v| = {error:.2e} m/s",
        lo,
        n.normalize().dot(&v_plus),
        filter.report().contacts
    );
    assert!(error <= s / 10.0, "{error:e}");
    assert!(filter.report().contacts.is_empty());
}

/// The double pendulum's tip reaches the corner of the wall and the floor
/// only at the arm's full reach (`1.2² + 1.6² = (l1 + l2)²`), where the
/// two constraints' gradients are nearly opposite in joint space: a tip
/// swept along the floor grazes the wall there (its gap falls to 3e-8 m
/// and opens again, no impact), and a tip driven into the corner bounces
/// between wall and floor in an accumulation while the arm swings on at
/// 1.3 rad/s. On ten random starts (drawn with the seed 99, none picked;
/// four of them pass the corner), on exact samples and at `σ = 1e-4`,
/// against the plant: no restart of either estimator, and off the samples
/// that bracket a plant impact (38) within 0.1 rad/s and the filter within
/// 2e-2 (measured: at most 1.5e-2, at σ = 1e-4 on start 7, and 1.4e-2 on
/// exact samples of start 2). At σ = 1e-4 it was 9.1e-3 (1.1e-2 before
/// each constraint's band was its own gap's deviation) until the filter
/// let a contact lift off at the end of a piece (`lifted` in
/// `runtime/src/observer/kalman/propagate.rs`): start 7's tip now leaves
/// the floor with the plant at 5.595 s (1.0e-5 rad/s off where the
/// projection left 6.4e-5), and the corner accumulation 70 ms later, whose
/// outcome turns on such differences, ends with the estimate held on the
/// wall where the plant slides on the floor, 1.5e-2 off for a few samples.
/// Inside the corner's accumulations the filter was up to
/// 7.7e-2 off while its saltation matrix was Newton's law on both
/// constraints where the contact rule had met them one at a time; it is
/// now the product of the single impacts' (module docs of
/// `runtime/src/observer/kalman/propagate.rs`). Before, a plastic closure on both constraints at the
/// corner took the estimates to zero (error 1 rad/s, the filter then
/// refusing samples and restarting), and Newton's law on both at once
/// gave (38)'s estimate about 35 times its kinetic energy (13 rad/s off): see `turns_within_band`, `opposed` and
/// `gains_energy` in `runtime/src/observer/interval.rs`.
#[test]
fn the_double_pendulum_passes_the_corner_at_its_full_reach() {
    passes_the_corner_at_full_reach(&DoublePendulum::<f64>::new());
}

moreau::model! {
    /// The double pendulum of `models/double_pendulum.yaml` with
    /// restitution 0.3 instead of 0.8. Written for
    /// `a_low_bounce_double_pendulum_passes_the_corner_at_its_full_reach`.
    pub struct LowBouncePendulum;
    coordinates { th1: w1, th2: w2 }
    parameters { m1: 1.0, m2: 1.0, l1: 1.0, l2: 1.0, g: 9.81, b: 0.05, wall: 1.2, floor: 1.6 }
    let x_tip = l1 * sin(th1) + l2 * sin(th2);
    let y_tip = -l1 * cos(th1) - l2 * cos(th2);
    kinetic = 0.5 * (m1 + m2) * l1^2 * w1^2 + 0.5 * m2 * l2^2 * w2^2
        + m2 * l1 * l2 * w1 * w2 * cos(th1 - th2);
    potential = -(m1 + m2) * g * l1 * cos(th1) - m2 * g * l2 * cos(th2);
    applied { th1: -b * w1 + b * (w2 - w1), th2: -b * (w2 - w1) }
    constraints { wall: wall - x_tip >= 0, floor: y_tip + floor >= 0 }
    restitution = 0.3;
}

/// [`the_double_pendulum_passes_the_corner_at_its_full_reach`] with
/// restitution 0.3 ([`LowBouncePendulum`]): the bounces in the corner die
/// out within a few milliseconds. In a scratch run that found it, the
/// floor bounced 23 µs before the wall, and the wall's impact then met the
/// floor again, which was held along the piece between and so joined it
/// in one law (the rule for a fast impact beside a resting contact, as a
/// time-stepping plant's index set holds it). On two nearly opposite
/// gradients Newton's law on both reverses whatever velocity they do not
/// see: the arm's swing went from (−1.60, 1.60) to (1.11, −1.11) rad/s.
/// The floor was leaving, `J w = +5.7e-4` m/s and open by 1.1e-8 m; a
/// held contact now joins a fast impact only where it is not separating
/// (`runtime/src/observer/interval/traced.rs`). Asserted as there, on the
/// same ten starts.
///
/// Measured: the filter within 1.4e-2 rad/s off the brackets (start 2,
/// σ = 1e-4) and (38) within 2.5e-2; before, start 2's exact samples had
/// both 4.4 rad/s off (the contact rule is theirs in common).
#[test]
fn a_low_bounce_double_pendulum_passes_the_corner_at_its_full_reach() {
    passes_the_corner_at_full_reach(&LowBouncePendulum::<f64>::new());
}

moreau::model! {
    /// The three balls of `models/three_balls.yaml` with restitution 0.3
    /// at every contact instead of 0.7 and 0.9. Written for
    /// `balls_left_touching_by_a_collapse_part_as_the_samples_show`.
    pub struct LowBounceBalls;
    coordinates { x1: v1, x2: v2, x3: v3 }
    parameters { m1: 1.0, m2: 1.0, m3: 1.0, r: 0.125, L: 2.5 }
    kinetic = 0.5 * (m1 * v1^2 + m2 * v2^2 + m3 * v3^2);
    potential = 0;
    constraints {
        left_wall: x1 - r >= 0,
        balls_1_2: x2 - x1 - 2 * r >= 0,
        balls_2_3: x3 - x2 - 2 * r >= 0,
        right_wall: L - r - x3 >= 0,
    }
    restitution = 0.3;
    initial { x1: 0.5, x2: 1.25, x3: 1.5, v1: 2.0, v2: 0.0, v3: 0.0 }
}

/// Three balls between two walls with restitution 0.3
/// ([`LowBounceBalls`]), twelve starts drawn around the shipped initial
/// state (seed 99: positions within 0.05 m, speeds within 1 m/s, none
/// picked). On most of them the balls end in an inelastic collapse
/// against a wall within a second or two, after which the plant's balls
/// drift apart at 1e-4 to 1e-3 m/s while the filter's contact rule has
/// them touching: no force holds them, and no single sample can tell
/// resting from leaving that slowly. Held, a contact has no variance
/// across it, and no sample past the gate shows it open: before the
/// filter weighed the run of samples against each held contact (module
/// `opening` of `runtime/src/observer/kalman`), start 11's wall contact
/// stayed held 2.6 deviations open for seconds, the balls beside it were
/// 7.5e-2 m/s off, the gate skipped 234 of 5 001 samples, and the
/// velocity NEES median was 3e5; start 1 skipped 74 and was 4.0e-2 off.
///
/// Plant at `τ = 1e-5`, 1 kHz, `σ = 1e-4`, `v̂(0) = 0`, the filter's
/// defaults, scored over `[1, 5]` s. Asserted on every start: no restart
/// or refusal, at most 1 % of the samples skipped, and at most 2e-2 m/s
/// off the samples that bracket a plant impact. Measured: at most 28
/// skipped (start 9), at most 1.2e-2 off (start 6, unchanged by the
/// weighing); start 11 now 1 skipped, 1.07e-2 off, NEES median 2.6. The
/// NEES of starts 2 to 5 and 8 to 10 stays between 1.9e2 and 6.1e3: what
/// their collapses leave is a velocity error of 1e-5 to 1e-3 m/s on balls
/// that fly free (the collapse's many small impacts contract the
/// covariance, and the plant's step, not in the model, shifts the
/// outcome), not a held contact.
#[test]
fn balls_left_touching_by_a_collapse_part_as_the_samples_show() {
    let model = LowBounceBalls::<f64>::new();
    let u = SVector::zeros();
    let (q0, v0) = LowBounceBalls::<f64>::initial_state();
    let mut g = Gauss::new(99);
    let mut starts = Vec::new();
    while starts.len() < 12 {
        let q = q0 + Vector3::from_fn(|_, _| 0.05 * (2.0 * g.uniform() - 1.0));
        let v = v0 + Vector3::from_fn(|_, _| 2.0 * g.uniform() - 1.0);
        if model.gaps(&q).iter().all(|&h| h >= 0.0) {
            starts.push((q, v));
        }
    }
    let sigma = 1e-4;
    for (n, &start) in starts.iter().enumerate() {
        let data = reference(&model, start, 1e-5, 100, 5.0, &u);
        let measured = measure(&data, sigma, 7 + n as u64);
        let bracket = brackets(&data);
        let params = KalmanParams::new(40.0, sigma);
        let mut filter =
            SaltationKalman::<f64, 3, 4>::new(params, 0.0, measured[0], Vector3::zeros()).unwrap();
        let (mut skipped, mut released, mut nees) = (0, 0, Vec::new());
        let f = run_counting(
            &mut filter,
            &model,
            (&data, &measured),
            &u,
            (1.0, 5.0),
            |j, f: &SaltationKalman<f64, 3, 4>| {
                let report = f.kalman_report();
                skipped += usize::from(report.outlier);
                released += report.released;
                if data.samples[j].t >= 1.0 && !bracket[j] {
                    let d = data.samples[j].v - f.estimate().v;
                    let p = f.covariance().vv;
                    nees.push(d.dot(&p.cholesky().expect("P_vv positive definite").solve(&d)));
                }
            },
        );
        nees.sort_by(f64::total_cmp);
        eprintln!(
            "start {n}: median {:.2e} max off the brackets {:.2e}, {skipped} skipped, {released} contacts released, velocity NEES median {:.1}",
            f.scored.all.median,
            f.scored.clean.max,
            nees[nees.len() / 2]
        );
        assert_eq!((f.restarts, f.refused), (0, 0), "start {n}");
        assert!(
            skipped * 100 <= data.samples.len(),
            "start {n}: {skipped} skipped"
        );
        assert!(
            f.scored.clean.max <= 2e-2,
            "start {n}: {:e}",
            f.scored.clean.max
        );
    }
}

/// The runs of [`the_double_pendulum_passes_the_corner_at_its_full_reach`]
/// on `model` (a double pendulum with that wall and floor), and its
/// assertions.
fn passes_the_corner_at_full_reach<M>(model: &M)
where
    M: Sensitivities<2, 2, Scalar = f64, Input = SVector<f64, 0>> + std::fmt::Debug + 'static,
{
    let u = SVector::zeros();
    let mut g = Gauss::new(99);
    let mut starts = Vec::new();
    while starts.len() < 10 {
        let q = Vector2::new(3.0 * g.uniform() - 1.5, 3.0 * g.uniform() - 1.5);
        let v = Vector2::new(6.0 * g.uniform() - 3.0, 6.0 * g.uniform() - 3.0);
        if model.gaps(&q).iter().all(|&h| h >= 0.05) {
            starts.push((q, v));
        }
    }
    for (n, &start) in starts.iter().enumerate() {
        let data = reference(model, start, 1e-5, 100, 10.0, &u);
        for sigma in [0.0, 1e-4] {
            let measured = measure(&data, sigma, 500 + n as u64);
            let params = KalmanParams::new(20.0, sigma);
            let mut filter =
                SaltationKalman::<f64, 2, 2>::new(params, 0.0, measured[0], Vector2::zeros())
                    .unwrap();
            let f = run_counting(
                &mut filter,
                model,
                (&data, &measured),
                &u,
                WINDOW,
                |_, _| {},
            );
            let params = ObserverParams::new(10.0, 20.0).with_noise(sigma);
            let mut observer =
                ReducedOrder::<f64, 2, 2>::new(params, 0.0, measured[0], Vector2::zeros()).unwrap();
            let o = run_counting(
                &mut observer,
                model,
                (&data, &measured),
                &u,
                WINDOW,
                |_, _| {},
            );
            eprintln!(
                "{}, start {n} {start:?}, σ = {sigma:e}: filter median {:.2e} max off the brackets {:.2e}, {} restarts; (38) median {:.2e} max off the brackets {:.2e}, {} restarts",
                M::INFO.name,
                f.scored.all.median,
                f.scored.clean.max,
                f.restarts,
                o.scored.all.median,
                o.scored.clean.max,
                o.restarts
            );
            let at = format!("start {n}, σ = {sigma:e}");
            // no restart, and no sample refused
            let counts = (f.restarts, f.refused, o.restarts, o.refused);
            assert_eq!(counts, (0, 0, 0, 0), "{at}");
            assert!(
                o.scored.clean.max <= 0.1,
                "{at}: (38) {:e}",
                o.scored.clean.max
            );
            assert!(
                f.scored.clean.max <= 2e-2,
                "{at}: filter {:e}",
                f.scored.clean.max
            );
        }
    }
}

/// A held contact does no work on an estimate that separates from it.
/// Example 1's mass slides along the floor at `x = 0.3` at 5 m/s, and
/// the estimate also leaves the floor at `s` = 0.01 to 0.04 m/s, slower
/// than the contact rule's resting speed, so the rule holds the floor.
/// The samples are given no weight (`σ = 1` m against a covariance of
/// 1e-5 m and 1e-3 m/s), so one update is the prediction, and energy
/// (`½|v|² + g y`, the mass is 1 kg) is the reference: a frictionless
/// contact may take out the separating speed's share,
/// `½ s²`, but never add any.
///
/// Before, the floor pushed with about 40 m/s² (the centripetal and
/// normal-gravity acceleration of the slide) on the separating estimate
/// for the whole millisecond, adding `λ s τ`, and the projection onto
/// the floor at the end kept that energy as tangential speed: +2.6e-4,
/// +4.2e-4 and +4.5e-4 J/kg. Measured now: `−½ s²`, to within the
/// printed difference.
#[test]
fn a_held_contact_does_no_work_on_a_separating_estimate() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let g = 9.81;
    let energy = |q: &Vector2<f64>, v: &Vector2<f64>| 0.5 * v.norm_squared() + g * q[1];
    let x = 0.3;
    let q0 = Vector2::new(x, x * x);
    let tangent = Vector2::new(1.0, 2.0 * x).normalize();
    let normal = Vector2::new(-2.0 * x, 1.0).normalize();
    let p0 = Blocks::diagonal(SMatrix::identity() * 1e-10, SMatrix::identity() * 1e-6);
    for separating in [0.01, 0.02, 0.04] {
        let v0 = tangent * 5.0 + normal * separating;
        let params = KalmanParams::new(20.0, 1.0);
        let mut filter =
            SaltationKalman::<f64, 2, 2>::with_covariance(params, 0.0, q0, v0, p0).expect("filter");
        let sample = q0 + tangent * 5e-3;
        let e = filter.update(&model, 1e-3, &sample, &u).expect("update");
        let report = filter.report();
        assert!(
            report.contacts.contains(0),
            "s = {separating}: floor not held"
        );
        let change = energy(&e.q, &e.v) - energy(&q0, &v0);
        eprintln!(
            "separating at {separating} m/s: energy change {change:+.3e} J/kg (½ s² = {:.3e}; difference {:+.1e})",
            0.5 * separating * separating,
            change + 0.5 * separating * separating
        );
        assert!(change <= 1e-9, "s = {separating}: gained {change:e} J/kg");
        assert!(
            change >= -0.5 * separating * separating - 1e-9,
            "s = {separating}: lost {change:e} J/kg"
        );
    }
}

/// The filter's prediction never gains energy on Example 1, a
/// frictionless system whose impacts can only lose it. Twenty-four
/// random starts (seeds 555 and 777), `σ = 1e-4`, the defaults; at every
/// sample after 0.5 s a filter started from the running filter's
/// estimate and covariance, with the samples given no weight (`R = 1`
/// m²), is stepped to the next sample, so its update is the prediction
/// (its energy `½|v|² + g y` moves by the rounding and the Runge–Kutta
/// truncation only, unless the prediction puts energy in). Asserted: no
/// rise above 1e-7 J/kg. Measured: at most 2.3e-8 J/kg (seed 555, start
/// 6, at 8.273 s; 2.2e-9 before the held contacts' levels, module docs of
/// `runtime/src/observer/kalman/level.rs`: the filter started from the
/// running one's estimate does not have that filter's levels and holds
/// its contacts at the surface, which lifts an estimate held below it; my
/// reading, not traced: `g` times 2.3e-9 m is the gain); before held
/// contacts were settled at the start of a piece, 1.3e-4 J/kg (seed
/// 555, start 6, at 5.302 s: the floor pushing on an estimate leaving
/// it; see `a_held_contact_does_no_work_on_a_separating_estimate`).
#[test]
fn the_filters_prediction_never_gains_energy_on_example_1() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let energy = |q: &Vector2<f64>, v: &Vector2<f64>| 0.5 * v.norm_squared() + 9.81 * q[1];
    let mut unweighted = KalmanParams::new(20.0, 1e-4);
    unweighted.measurement = SMatrix::identity();
    let mut worst = (f64::NEG_INFINITY, String::new());
    for seed in [555, 777] {
        for (n, start) in random_example_1_starts(seed, 12).into_iter().enumerate() {
            let data = reference(&model, start, 1e-5, 100, 10.0, &u);
            let measured = measure(&data, 1e-4, 100 + n as u64);
            let params = KalmanParams::new(20.0, 1e-4);
            let mut filter =
                SaltationKalman::<f64, 2, 2>::new(params, 0.0, measured[0], Vector2::zeros())
                    .expect("filter");
            for (s, q) in data.samples.iter().zip(&measured).skip(1) {
                let before = filter.estimate();
                if s.t > 0.5 {
                    let mut prediction = SaltationKalman::<f64, 2, 2>::with_covariance(
                        unweighted,
                        before.t,
                        before.q,
                        before.v,
                        *filter.covariance(),
                    )
                    .expect("prediction");
                    let after = prediction.update(&model, s.t, q, &u).expect("prediction");
                    let gain = energy(&after.q, &after.v) - energy(&before.q, &before.v);
                    if gain > worst.0 {
                        worst = (gain, format!("seed {seed}, start {n}, t = {:.3}", s.t));
                    }
                }
                match filter.update(&model, s.t, q, &u) {
                    Ok(_) | Err(ObserverError::Outlier { .. }) => {}
                    Err(e) => panic!("seed {seed}, start {n}, t = {}: {e:?}", s.t),
                }
            }
        }
    }
    eprintln!(
        "largest energy gain of a prediction: {:.2e} J/kg ({})",
        worst.0, worst.1
    );
    assert!(worst.0 <= 1e-7, "{:e} J/kg at {}", worst.0, worst.1);
}

/// A sample inside a held contact is read on it. A compliant contact
/// under a steady force shows the encoder a position inside the
/// constraint, which a rigid model has no state for; emulated here on
/// [`Bowl`]'s first drawn start (it ends sliding along the rim) by moving
/// each sample taken while the plant is on the rim (its gap under 1e-7 m)
/// 10 σ outward, at σ = 1e-6 m, 1 kHz, over 10 s.
///
/// Before the filter read such samples on the contact, the prediction,
/// projected onto the rim, left almost no variance across it, and each
/// of these samples failed the gate: two skipped, the third taken with
/// `P` inflated, and again. It used one sample in three on the rim (5009
/// of the run's 10 000 skipped), and its median error over [2, 10] s
/// went from 1.39e-6 m/s on the samples as they are to 2.74e-4 (the
/// maximum off the brackets 1.39e-3 to 1.69e-3).
///
/// (38) (`l_d` = 10, told σ) on the same samples: it smooths its position
/// from the sample, held within four of the smoothing's deviations of it,
/// so before it read such samples on the contact its predicted motion
/// started inside the rim every interval, and its median went from
/// 1.10e-5 to 2.22e-5.
///
/// Asserted: the pressed samples leave each estimator's median within
/// 1.5 times that of the samples as they are, the filter's maximum off
/// the bracketing samples within 1e-2 and (38)'s within the issue's 0.1,
/// and the gate skips under one sample in a hundred (measured: the
/// filter's median the same, 1.39e-6, none skipped; (38)'s 7.4e-6, below
/// the 1.10e-5 of the samples as they are, since the samples read on the
/// rim carry no noise across it).
#[test]
fn a_sample_inside_a_held_contact_is_read_on_it() {
    let model = Bowl::<f64>::default();
    let u = SVector::zeros();
    let (bowl, _) = drawn_starts();
    let data = reference(&model, bowl[0], 1e-5, 100, 10.0, &u);
    let sigma = 1e-6;
    let as_they_are = measure(&data, sigma, 100);
    let mut pressed = as_they_are.clone();
    let mut on_rim = 0;
    for (s, q) in data.samples.iter().zip(&mut pressed) {
        if (1.0 - s.q.norm_squared()).abs() < 1e-7 {
            *q += s.q.normalize() * (10.0 * sigma);
            on_rim += 1;
        }
    }
    let run = |measured: &[Vector2<f64>]| {
        let (counted, skipped) =
            filter_counting(&model, (&data, measured), &u, (20.0, sigma), (2.0, 10.0));
        (counted.scored, skipped)
    };
    let (plain, _) = run(&as_they_are);
    let (read, skipped) = run(&pressed);
    eprintln!(
        "{on_rim} of {} samples on the rim, pressed 10 σ in: median {:.2e} (as they are {:.2e}), max off the brackets {:.2e} ({:.2e}), {skipped} skipped by the gate",
        pressed.len(),
        read.all.median,
        plain.all.median,
        read.clean.max,
        plain.clean.max
    );
    assert!(2 * on_rim > pressed.len(), "the start slides along the rim");
    assert!(read.all.median <= 1.5 * plain.all.median);
    assert!(read.clean.max <= 1e-2);
    assert!(100 * skipped < pressed.len(), "{skipped} skipped");
    let run_38 = |measured: &[Vector2<f64>]| {
        let params = ObserverParams::new(10.0, 20.0).with_noise(sigma);
        let mut observer =
            ReducedOrder::<f64, 2, 1>::new(params, 0.0, measured[0], Vector2::zeros()).unwrap();
        let counted = run_counting(
            &mut observer,
            &model,
            (&data, measured),
            &u,
            (2.0, 10.0),
            |_, _| {},
        );
        assert_eq!((counted.restarts, counted.refused), (0, 0));
        counted.scored
    };
    let (plain, read) = (run_38(&as_they_are), run_38(&pressed));
    eprintln!(
        "(38): median {:.2e} (as they are {:.2e}), max off the brackets {:.2e} ({:.2e})",
        read.all.median, plain.all.median, read.clean.max, plain.clean.max
    );
    assert!(read.all.median <= 1.5 * plain.all.median);
    assert!(read.clean.max <= 0.1);
}

/// A contact that the samples show open is released. Example 1's mass
/// rests at the bottom of the parabola for 0.5 s (σ = 1e-4; the filter
/// holds the floor and projects its covariance onto it), then an
/// unmodelled kick sends it up at `v = (0.3, 1)` m/s: a free flight,
/// `x = 0.3 s`, `y = s − g s²/2`, until it lands again 0.2 s later. The
/// model cannot predict the kick, and the projection left no variance
/// across the floor for the samples to act on: the filter kept the mass
/// on the floor, refusing samples and inflating its covariance every
/// third one, and its error was 0.51 m/s 50 ms after the kick and 2.6e-2
/// at 100 ms. Now, once the samples fail the gate three times in a row
/// (the filter's test that the model, not the sample, is wrong), the
/// floor they show open is released, its normal position and speed made
/// uncertain again: the error is at most 3.0e-3 from 50 to 150 ms after
/// the kick and 3.6e-4 at 100 ms (asserted: 1e-2 and 1e-3).
#[test]
fn a_contact_the_samples_show_open_is_released() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let (sigma, kick, g) = (1e-4, 0.5, 9.81);
    let truth = |t: f64| {
        let s = t - kick;
        if s <= 0.0 {
            (Vector2::zeros(), Vector2::zeros())
        } else {
            (
                Vector2::new(0.3 * s, s - 0.5 * g * s * s),
                Vector2::new(0.3, 1.0 - g * s),
            )
        }
    };
    let mut noise = Gauss::new(77);
    let mut filter = SaltationKalman::<f64, 2, 2>::new(
        KalmanParams::new(20.0, sigma),
        0.0,
        Vector2::zeros(),
        Vector2::zeros(),
    )
    .unwrap();
    let (mut worst, mut at_100ms) = (0.0_f64, 0.0);
    for k in 1..=650 {
        let t = k as f64 * 1e-3;
        let (q, v) = truth(t);
        let measured = q + Vector2::new(noise.normal(), noise.normal()) * sigma;
        let estimate = match filter.update(&model, t, &measured, &u) {
            Ok(e) => e,
            Err(ObserverError::Outlier { .. }) => filter.estimate(),
            Err(e) => panic!("t = {t}: {e:?}"),
        };
        let error = (estimate.v - v).norm();
        if t > kick + 0.05 - 1e-9 && t < kick + 0.15 {
            worst = worst.max(error);
        }
        if (t - (kick + 0.1)).abs() < 1e-9 {
            at_100ms = error;
        }
    }
    eprintln!(
        "released: error at most {worst:.2e} from 50 to 150 ms after the kick, {at_100ms:.2e} at 100 ms"
    );
    assert!(worst < 1e-2 && at_100ms < 1e-3, "{worst:e}, {at_100ms:e}");
}

/// The billiard's corners under noise, ten starts drawn with the seed
/// 31337 (`x, y` uniform in [−0.4, 0.4], `v` in [−2, 2]², none picked; a
/// seed no earlier fix was found on), `σ = 1e-4`, 6 s of plant at `τ =
/// 1e-5` sampled at 1 kHz. A corner sequence is a run of plant impacts on
/// different walls less than 0.5 ms apart (the ball bouncing floor, wall,
/// floor); after each that ends past 1 s, the estimators' largest error
/// over the 2nd to 10th samples (the noise decides nothing there any
/// more).
///
/// With a band about `σ` wide, a ball that bounced off the floor and
/// reached the wall 0.14 ms later was still within the floor's band, and
/// the floor, separating at 0.16 m/s, took a plastic share of the wall's
/// impulse: the filter and (38) left that corner 0.13 m/s off (start 5),
/// and the filter's worst over all sequences was 0.33 m/s. A constraint
/// that has just bounced (in this interval or the last) and separates
/// faster than its resting speed now takes no part in an impact on the
/// others (`Interval::classify`, module docs of
/// `runtime/src/observer/mod.rs`); a glued pair, which never bounced,
/// still does (`glued_balls_hit_the_wall_together_in_both_observers` in
/// `tests/observer.rs`).
///
/// Asserted: the filter within 0.1 after every sequence (measured: at
/// most 8.0e-2 since the reserve of
/// `a_box_rocking_onto_a_corner_keeps_the_other_law_in_reserve`, 5.6e-2
/// before it, 6.0e-2 before each constraint's band was its own gap's
/// deviation); (38), which corrects at its rate `l_d` only, above 0.1
/// after at most a fifth of them (measured 2 of 18, at 0.23 and 0.51,
/// unchanged by the fix; before: 7 of 18).
#[test]
fn a_wall_just_left_takes_no_part_in_the_impact_on_the_next() {
    let model = Billiard::<f64>::new();
    let u = SVector::zeros();
    let sigma = 1e-4;
    let mut g = Gauss::new(31337);
    let (mut n, mut sequences, mut over_38, mut worst) = (0, 0, 0, (0.0f64, 0.0f64));
    while n < 10 {
        let q = Vector2::new(0.8 * g.uniform() - 0.4, 0.8 * g.uniform() - 0.4);
        let v = Vector2::new(4.0 * g.uniform() - 2.0, 4.0 * g.uniform() - 2.0);
        if model.gaps(&q).iter().any(|&h| h < 0.02) {
            continue;
        }
        let data = reference(&model, (q, v), 1e-5, 100, 6.0, &u);
        let measured = measure(&data, sigma, 7 + n as u64);
        let mut f = SaltationKalman::<f64, 2, 4>::new(
            KalmanParams::new(20.0, sigma),
            0.0,
            measured[0],
            Vector2::zeros(),
        )
        .unwrap();
        let mut o = ReducedOrder::<f64, 2, 4>::new(
            ObserverParams::new(10.0, 20.0).with_noise(sigma),
            0.0,
            measured[0],
            Vector2::zeros(),
        )
        .unwrap();
        let errors = |estimates: Vec<Estimate<f64, 2>>| -> Vec<f64> {
            data.samples
                .iter()
                .zip(&estimates)
                .map(|(s, e)| (s.v - e.v).norm())
                .collect()
        };
        let filter = errors(run(&mut f, &model, &data, &measured, &u));
        let observer = errors(run(&mut o, &model, &data, &measured, &u));
        // the corner sequences: (first impact, last impact, walls met)
        let mut runs: Vec<(f64, f64, IndexSet<4>)> = Vec::new();
        for &(t, i, _) in &data.impacts {
            match runs.last_mut() {
                Some((_, last, walls)) if t - *last < 5e-4 => {
                    *last = t;
                    walls.insert(i);
                }
                _ => {
                    let mut walls = IndexSet::EMPTY;
                    walls.insert(i);
                    runs.push((t, t, walls));
                }
            }
        }
        for (first, last, walls) in runs {
            if walls.len() < 2 || last < 1.0 {
                continue;
            }
            let k = (last / 1e-3).ceil() as usize;
            let after = |e: &[f64]| e[k + 2..=k + 10].iter().copied().fold(0.0, f64::max);
            let (ef, eo) = (after(&filter), after(&observer));
            eprintln!(
                "start {n}, corner {walls:?} at {first:.4} to {last:.4} s: largest error 2 to 10 samples after, filter {ef:.2e}, (38) {eo:.2e}"
            );
            sequences += 1;
            over_38 += usize::from(eo > 0.1);
            worst = (worst.0.max(ef), worst.1.max(eo));
            assert!(ef <= 0.1, "start {n}, corner at {first}: filter {ef:e}");
        }
        n += 1;
    }
    eprintln!(
        "{sequences} corner sequences: filter at most {:.2e}; (38) above 0.1 after {over_38} (at most {:.2e})",
        worst.0, worst.1
    );
    assert!(sequences >= 10, "{sequences} corner sequences");
    assert!(
        5 * over_38 <= sequences,
        "(38) above 0.1 after {over_38} of {sequences}"
    );
}

/// The three balls' filter in the scalar `$t` on one noisy run (σ = 1e-4,
/// noise seed `seed`): the largest `|v̂₃ − v̂₂|` while the plant carries
/// balls 2 and 3 glued together (from the sample after its first impact
/// to the one before its second, where the pair meets the right wall),
/// and the largest error over the ten samples after that wall impact, the
/// two that bracket it left out.
macro_rules! glued_flight {
    ($t:ty, $seed:expr) => {{
        let model = ThreeBalls::<$t>::new();
        let truth = ThreeBalls::<f64>::new();
        let data = reference(
            &truth,
            ThreeBalls::<f64>::initial_state(),
            1e-5,
            100,
            1.0,
            &Default::default(),
        );
        let (glued, wall) = (data.impacts[0].0, data.impacts[1].0);
        let measured = measure(&data, 1e-4, $seed);
        let mut f = SaltationKalman::<$t, 3, 4>::new(
            KalmanParams::new(20.0, 1e-4),
            0.0,
            measured[0].cast(),
            SVector::zeros(),
        )
        .unwrap();
        let (mut apart, mut after) = (0.0_f64, 0.0_f64);
        for (s, q) in data.samples.iter().zip(&measured).skip(1) {
            let e = f
                .update(&model, s.t as $t, &q.cast(), &Default::default())
                .unwrap();
            let v: SVector<f64, 3> = e.v.cast();
            if s.t > glued + 1e-3 && s.t < wall - 1e-3 {
                apart = apart.max((v[2] - v[1]).abs());
            }
            if s.t > wall + 1e-3 && s.t < wall + 11e-3 {
                after = after.max((v - s.v).norm());
            }
        }
        (apart, after)
    }};
}

/// Balls 2 and 3 fly glued together from the first impact of the three
/// balls on (no force holds them together, none pulls them apart: their
/// contact rests with zero multiplier), and the filter's estimate must
/// keep them so: the contact rule calls such a contact resting, and the
/// filter holds it on its manifold as it holds a contact pushed onto it
/// (`Interval::classify`, `resting`). Otherwise the pair's relative
/// velocity is only as well known as the samples make it, drifts on
/// their noise, and the estimate takes the pair apart: the wall impact at
/// 0.94 s is then resolved as a sequence of single impacts, not as the
/// plant's simultaneous one. In `f32`, where the pair's relative speed
/// after the first impact is a unit of the last place (1.2e-7 m/s) and
/// so never seen approaching, that left the pair's velocities 0.13 m/s
/// off after the wall on two of the six noise seeds below.
///
/// Asserted on six noise seeds (σ = 1e-4), in `f64` and in `f32`: over
/// the glued flight `|v̂₃ − v̂₂|` at most 1e-6 m/s, and after the wall
/// impact (the ten samples after, the bracketing two left out) the error
/// at most 1e-3.
#[test]
fn glued_balls_stay_glued_in_the_filter() {
    for seed in 1..=6 {
        let (apart_64, after_64) = glued_flight!(f64, seed);
        let (apart_32, after_32) = glued_flight!(f32, seed);
        eprintln!(
            "three balls, noise seed {seed}: |v3 - v2| in glued flight at most {apart_64:.1e} (f64), {apart_32:.1e} (f32); error after the wall {after_64:.1e} (f64), {after_32:.1e} (f32)"
        );
        for (apart, after, scalar) in [(apart_64, after_64, "f64"), (apart_32, after_32, "f32")] {
            assert!(apart <= 1e-6, "seed {seed}, {scalar}: {apart:e}");
            assert!(after <= 1e-3, "seed {seed}, {scalar}: {after:e}");
        }
    }
}

/// Exact samples of the three-link arm, the filter told a generous
/// velocity bound (`C_v` = 200 rad/s, so `P_vv` starts at 4e4), from `v̂(0)
/// = 0`. Linearised at that guess, the first update pinned the velocity
/// from exact positions to a `P_vv` near 8e-10 while its error was 9e-3
/// (the linearisation at `v̂ = 0` misses the arm's Coriolis forces); the
/// next samples failed the gate, the inflated `P_vv` came out indefinite,
/// and the filter either refused every sample after (7236 of 8000 on
/// start 1; medians of 8 to 12 rad/s on three of the four starts) or,
/// once such a state restarted it, restarted 1 to 12 times in the first
/// 250 ms with errors up to 200 rad/s (the restart's velocity came from
/// the diverged position estimate). The first update after a start now
/// relinearises (Gauss–Newton on the prior's velocity), and a restart's
/// velocity comes from the last sample used.
///
/// Four random starts (seed 31, none picked; joint speeds up to 57
/// rad/s), 8 s each against the plant, scored from the first update on:
/// no restart, no sample refused, medians ≤ 1e-8 and maxima ≤ 1e-3
/// (measured: medians 3.9e-10 to 2.9e-9, maxima 3.1e-5 to 3.6e-4, the
/// largest at the arm's impacts).
#[test]
fn exact_samples_and_a_generous_velocity_bound_do_not_wedge_the_filter() {
    let model = Arm3::<f64>::new();
    let u = Vector3::zeros();
    let mut g = Gauss::new(31);
    let mut n = 0;
    while n < 4 {
        let q = Vector3::new(
            3.0 * g.uniform() - 1.5,
            3.0 * g.uniform() - 1.5,
            3.0 * g.uniform() - 1.5,
        );
        let v = Vector3::new(
            4.0 * g.uniform() - 2.0,
            4.0 * g.uniform() - 2.0,
            4.0 * g.uniform() - 2.0,
        );
        if model.gaps(&q)[0] < 0.02 {
            continue;
        }
        let data = reference(&model, (q, v), 1e-5, 100, 8.0, &u);
        let params = KalmanParams::new(200.0, 0.0);
        let mut filter =
            SaltationKalman::<f64, 3, 1>::new(params, 0.0, data.samples[0].q, Vector3::zeros())
                .unwrap();
        let exact = measure(&data, 0.0, 0);
        let Counted {
            scored,
            restarts,
            refused,
        } = run_counting(
            &mut filter,
            &model,
            (&data, &exact),
            &u,
            (1e-3, 8.0),
            |_, _| {},
        );
        eprintln!(
            "arm, start {n}: median {:.2e}, max {:.2e}, {restarts} restarts, {refused} samples refused",
            scored.all.median, scored.all.max
        );
        assert!(
            scored.all.median <= 1e-8,
            "start {n}: {:e}",
            scored.all.median
        );
        assert!(scored.all.max <= 1e-3, "start {n}: {:e}", scored.all.max);
        assert_eq!((restarts, refused), (0, 0), "start {n}");
        n += 1;
    }
}

/// An initial state `(q0, v0)` of a model of two coordinates (Example 1,
/// [`Bowl`], [`CartPole`]).
type Start = (Vector2<f64>, Vector2<f64>);

/// Random Example 1 starts whose exact solution ([`common::exact`]) does
/// not accumulate within 10 s: `(start, exact run)` for `count` draws of
/// `x ∈ [−1, 1]`, a height `0.5` to `4.5` above the parabola,
/// `v ∈ [−3, 3]²`.
fn exact_starts(seed: u64, count: usize) -> Vec<(Start, Reference<2>)> {
    let mut g = Gauss::new(seed);
    (0..count)
        .filter_map(|_| {
            let x = 2.0 * g.uniform() - 1.0;
            let y = x * x + 0.5 + 4.0 * g.uniform();
            let v = Vector2::new(6.0 * g.uniform() - 3.0, 6.0 * g.uniform() - 3.0);
            let start = (Vector2::new(x, y), v);
            common::exact::parabola(start, 10.0, 1e-3).map(|run| (start, run))
        })
        .collect()
}

/// Which plant made the samples, picked from them by the innovation
/// likelihood ([`pick_by_likelihood`]): among no plant (the defaults, a
/// rigid model right about the machine), the crate's law at steps of 5,
/// 10 and 20 µs on the samples' grid, 10 µs off the grid, and Siconos's
/// law at 10 µs, each filter's log-likelihood of the whole record (10 s
/// at 1 kHz, σ = 1e-4) is summed and the largest wins. A margin under
/// one nat (a likelihood ratio under e) is "not worth more than a bare
/// mention" on Kass and Raftery's scale of Bayes factors; the test takes
/// it as no decision. Asserted on Example 1's twelve random starts of
/// seed 555: samples of the crate's plant at 10 µs pick its step on the
/// grid, and samples of Siconos's law at 10 µs pick that law, each by
/// more than a nat (measured 2.4 to 16 and 103 to 1129 nats); on the
/// first six, samples taken halfway between the plant's steps (its
/// states there interpolated, every 100 steps) pick its step off the
/// grid (measured 26 to 44 nats); the first start's record with two
/// samples moved by 1 m still picks the step on the grid (the filters
/// refuse those samples as impossible, and the sum skips them); on the
/// six exact event-driven runs of [`exact_starts`] (no plant: Example 1
/// solved in closed form), no candidate is likelier than no plant by a
/// nat or more (measured: no plant picked on five, by 3.9 to 25 nats;
/// on the sixth, a 5 µs step by 0.7, a finer plant being nearly exact).
///
/// `cargo test --release --test kalman -- --nocapture picks_the_plant` (2 s)
#[test]
fn the_likelihood_picks_the_plant_that_made_the_samples() {
    use common::runs::reference_with;
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let sigma = 1e-4;
    let base = KalmanParams::new(20.0, sigma);
    let [none, fine, plant, off, coarse] = common::runs::plant_candidates(base);
    let siconos = (
        "Siconos's law, 10 µs",
        base.with_plant(StepParams::siconos(1e-5)),
    );
    let candidates = [none, fine, plant, off, coarse, siconos];
    let params = candidates.map(|(_, p)| p);
    // the pick among all the candidates, and the log-likelihood of no
    // plant; with `glitches`, samples moved by 1 m, which every filter
    // refuses as impossible and the sum skips
    let pick_with = |data: &Reference<2>, seed: u64, glitches: &[usize]| {
        let mut measured = measure(data, sigma, seed);
        for &k in glitches {
            measured[k][1] += 1.0;
        }
        let t: Vec<f64> = data.samples.iter().map(|s| s.t).collect();
        let v0 = Vector2::zeros();
        let among = |params: &[KalmanParams<f64, 2>]| {
            pick_by_likelihood::<_, _, 2, 2>(&model, params, &t, &measured, &v0, &u).unwrap()
        };
        (among(&params), among(&params[..1]).log_likelihood)
    };
    let pick = |data: &Reference<2>, seed: u64| pick_with(data, seed, &[]);
    let mut runs = Vec::new();
    for (n, start) in random_example_1_starts(555, 12).into_iter().enumerate() {
        let plant = reference(&model, start, 1e-5, 100, 10.0, &u);
        runs.push((
            "the crate's plant",
            n,
            pick(&plant, 100 + n as u64),
            Some(2),
        ));
        let siconos = reference_with(&model, start, StepParams::siconos(1e-5), 100, 10.0, &u);
        runs.push((
            "Siconos's plant",
            n,
            pick(&siconos, 100 + n as u64),
            Some(5),
        ));
    }
    // the first start's record again, with two glitches
    let plant = reference(
        &model,
        random_example_1_starts(555, 1)[0],
        1e-5,
        100,
        10.0,
        &u,
    );
    let glitched = pick_with(&plant, 100, &[3000, 7000]);
    runs.push(("the crate's plant with two glitches", 0, glitched, Some(2)));
    for (n, start) in random_example_1_starts(555, 6).into_iter().enumerate() {
        // every state of the plant, then every hundredth interval's middle
        let fine = reference(&model, start, 1e-5, 1, 10.0, &u);
        let samples = fine
            .samples
            .windows(2)
            .step_by(100)
            .map(|w| {
                State::new(
                    w[0].t + 5e-6,
                    (w[0].q + w[1].q) * 0.5,
                    (w[0].v + w[1].v) * 0.5,
                )
            })
            .collect();
        let between = Reference {
            samples,
            impacts: Vec::new(),
        };
        runs.push((
            "between the plant's steps",
            n,
            pick(&between, 100 + n as u64),
            Some(3),
        ));
    }
    for (n, (_, exact)) in exact_starts(4242, 40).into_iter().enumerate() {
        runs.push(("exact", n, pick(&exact, 5000 + n as u64), None));
    }
    for (source, n, (picked, no_plant), expected) in &runs {
        let at = format!(
            "{source}, start {n}: picked {} by {:.1} nats, {:.1} over no plant",
            candidates[picked.index].0,
            picked.margin,
            picked.log_likelihood - no_plant
        );
        eprintln!("{at}");
        match expected {
            Some(index) => assert!(picked.index == *index && picked.margin > 1.0, "{at}"),
            // no plant, or no decision against it
            None => assert!(picked.log_likelihood - no_plant < 1.0, "{at}"),
        }
    }
}

/// The issue's targets where the truth is exact: Example 1 solved event
/// by event in closed form ([`common::exact`], checked here against the
/// plant at `τ = 1e-6` up to its third impact), `σ = 1e-4` at 1 kHz,
/// `v̂(0) = 0`, scored over `[2, 10]` s. The knobs are picked by
/// [`tune_process_noise`] from one such record (a start and noise of its
/// own) and used unchanged on six random starts drawn apart (the starts
/// of 40 draws whose impacts do not accumulate: the closed form does not
/// cover sliding).
///
/// Asserted on every run: median ≤ 3e-5, 90th percentile ≤ 2e-4 and,
/// off the two samples bracketing each impact, maximum ≤ 1e-2 m/s. And
/// on the record the knobs come from, that the tuner finds no impact
/// delay: `|δ̄|` and `σ_t` at most 0.1 µs (a tenth of the finer plant's
/// step in `the_likelihood_finds_the_plants_impact_delay`).
///
/// The same filter on the plant's runs misses these on some starts (see
/// `example_1_figures_beside_the_reduced_order_observer`); this test shows
/// where that gap comes from. The plant at `τ = 1e-5` places each impact
/// somewhere inside its step, and so within about `τ/√12` in time of the
/// exact one; after an impact on the curved floor at several m/s that is
/// a velocity error of `1e-4` to `1e-3` m/s that no model of the exact
/// dynamics predicts, so the likelihood asks for impact noise there
/// (`σ_t = 3e-6` s by default), and every impact then costs the estimate
/// the samples it takes to pin the new velocity down. On exact data the
/// tuner finds that noise absent and the targets hold.
#[test]
fn example_1_targets_hold_on_exact_event_driven_data() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    // the closed form against the plant at τ = 1e-6, to the third impact
    let (start, exact) = exact_starts(4242, 40).remove(0);
    let until = exact.impacts[2].0;
    let plant = reference(&model, start, 1e-6, 1000, until, &u);
    for (a, b) in exact.samples.iter().zip(&plant.samples) {
        assert!((a.t - b.t).abs() < 1e-12);
        assert!(
            (a.q - b.q).norm() < 1e-4,
            "t = {}: q {} vs {}",
            a.t,
            a.q,
            b.q
        );
        assert!(
            (a.v - b.v).norm() < 1e-2,
            "t = {}: v {} vs {}",
            a.t,
            a.v,
            b.v
        );
    }
    // the knobs from one record of its own
    let (_, record) = exact_starts(99, 40).remove(0);
    let tuned = tuned_on(&record, 1e-4, 77);
    // no delay to find in exact impacts (measured: δ̄ −2.3e-8 s, σ_t
    // 4.5e-8 s, against 3.6 to 4.5 µs and 1.6 to 2.5 µs on the plant's
    // records at τ = 10 µs: `the_likelihood_finds_the_plants_impact_delay`)
    assert!(
        tuned.impact_delay.abs() <= 1e-7,
        "δ̄ {:e}",
        tuned.impact_delay
    );
    assert!(
        tuned.impact_time_sigma <= 1e-7,
        "σ_t {:e}",
        tuned.impact_time_sigma
    );
    let runs = exact_starts(4242, 40);
    assert!(runs.len() >= 5, "{} runs", runs.len());
    for (n, ((q0, v0), data)) in runs.iter().enumerate() {
        let measured = measure(data, 1e-4, 5000 + n as u64);
        let mut f =
            SaltationKalman::<f64, 2, 2>::new(tuned, 0.0, measured[0], Vector2::zeros()).unwrap();
        let sc = scored(&mut f, &model, data, &measured, &u);
        eprintln!(
            "exact run {n}, from ({:.2}, {:.2}) at ({:.2}, {:.2}), {} impacts: median {:.2e} p90 {:.2e} max {:.2e}, without the bracketing samples {:.2e}",
            q0[0],
            q0[1],
            v0[0],
            v0[1],
            data.impacts.len(),
            sc.all.median,
            sc.all.p90,
            sc.all.max,
            sc.clean.max
        );
        assert!(sc.all.median <= 3e-5, "run {n}: median {:e}", sc.all.median);
        assert!(sc.all.p90 <= 2e-4, "run {n}: p90 {:e}", sc.all.p90);
        assert!(sc.clean.max <= 1e-2, "run {n}: max {:e}", sc.clean.max);
    }
}

/// What the likelihood helper finds in a time-stepped reference. The plant
/// (Moreau–Jean at `τ`) resolves each impact at the end of the step whose
/// prediction sees it, which makes it an exact impact delayed by a
/// fraction of a step, uniform over the step: a mean `τ/2` and a spread
/// `τ/√12 = 0.29 τ` (`the_plants_impacts_come_half_a_step_late`,
/// `the_plants_impacts_are_exact_impacts_delayed`). [`tune_process_noise`],
/// from the defaults, on 10 s of two random Example 1 starts sampled at
/// 1 kHz with `σ = 1e-4` (seed 4242, noise seeds 500 and 501), at `τ` =
/// 10 µs and at `τ` = 1 µs.
///
/// Asserted on each record: the mean delay `δ̄` it picks inside the step,
/// away from its ends (`[0.1, 0.9] τ`), and the spread `σ_t` between a
/// third of `τ/√12` and `τ/2` (the largest spread a delay inside the step
/// can have), so both follow the step down by ten (measured: `δ̄` 0.45
/// and 0.36 τ at 10 µs, 0.85 and 0.43 τ at 1 µs; `σ_t` 0.25 and 0.16 τ,
/// 0.28 and 0.26 τ). On exact, event-driven records the same helper finds
/// neither (`example_1_targets_hold_on_exact_event_driven_data`).
#[test]
fn the_likelihood_finds_the_plants_impact_delay() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    for tau in [1e-5_f64, 1e-6] {
        let every = (1e-3 / tau).round() as usize;
        for (k, start) in random_example_1_starts(4242, 2).into_iter().enumerate() {
            let data = reference(&model, start, tau, every, 10.0, &u);
            let tuned = tuned_on(&data, 1e-4, 500 + k as u64);
            let (delay, spread) = (tuned.impact_delay / tau, tuned.impact_time_sigma / tau);
            eprintln!("plant at τ = {tau:e}, start {k}: δ̄ {delay:.3} τ, σ_t {spread:.3} τ");
            let uniform = 1.0 / 12.0_f64.sqrt();
            assert!(
                (0.1..=0.9).contains(&delay),
                "τ = {tau:e}, start {k}: δ̄ {delay} τ"
            );
            assert!(
                (uniform / 3.0..=0.5).contains(&spread),
                "τ = {tau:e}, start {k}: σ_t {spread} τ"
            );
        }
    }
}

/// The velocity error that each of the plant's impacts makes on its own:
/// from the last sample before each impact of `data` in `[from, to]` s,
/// one sampling period of the plant at its own step `tau` against the same
/// plant at `tau / 100`; `|Δv|` at the end of it, sorted.
fn plant_impact_errors(
    model: &Parabola<f64>,
    data: &Reference<2>,
    tau: f64,
    (from, to): (f64, f64),
) -> Vec<f64> {
    let u = SVector::zeros();
    let bracket = common::runs::brackets(data);
    let period = data.samples[1].t - data.samples[0].t;
    let every = (period / tau).round() as usize;
    let mut errors: Vec<f64> = (0..data.samples.len() - 1)
        .filter(|&j| bracket[j] && bracket[j + 1] && (from..=to).contains(&data.samples[j].t))
        .map(|j| {
            let s = data.samples[j];
            let coarse = reference(model, (s.q, s.v), tau, every, period, &u);
            let fine = reference(model, (s.q, s.v), tau / 100.0, every * 100, period, &u);
            (coarse.samples[1].v - fine.samples[1].v).norm()
        })
        .collect();
    errors.sort_by(f64::total_cmp);
    errors
}

/// The issue's targets on Example 1's four starts (the runs, seeds and
/// window of `example_1_figures_beside_the_reduced_order_observer`, the
/// filter with its defaults) when the plant resolves impacts ten times
/// finer: the plant at `τ = 1e-6`, the same 1 kHz samples and `σ = 1e-4`.
/// All three targets (median ≤ 3e-5, 90th percentile ≤ 2e-4, maximum off
/// the bracketing samples ≤ 1e-2) are asserted on every start, including
/// (0.2, 1), which misses the first two against the plant at `τ = 1e-5`
/// (printed there).
///
/// Why the step matters: the plant at `τ = 1e-5` takes an impact into the
/// step in which it happens, with the normal at its iterate, so each of
/// its impacts leaves a velocity error of its own against a plant a
/// hundred times finer from the same state (printed here for start
/// (0.2, 1) over `[2, 6.5]` s, before it slides: median about 1e-4 m/s),
/// more than the median target; the filter, told `σ_t = 3e-6` s, allows
/// for an error of that size and must wait for the samples after each
/// impact to pin the new velocity down.
/// At `τ = 1e-6` that error is ten times smaller, and so is the time it
/// takes.
#[test]
fn example_1_targets_hold_on_a_plant_ten_times_finer() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let sigma = 1e-4;
    for (n, start) in example_1_starts().into_iter().enumerate() {
        let data = reference(&model, start, 1e-6, 1000, 10.0, &u);
        let measured = measure(&data, sigma, 11 + n as u64);
        let sc = with_defaults(&data, &measured, sigma);
        eprintln!(
            "Example 1, start {n}, plant at τ = 1e-6, σ = 1e-4, defaults: median {:.2e} p90 {:.2e} max {:.2e} (without the bracketing samples: max {:.2e})",
            sc.all.median, sc.all.p90, sc.all.max, sc.clean.max
        );
        assert!(
            sc.all.median <= 3e-5,
            "start {n}: median {:e}",
            sc.all.median
        );
        assert!(sc.all.p90 <= 2e-4, "start {n}: p90 {:e}", sc.all.p90);
        assert!(sc.clean.max <= 1e-2, "start {n}: max {:e}", sc.clean.max);
    }
    let start = example_1_starts()[3];
    for tau in [1e-5, 1e-6] {
        let data = reference(&model, start, tau, (1e-3 / tau).round() as usize, 6.5, &u);
        let errors = plant_impact_errors(&model, &data, tau, (2.0, 6.5));
        let k = errors.len();
        eprintln!(
            "start (0.2, 1), plant at τ = {tau:e} against τ/100 over one period from before each of its {k} impacts in [2, 6.5] s: |Δv| median {:.2e} p90 {:.2e} max {:.2e}",
            errors[k / 2],
            errors[k * 9 / 10],
            errors[k - 1]
        );
    }
}

/// The windows after a plant impact that
/// [`velocity_nees_after_plant_impacts`] sorts samples into, in ms.
const AFTER_IMPACT_MS: [f64; 7] = [0.0, 3.0, 10.0, 30.0, 100.0, 300.0, f64::INFINITY];

/// The filter with its defaults, but `σ_t = sigma_t`, on the twelve
/// random Example 1 starts of seed 555 (plant at `τ = 1e-5`, `σ = 1e-4`,
/// noise seed `100 + n`, as [`example_1_random_starts_beside_the_reduced_order_observer`]):
/// for each window of [`AFTER_IMPACT_MS`] after the last plant impact,
/// the median over the samples in flight (every plant gap above 1e-6 m)
/// past 2 s of the velocity's normalised estimation error squared
/// `ṽᵀ P_vv⁻¹ ṽ`, and the median of `|ṽ|`.
fn velocity_nees_after_plant_impacts(sigma_t: f64) -> Vec<(f64, f64)> {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let sigma = 1e-4;
    let windows = AFTER_IMPACT_MS.len() - 1;
    let (mut nees, mut errors) = (vec![Vec::new(); windows], vec![Vec::new(); windows]);
    for (n, start) in random_example_1_starts(555, 12).into_iter().enumerate() {
        let data = reference(&model, start, 1e-5, 100, 10.0, &u);
        let measured = measure(&data, sigma, 100 + n as u64);
        let params = KalmanParams {
            impact_time_sigma: sigma_t,
            ..KalmanParams::new(20.0, sigma)
        };
        let mut f =
            SaltationKalman::<f64, 2, 2>::new(params, 0.0, measured[0], Vector2::zeros()).unwrap();
        let mut impacts = data.impacts.iter().map(|&(t, _, _)| t).peekable();
        let mut last_impact = f64::NEG_INFINITY;
        for (s, q) in data.samples.iter().zip(&measured).skip(1) {
            let e = f.update(&model, s.t, q, &u).unwrap();
            while let Some(t) = impacts.next_if(|&t| t <= s.t + 1e-12) {
                last_impact = t;
            }
            if s.t < 2.0 || model.gaps(&s.q).iter().any(|&h| h <= 1e-6) {
                continue;
            }
            let v_err = s.v - e.v;
            let p_vv = f
                .covariance()
                .vv
                .cholesky()
                .expect("P_vv positive definite");
            let ms = (s.t - last_impact) * 1e3;
            let w = AFTER_IMPACT_MS
                .windows(2)
                .position(|w| ms >= w[0] && ms < w[1])
                .unwrap();
            nees[w].push(v_err.dot(&p_vv.solve(&v_err)));
            errors[w].push(v_err.norm());
        }
    }
    nees.iter()
        .zip(&errors)
        .map(|(n, e)| (figures(n).median, figures(e).median))
        .collect()
}

/// Against the reference plant (`τ = 1e-5`), whose impacts the filter's
/// rigid model does not describe exactly, the filter's velocity
/// covariance still describes its velocity errors, from the first
/// samples after an impact to long after it: in every window after a
/// plant impact the median of `ṽᵀ P_vv⁻¹ ṽ` over the samples in flight is
/// within a factor of two of the median of χ² with two degrees of
/// freedom, `2 ln 2` (a consistent filter's). So where the filter misses
/// the issue's median of 3e-5 on random starts, it says so itself: its
/// error there is what its covariance allows for, not an overconfidence.
/// The same check catches a filter told that impacts are timed ten times
/// more precisely than the plant times them (`σ_t` = 0.3 µs instead of
/// the default 3 µs): its median NEES leaves the band, and its median
/// error is larger in every window; the tighter filter is wrong, not
/// better.
#[test]
fn velocity_covariance_describes_the_errors_after_plant_impacts() {
    let chi2_median = 2.0 * std::f64::consts::LN_2;
    let band = (chi2_median / 2.0, chi2_median * 2.0);
    let inside = |windows: &[(f64, f64)]| windows.iter().all(|&(n, _)| n >= band.0 && n <= band.1);
    let mut runs = Vec::new();
    for (label, sigma_t) in [("defaults", 3e-6), ("σ_t = 0.3 µs", 3e-7)] {
        let windows = velocity_nees_after_plant_impacts(sigma_t);
        for (w, (nees, error)) in AFTER_IMPACT_MS.windows(2).zip(&windows) {
            eprintln!(
                "{label}, [{}, {}) ms after a plant impact: median NEES of v {nees:.2} (χ²₂ median {chi2_median:.2}), median |ṽ| {error:.2e}",
                w[0], w[1]
            );
        }
        runs.push(windows);
    }
    let (defaults, tight) = (&runs[0], &runs[1]);
    assert!(inside(defaults), "defaults: {defaults:?}");
    assert!(!inside(tight), "σ_t = 0.3 µs: {tight:?}");
    for (d, t) in defaults.iter().zip(tight) {
        assert!(t.1 > d.1, "σ_t = 0.3 µs no worse: {t:?} against {d:?}");
    }
}

// ---------------------------------------------------------------------------
// Numerical care, reproducibility, bad data

/// The covariance as a dense matrix, checked symmetric (exactly: the
/// update symmetrises it) and positive definite (Cholesky).
fn assert_spd<const N: usize>(p: &Blocks<f64, N>, at: f64) {
    let d = dense(p);
    assert_eq!(d, d.transpose(), "P not symmetric at t = {at}");
    assert!(
        d.clone().cholesky().is_some(),
        "P not positive definite at t = {at}: {d}"
    );
}

/// 10⁵ updates (100 s of Example 1 at 1 kHz with σ = 1e-4: the
/// accumulation, then sliding for 95 s): the covariance stays symmetric
/// and positive definite after every update, and bounded.
#[test]
fn covariance_stays_symmetric_positive_definite_over_1e5_updates() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let data = example_1_run(100.0);
    let measured = measure(&data, 1e-4, 5);
    let params = KalmanParams::new(20.0, 1e-4);
    let mut f =
        SaltationKalman::<f64, 2, 2>::new(params, 0.0, measured[0], Vector2::zeros()).unwrap();
    let mut largest: f64 = 0.0;
    for (s, q) in data.samples.iter().zip(&measured).skip(1) {
        f.update(&model, s.t, q, &u).unwrap();
        assert_spd(f.covariance(), s.t);
        largest = largest.max(f.covariance().trace());
    }
    assert_eq!(data.samples.len() - 1, 100_000);
    eprintln!("10^5 updates: largest trace of P {largest:.2e}");
    assert!(largest < 1e3);
}

fn bits(estimates: &[Estimate<f64, 2>]) -> Vec<u64> {
    estimates
        .iter()
        .flat_map(|e| e.q.iter().chain(e.v.iter()).map(|x| x.to_bits()))
        .collect()
}

/// The same measurements give the same bits, estimate and covariance.
#[test]
fn same_measurements_give_the_same_bits() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let data = reference(&model, Parabola::<f64>::initial_state(), 1e-5, 100, 6.0, &u);
    let measured = measure(&data, 1e-4, 3);
    let run = || {
        let mut f = SaltationKalman::<f64, 2, 2>::new(
            KalmanParams::new(20.0, 1e-4),
            0.0,
            measured[0],
            Vector2::zeros(),
        )
        .unwrap();
        let e = run(&mut f, &model, &data, &measured, &u);
        (bits(&e), *f.covariance())
    };
    let (a, pa) = run();
    let (b, pb) = run();
    assert_eq!(a, b);
    assert_eq!(dense(&pa).map(f64::to_bits), dense(&pb).map(f64::to_bits));
}

/// Bad samples, inputs, parameters and settings are refused with an error
/// naming the problem, and the filter's state is kept bit for bit; the
/// next good sample goes on as if the bad one never came.
#[test]
fn bad_input_is_refused_and_the_state_kept() {
    let mut model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let data = reference(&model, Parabola::<f64>::initial_state(), 1e-5, 100, 1.0, &u);
    let measured = measure(&data, 1e-4, 9);
    let mut f = SaltationKalman::<f64, 2, 2>::new(
        KalmanParams::new(20.0, 1e-4),
        0.0,
        measured[0],
        Vector2::zeros(),
    )
    .unwrap();
    for (s, q) in data.samples.iter().zip(&measured).skip(1).take(500) {
        f.update(&model, s.t, q, &u).unwrap();
    }
    let kept = f;
    let t = data.samples[501].t;
    let q = measured[501];
    let same = |f: &SaltationKalman<f64, 2, 2>| assert!(*f == kept, "state changed");
    assert!(matches!(
        f.update(&model, t, &Vector2::new(f64::NAN, 1.0), &u),
        Err(ObserverError::Data(DataError::NonFinite {
            which: "q",
            index: 0
        }))
    ));
    same(&f);
    assert!(matches!(
        f.update(&model, kept.estimate().t, &q, &u),
        Err(ObserverError::InvalidTime { .. })
    ));
    same(&f);
    assert!(matches!(
        f.update(&model, f64::INFINITY, &q, &u),
        Err(ObserverError::InvalidTime { .. })
    ));
    same(&f);
    let g = Parabola::<f64>::parameter_index("g").unwrap();
    *model.parameter_mut(g).unwrap() = f64::NAN;
    assert!(
        matches!(f.update(&model, t, &q, &u), Err(ObserverError::Data(DataError::NonFiniteParameter { index })) if index == g)
    );
    same(&f);
    *model.parameter_mut(g).unwrap() = 9.81;
    // the next good sample: as if nothing had happened
    let mut fresh = kept;
    assert_eq!(
        f.update(&model, t, &q, &u).unwrap(),
        fresh.update(&model, t, &q, &u).unwrap()
    );
    // bad settings and initial data
    let bad = |p: KalmanParams<f64, 2>| {
        SaltationKalman::<f64, 2, 2>::new(p, 0.0, measured[0], Vector2::zeros()).unwrap_err()
    };
    let base = KalmanParams::<f64, 2>::new(20.0, 1e-4);
    assert!(matches!(
        bad(base.with_accel_noise(-1.0)),
        ObserverError::Data(DataError::InvalidParams {
            name: "accel_noise",
            ..
        })
    ));
    assert!(matches!(
        bad(KalmanParams {
            measurement: nalgebra::Matrix2::new(1.0, 0.5, 0.0, 1.0),
            ..base
        }),
        ObserverError::Data(DataError::InvalidParams {
            name: "measurement",
            ..
        })
    ));
    assert!(matches!(
        bad(KalmanParams { gate: 0.0, ..base }),
        ObserverError::Data(DataError::InvalidParams { name: "gate", .. })
    ));
    assert!(matches!(
        bad(KalmanParams {
            initial_velocity_sigma: f64::NAN,
            ..base
        }),
        ObserverError::Data(DataError::InvalidParams {
            name: "initial_velocity_sigma",
            ..
        })
    ));
    for tau in [-1e-5, f64::INFINITY] {
        assert!(matches!(
            bad(base.with_plant_step(tau)),
            ObserverError::Data(DataError::InvalidParams { name: "plant", .. })
        ));
    }
    assert!(matches!(
        bad(KalmanParams::new(-1.0, 1e-4)),
        ObserverError::Data(DataError::InvalidParams {
            name: "velocity_bound",
            ..
        })
    ));
    assert!(matches!(
        SaltationKalman::<f64, 2, 2>::new(base, 0.0, Vector2::new(0.0, f64::NAN), Vector2::zeros()),
        Err(ObserverError::Data(DataError::NonFinite {
            which: "q0",
            index: 1
        }))
    ));
    let asymmetric = Blocks {
        qv: nalgebra::Matrix2::new(1.0, 0.0, 0.0, 0.0),
        ..Blocks::identity()
    };
    assert!(matches!(
        SaltationKalman::<f64, 2, 2>::with_covariance(
            base,
            0.0,
            measured[0],
            Vector2::zeros(),
            asymmetric
        ),
        Err(ObserverError::Data(DataError::InvalidParams {
            name: "p0",
            ..
        }))
    ));
}

/// A glitch (one sample 5 mm off, 50 σ) is reported as an outlier and
/// skipped: the estimate after it is the prediction, which moves the
/// velocity less than a twentieth of what absorbing the sample (the gate
/// off) would; a run of consecutive outliers longer
/// than `max_outliers` is taken as the model being wrong and followed.
#[test]
fn a_glitch_is_reported_and_skipped_not_absorbed() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    // free flight between 1.0 and 1.5 s? the model file's start is in
    // flight from 0.66 s to 1.2 s
    let data = reference(&model, Parabola::<f64>::initial_state(), 1e-5, 100, 1.2, &u);
    let measured = measure(&data, 1e-4, 21);
    let params = KalmanParams::new(20.0, 1e-4);
    let run = |glitches: &[usize]| {
        let mut f =
            SaltationKalman::<f64, 2, 2>::new(params, 0.0, measured[0], Vector2::zeros()).unwrap();
        let mut out = Vec::new();
        for (k, (s, q)) in data.samples.iter().zip(&measured).enumerate().skip(1) {
            let q = if glitches.contains(&k) {
                q + Vector2::new(5e-3, 0.0)
            } else {
                *q
            };
            let e = f.update(&model, s.t, &q, &u).unwrap();
            out.push((e, *f.kalman_report()));
        }
        out
    };
    let clean = run(&[]);
    let glitched = run(&[1000]);
    let (_, report) = glitched[999];
    assert!(report.outlier && !report.inflated, "{report:?}");
    assert!(report.nis > params.gate);
    assert!(
        clean.iter().all(|(_, r)| !r.outlier),
        "no outlier in the clean run"
    );
    // what absorbing the glitch would have done: the same run with the gate off
    let absorbed = {
        let mut f = SaltationKalman::<f64, 2, 2>::new(
            KalmanParams {
                gate: f64::INFINITY,
                ..params
            },
            0.0,
            measured[0],
            Vector2::zeros(),
        )
        .unwrap();
        let mut v = Vector2::zeros();
        for (k, (s, q)) in data
            .samples
            .iter()
            .zip(&measured)
            .enumerate()
            .skip(1)
            .take(1001)
        {
            let q = if k == 1000 {
                q + Vector2::new(5e-3, 0.0)
            } else {
                *q
            };
            v = f.update(&model, s.t, &q, &u).unwrap().v;
        }
        v
    };
    let moved = (glitched[999].0.v - clean[999].0.v).norm();
    let would_move = (absorbed - clean[999].0.v).norm();
    eprintln!(
        "glitch: NIS {:.1}; the estimate moved {moved:.2e} (absorbing it: {would_move:.2e})",
        report.nis
    );
    assert!(moved < 0.05 * would_move);
    // three in a row: the third is used, with the covariance inflated
    let steps = run(&[1000, 1001, 1002]);
    assert!(steps[999].1.outlier && steps[1000].1.outlier);
    assert!(!steps[1001].1.outlier && steps[1001].1.inflated);
}

/// The filter in `f32` on Example 1 (the file's start, 10 s), beside the
/// same filter in `f64` and the reduced-order observer in `f32` on the
/// same samples, at the issue's σ = 1e-4 (three noise seeds) and at σ =
/// 1e-3, with its defaults and told the plant's step.
///
/// Told the plant in `f32`, the filter is on the plant's grid only in
/// the first fraction of a second (a scratch count: fewer than 2 000 of the
/// 40 000 intervals): past it, a sample time of a few seconds rounds in
/// `f32` by several tenths of a microsecond, so an interval is no longer
/// a whole number of 10 µs steps to the thousandth of a step that
/// [`KalmanParams::plant_grid`] asks, and the filter takes the impact
/// off the grid, as with the grid turned off. Measured, told the plant at
/// σ = 1e-4: medians 1.15e-5 to 1.61e-5 in `f32`, 8.2e-6 to 9.8e-6 in
/// `f64` (which keeps the plant's likely steps apart on the grid,
/// `KalmanParams::plant_step_mixture`; 8.3e-6 to 1.07e-5 as one Gaussian).
///
/// Asserted on every run: the covariance stays symmetric and positive
/// semi-definite to the round-off of `f32` (its smallest eigenvalue at
/// least `−64 ε tr P`; a square-root form would be needed for strict
/// definiteness at this conditioning) through the impacts, the
/// accumulation and sliding; the median error over [2, 10] s is below
/// (38)'s in `f32`, at most three times the `f64` filter's, and at σ =
/// 1e-4 at most the issue's 3e-5.
///
/// The last two fail on a floor under the innovation covariance of `ε
/// |q|²` (half the digits of a stored coordinate: `√ε |q|` = 1.7e-3 m at
/// `|q|` = 5 in `f32`, far above σ): medians of 8.5e-5 to 1.0e-4 at σ =
/// 1e-4, seven to ten times the `f64` filter's. The floor is now the
/// rounding of a coordinate and of the covariance the filter has held
/// (`SaltationKalman::update`, "GATE").
#[test]
fn runs_in_f32() {
    let model = Parabola::<f32>::new();
    let model_64 = Parabola::<f64>::new();
    let data = example_1_run(10.0);
    let runs = [(1e-4, 17), (1e-4, 18), (1e-4, 19), (1e-3, 17)];
    for ((sigma, seed), told) in runs
        .into_iter()
        .map(|run| (run, false))
        .chain(runs.into_iter().map(|run| (run, true)))
    {
        let measured = measure(&data, sigma, seed);
        // told the plant, or not, in both precisions
        let knobs = |p: KalmanParams<f32, 2>| if told { p.with_plant_step(1e-5) } else { p };
        let knobs_64 = |p: KalmanParams<f64, 2>| if told { p.with_plant_step(1e-5) } else { p };
        let q32: Vec<SVector<f32, 2>> = measured.iter().map(|q| q.cast::<f32>()).collect();
        let mut f = SaltationKalman::<f32, 2, 2>::new(
            knobs(KalmanParams::new(20.0, sigma as f32)),
            0.0,
            q32[0],
            SVector::zeros(),
        )
        .unwrap();
        let mut f64_filter = SaltationKalman::<f64, 2, 2>::new(
            knobs_64(KalmanParams::new(20.0, sigma)),
            0.0,
            measured[0],
            SVector::zeros(),
        )
        .unwrap();
        let mut o = ReducedOrder::<f32, 2, 2>::new(
            ObserverParams::new(10.0, 20.0).with_noise(sigma as f32),
            0.0,
            q32[0],
            SVector::zeros(),
        )
        .unwrap();
        let (mut ef, mut e64, mut eo) = (Vec::new(), Vec::new(), Vec::new());
        for ((s, q), q64) in data.samples.iter().zip(&q32).zip(&measured).skip(1) {
            let a = f.update(&model, s.t as f32, q, &SVector::zeros()).unwrap();
            let b = o.update(&model, s.t as f32, q, &SVector::zeros()).unwrap();
            let c = f64_filter
                .update(&model_64, s.t, q64, &SVector::zeros())
                .unwrap();
            // symmetric, and positive semi-definite to the round-off of f32
            let p = dense(&Blocks {
                qq: f.covariance().qq.cast(),
                qv: f.covariance().qv.cast(),
                vq: f.covariance().vq.cast(),
                vv: f.covariance().vv.cast(),
            });
            assert_eq!(p, p.transpose());
            let min = p.symmetric_eigenvalues().min();
            assert!(
                min >= -64.0 * f64::from(f32::EPSILON) * p.trace(),
                "σ = {sigma:e}, t = {}: {min:e}",
                s.t
            );
            if s.t >= 2.0 {
                ef.push((a.v.cast::<f64>() - s.v).norm());
                eo.push((b.v.cast::<f64>() - s.v).norm());
                e64.push((c.v - s.v).norm());
            }
        }
        let (ff, f6, fo) = (figures(&ef), figures(&e64), figures(&eo));
        eprintln!(
            "σ = {sigma:e}, noise seed {seed}{}: filter in f32 median {:.2e} p90 {:.2e}, in f64 median {:.2e} p90 {:.2e}; (38) in f32 median {:.2e} p90 {:.2e}",
            if told { ", told the plant" } else { "" },
            ff.median,
            ff.p90,
            f6.median,
            f6.p90,
            fo.median,
            fo.p90
        );
        assert!(ff.median < fo.median, "σ = {sigma:e}, seed {seed}");
        assert!(
            ff.median <= 3.0 * f6.median,
            "σ = {sigma:e}, seed {seed}: {:e} against {:e} in f64",
            ff.median,
            f6.median
        );
        if sigma <= 1e-4 {
            assert!(ff.median <= 3e-5, "seed {seed}: {:e}", ff.median);
        }
    }
}

/// What [`exact_in_f32`] saw on one run.
struct ExactF32 {
    /// The largest `|v − v̂|` over `[0.3 s, end]`, the samples that bracket
    /// a plant impact left out.
    max: f64,
    /// Samples refused (by the gate or the screen), and restarts.
    refused: usize,
    restarts: usize,
    /// The smallest eigenvalue of the covariance scaled to a unit
    /// diagonal, over every update (and whether a diagonal entry was ever
    /// negative).
    min_correlation: f64,
    negative_variance: bool,
}

/// The filter in `f32` (the model `m32`, its defaults, `C_v = c_v`) on the
/// exact samples of the `f64` plant `m64` from `start`, 1 kHz for `t_end`
/// seconds.
fn exact_in_f32<M32, M64, const N: usize, const K: usize>(
    m32: &M32,
    m64: &M64,
    start: (SVector<f64, N>, SVector<f64, N>),
    t_end: f64,
    c_v: f32,
) -> ExactF32
where
    M32: Sensitivities<N, K, Scalar = f32>,
    M64: Model<N, K, Scalar = f64> + std::fmt::Debug + 'static,
    M32::Input: Default,
    M64::Input: Default,
{
    let data = reference(m64, start, 1e-5, 100, t_end, &Default::default());
    let bracket = common::runs::brackets(&data);
    let mut f = SaltationKalman::<f32, N, K>::new(
        KalmanParams::new(c_v, 0.0),
        0.0,
        data.samples[0].q.cast(),
        SVector::zeros(),
    )
    .unwrap();
    let mut seen = ExactF32 {
        max: 0.0,
        refused: 0,
        restarts: 0,
        min_correlation: f64::INFINITY,
        negative_variance: false,
    };
    for (j, s) in data.samples.iter().enumerate().skip(1) {
        match f.update(m32, s.t as f32, &s.q.cast(), &Default::default()) {
            Ok(_) => {
                seen.refused += usize::from(f.kalman_report().outlier);
                seen.restarts += usize::from(f.report().restart.is_some());
            }
            Err(ObserverError::Outlier { .. }) => seen.refused += 1,
            Err(e) => panic!("t = {}: {e:?}", s.t),
        }
        let c = f.covariance();
        let p = DMatrix::from_fn(2 * N, 2 * N, |a, b| f64::from(c.entry(a, b)));
        seen.negative_variance |= p.diagonal().iter().any(|&d| d < 0.0);
        let scale = p.diagonal().map(|d| 1.0 / d.abs().sqrt().max(1e-300));
        let corr = DMatrix::from_fn(2 * N, 2 * N, |a, b| p[(a, b)] * scale[a] * scale[b]);
        seen.min_correlation = seen.min_correlation.min(corr.symmetric_eigenvalues().min());
        if s.t >= 0.3 && !bracket[j] {
            let v: SVector<f64, N> = f.estimate().v.cast();
            seen.max = seen.max.max((v - s.v).norm());
        }
    }
    seen
}

/// Exact samples in `f32`: the covariance stays positive definite, and
/// the filter neither diverges nor wedges.
///
/// On exact samples (`σ = 0`) the first update pins the state down from a
/// prior with `P_vv = C_v²` (400) to a posterior some five orders lower,
/// and the covariance form leaves errors of `ε` times the prior: in
/// `f32` (ε = 1.2e-7) that left the double pendulum's covariance 0.3 %
/// indefinite after the first update, scaled to a unit diagonal. The
/// process noise was far too small to repair it; the negative direction
/// grew with every update (−5 % after 40), variances were negative by 0.46
/// s, and from 0.68 s the estimate diverged: 3.8 rad/s off the bracketing
/// samples, 115 samples refused and a restart on the first start below.
/// In a throw-away sweep of the same draws the arm's second start was
/// refused 240 samples and restarted five times (30 rad/s off). Every
/// congruence `B P Bᵀ` of the filter (Joseph update, flow, saltation,
/// contact projection) now adds the diagonal that covers its own rounding
/// (`Blocks::congruence_covered`).
///
/// Covering the rounding where it happens also made a floor that stood in
/// for it unnecessary: the innovation covariance had under it 64 ε times
/// the initial velocity variance times `τ²` for the whole run, which in
/// `f32` (3e-9 m², a deviation of 5.5e-5 m) treated exact samples as
/// noisy. It let the three balls' glued pair drift 2.4e-5 m apart, and
/// their impact at 2.61 s was then resolved as a sequence of single
/// impacts instead of the plant's simultaneous one: 0.90 m/s off, six
/// samples refused. That floor is gone.
///
/// Runs: the starts of the double pendulum and the three-link arm drawn
/// with the seed 27182 (two each, none picked; the draws of a sweep of
/// the shipped models, billiard starts drawn between them), 6 s, and the
/// three balls from the model file's state, 6 s. Asserted on each: no
/// variance negative, the covariance scaled to a unit diagonal never
/// below −1e-5 in any direction, no restart, at most 0.5 % of the samples
/// refused, and the error off the bracketing samples at most 1e-2 over
/// `[0.3 s, 6 s]`.
#[test]
fn exact_samples_keep_the_covariance_positive_in_f32() {
    let mut g = Gauss::new(27182);
    let mut draw = |n: usize, range: f64, speed: f64| {
        (
            (0..n)
                .map(|_| range * (2.0 * g.uniform() - 1.0))
                .collect::<Vec<_>>(),
            (0..n)
                .map(|_| speed * (2.0 * g.uniform() - 1.0))
                .collect::<Vec<_>>(),
        )
    };
    let mut runs = Vec::new();
    for _ in 0..2 {
        let (q, v) = draw(2, 1.5, 2.0);
        let (q, v) = (Vector2::from_vec(q), Vector2::from_vec(v));
        if DoublePendulum::<f64>::new()
            .gaps(&q)
            .iter()
            .all(|&h| h > 0.02)
        {
            let seen = exact_in_f32::<_, _, 2, 2>(
                &DoublePendulum::<f32>::new(),
                &DoublePendulum::<f64>::new(),
                (q, v),
                6.0,
                20.0,
            );
            runs.push((format!("double pendulum from {:?}", q.as_slice()), seen));
        }
        let _billiard = draw(2, 0.4, 2.0);
        let (q, v) = draw(3, 1.5, 2.0);
        let (q, v) = (Vector3::from_vec(q), Vector3::from_vec(v));
        if Arm3::<f64>::new().gaps(&q)[0] > 0.02 {
            let seen = exact_in_f32::<_, _, 3, 1>(
                &Arm3::<f32>::new(),
                &Arm3::<f64>::new(),
                (q, v),
                6.0,
                200.0,
            );
            runs.push((format!("arm from {:?}", q.as_slice()), seen));
        }
    }
    let seen = exact_in_f32::<_, _, 3, 4>(
        &ThreeBalls::<f32>::new(),
        &ThreeBalls::<f64>::new(),
        ThreeBalls::<f64>::initial_state(),
        6.0,
        20.0,
    );
    runs.push(("three balls from the file's state".into(), seen));
    assert!(runs.len() >= 4, "{} runs", runs.len());
    for (label, seen) in &runs {
        eprintln!(
            "f32, exact samples, {label}: max off the brackets {:.2e}, {} refused, {} restarts, smallest eigenvalue of the scaled covariance {:.2e}",
            seen.max, seen.refused, seen.restarts, seen.min_correlation
        );
        assert!(!seen.negative_variance, "{label}");
        assert!(
            seen.min_correlation >= -1e-5,
            "{label}: {:e}",
            seen.min_correlation
        );
        assert_eq!(seen.restarts, 0, "{label}");
        assert!(seen.refused <= 30, "{label}: {} refused", seen.refused);
        assert!(seen.max <= 1e-2, "{label}: {:e}", seen.max);
    }
}

moreau::model! {
    /// A unit point mass in the corner between the floor `y ≥ 0` and a
    /// ramp `y ≥ −x` rising to the left, pushed toward the ramp by a
    /// force that swells and fades, `f sin²(ω t / 2)` (up to one and a
    /// half times its weight, over a period of 4π s); impacts are
    /// plastic. Past its weight the push lifts the
    /// mass off the floor and up the ramp while gravity alone still
    /// presses it onto the floor: only the ramp's force pulls it away.
    /// As the push fades the mass slides back down, strikes the floor and
    /// slides along it until the push brings it back into the corner.
    /// Written for `a_contact_that_another_contacts_force_pulls_away_lifts_off`.
    pub struct RampCorner;
    coordinates { x: vx, y: vy }
    parameters { g: 9.81, f: 14.715, w: 0.5 }
    kinetic = 0.5 * (vx^2 + vy^2);
    potential = g * y;
    applied { x: -f * sin(0.5 * w * t)^2 }
    constraints { floor: y >= 0, ramp: y + x >= 0 }
    restitution = 0.0;
}

/// A contact that only another contact's force pulls away lifts off when
/// that force says so. [`RampCorner`] rests in the corner of a floor and
/// a ramp until the push past its weight lifts it up the ramp, with
/// gravity alone still pressing it onto the floor. The end of a held
/// piece is projected only onto the contacts it still lies on
/// (`lifted` in `runtime/src/observer/kalman/propagate.rs`); that test
/// also asked the free motion alone to leave the contact, so the floor
/// stayed held until the gate let it go, and the error reached 0.1 m/s
/// off the bracketing samples (start 0, at the code before). A Franka
/// Panda whose hand rests on a table while a joint sits at its limit
/// lifts its hand the same way (a scratch run: 0.1 rad/s off, velocity
/// NEES median 118, before; 0.041 and 1.6 after).
///
/// The issue's numbers, as for the models of
/// `the_issues_numbers_hold_on_models_written_for_the_test`, on eight
/// drawn starts on the floor right of the corner (seed 7: `x` uniform in
/// [0, 0.3] m, `v_x` in [−0.5, 0] m/s), which the push brings into the
/// corner and up the ramp.
///
/// Measured: filter medians 1.8e-6 to 2.8e-6 m/s, 90th percentiles 7.0e-6
/// to 1.2e-5, maxima off the brackets 1.2e-5 to 4.0e-3; exact-sample
/// medians 9.0e-12 to 9.3e-12 with 22 to 33 of the 10 001 exact samples
/// skipped by the gate (1 940 on start 1 before a contradicted level
/// started again from the sample: `Levels::restart` in
/// `runtime/src/observer/kalman/level.rs`); (38) within 0.029.
#[test]
fn a_contact_that_another_contacts_force_pulls_away_lifts_off() {
    let model = RampCorner::<f64>::default();
    let mut g = Gauss::new(7);
    let starts: Vec<_> = (0..8)
        .map(|_| {
            let q = Vector2::new(0.3 * g.uniform(), 0.0);
            let v = Vector2::new(-0.5 * g.uniform(), 0.0);
            (q, v)
        })
        .collect();
    let met = issues_numbers_on(&model, &starts);
    eprintln!("the ramp's corner: the issue's 90th percentile (2e-4) met on {met} of 8 runs");
}
