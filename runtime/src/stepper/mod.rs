//! The Moreau–Jean time-stepper for the measure differential inclusion (8),
//!
//! $$M(q)\,dv + F(t, q, v)\,dt \in -N_{V(q)}(v_e),\qquad dq = v\,dt,$$
//!
//! as Siconos' `MoreauJeanOSI` in a `TimeStepping` simulation does it, so
//! that the two agree step by step on the same model (see
//! `tests/plant.rs` and `tests/reference/siconos_notes.md`).
//!
//! # One step, from `(t_k, q_k, v_k)` to `t_{k+1} = t_k + τ`
//!
//! 1. **Index set** (γ-prediction): constraint `α` takes part when
//!    `h_α(q_k) + γ τ J_α(q_k) v_k ≤ 0`.
//! 2. **Newton loop**, from the first iterate `q̃ = q_k + τ v_k`, `ṽ = v_k`:
//!    - iteration matrix `W = M(q̃) + τθ ∂F/∂v + τ²θ² ∂F/∂q`, the
//!      Jacobians at `(t_{k+1}, q̃, ṽ)`. This is how configuration- and
//!      velocity-dependent forces are treated: linearly implicit, with the
//!      Jacobians of `F` the model provides ([`Model::linearization`]),
//!      exactly Siconos' `W` for `FInt` and `FGyr`; like Siconos, no
//!      `∂(M(q) v)/∂q` term;
//!    - free velocity `v_free = ṽ − W⁻¹ R`, with the residual
//!      `R = M(q̃)(ṽ − v_k) + τ[θ F(t_{k+1}, q̃, ṽ) + (1 − θ) F(t_k, q_k, v_k)]`
//!      (with [`ApproachVelocity::Midpoint`], `M`, `F` and `J` are
//!      evaluated at the θ-point of the step instead, see below);
//!    - impulses from the LCP on the index set, Newton's law per
//!      constraint:
//!      `0 ≤ λ ⊥ J(q̃) v_{k+1} + e u ≥ 0` with
//!      `v_{k+1} = v_free + W⁻¹ J(q̃)ᵀ λ`, where the approach velocity `u`
//!      is `J(q_k) v_k` in Siconos ([`ApproachVelocity::Start`]), or the
//!      slower of `J(q_k) v_k` and `J(q̃) v_k` ([`ApproachVelocity::Slower`];
//!      see [`ApproachVelocity`] for why; the default, the midpoint step, is
//!      below);
//!    - position `q_{k+1} = q_k + τ (θ v_{k+1} + (1 − θ) v_k)`;
//!    - stop when `‖M(q_{k+1})(v_{k+1} − v_k) + τ[θ F_{k+1} + (1 − θ) F_k] − Jᵀλ‖₂`
//!      is at most the tolerance, or after the last allowed iteration;
//!      else iterate from `(q̃, ṽ) = (q_{k+1}, v_{k+1})`.
//!
//! On a smooth stretch the scheme is the θ-method; at an impact the LCP
//! gives Newton's law with the post-impact velocity of (9f); across an
//! accumulation of impacts (Zeno) it needs no event detection, and on a
//! constraint surface (sliding) the velocity-level law keeps `J v ≥ 0`, so
//! the gap drifts by `O(τ)` at most.
//!
//! The caller holds the state `(t, q, v)` and the stepper only settings: a
//! step is a pure function of them, and a step that fails leaves the state
//! as it was.
//!
//! # Energy: the midpoint step ([`ApproachVelocity::Midpoint`], the default)
//!
//! The steps above (Siconos' scheme, under any of the laws `Start`,
//! `Iterate`, `Slower`) gain energy when `M` depends on `q`. Measured on
//! the double pendulum (`DoublePendulum`, `e = 1`, `b = 0`, `τ = 1e-3`,
//! 100 s from its initial state, energy `½ vᵀM(q)v + V(q)`, `E₀ = −18.97 J`),
//! each step's energy change sorted by whether an impulse acted in it:
//!
//! | scheme | total | impact steps (≈ 250) | free-flight steps (≈ 99,750) |
//! |---|---|---|---|
//! | θ-method, `Start` | +5.3 J | +2.1 J (mean +8.3e-3 J, from −3.1e-2 to +8.1e-2) | +3.2 J (mean +3.2e-5 J) |
//! | θ-method, `Slower` | +1.9 J | −0.68 J (mean −2.8e-3 J, from −2.2e-2 to +7.0e-3) | +2.6 J (mean +2.6e-5 J) |
//! | midpoint, without the `¼ C(Δv)ᵀΔv` term | +1.8e-3 J | +1.7e-3 J (from −4.1e-3 to +4.2e-3) | +1.2e-4 J |
//! | midpoint ([`ApproachVelocity::Midpoint`]) | +6.0e-5 J | −3.4e-5 J (from −2.9e-5 to +3.1e-5) | +9.4e-5 J (largest step 6.3e-7 J) |
//!
//! The θ-method's free flight is the main source: it evaluates the mass
//! matrix at the end of the step (`M(q_{k+1})(v_{k+1} − v_k)`) and the
//! forces, Coriolis included, by the trapezoidal rule, which is not
//! symmetric in time when `M` varies. Without any contact (walls moved
//! away) it gains +1.2e-2 J in 100 s at rest-start and +11.9 J from
//! `v₀ = (3, −4)` (+0.92 J at `τ = 1e-4`); `θ = 0.55` loses −0.55 J
//! instead: energy behaviour is set by the scheme, not by round-off. The
//! impacts throw the pendulum into fast motion, where that drift is
//! largest; the laws `Start` and `Slower` then add or remove energy at
//! each impact as well (second column). With the θ-method the run ends in
//! `LcpError::NotPositiveSemidefinite` at t = 369 s (`Start`), 580.4 s
//! (`Iterate`) and 628.4 s (`Slower`).
//!
//! The midpoint step keeps the structure above (γ-prediction, one LCP per
//! Newton iteration, `q_{k+1} = q_k + τ (θ v_{k+1} + (1 − θ) v_k)`, the same
//! iteration matrix `W`) and moves the evaluation of `M`, `F` and `J` to the
//! θ-point `q_θ = q_k + θ (q_{k+1} − q_k)`, `v_θ = v_k + θ (v_{k+1} − v_k)`,
//! as Moreau's midpoint scheme does (J. J. Moreau, *Unilateral contact and
//! dry friction in finite freedom dynamics*, CISM Courses and Lectures 302,
//! Springer 1988, pp. 1–82; its first Newton iterate evaluates at
//! `q_k + θτ v_k`, Moreau's `q_M` for `θ = ½`):
//!
//! $$M(q_θ)(v_{k+1} − v_k) + τ\big[F(t_k + θτ, q_θ, v_θ) + \tfrac14 C(q_θ, Δv)^\top Δv\big] = J(q_θ)^\top λ,$$
//! $$0 ≤ λ ⊥ J(q_θ)(v_{k+1} + v_k) − (1 − e) ⊙ \min(J(q_k) v_k, 0) ≥ 0,$$
//!
//! with `Δv = v_{k+1} − v_k`. For `θ = ½`:
//!
//! - **impacts**: as in Acary's energy balance of the Moreau–Jean scheme
//!   (V. Acary, *Energy conservation and dissipation properties of
//!   time-integration methods for nonsmooth elastodynamics with contact*,
//!   ZAMM 96(5):585–603, 2016, doi:10.1002/zamm.201400231), the work of the
//!   impulses is the midpoint velocity times the impulse,
//!   `J(q_θ) ½(v_{k+1} + v_k) · λ`, which the law makes
//!   `½ (1 − e) min(J(q_k) v_k, 0) · λ`: zero for `e = 1`, never positive;
//! - **kinetic energy across a jump**: since the Christoffel symbols are
//!   symmetric, `xᵀ C(q, a) x = ½ xᵀ (Σᵢ aᵢ ∂M/∂qᵢ) x` and
//!   `C(q, a) b = C(q, b) a` for any `a`, `b`, `x` (this needs `C` in the
//!   Christoffel form [`Model::coriolis`] documents and `model!`
//!   generates); the term
//!   `¼ C(q_θ, Δv)ᵀ Δv` supplies `¼ Δvᵀ C(q_θ, v_θ) Δv`, the part of
//!   `½ v_{k+1}ᵀM(q_{k+1})v_{k+1} − ½ v_kᵀM(q_k)v_k` that the midpoint
//!   Coriolis force misses when `Δv` is not small. It is `O(τ²)` on smooth
//!   stretches (second order is kept) and turns the per-impact error from
//!   `O(τ)` into `O(τ²)` (largest per impact over 10³ s at `τ = 1e-3`:
//!   4.2e-3 J without it, 3.2e-5 J with it; 4.9e-7 J at `τ = 1e-4`); this is our derivation, in the spirit of the
//!   discrete gradients of energy-consistent integrators, not Moreau's;
//! - **free flight**: the implicit midpoint rule, symmetric and
//!   `ρ`-reversible (`ρ(q, v) = (q, −v)`), so its energy error is an
//!   `O(τ²)` oscillation without secular drift; the γ-prediction with
//!   `γ = ½` already predicts the gap at the midpoint.
//!
//! Over `10⁷` steps (`10⁴` s, 25,285 impact steps) the double pendulum's
//! energy stays between `E₀ − 3.5e-4 J` and `E₀ + 1.8e-4 J`, with no
//! trend; `examples/soak.rs` measures every shipped model. It is the
//! default of [`StepParams::new`], since a run with the defaults must not
//! gain energy; the first three laws stay as they were, `Start`
//! ([`StepParams::siconos`]) step for step with Siconos.

