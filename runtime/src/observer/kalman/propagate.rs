//! The covariance along the predicted motion of one interval: the
//! [`Tracer`] that the filter hands to the observers' interval, and the
//! process noise it adds on each piece and at each impact.
//!
//! # Process noise
//!
//! What the model leaves out enters in three places, each a knob of
//! [`KalmanParams`] with a physical meaning:
//!
//! - **everywhere**, white acceleration noise of density `diag(q_a²)`
//!   ([`KalmanParams::accel_noise`]), integrated exactly for `q'' = w`
//!   over a piece of length `h`: `[[h³/3, h²/2], [h²/2, h]] ⊗ diag(q_a²)`;
//! - **at an impact**, the velocity jump `Δv = v⁺ − v⁻` is known only to a
//!   relative accuracy `ρ_i` ([`KalmanParams::impact_noise`]; restitution
//!   coefficients and contact normals are never exact), and the impact's
//!   instant only to `σ_t` ([`KalmanParams::impact_time_sigma`]; a real
//!   impact lasts): `P_vv += ρ_i² (ΔvᵀMΔv / N) M⁻¹` (isotropic in the
//!   metric of the kinetic energy: the error's expected energy is `ρ_i²`
//!   times the jump's) and, for an impact that a gap's root timed,
//!   `P += σ_t² d dᵀ`, `d` the post-impact state's shift per unit of
//!   delay ([`Saltation::timing`]); where the impacts
//!   come late (or early) on average, by `δ̄`
//!   ([`KalmanParams::impact_delay`]), the predicted state moves by
//!   `δ̄ d` as well (below);
//! - **along a persistent contact**, the contact force `M⁻¹Jᵀλ = a_c` is
//!   known only to a relative density `ρ_c` ([`KalmanParams::contact_noise`];
//!   friction, compliance, a discretised plant's drift along a curved
//!   surface): white acceleration noise of density
//!   `ρ_c² (a_cᵀ M a_c / N) M⁻¹`, projected with the rest onto the contact
//!   manifold.
//!
//! The two contact terms scale with what the contacts do, so a filter
//! tuned on one run carries over to runs with harder or softer impacts;
//! [`tune_process_noise`](super::tune_process_noise) picks all four knobs
//! from a recorded run.
//!
//! # An impact met one constraint at a time
//!
//! Where the contact rule meets the constraints of an impact one at a
//! time (nearly opposite gradients, or an impact problem without a
//! solution in floating point: module docs of
//! `runtime/src/observer/mod.rs`), the velocity after it is not Newton's
//! law on the set, and neither is its saltation: the covariance goes
//! through the product of the single impacts' saltation matrices at the
//! same point, in the rule's order (fastest approach first, each
//! constraint once), the first timed by the root that found the impact
//! and the later ones untimed. Where Moreau's law with the least
//! restitution of the set replaced Newton's (Newton's would have put
//! energy in), the saltation is Newton's with that restitution on every
//! constraint that took an impulse, which is what Moreau's law is there.
//! The interval says which law it used ([`Jump::law`]), so the filter
//! computes the one saltation that law needs. On the double pendulum's
//! corner this took the filter's largest error in the accumulations from
//! 7.7e-2 to 6.2e-3 rad/s (7.1e-3 since a constraint that has just
//! bounced is left out of an impact on the others, 6.4e-3 since a
//! resting contact with no force on it is held; `tests/kalman.rs`,
//! `full_reach`).
//!
//! # A contact that may hover
//!
//! The contact rule holds a closed constraint whose gap and normal speed
//! are within the noise, and a strike elsewhere then meets it in one law,
//! the held one plastic. A body that micro-bounces a few micrometres up
//! looks the same to the samples, and there the strike drives the
//! hovering contact in and it bounces on its own: the two laws part by the
//! whole impulse the held one takes. A box rocking to rest on a floor
//! (`tests/kalman.rs`,
//! `a_box_rocking_onto_a_corner_keeps_the_other_law_in_reserve`): one
//! corner struck at 0.41 m/s beside the other, which micro-bounced 16 µm
//! up, sends the plant's box to 0.32 rad/s and the held law's to 0.79
//! rad/s the other way, and the filter stayed that far off for three
//! samples, the gate skipping two of them.
//!
//! So where the law held a contact that its force pressed on along the
//! piece before, beside an elastic impact, the interval also computes the
//! outcome with that contact a hair open (`Jump::alternative`: the set met
//! one constraint at a time, each with its restitution), and where the two
//! differ by more than the estimate's velocity noise, the filter keeps it
//! in reserve, an alternative of the mixture (module `mixture`) that is
//! not part of the estimate. Its offset is carried by the free flow, not
//! through the state's projection onto that contact or its plastic
//! closures, which would take the difference out. It is weighed only at a
//! sample that the state's law fails (past the gate), and becomes the
//! state if it explains that sample better; it is dropped once light, or
//! once its hop would have ended (the free flow no longer stands for it),
//! and not kept where it would end before the interval does or where the
//! mixture is full. Its prior weight is the chance that the contact
//! hovers: half, the samples not telling resting from hovering, times the
//! chance that a hidden run of micro-bounces begun when the contact was
//! last seen open or struck lasts until now (the longest starts with a hop
//! as high as the measurement's deviation `b` along the normal and lasts
//! `2 √(2 b / A) / (1 − e)` under the acceleration `A` that presses the
//! contact on; with its first hop's height uniform up to `b`, a run
//! outlasts `Δ` with probability `1 − x²`, `x` the share of that longest
//! run that `Δ` is). A contact glued with no force on it (balls flying
//! together), or under exact samples (`b = 0`), keeps its one law.
//!
//! Weighed at every sample and reported in the estimate's mean, as the
//! plant's steps are, the reserve took the box's worst corner speed error
//! from 0.31 to 0.09 m/s, but the billiard, whose ball rests on one wall
//! of a corner while it bounces off the other, went from 3.0e-3 to 5.1e-2
//! m/s off the brackets at 100 Hz and σ = 1e-4 (1.06e-2 to 3.8e-2 at 1
//! kHz), where samples within the noise made the hovering ball the state;
//! and with neither the force's condition nor the hop's, the three balls
//! sampled at 4 kHz went from 2.4e-5 to 1.03 m/s and the glued balls'
//! test failed. As kept, the box's worst is 0.12 m/s, and of the figures
//! the shipped systems' tests print one moved: a corner of the billiard,
//! 5.6e-2 to 8.0e-2 m/s (design record, "A contact that may hover").
//!
//! # The mean delay of an impact
//!
//! A shift `δ̄ d` of the state just after an impact is a perturbation of
//! the predicted motion, and the motion carries it to the end of the
//! interval as it carries the covariance: through each piece's transition
//! matrix `Φ`, each later impact's saltation matrix `Ξ` and each
//! projection `B` onto a contact manifold. [`Propagation::offset`] is that
//! sum, first order in `δ̄`, added to the predicted end of the interval
//! (the state itself is never moved in the middle of the interval: a
//! post-impact state moved along `d` lies a little inside the constraint,
//! which the interval's event location would take for a crossing).
//!
//! # A time-stepping plant
//!
//! Samples of a simulated plant ([`KalmanParams::plant`]) carry its
//! step's error at each impact. A Moreau–Jean step at `θ = 1/2` that
//! takes the impact into the step whose prediction sees it ends that step
//! in the state of an exact impact delayed by `τ/2 − s` in position, `s`
//! where the gap's root falls in the step, spread uniformly over a step;
//! on Example 1 its velocity comes `τ/(1 + e) − s` late
//! (`tests/kalman.rs`, `the_plants_impacts_are_exact_impacts_delayed`),
//! and where the forces depend on the velocity (a robot's Coriolis terms,
//! which change across the impact) its law's error is of another shape
//! again. Rather than a formula for one law, the filter asks the plant:
//! at each timed impact it takes one step of it across the impact, and
//! adds to its prediction the difference between that step's end and the
//! exact impact flown over the same time.
//!
//! Which step: where the samples lie on the plant's grid
//! ([`KalmanParams::plant_grid`], and the interval a whole number of the
//! plant's steps), the one the plant takes the impact into, from the
//! grid point `t_a` with `t̂* − t_a ∈ (γτ − τ, γτ]`, the pre-impact motion
//! taken back (or on) to `t_a`; and the covariance goes through
//! `DΔ + κ (Ξ − DΔ)` with the staircase's residual variance along `d`,
//! the Gaussian moments of the choice of step over the predicted
//! instant's deviation (module `grid`). From the plant's exact state the
//! prediction then lands on the plant's velocity after an impact to
//! rounding (7e-14 m/s on Example 1,
//! `on_the_plants_grid_the_filter_takes_each_impact_into_the_plants_step`);
//! told the plant, one Gaussian over the steps met the median and
//! 90th percentile on 37 of the 48 random Example 1 starts of
//! `example_1_random_starts_beside_the_reduced_order_observer`, against
//! 33 with the step below. Where the predicted instant is known to within
//! half a step and lies near a window's edge, the likely steps are kept
//! apart instead, a sum of Gaussians until the samples tell them apart
//! (module `mixture`, [`KalmanParams::plant_step_mixture`]): 42 of the 48.
//! A later impact takes each kept step into its own window (its instant is
//! its own, `g·Δq` from the state's), not through the state's map, which
//! is linear in `κ` and, where `σ ≪ τ`, would leave a step that crosses an
//! edge a whole step off. Off the grid, from the impact's instant, the
//! gap closing at the step's start (`s = 0`, the middle of the spread, so
//! to first order the mean of the error); the spread `τ²/12` of where the
//! gap closes joins `σ_t²`. Half a step along `d`, the same for position
//! and velocity, is the fallback where that step fails (or, on the grid,
//! does not impact on the guard). Told the plant, the
//! filter takes its jumps as exact (`ρ_i = 0`,
//! [`KalmanParams::with_plant_step`]): the plant's law is the model's, and
//! its step, now predicted, leaves only the phase. A relative error
//! `ρ_i = 1e-5` on top, the machine's default, is about `1e-4` m/s on a
//! 10 m/s jump and cost Example 1 more than the phase did: restarted from
//! the plant's state before each impact, the filter's median in flight
//! was 1.81 times that of an oracle that knows everything but the phase,
//! and 1.08 times with `ρ_i = 0` (off the grid; `what_the_plants_step_alone_hides`).
//!
//! One delay for both is not enough. Inside an accumulation of impacts on
//! Example 1's curved floor, a filter told `τ/2` as one delay fell behind
//! in normal velocity by a little more at each bounce (to 2e-2 m/s over
//! 22 bounces), its bounces coming earlier and earlier while its positions
//! stayed within micrometres of the samples, which therefore could not
//! correct it; told the plant, it holds as the filter without any delay
//! does (`a_single_delay_drifts_inside_an_accumulation`). On the robots
//! of `tests/robots/` the plant's step is what the defaults' overconfident
//! covariance was missing: the Panda's velocity NEES median fell from 6.7
//! to 40 to 4.4 to 6.4 (`the_filter_follows_a_panda_and_go1s_legs`).
//!
//! # A plant's law along a slide
//!
//! Along a slide the filter flies the exact constrained motion, and so
//! does a plant with the crate's default law
//! ([`ApproachVelocity::Midpoint`], which reflects the curvature's part
//! of the approach whole): over 1 ms at the bottom of Example 1's valley,
//! at 5.9 m/s, it is 1e-8 m/s off a plant ten times finer. Siconos's law
//! ([`ApproachVelocity::Start`], [`StepParams::siconos`]) restitutes that
//! part at `e` at every step, and drags: 4.5e-6 m/s per millisecond
//! there, falling to 1e-9 at 0.8 m/s, 5e-4 m/s lost at each pass through
//! the bottom. A filter that flew the exact slide fell behind by that
//! much at each pass, and the samples, which see it only as a position
//! drift far inside their noise, took hundreds of milliseconds to correct
//! it: its velocity NEES median was 31 on one run that slides
//! (`a_plant_with_siconoss_law_is_told_its_own_step`, seed 555, start 6).
//! So on each piece of a slide the filter told a plant whose law is not
//! the default takes one step of the plant from the piece's start, and
//! one with the same settings and the default law, and adds their
//! difference, times the plant's steps in the piece, to its prediction
//! (the velocity's part integrated into the position), before the
//! projection onto the contact, which keeps its part along the contact.
//! One step from the slide is within 15 % of the mean over the next
//! twelve of the plant's own (scratch). Told Siconos's law, that run's
//! NEES median is 0.83 and the sixteen runs' 0.40 to 1.57. A plant with
//! the default law adds nothing and takes no step.

