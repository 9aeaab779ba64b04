//! Section VI-D: the observer's restitution `ê` differs from the plant's
//! `e`. A ball in the nonconvex billiard without gravity and with `e = 1`
//! keeps hitting the walls for ever; both observers run with `ê` from 1
//! down to 0.7, and the error they settle at grows with `|ê − e|` (an
//! input-to-state-stable ball, as the paper argues).
//!
//! `cargo run --release --example restitution_sweep`

mod support;

use moreau::{FullOrder, FullOrderGains, ObserverParams, ReducedOrder};
use moreau_models::Billiard;
use nalgebra::{Vector2, Vector4};
use plotters::style::full_palette::{BLUE_700, RED_600};
use support::observe::{quantile, run, window};
use support::plot::{Panel, Result, Series, announce, csv, figure};
use support::reference::{Sampling, episodes, sample};

const T_END: f64 = 20.0;

fn main() -> Result<()> {
    let plant = Billiard::<f64> {
        g: 0.0,
        restitution: Vector4::repeat(1.0),
        ..Default::default()
    };
    let reference = sample::<_, 2, 4, 0>(
        &plant,
        Vector2::new(0.05, 0.1),
        Vector2::new(1.5, 0.7),
        Sampling::new(1e-5, 1e-3, T_END),
    )?;
    let impacts = episodes(&reference.impacts, 1.5e-5).len();
    println!(
        "The billiard without gravity, e = 1: {impacts} impacts in {T_END} s, sampled at 1 kHz."
    );
    println!("Observers with l_d = 10 and their own ê; error |v − v̂| over t ∈ [10, 20] s:");
    println!();
    println!("  |ê − e|    reduced (38): median    90th pct      full (36): median    90th pct");
    let params = ObserverParams::new(10.0, 5.0);
    let mut rows = Vec::new();
    for mismatch in [0.0, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3] {
        let e_hat = Vector4::repeat(1.0 - mismatch);
        let mut reduced = ReducedOrder::new(params, 0.0, reference.measured[0], Vector2::zeros())?
            .with_restitution(e_hat)?;
        let mut full = FullOrder::new(
            params,
            FullOrderGains::scalar(10.0, 10.0),
            0.0,
            reference.measured[0],
            Vector2::zeros(),
        )?
        .with_restitution(e_hat)?;
        let ro = window(
            &reference.t,
            &run::<_, _, 2, 4, 0>(&plant, &mut reduced, &reference)?.error,
            10.0,
            T_END,
        );
        let fo = window(
            &reference.t,
            &run::<_, _, 2, 4, 0>(&plant, &mut full, &reference)?.error,
            10.0,
            T_END,
        );
        let row = [
            mismatch,
            quantile(&ro, 0.5),
            quantile(&ro, 0.9),
            quantile(&fo, 0.5),
            quantile(&fo, 0.9),
        ];
        println!(
            "  {:5.2}      {:.3e}            {:.3e}     {:.3e}            {:.3e}",
            row[0], row[1], row[2], row[3], row[4]
        );
        rows.push(row);
    }
    let curve = |col: usize| rows.iter().map(|r| (r[0], r[col])).collect::<Vec<_>>();
    let [png, svg] = figure(
        "restitution_sweep",
        "Restitution mismatch: error settled by the observers against |ê − e| (billiard, e = 1)",
        "|ê − e|",
        &[
            Panel::new(
                "median |v − v̂| over [10, 20] s",
                vec![
                    Series::line("reduced (38)", RED_600, curve(1)),
                    Series::line("full (36)", BLUE_700, curve(3)),
                ],
            )
            .log(),
            Panel::new(
                "90th percentile",
                vec![
                    Series::line("reduced (38)", RED_600, curve(2)),
                    Series::line("full (36)", BLUE_700, curve(4)),
                ],
            )
            .log(),
        ],
    )?;
    let data = csv(
        "restitution_sweep",
        &[
            "mismatch",
            "reduced_median",
            "reduced_p90",
            "full_median",
            "full_p90",
        ],
        rows.iter().map(|r| r.to_vec()),
    )?;
    announce(&[&png, &svg, &data]);
    Ok(())
}
