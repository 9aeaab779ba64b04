//! The observers (36) and (38) end to end: reference trajectories from the
//! plant `MoreauJean` at a step at least ten times finer than the
//! observers' sampling period (a hundred times for Example 1), sampled,
//! with noise where stated; the true velocity is the plant's at the sample
//! times. No observer ever sees it.
//!
//! Run with `cargo test --release --test observer -- --nocapture` to see
//! every measured figure.

use moreau::{
    DataError, Design, Discretization, Estimate, FullOrder, FullOrderGains, GainRegion,
    KalmanParams, Model, ModelBounds, MoreauJean, Observer, ObserverError, ObserverParams,
    ReducedOrder, Restart, SaltationKalman, State, StepParams,
};
mod common;

use common::runs::{Figures, Reference, errors, example_1_run, figures, measure, reference, score};
use moreau_models::{Arm3, Billiard, DoublePendulum, Parabola, ThreeBalls};
use nalgebra::{SMatrix, SVector, Vector2, Vector3};

// ---------------------------------------------------------------------------
// Reference data

/// Feeds the measurements (from the second on) to `observer` and returns
/// the estimates, the initial one first.
fn observe<O, M, const N: usize, const K: usize>(
    observer: &mut O,
    model: &M,
    reference: &Reference<N>,
    measured: &[SVector<f64, N>],
    u: &M::Input,
) -> Vec<Estimate<f64, N>>
where
    O: Observer<M, N, K>,
    M: Model<N, K, Scalar = f64>,
{
    let mut estimates = vec![observer.estimate()];
    for (s, q) in reference.samples.iter().zip(measured).skip(1) {
        estimates.push(observer.update(model, s.t, q, u).unwrap());
    }
    estimates
}

/// The errors at sample times in `[from, to)`.
fn window<const N: usize>(
    reference: &Reference<N>,
    errors: &[f64],
    from: f64,
    to: f64,
) -> Vec<f64> {
    reference
        .samples
        .iter()
        .zip(errors)
        .filter(|(s, _)| s.t >= from - 1e-9 && s.t < to - 1e-9)
        .map(|(_, &e)| e)
        .collect()
}

fn reduced<const N: usize, const K: usize>(
    params: ObserverParams<f64>,
    start: &State<f64, N>,
    v0: SVector<f64, N>,
) -> ReducedOrder<f64, N, K> {
    ReducedOrder::new(params, start.t, start.q, v0).unwrap()
}

fn full<const N: usize, const K: usize>(
    params: ObserverParams<f64>,
    start: &State<f64, N>,
    v0: SVector<f64, N>,
) -> FullOrder<f64, N, K> {
    FullOrder::new(
        params,
        FullOrderGains::scalar(5.0, 25.0),
        start.t,
        start.q,
        v0,
    )
    .unwrap()
}

// ---------------------------------------------------------------------------
// Example 1

/// Example 1 as the issue sets it: l_d = 10, v̂(0) = 0, 1 kHz samples of a
/// plant at τ = 1e-5 over [0, 10] s. Figures over t ∈ [2, 10] s for both
/// discretizations, and the samples each plant impact needs before the
/// error is back below 1e-2.
///
/// Thresholds: the targets for `ImpactAware` (median ≤ 3e-5, 90th
/// percentile ≤ 2e-3); `SectionVii` must be worse on all three figures.
#[test]
fn example_1_figures() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let data = example_1_run(10.0);
    let measured = measure(&data, 0.0, 0);
    let mut results = Vec::new();
    // the third run is a diagnostic, not asserted: the impact-aware scheme
    // with its search inside the interval turned off (max_impacts = 0), so
    // impacts are met only where a sampled gap is closed
    let no_search = ObserverParams {
        max_impacts: 0,
        ..ObserverParams::new(10.0, 20.0)
    };
    for (scheme, params) in [
        ("ImpactAware", ObserverParams::new(10.0, 20.0)),
        (
            "SectionVii",
            ObserverParams::new(10.0, 20.0).with_scheme(Discretization::SectionVii),
        ),
        ("ImpactAware without search (diagnostic)", no_search),
    ] {
        let mut observer = reduced::<2, 2>(params, &data.samples[0], Vector2::zeros());
        let estimates = observe(&mut observer, &model, &data, &measured, &u);
        let errors = errors(&data, &estimates);
        let f = figures(&window(&data, &errors, 2.0, 10.0 + 1e-3));
        eprintln!(
            "Example 1, {scheme}: |v - v̂| over [2, 10] s: median {:.2e}, 90th percentile {:.2e}, max {:.2e}",
            f.median, f.p90, f.max
        );
        let mut recoveries = Vec::new();
        for &(t, constraint, speed) in &data.impacts {
            let first = data.samples.iter().position(|s| s.t >= t - 1e-12).unwrap();
            let back = (first..errors.len())
                .find(|&j| errors[j] < 1e-2)
                .map(|j| j - first);
            recoveries.push((t, constraint, speed, back));
        }
        let line = recoveries
            .iter()
            .map(|(t, c, speed, back)| match back {
                Some(n) => format!("{t:.4}s h{}({speed:.2}m/s):{n}", c + 1),
                None => format!("{t:.4}s h{}({speed:.2}m/s):never", c + 1),
            })
            .collect::<Vec<_>>()
            .join(" ");
        eprintln!("  samples after each plant impact until |v - v̂| < 1e-2: {line}");
        results.push((f, recoveries));
    }
    let (aware, plain) = (&results[0].0, &results[1].0);
    assert!(aware.median <= 3e-5, "median {:e}", aware.median);
    assert!(aware.p90 <= 2e-3, "90th percentile {:e}", aware.p90);
    assert!(plain.median > aware.median && plain.p90 > aware.p90 && plain.max > aware.max);
    // after the initial transient (the first two impacts, at 0.35 s and
    // 0.66 s, come while the error of v̂(0) = 0 is still decaying), no
    // plant impact leaves the impact-aware error above 1e-2 for more than
    // a few samples
    let worst = results[0].1[2..]
        .iter()
        .map(|r| r.3.unwrap_or(usize::MAX))
        .max()
        .unwrap();
    eprintln!("  ImpactAware: at most {worst} samples to recover after the transient");
    assert!(worst <= 5, "{worst}");
}

/// Measurements at their own rate: irregular intervals (uniform in
/// [0.5, 1.5] ms, a deterministic sequence) and 100 Hz, from the same
/// plant at τ = 1e-5 (50 to 1000 times finer). The update takes each
/// sample's own time; Example 1's targets (median ≤ 3e-5, 90th percentile
/// ≤ 2e-3 over [2, 10] s) still hold for both observers.
#[test]
fn irregular_and_slow_sampling() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let all = reference(&model, Parabola::<f64>::initial_state(), 1e-5, 1, 10.0, &u);
    for (label, irregular, every) in [("irregular 0.5-1.5 ms", true, 0), ("100 Hz", false, 1000)] {
        let mut indices = vec![0usize];
        let mut x = 0.37_f64;
        loop {
            let step = if irregular {
                x = (x * 7.31 + 0.13).fract();
                50 + (x * 100.0) as usize
            } else {
                every
            };
            let next = indices[indices.len() - 1] + step;
            if next >= all.samples.len() {
                break;
            }
            indices.push(next);
        }
        let data = Reference {
            samples: indices.iter().map(|&j| all.samples[j]).collect(),
            impacts: vec![],
        };
        let measured = measure(&data, 0.0, 0);
        let params = ObserverParams::new(10.0, 20.0);
        let start = &data.samples[0];
        for kind in ["reduced", "full"] {
            let estimates = if kind == "reduced" {
                observe(
                    &mut reduced::<2, 2>(params, start, Vector2::zeros()),
                    &model,
                    &data,
                    &measured,
                    &u,
                )
            } else {
                observe(
                    &mut full::<2, 2>(params, start, Vector2::zeros()),
                    &model,
                    &data,
                    &measured,
                    &u,
                )
            };
            let f = figures(&window(&data, &errors(&data, &estimates), 2.0, 10.0 + 1e-3));
            eprintln!(
                "Example 1, {label}, {kind}: {} samples; |v - v̂| over [2, 10] s: median {:.2e}, p90 {:.2e}, max {:.2e}",
                data.samples.len(),
                f.median,
                f.p90,
                f.max
            );
            assert!(f.median <= 3e-5 && f.p90 <= 2e-3, "{f:?}");
        }
    }
}

// ---------------------------------------------------------------------------
// Convergence on every shipped model

/// One convergence case: both observers from `v̂(0)`, on a plant run from
/// `start`; returns (|ṽ(0)|, figures over the last second) per observer.
fn converges<M, const N: usize, const K: usize>(
    name: &str,
    model: &M,
    start: (SVector<f64, N>, SVector<f64, N>),
    v_hat0: SVector<f64, N>,
    u: &M::Input,
) -> [(f64, Figures); 2]
where
    M: Model<N, K, Scalar = f64> + std::fmt::Debug + 'static,
{
    let t_end = 6.0;
    let data = reference(model, start, 1e-5, 100, t_end, u);
    let measured = measure(&data, 0.0, 0);
    let params = ObserverParams::new(10.0, 50.0);
    let e0 = (data.samples[0].v - v_hat0).norm();
    let mut out = [(e0, figures(&[0.0])); 2];
    for (k, kind) in ["reduced", "full"].iter().enumerate() {
        let estimates = if k == 0 {
            let mut o = reduced::<N, K>(params, &data.samples[0], v_hat0);
            observe(&mut o, model, &data, &measured, u)
        } else {
            let mut o = full::<N, K>(params, &data.samples[0], v_hat0);
            observe(&mut o, model, &data, &measured, u)
        };
        let errors = errors(&data, &estimates);
        let last = figures(&window(&data, &errors, t_end - 1.0, t_end + 1e-3));
        let speed = data.samples.iter().map(|s| s.v.norm()).fold(0.0, f64::max);
        eprintln!(
            "{name} {kind:7}: |ṽ(0)| {e0:.2}, {} plant impacts, max |v| {speed:.1}; last second: median {:.1e} ({:.1e} of |ṽ(0)|), p90 {:.1e} ({:.1e}), max {:.1e} ({:.1e})",
            data.impacts.len(),
            last.median,
            last.median / e0,
            last.p90,
            last.p90 / e0,
            last.max,
            last.max / e0
        );
        out[k] = (e0, last);
    }
    out
}

