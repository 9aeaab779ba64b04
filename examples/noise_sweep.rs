//! Measurement noise: Example 1 observed through positions with Gaussian
//! noise of standard deviation σ, sampled every 0.5, 1, 2 or 5 ms. The
//! reduced-order observer (l_d = 10, told σ) settles at an error that grows
//! linearly with σ, about 2 l_d σ, and hardly depends on the sampling
//! period: each sample injects `l_d` times a noise difference of size σ,
//! and the observer forgets it at the rate `l_d`, so the variance it keeps,
//! `l_d² σ² / (l_d T_s) · T_s`, does not involve `T_s`.
//!
//! Then, side by side on the same noisy runs (σ from 1e-6 to 1e-3, 1 kHz),
//! one table and one figure per system: finite differences of the
//! samples, the reduced-order observer (38), the full-order observer (36)
//! and the saltation Kalman filter, on Example 1 from three initial states
//! (the model file's accumulates at 4.456 s and then slides), the three
//! balls and the double pendulum. The filter runs three times: with its
//! default process noise (`KalmanParams::new`), with the process noise
//! picked once per system by `tune_process_noise` from a run with σ = 1e-4
//! and its own noise seed (its first 3 s), and with the defaults told that
//! the samples come from the plant's Moreau–Jean step
//! (`KalmanParams::with_plant_step`); every σ adds its own noise to one
//! plant run.
//!
//! `cargo run --release --example noise_sweep`

mod support;

use moreau::{
    FullOrder, FullOrderGains, KalmanParams, ObserverParams, ReducedOrder, SaltationKalman,
    Sensitivities, tune_process_noise,
};
use moreau_models::{DoublePendulum, Parabola, ThreeBalls};
use nalgebra::{SMatrix, SVector, Vector2};
use plotters::style::full_palette::{
    BLUE_700, GREEN_700, GREY_700, ORANGE_800, PURPLE_700, RED_600,
};
use support::observe::{quantile, run, window};
use support::plot::{Panel, Result, Series, announce, csv, figure};
use support::reference::{Gaussian, Reference};
use support::reference::{Sampling, sample};

const T_END: f64 = 10.0;
/// The plant's step: every run here is `MoreauJean` at 10 µs.
const PLANT_STEP: f64 = 1e-5;

fn main() -> Result<()> {
    let model = Parabola::<f64>::default();
    let (q0, v0) = Parabola::<f64>::initial_state();
    let sigmas = [1e-6, 1e-5, 1e-4, 1e-3];
    let periods = [0.5e-3, 1e-3, 2e-3, 5e-3];
    println!(
        "Example 1 with noisy positions: median |v − v̂| over t ∈ [2, 10] s, reduced-order observer, l_d = 10"
    );
    println!();
    print!("  σ \\ T_s  ");
    for p in periods {
        print!("  {:>9}", format!("{} ms", p * 1e3));
    }
    println!();
    let mut rows = Vec::new();
    for (i, &sigma) in [0.0].iter().chain(&sigmas).enumerate() {
        print!("  {sigma:8.0e}");
        let mut row = vec![sigma];
        for &period in &periods {
            let reference = sample::<_, 2, 2, 0>(
                &model,
                q0,
                v0,
                Sampling::new(PLANT_STEP, period, T_END).with_noise(sigma, 7 + i as u64),
            )?;
            let params = ObserverParams::new(10.0, 20.0).with_noise(sigma);
            let mut observer =
                ReducedOrder::new(params, 0.0, reference.measured[0], Vector2::zeros())?;
            let estimates = run::<_, _, 2, 2, 0>(&model, &mut observer, &reference)?;
            let median = quantile(&window(&reference.t, &estimates.error, 2.0, T_END), 0.5);
            print!("  {median:9.2e}");
            row.push(median);
        }
        println!();
        rows.push(row);
    }
    let colors = [RED_600, ORANGE_800, GREEN_700, BLUE_700];
    let series = periods
        .iter()
        .enumerate()
        .map(|(j, p)| {
            let points = rows
                .iter()
                .skip(1)
                .map(|r| (r[0].log10(), r[j + 1]))
                .collect();
            Series::line(&format!("T_s = {} ms", p * 1e3), colors[j], points)
        })
        .collect();
    let [png, svg] = figure(
        "noise_sweep",
        "Measurement noise: median error of the reduced-order observer (Example 1)",
        "log10 σ [m]",
        &[Panel::new("median |v − v̂| over [2, 10] s", series).log()],
    )?;
    let mut header = vec!["sigma".to_string()];
    header.extend(
        periods
            .iter()
            .map(|p| format!("median_error_Ts_{}ms", p * 1e3)),
    );
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    let data = csv("noise_sweep", &header, rows)?;
    announce(&[&png, &svg, &data]);

    // side by side: finite differences, (38), (36), the saltation Kalman filter
    let parabola = Parabola::<f64>::default();
    side_by_side::<_, 2, 2>(
        "parabola_a",
        "Example 1, the model file's start (accumulates, slides)",
        &parabola,
        Parabola::<f64>::initial_state(),
        20.0,
    )?;
    side_by_side::<_, 2, 2>(
        "parabola_b",
        "Example 1 from (−1, 3), v = (−2, 5)",
        &parabola,
        (Vector2::new(-1.0, 3.0), Vector2::new(-2.0, 5.0)),
        20.0,
    )?;
    side_by_side::<_, 2, 2>(
        "parabola_c",
        "Example 1 from (0.5, 6), v = (4, 0)",
        &parabola,
        (Vector2::new(0.5, 6.0), Vector2::new(4.0, 0.0)),
        20.0,
    )?;
    side_by_side::<_, 3, 4>(
        "three_balls",
        "The three balls",
        &ThreeBalls::<f64>::default(),
        ThreeBalls::<f64>::initial_state(),
        10.0,
    )?;
    side_by_side::<_, 2, 2>(
        "double_pendulum",
        "The double pendulum",
        &DoublePendulum::<f64>::default(),
        DoublePendulum::<f64>::initial_state(),
        50.0,
    )?;
    Ok(())
}