use nalgebra::{RealField, SMatrix, SVector};

use crate::lcp::{IndexSet, Lcp};
use crate::linalg::Ldlt;
use crate::model::Sensitivities;
use crate::state::State;
use crate::stepper::{ApproachVelocity, MoreauJean, StepParams, StepReport};
use crate::validate::{self, factor_mass};

use super::super::ObserverError;
use super::super::interval::{Flight, Jump, Law, Tracer, fastest_approach, saturate};
use super::grid::{SPLIT, likely_windows, staircase};
use super::level::Levels;
use super::mixture::{ALTERNATIVES, Mixture, Offset, no_offset};
use super::saltation::{
    Saltation, constrained_flow_jacobian, flow_jacobian, flow_transition, project_onto_contact,
    saltation,
};
use super::{Blocks, KalmanParams};

type Result<X, T> = core::result::Result<X, ObserverError<T>>;

/// The covariance along the predicted motion of one interval.
pub(super) struct Propagation<'a, M, T, const N: usize, const K: usize>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    model: &'a M,
    u: &'a M::Input,
    t0: T,
    /// The interval's end, `t0` plus its length.
    end: T,
    bound: T,
    /// `q_a²` per coordinate.
    density: SVector<T, N>,
    /// `ρ_i²`, `ρ_c²` and `σ_t²` (with a plant whose grid is not known,
    /// its phase's `τ_p²/12`).
    impact: T,
    contact: T,
    timing: T,
    /// The machine's own `σ_t`, without a plant's phase.
    machine_timing: T,
    /// Whether the plant's step grid passes through the samples (the
    /// interval is a whole number of its steps; module `grid`).
    on_grid: bool,
    /// The covariance so far.
    pub p: Blocks<T, N>,
    /// The move of the predicted end onto the contact manifold, when the
    /// last piece was a persistent contact.
    pub correction: (SVector<T, N>, SVector<T, N>),
    /// `δ̄`, the mean delay of an impact.
    delay: T,
    /// The time-stepping plant the samples come from
    /// ([`KalmanParams::plant`]; `None` for a machine).
    plant: Option<StepParams<T>>,
    /// The predicted end's shift from the mean delays of the impacts so
    /// far, carried to the end of the last piece (module docs), plus the
    /// prior's deviation from the linearisation point when the filter
    /// relinearises ([`Propagation::relinearised`]).
    pub offset: (SVector<T, N>, SVector<T, N>),
    /// Whether `offset` is carried (a mean delay, or a relinearisation).
    carry: bool,
    /// The steps a plant may have taken an impact into, beside the
    /// predicted one (module `mixture`): offsets carried as `offset` is.
    pub mixture: Mixture<T, N>,
    /// When each constraint was last seen open or struck at a sample
    /// (`None`: no law is kept in reserve; module docs, "A contact that
    /// may hover"), and the measurement noise `R`.
    held_since: Option<SVector<T, K>>,
    measurement: SMatrix<T, N, N>,
    /// Whether an impact may still split the prediction
    /// ([`KalmanParams::plant_step_mixture`] set, and none split yet in
    /// this interval).
    may_split: bool,
    /// `Φ P_k`, the covariance of the predicted end with the start, when
    /// the filter relinearises (`None` otherwise: no work).
    pub cross: Option<Blocks<T, N>>,
    pub saltations: u32,
    pub projections: u32,
    /// The constraints held along the last piece (pushing), if it ended
    /// the interval: the contacts the predicted end lies on.
    pub held: IndexSet<K>,
    /// The gaps the held contacts are held at, their covariance and its
    /// correlation with the state, carried along the interval (module
    /// `level`; only the correlation changes here).
    pub levels: Levels<T, N, K>,
    /// The fastest approach `−J_i w⁻` of each constraint that took an
    /// impulse at an impact of the interval (`0` where none did).
    pub struck: SVector<T, K>,
}