/// "Decays", on every shipped model, for three initial states and initial
/// estimates each, both observers, 6 s of a plant at τ = 1e-5 sampled at
/// 1 kHz: over the last second, the median of `|v − v̂|` is at most 1e-3
/// and its maximum at most 1e-2 of the initial error `|ṽ(0)|`.
///
/// Where the numbers come from: where gain selection guarantees a rate
/// (Example 1, the billiard and the three balls: `r = l_d = 10`), five
/// seconds leave `e^{−50}`; what remains is the plant's own discretization
/// error, which the observer cannot tell from motion (refining the plant
/// tenfold lowers these floors tenfold: measured). The worst runs are the
/// arm at 40 rad/s (median 1.3e-4, max 3.8e-3 of `|ṽ(0)|`, measured) and
/// the full-order observer there; the thresholds leave a margin of 2.6 on
/// the maximum and 7 on the median.
#[test]
fn every_shipped_model_converges() {
    let mut all = Vec::new();
    let zero = SVector::<f64, 0>::zeros();
    let parabola = Parabola::<f64>::new();
    for (start, v_hat0) in [
        (Parabola::<f64>::initial_state(), Vector2::zeros()),
        (
            (Vector2::new(-1.0, 3.0), Vector2::new(2.0, 5.0)),
            Vector2::new(-3.0, 0.0),
        ),
        (
            (Vector2::new(0.5, 6.0), Vector2::new(-4.0, 0.0)),
            Vector2::new(0.0, 2.0),
        ),
    ] {
        all.extend(converges::<_, 2, 2>(
            "Parabola", &parabola, start, v_hat0, &zero,
        ));
    }
    let balls = ThreeBalls::<f64>::new();
    for (start, v_hat0) in [
        (ThreeBalls::<f64>::initial_state(), Vector3::zeros()),
        (
            (Vector3::new(0.4, 1.0, 2.0), Vector3::new(1.0, -1.5, 0.5)),
            Vector3::new(0.0, 1.0, 0.0),
        ),
        (
            (Vector3::new(0.2, 1.2, 1.45), Vector3::new(3.0, 0.0, -1.0)),
            Vector3::new(1.0, 1.0, 1.0),
        ),
    ] {
        all.extend(converges::<_, 3, 4>(
            "ThreeBalls",
            &balls,
            start,
            v_hat0,
            &zero,
        ));
    }
    let billiard = Billiard::<f64>::new();
    for (start, v_hat0) in [
        (Billiard::<f64>::initial_state(), Vector2::zeros()),
        (
            (Vector2::new(0.1, -0.2), Vector2::new(-1.0, 1.2)),
            Vector2::new(1.0, 0.0),
        ),
        (
            (Vector2::new(-0.1, 0.15), Vector2::new(0.8, 2.0)),
            Vector2::new(-0.5, -0.5),
        ),
    ] {
        all.extend(converges::<_, 2, 4>(
            "Billiard", &billiard, start, v_hat0, &zero,
        ));
    }
    let pendulum = DoublePendulum::<f64>::new();
    for (start, v_hat0) in [
        (
            DoublePendulum::<f64>::initial_state(),
            Vector2::new(1.0, 1.0),
        ),
        (
            (Vector2::new(1.2, 0.2), Vector2::new(0.5, -1.0)),
            Vector2::zeros(),
        ),
        (
            (Vector2::new(-1.5, 0.3), Vector2::new(1.0, 2.0)),
            Vector2::new(-1.0, 0.0),
        ),
    ] {
        all.extend(converges::<_, 2, 2>(
            "DoublePendulum",
            &pendulum,
            start,
            v_hat0,
            &zero,
        ));
    }
    let arm = Arm3::<f64>::new();
    for (start, v_hat0, u) in [
        (
            Arm3::<f64>::initial_state(),
            Vector3::repeat(1.0),
            Vector3::zeros(),
        ),
        (
            (Vector3::new(0.5, 0.3, -0.2), Vector3::new(1.0, -1.0, 0.5)),
            Vector3::zeros(),
            Vector3::new(8.0, 2.0, 0.5),
        ),
        (
            (Vector3::new(1.2, -0.8, 0.4), Vector3::zeros()),
            Vector3::new(0.0, 2.0, -2.0),
            Vector3::new(-4.0, 1.0, 0.0),
        ),
    ] {
        all.extend(converges::<_, 3, 1>("Arm3", &arm, start, v_hat0, &u));
    }
    let worst_median = all.iter().map(|(e0, f)| f.median / e0).fold(0.0, f64::max);
    let worst_p90 = all.iter().map(|(e0, f)| f.p90 / e0).fold(0.0, f64::max);
    let worst_max = all.iter().map(|(e0, f)| f.max / e0).fold(0.0, f64::max);
    eprintln!(
        "worst over {} runs, last second relative to |ṽ(0)|: median {worst_median:.1e}, p90 {worst_p90:.1e}, max {worst_max:.1e}",
        all.len()
    );
    assert!(worst_median <= 1e-3 && worst_max <= 1e-2);
}

/// A ball sliding along one of the billiard's walls into another, on exact
/// samples. The prediction holds the first wall as a persistent contact,
/// and a held contact keeps the small normal speed the contact rule took
/// for rest: it drifts off by it (8e-9 m in 0.8 ms). With no noise the
/// contact band is zero, and at the impact on the second wall the first
/// was read as open; the impact was then resolved as a sequence of bounces
/// (three impacts) instead of Newton's law on both walls at once, as the
/// plant resolves it, and (38) was 0.38 to 0.45 m/s off for 300 samples. A
/// contact held along the piece that leads to an event now stays closed
/// there.
///
/// Fig. 1c's run (the model file's start, `v̂(0) = 0`, `l_d = 10`, `C_v =
/// 5`, as `examples/billiard.rs` runs it; before: (38)'s maximum over
/// [1.5, 3] s 0.42) and ten starts drawn with the seed 4242 (`x, y`
/// uniform in [−0.4, 0.4], `v` in [−2, 2]², none picked; before: 0.11 to
/// 0.45 on three of them, 3.4e-2 on a fourth), 6 s of plant at `τ =
/// 1e-5` sampled at 1 kHz: (38)'s and (36)'s maxima over [1, 6] s off the
/// samples that bracket a plant impact at most 2e-2 (measured: at most
/// 9.3e-3).
#[test]
fn a_contact_held_into_a_corner_stays_closed_at_the_impact() {
    let u = SVector::<f64, 0>::zeros();
    let billiard = Billiard::<f64>::new();
    let params = ObserverParams::new(10.0, 5.0);
    let fig_1c = reference(
        &billiard,
        Billiard::<f64>::initial_state(),
        1e-5,
        100,
        3.0,
        &u,
    );
    let exact = measure(&fig_1c, 0.0, 0);
    let mut o = reduced::<2, 4>(params, &fig_1c.samples[0], Vector2::zeros());
    let estimates = observe(&mut o, &billiard, &fig_1c, &exact, &u);
    let fig = score(&fig_1c, &estimates, (1.5, 3.0 + 1e-9));
    eprintln!("Fig. 1c, (38) over [1.5, 3] s: {:?}", fig.all);
    assert!(fig.all.max <= 2e-2, "{:?}", fig.all);
    let mut g = common::runs::Gauss::new(4242);
    let mut n = 0;
    let params = ObserverParams::new(10.0, 20.0);
    while n < 10 {
        let q = Vector2::new(0.8 * g.uniform() - 0.4, 0.8 * g.uniform() - 0.4);
        let v = Vector2::new(4.0 * g.uniform() - 2.0, 4.0 * g.uniform() - 2.0);
        if billiard.gaps(&q).iter().any(|&h| h < 0.02) {
            continue;
        }
        let data = reference(&billiard, (q, v), 1e-5, 100, 6.0, &u);
        let exact = measure(&data, 0.0, 0);
        let mut o = reduced::<2, 4>(params, &data.samples[0], Vector2::zeros());
        let reduced_order = score(
            &data,
            &observe(&mut o, &billiard, &data, &exact, &u),
            (1.0, 6.0 + 1e-9),
        );
        let mut f = full::<2, 4>(params, &data.samples[0], Vector2::zeros());
        let full_order = score(
            &data,
            &observe(&mut f, &billiard, &data, &exact, &u),
            (1.0, 6.0 + 1e-9),
        );
        eprintln!(
            "billiard start {n}: maximum off the brackets over [1, 6] s, (38) {:.2e}, (36) {:.2e}",
            reduced_order.clean.max, full_order.clean.max
        );
        assert!(
            reduced_order.clean.max <= 2e-2,
            "start {n}: (38) {:e}",
            reduced_order.clean.max
        );
        assert!(
            full_order.clean.max <= 2e-2,
            "start {n}: (36) {:e}",
            full_order.clean.max
        );
        n += 1;
    }
}

// ---------------------------------------------------------------------------
// Decay rate against gain selection

