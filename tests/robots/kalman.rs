//! The saltation Kalman filter on robots given as URDF, under noise: a UR5
//! with damped joints whose tool strikes a table, rests on it and swings
//! off it again (`examples/ur5_table.yaml`), a Franka Panda with a table
//! and walls (`tests/robots/panda.yaml`) and Unitree Go1's twelve leg
//! joints with the ground and walls under two feet
//! (`tests/robots/go1.yaml`), and once each the other robots of
//! `tests/robots/` (a two-link tree, arms with prismatic joints, joint
//! limits and constraints on body directions, a twelve-link chain). Each
//! runs from random starts on the plant (Moreau–Jean at `τ = 1e-5`), its
//! joint positions sampled at 1 kHz with Gaussian noise `σ = 1e-4` rad, `v̂(0) = 0`; the filter with its
//! defaults beside the reduced-order observer (38) (`l_d = 20`), both told
//! `σ`, scored over `[1, 3]` s against the plant's velocities.
//!
//! Nothing in the filter is written for these robots: the dynamics, the
//! constraint Jacobians and the derivatives its saltation matrices and
//! contact projections need come from the URDF through `model!`.

use crate::common::runs::{
    Gauss, Reference, Scored, brackets, measure, observe_counting, plant_candidates, reference,
    score,
};
use moreau::{
    KalmanParams, Model, ObserverParams, ReducedOrder, SaltationKalman, Sensitivities,
    pick_by_likelihood, tune_process_noise,
};
use nalgebra::SVector;
use std::sync::OnceLock;

use crate::{
    Go1, Panda, PandaFingers, PandaFingersFree, Serial12, SliderArmLimits, SliderArmMixed, So100,
    TwoLinkTree, Ur5Table,
};

const SIGMA: f64 = 1e-4;
const WINDOW: (f64, f64) = (1.0, 3.0);
/// The velocity bound told to both estimators: above every joint speed
/// the runs reach (asserted; the undamped Panda whips its wrist to 67
/// rad/s).
const VELOCITY_BOUND: f64 = 150.0;

/// One run of both estimators on one start.
struct Run {
    filter: Scored,
    observer: Scored,
    /// Restarts and samples refused (by the screen of physically
    /// impossible samples, `ObserverError::Outlier`), filter and (38).
    restarts: (usize, usize),
    refused: (usize, usize),
    /// Samples the filter's innovation gate skipped (`KalmanReport::outlier`:
    /// the update returns the prediction; not a refusal).
    skipped: usize,
    /// The median over the window (without the samples that bracket a
    /// plant impact) of the filter's velocity NEES `eᵀ P_vv⁻¹ e`.
    nees_median: f64,
    /// The median over the same samples, where the plant holds a contact
    /// (its gap under 1e-6), of the filter's normalised error squared of
    /// that gap, `(h_i(q̂) − h_i(q))² / J_i P_qq J_iᵀ` (`None` where the
    /// plant holds none).
    held_gap: Option<f64>,
}

/// Random starts of `model`: the first `first` if given, then joint
/// coordinates uniform in `[−range, range]` (rad, or m for a prismatic
/// joint) and speeds in `[−1, 1]` (seed 27182, none picked), every gap at
/// least 2 cm open.
fn starts<M, const N: usize, const K: usize>(
    model: &M,
    first: Option<(SVector<f64, N>, SVector<f64, N>)>,
    count: usize,
    range: f64,
) -> Vec<(SVector<f64, N>, SVector<f64, N>)>
where
    M: Model<N, K, Scalar = f64>,
{
    let mut g = Gauss::new(27182);
    let mut starts: Vec<_> = first.into_iter().collect();
    while starts.len() < count {
        let q = SVector::<f64, N>::from_fn(|_, _| range * (2.0 * g.uniform() - 1.0));
        let v = SVector::<f64, N>::from_fn(|_, _| 2.0 * g.uniform() - 1.0);
        if model.gaps(&q).iter().all(|&h| h >= 0.02) {
            starts.push((q, v));
        }
    }
    starts
}