impl<'a, M, T, const N: usize, const K: usize> Propagation<'a, M, T, N, K>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    /// Follows `p` from `t0` over an interval of length `length` under the
    /// noise of `params`; `held_since`, when each constraint was last seen
    /// open or struck at a sample, lets a law that holds a contact beside
    /// an impact keep the one in which it hovered in reserve (module docs,
    /// "A contact that may hover"); a contact held along a piece is held
    /// at its gap in `levels` (module `level`: the levels' means and
    /// variances).
    pub fn new(
        model: &'a M,
        u: &'a M::Input,
        (t0, length): (T, T),
        params: &KalmanParams<T, N>,
        (p, mixture): (Blocks<T, N>, Mixture<T, N>),
        (held_since, levels): (Option<SVector<T, K>>, &Levels<T, N, K>),
    ) -> Self {
        let square = |x: T| x * x;
        // the samples lie on the plant's grid where the interval is a
        // whole number of its steps, to a thousandth of a step
        let on_grid = params.plant_grid
            && params.plant.is_some_and(|plant| {
                let steps = length / plant.tau;
                steps >= T::one() && (steps - steps.round()).abs() <= nalgebra::convert(1e-3)
            });
        Self {
            model,
            u,
            t0,
            end: t0 + length,
            bound: params.observer.velocity_bound,
            density: params.accel_noise.component_mul(&params.accel_noise),
            impact: square(params.impact_noise),
            contact: square(params.contact_noise),
            // the plant's step grid, a uniform phase over a step, adds
            // its spread `τ_p/√12` to the machine's `σ_t`
            timing: square(params.impact_time_sigma)
                + params
                    .plant
                    .map_or(T::zero(), |p| square(p.tau) / nalgebra::convert(12.0)),
            machine_timing: params.impact_time_sigma,
            on_grid,
            p,
            correction: (SVector::zeros(), SVector::zeros()),
            delay: params.impact_delay,
            plant: params.plant,
            offset: (SVector::zeros(), SVector::zeros()),
            carry: params.impact_delay != T::zero() || params.plant.is_some(),
            mixture,
            held_since,
            measurement: params.measurement,
            may_split: params.plant_step_mixture,
            cross: None,
            saltations: 0,
            projections: 0,
            held: IndexSet::EMPTY,
            levels: *levels,
            struck: SVector::zeros(),
        }
    }

    /// The probability that one of the contacts `hovering` that the law of
    /// `jump` held (met with no restitution, pressed on by their force)
    /// hovers a hair above its constraint, unseen, and
    /// when its hop in the outcome `w⁺ + dv` ends (module docs, "A contact
    /// that may hover"). The probability is half, the samples not telling
    /// resting from hovering, times the chance that a hidden run of
    /// micro-bounces begun when the contact was last seen open or struck
    /// lasts until now: the longest such run starts with a hop as high as
    /// the measurement's deviation `b` along the normal and lasts `2 √(2 b
    /// / A) / (1 − e)` under the acceleration `A` that presses the contact
    /// on; with its first hop's height uniform up to `b`, a run outlasts
    /// `Δ` with probability `1 − x²`, `x` the share of that longest run
    /// that `Δ` is. `None` where no held contact may hover, or where its
    /// hop ends before the interval does (the free flow that carries the
    /// outcome's offset no longer describes it at the sample).
    fn may_hover(
        &self,
        jump: &Jump<'_, T, N, K>,
        (hovering, dv): (IndexSet<K>, &SVector<T, N>),
    ) -> Option<(T, T)> {
        let (since, measurement) = (self.held_since.as_ref()?, &self.measurement);
        let t = self.t0 + jump.s;
        let (half, two): (T, T) = (nalgebra::convert(0.5), nalgebra::convert(2.0));
        let w = jump.w_plus + dv;
        let mut likeliest: Option<(T, T)> = None;
        for i in hovering {
            let row = jump.jac.row(i);
            let g = row.norm();
            let press = -row.dot(&jump.free.accel.transpose()) / g;
            let band = (row * measurement * row.transpose())[(0, 0)]
                .max(T::zero())
                .sqrt()
                / g;
            let departs = row.dot(&w.transpose()) / g;
            if press <= T::zero() || band <= T::zero() || departs <= T::zero() {
                continue;
            }
            let lands = t + two * departs / press;
            let longest = two * (two * band / press).sqrt() / (T::one() - jump.restitution[i]);
            let x = (t - since[i]) / longest;
            if x < T::one() && lands >= self.end {
                let p = half * (T::one() - x * x);
                if likeliest.is_none_or(|(q, _)| p > q) {
                    likeliest = Some((p, lands));
                }
            }
        }
        likeliest
    }

    /// The mean delay of an impact and the variance of its instant, as
    /// this propagation times impacts: `δ̄` plus half a plant's step (its
    /// impacts land uniformly within a step), and `σ_t²` plus `τ_p²/12`.
    /// The depth a struck contact is held at takes them (module `level`).
    pub fn lateness(&self) -> (T, T) {
        let half: T = nalgebra::convert(0.5);
        let step = self.plant.map_or(T::zero(), |plant| plant.tau);
        (self.delay + step * half, self.timing)
    }

    /// The same propagation for a prediction linearised at a point other
    /// than the prior's mean: `deviation` (the prior's mean minus that
    /// point) is carried to the end as the offset is, so that the
    /// predicted end is `φ(x_lin) + Φ (x̂_k − x_lin)`, and `Φ P_k` is
    /// followed in [`Propagation::cross`] (see the filter's
    /// relinearisation in `runtime/src/observer/kalman/mod.rs`).
    pub fn relinearised(self, deviation: (SVector<T, N>, SVector<T, N>)) -> Self {
        Self {
            offset: deviation,
            carry: true,
            cross: Some(self.p),
            ..self
        }
    }

    /// Carries the offset (the mean delays', a relinearisation's
    /// deviation) and `Φ P_k` through the linear map `map` (a piece's
    /// transition, an impact's saltation, a projection). Nothing to carry,
    /// and no work, without a mean delay (the default) or a
    /// relinearisation.
    fn carry_offset(&mut self, map: &Blocks<T, N>) {
        if self.carry {
            self.offset = map.apply(&self.offset.0, &self.offset.1);
        }
        self.mixture.carry(map);
        if let Some(cross) = &mut self.cross {
            *cross = map.mul(cross);
        }
    }
}