/// The measured decay of the Lyapunov function's root,
/// `√(q̃ᵀ L_ρ1 q̃ + ṽᵀ M(q) ṽ)` (with `L_ρ1 = 0`: the kinetic-metric norm
/// `|ṽ|_M`), over the samples in `[0, t_end]` (no plant impact there) while
/// `V ≥ 1e-4 V(0)` (below that, within two decades of the plant's own
/// discretization error, about 1e-6 here, the ratio of consecutive values
/// measures the plant, not the observer): the overall rate
/// `−ln(V(t₁)/V(0))/t₁` and the smallest rate over one sampling interval.
fn measured_rates<M, const N: usize, const K: usize>(
    model: &M,
    data: &Reference<N>,
    estimates: &[Estimate<f64, N>],
    l_rho1: f64,
    t_end: f64,
) -> (f64, f64)
where
    M: Model<N, K, Scalar = f64>,
{
    let norms: Vec<(f64, f64)> = data
        .samples
        .iter()
        .zip(estimates)
        .take_while(|(s, _)| s.t <= t_end + 1e-9)
        .map(|(s, e)| {
            let (dq, dv) = (s.q - e.q, s.v - e.v);
            let w = l_rho1 * dq.norm_squared() + (dv.transpose() * model.mass(&s.q) * dv)[0];
            (s.t, w.sqrt())
        })
        .collect();
    let floor = 1e-4 * norms[0].1;
    let norms: Vec<(f64, f64)> = norms.into_iter().take_while(|&(_, w)| w >= floor).collect();
    let (t1, w1) = norms[norms.len() - 1];
    let overall = -(w1 / norms[0].1).ln() / t1;
    let worst_step = norms
        .windows(2)
        .map(|w| -(w[1].1 / w[0].1).ln() / (w[1].0 - w[0].0))
        .fold(f64::INFINITY, f64::min);
    (overall, worst_step)
}

/// The gain-selection constants over the bounding box of the plant's
/// configurations in `[0, t_end]` (widened by 0.05) with `C_v = 1.1 max |v|`.
fn bounds_along<M, const N: usize, const K: usize>(
    model: &M,
    data: &Reference<N>,
    t_end: f64,
    u: &M::Input,
) -> ModelBounds<f64>
where
    M: Model<N, K, Scalar = f64>,
{
    let stretch = data.samples.iter().filter(|s| s.t <= t_end + 1e-9);
    let (mut lo, mut hi, mut speed) = (data.samples[0].q, data.samples[0].q, 0.0_f64);
    for s in stretch {
        lo = lo.inf(&s.q);
        hi = hi.sup(&s.q);
        speed = speed.max(s.v.norm());
    }
    let margin = SVector::repeat(0.05);
    let region = GainRegion::new(lo - margin, hi + margin, 1.1 * speed);
    ModelBounds::estimate(model, &region, u).unwrap()
}

/// On smooth stretches (no impact) the error decays at least at the rate
/// gain selection guarantees, checked over every sampling interval:
///
/// - reduced order: `|ṽ|_M` at `r = l_d − (C_F + C_M C_v)/λ_min`
///   ([`ModelBounds::decay_rate`]: Corollary 2's `β` over `λ_min`, at
///   least Corollary 3's `β` for these models, whose `λ_min ≤ 1`);
/// - full order, `Λ = λI`, `L_ρ1 = ρI`: `√(q̃ᵀ L_ρ1 q̃ + ṽᵀ M ṽ)` (the
///   Lyapunov function of Theorem 2) at `min(λ, r)`.
///
/// Example 1 has `M = I`, `C = 0` and a constant `F`: the reduced-order
/// discretization integrates `ṽ' = −l_d ṽ` exactly there, so its rate
/// equals `r = l_d` to round-off (the comparison allows `1e-9` relative,
/// far above the round-off of a logarithm and far below any discretization
/// error). The double pendulum has `C ≠ 0`, a configuration-dependent `M`
/// and damping; it achieves more than its guarantee.
#[test]
fn smooth_decay_is_at_least_the_guaranteed_rate() {
    let zero = SVector::<f64, 0>::zeros();
    // Example 1 before its first impact (0.355 s)
    let parabola = Parabola::<f64>::new();
    let data = example_1_run(0.34);
    assert!(data.impacts.is_empty());
    let bounds = bounds_along(&parabola, &data, 0.34, &zero);
    let v_hat0 = Vector2::zeros();
    decays_at_the_guaranteed_rate("Example 1", &parabola, &data, &bounds, 10.0, v_hat0);
    // the double pendulum released at rest from (−1.2, −1.2) rad: its tip
    // swings clear of wall and floor for 0.49 s; with the gain Corollary 3
    // asks for β = 1
    let pendulum = DoublePendulum::<f64>::new();
    let start = (Vector2::new(-1.2, -1.2), Vector2::zeros());
    let data = reference(&pendulum, start, 1e-5, 100, 0.45, &zero);
    assert!(
        data.samples
            .iter()
            .all(|s| pendulum.gaps(&s.q).min() > 1e-3)
    );
    let bounds = bounds_along(&pendulum, &data, 0.45, &zero);
    let l_d = bounds.gain_for_margin(Design::ReducedOrder, 1.0).ceil();
    let v_hat0 = Vector2::new(1.0, -1.0);
    decays_at_the_guaranteed_rate("double pendulum", &pendulum, &data, &bounds, l_d, v_hat0);
}

/// Both observers from `v̂(0) = v0` on `data` (a smooth stretch): asserts
/// the per-interval decay rates of the test above.
fn decays_at_the_guaranteed_rate<M>(
    name: &str,
    model: &M,
    data: &Reference<2>,
    bounds: &ModelBounds<f64>,
    l_d: f64,
    v0: SVector<f64, 2>,
) where
    M: Model<2, 2, Scalar = f64, Input = SVector<f64, 0>>,
{
    let (lambda, rho) = (5.0, 25.0); // the gains of `full`
    let zero = SVector::<f64, 0>::zeros();
    let t_end = data.samples[data.samples.len() - 1].t;
    let rate = bounds.decay_rate(l_d);
    eprintln!(
        "{name}: λ_min {:.3}, λ_max {:.3}, C_M {:.3}, C_F {:.3}, C_v {:.2}; l_d {l_d}: β (Cor. 2) {:.3}, β (Cor. 3) {:.3}, guaranteed rate r {rate:.3}/s",
        bounds.mass_min,
        bounds.mass_max,
        bounds.coriolis,
        bounds.force_lipschitz,
        bounds.velocity_bound,
        bounds.margin(Design::FullOrder, l_d),
        bounds.margin(Design::ReducedOrder, l_d),
    );
    assert!(rate >= bounds.margin(Design::ReducedOrder, l_d) - 1e-12);
    let params = ObserverParams::new(l_d, bounds.velocity_bound);
    let measured = measure(data, 0.0, 0);

    let estimates = observe(
        &mut reduced::<2, 2>(params, &data.samples[0], v0),
        model,
        data,
        &measured,
        &zero,
    );
    let (overall, worst) = measured_rates(model, data, &estimates, 0.0, t_end);
    eprintln!(
        "  reduced order: |ṽ|_M decays at {overall:.4}/s overall, {worst:.4}/s in the worst interval (guaranteed {rate:.4}/s)"
    );
    assert!(worst >= rate * (1.0 - 1e-9), "{worst} < {rate}");
    let estimates = observe(
        &mut full::<2, 2>(params, &data.samples[0], v0),
        model,
        data,
        &measured,
        &zero,
    );
    let (overall, worst) = measured_rates(model, data, &estimates, rho, t_end);
    let guaranteed = rate.min(lambda);
    eprintln!(
        "  full order: √(q̃ᵀL_ρ1q̃ + ṽᵀMṽ) decays at {overall:.4}/s overall, {worst:.4}/s in the worst interval (guaranteed min(λ, r) = {guaranteed:.4}/s)"
    );
    assert!(worst >= guaranteed * (1.0 - 1e-9), "{worst} < {guaranteed}");
}

// ---------------------------------------------------------------------------
// Restitution mismatch and measurement noise

/// With `ê = e − δ` the error no longer vanishes at impacts (Section VI-D):
/// each impact leaves roughly `δ` times the normal speed in `ṽ`, which the
/// injection then removes at `l_d`. Over the bouncing stretch of Example 1
/// (`t ∈ [1.5, 4.45)` s, after the initial transient and before the
/// accumulation ends) the mean of `|v − v̂|`, and its maximum over the
/// samples that do not bracket a plant impact, grow with `δ`: asserted
/// strictly increasing. The maximum over all samples is printed, not
/// asserted: once `|ṽ| τ_s` exceeds the distance the plant still has to go
/// to an impact just after a sample, the observer applies Newton's law one
/// sample early, and that sample carries the whole jump `(1 + ê) u`, which
/// *shrinks* as `ê = e − δ` does (measured: 5.33 at `δ = 0.1`, 5.12 at
/// `δ = 0.2`, both the sample 40 µs before the impact at 1.778 s, ratio
/// 1.04 ≈ 1.8 / 1.7).
///
/// With `δ = 0` the observer applies every plant impact itself: at each
/// sample of the stretch `|v − v̂|` stays below the velocity jump
/// `(1 + e) u` of the latest plant impact (approach speed `u`), which an
/// impact missed, or applied twice, would leave whole. The bound is not
/// empty where it matters: at the end of the stretch the impacts come
/// every 0.9 ms, at `u ≈ 0.05 m/s`, faster than the 1 kHz samples, and the
/// error there (up to a third of the jump, 3.1e-2, the largest of the
/// stretch; below 5e-3 before the accumulation) depends on where the
/// impacts fall between the samples, so on the plant's Newton's law.
#[test]
fn restitution_mismatch_grows_the_error() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let data = example_1_run(4.45);
    let measured = measure(&data, 0.0, 0);
    let e = model.restitution();
    let mut curve = Vec::new();
    for delta in [0.0, 0.05, 0.1, 0.2] {
        let params = ObserverParams::new(10.0, 20.0);
        let mut observer = reduced::<2, 2>(params, &data.samples[0], Vector2::zeros())
            .with_restitution(e.add_scalar(-delta))
            .unwrap();
        let estimates = observe(&mut observer, &model, &data, &measured, &u);
        let all = errors(&data, &estimates);
        if delta == 0.0 {
            below_the_latest_jump(&data, &all, e.as_slice(), (1.5, 4.45));
        }
        let errors = window(&data, &all, 1.5, 4.45);
        let mean = errors.iter().sum::<f64>() / errors.len() as f64;
        let f = figures(&errors);
        let clean = score(&data, &estimates, (1.5, 4.45)).clean;
        eprintln!(
            "ê = e − {delta}: |v − v̂| over [1.5, 4.45) s: mean {mean:.2e}, median {:.2e}, p90 {:.2e}, max {:.2e}, max off the impacts {:.2e}",
            f.median, f.p90, f.max, clean.max
        );
        curve.push((delta, mean, clean.max));
    }
    for w in curve.windows(2) {
        assert!(w[1].1 > w[0].1 && w[1].2 > w[0].2, "{curve:?}");
    }
}