/// The plant's run from `start` (Moreau–Jean at `τ = 1e-5`, every
/// hundredth state kept: 1 kHz), checked against the velocity bound.
fn plant_run<M, const N: usize, const K: usize>(
    model: &M,
    start: (SVector<f64, N>, SVector<f64, N>),
) -> Reference<N>
where
    M: Model<N, K, Scalar = f64, Input: Default> + std::fmt::Debug + 'static,
{
    let data = reference(model, start, 1e-5, 100, WINDOW.1, &M::Input::default());
    let fastest = data.samples.iter().map(|s| s.v.amax()).fold(0.0, f64::max);
    assert!(
        fastest < VELOCITY_BOUND,
        "{}: {fastest} rad/s",
        M::INFO.name
    );
    data
}

/// The plant's run from the Panda's start `n` of four, made once for the
/// two tests that score the filter on it (each run takes about 10 s).
fn panda_run(n: usize) -> &'static Reference<7> {
    static RUNS: [OnceLock<Reference<7>>; 4] = [const { OnceLock::new() }; 4];
    RUNS[n].get_or_init(|| {
        let panda = Panda::<f64>::new();
        plant_run::<_, 7, 6>(&panda, starts::<_, 7, 6>(&panda, None, 4, 1.5)[n])
    })
}

/// Both estimators on the plant's run `data`, measured with the noise seed
/// `seed`, the filter with the default knobs.
fn run<M, const N: usize, const K: usize>(model: &M, data: &Reference<N>, seed: u64) -> Run
where
    M: Sensitivities<N, K, Scalar = f64, Input: Default>,
{
    run_with(model, data, seed, KalmanParams::new(VELOCITY_BOUND, SIGMA))
}

/// [`run`] with the filter's knobs `params`.
fn run_with<M, const N: usize, const K: usize>(
    model: &M,
    data: &Reference<N>,
    seed: u64,
    params: KalmanParams<f64, N>,
) -> Run
where
    M: Sensitivities<N, K, Scalar = f64, Input: Default>,
{
    let u = M::Input::default();
    let measured = measure(data, SIGMA, seed);
    let bracket = brackets(data);
    let mut filter =
        SaltationKalman::<f64, N, K>::new(params, 0.0, measured[0], SVector::zeros()).unwrap();
    let mut nees = Vec::new();
    let mut gaps = Vec::new();
    let mut skipped = 0;
    let (estimates, f_restarts, f_refused) =
        observe_counting(&mut filter, model, (data, &measured), &u, |j, f| {
            skipped += usize::from(f.kalman_report().outlier);
            let s = &data.samples[j];
            if s.t >= WINDOW.0 && !bracket[j] {
                let q = f.estimate().q;
                let (plant, estimate) = (model.gaps(&s.q), model.gaps(&q));
                let jac = model.gap_jacobian(&q);
                for i in (0..K).filter(|&i| plant[i] < 1e-6) {
                    let row = jac.row(i);
                    let variance = (row * f.covariance().qq).dot(&row);
                    gaps.push((estimate[i] - plant[i]).powi(2) / variance);
                }
                let e = s.v - f.estimate().v;
                let chol = f
                    .covariance()
                    .vv
                    .cholesky()
                    .expect("P_vv positive definite");
                nees.push(e.dot(&chol.solve(&e)));
            }
        });
    let filter_scored = score(data, &estimates, WINDOW);
    let mut observer = ReducedOrder::<f64, N, K>::new(
        ObserverParams::new(20.0, VELOCITY_BOUND).with_noise(SIGMA),
        0.0,
        measured[0],
        SVector::zeros(),
    )
    .unwrap();
    let (estimates, o_restarts, o_refused) =
        observe_counting(&mut observer, model, (data, &measured), &u, |_, _| {});
    nees.sort_by(f64::total_cmp);
    gaps.sort_by(f64::total_cmp);
    Run {
        filter: filter_scored,
        observer: score(data, &estimates, WINDOW),
        restarts: (f_restarts, o_restarts),
        refused: (f_refused, o_refused),
        skipped,
        nees_median: nees[nees.len() / 2],
        held_gap: gaps.get(gaps.len() / 2).copied(),
    }
}