/// White acceleration noise of density `d` (a symmetric `N × N` matrix)
/// integrated exactly over `h` for `q'' = w`:
/// `[[h³/3, h²/2], [h²/2, h]] ⊗ d`.
fn white_noise<T: RealField + Copy, const N: usize>(d: &SMatrix<T, N, N>, h: T) -> Blocks<T, N> {
    let h2 = h * h;
    let qv = d * (h2 * nalgebra::convert(0.5));
    Blocks {
        qq: d * (h2 * h / nalgebra::convert(3.0)),
        qv,
        vq: qv,
        vv: d * h,
    }
}

/// `(wᵀ M w / N) M⁻¹`: the covariance of an error isotropic in the metric
/// of the kinetic energy whose expected energy is that of `w`.
fn energy_isotropic<T: RealField + Copy, const N: usize>(
    mass: &SMatrix<T, N, N>,
    chol: &Ldlt<T, N>,
    w: &SVector<T, N>,
) -> SMatrix<T, N, N> {
    let scale = w.dot(&(mass * w)) / nalgebra::convert(N.max(1) as f64);
    chol.solve(&SMatrix::identity()) * scale
}

impl<M, T, const N: usize, const K: usize> Propagation<'_, M, T, N, K>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    /// The relative noise of the contact force that pushed along `piece`
    /// on the constraints `held`: `ρ_c² (a_cᵀ M a_c / N) M⁻¹` with
    /// `a_c = M⁻¹ J_heldᵀ ∫λ / h`.
    fn contact_density(
        &self,
        piece: &Flight<'_, T, N, K>,
        held: IndexSet<K>,
        jac: &SMatrix<T, K, N>,
        (mass, chol): (&SMatrix<T, N, N>, &Ldlt<T, N>),
    ) -> SMatrix<T, N, N> {
        if self.contact == T::zero() || piece.h <= T::zero() {
            return SMatrix::zeros();
        }
        let mut push = SVector::<T, N>::zeros();
        for i in held {
            push += jac.row(i).transpose() * piece.impulse[i];
        }
        let accel = chol.solve(&push) / piece.h;
        energy_isotropic(mass, chol, &accel) * self.contact
    }

    /// The constraints of `held` that the motion leaves at the end of
    /// `piece`: the acceleration-level law `0 ≤ λ ⊥ J a + J̇ w ≥ 0` on
    /// `held` at `(p1, w1)` gives them no force and a normal acceleration
    /// away from the constraint (beyond rounding: `√ε` of the free
    /// motion's terms), and their normal speed `J_i w1` is already
    /// separating.
    ///
    /// A contact whose force runs out inside a piece (a robot's tool
    /// lifting off a table as the arm swings) lifts off in the predicted
    /// motion as well, since the interval holds it at acceleration level
    /// at every stage; projecting the end onto its manifold took that
    /// separating speed back out of the estimate, and the covariance,
    /// projected with it, kept the samples from putting it back. On a
    /// UR5 swinging its tool off a table (`tests/robots/kalman.rs`), one
    /// such projection left the joint velocities 2.2e-4 rad/s off while
    /// the filter claimed 3.1e-5, for hundreds of milliseconds; on the
    /// double pendulum's tip leaving the floor, 6.4e-5 rad/s off against
    /// 1.0e-5 when it lifts off with the plant. A contact that only the
    /// other contacts' forces pull away lifts off too: the law says so
    /// (a mass pushed up a ramp off the floor that gravity alone presses
    /// it onto; a Panda's hand lifted off a table by the force of a joint
    /// limit). Asking the free motion alone to leave it as well, as this
    /// did before, held such a contact until the gate let it go, 0.1 m/s
    /// off (`tests/kalman.rs`,
    /// `a_contact_that_another_contacts_force_pulls_away_lifts_off`). A
    /// pair that travels together with no force (glued balls), whose
    /// normal acceleration is zero up to rounding, stays held.
    fn lifted(
        &self,
        piece: &Flight<'_, T, N, K>,
        held: IndexSet<K>,
        (jac, rate): (&SMatrix<T, K, N>, &SMatrix<T, K, N>),
        mass: &Ldlt<T, N>,
    ) -> Result<IndexSet<K>, T> {
        let w1 = piece.w1;
        // only a constraint already separating can have lifted off: the
        // common piece, resting or sliding with no normal speed, needs no
        // forces and no law at its end
        let mut separating = IndexSet::<K>::EMPTY;
        for i in held {
            if jac.row(i).dot(&w1.transpose()) > T::zero() {
                separating.insert(i);
            }
        }
        if separating.is_empty() {
            return Ok(IndexSet::EMPTY);
        }
        // (the forces at `sat(w)`, as the interval takes them)
        let forces = self.model.forces(
            self.t0 + piece.s0 + piece.h,
            piece.p1,
            &saturate(w1, self.bound),
            self.u,
        );
        validate::finite_model(&forces, "F")?;
        let accel = -mass.solve(&forces);
        let minv_jt = mass.solve(&jac.transpose());
        let delassus = jac * minv_jt;
        let delassus = (delassus + delassus.transpose()) * nalgebra::convert::<f64, T>(0.5);
        let jdot_w = rate * w1;
        let b = jac * accel + jdot_w;
        let Ok(law) = Lcp::default().solve(&delassus, &b, held) else {
            // no law at the end to tell from: the end stays on them all
            return Ok(IndexSet::EMPTY);
        };
        let sqrt_eps = T::default_epsilon().sqrt();
        let mut lifted = IndexSet::EMPTY;
        for i in separating.iter() {
            let scale = jac.row(i).norm() * accel.norm() + jdot_w[i].abs();
            let beyond = sqrt_eps * scale;
            if law.lambda[i] == T::zero() && law.w[i] > beyond {
                lifted.insert(i);
            }
        }
        Ok(lifted)
    }

    /// The noise an impact adds: `ρ_i² (ΔvᵀMΔv/N) M⁻¹` on the velocity and,
    /// for an impact that a gap's root timed (`timed`), `σ_t² d dᵀ` along
    /// the delay direction. A plastic closure or a law met at a constraint
    /// already closed has no instant of its own (the interval applies it
    /// where the contact rule holds the constraint), as it has no mean
    /// delay ([`KalmanParams::impact_delay`]). On Example 1 such laws are
    /// the plastic closures by which the filter enters a slide; with the
    /// timing term there as well, the median velocity error over
    /// `[2, 10]` s of the model file's start (σ = 1e-4, defaults) was
    /// 2.7e-5 m/s instead of 2.1e-5 when this rule was made (a scratch
    /// run; the current figure is in README, "Under noise").
    fn impact_noise(
        &self,
        s: &Saltation<T, N, K>,
        timed: bool,
        q: &SVector<T, N>,
        w: &SVector<T, N>,
    ) -> Result<Blocks<T, N>, T> {
        let (dq, dv) = s.timing;
        let mut noise = if timed {
            Blocks::outer(&dq, &dv).scaled(self.timing)
        } else {
            Blocks::diagonal(SMatrix::zeros(), SMatrix::zeros())
        };
        if self.impact > T::zero() {
            let mass = self.model.mass(q);
            validate::finite_model(&mass, "M")?;
            let chol = factor_mass(&mass)?;
            noise.vv += energy_isotropic(&mass, &chol, &(s.v_plus - w)) * self.impact;
        }
        Ok(noise)
    }

    /// Merges the mixture into the prediction: the offset moves to its
    /// mean, and its spread joins the covariance.
    fn collapse(&mut self) {
        let ((dq, dv), spread) = self.mixture.moments();
        self.p = self.p.add(&spread).symmetrized();
        self.offset.0 += dq;
        self.offset.1 += dv;
        self.mixture = Mixture::empty();
    }

    /// A timed impact on the grid of a plant whose steps fall on the
    /// samples (module `grid`): the step window the predicted instant
    /// falls in, the plant's error there against the exact impact, and
    /// the staircase's moments over the instant's deviation. `None` where
    /// the guard does not approach, the plant's step from the window's
    /// start fails or does not impact on the guard (the fallback is the
    /// uniform phase).
    fn on_grid_impact(
        &self,
        jump: &Jump<'_, T, N, K>,
        (w, s): (&SVector<T, N>, &Saltation<T, N, K>),
        guard: usize,
        plant: StepParams<T>,
    ) -> Option<OnGrid<T, N>> {
        let row = jump.jac.row(guard);
        let rate = row.dot(&w.transpose());
        if rate.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Less) {
            return None;
        }
        // the instant's deviation from the estimate's gap along the guard
        let sigma_state = (row * self.p.qq * row.transpose())[(0, 0)]
            .max(T::zero())
            .sqrt()
            / -rate;
        let (tau, gamma) = (plant.tau, plant.gamma);
        // the step from `t_a` sees the gap close when `t* − t_a ∈ (γτ − τ, γτ]`
        let start = ((jump.s - gamma * tau) / tau).ceil() * tau;
        let phase = jump.s - start;
        let lower = gamma * tau - tau - phase;
        let t = self.t0 + jump.s;
        let error = plant_window_error(
            self.model,
            self.u,
            (t, phase, jump.p, w, &s.v_plus),
            plant,
            guard,
        )?;
        let reset = s.reset();
        // the instant's error per unit of the state's: `δ = g·δq`
        let g = row.transpose() / -rate;
        let sigma2 = sigma_state * sigma_state + self.machine_timing * self.machine_timing;
        if self.may_split
            && let Some((windows, split)) = likely_windows(tau, lower, sigma2.sqrt())
        {
            // a sum over the likely steps (module `mixture`): each the
            // state conditioned on its window (the instant's error `δ`
            // has `Cov(x, δ) = P ĝ`, `ĝ = (−J_g/(J_g v), 0)`), through the
            // reset's Jacobian (inside a window the plant's outcome does
            // not move with the instant), `j τ d` apart; one covariance,
            // conditioned on the windows' mean variance
            let (pg_q, pg_v) = (self.p.qq * g, self.p.vq * g);
            let moved = |m: T| reset.apply(&(pg_q * (m / sigma2)), &(pg_v * (m / sigma2)));
            let best = windows[0];
            let variance = windows[..split]
                .iter()
                .fold(T::zero(), |acc, w| acc + w.probability * w.variance);
            let shrink = (sigma2 - variance) / (sigma2 * sigma2);
            let conditioned = self.p.add(&Blocks::outer(&pg_q, &pg_v).scaled(-shrink));
            let along = |steps: T| (s.timing.0 * (steps * tau), s.timing.1 * (steps * tau));
            let (own_q, own_v) = moved(best.mean);
            let (own_dq, own_dv) = along(best.steps);
            let mut alternatives = [(no_offset(), T::zero()); SPLIT - 1];
            for (slot, w) in alternatives.iter_mut().zip(&windows[1..split]) {
                let (mq, mv) = moved(w.mean - best.mean);
                let (dq, dv) = along(w.steps - best.steps);
                *slot = ((mq + dq, mv + dv), (w.probability / best.probability).ln());
            }
            // only steps the samples can tell apart are kept apart: an
            // alternative at least one deviation of the velocity after the
            // impact from the state (closer ones, as the slow bounces of an
            // accumulation, are one Gaussian's spread: the moments below)
            let after = reset.congruence(&conditioned);
            let apart = nalgebra::Cholesky::new(after.vv).is_some_and(|chol| {
                alternatives[..split - 1]
                    .iter()
                    .any(|((_, dv), _)| dv.dot(&chol.solve(dv)) >= T::one())
            });
            if apart && conditioned.is_finite() && reset.is_finite() {
                return Some(OnGrid {
                    offset: (error.0 + own_q + own_dq, error.1 + own_v + own_dv),
                    map: reset,
                    residual: T::zero(),
                    steps: Steps::Split {
                        conditioned,
                        alternatives,
                        len: split - 1,
                    },
                });
            }
        }
        let stairs = staircase(tau, lower, sigma_state, self.machine_timing);
        let map = reset
            .scaled(T::one() - stairs.slope)
            .add(&s.matrix.scaled(stairs.slope));
        let offset = (
            error.0 + s.timing.0 * stairs.mean,
            error.1 + s.timing.1 * stairs.mean,
        );
        // the steps an earlier impact may have been taken into: each has
        // its own instant, `g·Δq_a` from the state's, and so its own window
        // and its own staircase mean (through the state's map, linear with
        // the state's `κ ≈ 0` where `σ ≪ τ`, a step whose instant lies
        // across an edge would land a whole step off)
        let mut carried = [no_offset(); ALTERNATIVES];
        for (a, slot) in carried.iter_mut().enumerate().take(self.mixture.len()) {
            let (dq, dv) = self.mixture.offset(a);
            let shifted = lower - g.dot(&dq);
            let whole = (shifted / tau).ceil();
            let own = staircase(tau, shifted - whole * tau, sigma_state, self.machine_timing);
            let jump_a = own.mean - whole * tau - stairs.mean;
            let (rq, rv) = reset.apply(&dq, &dv);
            *slot = (rq + s.timing.0 * jump_a, rv + s.timing.1 * jump_a);
        }
        (map.is_finite() && stairs.residual.is_finite()).then_some(OnGrid {
            offset,
            map,
            residual: stairs.residual,
            steps: Steps::Carried(carried),
        })
    }

    /// The saltation of an impact that the contact rule resolved one
    /// constraint at a time (the fastest approach first, each once, as
    /// `Interval::one_at_a_time` does): the product of the single
    /// constraints' saltations at the same point, the first timed by the
    /// guard, the later ones untimed (they follow at once), and the timing
    /// direction carried through the later ones. `None` when no constraint
    /// of the set approaches.
    fn one_at_a_time(
        &self,
        jump: &Jump<'_, T, N, K>,
        w: &SVector<T, N>,
        e: &SVector<T, K>,
        guard: Option<usize>,
    ) -> Result<Option<Saltation<T, N, K>>, T> {
        let t = self.t0 + jump.s;
        let mut left = jump.set;
        let mut composed: Option<Saltation<T, N, K>> = None;
        let mut v = *w;
        while let Some((i, _)) = fastest_approach(jump.jac, &v, left) {
            left.remove(i);
            let mut single = IndexSet::EMPTY;
            single.insert(i);
            let timed = if composed.is_none() {
                guard.filter(|&g| g == i)
            } else {
                None
            };
            let step = saltation(self.model, t, jump.p, &v, self.u, single, e, timed)?;
            v = step.v_plus;
            composed = Some(match composed {
                None => step,
                Some(before) => Saltation {
                    matrix: step.matrix.mul(&before.matrix),
                    reset_dv: step.reset_dv * before.reset_dv,
                    reset_dq: step.reset_dq + step.reset_dv * before.reset_dq,
                    timing: step.matrix.apply(&before.timing.0, &before.timing.1),
                    lambda: before.lambda + step.lambda,
                    ..step
                },
            });
        }
        Ok(composed)
    }
}

