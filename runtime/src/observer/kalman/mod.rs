//! The saltation Kalman filter generated from the model: a third estimator
//! beside (36) and (38), sharing their interval machinery and carrying a
//! covariance with the estimate.
//!
//! # One interval `[t_k, t_{k+1}]`
//!
//! 0. **Screen** the sample as the observers do (module docs of
//!    `runtime/src/observer/mod.rs`, "Bad samples, bad states, long
//!    gaps"): one farther from the last accepted sample than the system
//!    can move is refused ([`ObserverError::Outlier`]), the filter
//!    untouched; a run of such samples that agree with each other, an
//!    interval longer than [`ObserverParams::max_interval`] (3 s with
//!    [`KalmanParams::new`]), a prediction that fails from the filter's
//!    own state, or a covariance whose innovation covariance no longer
//!    factors (not positive definite by more than rounding) restarts it
//!    from the measurement with the observers' restart velocity (the mean
//!    velocity since the last sample used, not since the estimate, which
//!    may be what failed) and a fresh covariance
//!    ([`UpdateReport::restart`]).
//!    Every estimate is held to the velocity bound `C_v`, as theirs are.
//! 1. **Predict** the state `x = (q, v)` from the estimate `(q̂_k, v̂_k)`
//!    through the observers' interval: fourth-order Runge–Kutta on the
//!    model, every impact located inside the interval (Newton's law with
//!    the LCP on the closed constraints), persistent contacts held at
//!    acceleration level, under the same contact rule (module docs of
//!    `runtime/src/observer/mod.rs`) with its noise taken from the
//!    covariance: the band of constraint `i` is
//!    [`KalmanParams::band_sigmas`] (default 1) times the deviation of
//!    the estimate's own gap along its normal, `σ_i = √(J_i P_qq J_iᵀ) /
//!    |J_i|` (at least the rounding of `q`, at most `σ`), the velocity
//!    tests `n_σ` times `σ_v = √max P_vv,ii`, counted once: as the
//!    velocity noise `ν` of the resting speed (with exact samples, where
//!    `ν` is zero, as the uncertainty an approach must exceed to bounce).
//!    The prediction starts from
//!    the filtered `q̂_k`, not from a raw sample, so a bounce a few `σ_i`
//!    high (`σ_i` a small fraction of `σ` after a few samples) is told
//!    from sliding. The interval tells each piece of
//!    motion and each impact as it happens, and the covariance follows:
//!    - a piece of flight of length `h` from `x_0`:
//!      `P ← Φ P Φᵀ + Q(h)`, `Φ` the [`transition`] of the Jacobian
//!      [`flow_jacobian`] at `x_0` (Runge–Kutta on the variational
//!      equation with `A` held at the start of the piece: exact when `A`
//!      is constant, as for Example 1 in flight, and otherwise of the
//!      accuracy of a Jacobian frozen over at most one sampling interval;
//!      for a model whose acceleration depends on neither `q` nor `v` by
//!      its structure, `Φ = (I, hI; 0, I)` exactly and the congruence is
//!      written out, [`Blocks::ballistic_congruence_covered`], to the
//!      general path's bits),
//!      `Q(h)` white acceleration noise of density `diag(q_a²)` integrated
//!      exactly for `q'' = w`: `[[h³/3, h²/2], [h²/2, h]] ⊗ diag(q_a²)`;
//!    - an impact: `P ← Ξ P Ξᵀ`, `Ξ` the [`saltation`] matrix of Newton's
//!      law on the constraints that end it with a positive impulse (the
//!      LCP's outcome), `ê_i` where the law was elastic and `0` where
//!      plastic, the impact time moved by the constraint whose root timed
//!      it (none for a plastic closure or a law met at a closed constraint:
//!      then `Ξ = DΔ`, the reset's Jacobian; where the contact rule met
//!      the constraints one at a time, the product of the single impacts'
//!      `Ξ`, module `propagate`);
//!    - a piece of persistent contact on the set `S` (the constraints whose
//!      multiplier pushed along it, and those resting with no multiplier,
//!      as glued bodies in free flight: `Interval::classify`): the
//!      Jacobian of the constrained flow
//!      ([`constrained_flow_jacobian`]), `P ← Φ P Φᵀ + Q(h)`, then `P`
//!      projected onto the tangent space of the contact manifold at the
//!      end of the piece (less the constraints the motion lifts off there:
//!      no force and a separating acceleration and speed at the end, module
//!      `propagate`), `h_S(q) = ℓ_S` and `J_S(q) v = 0` (`ℓ` the levels
//!      the contacts are held at: `0`, the rigid surface, unless an
//!      impact into the contact and the samples since put it deeper,
//!      module `level`: states of the filter, their covariance and its
//!      correlation with `(q, v)` carried through the projection and the
//!      update), linearised as
//!      `J_S δq = 0` and `∂(J_S v)/∂q δq + J_S δv = 0`
//!      ([`Sensitivities::jacobian_dq`]), in the metric of `M` (that of a
//!      plastic impact): `P ← B P Bᵀ`, a congruence, so positive
//!      semi-definite (as computed too: below); the predicted state is moved
//!      onto the manifold in the same metric. The contact force cancels
//!      the normal motion, modelled and unmodelled; what stays uncertain
//!      across the contact (its compliance, the plant's own penetration)
//!      is the part of the noise's position and velocity variances that
//!      the projection took, put back uncorrelated: `P` stays positive
//!      definite, and a penetration seen in exact samples moves the
//!      position estimate, not the velocity; and the variance of each
//!      level, along the way the manifold moves with it (module
//!      `level`). The piece starts with the separating normal speed of
//!      the held constraints that push taken out in the same metric
//!      (`Interval::settled`), so the force that
//!      holds them does no work on an estimate leaving them: the
//!      prediction never gains energy from a contact (`tests/kalman.rs`,
//!      `a_held_contact_does_no_work_on_a_separating_estimate`).
//!
//!    **Relinearised** on the first update after a start or a restart. Its
//!    prior velocity is a guess (`v̂(0)`, or a restart's mean velocity)
//!    with a variance of `C_v²`, and a prediction linearised there can be
//!    far off where the forces are nonlinear in `v`: on exact samples of
//!    the three-link arm, `v̂(0) = 0` missed the Coriolis forces, the first
//!    update claimed a velocity known to 3e-5 rad/s that was 9e-3 off, and
//!    the filter then refused or restarted for 250 ms (`tests/kalman.rs`).
//!    So that update is an iterated extended Kalman update (Gauss–Newton
//!    on the state at `t_k`): with `Φ P_k` carried along the prediction
//!    ([`Propagation`]), the start the sample implies is
//!    `x_lin = x̂_k + P_k Φᵀ Hᵀ S⁻¹ (q_{k+1} − m)`, `m = φ(x_lin) + Φ (x̂_k −
//!    x_lin)` the prediction linearised at the last such point, and the
//!    interval is predicted again from it until the velocity moves by less
//!    than `√ε (1 + |v|)` (at most four times; a prediction that fails
//!    keeps the last). The update then uses the last `m`, `Φ` and `P`. The
//!    impacts of the interval are located again from each point, so a
//!    guess that missed one does not decide. Every later update is the
//!    plain extended one (its prior is the filter's own, and one
//!    prediction per update is what it costs).
//! 2. **Read** the sample: one that lies deeper inside a contact held at
//!    the predicted end than `√gate` deviations of the measurement along
//!    its normal is read on the contact (moved onto `h_V = ℓ_V` by the
//!    least-squares step along the normals). The rigid model has no state
//!    for that depth (a compliant contact under a steady force, a
//!    time-stepping plant's drift along a curved constraint), and the
//!    projection onto the contact left the covariance almost nothing
//!    across it, so the gate would skip every such sample: on samples
//!    10 σ inside a held rim the filter used one in three and its median
//!    error grew 200-fold (`tests/kalman.rs`,
//!    `a_sample_inside_a_held_contact_is_read_on_it`). A sample outside a
//!    held contact is read as it is: it is how a contact shows it opens.
//!
//!    **Gate** the innovation `y = q_{k+1} − p(τ)`, `S = P_qq + R`: a
//!    normalised innovation squared `yᵀS⁻¹y` above
//!    [`KalmanParams::gate`] marks the sample an outlier; it is reported
//!    ([`KalmanReport::outlier`]) and skipped (the estimate is the
//!    prediction). After [`KalmanParams::max_outliers`] consecutive
//!    outliers the model, not the sample, is taken to be wrong. First,
//!    a persistent contact held at the predicted end whose gap the sample
//!    shows open (beyond `n_σ` times the measurement noise along its
//!    normal, plus the band) is released: the projection onto its
//!    manifold left no variance across it, so no sample could ever move
//!    the estimate off it (an unmodelled kick, or a corner impact whose
//!    outcome the LCP got wrong, kept the estimate on the contact for tens
//!    of milliseconds), and its normal position and speed are made
//!    uncertain again by as much as the sample's gap says
//!    ([`KalmanReport::released`]). Then, if the sample is still past the
//!    gate, `P` is inflated by `yᵀS⁻¹y / N`. The sample is used.
//!
//!    **Weigh** each held contact against the run of samples before the
//!    gate: a contact that no force holds can open more slowly than any
//!    one sample shows (balls an inelastic collapse left touching, which
//!    the plant's drift apart at 1e-4 m/s), and none is then past the
//!    gate. A one-sided cumulative sum of the samples' standardised gaps
//!    above the contact's level (module `opening`) makes the case, and a
//!    contact it shows open is released as above, by the gap the run
//!    shows over the time the contact has been held.
//! 3. **Update** with `H = [I 0]`: `K = P Hᵀ S⁻¹`, `x ← x + K y` and the
//!    Joseph form `P ← (I − KH) P (I − KH)ᵀ + K R Kᵀ`, symmetrised.
//!    Where the filter keeps a plant's likely steps apart
//!    ([`KalmanParams::plant_step_mixture`], module `mixture`), each is
//!    reweighed by its own innovation's likelihood and moved by
//!    `(I − K H)`; the gate takes the smallest of their innovations; the
//!    estimate is their mean and [`SaltationKalman::covariance`] holds
//!    their spread ([`KalmanReport::alternatives`]). The levels of the
//!    contacts held at the end are updated with the state, through their
//!    correlation with it, and follow (module `level`): a contact struck
//!    in the interval takes the depth a delayed impact leaves, which the
//!    sample, when used, measures by a scalar Kalman update until the
//!    state carries it.
//!
//! Every congruence `B P Bᵀ` above (flow, saltation, projection, Joseph
//! update) adds on its diagonal what covers its own rounding
//! ([`Blocks::congruence_covered`]), so `P` is positive semi-definite as
//! computed, not only in exact arithmetic: an update that pins the state
//! down from a diffuse prior leaves errors of `ε` times the prior, and in
//! `f32` on exact samples that once left `P` indefinite and the filter
//! diverging (`tests/kalman.rs`,
//! `exact_samples_keep_the_covariance_positive_in_f32`).
//!
//! Nothing here is written by the user: the Jacobians come from the
//! model's generated [`Model::linearization`](crate::Model::linearization) and [`Sensitivities`].