/// One line per run: both estimators' figures, the filter's NEES, the
/// restarts and refusals.
fn print(name: &str, n: usize, r: &Run) {
    eprintln!(
        "{name}, start {n}: filter median {:.2e} p90 {:.2e} max off the brackets {:.2e}, velocity NEES median {:.2}, restarts {} refused {} skipped by its gate {}; (38) median {:.2e} p90 {:.2e} max off the brackets {:.2e}, restarts {} refused {}",
        r.filter.all.median,
        r.filter.all.p90,
        r.filter.clean.max,
        r.nees_median,
        r.restarts.0,
        r.refused.0,
        r.skipped,
        r.observer.all.median,
        r.observer.all.p90,
        r.observer.clean.max,
        r.restarts.1,
        r.refused.1,
    );
}

/// No restart of either estimator, at most one sample refused by each
/// (refused: a sample farther than `C_v` lets the system move,
/// `ObserverError::Outlier`), and the filter's median at least `factor`
/// times below (38)'s. The samples the filter's innovation gate skips are
/// printed, not asserted (measured: 3 on the Panda's start 1 with the
/// defaults, none on any other run).
fn assert_steady_and_ahead(at: &str, r: &Run, factor: f64) {
    assert_eq!(r.restarts, (0, 0), "{at}");
    assert!(
        r.refused.0 <= 1 && r.refused.1 <= 1,
        "{at}: {:?}",
        r.refused
    );
    assert!(
        factor * r.filter.all.median <= r.observer.all.median,
        "{at}: {:e} against (38)'s {:e}",
        r.filter.all.median,
        r.observer.all.median
    );
}

/// The robots other than the UR5: the run printed, [`assert_steady_and_ahead`]
/// with a factor of five, and the filter within the 0.1 off the
/// bracketing samples.
fn check(name: &str, n: usize, r: &Run) {
    print(name, n, r);
    let at = format!("{name}, start {n}");
    assert_steady_and_ahead(&at, r, 5.0);
    assert!(r.filter.clean.max <= 0.1, "{at}: {:e}", r.filter.clean.max);
}

/// The χ² median with `n` degrees of freedom (Wilson–Hilferty).
fn chi_square_median(n: usize) -> f64 {
    let c = 2.0 / (9.0 * n as f64);
    n as f64 * (1.0 - c).powi(3)
}

/// A UR5 whose tool strikes a table, bounces, rests and slides on it, and
/// swings off it again as the arm moves (the model file's start and five
/// random ones; 7 to 12 plant impacts each).
///
/// The tool's contact force runs out inside a sampling interval when the
/// arm lifts it off; the filter's prediction lifts off with it (the
/// interval holds a contact at acceleration level), but the filter then
/// projected the end of the piece onto the contact manifold, which took
/// the separating speed back out and, the covariance projected with it,
/// left the joint velocities 2.2e-4 rad/s off while the filter claimed
/// 3.1e-5, for hundreds of milliseconds. Medians were 1.7e-5 to 6.5e-5
/// and the velocity NEES median up to 19 (6 joints) on these six runs;
/// now the end is projected only onto the contacts it still lies on
/// (module docs of `runtime/src/observer/kalman/propagate.rs`, `lifted`).
///
/// Asserted on every run: no restart and at most one sample refused (by
/// the physical screen; the filter's innovation gate skipped none on
/// these runs, printed); the issue's
/// Example 1 targets, median at most 3e-5 rad/s and at most 1e-2 off the
/// samples that bracket a plant impact; the median at least twenty times
/// below (38)'s (the factor by which the hand-written Python
/// saltation filter beat (38)); and the covariance not overconfident on
/// the typical sample: the velocity NEES median at most the χ² median
/// with 6 degrees of freedom (5.35).
#[test]
fn the_filter_follows_a_ur5_onto_and_off_a_table() {
    let model = Ur5Table::<f64>::new();
    let starts = starts::<_, 6, 1>(&model, Some(Ur5Table::<f64>::initial_state()), 6, 1.5);
    for (n, &start) in starts.iter().enumerate() {
        let r = run::<_, 6, 1>(&model, &plant_run::<_, 6, 1>(&model, start), 7 + n as u64);
        print("UR5 on a table", n, &r);
        let at = format!("start {n}");
        assert_steady_and_ahead(&at, &r, 20.0);
        assert!(
            r.filter.all.median <= 3e-5,
            "{at}: {:e}",
            r.filter.all.median
        );
        assert!(r.filter.clean.max <= 1e-2, "{at}: {:e}", r.filter.clean.max);
        assert!(
            r.nees_median <= chi_square_median(6),
            "{at}: NEES median {}",
            r.nees_median
        );
    }
}

