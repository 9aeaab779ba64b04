//! A user's crate: it depends on `moreau` alone, writes its model inline
//! and runs the reduced-order observer on it.
//!
//! The model: a robot finger (a rod on a motor, in a vertical plane) that
//! taps a wall. Its motor torque is a known input; the encoder gives the
//! angle; the observer estimates the angular velocity through the impacts.
//!
//! `cargo run --release -p moreau-user-model`

use moreau::{Model, MoreauJean, Observer, ObserverParams, ReducedOrder, State, StepParams};
use nalgebra::{SVector, Vector1};

moreau::model! {
    /// A rod of mass `m` and length `l` on a motor shaft, with viscous
    /// friction `b`, tapping a wall at angle `wall`.
    pub struct Finger;
    coordinates { th: w }
    parameters { m: 0.2, l: 0.1, g: 9.81, b: 0.002, wall: 0.6 }
    inputs { torque }
    kinetic = 0.5 * (m * l^2 / 3) * w^2;
    potential = m * g * 0.5 * l * sin(th);
    applied { th: torque - b * w }
    constraints { wall: th <= wall }
    restitution = 0.6;
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let finger = Finger::<f64>::default();
    // the plant, stepped at 10 µs; the encoder, read every millisecond
    let plant = MoreauJean::new(StepParams::new(1e-5))?;
    let mut state = State::new(0.0, Vector1::new(0.0), Vector1::new(0.0));
    let params = ObserverParams::new(20.0, 50.0);
    let mut observer = ReducedOrder::new(params, 0.0, state.q, Vector1::zeros())?;

    let mut impacts = 0;
    for k in 1..=2000 {
        // a square-wave torque lifts the finger against the wall (gravity
        // pulls it back with m g l / 2 = 0.098 N m), then lets it fall
        let torque = SVector::<f64, 1>::new(if (k / 250) % 2 == 0 { 0.13 } else { 0.05 });
        for _ in 0..100 {
            impacts += plant.step(&finger, &mut state, &torque)?.impacts().count();
        }
        let estimate = observer.update(&finger, state.t, &state.q, &torque)?;
        if k % 250 == 0 {
            println!(
                "t = {:4.2} s  angle {:+.4} rad  velocity {:+.4} rad/s  estimate {:+.4}  error {:.1e}",
                state.t,
                state.q[0],
                state.v[0],
                estimate.v[0],
                (state.v[0] - estimate.v[0]).abs()
            );
        }
    }
    println!(
        "{impacts} fine steps with an impulse on the wall; model {} ({} operations per evaluation)",
        Finger::<f64>::INFO.name,
        Finger::<f64>::INFO.op_count
    );
    Ok(())
}
