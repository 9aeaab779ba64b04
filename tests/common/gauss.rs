//! A tiny deterministic Gaussian generator, one source for the integration
//! tests (`tests/common/runs.rs`, which re-exports it), the examples that
//! reuse those runs, and the runtime's unit tests (`runtime/src/testing.rs`);
//! each includes this file by path.

/// A tiny deterministic Gaussian generator: xorshift64* and Box–Muller.
pub struct Gauss {
    state: u64,
    spare: Option<f64>,
}

impl Gauss {
    pub fn new(seed: u64) -> Self {
        Self {
            state: seed.max(1),
            spare: None,
        }
    }

    /// Uniform in (0, 1].
    pub fn uniform(&mut self) -> f64 {
        self.state ^= self.state >> 12;
        self.state ^= self.state << 25;
        self.state ^= self.state >> 27;
        let x = self.state.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((x >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    /// Standard normal.
    pub fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let angle = 2.0 * core::f64::consts::PI * u2;
        self.spare = Some(r * angle.sin());
        r * angle.cos()
    }
}