/// Asserts `|v − v̂| < (1 + e_i) u` at every sample of `[from, to)`, `u` the
/// approach speed of the latest plant impact (on constraint `i`) at or
/// before the sample.
fn below_the_latest_jump<const N: usize>(
    data: &Reference<N>,
    errors: &[f64],
    e: &[f64],
    (from, to): (f64, f64),
) {
    let mut worst = (0.0, 0.0);
    for (s, &err) in data.samples.iter().zip(errors) {
        if s.t < from - 1e-9 || s.t >= to - 1e-9 {
            continue;
        }
        let latest = data.impacts.iter().rev().find(|i| i.0 <= s.t + 1e-9);
        let &(_, i, u) = latest.expect("a plant impact before the stretch");
        let ratio = err / ((1.0 + e[i]) * u);
        if ratio > worst.0 {
            worst = (ratio, s.t);
        }
    }
    eprintln!(
        "ê = e: |v − v̂| is at most {:.2} of the latest plant impact's jump (at t = {:.3} s)",
        worst.0, worst.1
    );
    assert!(worst.0 < 1.0, "{worst:?}");
}

/// Gaussian noise of standard deviation `σ` on each measured coordinate
/// (the observer is told `σ`), over `[2, 10]` s of Example 1: flight and
/// impacts up to the accumulation that ends at 4.456 s, sliding after it.
///
/// Where the level comes from: the injection passes the difference of two
/// noisy samples with gain `φ = (1 − e^{−l_d τ})/τ ≈ l_d`, and the
/// interval's decay `1 − φτ` filters it: `e_{k+1} = (1 − φτ) e_k +
/// φ (n_{k+1} − n_k)`, whose stationary standard deviation is
/// `u = φσ √(2/(2 − φτ)) ≈ l_d σ` per coordinate.
/// - In flight both coordinates carry it: the median of `|ṽ|` is the
///   Rayleigh `1.18 u = 0.83 √2 l_d σ`.
/// - Sliding, the tangential coordinate carries it, and the normal one
///   only what the last injection left separating: each piece of a held
///   contact starts with a separating normal speed taken out
///   (`Interval::settled`), and an approach is closed at the end of each
///   update. At a sample the normal error is then the positive part of
///   the last injection's normal term `φ (n_{k+1} − n_k)`, of standard
///   deviation `√2 u`, and `|ṽ|` is `√(t² + max(x, 0)²)` with `t ~ N(0,
///   u²)`, `x ~ N(0, 2u²)`: its median, drawn below, is `0.72 √2 l_d σ`.
///
/// Asserted for `σ > 0`: the median over the flight at least `0.8 √2 l_d
/// σ` (0.96 of its floor); the median over the slide between 0.9 and 1.25
/// times its floor (measured 1.01 at `σ ≤ 1e-4`, 1.14 at `1e-3`); over
/// the window, the median grows with `σ` and is at most `2 √2 l_d σ + m₀`
/// (`m₀` the noise-free median), the 90th percentile below `p₀ + 4 √2 l_d
/// σ` (`p₀` noise-free), and noise never makes the observer locate an
/// impact on the sliding contact (`t > 5` s). The maximum is printed, not
/// asserted: when noise puts the sample just before an impact inside the
/// band, the observer applies Newton's law up to `n_σ σ / v_n` early, and
/// that one sample carries the whole jump.
///
/// Before held contacts were settled, the slide's normal error alone had
/// a median of 1.1 to 1.3 × `√2 l_d σ` at `σ ≤ 1e-5`: the floor, held at
/// acceleration level, kept each separating injection's normal speed for
/// as long as the rule held it, and pushed on it. The window's median was
/// 1.52 × at `σ = 1e-6` (now 0.90 ×); this comment then put the excess
/// down to the noisy tangent of the contact, and asserted the flight's
/// floor over the whole window.
#[test]
fn noise_sets_the_error_level() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let data = example_1_run(10.0);
    let l_d = 10.0;
    let accumulation = data.impacts.last().expect("impacts").0;
    let (flight, slide) = (
        (2.0, accumulation - 0.05),
        (accumulation + 0.15, 10.0 + 1e-3),
    );
    // the slide's floor in units of `√2 l_d σ`: the median of
    // `√(t² + max(x, 0)²)/√2`, `t ~ N(0, 1)`, `x ~ N(0, 2)`
    let mut g = common::runs::Gauss::new(2024);
    let draws: Vec<f64> = (0..200_000)
        .map(|_| {
            let (t, x) = (g.normal(), 2f64.sqrt() * g.normal());
            (t * t + x.max(0.0).powi(2)).sqrt() / 2f64.sqrt()
        })
        .collect();
    let slide_floor = figures(&draws).median;
    eprintln!("accumulation at {accumulation:.3} s; the slide's floor {slide_floor:.3} × √2 l_d σ");
    let mut curve = Vec::new();
    for sigma in [0.0, 1e-6, 1e-5, 1e-4, 1e-3] {
        let measured = measure(&data, sigma, 7);
        let params = ObserverParams::new(l_d, 20.0).with_noise(sigma);
        let mut observer = reduced::<2, 2>(params, &data.samples[0], Vector2::zeros());
        let mut estimates = vec![observer.estimate()];
        let mut sliding_impacts = 0;
        for (s, q) in data.samples.iter().zip(&measured).skip(1) {
            estimates.push(observer.update(&model, s.t, q, &u).unwrap());
            if s.t > 5.0 {
                sliding_impacts += observer.report().impacts;
            }
        }
        let errors = errors(&data, &estimates);
        let f = figures(&window(&data, &errors, 2.0, 10.0 + 1e-3));
        let in_flight = figures(&window(&data, &errors, flight.0, flight.1)).median;
        let sliding = figures(&window(&data, &errors, slide.0, slide.1)).median;
        let scale = 2f64.sqrt() * l_d * sigma;
        eprintln!(
            "σ = {sigma:.0e}: |v − v̂| over [2, 10] s: median {:.2e} ({:.2} × √2 l_d σ), p90 {:.2e} ({:.2} ×), max {:.2e}; median in flight {:.2} ×, sliding {:.2} × (of its floor {:.2}); impacts located while sliding: {sliding_impacts}",
            f.median,
            f.median / scale,
            f.p90,
            f.p90 / scale,
            f.max,
            in_flight / scale,
            sliding / scale,
            sliding / (slide_floor * scale),
        );
        curve.push((sigma, f, (in_flight, sliding), sliding_impacts));
    }
    let (m0, p0) = (curve[0].1.median, curve[0].1.p90);
    for w in curve.windows(2) {
        assert!(w[1].1.median > w[0].1.median, "{curve:?}");
    }
    for (sigma, f, (in_flight, sliding), sliding_impacts) in &curve[1..] {
        let scale = 2f64.sqrt() * l_d * sigma;
        assert!(
            *in_flight >= 0.8 * scale,
            "σ = {sigma}: in flight {in_flight:e}"
        );
        assert!(
            *sliding >= 0.9 * slide_floor * scale && *sliding <= 1.25 * slide_floor * scale,
            "σ = {sigma}: sliding {sliding:e}"
        );
        assert!(f.median <= 2.0 * scale + m0, "σ = {sigma}: {f:?}");
        assert!(f.p90 <= p0 + 4.0 * scale, "σ = {sigma}: {f:?}");
        assert_eq!(*sliding_impacts, 0, "σ = {sigma}");
    }
    assert_eq!(curve[0].3, 0, "σ = 0");
}

/// The mass sliding on Example 1's floor `y = x²` (frictionless, `g =
/// 9.81`, unit mass) from `x` at `ẋ`, over `t`: the Lagrangian of the one
/// coordinate left, `(1 + 4x²) ẍ + 4x ẋ² + 2g x = 0`, by classical
/// Runge–Kutta in ten thousand steps. Returns `(q, v)`.
fn slide_on_the_floor(x: f64, xd: f64, t: f64) -> (Vector2<f64>, Vector2<f64>) {
    let acc = |x: f64, xd: f64| -(4.0 * x * xd * xd + 2.0 * 9.81 * x) / (1.0 + 4.0 * x * x);
    let steps = 10_000;
    let h = t / steps as f64;
    let (mut x, mut xd) = (x, xd);
    for _ in 0..steps {
        let (k1x, k1v) = (xd, acc(x, xd));
        let (k2x, k2v) = (
            xd + 0.5 * h * k1v,
            acc(x + 0.5 * h * k1x, xd + 0.5 * h * k1v),
        );
        let (k3x, k3v) = (
            xd + 0.5 * h * k2v,
            acc(x + 0.5 * h * k2x, xd + 0.5 * h * k2v),
        );
        let (k4x, k4v) = (xd + h * k3v, acc(x + h * k3x, xd + h * k3v));
        x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        xd += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
    (Vector2::new(x, x * x), Vector2::new(xd, 2.0 * x * xd))
}

/// An estimate that leaves a held contact takes no separating speed into
/// the slide. Example 1's mass slides along the floor through `x = 0.3`
/// at 5 m/s; both observers start there, told `σ = 1e-3`, with the
/// plant's velocity plus a separating normal speed `s` of 0.01 to 0.04
/// m/s, slower than the resting speed the band allows; one update with the
/// exact sample 1 ms on. Reference: the slide itself, integrated in the
/// one coordinate left (`slide_on_the_floor`). Where the contact rule
/// held the floor, the plant's velocity is on its tangent and the settle
/// projects onto that tangent in the metric of `M`, so asserted: `|ṽ|`
/// falls below `1e-3 s` (measured at most 2.6e-5 s). Where the rule let
/// the estimate depart (a separation faster than (38)'s noise), `|ṽ|`
/// does not grow.
///
/// Before, the floor held at acceleration level kept `J v̂ = s` over the
/// interval and pushed on the estimate with about 40 m/s² while it left:
/// (36) ended the update 0.98 `s` off at every `s`, and (38) at `s = 0.01`.
#[test]
fn a_held_contact_takes_no_separating_speed_into_the_slide() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let x = 0.3;
    let q0 = Vector2::new(x, x * x);
    let tangent = Vector2::new(1.0, 2.0 * x).normalize();
    let normal = Vector2::new(-2.0 * x, 1.0).normalize();
    let v0 = tangent * 5.0;
    let (q1, v1) = slide_on_the_floor(x, v0[0], 1e-3);
    let params = ObserverParams::new(10.0, 20.0).with_noise(1e-3);
    let start = State {
        t: 0.0,
        q: q0,
        v: v0,
    };
    let mut held = 0;
    for s in [0.01, 0.02, 0.04] {
        let v_hat0 = v0 + normal * s;
        let mut o38 = reduced::<2, 2>(params, &start, v_hat0);
        let mut o36 = full::<2, 2>(params, &start, v_hat0);
        let after = [
            (
                "(38)",
                o38.update(&model, 1e-3, &q1, &u).unwrap(),
                o38.report().contacts,
            ),
            (
                "(36)",
                o36.update(&model, 1e-3, &q1, &u).unwrap(),
                o36.report().contacts,
            ),
        ];
        for (name, e, contacts) in after {
            let error = (e.v - v1).norm();
            let on_floor = contacts.contains(0);
            eprintln!(
                "{name}, s = {s}: floor held {on_floor}, |ṽ| {s:.2e} -> {error:.2e} ({:.1e} s)",
                error / s
            );
            if on_floor {
                held += 1;
                assert!(error <= 1e-3 * s, "{name}, s = {s}: {error:e}");
            } else {
                assert!(error <= s, "{name}, s = {s}: {error:e}");
            }
        }
    }
    assert!(held >= 4, "the floor held in {held} of 6 updates");
}

