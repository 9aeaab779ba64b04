//! Fig. 1a of the paper: three balls on a line between two walls. Balls 2
//! and 3 start at rest and in contact; ball 1 runs into them, and 2 and 3
//! leave the impact glued together, as the impact LCP predicts. The
//! reduced-order (38) and full-order (36) observers, side by side, see the
//! three positions sampled at 1 kHz.
//!
//! `cargo run --release --example three_balls`

mod support;

use moreau_models::ThreeBalls;
use nalgebra::Vector3;
use support::compare::{Setup, compare};

fn main() -> support::plot::Result<()> {
    let (q0, v0) = ThreeBalls::<f64>::initial_state();
    compare::<_, 3, 4>(
        &ThreeBalls::<f64>::default(),
        &Setup {
            stem: "three_balls",
            title: "Fig. 1a: three balls between two walls, observers (38) and (36)",
            q0,
            v0,
            v_hat0: Vector3::new(0.0, 0.5, -0.5),
            plant_tau: 1e-5,
            sample: 1e-3,
            t_end: 6.0,
            l_d: 10.0,
            velocity_bound: 5.0,
            lambda: 10.0,
            rho: 10.0,
        },
    )
}