impl<M, T, const N: usize, const K: usize> Tracer<T, N, K> for Propagation<'_, M, T, N, K>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    const ALTERNATIVE: bool = true;

    fn flight(&mut self, piece: &Flight<'_, T, N, K>) -> Result<(), T> {
        let w0 = saturate(piece.w0, self.bound);
        let t = self.t0 + piece.s0;
        // the contacts that pushed along the piece, and those resting on
        // it with no force (glued bodies in free flight: without the
        // projection their relative velocity is only as well known as the
        // samples make it, and the estimate takes them apart)
        let held = piece.held();
        let (phi, flown) = if held.is_empty() && M::STRUCTURE.acceleration_state_free() {
            // an acceleration free of q and v by the model's structure
            // (Example 1, the three balls, the billiard): Φ = (I, hI; 0, I)
            // exactly, which the general path computes to the bit; no
            // Jacobian, and the congruence written out
            (
                Blocks::ballistic(piece.h),
                self.p.ballistic_congruence_covered(piece.h),
            )
        } else {
            let (a, _) = if held.is_empty() {
                flow_jacobian(self.model, t, piece.p0, &w0, self.u)?
            } else {
                constrained_flow_jacobian(self.model, t, piece.p0, &w0, self.u, held)?
            };
            let phi = flow_transition(&a, piece.h);
            (phi, phi.congruence_covered(&self.p))
        };
        self.levels.map_state(&phi);
        self.held = held;
        // an alternative with a contact open that the state holds flies
        // free, not along the contact (carried again below)
        let open = if held.is_empty() {
            None
        } else {
            self.mixture.open_offsets()
        };
        let noise = white_noise(&SMatrix::from_diagonal(&self.density), piece.h);
        let mut p = flown.add(&noise);
        self.carry_offset(&phi);
        self.correction = (SVector::zeros(), SVector::zeros());
        if !held.is_empty() {
            // a plant whose law drags along a slide: its steps over the
            // piece, each with the drag of one from the piece's start
            // (module docs, "A plant's law along a slide"), before the
            // projection, which keeps their part along the contact
            if let Some(plant) = self.plant
                && let Some((dq, dv)) =
                    plant_slide_error(self.model, self.u, (t, piece.p0, &w0), plant)
            {
                let steps = piece.h / plant.tau;
                let half: T = nalgebra::convert(0.5);
                self.offset.0 += dq * steps + dv * (steps * piece.h * half);
                self.offset.1 += dv * steps;
            }
            // onto the manifold h_S = ℓ_S, J_S v = 0 at the end of the
            // piece (ℓ the contacts' levels, module `level`): the
            // covariance, and the state in the same metric
            let (h, jac) = self.model.contact(piece.p1);
            let rate = self.model.jacobian_dq(piece.p1, piece.w1);
            validate::finite_model(&h, "h")?;
            validate::finite_model(&jac, "J")?;
            validate::finite_model(&rate, "d(Jv)/dq")?;
            let m = self.model.mass(piece.p1);
            validate::finite_model(&m, "M")?;
            let mass = factor_mass(&m)?;
            let contact = self.contact_density(piece, held, &jac, (&m, &mass));
            p = p.add(&white_noise(&contact, piece.h));
            // the contacts the end still lies on: not those the motion
            // leaves there (`lifted`)
            let ends_on = held.difference(self.lifted(piece, held, (&jac, &rate), &mass)?);
            self.held = ends_on;
            let mut across = SMatrix::<T, N, N>::identity();
            let projection = if ends_on.is_empty() {
                None
            } else {
                project_onto_contact(
                    &p,
                    &mass,
                    &(h - self.levels.mean),
                    &jac,
                    &rate,
                    piece.w1,
                    ends_on,
                )
            };
            let mut level = None;
            if let Some(projection) = projection {
                p = projection.p;
                across -= projection.map.qq;
                self.correction = (projection.dq, projection.dv);
                self.carry_offset(&projection.map);
                self.projections += 1;
                // the levels' own covariance and their correlation with
                // the state (a contact held without an impact has no
                // variance: nothing to add)
                if self.levels.uncertain() {
                    level = Some(self.levels.project(&projection));
                }
            }
            // what the contact leaves uncertain across it: the part of
            // the piece's noise that the projection took (`I − Π` of its
            // position and velocity variances), put back uncorrelated (a
            // correlated floor would turn the contact's own penetration,
            // seen in the samples, into a velocity); the tangential noise
            // is still in `P`, and adding it again counted it twice (the
            // three balls' glued pair, held at every step, 10 to 22 %
            // higher medians at σ = 1e-4)
            p = p.add(&Blocks::diagonal(
                across * noise.qq * across.transpose(),
                across * noise.vv * across.transpose(),
            ));
            if let Some(level) = level {
                p = p.add(&level);
            }
        }
        if let Some(open) = open {
            let (a_free, _) = flow_jacobian(self.model, t, piece.p0, &w0, self.u)?;
            let phi_free = flow_transition(&a_free, piece.h);
            self.mixture.restore_open(&open, Some(&phi_free));
        }
        self.p = p.symmetrized();
        Ok(())
    }

    fn jump(&mut self, jump: &Jump<'_, T, N, K>) -> Result<(), T> {
        // the restitutions of the elastic constraints, and the set that
        // took an impulse with theirs
        let mut e_set = SVector::<T, K>::zeros();
        for i in jump.elastic {
            e_set[i] = jump.restitution[i];
        }
        let mut active = IndexSet::EMPTY;
        let mut e = SVector::<T, K>::zeros();
        for i in jump.set {
            if jump.lambda[i] > T::zero() {
                active.insert(i);
                e[i] = e_set[i];
            }
        }
        if active.is_empty() {
            return Ok(());
        }
        for i in active {
            let approach = -jump.jac.row(i).dot(&jump.w_minus.transpose());
            self.struck[i] = self.struck[i].max(approach);
        }
        self.held = IndexSet::EMPTY;
        // the impact time moves with the constraint whose root timed it
        // (the fastest-approaching if several), for an elastic law only
        let jac = jump.jac;
        let guard = jump
            .guard
            .intersection(jump.elastic)
            .intersection(active)
            .iter()
            .map(|i| {
                let row = jac.row(i);
                (i, row.dot(&jump.w_minus.transpose()) / row.norm())
            })
            .fold(None, |best: Option<(usize, T)>, (i, r)| match best {
                Some((_, b)) if b <= r => best,
                _ => Some((i, r)),
            })
            .map(|(i, _)| i);
        self.correction = (SVector::zeros(), SVector::zeros());
        let w = saturate(jump.w_minus, self.bound);
        let t = self.t0 + jump.s;
        // the saltation of the law that gave `w⁺` (module docs): Newton's
        // on the set; Moreau's, which is Newton's with the least
        // restitution on every constraint that took an impulse; or the
        // product of single impacts where the rule met the constraints
        // one at a time
        let newton =
            |e: &SVector<T, K>| saltation(self.model, t, jump.p, &w, self.u, active, e, guard);
        let s = match jump.law {
            Law::Newton => newton(&e)?,
            Law::Moreau(least) => {
                let mut uniform = SVector::<T, K>::zeros();
                for i in active {
                    uniform[i] = least;
                }
                newton(&uniform)?
            }
            Law::OneAtATime => match self.one_at_a_time(jump, &w, &e_set, guard)? {
                Some(product) => product,
                None => newton(&e)?,
            },
        };
        // a gap's root timed the impact: it has an instant, uncertain by
        // σ_t (and a plant's step grid) and late on average by δ̄ (or by
        // a plant's own step); a closure the LCP makes at the start of a
        // piece has neither
        let timed = guard.is_some();
        // a plant whose grid passes through the samples: the window its
        // step falls in, and the staircase's moments (module `grid`)
        let on_grid = match (self.plant.filter(|_| self.on_grid), guard) {
            (Some(plant), Some(g)) => self.on_grid_impact(jump, (&w, &s), g, plant),
            _ => None,
        };
        let splits = on_grid
            .as_ref()
            .is_some_and(|g| matches!(g.steps, Steps::Split { .. }));
        if splits && !self.mixture.is_empty() {
            // the steps of an earlier impact, still undecided, are
            // merged into one Gaussian (their mean and spread), and
            // this impact takes the staircase's moments: inside an
            // accumulation, splitting at every bounce and merging at
            // the next left the normal velocity 4.8e-3 m/s off where
            // one split at a time leaves 1.8e-3
            // (`a_single_delay_drifts_inside_an_accumulation`)
            self.collapse();
            self.may_split = false;
            return self.jump(jump);
        }
        let (map, noise) = match &on_grid {
            Some(on_grid) => (
                on_grid.map,
                self.impact_noise(&s, false, jump.p, &w)?
                    .add(&Blocks::outer(&s.timing.0, &s.timing.1).scaled(on_grid.residual)),
            ),
            None => (s.matrix, self.impact_noise(&s, timed, jump.p, &w)?),
        };
        let prior = match &on_grid {
            Some(OnGrid {
                steps: Steps::Split { conditioned, .. },
                ..
            }) => *conditioned,
            _ => self.p,
        };
        self.p = map.congruence_covered(&prior).add(&noise).symmetrized();
        // (the levels' correlation mapped as the state is; a plant's
        // step window's conditioning of `P`, module `grid`, leaves it as
        // it was)
        self.levels.map_state(&map);
        // a closure with no bounce is the state's contact: an alternative
        // that has it open does not meet it
        let plastic = jump.elastic.intersection(active).is_empty();
        let open = if plastic {
            self.mixture.open_offsets()
        } else {
            None
        };
        self.carry_offset(&map);
        if let Some(open) = open {
            self.mixture.restore_open(&open, None);
        }
        if let Some(on_grid) = on_grid {
            self.offset.0 += on_grid.offset.0;
            self.offset.1 += on_grid.offset.1;
            match on_grid.steps {
                // the other steps the plant may have taken it into, after
                // the impact (module `mixture`)
                Steps::Split {
                    alternatives, len, ..
                } => {
                    for &(offset, log_weight) in &alternatives[..len] {
                        self.mixture.push(offset, log_weight);
                    }
                    self.may_split = false;
                }
                // an earlier impact's kept steps, each in its own window
                Steps::Carried(carried) => {
                    for (a, &offset) in carried.iter().enumerate().take(self.mixture.len()) {
                        self.mixture.set_offset(a, offset);
                    }
                }
            }
        } else if timed {
            // a mean delay moves the state along `d`; a plant's step, by
            // its own error at the impact (module docs, "A time-stepping
            // plant"), or where its step fails by half a step along `d`
            let half: T = nalgebra::convert(0.5);
            let mut along_d = self.delay;
            if let Some(plant) = self.plant {
                match plant_step_error(self.model, self.u, (t, jump.p, &w, &s.v_plus), plant) {
                    Some((dq, dv)) => {
                        self.offset.0 += dq;
                        self.offset.1 += dv;
                    }
                    None => along_d += plant.tau * half,
                }
            }
            if along_d != T::zero() {
                self.offset.0 += s.timing.0 * along_d;
                self.offset.1 += s.timing.1 * along_d;
            }
        }
        // a contact the law held that may have hovered (`Jump::alternative`):
        // its outcome kept in reserve (module docs)
        if let Some((dv, (p, lands))) = jump
            .alternative
            .and_then(|(hovering, dv)| Some((dv, self.may_hover(jump, (hovering, &dv))?)))
        {
            let offset = (SVector::zeros(), dv);
            self.mixture
                .push_open(offset, p.ln() - (T::one() - p).ln(), lands);
        }
        self.saltations += 1;
        Ok(())
    }
}

