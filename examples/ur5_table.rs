//! A UR5 from its URDF, motors off, falls onto a table: the tool strikes it,
//! bounces (restitution 0.3) and comes to rest on it. The reduced-order
//! observer (38) and the saltation Kalman filter, side by side, estimate
//! the six joint velocities from joint positions sampled at 1 kHz with
//! encoder-like noise (σ = 10⁻⁴ rad, about 0.006°); neither is given
//! anything but the model and `σ`.
//!
//! `cargo run --release --example ur5_table`

mod support;

use moreau::{KalmanParams, Model, ObserverParams, ReducedOrder, SaltationKalman};
use nalgebra::SVector;
use plotters::style::full_palette::{BLUE_700, GREEN_700, GREY_400, ORANGE_800};
use support::observe::{at, quantile, run, window};
use support::plot::{Panel, Result, Series, announce, csv, figure};
use support::reference::{Sampling, episodes, sample};

moreau::model!(file = "examples/ur5_table.yaml");

const T_END: f64 = 3.0;
const SIGMA: f64 = 1e-4;
const PLANT_TAU: f64 = 1e-5;

fn main() -> Result<()> {
    let model = Ur5Table::<f64>::new();
    let (q0, v0) = Ur5Table::<f64>::initial_state();
    let reference = sample::<_, 6, 1, 0>(
        &model,
        q0,
        v0,
        Sampling::new(PLANT_TAU, 1e-3, T_END).with_noise(SIGMA, 11),
    )?;
    let params = ObserverParams::new(20.0, 40.0).with_noise(SIGMA);
    let mut observer = ReducedOrder::new(params, 0.0, reference.measured[0], SVector::repeat(0.5))?;
    let estimates = run::<_, _, 6, 1, 0>(&model, &mut observer, &reference)?;
    let mut filter = SaltationKalman::new(
        KalmanParams::new(40.0, SIGMA),
        0.0,
        reference.measured[0],
        SVector::repeat(0.5),
    )?;
    let filtered = run::<_, _, 6, 1, 0>(&model, &mut filter, &reference)?;
    let gap: Vec<f64> = reference.q.iter().map(|q| model.gaps(q)[0]).collect();
    let impacts = episodes(&reference.impacts, 1.5 * PLANT_TAU).len();

    println!(
        "A UR5 falling onto a table; reduced-order observer (38) and saltation Kalman filter from noisy joint positions"
    );
    println!(
        "plant: Moreau–Jean at τ = {PLANT_TAU:e} s, {impacts} impact episode(s) in {T_END} s; samples every 1 ms, σ = {SIGMA:e} rad; l_d = 20, C_v = 40 rad/s; v̂(0) = 0.5 rad/s per joint, v(0) = 0"
    );
    println!(
        "model: {} operations in the fused evaluation",
        Ur5Table::<f64>::INFO.op_count
    );
    println!();
    println!("   t [s]   tool height above the table [m]   |v − v̂| [rad/s], (38)   filter");
    for k in 1..=6 {
        let t = T_END * f64::from(k) / 6.0;
        println!(
            "  {t:5.2}    {:+.4}                            {:.3e}      {:.3e}",
            at(&reference.t, &gap, t),
            at(&reference.t, &estimates.error, t),
            at(&reference.t, &filtered.error, t)
        );
    }
    println!();
    for (name, e) in [("(38)", &estimates), ("filter", &filtered)] {
        let late = window(&reference.t, &e.error, 2.0, T_END);
        println!(
            "{name:>6}: median |v − v̂| over [2, {T_END}] s: {:.3e} rad/s",
            quantile(&late, 0.5)
        );
    }

    let points = |ys: &[f64]| {
        reference
            .t
            .iter()
            .copied()
            .zip(ys.iter().copied())
            .collect()
    };
    let speed: Vec<f64> = reference.v.iter().map(|v| v.norm()).collect();
    let [png, svg] = figure(
        "ur5_table",
        "A UR5 striking a table; (38) and the saltation Kalman filter, 1 kHz noisy encoders",
        "t [s]",
        &[
            Panel::new(
                "tool height above the table [m]",
                vec![Series::line("h", BLUE_700, points(&gap))],
            ),
            Panel::new(
                "|v|, |v − v̂| [rad/s]",
                vec![
                    Series::thin("|v|", GREY_400, points(&speed)),
                    Series::line("|v − v̂|, (38)", ORANGE_800, points(&estimates.error)),
                    Series::line("|v − v̂|, filter", GREEN_700, points(&filtered.error)),
                ],
            )
            .log(),
        ],
    )?;
    let rows: Vec<Vec<f64>> = reference
        .t
        .iter()
        .enumerate()
        .map(|(k, t)| vec![*t, gap[k], speed[k], estimates.error[k], filtered.error[k]])
        .collect();
    let data = csv(
        "ur5_table",
        &["t", "gap", "speed", "error_38", "error_filter"],
        rows,
    )?;
    announce(&[&png, &svg, &data]);
    Ok(())
}
