//! The full-order (36) and reduced-order (38) observers side by side on one
//! model: the plant sampled, both observers fed the same measurements, a
//! table printed, a figure and a CSV file written.

use moreau::{FullOrder, FullOrderGains, Model, ObserverParams, ReducedOrder};
use nalgebra::SVector;
use plotters::style::RGBColor;
use plotters::style::full_palette::{
    BLUE_700, GREEN_700, GREY_400, ORANGE_800, PURPLE_600, RED_600, TEAL_700,
};

use super::observe::{at, quantile, run, window};
use super::plot::{Panel, Result, Series, announce, csv, figure};
use super::reference::{Sampling, episodes, sample};

/// One comparison.
pub struct Setup<const N: usize> {
    /// File stem of the outputs (`out/<stem>.{png,svg,csv}`).
    pub stem: &'static str,
    /// Figure title.
    pub title: &'static str,
    /// Initial state of the plant.
    pub q0: SVector<f64, N>,
    pub v0: SVector<f64, N>,
    /// Initial velocity estimate of both observers.
    pub v_hat0: SVector<f64, N>,
    /// Plant step, sampling period, final time.
    pub plant_tau: f64,
    pub sample: f64,
    pub t_end: f64,
    /// Observer gain `l_d`, velocity bound `C_v`, full-order `Λ = λ I` and
    /// `L_ρ1 = ρ I`.
    pub l_d: f64,
    pub velocity_bound: f64,
    pub lambda: f64,
    pub rho: f64,
}

const COLORS: [RGBColor; 6] = [
    BLUE_700, ORANGE_800, GREEN_700, PURPLE_600, TEAL_700, RED_600,
];

/// Runs the comparison and writes its outputs.
pub fn compare<M, const N: usize, const K: usize>(model: &M, s: &Setup<N>) -> Result<()>
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, 0>>,
{
    let reference = sample::<_, N, K, 0>(
        model,
        s.q0,
        s.v0,
        Sampling::new(s.plant_tau, s.sample, s.t_end),
    )?;
    let params = ObserverParams::new(s.l_d, s.velocity_bound);
    let mut reduced = ReducedOrder::new(params, 0.0, reference.measured[0], s.v_hat0)?;
    let gains = FullOrderGains::scalar(s.lambda, s.rho);
    let mut full = FullOrder::new(params, gains, 0.0, reference.measured[0], s.v_hat0)?;
    let ro = run::<_, _, N, K, 0>(model, &mut reduced, &reference)?;
    let fo = run::<_, _, N, K, 0>(model, &mut full, &reference)?;

    let impacts = episodes(&reference.impacts, 1.5 * s.plant_tau).len();
    println!("{}", s.title);
    println!(
        "plant: Moreau–Jean at τ = {:e} s, {} impacts in {} s; observers: l_d = {}, C_v = {}, samples every {:e} s;",
        s.plant_tau, impacts, s.t_end, s.l_d, s.velocity_bound, s.sample
    );
    println!(
        "full order with Λ = {} I, L_ρ1 = {} I; both start from v̂(0) = {:?}",
        s.lambda,
        s.rho,
        s.v_hat0.as_slice()
    );
    println!();
    println!("   t [s]    reduced (38)    full (36)     |v − v̂| [m/s]");
    for k in 1..=8 {
        let t = s.t_end * f64::from(k) / 8.0;
        println!(
            "  {t:6.2}    {:.3e}       {:.3e}",
            at(&reference.t, &ro.error, t),
            at(&reference.t, &fo.error, t)
        );
    }
    let (a, b) = (s.t_end / 2.0, s.t_end);
    for (name, e) in [("reduced (38)", &ro.error), ("full (36)", &fo.error)] {
        let w = window(&reference.t, e, a, b);
        println!(
            "  {name:13} over t ∈ [{a}, {b}] s: median {:.2e}, 90th percentile {:.2e}, max {:.2e}",
            quantile(&w, 0.5),
            quantile(&w, 0.9),
            quantile(&w, 1.0)
        );
    }

    let t = &reference.t;
    let series = |f: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        (0..t.len()).map(|k| (t[k], f(k))).collect()
    };
    let h: Vec<SVector<f64, K>> = reference.q.iter().map(|q| model.gaps(q)).collect();
    let mut panels = vec![Panel::new(
        "gap",
        (0..K)
            .map(|i| {
                Series::line(
                    &format!("h: {}", M::INFO.constraints[i]),
                    COLORS[i % 6],
                    series(&|k| h[k][i]),
                )
            })
            .collect(),
    )];
    for i in 0..N {
        let name = M::INFO.velocities[i];
        panels.push(Panel::new(
            name,
            vec![
                Series::line(name, GREY_400, series(&|k| reference.v[k][i])),
                Series::thin("reduced (38)", RED_600, series(&|k| ro.v[k][i])),
                Series::thin("full (36)", BLUE_700, series(&|k| fo.v[k][i])),
            ],
        ));
    }
    panels.push(
        Panel::new(
            "|v − v̂|",
            vec![
                Series::thin("reduced (38)", RED_600, series(&|k| ro.error[k])),
                Series::thin("full (36)", BLUE_700, series(&|k| fo.error[k])),
            ],
        )
        .log(),
    );
    let [png, svg] = figure(s.stem, s.title, "t [s]", &panels)?;

    let mut header: Vec<String> = vec!["t".into()];
    header.extend(M::INFO.coordinates.iter().map(|c| c.to_string()));
    header.extend(M::INFO.velocities.iter().map(|c| c.to_string()));
    header.extend(
        M::INFO
            .velocities
            .iter()
            .map(|c| format!("{c}_hat_reduced")),
    );
    header.extend(M::INFO.velocities.iter().map(|c| format!("{c}_hat_full")));
    header.extend(M::INFO.constraints.iter().map(|c| format!("h_{c}")));
    header.extend(["error_reduced".to_string(), "error_full".to_string()]);
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    let data = csv(
        s.stem,
        &header,
        (0..t.len()).map(|k| {
            let mut row = vec![t[k]];
            row.extend(reference.q[k].iter());
            row.extend(reference.v[k].iter());
            row.extend(ro.v[k].iter());
            row.extend(fo.v[k].iter());
            row.extend(h[k].iter());
            row.extend([ro.error[k], fo.error[k]]);
            row
        }),
    )?;
    announce(&[&png, &svg, &data]);
    Ok(())
}