mod blocks;
mod grid;
mod level;
mod mixture;
mod opening;
mod propagate;
mod saltation;
mod tune;

pub use blocks::Blocks;
pub use saltation::{Saltation, constrained_flow_jacobian, flow_jacobian, saltation, transition};
pub use tune::{NoiseFactors, Picked, Tuning, pick_by_likelihood, tune_process_noise};

use nalgebra::{RealField, SMatrix, SVector};

use crate::lcp::{IndexSet, Lcp};
use crate::model::{Model, Sensitivities};
use crate::stepper::StepParams;

use super::interval::{Cache, Interval, Memory, moved_past_bound, saturate, write_back};
use super::reduced_order::restart_velocity;
use super::{
    Estimate, Observer, ObserverError, ObserverParams, Outliers, Plan, Restart, UpdateReport,
};
use crate::error::DataError;
use crate::validate;
use level::Levels;
use mixture::Mixture;
use opening::Openings;
use propagate::Propagation;

type Result<X, T> = core::result::Result<X, ObserverError<T>>;

/// Settings of the [`SaltationKalman`] filter.
///
/// One `Copy` struct of knobs, each with its default and what moving it
/// does; [`KalmanParams::new`] takes the velocity bound and the
/// measurement noise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KalmanParams<T: RealField + Copy, const N: usize> {
    /// The interval's settings, shared with the observers: the velocity
    /// bound `C_v` (forces at `sat(v̂)`), the measurement noise `σ` and
    /// `noise_sigmas`, which set the contact band, the contact rule and
    /// `max_impacts`. Its gain `l_d` is not used by the filter.
    pub observer: ObserverParams<T>,
    /// Process noise as acceleration noise per coordinate: the amplitude
    /// spectral density `q_a,i` of a white acceleration on `q_i` (units of
    /// `q` per s² per √Hz; the covariance it adds over `h` is
    /// `[[h³/3, h²/2], [h²/2, h]] q_a,i²`). Default `1e-5` on every
    /// coordinate: a model that describes the machine between impacts as
    /// well as a fine simulation does (see [`KalmanParams::new`] for where
    /// the defaults come from); a machine with unmodelled friction,
    /// flexibility or actuator error needs more, and
    /// [`tune_process_noise`] picks it from a recorded run.
    pub accel_noise: SVector<T, N>,
    /// The measurement noise covariance `R` (symmetric positive
    /// semi-definite; default `σ² I` from [`KalmanParams::new`]).
    pub measurement: SMatrix<T, N, N>,
    /// Innovation gate: a normalised innovation squared `yᵀS⁻¹y` above it
    /// marks the sample an outlier (default: the χ² quantile with `N`
    /// degrees of freedom four standard deviations out, probability
    /// 3.2e-5 for a sample the model explains: 21.9 for `N = 2`, 24.5
    /// for `N = 3`; Wilson–Hilferty). Infinity turns the gate off.
    pub gate: T,
    /// Consecutive outliers skipped before the filter takes the model to be
    /// wrong and uses the sample with its covariance inflated (default `2`).
    pub max_outliers: u32,
    /// Standard deviation of the initial velocity estimate on each
    /// coordinate (default `C_v`, the velocity bound: what the filter knows
    /// of a velocity it has not seen).
    pub initial_velocity_sigma: T,
    /// Relative accuracy `ρ_i` of an impact's velocity jump
    /// (dimensionless): the post-impact velocity error has the covariance
    /// `ρ_i² (ΔvᵀMΔv/N) M⁻¹`, isotropic in the kinetic-energy metric with
    /// `ρ_i²` times the jump's energy (module `propagate`). Default `1e-5`:
    /// a restitution coefficient and a contact normal known to about
    /// 0.001 %, as a rigid model of a rigid plant knows them;
    /// [`KalmanParams::with_plant_step`] sets `0`, the plant's jumps being
    /// the model's law through its step.
    pub impact_noise: T,
    /// Standard deviation `σ_t` of an impact's instant, in seconds: the
    /// filter takes every impact to be instantaneous and at the located
    /// time, and this is what it allows for a real one (a contact that
    /// lasts, a plant that meets the constraint on its own time grid). At
    /// each impact that a gap's root timed (not at a plastic closure or a
    /// law met at a closed constraint, which have no instant) it adds
    /// `σ_t² d dᵀ` to the covariance, with `d` the
    /// state's shift per unit of impact delay
    /// ([`Saltation::timing`](super::Saltation)): the velocity jump in
    /// position, the change of acceleration in velocity. Default `3e-6`
    /// (the spread of an impact placed anywhere within a 10 µs step,
    /// `τ/√12`; a compliant contact that lasts `t_c` wants about
    /// `t_c/√12`).
    pub impact_time_sigma: T,
    /// The mean `δ̄` of an impact's instant past the located one, in
    /// seconds (signed): where impacts come late (or early) on average,
    /// the predicted state after each moves by `δ̄ d`, with `d` the
    /// state's shift per unit of delay as for
    /// [`KalmanParams::impact_time_sigma`], carried to the end of the
    /// interval by the motion's own Jacobians (module `propagate`).
    /// Default `0`, a rigid machine. A compliant contact that lasts `t_c`
    /// rebounds about `t_c/2` after its first touch; a time-stepping plant
    /// that takes the impact into the step in which it happens (Moreau–Jean
    /// with a γ-prediction, as [`MoreauJean`](crate::MoreauJean)) resolves it on average half a
    /// step late, and with its law's own error on top: for such samples
    /// set [`KalmanParams::plant`] instead. [`tune_process_noise`] picks
    /// `δ̄` from a recorded run, with `σ_t`.
    pub impact_delay: T,
    /// The time-stepping plant the samples come from, or `None` (the
    /// default) for samples of a machine. A plant that steps across an
    /// impact (Moreau–Jean: this crate's [`MoreauJean`](crate::MoreauJean),
    /// as Siconos's) ends that step in a state an exact impact does not
    /// reach: late by part of a step, and with its own law's error on top
    /// (for a Moreau–Jean step at `θ = 1/2` on Example 1 the normal
    /// velocity comes `τ (1/(1 + e) − 1/2)` later than the position; where
    /// forces depend on the velocity, as a robot's do, the error has
    /// another shape). So at each impact a gap's root timed, the filter
    /// takes one step of this plant across the impact and moves its
    /// prediction by that step's end against the exact impact's at the
    /// same time. Where the samples are the plant's states at its own
    /// steps ([`KalmanParams::plant_grid`], and the interval a whole
    /// number of steps), the filter knows the step the impact falls in:
    /// the step starts on the plant's grid, and the deviation of the
    /// predicted instant (from the covariance) says how likely the
    /// neighbouring step is, which the filter takes in by the Gaussian
    /// moments of that choice (module `grid`). Otherwise the step starts
    /// at the impact, the gap closing at its start (the middle of where it
    /// closes for the plant, over a step, to first order), and the spread
    /// of where the gap closes in a step, `τ/√12`, adds to
    /// [`KalmanParams::impact_time_sigma`] in quadrature. Where that one
    /// step fails, the prediction moves as an impact half a step late
    /// does. Telling the filter `τ/2` as one delay of position and
    /// velocity instead leaves the law's error, which inside an
    /// accumulation of impacts builds up into an error the samples hardly
    /// see (module `propagate`, "A time-stepping plant"). Along a slide,
    /// a plant whose law is not the default
    /// ([`ApproachVelocity::Midpoint`](crate::ApproachVelocity::Midpoint))
    /// drags (Siconos's does, on a curved surface), and the filter adds
    /// that drag, one step of the plant against one with the default law
    /// on each piece of the slide (module `propagate`, "A plant's law
    /// along a slide").
    /// [`KalmanParams::with_plant_step`] and [`KalmanParams::with_plant`]
    /// set it.
    pub plant: Option<StepParams<T>>,
    /// Whether the samples are the [`plant`](KalmanParams::plant)'s states
    /// at its own steps (default `true`), as a simulation that records
    /// every `n`-th state gives them: the plant's step grid then passes
    /// through every sample time, and where an interval is a whole number
    /// of the plant's steps (to a thousandth of a step) the filter takes
    /// each impact into the step the plant takes it into, rather than a
    /// step anywhere around it. Set it `false` for samples taken between
    /// the plant's steps (interpolated, or timed by another clock).
    /// Without a plant it does nothing. In `f32`, sample times of a few
    /// seconds round by more than a thousandth of a 10 µs step, and the
    /// filter stays off the grid there (`tests/kalman.rs`, `runs_in_f32`).
    pub plant_grid: bool,
    /// Whether, on the [`plant`](KalmanParams::plant)'s grid, the filter
    /// keeps the steps an impact may have been taken into apart until the
    /// samples tell them apart (default `true`): where the impact's
    /// predicted instant lies within half a step of a window's edge, the
    /// outcomes a step apart differ by a whole step's delay (a few 1e-3
    /// m/s after a fast impact on a curved surface), and the filter
    /// carries the likely ones as a sum of Gaussians that share its
    /// covariance (module `mixture`). `false` takes every impact by the
    /// staircase's Gaussian moments (module `grid`), one Gaussian, as the
    /// filter did before the mixture. Without a plant, or off its grid,
    /// it does nothing.
    pub plant_step_mixture: bool,
    /// Relative accuracy `ρ_c` of a persistent contact's force, as a
    /// density (units √s): along a piece of sliding or resting contact
    /// with contact acceleration `a_c = M⁻¹Jᵀλ`, white acceleration noise
    /// of density `ρ_c² (a_cᵀ M a_c / N) M⁻¹` (friction, compliance and a
    /// discretised plant's drift along a curved surface are what the
    /// frictionless rigid contact leaves out). Default `1e-6`.
    pub contact_noise: T,
    /// The contact rule's distance band, in standard deviations of the
    /// estimate's gap (default `1`): constraint `i` is closed where the
    /// predicted gap is within `|J_i| (d + b_σ σ_i)`, `σ_i = √(J_i P_qq
    /// J_iᵀ) / |J_i|` the deviation of the estimate along that
    /// constraint's normal (at least the rounding of `q`, `4 ε max(|q|,
    /// 1)`, at most `σ`; `d` the observers' `contact_distance`), and a
    /// bounce is told from sliding when it rises higher than about twice
    /// that band (the resting speed's fall term `√(4 A g b)`).
    ///
    /// The deviation is the gap's own, not the largest of the position's
    /// (`√max P_qq,ii`, used before): along a curved floor the position
    /// is known far worse along the floor than across it. On one Example
    /// 1 run (a held-out seed), 5.8e-6 m against 1.2e-6 m across: the
    /// wider band held a bounce leaving at 1.2e-2 m/s as sliding, and the
    /// plant's bounces then went on unseen, 1.07e-2 m/s off. With the
    /// gap's deviation the filter followed them, at most 9.9e-4 off. Over
    /// 72 held-out random Example 1 starts the largest error off the
    /// bracketing samples went from 1.07e-2 to 6.4e-3, over the 48 of
    /// `tests/kalman.rs` from 8.2e-3 to 5.1e-3, and over the noisy runs
    /// of the other shipped models the samples above 1e-2 went from 549
    /// to 435 (medians within a few per cent; on the double pendulum's
    /// random starts up to 18 % higher).
    ///
    /// The observers need
    /// `n_σ = 3` sample deviations there: they carry no covariance, and a
    /// sample that noise puts outside the band would fall back as an
    /// impact. The filter predicts from its own estimate, whose error is
    /// `σ_i`, and a wrong call costs it what its covariance already allows
    /// for; with three deviations it held the last bounces of an
    /// accumulation (rebounds of a few cm/s, under `σ` high) as sliding,
    /// 1e-2 m/s off between them. Its velocity tests keep `n_σ`
    /// (`observer.noise_sigmas`) deviations of the velocity, `√max P_vv,ii`:
    /// a pair that travels together must not bounce on its estimate's
    /// noise (module docs).
    pub band_sigmas: T,
}

