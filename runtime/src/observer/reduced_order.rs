//! The reduced-order observer (38), in the convergent form its Corollary 3
//! needs.

use nalgebra::{RealField, SMatrix, SVector};

use crate::lcp::{IndexSet, Lcp};
use crate::model::Model;

use super::interval::{
    Cache, Events, Interval, Memory, hold_to_bound, saturate, saturate_for, write_back,
};
use super::{
    Discretization, Estimate, Observer, ObserverError, ObserverParams, Outliers, Plan, Restart,
    UpdateReport, check_start,
};
use crate::error::DataError;
use crate::validate::{self, factor_mass, finite_model};

/// The reduced-order velocity observer (38): `q̂ = q`, and
///
/// $$\hat v = z + l_d q,\qquad M(q)\,dz + \bar F(t, q, \hat v)\,dt + l_d M(q)\,\hat v\,dt \in -N_{V(q)}(\hat v_e),$$
///
/// so that `M dv̂ = −F̄ dt + l_d M (v − v̂) dt − η̂` and the error obeys
/// `M dṽ = −(F − F̄) dt − l_d M ṽ dt − (η − η̂)` (the printed signs of (38)
/// give `+ l_d M ṽ dt`: see the module docs of
/// `runtime/src/observer/mod.rs`).
///
/// The state is `(t_k, q_k, v̂_k)` (and `q̄_k` under noise, below),
/// fixed-size, on the stack; an update allocates nothing.
///
/// # Under measurement noise
///
/// Told `σ > 0` ([`ObserverParams::with_noise`]), the observer locates
/// impacts from a smoothed position instead of the raw sample: the
/// predicted motion of each interval starts at `q̄_k`, the predicted end
/// `p` of the last interval blended with the measurement, `q̄_{k+1} = p +
/// β (q_{k+1} − p)`, `β = min(1, (4 l_d τ)^{2/3})`, held within four
/// deviations of `q̄_{k+1} − q_{k+1}` of the sample in each coordinate
/// (about `3.6 σ`; the docs of `smoothed` say why). Its noise is `σ √(β/(2 −
/// β))` (a third of `σ` at `l_d τ = 0.01`), and the contact rule (band,
/// resting speed) of the interval uses that noise instead of `σ`. What is
/// decided from `q̄`: where each gap closes inside the interval (a noisy
/// start moves the located impact by `δh / v_n`, and the jump then by
/// `(1 + e) A δh / v_n` with `A` the normal acceleration), whether a closed
/// constraint is approached fast enough to bounce or is closed plastically,
/// and the set `V(q̄_{k+1})` the estimate ends in.
///
/// An impact located from `q̄_k` is then confirmed by the sample after
/// it: the measured minus the predicted displacement says how far off the
/// start was along the normal, weighed against the noise of `q̄_k` and of
/// two samples, and the impact is timed again within the interval, its
/// rebound changed as Newton's law changes it (see
/// `runtime/src/observer/interval/retime.rs`; only an interval with one
/// restituted impact, on one constraint, at the cost of one more `J̇ w`
/// there; `M`, `F` and `J` come from the prediction). And a closed constraint
/// separating slower than its resting speed but faster than the
/// estimate's noise is departing, not held (see the contact rule in
/// `runtime/src/observer/mod.rs`).
///
/// A sample deeper inside a contact that the prediction holds at its end
/// than four deviations of the noise along the normal (`h_i(q) < −4 σ
/// |J_i|`: a compliant contact under a steady force) is read on the
/// contact, as the filter reads it (`runtime/src/observer/interval/read.rs`):
/// unread, it pulled `q̄` inside the constraint every interval, and the
/// median error doubled on samples 10 σ inside a held rim (`tests/kalman.rs`,
/// `a_sample_inside_a_held_contact_is_read_on_it`). The sample as read is
/// the measurement of the update: its injection, `q̄`, and `q̂`.
///
/// The correction is unchanged: the injection is still the measured
/// displacement minus the predicted one, `(q_{k+1} − q_k) − (p − q̄_k)`,
/// times the gain of (38), so the error obeys the same `M dṽ = … − l_d M ṽ
/// dt − (η − η̂)` and the guarantee (and the cost: one prediction per
/// update) is kept; only where and when the impulse `η̂` acts moves (where
/// by at most the hold of `q̄`, about `3.6 σ`, when within the interval). Without noise `q̄ = q`, no
/// impact is timed again, and the update is the one above, bit for bit.
///
/// ```
/// use moreau_runtime::{Model, ModelInfo, Observer, ObserverParams, ReducedOrder};
/// use nalgebra::{Matrix1, SVector, Vector1};
///
/// /// A unit ball above the floor y = 0.
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
/// // the ball falls from y = 2 at rest; the observer starts believing it
/// // rises at 1 m/s and sees only the exact positions y(t) = 2 − g t²/2
/// let y = |t: f64| 2.0 - 0.5 * 9.81 * t * t;
/// let params = ObserverParams::new(10.0, 20.0);
/// let mut observer = ReducedOrder::<f64, 1, 1>::new(params, 0.0, Vector1::new(2.0), Vector1::new(1.0))?;
/// for k in 1..=300 {
///     let t = k as f64 * 1e-3;
///     observer.update(&Ball, t, &Vector1::new(y(t)), &SVector::zeros())?;
/// }
/// // the error decays like e^{-l_d t}: 1 m/s · e^{-3} = 0.05 m/s after 0.3 s
/// let error = observer.estimate().v[0] - (-9.81 * 0.3);
/// assert!((error - (-3.0_f64).exp()).abs() < 1e-9);
/// # Ok::<(), moreau_runtime::ObserverError<f64>>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReducedOrder<T: RealField + Copy, const N: usize, const K: usize> {
    params: ObserverParams<T>,
    restitution: Option<SVector<T, K>>,
    lcp: Lcp<T>,
    t: T,
    q: SVector<T, N>,
    v: SVector<T, N>,
    /// The smoothed position `q̄_k` the predicted motion starts from under
    /// noise (see [`smoothing`]); the measurement `q_k` itself when `σ = 0`.
    smooth: SVector<T, N>,
    report: UpdateReport<T, N, K>,
    /// The outliers refused since the last accepted measurement.
    outliers: Outliers<T, N>,
    /// Memos of the injection gain and of a constant `M`'s factor.
    cache: Cache<T, N>,
}

