//! A double pendulum whose tip hits the floor (and could hit a wall): a
//! configuration-dependent mass matrix, Coriolis forces and joint damping.
//! The impacts accumulate and the tip then slides along the floor. The
//! reduced-order (38) and full-order (36) observers, side by side, see the
//! joint angles sampled at 1 kHz.
//!
//! `cargo run --release --example double_pendulum`

mod support;

use moreau_models::DoublePendulum;
use nalgebra::Vector2;
use support::compare::{Setup, compare};

fn main() -> support::plot::Result<()> {
    let (q0, v0) = DoublePendulum::<f64>::initial_state();
    compare::<_, 2, 2>(
        &DoublePendulum::<f64>::default(),
        &Setup {
            stem: "double_pendulum",
            title: "A double pendulum hitting the floor, observers (38) and (36)",
            q0,
            v0,
            v_hat0: Vector2::new(1.0, -1.0),
            plant_tau: 1e-5,
            sample: 1e-3,
            t_end: 5.0,
            l_d: 20.0,
            velocity_bound: 10.0,
            lambda: 10.0,
            rho: 10.0,
        },
    )
}