/// The Cholesky factor of the innovation covariance `S = P_qq + R + δ I`
/// and the `R + δ I` it used, `δ` starting at `floor` (the rounding of the
/// samples and of `P`).
///
/// With exact samples (`R = 0`) and `P` held on a contact manifold (its
/// normal variance zero up to rounding), `P_qq` can come out of the
/// propagation with an eigenvalue a few roundings below zero, more than a
/// floor set by `P_qq`'s own size covers; `δ` then grows a hundredfold at
/// a time (at most six times) until `S` factors, as a Gaussian-process
/// code adds jitter. Only a covariance that is not positive definite by
/// more than rounding is an error.
fn innovation_factor<T: RealField + Copy, const N: usize>(
    p_qq: &SMatrix<T, N, N>,
    measurement: &SMatrix<T, N, N>,
    floor: T,
) -> Result<
    (
        SMatrix<T, N, N>,
        nalgebra::linalg::Cholesky<T, nalgebra::Const<N>>,
    ),
    T,
> {
    let mut delta = floor;
    for _ in 0..7 {
        let r = measurement + SMatrix::<T, N, N>::identity() * delta;
        if let Some(chol) = nalgebra::linalg::Cholesky::new(p_qq + r) {
            return Ok((r, chol));
        }
        delta *= nalgebra::convert(100.0);
    }
    Err(ObserverError::Data(DataError::InvalidParams {
        name: "measurement",
        value: measurement.trace(),
    }))
}

/// The rounding of a position `q` as stored: `4 ε max(|q|_∞, 1)` (the
/// floor of the innovation covariance's deviation, and of each contact
/// band's).
fn position_rounding<T: RealField + Copy, const N: usize>(q: &SVector<T, N>) -> T {
    T::default_epsilon() * nalgebra::convert(4.0) * q.amax().max(T::one())
}

/// `χ²_N` quantile `z` standard deviations out, by Wilson–Hilferty:
/// `N (1 − 2/(9N) + z √(2/(9N)))³`.
fn chi_square_quantile<T: RealField + Copy>(n: usize, z: T) -> T {
    let n: T = nalgebra::convert(n.max(1) as f64);
    let c = nalgebra::convert::<f64, T>(2.0 / 9.0) / n;
    let base = T::one() - c + z * c.sqrt();
    n * base * base * base
}

impl<T: RealField + Copy, const N: usize> KalmanParams<T, N> {
    /// Velocity bound `C_v`, measurement noise `σ` on each coordinate, and
    /// the defaults.
    ///
    /// The four process-noise defaults (`q_a = 1e-5`, `ρ_i = 1e-5`,
    /// `σ_t = 3e-6 s`, `ρ_c = 1e-6`) describe a rigid model that is right
    /// about the machine: [`tune_process_noise`], run on recorded runs of
    /// every shipped system (1 kHz samples of the plant at a 10 µs step),
    /// lands within a decade or so of each of them, and on those systems
    /// the defaults do about as well as tuned values (within a factor of
    /// four either way: the noise sweep of the README). On hardware, where friction, flexibility and compliant
    /// contacts are not in the model, tune them from a recorded run: too
    /// small a process noise shows as innovations failing the gate.
    ///
    /// ```
    /// use moreau_runtime::KalmanParams;
    ///
    /// let p = KalmanParams::<f64, 2>::new(20.0, 1e-4);
    /// assert_eq!(p.measurement[(0, 0)], 1e-8);
    /// assert!((p.gate - 21.9).abs() < 0.1);
    /// ```
    #[must_use]
    pub fn new(velocity_bound: T, sigma: T) -> Self {
        Self {
            observer: ObserverParams::new(T::one(), velocity_bound).with_noise(sigma),
            accel_noise: SVector::repeat(nalgebra::convert(1e-5)),
            measurement: SMatrix::identity() * (sigma * sigma),
            gate: chi_square_quantile(N, nalgebra::convert(4.0)),
            max_outliers: 2,
            initial_velocity_sigma: velocity_bound,
            impact_noise: nalgebra::convert(1e-5),
            impact_time_sigma: nalgebra::convert(3e-6),
            impact_delay: T::zero(),
            plant: None,
            plant_grid: true,
            plant_step_mixture: true,
            contact_noise: nalgebra::convert(1e-6),
            band_sigmas: T::one(),
        }
    }