mod error;
mod params;
mod report;

pub use error::StepError;
pub use params::{ApproachVelocity, StepParams};
pub use report::{Impact, StepReport};

use nalgebra::{RealField, SMatrix, SVector};

use crate::error::DataError;
use crate::lcp::{IndexSet, Lcp};
use crate::linalg::{Ldlt, Lu};
use crate::model::{Linearization, Model};
use crate::state::State;
use crate::validate;

/// The Moreau–Jean stepper: settings and nothing else.
///
/// ```
/// use moreau_runtime::{Model, ModelInfo, MoreauJean, State, StepParams};
/// use nalgebra::{Matrix1, SVector, Vector1};
///
/// /// A unit ball above the floor y = 0, restitution 0.5.
/// struct Ball;
/// impl Model<1, 1> for Ball {
///     type Scalar = f64;
///     type Input = SVector<f64, 0>;
///     const INFO: ModelInfo<1, 1> = ModelInfo {
///         name: "Ball", coordinates: ["y"], velocities: ["vy"], constraints: ["floor"],
///         parameters: &[], inputs: &[], source: "", op_count: 0,
///     };
///     fn mass(&self, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
///     fn coriolis(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
///     fn gravity(&self, _: &Vector1<f64>) -> Vector1<f64> { Vector1::new(9.81) }
///     fn forces(&self, _: f64, q: &Vector1<f64>, _: &Vector1<f64>, _: &SVector<f64, 0>) -> Vector1<f64> {
///         self.gravity(q)
///     }
///     fn gaps(&self, q: &Vector1<f64>) -> Vector1<f64> { *q }
///     fn gap_jacobian(&self, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
///     fn restitution(&self) -> Vector1<f64> { Vector1::new(0.5) }
///     fn parameter(&self, _: usize) -> Option<f64> { None }
///     fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> { None }
/// }
///
/// let stepper = MoreauJean::new(StepParams::new(1e-3))?;
/// let mut state = State::new(0.0, Vector1::new(1.0), Vector1::new(0.0));
/// let mut bounces = 0;
/// while state.t < 1.0 {
///     let report = stepper.step(&Ball, &mut state, &SVector::zeros())?;
///     bounces += report.impacts().count();
/// }
/// // dropped from 1 m, the ball lands after √(2/9.81) = 0.45 s, leaves at
/// // half its speed and lands again 0.45 s later
/// assert_eq!(bounces, 2);
/// assert!(state.q[0] >= -1e-3);
/// # Ok::<(), moreau_runtime::StepError<f64>>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoreauJean<T> {
    params: StepParams<T>,
    lcp: Lcp<T>,
}