// ---------------------------------------------------------------------------
// Well-posedness: the same measurements give the same bits

fn bits<const N: usize>(estimates: &[Estimate<f64, N>]) -> Vec<u64> {
    estimates
        .iter()
        .flat_map(|e| {
            std::iter::once(e.t)
                .chain(e.q.iter().copied())
                .chain(e.v.iter().copied())
        })
        .map(f64::to_bits)
        .collect()
}

/// The observer's output for a measured trajectory is unique (Theorem 1)
/// and, numerically, reproducible bit for bit: two observers fed the same
/// noisy samples of Example 1 (σ = 1e-4: impacts, an accumulation, noisy
/// sliding) and of the billiard agree to the last bit, for both observers
/// and both discretizations; so does a copy taken half-way.
#[test]
fn same_measurements_give_the_same_bits() {
    let u = SVector::zeros();
    let parabola = Parabola::<f64>::new();
    let data = example_1_run(6.0);
    let measured = measure(&data, 1e-4, 11);
    let billiard = Billiard::<f64>::new();
    let data_b = reference(
        &billiard,
        Billiard::<f64>::initial_state(),
        1e-5,
        100,
        6.0,
        &u,
    );
    let measured_b = measure(&data_b, 1e-4, 12);
    for scheme in [Discretization::ImpactAware, Discretization::SectionVii] {
        let params = ObserverParams::new(10.0, 20.0)
            .with_noise(1e-4)
            .with_scheme(scheme);
        let runs: Vec<Vec<u64>> = (0..2)
            .map(|_| {
                let mut a = reduced::<2, 2>(params, &data.samples[0], Vector2::zeros());
                let mut b = full::<2, 2>(params, &data.samples[0], Vector2::zeros());
                let mut c = reduced::<2, 4>(params, &data_b.samples[0], Vector2::zeros());
                let mut out = bits(&observe(&mut a, &parabola, &data, &measured, &u));
                out.extend(bits(&observe(&mut b, &parabola, &data, &measured, &u)));
                out.extend(bits(&observe(&mut c, &billiard, &data_b, &measured_b, &u)));
                out
            })
            .collect();
        assert_eq!(runs[0], runs[1], "{scheme:?}");
        // a copy continues exactly as the original
        let mut original = reduced::<2, 2>(params, &data.samples[0], Vector2::zeros());
        let half = data.samples.len() / 2;
        for (s, q) in data.samples.iter().zip(&measured).take(half).skip(1) {
            original.update(&parabola, s.t, q, &u).unwrap();
        }
        let mut copy = original;
        for (s, q) in data.samples.iter().zip(&measured).skip(half) {
            let a = original.update(&parabola, s.t, q, &u).unwrap();
            let b = copy.update(&parabola, s.t, q, &u).unwrap();
            assert_eq!(bits(&[a]), bits(&[b]));
        }
        eprintln!(
            "{scheme:?}: {} estimates bit-identical across runs",
            runs[0].len() / 5
        );
    }
}

// ---------------------------------------------------------------------------
// The printed signs of (38) and (36)

/// A fall from rest at (0, 60) m inside Example 1's parabola with the
/// ceiling moved to 100 m: no impact for 3 s. Samples at 1 kHz of a plant
/// at 1e-5.
fn free_fall() -> (Parabola<f64>, Reference<2>) {
    let model = Parabola::<f64> {
        c: 100.0,
        ..Default::default()
    };
    let data = reference(
        &model,
        (Vector2::new(0.0, 60.0), Vector2::new(1.0, 0.0)),
        1e-5,
        100,
        3.0,
        &SVector::zeros(),
    );
    assert!(data.impacts.is_empty());
    (model, data)
}

/// The reduced-order observer in its own coordinates `z`, stepped as
/// Section VII prints it (semi-explicit Euler, `M` and `F` at `q_{k+1}`),
/// with the sign `s` of the gain: `v̂ = z + s l_d q`,
/// `M dz + F dt + s l_d M v̂ dt = 0` (no constraint active). `s = +1` is
/// the form implemented, `s = −1` is (38) as printed (`v̂ = z − l_d q`,
/// `− l_d M v̂ dt`). Returns `|v − v̂|` at each sample.
fn reduced_z_form(model: &Parabola<f64>, data: &Reference<2>, l_d: f64, sign: f64) -> Vec<f64> {
    let mut z = Vector2::zeros() - data.samples[0].q * (sign * l_d);
    let mut out = vec![data.samples[0].v.norm()];
    for w in data.samples.windows(2) {
        let (tau, q1) = (w[1].t - w[0].t, w[1].q);
        let v_hat = z + q1 * (sign * l_d);
        let (mass, forces) = model.dynamics(w[1].t, &q1, &v_hat, &SVector::zeros());
        let m_inv = mass.try_inverse().unwrap();
        z -= m_inv * (forces + mass * v_hat * (sign * l_d)) * tau;
        out.push((z + q1 * (sign * l_d) - w[1].v).norm());
    }
    out
}

/// (38) as printed makes the error grow like `e^{l_d t}`:
/// `M dṽ = −(F − F̄) dt + l_d M ṽ dt − (η − η̂)`. The form Corollary 3's
/// proof needs (`v̂ = z + l_d q`, `+ l_d M v̂ dt`) makes it decay. Both in
/// the same Section VII discretization, on the same 3 s of free fall, with
/// `l_d = 10`:
///
/// - printed: the error grows at least `e^{l_d t}/10` (Euler's
///   `(1 + l_d τ)^k = e^{29.85}` at 3 s, the factor 10 for that and for the
///   initial step);
/// - implemented: it falls to Euler's lag, `l_d τ |v| + τ|g|/2` (the
///   semi-explicit step evaluates `v̂` with `z_k` and `q_{k+1}`, see the
///   module docs), at most twice that is asserted;
/// - the library's observer (impact-aware) on the same data: to round-off
///   of the exact `e^{−l_d t}` decay (below 1e-9).
#[test]
fn printed_38_diverges_and_the_implemented_form_converges() {
    let (model, data) = free_fall();
    let l_d = 10.0;
    let tau = 1e-3;
    let printed = reduced_z_form(&model, &data, l_d, -1.0);
    let implemented = reduced_z_form(&model, &data, l_d, 1.0);
    let end = data.samples.len() - 1;
    let growth = printed[end] / printed[0];
    let lag = l_d * tau * data.samples[end].v.norm() + tau * 9.81 / 2.0;
    let params = ObserverParams::new(l_d, 50.0);
    let mut observer = reduced::<2, 2>(params, &data.samples[0], Vector2::zeros());
    let library = errors(
        &data,
        &observe(
            &mut observer,
            &model,
            &data,
            &measure(&data, 0.0, 0),
            &SVector::zeros(),
        ),
    );
    eprintln!(
        "free fall, 3 s, l_d = {l_d}: printed (38): |ṽ| {:.2e} -> {:.2e} (x{growth:.2e}, e^(l_d t) = {:.2e}); implemented, Section VII: {:.2e} (Euler lag {lag:.2e}); library: {:.2e}",
        printed[0],
        printed[end],
        (l_d * 3.0f64).exp(),
        implemented[end],
        library[end]
    );
    assert!(growth >= (l_d * 3.0f64).exp() / 10.0, "{growth:e}");
    assert!(implemented[end] <= 2.0 * lag, "{:e}", implemented[end]);
    assert!(library[end] <= 1e-9, "{:e}", library[end]);
}