/// The UR5 of [`the_filter_follows_a_ur5_onto_and_off_a_table`] with a
/// plastic table (`e = 0`, set on the model's `restitution`), on the same
/// starts and noise: every strike stops the tool, which the plant then
/// holds where its step left it, inside the table by up to `τ |ḣ|` (3.2e-5
/// m at 3.4 m/s), while the arm slides it along and off.
///
/// The filter holds a struck contact at a level the samples teach (module
/// docs of `runtime/src/observer/kalman/level.rs`). Its covariance once
/// held the state on that level with no variance across it: it claimed
/// the tool's gap to 7e-11 m while its level was 1e-6 m off the plant's
/// (the gap's normalised error squared, median over the held samples, 1.2e7
/// to 3.2e8 on these runs told the plant's step), and the claim went on
/// into the flight after lift-off: velocity NEES medians 4.2 to 25 with the
/// defaults. The level's variance was then put into `P` afresh at each
/// projection, uncorrelated with the state (gap medians 0.05 to 2.4 told
/// the plant), which left the velocity NEES medians at 2.4 to 11.6 with
/// the defaults and 1.9 to 22 told the plant, and the medians at 2.1e-5
/// to 5.9e-5 rad/s: where the arm slides the tool at 10 to 21 rad/s, a
/// level that is off bends every prediction along the slide the same way,
/// which an error drawn afresh at each interval does not describe. The
/// level is now a state of the filter, its correlation with `(q, v)`
/// carried through the prediction and the update (module docs of
/// `level.rs`, "A level is a state"): NEES medians 0.9 to 3.6 with the
/// defaults and 0.8 to 2.6 told the plant, medians 1.3e-5 to 3.6e-5 and
/// 1.1e-5 to 2.9e-5.
///
/// Asserted on every run, told the plant's step (`with_plant_step`: the
/// level's prior is then the plant's penetration): the held gap's
/// normalised error squared `(h(q̂) − h(q))² / J P_qq Jᵀ`, median over the
/// samples where the plant holds the tool (its gap under 1e-6 m, off the
/// bracketing samples), within the 99th percentile of χ² with one degree
/// of freedom (6.63: a consistent filter's median is 0.455, and the claim
/// without the level's variance missed the bound by six orders); the
/// velocity NEES median within the χ² median with 6 degrees of freedom
/// (5.35; 7.3 and 22 on starts 2 and 3 before the level was a state) and
/// the median of at most 3e-5 rad/s (4.3e-5 and 7.5e-5 on starts
/// 5 and 3 before); no restart and at most one sample refused; the
/// filter's median at least five times below (38)'s. With the defaults,
/// the velocity NEES median within the same 5.35 (8.4, 7.1 and 11.6 on
/// starts 2, 3 and 5 before), and on the plant's exact positions the
/// issue's median of at most 1e-8 (measured 9.1e-10 to 4.7e-9; 1.5e-8 and
/// 2.6e-8 on two starts while the deepest level was three deviations of
/// the impact's timing, module docs of `level.rs`). Printed, not
/// asserted: the defaults' median (over 3e-5 on start 5, 3.6e-5) and held
/// gap, whose timing prior (impacts on time within 3 µs) puts one plant's
/// penetration at 3.1 of its deviations (start 4: gap median 9.1).
#[test]
fn the_filter_follows_a_plastic_ur5_onto_and_off_a_table() {
    let mut model = Ur5Table::<f64>::new();
    model.restitution[0] = 0.0;
    let starts = starts::<_, 6, 1>(&model, Some(Ur5Table::<f64>::initial_state()), 6, 1.5);
    for (n, &start) in starts.iter().enumerate() {
        let data = plant_run::<_, 6, 1>(&model, start);
        let seed = 7 + n as u64;
        let r = run(&model, &data, seed);
        print("plastic UR5", n, &r);
        if let Some(gaps) = r.held_gap {
            eprintln!(
                "plastic UR5, start {n}: held gap's normalised error squared, median {gaps:.3}"
            );
        }
        assert!(
            r.nees_median <= chi_square_median(6),
            "plastic UR5, start {n}: NEES median {}",
            r.nees_median
        );
        let params = KalmanParams::new(VELOCITY_BOUND, SIGMA).with_plant_step(1e-5);
        let told = run_with(&model, &data, seed, params);
        print("plastic UR5 told the plant", n, &told);
        let gaps = told.held_gap.expect("the plant holds the tool");
        eprintln!(
            "plastic UR5 told the plant, start {n}: held gap's normalised error squared, median {gaps:.3}"
        );
        let at = format!("plastic UR5, start {n}, told the plant");
        assert_steady_and_ahead(&at, &told, 5.0);
        assert!(gaps <= 6.63, "{at}: {gaps}");
        assert!(
            told.nees_median <= chi_square_median(6),
            "{at}: NEES median {}",
            told.nees_median
        );
        assert!(
            told.filter.all.median <= 3e-5,
            "{at}: {:e}",
            told.filter.all.median
        );
        let exact = exact_sample_median(&model, &data);
        eprintln!("plastic UR5, start {n}: on exact samples, median {exact:.2e}");
        assert!(
            exact <= 1e-8,
            "plastic UR5, start {n}, exact samples: {exact:e}"
        );
    }
}