/// What a plant's step grid makes of one timed impact
/// ([`Propagation::on_grid_impact`]).
struct OnGrid<T: RealField + Copy, const N: usize> {
    /// The plant's error in its window plus the staircase's mean shift
    /// along the delay direction.
    offset: (SVector<T, N>, SVector<T, N>),
    /// `DΔ + κ (Ξ − DΔ)`.
    map: Blocks<T, N>,
    /// The delay's variance the state does not explain, along `d`.
    residual: T,
    /// What becomes of the steps the plant may have taken impacts into.
    steps: Steps<T, N>,
}

/// The steps an impact on the plant's grid keeps apart (module
/// `mixture`).
enum Steps<T: RealField + Copy, const N: usize> {
    /// The impact splits the prediction: the covariance before it
    /// conditioned on the predicted step, and the other likely steps'
    /// offsets after it from the predicted one with their log-weights
    /// relative to it (the first `len`).
    Split {
        conditioned: Blocks<T, N>,
        alternatives: [(Offset<T, N>, T); SPLIT - 1],
        len: usize,
    },
    /// It does not: the steps an earlier impact was kept apart in, each
    /// taken into its own window (the first [`Mixture::len`]).
    Carried([Offset<T, N>; ALTERNATIVES]),
}

/// The drag of a plant's law along a slide: one step of the plant
/// `plant` from `(q, v)` at `t` against the same step with the
/// energy-consistent law ([`ApproachVelocity::Midpoint`]), which holds a
/// slide on a curved surface (module docs, "A plant's law along a
/// slide"). `None` for a plant with that law (nothing to add), where
/// either step fails, or where the difference is not finite.
fn plant_slide_error<M, T, const N: usize, const K: usize>(
    model: &M,
    u: &M::Input,
    (t, q, v): (T, &SVector<T, N>, &SVector<T, N>),
    plant: StepParams<T>,
) -> Option<(SVector<T, N>, SVector<T, N>)>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    if plant.approach_velocity == ApproachVelocity::Midpoint {
        return None;
    }
    let (plants, _) = plant_step(model, u, (t, q, v), plant)?;
    let (holding, _) = plant_step(
        model,
        u,
        (t, q, v),
        plant.with_approach_velocity(ApproachVelocity::Midpoint),
    )?;
    finite((plants.q - holding.q, plants.v - holding.v))
}