impl<T: RealField + Copy> MoreauJean<T> {
    /// A stepper with these settings, after checking them.
    ///
    /// # Errors
    ///
    /// [`StepError::Data`] with [`DataError::InvalidParams`] when a setting is
    /// out of its range.
    pub fn new(params: StepParams<T>) -> Result<Self, StepError<T>> {
        check_params(&params)?;
        Ok(Self {
            params,
            lcp: Lcp::default(),
        })
    }

    /// The settings.
    pub fn params(&self) -> &StepParams<T> {
        &self.params
    }

    /// The same stepper with another LCP solver setting.
    #[must_use]
    pub fn with_lcp(self, lcp: Lcp<T>) -> Self {
        Self { lcp, ..self }
    }

    /// Advances `state` by one step `τ` under the known input `u`, and says
    /// what happened.
    ///
    /// # Time
    ///
    /// When `state.t` is a multiple of `τ` (to a few rounding errors, as
    /// from `t = 0`), the new time is the correctly rounded `(k + 1) τ`:
    /// `t_k` never drifts from `kτ` by more than half a unit in the last
    /// place, however long the run (no rounding error gathers from adding
    /// `τ` at every step). From any other time, `t + τ`.
    ///
    /// A step is refused with [`StepError::TimeDoesNotAdvance`], before
    /// anything changes, when the scalar type resolves `τ` at `t` too
    /// coarsely to keep time (`16 ε |t| ≥ τ`, which includes `t + τ == t`;
    /// past it, adding `τ` rounds by a large part of a step, and summed time
    /// runs percents slow or fast): in `f32` with `τ = 1` ms that is from
    /// `t ≈ 524` s on (`f64`: `2.8e11` s). To run
    /// longer, keep `t` relative to an epoch that the caller moves: every
    /// so often (a multiple of `τ`, say every 1000 s) subtract it from
    /// `state.t` and add it to the epoch, which the caller holds in a wider
    /// type (an integer count of steps or an `f64`); a model whose forces
    /// depend on `t` then takes the epoch as a parameter or input.
    ///
    /// ```
    /// use moreau_runtime::{Model, ModelInfo, MoreauJean, State, StepError, StepParams};
    /// use nalgebra::{Matrix1, SVector, Vector1};
    ///
    /// /// A unit mass pulled by gravity, no constraint.
    /// struct Fall;
    /// impl Model<1, 0> for Fall {
    ///     type Scalar = f32;
    ///     type Input = SVector<f32, 0>;
    ///     const INFO: ModelInfo<1, 0> = ModelInfo {
    ///         name: "Fall", coordinates: ["y"], velocities: ["vy"], constraints: [],
    ///         parameters: &[], inputs: &[], source: "", op_count: 0,
    ///     };
    ///     fn mass(&self, _: &Vector1<f32>) -> Matrix1<f32> { Matrix1::new(1.0) }
    ///     fn coriolis(&self, _: &Vector1<f32>, _: &Vector1<f32>) -> Matrix1<f32> { Matrix1::zeros() }
    ///     fn gravity(&self, _: &Vector1<f32>) -> Vector1<f32> { Vector1::new(9.81) }
    ///     fn forces(&self, _: f32, q: &Vector1<f32>, _: &Vector1<f32>, _: &SVector<f32, 0>) -> Vector1<f32> {
    ///         self.gravity(q)
    ///     }
    ///     fn gaps(&self, _: &Vector1<f32>) -> SVector<f32, 0> { SVector::zeros() }
    ///     fn gap_jacobian(&self, _: &Vector1<f32>) -> nalgebra::SMatrix<f32, 0, 1> { nalgebra::SMatrix::zeros() }
    ///     fn restitution(&self) -> SVector<f32, 0> { SVector::zeros() }
    ///     fn parameter(&self, _: usize) -> Option<f32> { None }
    ///     fn parameter_mut(&mut self, _: usize) -> Option<&mut f32> { None }
    /// }
    ///
    /// let stepper = MoreauJean::new(StepParams::new(1e-3_f32))?;
    /// let u = SVector::zeros();
    /// // at t = 32768 s, f32 cannot tell t + 1 ms from t: refused, unchanged
    /// // (and so is every step from t = 524 s on)
    /// let mut late = State::new(32768.0_f32, Vector1::new(0.0), Vector1::new(0.0));
    /// let err = stepper.step(&Fall, &mut late, &u).unwrap_err();
    /// assert!(matches!(err, StepError::TimeDoesNotAdvance { .. }));
    /// assert_eq!(late.t, 32768.0);
    /// // the same run on a moving epoch: whole seconds held in an integer
    /// let (mut epoch_s, mut state) = (32768_u64, State::new(0.0_f32, Vector1::new(0.0), Vector1::new(0.0)));
    /// for _ in 0..2500 {
    ///     stepper.step(&Fall, &mut state, &u)?;
    ///     if state.t >= 1.0 {
    ///         state.t -= 1.0; // exact: t is (k τ) rounded, and 1 s = 1000 τ
    ///         epoch_s += 1;
    ///     }
    /// }
    /// assert_eq!(epoch_s, 32770);
    /// assert!((state.t - 0.5).abs() < 1e-6);
    /// # Ok::<(), StepError<f32>>(())
    /// ```
    ///
    /// # Errors
    ///
    /// A [`StepError`] naming the problem; `state` is then unchanged.
    pub fn step<M, const N: usize, const K: usize>(
        &self,
        model: &M,
        state: &mut State<T, N>,
        u: &M::Input,
    ) -> Result<StepReport<T, K>, StepError<T>>
    where
        M: Model<N, K, Scalar = T>,
    {
        check_inputs(model, state, u)?;
        let t_next = self.next_time(state.t)?;
        // INDEX SET by γ-prediction, and what the step keeps from its start
        let start = self.begin(model, state, t_next, u)?;
        let mut report = StepReport::new(start.t_next, start.active);
        // NEWTON, from the first iterate (q_k + τ v_k, v_k)
        let mut iterate = (start.q + start.v * self.params.tau, start.v);
        loop {
            let next = self.iterate(model, &start, iterate, u)?;
            report.record(&next.impulse);
            report.newton_residual = self.residual(model, &start, &next, u);
            report.converged = report.newton_residual <= self.params.newton_tolerance;
            iterate = (next.q, next.v);
            if report.converged || report.newton_iterations >= self.params.newton_iterations {
                break;
            }
        }
        // WRITEBACK: only a finite result replaces the caller's state
        let (q, v) = iterate;
        if !(q.iter().all(|x| x.is_finite())
            && v.iter().all(|x| x.is_finite())
            && start.t_next.is_finite())
        {
            return Err(DataError::NonFiniteResult.into());
        }
        *state = State::new(start.t_next, q, v);
        Ok(report)
    }

