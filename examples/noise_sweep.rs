//! Measurement noise: Example 1 observed through positions with Gaussian
//! noise of standard deviation σ, sampled every 0.5, 1, 2 or 5 ms. The
//! reduced-order observer (l_d = 10, told σ) settles at an error that grows
//! linearly with σ, about 2 l_d σ, and hardly depends on the sampling
//! period: each sample injects `l_d` times a noise difference of size σ,
//! and the observer forgets it at the rate `l_d`, so the variance it keeps,
//! `l_d² σ² / (l_d T_s) · T_s`, does not involve `T_s`.
//!
//! `cargo run --release --example noise_sweep`

mod support;

use moreau::{ObserverParams, ReducedOrder};
use moreau_models::Parabola;
use nalgebra::Vector2;
use plotters::style::full_palette::{BLUE_700, GREEN_700, ORANGE_800, RED_600};
use support::observe::{quantile, run, window};
use support::plot::{Panel, Result, Series, announce, csv, figure};
use support::reference::{Sampling, sample};

const T_END: f64 = 10.0;

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
                Sampling::new(1e-5, period, T_END).with_noise(sigma, 7 + i as u64),
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
    Ok(())
}
