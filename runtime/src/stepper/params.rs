//! The knobs of a Moreau–Jean step.

use nalgebra::RealField;

/// Settings of the Moreau–Jean θ-method ([`MoreauJean`](super::MoreauJean)).
///
/// One `Copy` struct of knobs, each with its default, what moving it does,
/// and a builder method (`with_…`). [`StepParams::new`] takes Siconos'
/// `θ`, `γ` and Newton loop (`MoreauJeanOSI(0.5, 0.5)` in a `TimeStepping`
/// with its default Newton loop) but **not** Siconos' evaluation points nor
/// its Newton's law: the default is the energy-consistent midpoint step,
/// [`ApproachVelocity::Midpoint`], under which a run with `e = 1` and no
/// damping keeps its energy without drift (Siconos' θ-method gains energy
/// when `M` depends on `q`; see the table of [`ApproachVelocity`]).
/// [`StepParams::siconos`] is Siconos' settings in full
/// ([`ApproachVelocity::Start`]), for step-by-step agreement with it.
///
/// ```
/// use moreau_runtime::{ApproachVelocity, StepParams};
///
/// let ours = StepParams::new(1e-3);
/// assert_eq!(ours.approach_velocity, ApproachVelocity::Midpoint);
/// let siconos = StepParams::siconos(1e-3);
/// assert_eq!(siconos, ours.with_approach_velocity(ApproachVelocity::Start));
/// // every setting has its builder
/// let stiff = StepParams::new(1e-4)
///     .with_theta(1.0)
///     .with_gamma(0.0)
///     .with_newton_tolerance(1e-10)
///     .with_newton_iterations(1);
/// assert_eq!((stiff.theta, stiff.gamma, stiff.newton_iterations), (1.0, 0.0, 1));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepParams<T> {
    /// Time step `τ > 0` (no default; [`StepParams::new`] takes it).
    pub tau: T,
    /// `θ ∈ (0, 1]` of the θ-method (default `0.5`): forces are weighted
    /// `(1 − θ)` at the start of the step and `θ` at its end, and the
    /// position is updated with `θ v_{k+1} + (1 − θ) v_k`. `0.5` is second
    /// order on smooth stretches and conserves energy best; `1` is
    /// backward Euler, the most dissipative.
    pub theta: T,
    /// `γ ∈ [0, 1]` of the index-set prediction (default `0.5`): constraint
    /// `α` takes part in the step when `h_α(q_k) + γ τ J_α(q_k) v_k ≤ 0`.
    /// Larger `γ` looks further ahead (contacts are caught earlier, gaps
    /// stay positive more often); `0` activates only on penetration.
    pub gamma: T,
    /// Newton tolerance on `‖M(q)(v − v_k) + τ[θ F + (1 − θ) F_k] − Jᵀλ‖₂`
    /// (default `1e-6`, Siconos' absolute tolerance in impulse units).
    pub newton_tolerance: T,
    /// Largest number of Newton iterations per step (default `50`, as
    /// Siconos). `1` gives a fixed cost per step: the linearly implicit
    /// scheme, exact for constant `M` and forces.
    pub newton_iterations: u32,
    /// How Newton's law measures the normal velocity before the step, and
    /// where the step evaluates `M`, `F` and `J` (default
    /// [`ApproachVelocity::Midpoint`], the energy-consistent step).
    pub approach_velocity: ApproachVelocity,
}