    /// The time at the end of a step from `t`: on the grid `kτ` when `t` is
    /// on it (to a few rounding errors), so that a run from `t = 0` (or any
    /// multiple of `τ`) keeps `t_k` the correctly rounded `kτ` however long
    /// it runs, instead of gathering one rounding error per step; `t + τ`
    /// otherwise.
    ///
    /// # Errors
    ///
    /// [`StepError::TimeDoesNotAdvance`] when the scalar type resolves `τ`
    /// at `t` too coarsely to keep time: `16 ε |t| ≥ τ`, which includes
    /// `t + τ == t`. Below it, the spacing of the numbers near `t` is under
    /// `τ/16`, `t/τ` is within `0.1` of its integer `k`, and the grid is
    /// found again at every step.
    fn next_time(&self, t: T) -> Result<T, StepError<T>> {
        let tau = self.params.tau;
        let eps = T::default_epsilon();
        // t is finite (checked) and τ positive: no NaN here
        let sixteen: T = nalgebra::convert(16.0);
        if sixteen * eps * t.abs() >= tau || t + tau == t {
            return Err(StepError::TimeDoesNotAdvance { t, tau });
        }
        let k = (t / tau).round();
        let four: T = nalgebra::convert(4.0);
        if (t - k * tau).abs() <= four * eps * t.abs().max(tau) {
            Ok((k + T::one()) * tau)
        } else {
            Ok(t + tau)
        }
    }