/// The filter's median error over the window on the plant's exact
/// positions (`σ = 0`), with the defaults.
fn exact_sample_median<M, const N: usize, const K: usize>(model: &M, data: &Reference<N>) -> f64
where
    M: Sensitivities<N, K, Scalar = f64, Input: Default>,
{
    let exact = measure(data, 0.0, 0);
    let params = KalmanParams::new(VELOCITY_BOUND, 0.0);
    let mut filter =
        SaltationKalman::<f64, N, K>::new(params, 0.0, exact[0], SVector::zeros()).unwrap();
    let u = M::Input::default();
    let (estimates, _, _) = observe_counting(&mut filter, model, (data, &exact), &u, |_, _| {});
    score(data, &estimates, WINDOW).all.median
}

/// A Franka Panda (seven joints, no damping: its wrist whips up to 67
/// rad/s) and Go1's legs (twelve joints, six constraints), four and three
/// random starts.
///
/// Asserted on every run: no restart and at most one sample refused by
/// either estimator's physical screen (the filter's innovation gate
/// skipped three samples on the Panda's start 1, none elsewhere;
/// printed); the filter's median at least five times below (38)'s
/// (measured: 8 to 45 times), and off the bracketing samples within the
/// issue's 0.1 ((38), printed, up to 9.6e-2). The filter's largest, 2.0e-2
/// and 2.2e-2 on Go1, are each at the first sample after a foot met the
/// ground slower than the 1 cm/s from which the reference counts an
/// impact (start 0: at 0.6 mm/s, then resting on it), so no bracket is
/// left out there; at the next sample the filter is 7e-5 and 1e-3 off.
///
/// Printed, not asserted: the filter's velocity NEES. With the default
/// process noise it is above the χ² median on these fast runs (6.7 to 40
/// for the Panda's 7 joints, 9.5 to 81 for Go1's 12): the defaults
/// describe a model as right as a fine simulation is.
/// Knobs picked by `tune_process_noise` from one record of the Panda
/// bring its NEES median under the χ² median on the other starts
/// (`process_noise_tuned_on_one_panda_record_holds_on_others`).
///
/// Told the plant (`KalmanParams::with_plant_step`: the filter takes the
/// plant's own Moreau–Jean step of 10 µs at each impact instead of an
/// exact impact), the same runs again: asserted, the velocity NEES median
/// within 1.5 times the χ² median and the median error no larger than
/// with the defaults, on every run. Measured: NEES medians 4.3 to 6.4 on
/// the Panda (χ² median 6.35) and 8.1 to 8.5 on Go1 (11.3); median
/// errors 1.2e-4 to 3.0e-4 on the Panda and 1.1e-4 to 1.9e-4 on Go1 (the
/// filter keeps the plant's likely steps apart at some of Go1's impacts,
/// `KalmanParams::plant_step_mixture`; as one Gaussian its NEES medians
/// were 8.3 to 8.6).
/// What the defaults' covariance missed on these fast runs was the
/// plant's step at the impacts (module docs of
/// `runtime/src/observer/kalman/propagate.rs`, "A time-stepping plant").
#[test]
fn the_filter_follows_a_panda_and_go1s_legs() {
    fn told_the_plant<M, const N: usize, const K: usize>(
        name: &str,
        model: &M,
        (n, data): (usize, &Reference<N>),
        defaults: &Run,
    ) where
        M: Sensitivities<N, K, Scalar = f64, Input: Default>,
    {
        let params = KalmanParams::new(VELOCITY_BOUND, SIGMA).with_plant_step(1e-5);
        let r = run_with::<_, N, K>(model, data, 7 + n as u64, params);
        print(&format!("{name} told the plant"), n, &r);
        let at = format!("{name}, start {n}, told the plant");
        assert_steady_and_ahead(&at, &r, 5.0);
        assert!(
            r.nees_median <= 1.5 * chi_square_median(N),
            "{at}: NEES median {}",
            r.nees_median
        );
        assert!(
            r.filter.all.median <= defaults.filter.all.median,
            "{at}: {:e} against {:e}",
            r.filter.all.median,
            defaults.filter.all.median
        );
    }
    let panda = Panda::<f64>::new();
    for n in 0..4 {
        let defaults = run::<_, 7, 6>(&panda, panda_run(n), 7 + n as u64);
        check("Panda", n, &defaults);
        told_the_plant::<_, 7, 6>("Panda", &panda, (n, panda_run(n)), &defaults);
    }
    let go1 = Go1::<f64>::new();
    for (n, &start) in starts::<_, 12, 6>(&go1, None, 3, 1.5).iter().enumerate() {
        let data = plant_run::<_, 12, 6>(&go1, start);
        let defaults = run::<_, 12, 6>(&go1, &data, 7 + n as u64);
        check("Go1", n, &defaults);
        told_the_plant::<_, 12, 6>("Go1", &go1, (n, &data), &defaults);
    }
}