/// (36a)–(36d) as printed are consistent: `q̂' = v̂ + Λ q̃`, so
/// `q̃' = ṽ − Λ q̃` and the cross terms of `W = q̃ᵀL_ρ1q̃ + ṽᵀMṽ` cancel.
/// The paper's "one can equally write" line (and `F̂₁` in the proof of
/// Corollary 2) reads `q̂' = v̂ − Λ q̃`: then `q̃' = ṽ + Λ q̃`, and with
/// `Λ = 5`, `L_ρ1 = 25`, `l_d = 10` the error system
/// `[[5, 1], [−25, −10]]` has the eigenvalue `(−5 + √125)/2 = 3.09`: the
/// position error grows like `e^{3.09 t}`.
///
/// Both on 3 s of free fall, in the same explicit discretization of the
/// estimate coordinates (`v̂` injected with the measured displacement), with
/// `q̂(0)` 1 cm off: the flipped sign's `|q̃|` grows at least
/// `e^{3.09·3}/10 = 1e3` times; the consistent sign's and the library's
/// full-order observer's fall below 1e-6 m.
#[test]
fn printed_36_sign_diverges_and_36a_to_36d_converge() {
    let (model, data) = free_fall();
    let (l_d, lambda, rho) = (10.0, 5.0, 25.0);
    let offset = Vector2::new(0.01, 0.0);
    let run = |sign: f64| {
        let mut q_hat = data.samples[0].q + offset;
        let mut v_hat = Vector2::zeros();
        for w in data.samples.windows(2) {
            let tau = w[1].t - w[0].t;
            let q_tilde = w[0].q - q_hat;
            let (mass, forces) = model.dynamics(w[0].t, &w[0].q, &v_hat, &SVector::zeros());
            let m_inv = mass.try_inverse().unwrap();
            q_hat += (v_hat + q_tilde * (sign * lambda)) * tau;
            v_hat +=
                (m_inv * (-forces + q_tilde * rho)) * tau + (w[1].q - w[0].q - v_hat * tau) * l_d;
        }
        (data.samples[data.samples.len() - 1].q - q_hat).norm()
    };
    let consistent = run(1.0);
    let flipped = run(-1.0);
    let growth_rate = (-5.0 + 125f64.sqrt()) / 2.0;
    let params = ObserverParams::new(l_d, 50.0);
    let mut observer = FullOrder::<f64, 2, 2>::new(
        params,
        FullOrderGains::scalar(lambda, rho),
        0.0,
        data.samples[0].q,
        Vector2::zeros(),
    )
    .unwrap()
    .with_position_estimate(data.samples[0].q + offset)
    .unwrap();
    let estimates = observe(
        &mut observer,
        &model,
        &data,
        &measure(&data, 0.0, 0),
        &SVector::zeros(),
    );
    let end = data.samples.len() - 1;
    let library = (data.samples[end].q - estimates[end].q).norm();
    eprintln!(
        "free fall, 3 s, |q̃(0)| = 1 cm: q̂' = v̂ − Λq̃ (printed line): |q̃| = {flipped:.2e} (e^(3.09 t) = {:.2e} times); q̂' = v̂ + Λq̃ (36a–d): {consistent:.2e}; library FullOrder: {library:.2e}",
        (growth_rate * 3.0f64).exp()
    );
    assert!(
        flipped >= 0.01 * (growth_rate * 3.0f64).exp() / 10.0,
        "{flipped:e}"
    );
    assert!(consistent <= 1e-6, "{consistent:e}");
    assert!(library <= 1e-6, "{library:e}");
}

// ---------------------------------------------------------------------------
// Bad input

/// A non-finite measurement, time or input, a time that does not advance,
/// a non-finite model parameter, a model restitution out of `[0, 1]`: each
/// is an error naming it, and the observer keeps its state to the bit (the
/// next good update gives what it gives without the bad one). Bad settings
/// and gains are refused at construction.
#[test]
fn bad_input_is_refused_and_the_state_kept() {
    let arm = Arm3::<f64>::new();
    let u = Vector3::new(1.0, 0.5, 0.1);
    let data = reference(&arm, Arm3::<f64>::initial_state(), 1e-4, 10, 0.2, &u);
    let params = ObserverParams::new(10.0, 50.0);
    let mut observer = full::<3, 1>(params, &data.samples[0], Vector3::zeros());
    let mut twin = observer;
    let n = data.samples.len();
    for s in &data.samples[1..n - 1] {
        observer.update(&arm, s.t, &s.q, &u).unwrap();
        twin.update(&arm, s.t, &s.q, &u).unwrap();
    }
    let (before, report) = (observer.estimate(), *observer.report());
    let last = data.samples[n - 1];
    let nan_q = Vector3::new(last.q[0], f64::NAN, last.q[2]);
    let bad_model = Arm3::<f64> {
        g: f64::NAN,
        ..Default::default()
    };
    let bad_e = Arm3::<f64> {
        restitution: SVector::repeat(1.5),
        ..Default::default()
    };
    type Outcome = Result<Estimate<f64, 3>, ObserverError<f64>>;
    let cases: [(Outcome, ObserverError<f64>); 7] = [
        (
            observer.update(&arm, last.t, &nan_q, &u),
            ObserverError::Data(DataError::NonFinite {
                which: "q",
                index: 1,
            }),
        ),
        (
            observer.update(&arm, last.t, &Vector3::repeat(f64::INFINITY), &u),
            ObserverError::Data(DataError::NonFinite {
                which: "q",
                index: 0,
            }),
        ),
        (
            observer.update(&arm, f64::NAN, &last.q, &u),
            ObserverError::InvalidTime {
                t: f64::NAN,
                last: before.t,
            },
        ),
        (
            observer.update(&arm, before.t, &last.q, &u),
            ObserverError::InvalidTime {
                t: before.t,
                last: before.t,
            },
        ),
        (
            observer.update(&arm, last.t, &last.q, &Vector3::new(0.0, 0.0, f64::NAN)),
            ObserverError::Data(DataError::NonFiniteInput { index: 2 }),
        ),
        (
            observer.update(&bad_model, last.t, &last.q, &u),
            ObserverError::Data(DataError::NonFiniteParameter {
                index: Arm3::<f64>::parameter_index("g").unwrap(),
            }),
        ),
        (
            observer.update(&bad_e, last.t, &last.q, &u),
            ObserverError::Data(DataError::InvalidRestitution {
                constraint: 0,
                value: 1.5,
            }),
        ),
    ];
    for (result, expected) in cases {
        match (result, expected) {
            (
                Err(ObserverError::InvalidTime { t, last }),
                ObserverError::InvalidTime { t: t2, last: l2 },
            ) => {
                assert!((t.is_nan() && t2.is_nan()) || t == t2);
                assert_eq!(last, l2);
            }
            (Err(e), expected) => assert_eq!(e, expected),
            (Ok(_), expected) => panic!("accepted, expected {expected:?}"),
        }
        eprintln!("refused: {expected:?}");
        assert_eq!(bits(&[observer.estimate()]), bits(&[before]));
        assert_eq!(*observer.report(), report);
    }
    let a = observer.update(&arm, last.t, &last.q, &u).unwrap();
    let b = twin.update(&arm, last.t, &last.q, &u).unwrap();
    assert_eq!(bits(&[a]), bits(&[b]));

    // settings, gains and restitution are checked where they are given
    let start = &data.samples[0];
    let bad = |p: ObserverParams<f64>| {
        ReducedOrder::<f64, 3, 1>::new(p, 0.0, start.q, start.v).unwrap_err()
    };
    assert!(matches!(
        bad(ObserverParams::new(0.0, 1.0)),
        ObserverError::Data(DataError::InvalidParams { name: "l_d", .. })
    ));
    assert!(matches!(
        bad(ObserverParams::new(f64::NAN, 1.0)),
        ObserverError::Data(DataError::InvalidParams { name: "l_d", .. })
    ));
    assert!(matches!(
        bad(ObserverParams::new(1.0, -1.0)),
        ObserverError::Data(DataError::InvalidParams {
            name: "velocity_bound",
            ..
        })
    ));
    assert!(matches!(
        bad(ObserverParams::new(1.0, 1.0).with_noise(f64::NAN)),
        ObserverError::Data(DataError::InvalidParams { name: "noise", .. })
    ));
    for step in [0.0, -1e-3, f64::NAN] {
        assert!(matches!(
            bad(ObserverParams {
                max_step: step,
                ..ObserverParams::new(1.0, 1.0)
            }),
            ObserverError::Data(DataError::InvalidParams {
                name: "max_step",
                ..
            })
        ));
    }
    let gains = FullOrderGains {
        lambda: SMatrix::<f64, 3, 3>::from_diagonal(&Vector3::new(1.0, -1.0, 1.0)),
        l_rho1: SMatrix::identity(),
    };
    assert!(matches!(
        FullOrder::<f64, 3, 1>::new(params, gains, 0.0, start.q, start.v),
        Err(ObserverError::Data(DataError::InvalidParams {
            name: "lambda",
            ..
        }))
    ));
    assert!(matches!(
        ReducedOrder::<f64, 3, 1>::new(params, 0.0, start.q, start.v)
            .unwrap()
            .with_restitution(SVector::repeat(-0.1)),
        Err(ObserverError::Data(DataError::InvalidRestitution {
            constraint: 0,
            ..
        }))
    ));
    assert!(matches!(
        ReducedOrder::<f64, 3, 1>::new(params, 0.0, Vector3::new(0.0, f64::NAN, 0.0), start.v),
        Err(ObserverError::Data(DataError::NonFinite {
            which: "q0",
            index: 1
        }))
    ));
}