    /// The start of a step: the index set by γ-prediction,
    /// `h(q_k) + γ τ J(q_k) v_k ≤ 0`, and the terms every Newton iteration
    /// reuses.
    fn begin<M, const N: usize, const K: usize>(
        &self,
        model: &M,
        state: &State<T, N>,
        t_next: T,
        u: &M::Input,
    ) -> Result<Start<T, N, K>, StepError<T>>
    where
        M: Model<N, K, Scalar = T>,
    {
        let State { t, q, v } = *state;
        let (gaps, jac) = model.contact(&q);
        finite_matrix(&gaps, "h")?;
        finite_matrix(&jac, "J")?;
        let normal_velocity = jac * v;
        // F(t_k, q_k, v_k) enters only the θ-method's residual; the midpoint
        // step evaluates F at the θ-point alone
        let forces = if self.params.approach_velocity == ApproachVelocity::Midpoint {
            SVector::zeros()
        } else {
            let forces = model.forces(t, &q, &v, u);
            finite_matrix(&forces, "F")?;
            forces
        };
        Ok(Start {
            t,
            t_next,
            q,
            v,
            normal_velocity,
            forces,
            restitution: model.restitution(),
            active: predict_index_set(&gaps, &normal_velocity, self.params.gamma * self.params.tau),
        })
    }

    /// One Newton iteration from the iterate `(q̃, ṽ)`: the iteration matrix
    /// `W`, the free velocity, the impulses of the LCP, then the velocity
    /// `v_{k+1} = v_free + W⁻¹ Jᵀ λ` and the position
    /// `q_{k+1} = q_k + τ (θ v_{k+1} + (1 − θ) v_k)`.
    fn iterate<M, const N: usize, const K: usize>(
        &self,
        model: &M,
        start: &Start<T, N, K>,
        (q, v): (SVector<T, N>, SVector<T, N>),
        u: &M::Input,
    ) -> Result<Iterate<T, N, K>, StepError<T>>
    where
        M: Model<N, K, Scalar = T>,
    {
        let (tau, theta) = (self.params.tau, self.params.theta);
        // the point M, F and J are evaluated at: the iterate (q̃, ṽ), or the
        // θ-point of the step for the midpoint law
        let (t_e, q_e, v_e) = self.evaluation_point(start, &q, &v);
        let lin = if explicit_forces::<M, N, K>() {
            // ∂F/∂q = ∂F/∂v = 0 by the model's structure: W = M, and the
            // model need not compute the Jacobians
            let (mass, forces) = model.dynamics(t_e, &q_e, &v_e, u);
            Linearization {
                mass,
                forces,
                forces_dq: SMatrix::zeros(),
                forces_dv: SMatrix::zeros(),
            }
        } else {
            model.linearization(t_e, &q_e, &v_e, u)
        };
        let w = if explicit_forces::<M, N, K>() && M::STRUCTURE.mass_diagonal {
            Factor::Diagonal(validate::diagonal_mass(&lin.mass)?)
        } else {
            let mass = check_mass(&lin.mass)?;
            iteration_matrix(&lin.mass, mass, &lin.forces_dq, &lin.forces_dv, tau, theta)?
        };
        finite_matrix(&lin.forces, "F")?;
        // FREE VELOCITY: v_free = ṽ − W⁻¹ R(q̃, ṽ)
        let forces = self.step_forces(model, start, &q_e, &v, lin.forces);
        finite_matrix(&forces, "C")?;
        let residual = lin.mass * (v - start.v) + self.force_impulse(start, &forces);
        let v_free = v - solve(&w, &residual)?;
        // IMPULSES: Newton's law compares J v_{k+1} with the restitution
        // term; with no constraint in the index set there is nothing to
        // compare (J(q_k) was checked finite at the start)
        if start.active.is_empty() {
            let v_next = v_free;
            return Ok(Iterate {
                q: update_position(&start.q, &start.v, &v_next, tau, theta),
                v: v_next,
                jacobian: SMatrix::zeros(),
                impulse: Impulse::none(),
                dynamics: (lin.mass, lin.forces),
            });
        }
        let jac = model.gap_jacobian(&q_e);
        finite_matrix(&jac, "J")?;
        let restitution_term = match self.params.approach_velocity {
            ApproachVelocity::Start => start.restitution.component_mul(&start.normal_velocity),
            ApproachVelocity::Iterate => start.restitution.component_mul(&(jac * start.v)),
            ApproachVelocity::Slower => start
                .restitution
                .component_mul(&start.normal_velocity.sup(&(jac * start.v))),
            // J(q_θ) v_k − (1 − e) ⊙ min(J(q_k) v_k, 0)
            ApproachVelocity::Midpoint => {
                let approaching = start.normal_velocity.inf(&SVector::zeros());
                jac * start.v
                    - (SVector::repeat(T::one()) - start.restitution).component_mul(&approaching)
            }
        };
        let impulse = self.solve_impulses(&w, &jac, &v_free, &restitution_term, start.active)?;
        // UPDATE velocity, then position by the θ-method
        let v_next = v_free + impulse.velocity_change;
        let q_next = update_position(&start.q, &start.v, &v_next, tau, theta);
        Ok(Iterate {
            q: q_next,
            v: v_next,
            jacobian: jac,
            impulse,
            dynamics: (lin.mass, lin.forces),
        })
    }

