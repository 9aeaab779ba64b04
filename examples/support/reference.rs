//! Measured trajectories for the observers: the plant stepped at a fine
//! step, sampled at the measurement rate, with optional Gaussian noise on
//! the positions. The observers never see the plant's velocities, which
//! serve only to measure their error.

use moreau::{Impact, Model, MoreauJean, State, StepParams};
use nalgebra::SVector;

use super::plot::Result;

/// A sampled plant trajectory.
pub struct Reference<const N: usize> {
    /// Sample times.
    pub t: Vec<f64>,
    /// True positions at the samples.
    pub q: Vec<SVector<f64, N>>,
    /// True velocities at the samples (for the error only).
    pub v: Vec<SVector<f64, N>>,
    /// Measured positions: `q` plus noise.
    pub measured: Vec<SVector<f64, N>>,
    /// Every impact of the plant (fine steps with an impulse).
    pub impacts: Vec<Impact<f64>>,
}

/// How a plant run is stepped and measured.
#[derive(Clone, Copy, Debug)]
pub struct Sampling {
    /// The plant's time step.
    pub plant_tau: f64,
    /// The sampling period of the measurements (an integer multiple of
    /// `plant_tau`).
    pub period: f64,
    /// The final time.
    pub t_end: f64,
    /// Standard deviation of the Gaussian noise on the measured positions.
    pub noise: f64,
    /// Seed of the noise.
    pub seed: u64,
}

impl Sampling {
    /// Noise-free measurements every `period` of a plant stepped by
    /// `plant_tau`, until `t_end`.
    pub fn new(plant_tau: f64, period: f64, t_end: f64) -> Self {
        Self {
            plant_tau,
            period,
            t_end,
            noise: 0.0,
            seed: 1,
        }
    }

    /// The same, with noise of standard deviation `noise` drawn from `seed`.
    pub fn with_noise(self, noise: f64, seed: u64) -> Self {
        Self {
            noise,
            seed,
            ..self
        }
    }
}

/// Runs `model` from `(q0, v0)` as `sampling` says and samples it.
pub fn sample<M, const N: usize, const K: usize, const NU: usize>(
    model: &M,
    q0: SVector<f64, N>,
    v0: SVector<f64, N>,
    sampling: Sampling,
) -> Result<Reference<N>>
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>>,
{
    let Sampling {
        plant_tau,
        period: sample_period,
        t_end,
        noise,
        seed,
    } = sampling;
    let every = (sample_period / plant_tau).round() as usize;
    assert!(
        every >= 1,
        "the sampling period is shorter than the plant step"
    );
    let stepper = MoreauJean::new(StepParams::new(plant_tau))?;
    let mut state = State::new(0.0, q0, v0);
    let mut rng = Gaussian::new(seed);
    let mut out = Reference {
        t: vec![],
        q: vec![],
        v: vec![],
        measured: vec![],
        impacts: vec![],
    };
    let u = SVector::<f64, NU>::zeros();
    let steps = (t_end / plant_tau).round() as usize;
    for k in 0..=steps {
        if k % every == 0 {
            // the sample time is k τ, free of accumulated rounding
            let t = k as f64 * plant_tau;
            out.t.push(t);
            out.q.push(state.q);
            out.v.push(state.v);
            out.measured
                .push(state.q + SVector::from_fn(|_, _| noise * rng.next()));
        }
        if k < steps {
            let report = stepper.step(model, &mut state, &u)?;
            out.impacts.extend(report.impacts());
        }
    }
    Ok(out)
}

/// Standard normal numbers from xorshift64* and the Box–Muller transform:
/// deterministic, so every run of an example draws the same noise.
pub struct Gaussian {
    state: u64,
    spare: Option<f64>,
}

impl Gaussian {
    /// A generator seeded with `seed` (any value).
    pub fn new(seed: u64) -> Self {
        Self {
            state: seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1,
            spare: None,
        }
    }

    fn uniform(&mut self) -> f64 {
        self.state ^= self.state >> 12;
        self.state ^= self.state << 25;
        self.state ^= self.state >> 27;
        let bits = self.state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        (bits as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// The next standard normal number.
    pub fn next(&mut self) -> f64 {
        if let Some(x) = self.spare.take() {
            return x;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let a = std::f64::consts::TAU * u2;
        self.spare = Some(r * a.sin());
        r * a.cos()
    }
}

/// Groups impacts closer than `gap` seconds into episodes: (first, last,
/// count). An accumulation of impacts is one long episode.
pub fn episodes(impacts: &[Impact<f64>], gap: f64) -> Vec<(f64, f64, usize)> {
    let mut out: Vec<(f64, f64, usize)> = Vec::new();
    for i in impacts {
        match out.last_mut() {
            Some(e) if i.t - e.1 <= gap => {
                e.1 = i.t;
                e.2 += 1;
            }
            _ => out.push((i.t, i.t, 1)),
        }
    }
    out
}