impl<T: RealField + Copy, const N: usize, const K: usize> ReducedOrder<T, N, K> {
    /// An observer with these settings, started at time `t0` from the first
    /// measurement `q0` and the initial velocity estimate `v0`.
    ///
    /// # Errors
    ///
    /// [`DataError::InvalidParams`] for a setting out of its range,
    /// [`DataError::NonFinite`] (`"q0"`, `"v0"`) or
    /// [`ObserverError::InvalidTime`] for non-finite initial data.
    pub fn new(
        params: ObserverParams<T>,
        t0: T,
        q0: SVector<T, N>,
        v0: SVector<T, N>,
    ) -> Result<Self, ObserverError<T>> {
        params.check()?;
        check_start(t0, &q0, &v0)?;
        Ok(Self {
            params,
            restitution: None,
            lcp: Lcp::default(),
            t: t0,
            q: q0,
            v: v0,
            smooth: q0,
            report: UpdateReport::new(t0, T::zero()),
            outliers: Outliers::NONE,
            cache: Cache::default(),
        })
    }

    /// The same observer with its own restitution coefficients `ê`
    /// (Section VI-D) instead of the model's.
    ///
    /// # Errors
    ///
    /// [`DataError::InvalidRestitution`] for a coefficient outside
    /// `[0, 1]`.
    pub fn with_restitution(self, restitution: SVector<T, K>) -> Result<Self, ObserverError<T>> {
        validate::restitution(&restitution)?;
        Ok(Self {
            restitution: Some(restitution),
            ..self
        })
    }

    /// The observer's restitution `ê`: its own, or `None` for the model's.
    pub fn restitution(&self) -> Option<SVector<T, K>> {
        self.restitution
    }

    /// The observer state `z = v̂ − l_d q` of (38).
    pub fn z(&self) -> SVector<T, N> {
        self.v - self.q * self.params.l_d
    }