/// Fig. 1a: balls 2 and 3 travel glued (gap 0, relative velocity 0) and
/// hit the right wall together. The plant resolves the impact
/// simultaneously (both contacts in one LCP) and they stay glued; with
/// `⟨∇h_wall, M⁻¹ ∇h_23⟩ ≠ 0` the outcome depends discontinuously on the
/// pre-impact velocities (the paper's Section III-D), so an observer that
/// read the round-off of its estimate of `v₂ − v₃` as an approach would
/// resolve it as a sequence of pairwise impacts and separate the balls.
/// Both observers must resolve it as the plant does: the wall impact at
/// 0.94 s does not raise their error (the largest error after it is at
/// most the largest in the 0.14 s before it; the sequential resolution
/// raised the full-order error to 0.13 m/s, measured when it did that).
#[test]
fn glued_balls_hit_the_wall_together_in_both_observers() {
    let model = ThreeBalls::<f64>::default();
    let data = reference::<_, 3, 4>(
        &model,
        ThreeBalls::<f64>::initial_state(),
        1e-5,
        100,
        1.5,
        &SVector::zeros(),
    );
    assert!(
        data.impacts
            .iter()
            .any(|&(t, i, _)| i == 3 && t > 0.9 && t < 1.0),
        "no wall impact near 0.94 s"
    );
    let measured = measure(&data, 0.0, 1);
    let params = ObserverParams::new(10.0, 5.0);
    let v0 = SVector::<f64, 3>::new(0.0, 0.5, -0.5);
    let start = &data.samples[0];
    let mut ro = reduced::<3, 4>(params, start, v0);
    let mut fo = full::<3, 4>(params, start, v0);
    let ro = errors(
        &data,
        &observe(&mut ro, &model, &data, &measured, &SVector::zeros()),
    );
    let fo = errors(
        &data,
        &observe(&mut fo, &model, &data, &measured, &SVector::zeros()),
    );
    let before = |e: &[f64]| figures(&window(&data, e, 0.8, 0.94)).max;
    let after = |e: &[f64]| figures(&window(&data, e, 0.94, 1.5)).max;
    eprintln!(
        "glued balls at the wall: max |v − v̂| before / after: reduced {:.1e} / {:.1e}, full {:.1e} / {:.1e}",
        before(&ro),
        after(&ro),
        before(&fo),
        after(&fo)
    );
    assert!(
        after(&ro) <= before(&ro),
        "reduced: {} after, {} before",
        after(&ro),
        before(&ro)
    );
    assert!(
        after(&fo) <= before(&fo),
        "full: {} after, {} before",
        after(&fo),
        before(&fo)
    );
}

/// Embedded targets run the observers in `f32`: Example 1 observed in
/// `f32` (model, times, measurements) from an `f64` plant.
///
/// Thresholds: in `f32`, the sample times near t = 10 s are spaced by
/// `ε₃₂ t ≈ 1e-6 s`, a relative error of 1e-3 on a 1 ms interval; times the
/// velocity (about 10 m/s) and the injection (l_d τ = 1e-2 per sample)
/// that is an error of up to 1e-4 m/s per sample (measured medians over
/// [2, 10] s: 2.8e-5 reduced, 2.4e-5 full); the median must stay below
/// 1e-3 and the error must still converge from v̂(0) = 0 (below 1e-2 m/s
/// at 2 s, from 9.5 m/s).
#[test]
fn observers_run_in_f32() {
    let model32 = Parabola::<f32>::default();
    let data = example_1_run(10.0);
    let params = ObserverParams::new(10.0_f32, 20.0);
    let q0: SVector<f32, 2> = data.samples[0].q.cast();
    let mut ro = ReducedOrder::<f32, 2, 2>::new(params, 0.0, q0, SVector::zeros()).unwrap();
    let mut fo = FullOrder::<f32, 2, 2>::new(
        params,
        FullOrderGains::scalar(5.0, 25.0),
        0.0,
        q0,
        SVector::zeros(),
    )
    .unwrap();
    let (mut ro_errors, mut fo_errors) = (vec![0.0; 1], vec![0.0; 1]);
    for s in &data.samples[1..] {
        let q: SVector<f32, 2> = s.q.cast();
        let a = ro
            .update(&model32, s.t as f32, &q, &SVector::zeros())
            .unwrap();
        let b = fo
            .update(&model32, s.t as f32, &q, &SVector::zeros())
            .unwrap();
        ro_errors.push((a.v.cast::<f64>() - s.v).norm());
        fo_errors.push((b.v.cast::<f64>() - s.v).norm());
    }
    for (name, e) in [("reduced", &ro_errors), ("full", &fo_errors)] {
        let late = figures(&window(&data, e, 2.0, 10.0));
        let at_two = e[2000];
        eprintln!(
            "f32 {name}: |v − v̂| at 2 s {at_two:.1e}; over [2, 10] s median {:.1e}, p90 {:.1e}, max {:.1e}",
            late.median, late.p90, late.max
        );
        assert!(at_two < 1e-2, "{name}: {at_two}");
        assert!(late.median < 1e-3, "{name}: {late:?}");
    }
}

// ---------------------------------------------------------------------------
// Bad samples, bad states, long gaps (issue 9, defects 1 and 2)
// ---------------------------------------------------------------------------

/// The reproducer of issue 9: Example 1 with its plant at `τ = 1e-5`,
/// sampled at 1 kHz, `l_d = 10`, `C_v = 20`, `v̂(0) = 0`; `sample(k, q)`
/// may change the measurement. Returns, per observer (reduced, full), the
/// results of every update and the velocity error after it.
type Run = Vec<(Result<Estimate<f64, 2>, ObserverError<f64>>, f64)>;
fn example_1_stream(
    v0: Vector2<f64>,
    samples: usize,
    sample: impl Fn(usize, Vector2<f64>) -> Option<(f64, Vector2<f64>)>,
) -> [Run; 2] {
    let (model, u) = (Parabola::<f64>::new(), SVector::<f64, 0>::zeros());
    let (q0, plant_v0) = Parabola::<f64>::initial_state();
    let stepper = MoreauJean::new(StepParams::new(1e-5)).unwrap();
    let mut plant = State::new(0.0, q0, plant_v0);
    let params = ObserverParams::new(10.0, 20.0);
    let mut ro = ReducedOrder::<f64, 2, 2>::new(params, 0.0, q0, v0).unwrap();
    let gains = FullOrderGains::scalar(5.0, 25.0);
    let mut fo = FullOrder::<f64, 2, 2>::new(params, gains, 0.0, q0, v0).unwrap();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for k in 1..=samples {
        for _ in 0..100 {
            stepper.step(&model, &mut plant, &u).unwrap();
        }
        let Some((t, q)) = sample(k, plant.q) else {
            continue;
        };
        let ra = ro.update(&model, t, &q, &u);
        a.push((ra, (ro.estimate().v - plant.v).norm()));
        let rb = fo.update(&model, t, &q, &u);
        b.push((rb, (fo.estimate().v - plant.v).norm()));
    }
    [a, b]
}

/// Issue 9, defect 1: one finite glitch of 1e2 to 1e6 m (a bad encoder
/// read, a unit slip) used to drive the estimate to 1e4–1e300 and wedge
/// both observers (every later update `Lcp(Infeasible)`). Now the sample
/// is refused as an outlier, the estimate kept bit for bit, and every
/// later update succeeds: recovery in 0 samples, the run bit-identical to
/// one that never saw the bad sample; the next report counts it.
#[test]
fn a_finite_glitch_is_skipped_as_an_outlier() {
    let clean = example_1_stream(Vector2::zeros(), 3000, |k, q| {
        (k != 1000).then_some((k as f64 * 1e-3, q))
    });
    for glitch in [1e2, 1e3, 1e4, 1e5, 1e6] {
        let runs = example_1_stream(Vector2::zeros(), 3000, |k, q| {
            let q = if k == 1000 {
                q + Vector2::new(glitch, glitch)
            } else {
                q
            };
            Some((k as f64 * 1e-3, q))
        });
        for (run, clean) in runs.iter().zip(&clean) {
            assert!(
                matches!(run[999].0, Err(ObserverError::Outlier { .. })),
                "{:?}",
                run[999].0
            );
            let after: Vec<_> = run[..999].iter().chain(&run[1000..]).collect();
            assert_eq!(after.len(), clean.len());
            for (k, ((r, e), (c, ec))) in after.iter().zip(clean).enumerate() {
                let r = r.as_ref().unwrap_or_else(|e| panic!("sample {k}: {e}"));
                let c = c.as_ref().unwrap();
                assert_eq!(bits(&[*r]), bits(&[*c]), "sample {k}");
                assert_eq!(e, ec);
            }
        }
        eprintln!(
            "glitch {glitch:e} m at sample 1000: refused as an outlier; |v − v̂| at 3 s {:.1e} (reduced), {:.1e} (full)",
            runs[0][2999].1, runs[1][2999].1
        );
    }
}

/// Issue 9, defect 1: a burst of ten bad samples in a row (finite, up to
/// 1e6 m, none near another) is refused sample by sample; as they do not
/// agree with each other, the estimate never restarts from one, and the run
/// goes on bit-identical to one that never saw them; the next report counts
/// ten skipped samples.
#[test]
fn a_burst_of_bad_samples_is_skipped() {
    let bad = |k: usize| 1e6 * (k as f64 - 1004.5) / 5.0;
    let clean = example_1_stream(Vector2::zeros(), 2000, |k, q| {
        (!(1000..1010).contains(&k)).then_some((k as f64 * 1e-3, q))
    });
    let runs = example_1_stream(Vector2::zeros(), 2000, |k, q| {
        let q = if (1000..1010).contains(&k) {
            q + Vector2::new(bad(k), -bad(k))
        } else {
            q
        };
        Some((k as f64 * 1e-3, q))
    });
    for (run, clean) in runs.iter().zip(&clean) {
        for r in &run[999..1009] {
            assert!(
                matches!(r.0, Err(ObserverError::Outlier { .. })),
                "{:?}",
                r.0
            );
        }
        let after: Vec<_> = run[..999].iter().chain(&run[1009..]).collect();
        for (k, ((r, _), (c, _))) in after.iter().zip(clean).enumerate() {
            assert_eq!(
                bits(&[*r.as_ref().unwrap()]),
                bits(&[*c.as_ref().unwrap()]),
                "{k}"
            );
        }
    }
    // the count, on the reduced-order observer alone
    let (model, u) = (Parabola::<f64>::new(), SVector::<f64, 0>::zeros());
    let (q0, _) = Parabola::<f64>::initial_state();
    let params = ObserverParams::new(10.0, 20.0);
    let mut ro = ReducedOrder::<f64, 2, 2>::new(params, 0.0, q0, Vector2::zeros()).unwrap();
    for k in 1000..1010 {
        let q = q0 + Vector2::new(bad(k), -bad(k));
        assert!(ro.update(&model, (k - 999) as f64 * 1e-4, &q, &u).is_err());
    }
    ro.update(&model, 1.1e-3, &q0, &u).unwrap();
    assert_eq!((ro.report().outliers, ro.report().restart), (10, None));
}