/// The other robots of `tests/robots/`, one random start each, with the
/// filter's defaults: a two-link tree written in YAML bodies (a tip on a
/// floor), an arm with two prismatic joints and joint limits on a table
/// (`slider_arm_limits.yaml`; starts within ±0.5), the same arm with a
/// locked joint, a YAML body, tilted gravity and constraints on body
/// directions (`slider_arm_mixed.yaml`), a twelve-link serial chain
/// whose tip and middle strike six walls (`serial_12.yaml`), the SO-100
/// arm (`so100.yaml`, a link and a joint both called `gripper`), and the
/// Panda with its fingers as the URDF has them, the second mimicking the
/// first, within their limits (`panda_fingers.yaml`: the arm from the
/// Panda's first start, the fingers half open).
/// Nothing in the filter or in this test was tuned on them.
///
/// Asserted on every run, as on the Panda and Go1: no restart and at most
/// one sample refused by either estimator, the filter's median at least
/// five times below (38)'s (measured: 16 to 230 times) and within 0.1 off
/// the bracketing samples (measured: at most 4.0e-3). (38) itself, printed,
/// is 0.18 off there on the chain.
#[test]
fn the_filter_follows_the_other_robots() {
    fn once<M, const N: usize, const K: usize>(model: &M, range: f64)
    where
        M: Sensitivities<N, K, Scalar = f64, Input: Default> + std::fmt::Debug + 'static,
    {
        let data = plant_run::<_, N, K>(model, starts::<_, N, K>(model, None, 1, range)[0]);
        check(M::INFO.name, 0, &run::<_, N, K>(model, &data, 7));
    }
    once::<_, 2, 2>(&TwoLinkTree::<f64>::new(), 1.5);
    once::<_, 4, 5>(&SliderArmLimits::<f64>::new(), 0.5);
    once::<_, 5, 6>(&SliderArmMixed::<f64>::new(), 0.5);
    once::<_, 12, 6>(&Serial12::<f64>::new(), 1.0);
    once::<_, 6, 6>(&So100::<f64>::new(), 1.5);
    // the Panda's arm from its starts, its fingers half open and at rest
    let gripper = PandaFingers::<f64>::new();
    let panda = Panda::<f64>::new();
    let (arm, speed) = starts::<_, 7, 6>(&panda, None, 1, 1.5)[0];
    let start = (
        SVector::<f64, 8>::from_fn(|i, _| arm.get(i).copied().unwrap_or(0.02)),
        SVector::<f64, 8>::from_fn(|i, _| speed.get(i).copied().unwrap_or(0.0)),
    );
    let data = plant_run::<_, 8, 8>(&gripper, start);
    check("PandaFingers", 0, &run::<_, 8, 8>(&gripper, &data, 7));
}