    /// The plain Section VII step: `z_{k+1} = z_k − τ M(q_{k+1})⁻¹ (F̄ +
    /// l_d M v̂')` with `v̂' = z_k + l_d q_{k+1}`, then the LCP (41) at
    /// `q_{k+1}` on the constraints whose sampled gap is closed.
    fn section_vii<M>(
        &self,
        interval: &Interval<'_, M, T, N, K>,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<SVector<T, N>, ObserverError<T>>
    where
        M: Model<N, K, Scalar = T>,
    {
        let (l_d, tau) = (self.params.l_d, interval.tau);
        let q1 = &interval.q1;
        let v_pre = self.v + (q1 - self.q) * l_d;
        let (mass, forces) = interval.model.dynamics(
            interval.t0 + tau,
            q1,
            &saturate_for::<M, T, N, K>(&v_pre, self.params.velocity_bound),
            interval.u,
        );
        report.evaluations += 1;
        finite_model(&forces, "F")?;
        let chol = match interval.mass {
            Some(chol) => chol,
            None => factor_mass(&mass)?,
        };
        let v_free = v_pre - chol.solve(&forces) * tau - v_pre * (tau * l_d);
        report.innovation = q1 - self.q - self.v * tau;
        section_vii_impact(interval, &chol, &self.v, &v_free, report)
    }
}

impl<T: RealField + Copy, const N: usize, const K: usize> ReducedOrder<T, N, K> {
    /// The interval integrated by the chosen discretization, from `v̂_k`
    /// held to `C_v`; `Err` names a restart when that failed from the
    /// observer's own state.
    fn integrate<M>(
        &self,
        interval: &Interval<'_, M, T, N, K>,
        beta: T,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<Integrated<T, N>, Restart>
    where
        M: Model<N, K, Scalar = T>,
    {
        let v0 = saturate(&self.v, self.params.velocity_bound);
        let result = match self.params.scheme {
            Discretization::ImpactAware => (|| {
                // PREDICT from (q_k, v̂_k) (from q̄_k under noise), impacts
                // inside the interval; under noise its events are recorded:
                // the impacts, to be confirmed below, and the contacts held
                // at its end (the exact-sample update keeps the plain
                // prediction, and its cost)
                let mut events = Events::new();
                let (p_end, w_end) = if self.params.noise > T::zero() {
                    interval.predict_traced(&v0, report, &mut events)?
                } else {
                    interval.predict(&v0, report)?
                };
                // READ under noise a sample deeper inside a contact held
                // at the predicted end than the noise explains on the
                // contact (`Interval::read_on_contacts`; four deviations,
                // the smoothing's hold)
                let q1 = if self.params.noise > T::zero() && !events.held.is_empty() {
                    let variance = self.params.noise * self.params.noise;
                    let measurement = SMatrix::<T, N, N>::identity() * variance;
                    let deviations = nalgebra::convert(SMOOTHING_GATE);
                    interval.read_on_contacts(
                        &interval.q1,
                        None,
                        (events.held, &SVector::zeros()),
                        (&measurement, deviations),
                    )?
                } else {
                    interval.q1
                };
                // INJECT l_d ∫(v − v̂) = the measured minus the predicted
                // displacement, integrated exactly over τ
                // (under noise the prediction starts from q̄_k, and the
                // displacement it explains is `p(τ) − q̄_k`)
                let innovation = if interval.q0 == self.q {
                    q1 - p_end
                } else {
                    (q1 - self.q) - (p_end - interval.q0)
                };
                report.innovation = innovation;
                let v = w_end + innovation * interval.gain;
                // CONFIRM: an impact timed from the noisy start, timed
                // again with the sample after it
                let noise = (self.params.noise, interval.params.noise);
                let v = if self.params.noise > T::zero() {
                    match interval.retime(&events, &innovation, noise)? {
                        Some(dv) => v + dv,
                        None => v,
                    }
                } else {
                    v
                };
                // CLOSE: v̂_e ∈ V(q̄_{k+1}) (V(q_{k+1}) without noise)
                let end = smoothed(&self.params, beta, &q1, &p_end);
                let v = if end == interval.q1 {
                    interval.close_at_end(&v, report)?
                } else {
                    Interval {
                        q1: end,
                        ..*interval
                    }
                    .close_at_end(&v, report)?
                };
                Ok(Integrated {
                    v,
                    smooth: end,
                    q: q1,
                })
            })(),
            Discretization::SectionVii => self.section_vii(interval, report).map(|v| Integrated {
                v,
                smooth: interval.q1,
                q: interval.q1,
            }),
        };
        match result {
            Ok(done) if done.v.iter().all(|x| x.is_finite()) => Ok(done),
            // a failure from the observer's own state, or (no other error
            // arises past the checks of `begin`) anything else
            Ok(_) | Err(_) => Err(Restart::Infeasible),
        }
    }

    /// The estimate restarted from the measurement `q_{k+1}`: `v̂_k` kept
    /// after outliers, else the mean velocity over the interval, held to
    /// `C_v`, then Newton's law at `q_{k+1}` for the closed constraints it
    /// approaches.
    fn restart<M>(
        &self,
        interval: &Interval<'_, M, T, N, K>,
        why: Restart,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<SVector<T, N>, ObserverError<T>>
    where
        M: Model<N, K, Scalar = T>,
    {
        restart_velocity(interval, &self.v, why, report)
    }
}

/// What one interval integrated gives the observer's next state.
struct Integrated<T: RealField + Copy, const N: usize> {
    /// `v̂_{k+1}`.
    v: SVector<T, N>,
    /// `q̄_{k+1}`, the smoothed position the next interval starts from.
    smooth: SVector<T, N>,
    /// `q_{k+1}`, the sample as read: on the contacts held at the
    /// predicted end, under noise (`Interval::read_on_contacts`).
    q: SVector<T, N>,
}

/// The weight `β` of the measurement in the smoothed position (see
/// [`smoothed`]): `1` without noise or for the Section VII scheme (which
/// steps from the sample), else `min(1, (4 l_d τ)^{2/3})`.
///
/// Where it comes from: `q̄_{k+1} = p + β (q_{k+1} − p)`, `p` the predicted
/// end of the interval, passes the measurement noise with the standard
/// deviation `σ √(β/(2 − β)) ≈ σ √(β/2)` and lags a velocity error `ṽ` by
/// `ṽ τ / β`; with `ṽ` at the noise floor of the estimate, `√2 l_d σ`, the
/// sum is smallest at `β^{3/2} = 4 l_d τ` (about `0.12` for `l_d τ = 0.01`,
/// a third of the noise), whatever `σ`.
pub(crate) fn smoothing<T: RealField + Copy>(params: &ObserverParams<T>, tau: T) -> T {
    if params.noise == T::zero() || params.scheme != Discretization::ImpactAware {
        return T::one();
    }
    let four: T = nalgebra::convert(4.0);
    let two_thirds: T = nalgebra::convert(2.0 / 3.0);
    (four * params.l_d * tau).powf(two_thirds).min(T::one())
}

/// How many deviations of `q̄_{k+1} − q_{k+1}` the smoothed position may
/// stray from the measurement before it is held back ([`smoothed`]): four,
/// as the filter's innovation gate (`KalmanParams::gate`, `z = 4`).
const SMOOTHING_GATE: f64 = 4.0;

/// The smoothed position `q̄_{k+1}` from the measured `q_{k+1}` and the
/// predicted end `p` of the interval: `p + β (q_{k+1} − p)` (`β` from
/// [`smoothing`]), the measurement itself when `β = 1` (`σ = 0`).
///
/// It is held within four deviations ([`SMOOTHING_GATE`]) of the
/// measurement in each coordinate, the deviation being that of
/// `q̄_{k+1} − q_{k+1} = (1 − β)(p − q_{k+1})` when the estimate is at its
/// noise floor: `(1 − β) σ √(2/(2 − β))` (`p` carries the noise of `q̄_k`,
/// `σ² β/(2 − β)`, the sample `σ²`), `0.91 σ` at `l_d τ = 0.01`. The hold
/// is for a prediction that noise cannot explain (a velocity estimate
/// still wrong after a restart or an impact): `q̄` then follows the
/// samples instead of lagging further. Noise alone reaches it once in
/// about 16 000 samples of a coordinate. The contact band's `n_σ σ` (3.3
/// of these deviations at `n_σ = 3`), used before, was reached once in
/// about 1 000, and each time set `q̄` `n_σ σ` from a sample that noise
/// had put far out. On one Example 1 run, three samples 2.4σ to 3.8σ low
/// held `q̄` 0.8σ, then 1.4σ under the plant; three samples on it was
/// still 1.7σ under, and a bounce was located 1.3 ms before the plant's,
/// 0.125 m/s off at that sample (with the four deviations, 2.6e-3 there,
/// and the bounce located 0.8 ms early, inside its bracketing samples).
pub(crate) fn smoothed<T: RealField + Copy, const N: usize>(
    params: &ObserverParams<T>,
    beta: T,
    q1: &SVector<T, N>,
    p: &SVector<T, N>,
) -> SVector<T, N> {
    if beta >= T::one() {
        return *q1;
    }
    let two: T = nalgebra::convert(2.0);
    let deviation = (T::one() - beta) * params.noise * (two / (two - beta)).sqrt();
    let band = deviation * nalgebra::convert(SMOOTHING_GATE);
    let mixed = p + (q1 - p) * beta;
    SVector::from_fn(|i, _| mixed[i].max(q1[i] - band).min(q1[i] + band))
}

/// The settings the interval sees under noise: `σ` replaced by the noise
/// of the smoothed position, `σ √(β/(2 − β))` (`β` from [`smoothing`]
/// for this `τ`); unchanged
/// without noise or for a `τ` that is not positive (refused later).
fn smoothed_noise<T: RealField + Copy>(
    params: &ObserverParams<T>,
    tau: T,
    beta: T,
) -> ObserverParams<T> {
    let positive = tau > T::zero();
    if params.noise == T::zero() || !positive || params.scheme != Discretization::ImpactAware {
        return *params;
    }
    let two: T = nalgebra::convert(2.0);
    params.with_noise(params.noise * (beta / (two - beta)).sqrt())
}

/// The velocity a restart starts from (see [`Restart`]), closed at the
/// measurement; the report records the restart and, as its innovation, the
/// displacement the old estimate did not explain (so the next update
/// treats the estimate as uncertain).
pub(crate) fn restart_velocity<M, T, const N: usize, const K: usize>(
    interval: &Interval<'_, M, T, N, K>,
    v_k: &SVector<T, N>,
    why: Restart,
    report: &mut UpdateReport<T, N, K>,
) -> Result<SVector<T, N>, ObserverError<T>>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    let bound = interval.params.velocity_bound;
    let displacement = interval.q1 - interval.q0;
    let v = match why {
        Restart::Outliers => *v_k,
        Restart::LongInterval | Restart::Infeasible => displacement / interval.tau,
    };
    let (v, held) = hold_to_bound(&v, bound);
    report.at_velocity_bound = held;
    report.restart = Some(why);
    report.innovation = displacement - saturate(v_k, bound) * interval.tau;
    let v = interval.close_at_end(&v, report)?;
    if v.iter().all(|x| x.is_finite()) {
        Ok(v)
    } else {
        Err(DataError::NonFiniteResult.into())
    }
}

/// The LCP (41) of the Section VII scheme at `q_{k+1}`: the constraints
/// whose gap is closed at `q_k` or at `q_{k+1}`, Newton's law
/// `0 ≤ λ ⊥ J(q_{k+1})(v̂_{k+1} + ê v̂_k) ≥ 0`, `v̂_{k+1} = v_free + M⁻¹Jᵀλ`.
pub(crate) fn section_vii_impact<M, T, const N: usize, const K: usize>(
    interval: &Interval<'_, M, T, N, K>,
    chol: &crate::linalg::Ldlt<T, N>,
    v_before: &SVector<T, N>,
    v_free: &SVector<T, N>,
    report: &mut UpdateReport<T, N, K>,
) -> Result<SVector<T, N>, ObserverError<T>>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    let (h0, jac0) = interval.contact(&interval.q0)?;
    let (h1, jac) = interval.contact(&interval.q1)?;
    let band = interval.params.contact_band();
    let mut set = IndexSet::new();
    for i in 0..K {
        let g = jac.row(i).norm() * band;
        if h0[i] <= g || h1[i] <= g {
            set.insert(i);
        }
    }
    // Newton's law measures the approach as the plant stepper's default
    // does: the slower of J(q_k) v̂_k and J(q_{k+1}) v̂_k (the latter alone
    // kicks an estimate sliding on a curved constraint off it, every step)
    let approach_velocity = (jac0 * v_before).sup(&(jac * v_before));
    let approach = interval.restitution.component_mul(&approach_velocity);
    let before = report.impulses;
    let dv = interval.impulse(&jac, chol, v_free, &approach, set, report)?;
    if report.impulses != before {
        report.impacts = 1;
        report.first_impact = Some(interval.t0 + interval.tau);
    }
    Ok(v_free + dv)
}

impl<M, T, const N: usize, const K: usize> Observer<M, N, K> for ReducedOrder<T, N, K>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    fn update(
        &mut self,
        model: &M,
        t: T,
        q: &SVector<T, N>,
        u: &M::Input,
    ) -> Result<Estimate<T, N>, ObserverError<T>> {
        // `β` once per update: the interval's noise and the smoothing of
        // its end share it
        let beta = smoothing(&self.params, t - self.t);
        let smoothed_params = smoothed_noise(&self.params, t - self.t, beta);
        let memory = Memory {
            params: &smoothed_params,
            lcp: &self.lcp,
            t: self.t,
            q: self.smooth,
            restitution: self.restitution.as_ref(),
            report: &self.report,
            release_departures: true,
        };
        let (interval, fresh) = Interval::begin(model, u, memory, &mut self.cache, t, q)?;
        // SCREEN: an outlier is refused here, the estimate untouched
        let plan = self
            .outliers
            .screen(&self.params, (t, interval.tau), &self.q, q)?;
        let mut report = fresh;
        let integrated = match plan {
            Plan::Integrate => self.integrate(&interval, beta, &mut report),
            Plan::Restart(why) => Err(why),
        };
        let Integrated { v, smooth, q } = match integrated {
            Ok(done) => done,
            Err(why) => {
                report = fresh;
                let v = self.restart(&interval, why, &mut report)?;
                Integrated {
                    v,
                    smooth: *q,
                    q: *q,
                }
            }
        };
        // WRITEBACK: the estimate held to C_v (a radial projection onto a
        // ball that holds the true velocity never moves it away from it)
        let v = write_back(&v, &self.params, (&self.q, &q, t - self.t), &mut report);
        report.outliers = self.outliers.accept();
        (self.t, self.q, self.v, self.report) = (t, q, v, report);
        self.smooth = smooth;
        Ok(Self::estimate(self))
    }