    /// `τ [θ F(t_{k+1}, q, v) + (1 − θ) F(t_k, q_k, v_k)]`, from the force at
    /// the iterate.
    fn force_impulse<const N: usize, const K: usize>(
        &self,
        start: &Start<T, N, K>,
        forces: &SVector<T, N>,
    ) -> SVector<T, N> {
        let (tau, theta) = (self.params.tau, self.params.theta);
        if self.params.approach_velocity == ApproachVelocity::Midpoint {
            return forces * tau;
        }
        start.forces * (tau * (T::one() - theta)) + forces * (tau * theta)
    }

    /// The force of the step at its evaluation point: `F` itself, or, for
    /// [`ApproachVelocity::Midpoint`], `F + ¼ C(q_θ, Δv)ᵀ Δv` with
    /// `Δv = v − v_k`, the term that makes the kinetic energy's balance
    /// hold across a velocity jump (see the module docs).
    fn step_forces<M, const N: usize, const K: usize>(
        &self,
        model: &M,
        start: &Start<T, N, K>,
        q_e: &SVector<T, N>,
        v: &SVector<T, N>,
        forces: SVector<T, N>,
    ) -> SVector<T, N>
    where
        M: Model<N, K, Scalar = T>,
    {
        // with M constant the Christoffel symbols, and so C, vanish
        if self.params.approach_velocity != ApproachVelocity::Midpoint || M::STRUCTURE.mass_constant
        {
            return forces;
        }
        let jump = v - start.v;
        // no jump (the first Newton iterate, `ṽ = v_k`): the term is zero,
        // and `C(q, 0)ᵀ 0` costs a Coriolis matrix to find it
        if jump.iter().all(|x| x.is_zero()) {
            return forces;
        }
        forces + model.coriolis(q_e, &jump).tr_mul(&jump) * nalgebra::convert::<f64, T>(0.25)
    }

    /// Where a Newton iteration from the iterate `(q̃, ṽ)` evaluates `M`,
    /// `F` and `J`: at the iterate itself (Siconos), or, for
    /// [`ApproachVelocity::Midpoint`], at the θ-point of the step
    /// `(t_k + θτ, q_k + θ(q̃ − q_k), v_k + θ(ṽ − v_k))`.
    fn evaluation_point<const N: usize, const K: usize>(
        &self,
        start: &Start<T, N, K>,
        q: &SVector<T, N>,
        v: &SVector<T, N>,
    ) -> (T, SVector<T, N>, SVector<T, N>) {
        if self.params.approach_velocity != ApproachVelocity::Midpoint {
            return (start.t_next, *q, *v);
        }
        let theta = self.params.theta;
        (
            start.t + self.params.tau * theta,
            start.q + (q - start.q) * theta,
            start.v + (v - start.v) * theta,
        )
    }

    /// The Newton residual at the new iterate,
    /// `‖M(q)(v − v_k) + τ[θ F + (1 − θ) F_k] − Jᵀλ‖₂` (as Siconos tests it).
    fn residual<M, const N: usize, const K: usize>(
        &self,
        model: &M,
        start: &Start<T, N, K>,
        next: &Iterate<T, N, K>,
        u: &M::Input,
    ) -> T
    where
        M: Model<N, K, Scalar = T>,
    {
        let (t_e, q_e, v_e) = self.evaluation_point(start, &next.q, &next.v);
        // M constant and F free of q and v: the evaluation at the new
        // iterate (same time, same input) gives what the iteration had
        let (mass, forces) = if explicit_forces::<M, N, K>() && M::STRUCTURE.mass_constant {
            next.dynamics
        } else {
            model.dynamics(t_e, &q_e, &v_e, u)
        };
        // a non-finite term makes the residual NaN: not converged, and the
        // next iteration reports it
        let forces = self.step_forces(model, start, &q_e, &next.v, forces);
        let r = mass * (next.v - start.v) + self.force_impulse(start, &forces)
            - next.jacobian.transpose() * next.impulse.lambda;
        r.norm()
    }