/// The normal velocity `u` before the step in Newton's law
/// `0 ≤ λ ⊥ J(q̃) v_{k+1} + e ⊙ u ≥ 0`, where `q̃` is the Newton iterate at
/// which the step measures `v_{k+1}` (`q_k + τ v_k` in the first iteration);
/// or, with [`ApproachVelocity::Midpoint`], the energy-consistent step that
/// moves the whole step, not only the law, to the midpoint.
///
/// Between `q_k` and `q̃` the normal of a curved constraint turns, so the
/// two natural measurements of the approach, `J(q_k) v_k` and `J(q̃) v_k`,
/// differ by `τ v_kᵀ ∇²h v_k`. Which one `e` multiplies matters:
///
/// | | `Start` (Siconos) | `Iterate` | `Slower` | `Midpoint` (default) |
/// |---|---|---|---|---|
/// | `u` | `J(q_k) v_k` | `J(q̃) v_k` | `max(J(q_k) v_k, J(q̃) v_k)` | see below |
/// | sliding on a curved surface | stays on it | bounces off it (`e` times the curvature term, every step) | stays on it | stays on it |
/// | `e = 1` impacts on a dispersing obstacle | gains energy at every impact, without bound | keeps the energy exactly | keeps the energy exactly | keeps the energy exactly |
/// | kinetic energy at an impact, no other force | may grow | may grow (sliding kicks) | never grows (one constraint) | never grows (any number of constraints) |
/// | `e = 1`, configuration-dependent `M(q)` (double pendulum, `τ = 1e-3`) | runs away, LCP fails at 369 s | runs away, LCP fails at 580 s | runs away, LCP fails at 628 s | bounded, within `3.5e-4 J` over `10⁷` steps |
///
/// With `u = max(…)`, one constraint and no other force, the kinetic energy
/// changes at an impact by `½ λ (J v_k − e u) ≤ 0`: the law never creates
/// energy, equals Siconos' while sliding (`J(q_k) v_k ≈ 0`) and the
/// same-Jacobian law at an impact on a dispersing obstacle.
///
/// The first three laws share Siconos' θ-method, whose free flight gains
/// energy when `M` depends on `q`: with `e = 1` and no damping the double
/// pendulum and the three-link arm run away under all three, and on the
/// curved floor of Example 1 `Slower` loses the energy instead (84.24 J to
/// 1.53 J over 10⁷ steps). [`ApproachVelocity::Midpoint`], the default,
/// keeps the energy of every shipped model (README, "Energy"); choose
/// `Start` ([`StepParams::siconos`]) to reproduce Siconos step by step, and
/// `Slower` or `Iterate` only to compare with the θ-method. The module
/// documentation of [`MoreauJean`](super::MoreauJean) gives the
/// measurements and the scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ApproachVelocity {
    /// `u = J(q_k) v_k`, as Siconos' `MoreauJeanOSI` does (its
    /// `NewtonImpactNSL` uses the output `J(q_k) v_k` of the previous step):
    /// for step-by-step agreement with Siconos.
    Start,
    /// `u = J(q̃) v_k`: both velocities along the same normals.
    Iterate,
    /// `u = max(J(q_k) v_k, J(q̃) v_k)`, per constraint: the slower of the
    /// two approaches.
    Slower,
    /// The energy-consistent step (Moreau's midpoint scheme, with the
    /// impact law written at the midpoint velocity as in Acary's energy
    /// analysis of Moreau–Jean): `M`, `F` and `J` evaluated at the θ-point
    /// `q_θ = q_k + θ (q_{k+1} − q_k)` (the midpoint for `θ = ½`), the force
    /// term `τ [F(t_k + θτ, q_θ, v_θ) + ¼ C(q_θ, Δv)ᵀ Δv]` in place of the
    /// θ-weighted `F`, and Newton's law
    /// `0 ≤ λ ⊥ J(q_θ)(v_{k+1} + v_k) − (1 − e) ⊙ min(J(q_k) v_k, 0) ≥ 0`.
    ///
    /// With `θ = ½` the work of the impulses in a step is
    /// `½ (1 − e) ⊙ min(J(q_k) v_k, 0) · λ ≤ 0`, zero for `e = 1`, and the
    /// free flight is the implicit midpoint rule (symmetric: no secular
    /// drift). On a curved surface `J(q_θ) v_k = J(q_k) v_k + O(τ)`; only
    /// the approach `J(q_k) v_k` is scaled by `e`, the curvature part is
    /// reflected whole, so a sliding contact stays on its surface.
    ///
    /// The default ([`StepParams::new`]).
    #[default]
    Midpoint,
}

impl<T: RealField + Copy> StepParams<T> {
    /// Time step `tau` with the defaults: Siconos' `θ`, `γ` and Newton loop
    /// (`θ = γ = 0.5`, Newton tolerance `1e-6`, 50 iterations) and the
    /// energy-consistent midpoint step, [`ApproachVelocity::Midpoint`]
    /// (Siconos' θ-method and law are [`ApproachVelocity::Start`]: see
    /// [`StepParams::siconos`]).
    #[must_use]
    pub fn new(tau: T) -> Self {
        Self {
            tau,
            theta: nalgebra::convert(0.5),
            gamma: nalgebra::convert(0.5),
            newton_tolerance: nalgebra::convert(1e-6),
            newton_iterations: 50,
            approach_velocity: ApproachVelocity::Midpoint,
        }
    }

    /// Siconos' settings in full, its Newton's law included: [`new`](Self::new)
    /// with [`ApproachVelocity::Start`]. With these the stepper agrees with
    /// Siconos' `MoreauJeanOSI` step by step (`tests/plant.rs`).
    #[must_use]
    pub fn siconos(tau: T) -> Self {
        Self::new(tau).with_approach_velocity(ApproachVelocity::Start)
    }

    /// The same settings with time step `τ`.
    #[must_use]
    pub fn with_tau(self, tau: T) -> Self {
        Self { tau, ..self }
    }

    /// The same settings with `θ` (see [`theta`](Self::theta)).
    #[must_use]
    pub fn with_theta(self, theta: T) -> Self {
        Self { theta, ..self }
    }

    /// The same settings with `γ` (see [`gamma`](Self::gamma)).
    #[must_use]
    pub fn with_gamma(self, gamma: T) -> Self {
        Self { gamma, ..self }
    }

    /// The same settings with this Newton tolerance (see
    /// [`newton_tolerance`](Self::newton_tolerance)).
    #[must_use]
    pub fn with_newton_tolerance(self, newton_tolerance: T) -> Self {
        Self {
            newton_tolerance,
            ..self
        }
    }

    /// The same settings with at most this many Newton iterations (see
    /// [`newton_iterations`](Self::newton_iterations)).
    #[must_use]
    pub fn with_newton_iterations(self, newton_iterations: u32) -> Self {
        Self {
            newton_iterations,
            ..self
        }
    }

    /// The same settings with this Newton's law (see [`ApproachVelocity`]).
    #[must_use]
    pub fn with_approach_velocity(self, approach_velocity: ApproachVelocity) -> Self {
        Self {
            approach_velocity,
            ..self
        }
    }
}
