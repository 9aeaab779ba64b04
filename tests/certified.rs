//! Certified gain constants (issue 13): the proven bounds of
//! [`CertifiedBounds::certify`] against the sampled estimate of
//! [`ModelBounds::estimate`], against closed forms, and against a run of
//! both observers with the proven gain.
//!
//! `cargo test --release --test certified -- --nocapture` prints the
//! tightness table (the README's) and the timings.

use std::time::Instant;

use moreau::{
    Budget, CertifiedBounds, CertifyError, Design, Enclosure, Estimate, FullOrder, FullOrderGains,
    GainRegion, Interval, Model, ModelBounds, MoreauJean, Observer, ObserverParams, ReducedOrder,
    State, StepParams,
};
use moreau_models::{Arm3, Billiard, DoublePendulum, Parabola, ThreeBalls};
use nalgebra::{SVector, Vector2, Vector3};

// ---------------------------------------------------------------------------
// The working regions of the shipped models

/// Example 1: the parabola up to its ceiling `y = 8` (|x| ≤ √8 < 3),
/// speeds up to 15 m/s (it starts at 9.5).
fn parabola_region() -> GainRegion<f64, 2> {
    GainRegion::new(Vector2::new(-3.0, 0.0), Vector2::new(3.0, 8.0), 15.0)
}

/// The three balls between their walls, up to 3 m/s (ball 1 starts at 2).
fn balls_region() -> GainRegion<f64, 3> {
    GainRegion::new(Vector3::repeat(0.0), Vector3::repeat(2.5), 3.0)
}

/// The billiard's square `[−1, 1]²`, up to 6 m/s.
fn billiard_region() -> GainRegion<f64, 2> {
    GainRegion::new(Vector2::repeat(-1.0), Vector2::repeat(1.0), 6.0)
}

/// The double pendulum over `|θ| ≤ 1.5` rad (its walls keep it there),
/// up to 5 rad/s.
fn pendulum_region() -> GainRegion<f64, 2> {
    GainRegion::new(Vector2::repeat(-1.5), Vector2::repeat(1.5), 5.0)
}

/// The arm within 0.5 rad of its initial configuration `(0.9, −0.6, −0.4)`,
/// up to 3 rad/s.
fn arm_region() -> GainRegion<f64, 3> {
    let q0 = Vector3::new(0.9, -0.6, -0.4);
    GainRegion::new(q0 - Vector3::repeat(0.5), q0 + Vector3::repeat(0.5), 3.0)
}

/// The arm's inputs: the boxes `|u_i| ≤ 5` N·m (they do not enter `∂F/∂v`).
fn arm_inputs() -> [Interval; 3] {
    [Interval::new(-5.0, 5.0).unwrap(); 3]
}

/// Certifies with the default budget, times it, and checks every proven
/// bound against the sampled estimate over the same region.
fn both<M, const N: usize, const K: usize>(
    name: &str,
    model: &M,
    region: &GainRegion<f64, N>,
    u: &[Interval],
    u_sample: &M::Input,
) -> (CertifiedBounds<N>, ModelBounds<f64>, f64)
where
    M: Enclosure<N, K> + Model<N, K, Scalar = f64>,
{
    let start = Instant::now();
    let proven = CertifiedBounds::certify(model, region, u, &Budget::default()).unwrap();
    let seconds = start.elapsed().as_secs_f64();
    let sampled = ModelBounds::estimate(model, region, u_sample).unwrap();
    eprintln!("{name} ({:.1} ms):\n{proven}", 1e3 * seconds);
    assert!(
        proven.encloses(&sampled),
        "{name}: proven {:?} does not enclose sampled {sampled:?}",
        proven.bounds()
    );
    // each proven bound also encloses what its own search saw at points
    assert!(proven.mass_min.bound <= proven.mass_min.witness);
    for c in [&proven.mass_max, &proven.coriolis, &proven.force_lipschitz] {
        assert!(c.bound >= c.witness, "{name}: {c:?}");
    }
    (proven, sampled, seconds)
}

/// `certified / sampled` (`sampled / certified` for `λ_min`) as printed in
/// the README's table.
fn row(name: &str, t: [f64; 4], seconds: f64) -> String {
    format!(
        "| {name} | {:.4} | {:.4} | {:.4} | {:.4} | {:.1} ms |",
        t[0],
        t[1],
        t[2],
        t[3],
        1e3 * seconds
    )
}

