//! The paper's Example 1 and Fig. 4: a unit mass under gravity bounces
//! inside the parabola `y ≥ x²` below the ceiling `y ≤ 8` (e = 0.9); its
//! impacts accumulate near t = 4.5 s and it then slides on the parabola.
//! The reduced-order observer (38), with `l_d = 10` and `v̂(0) = 0`, sees
//! only the positions, sampled at 1 kHz from a plant stepped at 10 µs.
//!
//! Prints the convergence table and writes `out/parabola.{png,svg,csv}`.
//!
//! `cargo run --release --example parabola`

mod support;

use moreau::{Model, ObserverParams, ReducedOrder};
use moreau_models::Parabola;
use plotters::style::full_palette::{BLUE_700, GREY_400, ORANGE_800, RED_600};
use support::observe::{at, quantile, run, window};
use support::plot::{Panel, Result, Series, announce, csv, figure};
use support::reference::{Sampling, episodes, sample};

/// The plant's step and the sampling period of the measurements.
const PLANT_TAU: f64 = 1e-5;
const SAMPLE: f64 = 1e-3;
const T_END: f64 = 10.0;

fn main() -> Result<()> {
    let model = Parabola::<f64>::default();
    let (q0, v0) = Parabola::<f64>::initial_state();
    let reference = sample::<_, 2, 2, 0>(&model, q0, v0, Sampling::new(PLANT_TAU, SAMPLE, T_END))?;

    let params = ObserverParams::new(10.0, 20.0);
    let mut observer = ReducedOrder::new(
        params,
        0.0,
        reference.measured[0],
        nalgebra::Vector2::zeros(),
    )?;
    let estimates = run::<_, _, 2, 2, 0>(&model, &mut observer, &reference)?;

    // The plant's impacts: runs of fine steps with an impulse. The last run,
    // which lasts to the end, is the sliding that follows the accumulation.
    let runs = episodes(&reference.impacts, 1.5 * PLANT_TAU);
    let sliding = runs
        .last()
        .filter(|r| r.1 >= T_END - 2.0 * PLANT_TAU && r.1 - r.0 > 0.1);
    let impacts = runs.len() - usize::from(sliding.is_some());
    let on_ceiling: Vec<_> = reference
        .impacts
        .iter()
        .filter(|i| i.constraint == 1)
        .copied()
        .collect();
    let ceiling = episodes(&on_ceiling, 1.5 * PLANT_TAU).len();

    println!("Example 1 (the paper's Fig. 4): reduced-order observer (38), l_d = 10, v̂(0) = 0,");
    println!("positions sampled at 1 kHz from a Moreau–Jean plant at τ = 1e-5 s.");
    println!();
    println!("   t [s]    |v − v̂| [m/s]");
    for t in [0.5, 1.0, 2.0, 4.0, 6.0, 8.0, 10.0] {
        println!("  {t:6.1}    {:.3e}", at(&reference.t, &estimates.error, t));
    }
    let late = window(&reference.t, &estimates.error, 2.0, T_END);
    println!();
    println!(
        "  over t ∈ [2, 10] s: median {:.2e}, 90th percentile {:.2e}, max {:.2e} m/s",
        quantile(&late, 0.5),
        quantile(&late, 0.9),
        quantile(&late, 1.0)
    );
    println!(
        "  impacts before the accumulation point: {impacts}, {ceiling} of them on the ceiling"
    );
    match sliding {
        Some((start, _, _)) => {
            println!("  accumulation point: t = {start:.3} s; sliding on the parabola from then on")
        }
        None => println!("  no accumulation within {T_END} s"),
    }

    let t = &reference.t;
    let series = |f: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        (0..t.len()).map(|k| (t[k], f(k))).collect()
    };
    let h: Vec<_> = reference.q.iter().map(|q| model.gaps(q)).collect();
    let panels = [
        Panel::new(
            "gap",
            vec![
                Series::line("h1 = y − x²", BLUE_700, series(&|k| h[k][0])),
                Series::line("h2 = 8 − y", ORANGE_800, series(&|k| h[k][1])),
            ],
        ),
        Panel::new(
            "v_x [m/s]",
            vec![
                Series::line("v_x", GREY_400, series(&|k| reference.v[k][0])),
                Series::thin("estimate", RED_600, series(&|k| estimates.v[k][0])),
            ],
        )
        .with_inset(4.0, 4.7),
        Panel::new(
            "v_y [m/s]",
            vec![
                Series::line("v_y", GREY_400, series(&|k| reference.v[k][1])),
                Series::thin("estimate", RED_600, series(&|k| estimates.v[k][1])),
            ],
        )
        .with_inset(4.0, 4.7),
        Panel::new(
            "|v − v̂| [m/s]",
            vec![Series::line(
                "error",
                RED_600,
                series(&|k| estimates.error[k]),
            )],
        )
        .log(),
    ];
    let [png, svg] = figure(
        "parabola",
        "Example 1: a ball in a parabola below a ceiling, reduced-order observer (38)",
        "t [s]",
        &panels,
    )?;
    let data = csv(
        "parabola",
        &[
            "t", "x", "y", "vx", "vy", "vx_hat", "vy_hat", "h1", "h2", "error",
        ],
        (0..t.len()).map(|k| {
            let (q, v, e) = (reference.q[k], reference.v[k], estimates.v[k]);
            vec![
                t[k],
                q[0],
                q[1],
                v[0],
                v[1],
                e[0],
                e[1],
                h[k][0],
                h[k][1],
                estimates.error[k],
            ]
        }),
    )?;
    announce(&[&png, &svg, &data]);
    Ok(())
}