    /// The same settings with the acceleration noise `q_a` on every
    /// coordinate.
    ///
    /// ```
    /// use moreau_runtime::KalmanParams;
    ///
    /// let p = KalmanParams::<f64, 2>::new(20.0, 1e-4).with_accel_noise(0.5).scaled(2.0);
    /// assert_eq!(p.accel_noise[1], 1.0);
    /// ```
    #[must_use]
    pub fn with_accel_noise(self, q_a: T) -> Self {
        Self {
            accel_noise: SVector::repeat(q_a),
            ..self
        }
    }

    /// The same settings for samples of a simulated rigid plant,
    /// [`MoreauJean`](crate::MoreauJean) at the step `tau` with its default settings
    /// ([`KalmanParams::plant`]): its impacts are instantaneous on its own
    /// time grid, so the grid is the only spread of their instants
    /// ([`KalmanParams::impact_time_sigma`] `0`: on the samples' grid,
    /// [`KalmanParams::plant_grid`], the step each impact falls in; off
    /// it, a phase of `τ/√12`) and its own step the only offset
    /// ([`KalmanParams::impact_delay`] `0`); its jumps follow the model's
    /// own law through that step, so the relative error of a jump is `0`
    /// too ([`KalmanParams::impact_noise`]; the step is what is left).
    ///
    /// ```
    /// use moreau_runtime::KalmanParams;
    ///
    /// let p = KalmanParams::<f64, 2>::new(20.0, 1e-4).with_plant_step(1e-5);
    /// assert_eq!(p.plant.map(|plant| plant.tau), Some(1e-5));
    /// assert_eq!((p.impact_noise, p.impact_time_sigma, p.impact_delay), (0.0, 0.0, 0.0));
    /// ```
    #[must_use]
    pub fn with_plant_step(self, tau: T) -> Self {
        self.with_plant(StepParams::new(tau))
    }

    /// The same settings with [`KalmanParams::plant_grid`]: `false` for
    /// samples of the plant taken between its steps.
    ///
    /// ```
    /// use moreau_runtime::KalmanParams;
    ///
    /// let p = KalmanParams::<f64, 2>::new(20.0, 1e-4).with_plant_step(1e-5);
    /// assert!(p.plant_grid);
    /// assert!(!p.with_plant_grid(false).plant_grid);
    /// ```
    #[must_use]
    pub fn with_plant_grid(self, plant_grid: bool) -> Self {
        Self { plant_grid, ..self }
    }

    /// The same settings with [`KalmanParams::plant_step_mixture`]:
    /// `false` for one Gaussian over the steps an impact may have been
    /// taken into.
    ///
    /// ```
    /// use moreau_runtime::KalmanParams;
    ///
    /// let p = KalmanParams::<f64, 2>::new(20.0, 1e-4).with_plant_step(1e-5);
    /// assert!(p.plant_step_mixture);
    /// assert!(!p.with_plant_step_mixture(false).plant_step_mixture);
    /// ```
    #[must_use]
    pub fn with_plant_step_mixture(self, plant_step_mixture: bool) -> Self {
        Self {
            plant_step_mixture,
            ..self
        }
    }

    /// [`KalmanParams::with_plant_step`] for a plant with other settings
    /// than the defaults (Siconos's law, for one:
    /// [`StepParams::siconos`]).
    ///
    /// ```
    /// use moreau_runtime::{KalmanParams, StepParams};
    ///
    /// let siconos = StepParams::siconos(1e-5);
    /// let p = KalmanParams::<f64, 2>::new(20.0, 1e-4).with_plant(siconos);
    /// assert_eq!(p.plant, Some(siconos));
    /// ```
    #[must_use]
    pub fn with_plant(self, plant: StepParams<T>) -> Self {
        Self {
            plant: Some(plant),
            impact_noise: T::zero(),
            impact_time_sigma: T::zero(),
            impact_delay: T::zero(),
            ..self
        }
    }

    /// The same settings with the process noise scaled by `factor` (the
    /// knob [`tune_process_noise`] turns).
    #[must_use]
    pub fn scaled(self, factor: T) -> Self {
        self.scaled_by(&NoiseFactors {
            accel: factor,
            ..NoiseFactors::unit()
        })
    }

    /// The same settings with each process-noise knob scaled by its
    /// factor, and the mean impact delay shifted (what
    /// [`tune_process_noise`] returns).
    ///
    /// ```
    /// use moreau_runtime::{KalmanParams, NoiseFactors};
    ///
    /// let f = NoiseFactors { accel: 2.0, impact_time: 0.5, delay: 4e-6, ..NoiseFactors::unit() };
    /// let p = KalmanParams::<f64, 2>::new(20.0, 1e-4).scaled_by(&f);
    /// assert_eq!((p.accel_noise[0], p.impact_time_sigma, p.impact_delay), (2e-5, 1.5e-6, 4e-6));
    /// ```
    #[must_use]
    pub fn scaled_by(self, f: &NoiseFactors<T>) -> Self {
        Self {
            accel_noise: self.accel_noise * f.accel,
            impact_noise: self.impact_noise * f.impact,
            impact_time_sigma: self.impact_time_sigma * f.impact_time,
            contact_noise: self.contact_noise * f.contact,
            impact_delay: self.impact_delay + f.delay,
            ..self
        }
    }

    /// Checks every setting.
    fn check(&self) -> Result<(), T> {
        self.observer.check()?;
        let bad = |name, value| {
            Err(ObserverError::Data(DataError::InvalidParams {
                name,
                value,
            }))
        };
        for &a in self.accel_noise.iter() {
            if !(a >= T::zero() && a.is_finite()) {
                return bad("accel_noise", a);
            }
        }
        let r = &self.measurement;
        for i in 0..N {
            for j in 0..N {
                let x = r[(i, j)];
                if !x.is_finite() || x != r[(j, i)] {
                    return bad("measurement", x);
                }
            }
            if r[(i, i)] < T::zero() {
                return bad("measurement", r[(i, i)]);
            }
        }
        if self.gate.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Greater) {
            return bad("gate", self.gate);
        }
        let s = self.initial_velocity_sigma;
        if !(s > T::zero() && s.is_finite()) {
            return bad("initial_velocity_sigma", s);
        }
        for (name, s) in [
            ("impact_noise", self.impact_noise),
            ("impact_time_sigma", self.impact_time_sigma),
            ("contact_noise", self.contact_noise),
            ("band_sigmas", self.band_sigmas),
        ] {
            if !(s >= T::zero() && s.is_finite()) {
                return bad(name, s);
            }
        }
        if !self.impact_delay.is_finite() {
            return bad("impact_delay", self.impact_delay);
        }
        if let Some(plant) = self.plant {
            if crate::MoreauJean::new(plant).is_err() {
                return bad("plant", plant.tau);
            }
        }
        Ok(())
    }
}

/// What the last update of a [`SaltationKalman`] did, beyond the
/// observers' [`UpdateReport`]. Read from
/// [`SaltationKalman::kalman_report`]; it is `#[non_exhaustive]`, so a
/// field added later (as `alternatives` was) breaks no caller.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct KalmanReport<T> {
    /// The normalised innovation squared `yᵀS⁻¹y`, `χ²_N` distributed when
    /// the noise model is true.
    pub nis: T,
    /// `ln det S` of the innovation covariance.
    pub log_det: T,
    /// The sample failed the gate and was skipped.
    pub outlier: bool,
    /// The sample was used after consecutive outliers, with the
    /// prediction's covariance widened (contacts released, then inflated
    /// if that was not enough).
    pub inflated: bool,
    /// Saltation matrices applied (impacts and plastic closures).
    pub saltations: u32,
    /// Projections of the covariance onto a contact manifold.
    pub projections: u32,
    /// Persistent contacts released because the samples showed them open:
    /// one sample after the model had failed, or the run of samples since
    /// the contact was held (module docs, step 2).
    pub released: u32,
    /// Predictions made again at a new linearisation point (only the
    /// first update after a start or a restart: module docs, step 1, "Relinearised").
    pub relinearisations: u32,
    /// The steps a plant may have taken a recent impact into that the
    /// filter keeps apart beside its state after the update
    /// ([`KalmanParams::plant_step_mixture`]): while there are any, the
    /// estimate is a sum of Gaussians, and [`SaltationKalman::covariance`]
    /// holds the spread of their means.
    pub alternatives: u32,
}