/// The Panda's fingers free of their limits (`panda_fingers_free.yaml`):
/// the fingers slide through each other and out of the hand, and with the
/// hand tilted the one finger coordinate lifts one fingertip while it
/// lowers the other, so the two table contacts are a thin wedge (light
/// fingers: gradients nearly opposite in the metric of `M`). Four starts:
/// the arm's joints uniform in ±1.5 rad and speeds in ±1 rad/s (seed
/// 27182), the fingers 2 cm open and at rest, every gap at least 2 cm
/// open.
///
/// On start 3 one fingertip strikes the table at 2.0872 s, at 2.9 m/s,
/// while the other rests on it: one at a time (the opposed gradients'
/// rule) the striking one bounced, the resting one's closure drove it in
/// again at 2.56 m/s, and, met once at that point already, it was held as
/// a persistent contact while approaching. (On another start a fingertip
/// that had just bounced was driven in again by the other's impulse at
/// the same point, and held the same way.) The prediction flew it 2 mm
/// into the table, and the filter was 45 rad/s off the bracketing
/// samples, (38) 18. Both are now one law on the pair (module docs of `runtime/src/observer/mod.rs`, the
/// contact rule): 6.3e-3 and 0.135.
///
/// Asserted on every start: no restart and at most one sample refused by
/// either estimator; on start 3, the filter within 1e-2 off the bracketing
/// samples and (38) within 0.2. Printed, not asserted: start 2 is still
/// 0.58 rad/s off (the filter) and 0.54 ((38)), after fingertips that
/// alternate bounces in the wedge, tens in a millisecond, faster than the
/// plant's step; with the fingers' limits as the URDF gives them (the
/// other robots' test) none of this happens.
#[test]
fn fingertips_striking_a_table_together_take_one_law() {
    let model = PandaFingersFree::<f64>::new();
    let mut g = Gauss::new(27182);
    let mut starts = Vec::new();
    while starts.len() < 4 {
        let q = SVector::<f64, 7>::from_fn(|_, _| 1.5 * (2.0 * g.uniform() - 1.0));
        let v = SVector::<f64, 7>::from_fn(|_, _| 2.0 * g.uniform() - 1.0);
        let q = SVector::<f64, 8>::from_fn(|i, _| q.get(i).copied().unwrap_or(0.02));
        let v = SVector::<f64, 8>::from_fn(|i, _| v.get(i).copied().unwrap_or(0.0));
        if model.gaps(&q).iter().all(|&h| h >= 0.02) {
            starts.push((q, v));
        }
    }
    for (n, &start) in starts.iter().enumerate() {
        let r = run::<_, 8, 6>(&model, &plant_run::<_, 8, 6>(&model, start), 7);
        print("PandaFingersFree", n, &r);
        let at = format!("start {n}");
        assert_eq!(r.restarts, (0, 0), "{at}");
        assert!(
            r.refused.0 <= 1 && r.refused.1 <= 1,
            "{at}: {:?}",
            r.refused
        );
        if n == 3 {
            assert!(r.filter.clean.max <= 1e-2, "{at}: {:e}", r.filter.clean.max);
            assert!(
                r.observer.clean.max <= 0.2,
                "{at}: (38) {:e}",
                r.observer.clean.max
            );
        }
    }
}

