//! The saltation Kalman filter over 10⁷ updates: Example 1's plant
//! (Moreau–Jean at τ = 1e-5) sampled at every step for 100 s (impacts,
//! the accumulation at 4.456 s, then sliding), positions with seeded
//! Gaussian noise σ = 1e-4. After every update the covariance must be
//! exactly symmetric and positive definite (a Cholesky factorisation of
//! `P_qq` and of its Schur complement `P_vv − P_vq P_qq⁻¹ P_qv`); the run
//! prints the extremes it saw.
//!
//! `cargo run --release --example kalman_long_run [updates]` (default 10⁷)

mod support;

use moreau::{KalmanParams, MoreauJean, Observer, SaltationKalman, State, StepParams};
use moreau_models::Parabola;
use nalgebra::{SVector, Vector2};
use support::reference::Gaussian;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let updates: usize = std::env::args()
        .nth(1)
        .map_or(Ok(10_000_000), |a| a.parse())?;
    let model = Parabola::<f64>::default();
    let (q0, v0) = Parabola::<f64>::initial_state();
    let tau = 1e-5;
    let stepper = MoreauJean::new(StepParams::new(tau))?;
    let mut state = State::new(0.0, q0, v0);
    let u = SVector::zeros();
    let sigma = 1e-4;
    let mut gauss = Gaussian::new(3);
    let params = KalmanParams::new(20.0, sigma);
    let mut filter = SaltationKalman::<f64, 2, 2>::new(params, 0.0, q0, Vector2::zeros())?;
    let (mut min_pivot, mut max_trace) = (f64::INFINITY, 0.0_f64);
    let (mut outliers, mut saltations) = (0u64, 0u64);
    for k in 1..=updates {
        stepper.step(&model, &mut state, &u)?;
        let q = state.q + Vector2::new(sigma * gauss.next(), sigma * gauss.next());
        filter.update(&model, k as f64 * tau, &q, &u)?;
        let p = filter.covariance();
        assert!(p.qq == p.qq.transpose() && p.vv == p.vv.transpose() && p.vq == p.qv.transpose());
        let chol = p.qq.cholesky().ok_or("P_qq not positive definite")?;
        let schur = p.vv - p.vq * chol.solve(&p.qv);
        let schur_chol = schur
            .cholesky()
            .ok_or("the Schur complement of P_qq is not positive definite")?;
        let pivot = chol
            .l()
            .diagonal()
            .min()
            .min(schur_chol.l().diagonal().min());
        min_pivot = min_pivot.min(pivot / p.trace().sqrt());
        max_trace = max_trace.max(p.trace());
        outliers += u64::from(filter.kalman_report().outlier);
        saltations += u64::from(filter.kalman_report().saltations);
    }
    println!(
        "{updates} updates over {:.0} s: P symmetric and positive definite after every one; smallest Cholesky pivot / √tr P {min_pivot:.2e}, largest tr P {max_trace:.2e}; {saltations} saltations, {outliers} outliers",
        updates as f64 * tau
    );
    Ok(())
}