impl<T: RealField + Copy> KalmanReport<T> {
    fn empty() -> Self {
        Self {
            nis: T::zero(),
            log_det: T::zero(),
            outlier: false,
            inflated: false,
            saltations: 0,
            projections: 0,
            released: 0,
            relinearisations: 0,
            alternatives: 0,
        }
    }

    /// The log-likelihood of the sample given the past ones,
    /// `−½ (yᵀS⁻¹y + ln det S + N ln 2π)`, for `N` coordinates.
    ///
    /// ```
    /// use moreau_runtime::{KalmanParams, SaltationKalman};
    /// use nalgebra::Vector1;
    ///
    /// // before any sample: yᵀS⁻¹y = 0 and ln det S = 0
    /// let params = KalmanParams::<f64, 1>::new(1.0, 1e-3);
    /// let filter =
    ///     SaltationKalman::<f64, 1, 1>::new(params, 0.0, Vector1::new(1.0), Vector1::zeros())?;
    /// let r = filter.kalman_report();
    /// assert_eq!((r.nis, r.log_det), (0.0, 0.0));
    /// let expected = -0.5 * (2.0 * std::f64::consts::PI).ln();
    /// assert!((r.log_likelihood(1) - expected).abs() < 1e-15);
    /// # Ok::<(), moreau_runtime::ObserverError<f64>>(())
    /// ```
    pub fn log_likelihood(&self, n: usize) -> T {
        let two_pi: T = nalgebra::convert(2.0 * core::f64::consts::PI);
        let n: T = nalgebra::convert(n as f64);
        -(self.nis + self.log_det + n * two_pi.ln()) * nalgebra::convert(0.5)
    }
}

/// The saltation Kalman filter: the state `(q̂, v̂)` and its covariance
/// `P` (`2N × 2N`, as [`Blocks`]) from noisy position samples at any rate,
/// through impacts, accumulations and sliding (module docs of
/// `runtime/src/observer/kalman/mod.rs`).
///
/// Its methods mirror [`Observer`](super::Observer)'s (`update`,
/// `estimate`, `report`, `params`); it cannot implement that trait, whose
/// `update` accepts any [`Model`](crate::Model), because the covariance needs the
/// model's [`Sensitivities`] (every `model!` type has them).
///
/// ```
/// use moreau_runtime::{KalmanParams, Model, ModelInfo, Observer, SaltationKalman, Sensitivities};
/// use nalgebra::{Matrix1, SVector, Vector1};
///
/// /// A unit ball above the floor y ≥ 0, e = 0.8.
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
///     fn forces(&self, _: f64, _: &Vector1<f64>, _: &Vector1<f64>, _: &SVector<f64, 0>) -> Vector1<f64> {
///         Vector1::new(9.81)
///     }
///     fn gaps(&self, q: &Vector1<f64>) -> Vector1<f64> { *q }
///     fn gap_jacobian(&self, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
///     fn restitution(&self) -> Vector1<f64> { Vector1::new(0.8) }
///     fn parameter(&self, _: usize) -> Option<f64> { None }
///     fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> { None }
/// }
/// impl Sensitivities<1, 1> for Ball {
///     fn mass_dq(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
///     fn jacobian_dq(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
/// }
///
/// // dropped from 1 m at rest, bouncing at t₁ with 0.8 of its speed; exact
/// // samples every 1 ms, and the filter starts believing v̂ = 0 ± 5 m/s
/// let t1 = (2.0 / 9.81_f64).sqrt();
/// let y = |t: f64| if t < t1 { 1.0 - 4.905 * t * t } else { 0.8 * 9.81 * t1 * (t - t1) - 4.905 * (t - t1).powi(2) };
/// let v = |t: f64| if t < t1 { -9.81 * t } else { 0.8 * 9.81 * t1 - 9.81 * (t - t1) };
/// let params = KalmanParams { initial_velocity_sigma: 5.0, ..KalmanParams::new(20.0, 0.0) };
/// let mut filter = SaltationKalman::<f64, 1, 1>::new(params, 0.0, Vector1::new(1.0), Vector1::zeros())?;
/// for k in 1..=500 {
///     let t = k as f64 * 1e-3;
///     let estimate = filter.update(&Ball, t, &Vector1::new(y(t)), &SVector::zeros())?;
///     if k == 452 {
///         // the bounce was located inside the last interval
///         assert_eq!(filter.report().impacts, 1);
///         assert_eq!(filter.kalman_report().saltations, 1);
///         assert!((estimate.v[0] - v(t)).abs() < 1e-6);
///     }
/// }
/// # Ok::<(), moreau_runtime::ObserverError<f64>>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SaltationKalman<T: RealField + Copy, const N: usize, const K: usize> {
    params: KalmanParams<T, N>,
    restitution: Option<SVector<T, K>>,
    lcp: Lcp<T>,
    t: T,
    q: SVector<T, N>,
    v: SVector<T, N>,
    p: Blocks<T, N>,
    /// Consecutive samples past the innovation gate.
    outliers: u32,
    /// The observers' physical screen: samples farther than the system can
    /// move (refused), and the runs of them that restart the filter.
    screen: Outliers<T, N>,
    report: UpdateReport<T, N, K>,
    kalman: KalmanReport<T>,
    /// The observers' memos (injection gain, a constant `M`'s factor).
    cache: Cache<T, N>,
    /// The last sample used (a restart's velocity starts from it).
    sample: SVector<T, N>,
    /// Whether the next update is the first since a start or a restart
    /// (and relinearises: module docs, step 1, "Relinearised").
    fresh: bool,
    /// The steps a plant may have taken a recent impact into, beside the
    /// one the state holds (module `mixture`; empty without a plant).
    mixture: Mixture<T, N>,
    /// When each constraint was last seen open or struck at a sample (the
    /// sample's time): how long the contacts held since have been
    /// (module `propagate`, "A contact that may hover").
    held_since: SVector<T, K>,
    /// The gaps the held contacts are held at, their covariance and its
    /// correlation with the state (module `level`).
    levels: Levels<T, N, K>,
    /// The case the samples build against each held contact (module
    /// `opening`).
    openings: Openings<T, K>,
    /// `P` plus the spread of the mixture's means: the covariance of the
    /// estimate the filter reports.
    reported: Blocks<T, N>,
}

impl<T: RealField + Copy, const N: usize, const K: usize> SaltationKalman<T, N, K> {
    /// A filter with these settings, started at time `t0` from the first
    /// measurement `q0` (its covariance `R`) and the velocity estimate `v0`
    /// (standard deviation [`KalmanParams::initial_velocity_sigma`] per
    /// coordinate).
    ///
    /// # Errors
    ///
    /// [`DataError::InvalidParams`](crate::DataError::InvalidParams) for a setting out of its range,
    /// [`DataError::NonFinite`](crate::DataError::NonFinite) (`"q0"`, `"v0"`) or
    /// [`ObserverError::InvalidTime`] for non-finite initial data.
    pub fn new(
        params: KalmanParams<T, N>,
        t0: T,
        q0: SVector<T, N>,
        v0: SVector<T, N>,
    ) -> Result<Self, T> {
        params.check()?;
        let s = params.initial_velocity_sigma;
        let p = Blocks::diagonal(params.measurement, SMatrix::identity() * (s * s));
        Self::with_covariance(params, t0, q0, v0, p)
    }

    /// A filter started from `(q0, v0)` with the covariance `p0`
    /// (symmetric positive semi-definite).
    ///
    /// # Errors
    ///
    /// As [`SaltationKalman::new`], and [`DataError::InvalidParams`](crate::DataError::InvalidParams)
    /// (`"p0"`) for a non-finite or non-symmetric `p0` or a negative
    /// variance.
    pub fn with_covariance(
        params: KalmanParams<T, N>,
        t0: T,
        q0: SVector<T, N>,
        v0: SVector<T, N>,
        p0: Blocks<T, N>,
    ) -> Result<Self, T> {
        params.check()?;
        if !t0.is_finite() {
            return Err(ObserverError::InvalidTime { t: t0, last: t0 });
        }
        validate::finite_vector(&q0, "q0")?;
        validate::finite_vector(&v0, "v0")?;
        let bad = |value| {
            Err(ObserverError::Data(DataError::InvalidParams {
                name: "p0",
                value,
            }))
        };
        if !p0.is_finite() || p0.symmetrized() != p0 {
            return bad(p0.trace());
        }
        for i in 0..2 * N {
            if p0.entry(i, i) < T::zero() {
                return bad(p0.entry(i, i));
            }
        }
        Ok(Self {
            params,
            restitution: None,
            lcp: Lcp::default(),
            t: t0,
            q: q0,
            v: v0,
            p: p0,
            outliers: 0,
            screen: Outliers::NONE,
            report: UpdateReport::new(t0, T::zero()),
            kalman: KalmanReport::empty(),
            cache: Cache::default(),
            sample: q0,
            fresh: true,
            mixture: Mixture::empty(),
            held_since: SVector::repeat(t0),
            levels: Levels::surface(),
            openings: Openings::none(),
            reported: p0,
        })
    }