// ---------------------------------------------------------------------------
// Enclosure of the sampled estimates, tightness, timings

/// On every shipped model each proven bound encloses the sampled estimate
/// (`λ_min` proven ≤ sampled, the others ≥), and is within 20 % of it with
/// the default budget (the three-link arm too, since its `M` is generated
/// in the trigonometric normal form, free of `q1`). Prints the README's
/// table.
#[test]
fn proven_bounds_enclose_the_sampled_estimates_within_20_percent() {
    let zero2 = SVector::<f64, 0>::zeros();
    let mut rows = Vec::new();
    let (p, s, t) = both(
        "Example 1",
        &Parabola::<f64>::new(),
        &parabola_region(),
        &[],
        &zero2,
    );
    rows.push(row("Parabola (Example 1)", p.tightness(&s), t));
    let (p, s, t) = both(
        "three balls",
        &ThreeBalls::<f64>::new(),
        &balls_region(),
        &[],
        &zero2,
    );
    rows.push(row("ThreeBalls", p.tightness(&s), t));
    let (p, s, t) = both(
        "billiard",
        &Billiard::<f64>::new(),
        &billiard_region(),
        &[],
        &zero2,
    );
    rows.push(row("Billiard", p.tightness(&s), t));
    let (p, s, t) = both(
        "double pendulum",
        &DoublePendulum::<f64>::new(),
        &pendulum_region(),
        &[],
        &zero2,
    );
    rows.push(row("DoublePendulum", p.tightness(&s), t));
    let (p, s, t) = both(
        "arm",
        &Arm3::<f64>::new(),
        &arm_region(),
        &arm_inputs(),
        &Vector3::zeros(),
    );
    rows.push(row("Arm3", p.tightness(&s), t));
    eprintln!("| model | λ_min s/c | λ_max c/s | C_M c/s | C_F c/s | time |");
    eprintln!("|---|---|---|---|---|---|");
    for r in &rows {
        eprintln!("{r}");
    }
    for r in &rows {
        let ratios: Vec<f64> = r
            .split('|')
            .skip(2)
            .take(4)
            .map(|x| x.trim().parse().unwrap())
            .collect();
        assert!(ratios.iter().all(|&x| (1.0..=1.2).contains(&x)), "{r}");
    }
}

// ---------------------------------------------------------------------------
// Closed forms

/// Example 1: `M = m I`, `C = 0`, `F = G` constant so `∂F/∂v = 0`:
/// `λ_min = λ_max = m`, `C_M = C_F = 0`, proven exactly (up to the
/// verification shift of the eigenvalue bound, `≤ 1e-12` relative).
#[test]
fn example_1_closed_form() {
    for m in [1.0, 0.3] {
        let mut model = Parabola::<f64>::new();
        model.m = m;
        let p =
            CertifiedBounds::certify(&model, &parabola_region(), &[], &Budget::default()).unwrap();
        assert!(p.mass_min.bound <= m && p.mass_min.bound >= m * (1.0 - 1e-12));
        assert!(p.mass_max.bound >= m && p.mass_max.bound <= m * (1.0 + 1e-12));
        assert_eq!((p.coriolis.bound, p.force_lipschitz.bound), (0.0, 0.0));
        // so the proven gain of Corollary 3 for β is β/m, to rounding
        let l_d = p.gain_for_margin(Design::ReducedOrder, 2.0);
        assert!(l_d >= 2.0 / m && l_d <= 2.0 / m * (1.0 + 1e-12));
    }
}

/// The three balls: `M = diag(m1, m2, m3)`, `C = 0`, no forces.
#[test]
fn three_balls_closed_form() {
    let mut model = ThreeBalls::<f64>::new();
    (model.m1, model.m2, model.m3) = (2.0, 0.5, 1.25);
    let p = CertifiedBounds::certify(&model, &balls_region(), &[], &Budget::default()).unwrap();
    assert!(p.mass_min.bound <= 0.5 && p.mass_min.bound >= 0.5 * (1.0 - 1e-12));
    assert!(p.mass_max.bound >= 2.0 && p.mass_max.bound <= 2.0 * (1.0 + 1e-12));
    assert_eq!((p.coriolis.bound, p.force_lipschitz.bound), (0.0, 0.0));
}