/// Issue 9, defect 1: an observer started from a wrong first measurement
/// (1e3 m off: a unit slip) sees every sample as an outlier; the samples
/// agree with each other, so after `max_outliers` = 3 refusals the 4th
/// restarts the estimate from the measurement, and from there it converges
/// as from any start (below 1e-2 m/s within 1000 samples; measured: 680
/// reduced, 803 full) instead of refusing every sample for good.
#[test]
fn samples_that_agree_with_each_other_restart_the_estimate() {
    let model = Parabola::<f64>::new();
    let (q0, v0) = Parabola::<f64>::initial_state();
    let wrong = q0 + Vector2::new(1e3, 1e3);
    let stepper = MoreauJean::new(StepParams::new(1e-5)).unwrap();
    let params = ObserverParams::new(10.0, 20.0);
    let ro = ReducedOrder::<f64, 2, 2>::new(params, 0.0, wrong, Vector2::zeros()).unwrap();
    let gains = FullOrderGains::scalar(5.0, 25.0);
    let fo = FullOrder::<f64, 2, 2>::new(params, gains, 0.0, wrong, Vector2::zeros()).unwrap();
    fn run<O: Observer<Parabola<f64>, 2, 2>>(
        mut o: O,
        name: &str,
        model: &Parabola<f64>,
        stepper: &MoreauJean<f64>,
        start: State<f64, 2>,
    ) {
        let u = SVector::zeros();
        let mut plant = start;
        let mut last_bad = 0;
        for k in 1..=2000 {
            for _ in 0..100 {
                stepper.step(model, &mut plant, &u).unwrap();
            }
            let r = o.update(model, k as f64 * 1e-3, &plant.q, &u);
            match k {
                1..=3 => assert!(matches!(r, Err(ObserverError::Outlier { .. })), "{r:?}"),
                4 => {
                    r.unwrap();
                    assert_eq!(o.report().restart, Some(Restart::Outliers));
                    assert_eq!(o.report().outliers, 3);
                }
                _ => {
                    r.unwrap();
                }
            }
            if (o.estimate().v - plant.v).norm() >= 1e-2 {
                last_bad = k;
            }
        }
        eprintln!(
            "wrong first measurement ({name}): restarted at sample 4, |v − v̂| below 1e-2 from sample {} on",
            last_bad + 1
        );
        assert!(last_bad < 1000, "{last_bad}");
    }
    let start = State::new(0.0, q0, v0);
    run(ro, "reduced", &model, &stepper, start);
    run(fo, "full", &model, &stepper, start);
}

/// Issue 9, defect 1: a huge initial guess `v̂(0) = (1e5, −1e5)` used to
/// wedge both observers. The estimate is held to `C_v = 20`, so the error
/// starts at most `C_v + |v(0)|` = 30 m/s and decays like `e^{−r t}`,
/// `r = l_d = 10` for (38) and `r = 7.5` for (36) (the real part of the
/// eigenvalues of its error system with `Λ = 5`, `L_ρ1 = 25`): below 1e-2
/// m/s after `ln(30/1e-2)/r` = 0.80 s and 1.07 s; asserted within 1000 and
/// 1200 samples (measured: reduced 777, full 1085).
#[test]
fn a_huge_initial_velocity_guess_recovers() {
    let runs = example_1_stream(Vector2::new(1e5, -1e5), 2000, |k, q| {
        Some((k as f64 * 1e-3, q))
    });
    for (run, limit) in runs.iter().zip([1000, 1200]) {
        assert!(run.iter().all(|r| r.0.is_ok()));
        assert!(run.iter().all(|r| r.0.as_ref().unwrap().v.norm() <= 20.0));
        let recovered = run.iter().rposition(|r| r.1 >= 1e-2).map_or(0, |k| k + 1);
        eprintln!("v̂(0) = (1e5, −1e5): |v − v̂| below 1e-2 from sample {recovered} on");
        assert!(recovered <= limit, "{recovered}");
    }
}

/// Issue 9, defect 2: a gap of 1 s between two samples used to give an
/// error of 573 m/s with `Ok`, and 1e6 s gave `v̂ = −1.4e24`. A gap longer
/// than `max_interval` (`3/l_d` = 0.3 s) restarts from the measurement
/// with the mean velocity over the gap, held to `C_v`, and the report says
/// so; the error then decays as from any start, below 1e-2 m/s within
/// 1000 samples.
#[test]
fn a_long_gap_gives_a_bounded_flagged_estimate() {
    for gap in [1.0, 1e6] {
        // samples up to 1 s, then none until 1 s + gap, then on
        let runs = example_1_stream(Vector2::zeros(), 4000, |k, q| {
            let t = k as f64 * 1e-3;
            match k {
                ..=1000 => Some((t, q)),
                1001..2000 => None,
                _ => Some((t + gap - 1.0, q)),
            }
        });
        for (which, run) in runs.iter().enumerate() {
            let (first, error) = &run[1000];
            let first = first.as_ref().unwrap();
            assert!(first.v.norm() <= 20.0, "{}", first.v);
            let recovered = run.iter().rposition(|r| r.1 >= 1e-2).unwrap() + 1 - 1000;
            eprintln!(
                "gap {gap:e} s ({}): first estimate |v̂| = {:.1}, |v − v̂| = {error:.1}; below 1e-2 after {recovered} samples",
                ["reduced", "full"][which],
                first.v.norm()
            );
            assert!(run.iter().all(|r| r.0.is_ok()));
            assert!(recovered <= 1000, "{recovered}");
        }
    }
    // the report says it
    let (model, u) = (Parabola::<f64>::new(), SVector::<f64, 0>::zeros());
    let (q0, _) = Parabola::<f64>::initial_state();
    let params = ObserverParams::new(10.0, 20.0);
    let mut ro = ReducedOrder::<f64, 2, 2>::new(params, 0.0, q0, Vector2::zeros()).unwrap();
    ro.update(&model, 1.0, &q0, &u).unwrap();
    assert_eq!(ro.report().restart, Some(Restart::LongInterval));
    ro.update(&model, 1.001, &q0, &u).unwrap();
    assert_eq!(ro.report().restart, None);
}

// ---------------------------------------------------------------------------
// Speeds above the velocity bound

/// `UpdateReport::at_velocity_bound` on Example 1 (the model file's start,
/// plant at `τ = 1e-5`, samples at 1 kHz, exact and with `σ = 1e-4`,
/// `v̂(0) = 0`), for (38), (36) and the saltation Kalman filter, each
/// told `σ`. With `C_v = 5` the mass moves faster than the bound for much
/// of the run (up to 12.3 m/s, sliding fast along the steep floor before
/// it settles): the estimates cannot follow (they are held to `C_v`, and
/// most samples are refused as farther than `C_v` lets the system move),
/// and the report must say so on every sample from 1 s on where the true
/// speed is above `1.25 C_v`, and on none where it is below `0.75 C_v`
/// (the samples that bracket a plant impact left out: the jump falls
/// between them). With `C_v = 20`, above every speed of the run, it is
/// never set. A sample refused as an outlier leaves the report of the
/// update before it.
#[test]
fn the_report_says_when_the_velocity_bound_holds_the_estimate() {
    let model = Parabola::<f64>::new();
    let u = SVector::<f64, 0>::zeros();
    let data = reference(&model, Parabola::<f64>::initial_state(), 1e-5, 100, 6.0, &u);
    let fastest = data.samples.iter().map(|s| s.v.norm()).fold(0.0, f64::max);
    assert!(fastest > 10.0 && fastest < 15.0, "{fastest}");
    let bracket = common::runs::brackets(&data);
    for (sigma, c_v) in [(0.0, 5.0), (1e-4, 5.0), (0.0, 20.0), (1e-4, 20.0)] {
        let measured = measure(&data, sigma, 3);
        let start = (measured[0], Vector2::zeros());
        let params = ObserverParams::new(10.0, c_v).with_noise(sigma);
        let flags = |o: &mut dyn Observer<Parabola<f64>, 2, 2>| -> Vec<bool> {
            let mut flags = vec![false];
            for (s, q) in data.samples.iter().zip(&measured).skip(1) {
                match o.update(&model, s.t, q, &u) {
                    Ok(_) | Err(ObserverError::Outlier { .. }) => {}
                    Err(e) => panic!("t = {}: {e:?}", s.t),
                }
                flags.push(o.report().at_velocity_bound);
            }
            flags
        };
        let kalman = KalmanParams::new(c_v, sigma);
        let runs = [
            (
                "(38)",
                flags(&mut ReducedOrder::new(params, 0.0, start.0, start.1).unwrap()),
            ),
            (
                "(36)",
                flags(
                    &mut FullOrder::new(
                        params,
                        FullOrderGains::scalar(5.0, 25.0),
                        0.0,
                        start.0,
                        start.1,
                    )
                    .unwrap(),
                ),
            ),
            (
                "filter",
                flags(
                    &mut SaltationKalman::<f64, 2, 2>::new(kalman, 0.0, start.0, start.1).unwrap(),
                ),
            ),
        ];
        for (name, flags) in runs {
            let at = format!("{name}, σ = {sigma:e}, C_v = {c_v}");
            let (mut above, mut set) = (0, 0);
            for ((s, &flag), &b) in data.samples.iter().zip(&flags).zip(&bracket) {
                let speed = s.v.norm();
                set += usize::from(flag);
                if s.t < 1.0 || b {
                    continue;
                }
                if speed > 1.25 * c_v {
                    above += 1;
                    assert!(flag, "{at}, t = {}: |v| = {speed}, not reported", s.t);
                }
                assert!(
                    speed >= 0.75 * c_v || !flag,
                    "{at}, t = {}: |v| = {speed}, reported",
                    s.t
                );
            }
            eprintln!(
                "{at}: {above} samples from 1 s on above 1.25 C_v, all reported; {set} updates at the bound in all"
            );
            if c_v == 20.0 {
                assert_eq!(set, 0, "{at}");
            } else {
                assert!(above >= 1000, "{at}: {above}");
            }
        }
    }
}