    /// The same filter with its own restitution coefficients `ê` instead
    /// of the model's.
    ///
    /// # Errors
    ///
    /// [`DataError::InvalidRestitution`](crate::DataError::InvalidRestitution) for a coefficient outside
    /// `[0, 1]`.
    pub fn with_restitution(self, restitution: SVector<T, K>) -> Result<Self, T> {
        validate::restitution(&restitution)?;
        Ok(Self {
            restitution: Some(restitution),
            ..self
        })
    }

    /// The current estimate `(q̂, v̂)` (also [`Observer::estimate`]): the
    /// mean over the steps a plant may have taken a recent impact into,
    /// where the filter keeps more than one
    /// ([`KalmanParams::plant_step_mixture`]).
    #[must_use]
    pub fn estimate(&self) -> Estimate<T, N> {
        self.estimate_at(self.mixture.mean())
    }

    /// The estimate with the mixture's mean `(dq, dv)` already computed
    /// (the update has it from the mixture's moments).
    fn estimate_at(&self, (dq, dv): mixture::Offset<T, N>) -> Estimate<T, N> {
        Estimate {
            t: self.t,
            q: self.q + dq,
            v: self.v + dv,
        }
    }

    /// What the last successful update's interval did (impacts, contacts,
    /// the innovation; also [`Observer::report`]).
    #[must_use]
    pub fn report(&self) -> &UpdateReport<T, N, K> {
        &self.report
    }

    /// The covariance `P` of the estimate (with the spread of the steps a
    /// plant may have taken a recent impact into, where the filter keeps
    /// more than one).
    pub fn covariance(&self) -> &Blocks<T, N> {
        &self.reported
    }

    /// What the last successful update's covariance did (the normalised
    /// innovation, the gate, saltations and projections).
    pub fn kalman_report(&self) -> &KalmanReport<T> {
        &self.kalman
    }

    /// The settings.
    pub fn params(&self) -> &KalmanParams<T, N> {
        &self.params
    }
}