/// The double pendulum, with `a = (m1 + m2) l1²`, `b = m2 l2²`,
/// `c = m2 l1 l2`, `s = c sin(θ1 − θ2)`, `δ = θ1 − θ2`:
///
/// - `M = [[a, c cos δ], [c cos δ, b]]`, eigenvalues
///   `(a + b)/2 ± √(((a − b)/2)² + c² cos² δ)`: over `|θ_i| ≤ 1.5`,
///   `δ ∈ [−3, 3]` reaches `δ = 0`, so `λ_min = (a+b)/2 − √(((a−b)/2)² + c²)`
///   and `λ_max = (a+b)/2 + √(…)`;
/// - `C(q, v) = s [[0, w2], [−w1, 0]]` (Christoffel form: `M₁₂` depends on
///   `δ` only), `‖C(q, d)‖₂ = |s| max(|d1|, |d2|)`, largest at `d = e_k`:
///   `C_M = c max |sin δ| = c` (`δ` reaches `π/2`);
/// - `F = C(q, v) v + G − Q`, `Q = (−2 b_d w1 + b_d w2, b_d w1 − b_d w2)`
///   (joint damping `b_d`): `∂F/∂v = [[2b_d, 2 s w2 − b_d], [−2 s w1 − b_d, b_d]]`,
///   whose sup over the box and the ball `|w| ≤ C_v` has no short closed
///   form: computed on a fine grid (a lower bound of the supremum).
#[test]
fn double_pendulum_closed_form() {
    let model = DoublePendulum::<f64>::new();
    let (m1, m2, l1, l2, bd) = (model.m1, model.m2, model.l1, model.l2, model.b);
    let (a, b, c) = ((m1 + m2) * l1 * l1, m2 * l2 * l2, m2 * l1 * l2);
    let root = (((a - b) / 2.0).powi(2) + c * c).sqrt();
    let (lmin, lmax) = ((a + b) / 2.0 - root, (a + b) / 2.0 + root);
    let region = pendulum_region();
    let tol = Budget::default().tolerance;
    let p = CertifiedBounds::certify(&model, &region, &[], &Budget::default()).unwrap();
    eprintln!("{p}");
    eprintln!("closed form: λ_min {lmin}, λ_max {lmax}, C_M {c}");
    assert!(p.mass_min.bound <= lmin && p.mass_min.bound >= lmin * (1.0 - 2.0 * tol));
    assert!(p.mass_max.bound >= lmax && p.mass_max.bound <= lmax * (1.0 + 2.0 * tol));
    assert!(p.coriolis.bound >= c && p.coriolis.bound <= c * (1.0 + 2.0 * tol));
    // the closed form of C itself, at a few points, against the model
    for (th1, th2, w1, w2) in [(0.3, -0.4, 1.0, 2.0), (-1.0, 0.5, -0.7, 0.2)] {
        let s = c * f64::sin(th1 - th2);
        let cq = model.coriolis(&Vector2::new(th1, th2), &Vector2::new(w1, w2));
        let closed = nalgebra::Matrix2::new(0.0, s * w2, -s * w1, 0.0);
        assert!((cq - closed).norm() < 1e-12, "{cq} vs {closed}");
    }
    // C_F on a grid: δ over [−3, 3], w on the circle |w| = C_v and inside
    let c_v = region.velocity_bound;
    let mut grid: f64 = 0.0;
    for i in 0..=600 {
        let s = c * f64::sin(-3.0 + 6.0 * i as f64 / 600.0);
        for j in 0..360 {
            let phi = j as f64 * std::f64::consts::TAU / 360.0;
            for r in [c_v, 0.5 * c_v] {
                let (w1, w2) = (r * phi.cos(), r * phi.sin());
                let d = nalgebra::Matrix2::new(2.0 * bd, 2.0 * s * w2 - bd, -2.0 * s * w1 - bd, bd);
                grid = grid.max(d.singular_values().max());
            }
        }
    }
    eprintln!("C_F on the grid {grid}");
    assert!(p.force_lipschitz.bound >= grid);
    assert!(p.force_lipschitz.bound <= grid * (1.0 + 2.0 * tol));
}