/// The estimators of the side-by-side tables, in their columns' order.
const ESTIMATORS: [&str; 6] = [
    "finite differences",
    "reduced (38)",
    "full (36)",
    "Kalman, defaults",
    "Kalman, tuned",
    "Kalman, plant step",
];

/// Median `|v − v̂|` over `[2, T_END]` s of each estimator on the same noisy
/// run, for each σ: a table on stdout, a figure and a CSV file.
fn side_by_side<M, const N: usize, const K: usize>(
    stem: &str,
    title: &str,
    model: &M,
    (q0, v0): (SVector<f64, N>, SVector<f64, N>),
    velocity_bound: f64,
) -> Result<()>
where
    M: Sensitivities<N, K, Scalar = f64, Input = SVector<f64, 0>>,
{
    let u = SVector::<f64, 0>::zeros();
    let sigmas = [1e-6, 1e-5, 1e-4, 1e-3];
    let period = 1e-3;
    // one plant run; each σ adds its own seeded noise to the same positions
    let exact = sample::<_, N, K, 0>(model, q0, v0, Sampling::new(PLANT_STEP, period, T_END))?;
    let noisy = |sigma: f64, seed: u64| {
        let mut gauss = Gaussian::new(seed);
        let measured = exact
            .q
            .iter()
            .map(|q| q + SVector::from_fn(|_, _| sigma * gauss.next()))
            .collect();
        Reference {
            t: exact.t.clone(),
            q: exact.q.clone(),
            v: exact.v.clone(),
            measured,
            impacts: Vec::new(),
        }
    };
    // the filter's process noise, from the first 3 s of the run with
    // σ = 1e-4 and a noise seed of its own
    let training = noisy(1e-4, 99);
    let first = training.t.iter().take_while(|&&t| t <= 3.0).count();
    let tuned = tune_process_noise::<_, _, N, K>(
        model,
        KalmanParams::new(velocity_bound, 1e-4),
        &training.t[..first],
        &training.measured[..first],
        &SVector::zeros(),
        &u,
        (-4.0, 2.0),
    )?;
    let knobs = tuned.params;
    println!();
    println!(
        "{title}: median |v − v̂| over t ∈ [2, {T_END}] s, 1 kHz (filter: q_a = {:.2e}, ρ_i = {:.2e}, σ_t = {:.2e}, δ̄ = {:.2e}, ρ_c = {:.2e} from 3 s of one σ = 1e-4 run)",
        knobs.accel_noise[0],
        knobs.impact_noise,
        knobs.impact_time_sigma,
        knobs.impact_delay,
        knobs.contact_noise
    );
    print!("  {:>8}", "σ");
    for name in ESTIMATORS {
        print!("  {name:>18}");
    }
    println!();
    let mut rows = Vec::new();
    for (i, &sigma) in sigmas.iter().enumerate() {
        let reference = noisy(sigma, 31 + i as u64);
        let medians = estimate_all::<M, N, K>(model, &reference, sigma, velocity_bound, &knobs)?;
        print!("  {sigma:8.0e}");
        for m in &medians {
            print!("  {m:18.2e}");
        }
        println!();
        let mut row = vec![sigma];
        row.extend(medians);
        rows.push(row);
    }
    let colors = [
        RED_600, ORANGE_800, GREEN_700, PURPLE_700, BLUE_700, GREY_700,
    ];
    let series = ESTIMATORS
        .iter()
        .enumerate()
        .map(|(j, name)| {
            let points = rows.iter().map(|r| (r[0].log10(), r[j + 1])).collect();
            Series::line(name, colors[j], points)
        })
        .collect();
    let stem = format!("noise_sweep_{stem}");
    let [png, svg] = figure(
        &stem,
        &format!("{title}: median error under noise"),
        "log10 σ",
        &[Panel::new("median |v − v̂|", series).log()],
    )?;
    let header = [
        "sigma",
        "finite_differences",
        "reduced_38",
        "full_36",
        "saltation_kalman_defaults",
        "saltation_kalman_tuned",
        "saltation_kalman_plant_step",
    ];
    let data = csv(&stem, &header, rows)?;
    announce(&[&png, &svg, &data]);
    Ok(())
}

