//! Fig. 1c of the paper: a ball under gravity in a nonconvex billiard whose
//! walls curve inward (what is left between four overlapping disks). Impacts
//! come in quick succession, and accumulate once the ball is wedged in a
//! corner. The reduced-order (38) and full-order (36) observers, side by
//! side, see the positions sampled at 1 kHz.
//!
//! `cargo run --release --example billiard`

mod support;

use moreau_models::Billiard;
use nalgebra::Vector2;
use support::compare::{Setup, compare};

fn main() -> support::plot::Result<()> {
    let (q0, v0) = Billiard::<f64>::initial_state();
    compare::<_, 2, 4>(
        &Billiard::<f64>::default(),
        &Setup {
            stem: "billiard",
            title: "Fig. 1c: a ball in a nonconvex billiard, observers (38) and (36)",
            q0,
            v0,
            v_hat0: Vector2::new(0.0, 0.0),
            plant_tau: 1e-5,
            sample: 1e-3,
            t_end: 3.0,
            l_d: 10.0,
            velocity_bound: 5.0,
            lambda: 10.0,
            rho: 10.0,
        },
    )
}