    fn estimate(&self) -> Estimate<T, N> {
        Self::estimate(self)
    }

    fn report(&self) -> &UpdateReport<T, N, K> {
        Self::report(self)
    }

    fn params(&self) -> &ObserverParams<T> {
        Self::params(self)
    }
}

impl<T: RealField + Copy, const N: usize, const K: usize> ReducedOrder<T, N, K> {
    /// The current estimate `(q̂, v̂)` (also [`Observer::estimate`]).
    #[must_use]
    pub fn estimate(&self) -> Estimate<T, N> {
        Estimate {
            t: self.t,
            q: self.q,
            v: self.v,
        }
    }

    /// What the last successful update did (also [`Observer::report`]).
    #[must_use]
    pub fn report(&self) -> &UpdateReport<T, N, K> {
        &self.report
    }

    /// The settings (also [`Observer::params`]).
    #[must_use]
    pub fn params(&self) -> &ObserverParams<T> {
        &self.params
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{Ball, Gauss, Puck, exact_ball};
    use nalgebra::{Vector1, Vector2};

    /// The hold of [`smoothed`] is four deviations of `q̄ − q` for an
    /// estimate at its noise floor. On a coordinate at rest, predicted
    /// exactly (`p = q̄_k`), with Gaussian samples of deviation `σ`: the
    /// deviation of `q̄ − q` over 400 000 samples is the analytic
    /// `(1 − β) σ √(2/(2 − β))` to 2 %, and the hold acts on about one
    /// sample in 16 000 (`P(|Z| > 4)`, 25 expected), where the contact
    /// band's `3σ` would act on one in 1 000 (about 390 here).
    #[test]
    fn the_hold_of_the_smoothed_position_is_four_of_its_deviations() {
        let mut gauss = Gauss::new(2024);
        let (sigma, tau): (f64, f64) = (1e-4, 1e-3);
        let params = ObserverParams::new(10.0, 20.0).with_noise(sigma);
        let beta = smoothing(&params, tau);
        let deviation = (1.0 - beta) * sigma * (2.0 / (2.0 - beta)).sqrt();
        let (mut q_bar, mut sum_sq, mut held) = (Vector1::zeros(), 0.0, 0);
        let (warm_up, count) = (1_000, 400_000);
        for k in 0..warm_up + count {
            let q = Vector1::new(sigma * gauss.normal());
            let next = smoothed(&params, beta, &q, &q_bar);
            let free = q_bar + (q - q_bar) * beta;
            if k >= warm_up {
                sum_sq += (next - q)[0].powi(2);
                held += usize::from(next != free);
            }
            q_bar = next;
        }
        let measured = (sum_sq / count as f64).sqrt();
        assert!(
            (measured / deviation - 1.0).abs() < 0.02,
            "{measured:e} against {deviation:e}"
        );
        eprintln!("q̄ − q: {measured:e} against {deviation:e}; held on {held} samples");
        assert!((5..=75).contains(&held), "held on {held} samples");
    }

    /// On exact samples of a bouncing ball (analytic, not made by any time
    /// stepper) with the exact initial velocity, the impact-aware observer
    /// locates each bounce inside its sampling interval and keeps the
    /// velocity exact to round-off; Section VII, whose sampled gaps are
    /// positive around each bounce, misses it by the whole jump.
    #[test]
    fn bounces_between_samples_are_located() {
        let ball = Ball { g: 9.81, e: 0.8 };
        let (y0, tau) = (1.0, 1e-3);
        let u = SVector::zeros();
        let params = ObserverParams::new(10.0, 20.0);
        let mut aware =
            ReducedOrder::<f64, 1, 1>::new(params, 0.0, Vector1::new(y0), Vector1::zeros())
                .unwrap();
        let plain_params = params.with_scheme(Discretization::SectionVii);
        let mut plain =
            ReducedOrder::<f64, 1, 1>::new(plain_params, 0.0, Vector1::new(y0), Vector1::zeros())
                .unwrap();
        let (mut worst, mut located, mut plain_worst) = (0.0_f64, Vec::new(), 0.0_f64);
        for k in 1..=2000 {
            let t = k as f64 * tau;
            let (y, v, _) = exact_ball(ball.g, ball.e, y0, t);
            let estimate = aware.update(&ball, t, &Vector1::new(y), &u).unwrap();
            worst = worst.max((estimate.v[0] - v).abs());
            if let Some(at) = aware.report().first_impact {
                located.push(at);
            }
            let estimate = plain.update(&ball, t, &Vector1::new(y), &u).unwrap();
            plain_worst = plain_worst.max((estimate.v[0] - v).abs());
        }
        let (_, _, impacts) = exact_ball(ball.g, ball.e, y0, 2.0);
        assert_eq!(located.len(), impacts.len());
        for (a, b) in located.iter().zip(&impacts) {
            assert!((a - b).abs() < 1e-12, "impact at {a}, exact {b}");
        }
        assert!(worst < 1e-10, "{worst}");
        // the first bounce (4.4 m/s) is missed: both gaps around it open
        assert!(plain_worst > 4.0, "{plain_worst}");
    }

    /// The ball dropped with `e = 0.5` comes to rest after an accumulation
    /// of bounces; the observer follows it (Newton's law for the resolved
    /// bounces, a plastic closure below the resting speed) and ends at
    /// rest in persistent contact, locating no impact there. What the
    /// merged bounces left (below the resting speed `ρ τ g ≈ 1e-3`) decays
    /// like `e^{−l_d t}`: below `1e-3 e^{−5} = 7e-6` half a second later.
    #[test]
    fn an_accumulation_ends_in_persistent_contact() {
        let ball = Ball { g: 9.81, e: 0.5 };
        let (y0, tau) = (0.5, 1e-3);
        let u = SVector::zeros();
        let params = ObserverParams::new(10.0, 20.0);
        let mut observer =
            ReducedOrder::<f64, 1, 1>::new(params, 0.0, Vector1::new(y0), Vector1::zeros())
                .unwrap();
        // accumulation at t = t1 (1 + 2e/(1 − e)) = 3 t1 for e = 1/2
        let t_rest = 3.0 * (2.0 * y0 / ball.g).sqrt();
        for k in 1..=1500 {
            let t = k as f64 * tau;
            let y = if t < t_rest {
                exact_ball(ball.g, ball.e, y0, t).0
            } else {
                0.0
            };
            observer.update(&ball, t, &Vector1::new(y), &u).unwrap();
            if t > t_rest + 0.05 {
                assert_eq!(observer.report().impacts, 0);
                assert!(observer.report().contacts.contains(0));
            }
            if t > t_rest + 0.5 {
                assert!(
                    observer.estimate().v[0].abs() < 7e-6,
                    "{}",
                    observer.estimate().v[0]
                );
            }
        }
    }

    /// Noisy samples of a ball at rest on the floor: the contact rule keeps
    /// the noise from opening the contact or triggering impacts, and the
    /// estimate's error settles near `l_d σ`.
    #[test]
    fn noise_does_not_trigger_impacts_at_rest() {
        let ball = Ball { g: 9.81, e: 0.9 };
        let sigma = 1e-3;
        let u = SVector::zeros();
        let params = ObserverParams::new(10.0, 20.0).with_noise(sigma);
        let mut observer =
            ReducedOrder::<f64, 1, 1>::new(params, 0.0, Vector1::zeros(), Vector1::zeros())
                .unwrap();
        // a deterministic ±σ√3 uniform sequence (standard deviation σ)
        let mut x = 0.3_f64;
        let mut sum_sq = 0.0;
        for k in 1..=4000 {
            x = (x * 9.73 + 0.31).fract();
            let y = sigma * 3f64.sqrt() * (2.0 * x - 1.0);
            let estimate = observer
                .update(&ball, k as f64 * 1e-3, &Vector1::new(y), &u)
                .unwrap();
            assert_eq!(observer.report().impacts, 0, "step {k}");
            sum_sq += estimate.v[0] * estimate.v[0];
        }
        let rms = (sum_sq / 4000.0).sqrt();
        // about l_d σ (measured 1.8 l_d σ: the estimate is kept in V(q), so
        // the approaching half of the noise is cut and the rest
        // accumulates); bounded by three times that
        assert!(rms < 3.0 * 10.0 * sigma, "{rms}");
    }

    /// Sliding: the contact force cancels the normal part of gravity, the
    /// estimate stays tangent, and the tangential error decays exactly like
    /// `e^{−l_d t}` (the contact does not disturb the injection).
    #[test]
    fn sliding_keeps_the_estimate_tangent() {
        let puck = Puck { f: 2.0 };
        let u = SVector::zeros();
        let params = ObserverParams::new(10.0, 20.0);
        let mut observer =
            ReducedOrder::<f64, 2, 1>::new(params, 0.0, Vector2::zeros(), Vector2::new(1.0, 0.0))
                .unwrap();
        for k in 1..=300 {
            let t = k as f64 * 1e-3;
            let q = Vector2::new(0.5 * puck.f * t * t, 0.0);
            let estimate = observer.update(&puck, t, &q, &u).unwrap();
            assert_eq!(estimate.v[1], 0.0);
            assert_eq!(observer.report().impacts, 0);
            assert!(observer.report().contacts.contains(0));
            let error = estimate.v[0] - puck.f * t;
            assert!((error - (-10.0 * t).exp()).abs() < 1e-12, "{error}");
        }
    }

    /// The observer is generic in the scalar: `f32` runs the same bounce.
    #[test]
    fn runs_in_f32() {
        let ball = Ball {
            g: 9.81_f32,
            e: 0.8,
        };
        let params = ObserverParams::new(10.0_f32, 20.0);
        let mut observer =
            ReducedOrder::<f32, 1, 1>::new(params, 0.0, Vector1::new(1.0), Vector1::zeros())
                .unwrap();
        let mut worst = 0.0_f32;
        for k in 1..=1000 {
            let t = k as f64 * 1e-3;
            let (y, v, _) = exact_ball(9.81, 0.8, 1.0, t);
            let estimate = observer
                .update(&ball, t as f32, &Vector1::new(y as f32), &SVector::zeros())
                .unwrap();
            worst = worst.max((estimate.v[0] - v as f32).abs());
        }
        // single precision: positions to 6e-8 m over τ = 1 ms are velocities
        // to ~1e-4 m/s, times the gain's filtering
        assert!(worst < 1e-2, "{worst}");
    }
}
