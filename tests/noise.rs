//! The reduced-order observer (38) under measurement noise.

use moreau::{Estimate, Model, Observer, ObserverParams, ReducedOrder};
mod common;

use common::runs::{Reference, Scored, measure, reference, score};
use moreau_models::{DoublePendulum, Parabola, ThreeBalls};
use nalgebra::{SVector, Vector2, Vector3};

/// (38) with `l_d = 10`, `C_v = 20`, told `σ`, from the first measurement
/// and `v̂(0) = 0`; returns the estimates, the initial one first.
fn run<M, const N: usize, const K: usize>(
    model: &M,
    data: &Reference<N>,
    measured: &[SVector<f64, N>],
    sigma: f64,
) -> Vec<Estimate<f64, N>>
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, 0>>,
{
    let u = SVector::zeros();
    let params = ObserverParams::new(10.0, 20.0).with_noise(sigma);
    let mut o = ReducedOrder::<f64, N, K>::new(params, 0.0, measured[0], SVector::zeros()).unwrap();
    let mut out = vec![o.estimate()];
    for (s, q) in data.samples.iter().zip(measured).skip(1) {
        out.push(o.update(model, s.t, q, &u).unwrap());
    }
    out
}

fn example_1_starts() -> Vec<(SVector<f64, 2>, SVector<f64, 2>)> {
    vec![
        Parabola::<f64>::initial_state(),
        (Vector2::new(-1.0, 3.0), Vector2::new(-2.0, 5.0)),
        (Vector2::new(0.5, 6.0), Vector2::new(4.0, 0.0)),
        (Vector2::new(0.2, 1.0), Vector2::new(1.0, -2.0)),
    ]
}

fn show(name: &str, s: &Scored) {
    eprintln!(
        "{name}: median {:.2e} p90 {:.2e} max {:.2e} clean max {:.2e} worst recovery {}  {:?}",
        s.all.median,
        s.all.p90,
        s.all.max,
        s.clean.max,
        s.recover.iter().max().unwrap_or(&0),
        s.recover
    );
}

#[test]
fn diagnostic() {
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    for (n, start) in example_1_starts().into_iter().enumerate() {
        let data = reference(&model, start, 1e-5, 100, 10.0, &u);
        for (sigma, seed) in [(1e-4, 11 + n as u64), (0.0, 0), (1e-4, 101 + n as u64)] {
            let measured = measure(&data, sigma, seed);
            let est = run::<_, 2, 2>(&model, &data, &measured, sigma);
            show(
                &format!("E1 start {n} σ {sigma:e} seed {seed}"),
                &score(&data, &est, (2.0, 10.001)),
            );
        }
    }
    let balls = ThreeBalls::<f64>::new();
    let (q0, v0) = ThreeBalls::<f64>::initial_state();
    let data = reference(&balls, (q0, v0), 1e-5, 100, 10.0, &u);
    for (sigma, seed) in [(1e-4, 5u64), (0.0, 0)] {
        let measured = measure(&data, sigma, seed);
        let est = run::<_, 3, 4>(&balls, &data, &measured, sigma);
        show(
            &format!("balls σ {sigma:e}"),
            &score(&data, &est, (2.0, 10.001)),
        );
    }
    let pend = DoublePendulum::<f64>::new();
    let start = DoublePendulum::<f64>::initial_state();
    let data = reference(&pend, start, 1e-5, 100, 10.0, &u);
    eprintln!("pendulum impacts {}", data.impacts.len());
    for (sigma, seed) in [(1e-4, 5u64), (0.0, 0)] {
        let measured = measure(&data, sigma, seed);
        let est = run::<_, 2, 2>(&pend, &data, &measured, sigma);
        show(
            &format!("pendulum σ {sigma:e}"),
            &score(&data, &est, (2.0, 10.001)),
        );
    }
    let _ = Vector3::<f64>::zeros();
}

#[test]
fn timeline() {
    let n: usize = std::env::var("START")
        .map(|s| s.parse().unwrap())
        .unwrap_or(0);
    let seed: u64 = std::env::var("SEED")
        .map(|s| s.parse().unwrap())
        .unwrap_or(11);
    let sigma: f64 = std::env::var("SIGMA")
        .map(|s| s.parse().unwrap())
        .unwrap_or(1e-4);
    let thr: f64 = std::env::var("THR")
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.05);
    let model = Parabola::<f64>::new();
    let u = SVector::zeros();
    let data = reference(&model, example_1_starts()[n], 1e-5, 100, 10.0, &u);
    let measured = measure(&data, sigma, seed);
    let params = ObserverParams::new(10.0, 20.0).with_noise(sigma);
    let mut o = ReducedOrder::<f64, 2, 2>::new(params, 0.0, measured[0], SVector::zeros()).unwrap();
    let imp: Vec<f64> = data.impacts.iter().map(|x| x.0).collect();
    for (j, (s, q)) in data.samples.iter().zip(&measured).enumerate().skip(1) {
        let e = o.update(&model, s.t, q, &u).unwrap();
        let err = (e.v - s.v).norm();
        if s.t >= 2.0 && err > thr {
            let near = imp
                .iter()
                .filter(|&&t| (t - s.t).abs() < 2.5e-3)
                .map(|t| format!("{:.5}", t))
                .collect::<Vec<_>>();
            let r = o.report();
            eprintln!(
                "j {j} t {:.3} err {:.3e} v [{:.4} {:.4}] v̂ [{:.4} {:.4}] h_true {:.2e} h_meas {:.2e} impacts {} contacts {:?} first {:?} near {:?}",
                s.t,
                err,
                s.v[0],
                s.v[1],
                e.v[0],
                e.v[1],
                model.gaps(&s.q)[0],
                model.gaps(q)[0],
                r.impacts,
                r.contacts,
                r.first_impact,
                near
            );
        }
    }
}