/// One step of the plant `plant` from `(q, v)` at `t`, and what the step
/// did; `None` where its settings are refused or the step fails.
fn plant_step<M, T, const N: usize, const K: usize>(
    model: &M,
    u: &M::Input,
    (t, q, v): (T, &SVector<T, N>, &SVector<T, N>),
    plant: StepParams<T>,
) -> Option<(State<T, N>, StepReport<T, K>)>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    let mut state = State::new(t, *q, *v);
    let report = MoreauJean::new(plant)
        .ok()?
        .step(model, &mut state, u)
        .ok()?;
    Some((state, report))
}

/// A plant's error `(Δq, Δv)`, or `None` where it is not finite.
fn finite<T: RealField + Copy, const N: usize>(
    error: (SVector<T, N>, SVector<T, N>),
) -> Option<(SVector<T, N>, SVector<T, N>)> {
    (error.0.iter().chain(error.1.iter()).all(|x| x.is_finite())).then_some(error)
}

/// The free motion from `(q, v)` at `t` over `r` (back in time where `r`
/// is negative), to second order: the exact impact's state flown to a
/// plant step's end, or the motion before an impact taken back to the
/// step's start.
fn flown<M, T, const N: usize, const K: usize>(
    model: &M,
    u: &M::Input,
    (t, q, v): (T, &SVector<T, N>, &SVector<T, N>),
    r: T,
) -> Option<(SVector<T, N>, SVector<T, N>)>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    let (mass, forces) = model.dynamics(t, q, v, u);
    let accel = -factor_mass(&mass).ok()?.solve(&forces);
    let half: T = nalgebra::convert(0.5);
    Some((q + v * r + accel * (half * r * r), v + accel * r))
}