    /// Solves the step's LCP on `active` and returns the impulses and the
    /// velocity change `W⁻¹ Jᵀ λ` they cause.
    fn solve_impulses<const N: usize, const K: usize>(
        &self,
        w: &Factor<T, N>,
        jac: &SMatrix<T, K, N>,
        v_free: &SVector<T, N>,
        restitution_term: &SVector<T, K>,
        active: IndexSet<K>,
    ) -> Result<Impulse<T, N, K>, StepError<T>> {
        if active.is_empty() {
            return Ok(Impulse::none());
        }
        let (delassus, w_inv_jt) = assemble_delassus(w, jac)?;
        // With force Jacobians in W, J W⁻¹ Jᵀ is not symmetric; the LCP is
        // posed with its symmetric part. For one active constraint that is
        // no change at all; for several, complementarity then holds up to
        // the skew part, O(τθ |∂F/∂v| / |M|) relative.
        let delassus = (delassus + delassus.transpose()) * nalgebra::convert::<f64, T>(0.5);
        let b = jac * v_free + restitution_term;
        let solution = self.lcp.solve(&delassus, &b, active)?;
        Ok(Impulse {
            lambda: solution.lambda,
            velocity_change: w_inv_jt * solution.lambda,
            trials: solution.trials,
            residual: solution.residual,
        })
    }
}

/// What a step keeps from its start `(t_k, q_k, v_k)`.
struct Start<T: RealField + Copy, const N: usize, const K: usize> {
    t: T,
    t_next: T,
    q: SVector<T, N>,
    v: SVector<T, N>,
    /// `J(q_k) v_k`.
    normal_velocity: SVector<T, K>,
    /// `F(t_k, q_k, v_k)` for the θ-method (zero, and unused, for the
    /// midpoint step).
    forces: SVector<T, N>,
    restitution: SVector<T, K>,
    /// The index set of the step.
    active: IndexSet<K>,
}

/// The outcome of one Newton iteration.
struct Iterate<T: RealField + Copy, const N: usize, const K: usize> {
    q: SVector<T, N>,
    v: SVector<T, N>,
    /// `J` at the iterate the impulses acted at (zero when no constraint
    /// is in the index set).
    jacobian: SMatrix<T, K, N>,
    impulse: Impulse<T, N, K>,
    /// `(M, F)` at the evaluation point of this iteration.
    dynamics: (SMatrix<T, N, N>, SVector<T, N>),
}

/// The outcome of the impact stage.
pub(super) struct Impulse<T: RealField + Copy, const N: usize, const K: usize> {
    lambda: SVector<T, K>,
    velocity_change: SVector<T, N>,
    trials: u32,
    residual: T,
}

impl<T: RealField + Copy, const N: usize, const K: usize> Impulse<T, N, K> {
    fn none() -> Self {
        Self {
            lambda: SVector::zeros(),
            velocity_change: SVector::zeros(),
            trials: 0,
            residual: T::zero(),
        }
    }
}

/// The γ-prediction index set `{α : h_α + γτ (J v)_α ≤ 0}`, from the gaps
/// `h`, the normal velocities `J v` and `γτ`.
///
/// ```
/// use moreau_runtime::predict_index_set;
/// use nalgebra::Vector3;
/// let gaps = Vector3::new(0.01, 0.01, -1e-9);
/// let normal_velocity = Vector3::new(-30.0, -1.0, 0.0);
/// let set = predict_index_set(&gaps, &normal_velocity, 0.5e-3);
/// // the first is predicted to close within the step, the second not, the
/// // third has penetrated
/// assert_eq!(set.iter().collect::<Vec<_>>(), [0, 2]);
/// ```
pub fn predict_index_set<T: RealField + Copy, const K: usize>(
    gaps: &SVector<T, K>,
    normal_velocity: &SVector<T, K>,
    gamma_tau: T,
) -> IndexSet<K> {
    let mut set = IndexSet::new();
    for i in 0..K {
        if gaps[i] + gamma_tau * normal_velocity[i] <= T::zero() {
            set.insert(i);
        }
    }
    set
}

/// Whether the model's structure proves `∂F/∂q = 0` and `∂F/∂v = 0`, so
/// that the step treats its forces explicitly (`W = M`) without asking the
/// model for the Jacobians.
const fn explicit_forces<M: Model<N, K>, const N: usize, const K: usize>() -> bool {
    M::STRUCTURE.forces_configuration_free && M::STRUCTURE.forces_velocity_free
}

/// A factored iteration matrix `W`.
enum Factor<T: RealField + Copy, const N: usize> {
    /// `W = M` diagonal (the model's structure proves it, and that the
    /// forces depend on neither `q` nor `v`): its diagonal. A solve is one
    /// division per coordinate, correctly rounded (the `L D Lᵀ` route
    /// divides the same way, after a factorization and two triangular
    /// sweeps that only subtract zeros).
    Diagonal(SVector<T, N>),
    /// `W = M` (forces that depend on neither `q` nor `v`): the `L D Lᵀ`
    /// factor the mass check already computed.
    Mass(Ldlt<T, N>),
    /// The general, non-symmetric `W`.
    Lu(Lu<T, N>),
}