/// The likelihood helper on a robot: `tune_process_noise` picks the
/// filter's knobs from one recorded run of the Panda (its first random
/// start, noise seed 1000: 3 s at 1 kHz, σ = 1e-4 rad, `v̂(0) = 0`), and
/// the filter runs with them on the other three starts (their own noise
/// seeds, as in `the_filter_follows_a_panda_and_go1s_legs`).
///
/// With the defaults the velocity NEES median on those three is 39.7, 6.7
/// and 18.2 against the χ² median of 6.35 for 7 joints: the filter claims
/// more than it knows on an undamped arm whipping at up to 67 rad/s. The
/// record asks for more acceleration noise (2.7 times), more impact noise
/// (11 times) and a mean impact delay of 2.3 µs.
///
/// Asserted on each held-out start: no restart; the NEES median at most
/// the χ² median and at least a fifth of it (an overcautious filter would
/// pass the first bound alone; measured 3.9 to 5.9); and the median error
/// no more than 1.2 times the defaults' (measured: 0.61 to 1.0 times).
#[test]
fn process_noise_tuned_on_one_panda_record_holds_on_others() {
    let panda = Panda::<f64>::new();
    let u = SVector::zeros();
    let record = panda_run(0);
    let measured = measure(record, SIGMA, 1000);
    let t: Vec<f64> = record.samples.iter().map(|s| s.t).collect();
    let tuned = tune_process_noise::<_, _, 7, 6>(
        &panda,
        KalmanParams::new(VELOCITY_BOUND, SIGMA),
        &t,
        &measured,
        &SVector::zeros(),
        &u,
        (-4.0, 4.0),
    )
    .unwrap();
    eprintln!(
        "tuned on one Panda record: {:?}, log-likelihood {:.1}, {} runs",
        tuned.factors, tuned.log_likelihood, tuned.evaluations
    );
    let median = chi_square_median(7);
    for n in 1..4 {
        let defaults = run::<_, 7, 6>(&panda, panda_run(n), 7 + n as u64);
        let r = run_with::<_, 7, 6>(&panda, panda_run(n), 7 + n as u64, tuned.params);
        eprintln!(
            "Panda, start {n}: NEES median {:.2} tuned, {:.2} with the defaults; median error {:.2e} tuned, {:.2e} with the defaults",
            r.nees_median, defaults.nees_median, r.filter.all.median, defaults.filter.all.median
        );
        let at = format!("start {n}");
        assert_eq!(r.restarts.0, 0, "{at}");
        assert!(
            r.nees_median <= median && r.nees_median >= median / 5.0,
            "{at}: NEES median {}",
            r.nees_median
        );
        assert!(
            r.filter.all.median <= 1.2 * defaults.filter.all.median,
            "{at}: {:e} against {:e}",
            r.filter.all.median,
            defaults.filter.all.median
        );
    }
}

/// Which plant made the Panda's samples, picked from each of its four
/// records by the innovation likelihood ([`pick_by_likelihood`]; the
/// same candidates as Example 1's test in `tests/kalman.rs`, without
/// Siconos's law): no plant, the crate's law at 5, 10 and 20 µs on the
/// samples' grid, and 10 µs off it. Asserted: the plant's own step on
/// its grid, by more than a nat, on a robot whose forces depend on the
/// velocity, so its plant's error at an impact has another shape than
/// Example 1's. Measured: 1.8 to 9.6 nats on these 3 s records (Example
/// 1's 10 s records: 2.4 to 16).
///
/// `cargo test --release --test robots -- --nocapture picks_the_panda`
#[test]
fn the_likelihood_picks_the_pandas_plant() {
    let panda = Panda::<f64>::new();
    let u = SVector::zeros();
    let candidates = plant_candidates(KalmanParams::new(VELOCITY_BOUND, SIGMA));
    let params = candidates.map(|(_, p)| p);
    for n in 0..4 {
        let record = panda_run(n);
        let measured = measure(record, SIGMA, 7 + n as u64);
        let t: Vec<f64> = record.samples.iter().map(|s| s.t).collect();
        let picked =
            pick_by_likelihood::<_, _, 7, 6>(&panda, &params, &t, &measured, &SVector::zeros(), &u)
                .unwrap();
        let at = format!(
            "Panda, start {n}: picked {} by {:.1} nats",
            candidates[picked.index].0, picked.margin
        );
        eprintln!("{at}");
        assert!(picked.index == 2 && picked.margin > 1.0, "{at}");
    }
}