/// The plant's error at an impact whose instant `t` falls `phase` after
/// the start of the plant's step that sees it (module `grid`): the
/// pre-impact motion at `(q, v⁻)` taken back by `phase` (to second
/// order), one step of the plant from there, against the exact impact at
/// `t` flown to the step's end. `None` where the step fails, does not
/// give the guard an impulse, or gives a non-finite state.
fn plant_window_error<M, T, const N: usize, const K: usize>(
    model: &M,
    u: &M::Input,
    (t, phase, q, v_minus, v_plus): (T, T, &SVector<T, N>, &SVector<T, N>, &SVector<T, N>),
    plant: StepParams<T>,
    guard: usize,
) -> Option<(SVector<T, N>, SVector<T, N>)>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    let (q_start, v_start) = flown(model, u, (t, q, v_minus), -phase)?;
    let (state, report) = plant_step(model, u, (t - phase, &q_start, &v_start), plant)?;
    if !report.impacting().contains(guard) {
        return None;
    }
    let (q_exact, v_exact) = flown(model, u, (t, q, v_plus), plant.tau - phase)?;
    finite((state.q - q_exact, state.v - v_exact))
}

/// The plant's own error at an impact: one step of the plant `plant`
/// ([`MoreauJean`] with these settings) from the impact's instant `t`,
/// where the gap closes at the step's start (the mean over a phase spread
/// uniformly over the step, to first order), against the exact impact
/// there followed by the free flight over the step (second order in
/// `τ_p`). `None` where the step fails or gives a non-finite state.
fn plant_step_error<M, T, const N: usize, const K: usize>(
    model: &M,
    u: &M::Input,
    (t, q, v_minus, v_plus): (T, &SVector<T, N>, &SVector<T, N>, &SVector<T, N>),
    plant: StepParams<T>,
) -> Option<(SVector<T, N>, SVector<T, N>)>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    let (state, _) = plant_step(model, u, (t, q, v_minus), plant)?;
    let (q_exact, v_exact) = flown(model, u, (t, q, v_plus), plant.tau)?;
    finite((state.q - q_exact, state.v - v_exact))
}
