//! The plant stepper beside Siconos, in one run: the same model, initial
//! state, θ, γ and step, timed the same way (the whole run, best of 5).
//! Siconos runs through `tests/siconos_reference.py --time` (Debian's
//! `python3-siconos`, model functions as Python callbacks and as compiled C
//! plugins); when it is not installed, only moreau's figures are printed.
//!
//! `cargo bench -p moreau-bench --bench vs_siconos`

use std::process::Command;
use std::time::Instant;

use moreau::{Model, MoreauJean, State, StepParams};
use moreau_models::{DoublePendulum, Parabola};
use nalgebra::SVector;

/// Seconds per step of a whole run, best of 5, with Siconos' settings.
fn moreau_per_step<M, const N: usize, const K: usize>(
    model: &M,
    q0: SVector<f64, N>,
    v0: SVector<f64, N>,
    steps: usize,
) -> f64
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, 0>>,
{
    let params = StepParams::siconos(1e-3);
    let stepper = MoreauJean::new(params).unwrap();
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let mut state = State::new(0.0, q0, v0);
        let start = Instant::now();
        for _ in 0..steps {
            stepper.step(model, &mut state, &SVector::zeros()).unwrap();
        }
        std::hint::black_box(state);
        best = best.min(start.elapsed().as_secs_f64() / steps as f64);
    }
    best
}

fn main() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let (q, v) = Parabola::<f64>::initial_state();
    let parabola = moreau_per_step::<_, 2, 2>(&Parabola::<f64>::default(), q, v, 10_000);
    let (q, v) = DoublePendulum::<f64>::initial_state();
    let pendulum = moreau_per_step::<_, 2, 2>(&DoublePendulum::<f64>::default(), q, v, 5_000);
    println!("moreau (Rust, generated model), whole run, best of 5:");
    println!(
        "  parabola         10000 steps  {:8.3} us/step",
        parabola * 1e6
    );
    println!(
        "  double_pendulum   5000 steps  {:8.3} us/step",
        pendulum * 1e6
    );
    let siconos = Command::new("/usr/bin/python3")
        .arg(format!("{root}/tests/siconos_reference.py"))
        .arg("--time")
        .output();
    match siconos {
        Ok(out) if out.status.success() => {
            println!("Siconos, same runs:");
            print!("{}", String::from_utf8_lossy(&out.stdout));
        }
        Ok(out) => println!(
            "Siconos could not run (install python3-siconos):\n{}",
            String::from_utf8_lossy(&out.stderr)
        ),
        Err(e) => println!("Siconos could not run ({e}); install python3-siconos"),
    }
}