/// `W = M + τθ ∂F/∂v + τ²θ² ∂F/∂q`, factored; `mass` is the `L D Lᵀ` factor
/// of `M`, reused when both Jacobians vanish. (Inlined: returned through
/// memory from a call, its factor costs a store-forwarding stall at the
/// first load.)
#[inline(always)]
fn iteration_matrix<T: RealField + Copy, const N: usize>(
    m: &SMatrix<T, N, N>,
    mass: Ldlt<T, N>,
    forces_dq: &SMatrix<T, N, N>,
    forces_dv: &SMatrix<T, N, N>,
    tau: T,
    theta: T,
) -> Result<Factor<T, N>, StepError<T>> {
    let zero = |a: &SMatrix<T, N, N>| a.iter().all(|x| *x == T::zero());
    if zero(forces_dq) && zero(forces_dv) {
        return Ok(Factor::Mass(mass));
    }
    let h_theta = tau * theta;
    let w = m + forces_dv * h_theta + forces_dq * (h_theta * h_theta);
    finite_matrix(&w, "W")?;
    Lu::new(&w)
        .map(Factor::Lu)
        .ok_or(StepError::SingularIterationMatrix)
}

/// `W⁻¹ x`.
#[inline(always)]
fn solve<T: RealField + Copy, const N: usize, const C: usize>(
    w: &Factor<T, N>,
    x: &SMatrix<T, N, C>,
) -> Result<SMatrix<T, N, C>, StepError<T>> {
    let x = match w {
        Factor::Diagonal(d) => {
            let mut x = *x;
            for mut column in x.column_iter_mut() {
                column.component_div_assign(d);
            }
            x
        }
        Factor::Mass(chol) => chol.solve(x),
        Factor::Lu(lu) => lu.solve(x),
    };
    if x.iter().all(|v| v.is_finite()) {
        Ok(x)
    } else {
        Err(StepError::SingularIterationMatrix)
    }
}

/// The Delassus matrix `J W⁻¹ Jᵀ` and `W⁻¹ Jᵀ`.
fn assemble_delassus<T: RealField + Copy, const N: usize, const K: usize>(
    w: &Factor<T, N>,
    jac: &SMatrix<T, K, N>,
) -> Result<(SMatrix<T, K, K>, SMatrix<T, N, K>), StepError<T>> {
    let w_inv_jt = solve(w, &jac.transpose())?;
    Ok((jac * w_inv_jt, w_inv_jt))
}

/// `q_{k+1} = q_k + τ (θ v_{k+1} + (1 − θ) v_k)`.
fn update_position<T: RealField + Copy, const N: usize>(
    q_k: &SVector<T, N>,
    v_k: &SVector<T, N>,
    v_next: &SVector<T, N>,
    tau: T,
    theta: T,
) -> SVector<T, N> {
    q_k + (v_next * theta + v_k * (T::one() - theta)) * tau
}

fn check_params<T: RealField + Copy>(p: &StepParams<T>) -> Result<(), StepError<T>> {
    let (zero, one) = (T::zero(), T::one());
    let bad = |name, value| Err(DataError::InvalidParams { name, value }.into());
    if !(p.tau > zero && p.tau.is_finite()) {
        return bad("tau", p.tau);
    }
    if !(p.theta > zero && p.theta <= one) {
        return bad("theta", p.theta);
    }
    // a τ so small that τ²θ², the weight of ∂F/∂q in W, underflows to zero
    // (τ = f64::MIN_POSITIVE) is out of range too
    let h = p.tau * p.theta;
    if h * h == zero {
        return bad("tau", p.tau);
    }
    if !(p.gamma >= zero && p.gamma <= one) {
        return bad("gamma", p.gamma);
    }
    if p.newton_tolerance < zero || !p.newton_tolerance.is_finite() {
        return bad("newton_tolerance", p.newton_tolerance);
    }
    if p.newton_iterations == 0 {
        return bad("newton_iterations", zero);
    }
    Ok(())
}

/// Rejects non-finite state, parameters and inputs, and restitution outside
/// `[0, 1]`.
fn check_inputs<M, T, const N: usize, const K: usize>(
    model: &M,
    state: &State<T, N>,
    u: &M::Input,
) -> Result<(), StepError<T>>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    let t = SVector::<T, 1>::new(state.t);
    validate::finite_vector(&t, "t")?;
    validate::finite_vector(&state.q, "q")?;
    validate::finite_vector(&state.v, "v")?;
    validate::model_and_input(model, u)?;
    validate::restitution(&model.restitution())?;
    Ok(())
}

/// Checks that `M` is positive definite and returns its `L D Lᵀ` factor
/// (the shared check, [`validate::factor_mass`]).
fn check_mass<T: RealField + Copy, const N: usize>(
    m: &SMatrix<T, N, N>,
) -> Result<Ldlt<T, N>, StepError<T>> {
    Ok(validate::factor_mass(m)?)
}

/// Rejects a non-finite model term (the shared check,
/// [`validate::finite_model`]).
fn finite_matrix<T: RealField + Copy, const R: usize, const C: usize>(
    m: &SMatrix<T, R, C>,
    which: &'static str,
) -> Result<(), StepError<T>> {
    Ok(validate::finite_model(m, which)?)
}