// ---------------------------------------------------------------------------
// The gain API and its errors

/// The gain methods round in the safe direction and agree with the
/// corollaries: the gain for `β` leaves at least `β`, the gain for a rate
/// decays at least at it, and they sit at or above the sampled ones.
#[test]
fn proven_gains_are_safe_and_consistent() {
    let model = DoublePendulum::<f64>::new();
    let region = pendulum_region();
    let p = CertifiedBounds::certify(&model, &region, &[], &Budget::default()).unwrap();
    let s = ModelBounds::estimate(&model, &region, &SVector::<f64, 0>::zeros()).unwrap();
    for design in [Design::FullOrder, Design::ReducedOrder] {
        let l_d = p.gain_for_margin(design, 1.0);
        assert!(p.margin(design, l_d) >= 1.0 - 1e-12);
        assert!(l_d >= s.gain_for_margin(design, 1.0));
    }
    let l_d = p.gain_for_decay_rate(3.0);
    assert!(p.decay_rate(l_d) >= 3.0 - 1e-12);
    assert!(p.decay_rate(l_d) <= s.decay_rate(l_d));
    assert_eq!(p.bounds().mass_min, p.mass_min.bound);
}

/// A polar particle: `M = diag(m, m r²)` is singular at `r = 0`. A box
/// reaching `r = 0` is refused, naming the worst box; a box away from it
/// is proven, with `λ_min = m r_min²`.
mod polar {
    moreau::model! {
        /// A particle in polar coordinates.
        pub struct Polar;
        coordinates { r: dr, th: dth }
        parameters { m: 2.0 }
        kinetic = 0.5 * m * (dr^2 + r^2 * dth^2);
        potential = 0;
    }
}

#[test]
fn a_box_where_m_is_singular_is_refused() {
    let model = polar::Polar::<f64>::new();
    let region = GainRegion::new(Vector2::new(-0.5, -1.0), Vector2::new(1.0, 1.0), 1.0);
    let e = CertifiedBounds::certify(&model, &region, &[], &Budget::default()).unwrap_err();
    eprintln!("{e}");
    match e {
        CertifyError::MassNotPositiveDefinite { lower, worst } => {
            assert!(lower <= 0.0);
            assert!(worst[0].contains(0.0), "{worst:?}");
        }
        e => panic!("{e:?}"),
    }
    let region = GainRegion::new(Vector2::new(0.5, -1.0), Vector2::new(1.0, 1.0), 1.0);
    let p = CertifiedBounds::certify(&model, &region, &[], &Budget::default()).unwrap();
    assert!(p.mass_min.bound <= 0.5 && p.mass_min.bound >= 0.5 * (1.0 - 1e-12));
    // a bad budget
    let bad = Budget {
        boxes: 0,
        ..Budget::default()
    };
    assert!(matches!(
        CertifiedBounds::certify(&model, &region, &[], &bad),
        Err(CertifyError::Region(_))
    ));
}

// ---------------------------------------------------------------------------
// The proven rate, measured

/// The plant from `start`, sampled every `every` steps of `tau` up to
/// `t_end` (no impacts asserted by the caller).
fn reference<M: Model<2, 2, Scalar = f64, Input = SVector<f64, 0>>>(
    model: &M,
    start: (Vector2<f64>, Vector2<f64>),
    tau: f64,
    every: usize,
    t_end: f64,
) -> Vec<State<f64, 2>> {
    let stepper = MoreauJean::new(StepParams::new(tau)).unwrap();
    let mut state = State::new(0.0, start.0, start.1);
    let mut samples = vec![state];
    let zero = SVector::<f64, 0>::zeros();
    for k in 1..=(t_end / tau).round() as usize {
        stepper.step(model, &mut state, &zero).unwrap();
        if k % every == 0 {
            samples.push(state);
        }
    }
    samples
}