/// The filter is an [`Observer`] of every model with [`Sensitivities`]:
/// [`update`](Observer::update) is one predict–gate–update cycle (module
/// docs); [`params`](Observer::params) gives the interval's settings
/// ([`KalmanParams::observer`]), the inherent
/// [`SaltationKalman::params`] all of them.
///
/// An update's errors name the problem (a non-finite measurement, input
/// or parameter, a time not after the last, a model that evaluates to NaN,
/// an innovation covariance that is not positive definite:
/// `InvalidParams { name: "measurement" }`, a sample farther than the
/// system can move: [`ObserverError::Outlier`]); the filter's state is
/// then unchanged, bit for bit. A sample past the innovation gate is no
/// error: it is reported in [`KalmanReport::outlier`] and skipped.
impl<M, T, const N: usize, const K: usize> Observer<M, N, K> for SaltationKalman<T, N, K>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    fn estimate(&self) -> Estimate<T, N> {
        Self::estimate(self)
    }

    fn report(&self) -> &UpdateReport<T, N, K> {
        Self::report(self)
    }

    fn params(&self) -> &ObserverParams<T> {
        &self.params.observer
    }

    fn update(
        &mut self,
        model: &M,
        t: T,
        q: &SVector<T, N>,
        u: &M::Input,
    ) -> Result<Estimate<T, N>, T> {
        // the contact rule's band and velocity noise are those of the
        // estimate the prediction starts from, not of a raw sample: the
        // bands `d + b_σ σ_i` (below), the velocity tests `n_σ σ_v`
        let sigma_q = self.p.qq.diagonal().amax().max(T::zero()).sqrt();
        let sigma_v = self.p.vv.diagonal().amax().max(T::zero()).sqrt();
        let measured_sigma = sigma_q.min(self.params.observer.noise);
        // (one band for the whole estimate, from its largest position
        // deviation: what releases held contacts that an outlier shows
        // open; the rule's bands are each constraint's own, below)
        let band = self.params.band_sigmas * measured_sigma;
        let rule = ObserverParams {
            noise: T::zero(),
            contact_distance: self.params.observer.contact_distance + band,
            ..self.params.observer
        };
        let memory = Memory {
            params: &rule,
            lcp: &self.lcp,
            t: self.t,
            q: self.q,
            restitution: self.restitution.as_ref(),
            report: &self.report,
            release_departures: false,
        };
        let (mut interval, mut report) = Interval::begin(model, u, memory, &mut self.cache, t, q)?;
        // SCREEN, as the observers do: a sample farther than the system
        // can move is refused here, the estimate untouched; a run of such
        // samples that agree with each other, or an interval longer than
        // `max_interval`, restarts the filter from the measurement
        let opened = report;
        let plan = self
            .screen
            .screen(&self.params.observer, (t, interval.tau), &self.q, q)?;
        // the estimate's velocity noise `n_σ σ_v` enters the rule once: as
        // its velocity noise `ν` (in the resting speed), or with exact
        // samples, `σ = 0`, where `ν` is zero as for the observers, as the
        // uncertainty a bounce must exceed. Counted in both, a bounce had
        // to approach `n_σ σ_v` faster than the resting speed, and
        // approaches the filter could tell from rest were closed
        // plastically (`tests/kalman.rs`,
        // `an_approach_the_filter_can_tell_from_rest_bounces`)
        let velocity_noise = rule.noise_sigmas * sigma_v;
        (interval.noise_speed, interval.uncertainty) = if measured_sigma > T::zero() {
            (velocity_noise, T::zero())
        } else {
            (T::zero(), velocity_noise)
        };
        // each constraint's band from the deviation of its own gap,
        // `√(J_i P_qq J_iᵀ) / |J_i|`, at least the rounding of `q` and at
        // most `σ` (where the model fails at the estimate the whole
        // estimate's band stays, and the prediction's own failure restarts
        // the filter, as it did before the bands were per constraint)
        if let Ok((_, jac)) = interval.contact(&self.q) {
            let rounding = position_rounding(&self.q);
            for i in 0..K {
                let row = jac.row(i);
                let g2 = row.norm_squared();
                let deviation = if g2 > T::zero() {
                    ((row * self.p.qq).dot(&row) / g2)
                        .max(T::zero())
                        .sqrt()
                        .max(rounding)
                } else {
                    sigma_q
                };
                interval.bands[i] = self.params.observer.contact_distance
                    + self.params.band_sigmas * deviation.min(self.params.observer.noise);
            }
        }
        // no injection: the filter's correction is its Kalman gain
        report.gain = T::zero();
        // PREDICT, the covariance following every piece and impact (a
        // restart takes its velocity from the last sample used, not from
        // an estimate that may be what failed: `restart_point`)
        let v0 = saturate(&self.v, self.params.observer.velocity_bound);
        let mut linearised = (self.q, v0);
        // the report before the prediction, for the relinearisations
        let unpredicted = self.fresh.then_some(report);
        let predicted = match plan {
            Plan::Integrate => self
                .predict(&interval, &v0, linearised, &mut report)
                .map_err(|_| Restart::Infeasible),
            Plan::Restart(why) => Err(why),
        };
        let (mut q_pred, mut v_pred, mut propagation) = match predicted {
            Ok(end) => end,
            // agreeing outliers, a long gap, or a prediction that failed
            // from the filter's own state: start again from the
            // measurement, as the observers do
            Err(why) => {
                let point = restart_point(&interval, &self.sample, &self.v, why, opened)?;
                return Ok(self.restarted(point));
            }
        };
        // RELINEARISE the first update after a start or a restart, whose
        // prior velocity is a guess (module docs, step 1, "Relinearised")
        let measurement = self.params.measurement;
        // the floor under `R` in `S = P_qq + R`: the rounding of a
        // coordinate stored in `T` (a few units of `ε |q|`: the sample's
        // own and the prediction's), plus 64 ε times the largest variance
        // in units of position that the covariance holds (`P_qq`,
        // `τ² P_vv`), so that exact samples (`R = 0`) never leave `S`
        // singular, without adding noise that a real `R` already
        // dominates. A floor of `ε |q|²` (half the digits of a coordinate)
        // is `√ε |q|` = 1.7e-3 m at `|q|` = 5 in `f32`, and held the `f32`
        // filter at σ = 1e-4 seven to ten times above the `f64` one
        // (`tests/kalman.rs`, `runs_in_f32`). A third term, 64 ε times
        // the initial velocity variance times `τ²`, stood in for the
        // rounding of the first updates from a diffuse prior until every
        // congruence covered its own (`Blocks::congruence_covered`); in
        // `f32` it treated exact samples as noisy to 5.5e-5 m for the
        // whole run (`exact_samples_keep_the_covariance_positive_in_f32`)
        let tau = interval.tau;
        let floor = |p: &Blocks<T, N>| {
            let eps = T::default_epsilon();
            let rounding = position_rounding(q);
            let held =
                p.qq.diagonal()
                    .amax()
                    .max(tau * tau * p.vv.diagonal().amax());
            rounding * rounding + eps * nalgebra::convert(64.0) * held
        };
        let mut relinearisations = 0;
        if let Some(unpredicted) = unpredicted {
            for _ in 0..RELINEARISATIONS {
                let Some(cross) = propagation.cross else {
                    break;
                };
                let p = &propagation.p;
                let Ok((_, chol)) = innovation_factor(&p.qq, &measurement, floor(p)) else {
                    break;
                };
                let w = chol.solve(&(q - q_pred));
                let next = (
                    self.q + cross.qq.transpose() * w,
                    saturate(
                        &(v0 + cross.qv.transpose() * w),
                        self.params.observer.velocity_bound,
                    ),
                );
                let step = (next.1 - linearised.1).amax();
                let mut again = unpredicted;
                let Ok(end) = self.predict(&interval, &v0, next, &mut again) else {
                    break;
                };
                (q_pred, v_pred, propagation) = end;
                (linearised, report) = (next, again);
                relinearisations += 1;
                let tolerance = T::default_epsilon().sqrt() * (T::one() + next.1.amax());
                if step <= tolerance {
                    break;
                }
            }
        }
        let mut p = propagation.p;
        let mut kalman = KalmanReport {
            saltations: propagation.saltations,
            projections: propagation.projections,
            relinearisations,
            ..KalmanReport::empty()
        };
        // READ a sample that lies deeper inside a held contact than the
        // gate allows on the contact (`Interval::read_on_contacts`); its
        // `h`, `J`, evaluated once here where the read needs them, serve
        // the levels below too
        let deviations = self.params.gate.sqrt();
        let at_sample = if propagation.held.is_empty() || !deviations.is_finite() {
            None
        } else {
            Some(interval.contact(q)?)
        };
        let read = interval.read_on_contacts(
            q,
            at_sample.as_ref(),
            (propagation.held, &self.levels.mean),
            (&self.params.measurement, deviations),
        )?;
        // GATE the innovation (the report keeps the sample's own)
        let y = read - q_pred;
        report.innovation = q - q_pred;
        // R plus the floor above, so that exact samples (R = 0) never
        // leave S singular
        let floor = floor(&p);
        // WEIGH the held contacts against the samples that show them
        // open by a little each (module `opening`): one whose case is
        // made is released before the sample is used, as the gate's
        // release does
        if let Some((h, jac)) = at_sample.as_ref() {
            let (opened, gaps, spans) = self.openings.weigh(
                (t, propagation.held, &self.levels.mean),
                (h, jac),
                (&self.params.measurement, floor, deviations),
            );
            if !opened.is_empty() {
                let released = release_contacts(model, (q, jac), (opened, &gaps, &spans), &mut p)?;
                kalman.released += released.len() as u32;
            }
        } else if !self.openings.is_none() {
            self.openings = Openings::none();
        }
        let mut outliers = self.outliers;
        let gate = self.params.gate;
        let measurement = &self.params.measurement;
        let factor = |p: &Blocks<T, N>| {
            innovation_factor(&p.qq, measurement, floor)
                .ok()
                .map(|(r, chol)| (r, chol, y.dot(&chol.solve(&y))))
        };
        let mut factored = factor(&p);
        if let Some((_, _, nis)) = factored
            && nis > gate
            && self.outliers >= self.params.max_outliers
        {
            // the model, not the sample, is wrong: first the contacts
            // that the sample shows open are released, then, if the
            // sample is still past the gate, the prediction is widened
            kalman.inflated = true;
            let span = interval.tau * nalgebra::convert((self.outliers + 1) as f64);
            let released = release_open_contacts(
                model,
                (q, propagation.held),
                (span, rule.contact_band()),
                &self.params,
                &mut p,
            )?;
            kalman.released += released.len() as u32;
            let mut nis = nis;
            if !released.is_empty() {
                factored = factor(&p);
                nis = factored.as_ref().map_or(nis, |f| f.2);
            }
            if nis > gate {
                p = p.scaled(nis / nalgebra::convert(N.max(1) as f64));
                factored = factor(&p);
            }
        }
        let Some((r, chol, nis)) = factored else {
            // a covariance that is not positive definite by more than
            // rounding: the filter's own state failed, and it starts again
            // from the measurement, as after a failed prediction (refusing
            // the sample would keep that state, and refuse every sample
            // after it)
            let point = restart_point(
                &interval,
                &self.sample,
                &self.v,
                Restart::Infeasible,
                opened,
            )?;
            return Ok(self.restarted(point));
        };
        kalman.nis = nis;
        kalman.log_det = chol
            .l()
            .diagonal()
            .iter()
            .fold(T::zero(), |acc, &d| acc + d.ln())
            * nalgebra::convert(2.0);
        // (a sample that one of the steps a plant may have taken a recent
        // impact into explains is no outlier: module `mixture`)
        let mut mixture = propagation.mixture;
        // a hovering contact whose hop has ended by this sample: its
        // offset, carried by the free flow, no longer stands for it
        // (module `propagate`, "A contact that may hover")
        mixture.drop_open(t);
        let theirs = mixture.innovations(&y, |x| chol.solve(x));
        let gated = mixture.least_nis(nis, &theirs);
        // the levels' correlation with the state as the prediction carried
        // it, measured with the state below (module `level`)
        let mut levels = propagation.levels;
        let (q_new, v_new) = if gated > gate && !kalman.inflated {
            kalman.outlier = true;
            outliers += 1;
            (q_pred, v_pred)
        } else {
            outliers = 0;
            // UPDATE, Joseph form
            let k_q = chol.solve(&p.qq).transpose();
            let k_v = chol.solve(&p.qv).transpose();
            levels.update(&p, (&k_q, &k_v), &r, |x| chol.solve(x), &y);
            p = p.joseph_position_update(&k_q, &k_v, &r);
            // each step's own innovation reweighs it, the likeliest
            // becoming the state (module `mixture`)
            let (dq, dv) = if mixture.is_empty() {
                (SVector::zeros(), SVector::zeros())
            } else {
                let (dq, dv) = mixture.update((nis, &theirs), (&k_q, &k_v), nis > gate);
                // those the samples cannot tell from the state join it
                let ((mq, mv), gained) = mixture.merge_close(&p);
                p = p.add(&gained);
                (dq + mq, dv + mv)
            };
            (q_pred + k_q * y + dq, v_pred + k_v * y + dv)
        };
        // WRITEBACK: only a finite result replaces the state, its
        // velocity held to C_v (the projection onto a ball that holds the
        // true velocity never moves the estimate away from it)
        let finite = |x: &SVector<T, N>| x.iter().all(|x| x.is_finite());
        if !(finite(&q_new) && finite(&v_new) && p.is_finite()) {
            return Err(ObserverError::Data(DataError::NonFiniteResult));
        }
        // (the move past C_v measured from the estimate's position: the
        // last sample used may be older than t_k, after a refused one)
        let v_new = write_back(
            &v_new,
            &self.params.observer,
            (&self.q, q, t - self.t),
            &mut report,
        );
        report.outliers = self.screen.accept();
        if !kalman.outlier {
            (self.sample, self.fresh) = (*q, false);
        }
        (self.t, self.q, self.v, self.p) = (t, q_new, v_new, p);
        self.mixture = mixture;
        self.levels = levels;
        for i in 0..K {
            if !propagation.held.contains(i) || report.impacted.contains(i) {
                self.held_since[i] = t;
            }
        }
        // the levels of the contacts held at the end, measured by the
        // sample where it was used (module `level`; nothing to do where
        // no contact is held now or was before, as in free flight). The
        // state is written: a sample whose `h`, `J` the model cannot give
        // (the read above evaluated them unless the gate is infinite)
        // measures no level, and the update stands.
        if !(propagation.held.is_empty() && self.levels.at_surface()) {
            let sample = if propagation.held.is_empty() || kalman.outlier {
                None
            } else {
                at_sample.or_else(|| interval.contact(q).ok())
            };
            let sample = sample
                .as_ref()
                .map(|(h, jac)| (h, jac, &self.params.measurement));
            self.levels.follow(
                propagation.held,
                &propagation.struck,
                propagation.lateness(),
                sample,
            );
            // a prediction the sample contradicted past the gate (the
            // filter widened it) held the struck contacts at levels the
            // plant has left: they start again from the sample (after
            // `follow`, so that the sample counts once and an impact in
            // the interval is not added again below the level it measures)
            if kalman.inflated
                && let Some(sample) = sample
            {
                self.levels.restart(sample);
            }
        }
        kalman.alternatives = u32::try_from(mixture.len()).unwrap_or(u32::MAX);
        // the estimate and its covariance: the mixture's moments, where
        // the filter keeps steps apart (each weight's `exp` once)
        let (mean, reported) = if mixture.is_empty() {
            (mixture::no_offset(), p)
        } else {
            let (mean, spread) = mixture.moments();
            (mean, p.add(&spread))
        };
        self.reported = reported;
        (self.outliers, self.report, self.kalman) = (outliers, report, kalman);
        Ok(self.estimate_at(mean))
    }
}

