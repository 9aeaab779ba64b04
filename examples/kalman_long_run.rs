//! The saltation Kalman filter over 10⁷ updates: Example 1's plant
//! (Moreau–Jean at τ = 1e-5) sampled at every step for 100 s (impacts,
//! the accumulation at 4.456 s, then sliding), positions with seeded
//! Gaussian noise σ = 1e-4. Two filters take the same samples: one with
//! its defaults, and one told the plant's step
//! (`KalmanParams::with_plant_step`), which keeps an impact's likely steps
//! apart as a sum of Gaussians and reports `P` plus their spread. After
//! every update each reported covariance must be exactly symmetric and
//! positive definite (a Cholesky factorisation of `P_qq` and of its Schur
//! complement `P_vv − P_vq P_qq⁻¹ P_qv`); the run prints the extremes it
//! saw.
//!
//! `cargo run --release --example kalman_long_run [updates]` (default 10⁷)

mod support;

use moreau::{KalmanParams, MoreauJean, Observer, SaltationKalman, State, StepParams};
use moreau_models::Parabola;
use nalgebra::{SVector, Vector2};
use support::reference::Gaussian;

/// One filter over the run and what its covariance did.
struct Watched {
    label: &'static str,
    filter: SaltationKalman<f64, 2, 2>,
    min_pivot: f64,
    max_trace: f64,
    outliers: u64,
    saltations: u64,
    kept_apart: u64,
}

impl Watched {
    fn new(label: &'static str, filter: SaltationKalman<f64, 2, 2>) -> Self {
        Self {
            label,
            filter,
            min_pivot: f64::INFINITY,
            max_trace: 0.0,
            outliers: 0,
            saltations: 0,
            kept_apart: 0,
        }
    }

    /// One update, then the covariance's checks.
    fn update(
        &mut self,
        model: &Parabola<f64>,
        t: f64,
        q: &Vector2<f64>,
    ) -> Result<(), Box<dyn std::error::Error>> {
        self.filter.update(model, t, q, &SVector::zeros())?;
        let p = self.filter.covariance();
        if !(p.qq == p.qq.transpose() && p.vv == p.vv.transpose() && p.vq == p.qv.transpose()) {
            return Err(format!("{}: P not symmetric at t = {t}", self.label).into());
        }
        let chol =
            p.qq.cholesky()
                .ok_or_else(|| format!("{}: P_qq not positive definite at t = {t}", self.label))?;
        let schur = p.vv - p.vq * chol.solve(&p.qv);
        let schur_chol = schur.cholesky().ok_or_else(|| {
            format!(
                "{}: the Schur complement of P_qq is not positive definite at t = {t}",
                self.label
            )
        })?;
        let pivot = chol
            .l()
            .diagonal()
            .min()
            .min(schur_chol.l().diagonal().min());
        self.min_pivot = self.min_pivot.min(pivot / p.trace().sqrt());
        self.max_trace = self.max_trace.max(p.trace());
        let report = self.filter.kalman_report();
        self.outliers += u64::from(report.outlier);
        self.saltations += u64::from(report.saltations);
        self.kept_apart += u64::from(report.alternatives > 0);
        Ok(())
    }
}

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
    let start = |p| SaltationKalman::<f64, 2, 2>::new(p, 0.0, q0, Vector2::zeros());
    let mut filters = [
        Watched::new("defaults", start(params)?),
        Watched::new("told the plant's step", start(params.with_plant_step(tau))?),
    ];
    for k in 1..=updates {
        stepper.step(&model, &mut state, &u)?;
        let q = state.q + Vector2::new(sigma * gauss.next(), sigma * gauss.next());
        for f in &mut filters {
            f.update(&model, k as f64 * tau, &q)?;
        }
    }
    for f in &filters {
        println!(
            "{}: {updates} updates over {:.0} s: P symmetric and positive definite after every one; smallest Cholesky pivot / √tr P {:.2e}, largest tr P {:.2e}; {} saltations, {} outliers, {} updates with steps kept apart",
            f.label,
            updates as f64 * tau,
            f.min_pivot,
            f.max_trace,
            f.saltations,
            f.outliers,
            f.kept_apart
        );
    }
    Ok(())
}