/// The smallest decay rate over one sampling interval of
/// `√(ρ|q̃|² + ṽᵀM ṽ)`, while it stays above `1e-4` of its start (below
/// that the plant's own discretization error shows; as in
/// `tests/observer.rs`).
fn worst_rate<M: Model<2, 2, Scalar = f64>>(
    model: &M,
    samples: &[State<f64, 2>],
    estimates: &[Estimate<f64, 2>],
    rho: f64,
) -> f64 {
    let norms: Vec<(f64, f64)> = samples
        .iter()
        .zip(estimates)
        .map(|(s, e)| {
            let (dq, dv) = (s.q - e.q, s.v - e.v);
            let w = rho * dq.norm_squared() + (dv.transpose() * model.mass(&s.q) * dv)[0];
            (s.t, w.sqrt())
        })
        .collect();
    let floor = 1e-4 * norms[0].1;
    norms
        .iter()
        .take_while(|&&(_, w)| w >= floor)
        .collect::<Vec<_>>()
        .windows(2)
        .map(|w| -(w[1].1 / w[0].1).ln() / (w[1].0 - w[0].0))
        .fold(f64::INFINITY, f64::min)
}

/// Feeds the samples' positions (from the second on) to `obs`: its
/// estimates, the initial one first.
fn run<O: Observer<DoublePendulum<f64>, 2, 2>>(
    obs: &mut O,
    model: &DoublePendulum<f64>,
    samples: &[State<f64, 2>],
) -> Vec<Estimate<f64, 2>> {
    let zero = SVector::<f64, 0>::zeros();
    let mut out = vec![obs.estimate()];
    for s in &samples[1..] {
        out.push(obs.update(model, s.t, &s.q, &zero).unwrap());
    }
    out
}

/// The double pendulum released at rest from `(−1.2, −1.2)` swings clear of
/// its wall and floor for 0.45 s (the stretch of `tests/observer.rs`).
/// Over the bounding box of that stretch (widened by 0.05) with
/// `C_v = 1.1 max|v|`, the proven gain of Corollary 3 for `β = 1` is run in
/// both observers from `v̂(0) = v(0) + (1, −1)`: the reduced-order error
/// `|ṽ|_M` decays at least at the proven rate `r` in every sampling
/// interval, the full-order Lyapunov root (`Λ = 5 I`, `L_ρ1 = 25 I`) at
/// least at `min(5, r)`.
#[test]
fn measured_decay_is_at_least_the_proven_rate() {
    let model = DoublePendulum::<f64>::new();
    let samples = reference(
        &model,
        (Vector2::new(-1.2, -1.2), Vector2::zeros()),
        1e-5,
        100,
        0.45,
    );
    assert!(samples.iter().all(|s| model.gaps(&s.q).min() > 1e-3));
    let (mut lo, mut hi, mut speed) = (samples[0].q, samples[0].q, 0.0_f64);
    for s in &samples {
        lo = lo.inf(&s.q);
        hi = hi.sup(&s.q);
        speed = speed.max(s.v.norm());
    }
    let margin = Vector2::repeat(0.05);
    let region = GainRegion::new(lo - margin, hi + margin, 1.1 * speed);
    let p = CertifiedBounds::certify(&model, &region, &[], &Budget::default()).unwrap();
    let l_d = p.gain_for_margin(Design::ReducedOrder, 1.0).ceil();
    let rate = p.decay_rate(l_d);
    assert!(p.margin(Design::ReducedOrder, l_d) >= 1.0);
    eprintln!("{p}\nproven gain l_d = {l_d}, proven rate r = {rate:.4}/s");
    let params = ObserverParams::new(l_d, p.velocity_bound);
    let v0 = samples[0].v + Vector2::new(1.0, -1.0);
    let start = &samples[0];
    let mut reduced = ReducedOrder::<f64, 2, 2>::new(params, start.t, start.q, v0).unwrap();
    let worst = worst_rate(&model, &samples, &run(&mut reduced, &model, &samples), 0.0);
    eprintln!("reduced order: worst interval {worst:.4}/s (proven {rate:.4}/s)");
    assert!(worst >= rate, "{worst} < {rate}");
    let gains = FullOrderGains::scalar(5.0, 25.0);
    let mut full = FullOrder::<f64, 2, 2>::new(params, gains, start.t, start.q, v0).unwrap();
    let worst = worst_rate(&model, &samples, &run(&mut full, &model, &samples), 25.0);
    let proven = rate.min(5.0);
    eprintln!("full order: worst interval {worst:.4}/s (proven min(λ, r) = {proven:.4}/s)");
    assert!(worst >= proven, "{worst} < {proven}");
}