/// Releases the persistent contacts that the sample `q` shows open, when
/// the model has failed to explain the samples (module docs, step 2):
/// each constraint `i` of `held` (held along the last piece of the
/// prediction, so projected onto `h_i = 0`, `J_i v = 0` with no variance
/// across it) whose measured gap exceeds `n_σ` times the noise of the
/// measurement along its normal, `√(J_i R J_iᵀ)`, plus the contact band
/// `band` (`|J_i|` times it). The contact then gets back what the
/// projection took, as a track started again along its normal
/// ([`release_contacts`]), with the measured gap `h_i` and the time `span`
/// since the samples last agreed. The next samples then measure the
/// speed. (Tying the two together, a separation at the start of `span`,
/// made the billiard's estimate overshoot and stay 0.1 m/s off for 20
/// ms.) Returns the constraints released.
fn release_open_contacts<M, T, const N: usize, const K: usize>(
    model: &M,
    (q, held): (&SVector<T, N>, IndexSet<K>),
    (span, band): (T, T),
    params: &KalmanParams<T, N>,
    p: &mut Blocks<T, N>,
) -> Result<IndexSet<K>, T>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    let mut open = IndexSet::EMPTY;
    if held.is_empty() || span <= T::zero() {
        return Ok(open);
    }
    let (h, jac) = model.contact(q);
    validate::finite_model(&h, "h")?;
    validate::finite_model(&jac, "J")?;
    for i in held {
        let row = jac.row(i);
        let sigma = (row * params.measurement * row.transpose())[0]
            .max(T::zero())
            .sqrt();
        if h[i] > params.observer.noise_sigmas * sigma + row.norm() * band {
            open.insert(i);
        }
    }
    release_contacts(model, (q, &jac), (open, &h, &SVector::repeat(span)), p)
}

/// Releases the contacts `open` at the sample `q`, each with the gap
/// `gaps[i]` the samples show it open by in the time `spans[i]` (the
/// gate's release, [`release_open_contacts`], and the samples' case
/// against a held contact, module `opening`): a normal
/// position anywhere up to that gap and, independent of it, a normal speed
/// of the size that opens it in that time, `P_qq += g_i² u uᵀ`, `P_vv +=
/// (g_i/span_i)² u uᵀ`, with `u = M⁻¹J_iᵀ/(J_i M⁻¹J_iᵀ)` (unit normal speed
/// in the metric of `M`, as an impulse along the normal would give).
/// `jac` is `J(q)`, which both callers have evaluated at the sample.
/// Returns the constraints released (a non-positive gap, span or
/// Delassus entry releases nothing).
fn release_contacts<M, T, const N: usize, const K: usize>(
    model: &M,
    (q, jac): (&SVector<T, N>, &SMatrix<T, K, N>),
    (open, gaps, spans): (IndexSet<K>, &SVector<T, K>, &SVector<T, K>),
    p: &mut Blocks<T, N>,
) -> Result<IndexSet<K>, T>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    let mut released = IndexSet::EMPTY;
    if open.is_empty() {
        return Ok(released);
    }
    let mass = model.mass(q);
    validate::finite_model(&mass, "M")?;
    let chol = validate::factor_mass(&mass)?;
    for i in open {
        let (gap, span) = (gaps[i], spans[i]);
        if !(gap > T::zero() && span > T::zero()) {
            continue;
        }
        let row = jac.row(i);
        let minv_jt = chol.solve(&row.transpose());
        let delassus = row.dot(&minv_jt.transpose());
        if delassus <= T::zero() {
            continue;
        }
        let u = minv_jt / delassus;
        let speed = gap / span;
        let along = u * u.transpose();
        *p = p
            .add(&Blocks::diagonal(
                along * (gap * gap),
                along * (speed * speed),
            ))
            .symmetrized();
        released.insert(i);
    }
    Ok(released)
}

/// A prediction: the predicted end `(q, v)` and the propagation that
/// followed the covariance to it.
type Predicted<'m, M, T, const N: usize, const K: usize> =
    (SVector<T, N>, SVector<T, N>, Propagation<'m, M, T, N, K>);

/// The most predictions the first update after a start or a restart makes
/// again at a new linearisation point (module docs, step 1,
/// "Relinearised"): Gauss–Newton converges in two or three where the prior
/// velocity is a guess.
const RELINEARISATIONS: usize = 4;

impl<T: RealField + Copy, const N: usize, const K: usize> SaltationKalman<T, N, K> {
    /// The interval's prediction, its covariance following every piece and
    /// impact, from the linearisation point `(q, w)`: `(q̂_k, v0)`, the
    /// prior's mean with its velocity held to `C_v`, except when
    /// relinearising. The first update after a start or a restart also
    /// carries the prior's deviation from that point and `Φ P_k`
    /// ([`Propagation::relinearised`]). Returns the predicted end
    /// `φ(x_lin) + Φ (x̂_k − x_lin)`, moved onto a contact manifold where
    /// the last piece held one, and the propagation.
    fn predict<'m, M>(
        &self,
        interval: &Interval<'m, M, T, N, K>,
        v0: &SVector<T, N>,
        (q, w): (SVector<T, N>, SVector<T, N>),
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<Predicted<'m, M, T, N, K>, T>
    where
        M: Sensitivities<N, K, Scalar = T>,
    {
        let mut propagation = Propagation::new(
            interval.model,
            interval.u,
            (self.t, interval.tau),
            &self.params,
            (self.p, self.mixture),
            (Some(self.held_since), &self.levels),
        );
        if self.fresh {
            propagation = propagation.relinearised((self.q - q, v0 - w));
        }
        let from = Interval { q0: q, ..*interval };
        let (q_end, v_end) = from.predict_traced(&w, report, &mut propagation)?;
        Ok((
            q_end + propagation.correction.0 + propagation.offset.0,
            v_end + propagation.correction.1 + propagation.offset.1,
            propagation,
        ))
    }
}

/// Where a restart puts the filter: the time and the measurement at the
/// end of the interval, the velocity and the report that records why.
type RestartPoint<T, const N: usize, const K: usize> =
    (T, SVector<T, N>, SVector<T, N>, UpdateReport<T, N, K>);

/// The restart at the end of `interval` for `why`, from the report `opened`
/// of the interval's start: the observers' restart velocity (`v̂_k` kept
/// after a run of outliers, else the mean velocity over the interval, held
/// to `C_v` and closed at the measurement), the interval opened at
/// `sample`, the last sample the filter used, not at its estimate.
fn restart_point<M, T, const N: usize, const K: usize>(
    interval: &Interval<'_, M, T, N, K>,
    sample: &SVector<T, N>,
    v_k: &SVector<T, N>,
    why: Restart,
    mut report: UpdateReport<T, N, K>,
) -> Result<RestartPoint<T, N, K>, T>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    let interval = Interval {
        q0: *sample,
        ..*interval
    };
    let v = restart_velocity(&interval, v_k, why, &mut report)?;
    Ok((interval.t0 + interval.tau, interval.q1, v, report))
}

impl<T: RealField + Copy, const N: usize, const K: usize> SaltationKalman<T, N, K> {
    /// The filter started again at `(t, q)` with the velocity `v`
    /// ([`restart_point`]) and the covariance of a fresh filter (`R` on the
    /// position, [`KalmanParams::initial_velocity_sigma`]`²` on the
    /// velocity); `report` records why.
    fn restarted(&mut self, (t, q, v, mut report): RestartPoint<T, N, K>) -> Estimate<T, N> {
        report.at_velocity_bound |=
            moved_past_bound(&self.params.observer, (&self.q, &q), t - self.t);
        let s = self.params.initial_velocity_sigma;
        let p = Blocks::diagonal(self.params.measurement, SMatrix::identity() * (s * s));
        report.outliers = self.screen.accept();
        (self.t, self.q, self.v, self.p) = (t, q, v, p);
        (self.mixture, self.reported) = (Mixture::empty(), p);
        self.held_since = SVector::repeat(t);
        self.levels = Levels::surface();
        self.openings = Openings::none();
        (self.sample, self.fresh) = (q, true);
        (self.outliers, self.report, self.kalman) = (0, report, KalmanReport::empty());
        Self::estimate(self)
    }
}