/// The estimators of [`ESTIMATORS`] on one sampled run; the median error
/// of each.
fn estimate_all<M, const N: usize, const K: usize>(
    model: &M,
    reference: &Reference<N>,
    sigma: f64,
    velocity_bound: f64,
    knobs: &KalmanParams<f64, N>,
) -> Result<[f64; 6]>
where
    M: Sensitivities<N, K, Scalar = f64, Input = SVector<f64, 0>>,
{
    let score = |v: &[SVector<f64, N>]| {
        let error: Vec<f64> = v
            .iter()
            .zip(&reference.v)
            .map(|(a, b)| (a - b).norm())
            .collect();
        quantile(&window(&reference.t, &error, 2.0, T_END), 0.5)
    };
    let (t, q) = (&reference.t, &reference.measured);
    // backward differences of the samples
    let mut fd = vec![SVector::zeros()];
    fd.extend((1..t.len()).map(|k| (q[k] - q[k - 1]) / (t[k] - t[k - 1])));
    let params = ObserverParams::new(10.0, velocity_bound).with_noise(sigma);
    let mut reduced = ReducedOrder::<f64, N, K>::new(params, t[0], q[0], SVector::zeros())?;
    let reduced = run::<_, _, N, K, 0>(model, &mut reduced, reference)?.v;
    let gains = FullOrderGains::scalar(5.0, 25.0);
    let mut full = FullOrder::<f64, N, K>::new(params, gains, t[0], q[0], SVector::zeros())?;
    let full = run::<_, _, N, K, 0>(model, &mut full, reference)?.v;
    // the filter with its default process noise, with the tuned one, and
    // told the plant's step, each told this run's σ
    let defaults = KalmanParams::new(velocity_bound, sigma);
    let stepped = defaults.with_plant_step(PLANT_STEP);
    let tuned = KalmanParams {
        observer: ObserverParams {
            noise: sigma,
            ..knobs.observer
        },
        measurement: SMatrix::identity() * (sigma * sigma),
        ..*knobs
    };
    let mut kalman = [0.0; 3];
    for (median, params) in kalman.iter_mut().zip([defaults, tuned, stepped]) {
        let mut filter = SaltationKalman::<f64, N, K>::new(params, t[0], q[0], SVector::zeros())?;
        *median = score(&run::<_, _, N, K, 0>(model, &mut filter, reference)?.v);
    }
    Ok([
        score(&fd),
        score(&reduced),
        score(&full),
        kalman[0],
        kalman[1],
        kalman[2],
    ])
}
