//! Our saltation Kalman filter on exactly the data `tests/kalman.rs`
//! scores it on (`example_1_figures_beside_the_reduced_order_observer`):
//! Example 1 from its four starts, the plant at `τ = 1e-5` sampled every
//! 1 ms with Gaussian noise `σ = 1e-4` (seed `11 + k` for start `k`),
//! `v̂(0) = 0`, the filter with its defaults and with the process noise
//! tuned once on the model file's start (its 10 s record, noise seed 1000).
//! Prints the figures over `t ∈ [2, 10]` s and the wall time per update
//! (median of five timed runs), and writes for the Python filter
//! `hybrid-tools` (`examples/hybrid_tools/skf_example1.py`, which reads
//! them): `out/vs_hybrid_tools/start<k>.csv` (t, the measured and the true
//! positions, the true velocity, both estimates, and `bracket`, 1 on the
//! samples that bracket a plant impact) and the tuning record
//! `out/vs_hybrid_tools/tuning.csv`.
//!
//! `cargo run --release --example vs_hybrid_tools`

mod support;

// the reference runs, noise and scoring of the tests, reused as they are
#[allow(dead_code)]
#[path = "../tests/common/runs.rs"]
mod runs;

use std::time::Instant;

use moreau::{Estimate, KalmanParams, Observer, SaltationKalman, tune_process_noise};
use moreau_models::Parabola;
use nalgebra::{SVector, Vector2};
use runs::{Reference, brackets, example_1_run, example_1_starts, measure, reference, score};
use support::plot::{Result, announce, csv, out_dir};

/// The measurement noise, as in the test.
const SIGMA: f64 = 1e-4;

/// Timed runs of each filter on each start (the median is reported).
const REPEATS: usize = 5;

fn main() -> Result<()> {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    std::fs::create_dir_all(out_dir()?.join("vs_hybrid_tools"))?;
    let tuned = tuned_process_noise(&model)?;
    let knobs = [
        ("defaults", KalmanParams::new(20.0, SIGMA)),
        ("tuned", tuned),
    ];
    println!("Example 1, σ = {SIGMA:e}, |v − v̂| over t ∈ [2, 10] s");
    let mut written = Vec::new();
    for (k, start) in example_1_starts().into_iter().enumerate() {
        let data = reference(&model, start, 1e-5, 100, 10.0, &u);
        let measured = measure(&data, SIGMA, 11 + k as u64);
        let mut columns = Vec::new();
        for (label, params) in knobs {
            // the run, timed whole; the median of REPEATS runs (all equal)
            let mut runs = (0..REPEATS)
                .map(|_| run(&model, params, &data, &measured))
                .collect::<Result<Vec<_>>>()?;
            runs.sort_by(|a, b| a.1.total_cmp(&b.1));
            let (estimates, seconds) = runs.swap_remove(REPEATS / 2);
            let per_update = seconds / (measured.len() - 1) as f64;
            let sc = score(&data, &estimates, (2.0, 10.0 + 1e-3));
            println!(
                "  start {k}, {label:8}: median {:.2e}  p90 {:.2e}  max {:.2e}  max w/o brackets {:.2e}  {:.1} µs/update",
                sc.all.median,
                sc.all.p90,
                sc.all.max,
                sc.clean.max,
                per_update * 1e6
            );
            columns.push(estimates.iter().map(|e| e.v).collect::<Vec<_>>());
        }
        let bracket = brackets(&data);
        let rows = (0..data.samples.len()).map(|j| {
            let (s, m) = (&data.samples[j], &measured[j]);
            vec![
                s.t,
                m[0],
                m[1],
                s.q[0],
                s.q[1],
                s.v[0],
                s.v[1],
                columns[0][j][0],
                columns[0][j][1],
                columns[1][j][0],
                columns[1][j][1],
                f64::from(u8::from(bracket[j])),
            ]
        });
        let header = [
            "t",
            "x_meas",
            "y_meas",
            "x",
            "y",
            "vx",
            "vy",
            "vx_defaults",
            "vy_defaults",
            "vx_tuned",
            "vy_tuned",
            "bracket",
        ];
        written.push(csv(&format!("vs_hybrid_tools/start{k}"), &header, rows)?);
    }
    let paths: Vec<&std::path::Path> = written.iter().map(|p| p.as_path()).collect();
    announce(&paths);
    Ok(())
}

/// The filter with `params` over the samples, from `v̂(0) = 0`: its
/// estimates and the wall time of the updates.
fn run(
    model: &Parabola<f64>,
    params: KalmanParams<f64, 2>,
    data: &Reference<2>,
    measured: &[SVector<f64, 2>],
) -> Result<(Vec<Estimate<f64, 2>>, f64)> {
    let u = SVector::zeros();
    let mut filter = SaltationKalman::<f64, 2, 2>::new(params, 0.0, measured[0], Vector2::zeros())?;
    let mut estimates = Vec::with_capacity(measured.len());
    estimates.push(filter.estimate());
    let start = Instant::now();
    for (s, q) in data.samples.iter().zip(measured).skip(1) {
        estimates.push(filter.update(model, s.t, q, &u)?);
    }
    Ok((estimates, start.elapsed().as_secs_f64()))
}

/// The process noise as `tests/kalman.rs` (`tuned_on`) picks it: from the
/// model file's start, its 10 s record with noise seed 1000.
/// Writes that record to `out/vs_hybrid_tools/tuning.csv` (t, x_meas,
/// y_meas), for the Python filter's tuning.
fn tuned_process_noise(model: &Parabola<f64>) -> Result<KalmanParams<f64, 2>> {
    let data = example_1_run(10.0);
    let measured = measure(&data, SIGMA, 1000);
    let t: Vec<f64> = data.samples.iter().map(|s| s.t).collect();
    let rows = t.iter().zip(&measured).map(|(&t, q)| vec![t, q[0], q[1]]);
    csv("vs_hybrid_tools/tuning", &["t", "x_meas", "y_meas"], rows)?;
    let tuned = tune_process_noise::<_, _, 2, 2>(
        model,
        KalmanParams::new(20.0, SIGMA),
        &t,
        &measured,
        &Vector2::zeros(),
        &SVector::zeros(),
        (-4.0, 2.0),
    )?;
    let p = tuned.params;
    println!(
        "tuned on start 0 (seed 1000): q_a {:.3e}, ρ_i {:.3e}, σ_t {:.3e}, δ̄ {:.3e}, ρ_c {:.3e} ({} runs)",
        p.accel_noise[0],
        p.impact_noise,
        p.impact_time_sigma,
        p.impact_delay,
        p.contact_noise,
        tuned.evaluations
    );
    Ok(p)
}
