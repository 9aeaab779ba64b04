//! The full-order observer (36).

use nalgebra::{RealField, SMatrix, SVector};

use crate::lcp::Lcp;
use crate::linalg::{Ldlt, SymmetricEigen};
use crate::model::Model;

use super::interval::{Cache, Interval, Memory, saturate, saturate_for, write_back};
use super::reduced_order::{restart_velocity, section_vii_impact};
use super::{
    Discretization, Estimate, Observer, ObserverError, ObserverParams, Outliers, Plan, Restart,
    UpdateReport, check_start,
};
use crate::validate::{self, factor_mass, finite_model};

/// The gains `Λ` and `L_ρ1` of the full-order observer (36), both
/// symmetric positive definite (`L_d = l_d I + Λ` and `L_ρ2 = l_d Λ` follow
/// from them and `l_d`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FullOrderGains<T: RealField + Copy, const N: usize> {
    /// `Λ`: the position error decays like `e^{−Λ t}` once the velocity
    /// error has.
    pub lambda: SMatrix<T, N, N>,
    /// `L_ρ1`: the stiffness that couples the position error into the
    /// velocity estimate (the `q̃ᵀ L_ρ1 q̃` of the Lyapunov function).
    pub l_rho1: SMatrix<T, N, N>,
}

impl<T: RealField + Copy, const N: usize> FullOrderGains<T, N> {
    /// `Λ = λ I`, `L_ρ1 = ρ I`.
    #[must_use]
    pub fn scalar(lambda: T, l_rho1: T) -> Self {
        Self {
            lambda: SMatrix::identity() * lambda,
            l_rho1: SMatrix::identity() * l_rho1,
        }
    }

    /// Checks that both are symmetric (to `1e3 ε` of their norm) and
    /// positive definite.
    fn check(&self) -> Result<(), ObserverError<T>> {
        for (name, m) in [("lambda", &self.lambda), ("l_rho1", &self.l_rho1)] {
            let bad = |value| super::invalid(name, value);
            let asymmetry = (m - m.transpose()).amax();
            let tolerance = T::default_epsilon() * nalgebra::convert(1e3) * m.amax();
            if !asymmetry.is_finite() || asymmetry > tolerance {
                return Err(bad(asymmetry));
            }
            let eigen = SymmetricEigen::new(m).ok_or_else(|| bad(m.amax()))?;
            if eigen.min() <= T::zero() {
                return Err(bad(eigen.min()));
            }
        }
        Ok(())
    }
}

/// The full-order observer (36): `q̂ = z₁`, `v̂ = z₂ + l_d q̃` with
/// `q̃ = q − q̂`, and
///
/// $$\dot z_1 = z_2 + L_d\,\tilde q,\qquad M(q)\,dz_2 + \bar F(t, q, \hat v)\,dt - (L_{\rho 1} + M(q) L_{\rho 2})\,\tilde q\,dt \in -N_{V(q)}(\hat v_e),$$
///
/// `L_d = l_d I + Λ`, `L_ρ2 = l_d Λ`. In the estimate's coordinates,
/// `q̂' = v̂ + Λ q̃` and `M dv̂ = −F̄ dt + L_ρ1 q̃ dt + l_d M ṽ dt − η̂`, so
/// the error obeys `q̃' = ṽ − Λ q̃`,
/// `M dṽ = −(F − F̄) dt − L_ρ1 q̃ dt − l_d M ṽ dt − (η − η̂)` (derivation in
/// the module docs of `runtime/src/observer/mod.rs`).
///
/// The state is `(t_k, q_k, q̂_k, v̂_k)`, fixed-size, on the stack.
///
/// ```
/// use moreau_runtime::{FullOrder, FullOrderGains, Model, ModelInfo, Observer, ObserverParams};
/// use nalgebra::{Matrix1, SVector, Vector1};
/// # struct Ball;
/// # impl Model<1, 1> for Ball {
/// #     type Scalar = f64;
/// #     type Input = SVector<f64, 0>;
/// #     const INFO: ModelInfo<1, 1> = ModelInfo {
/// #         name: "Ball", coordinates: ["y"], velocities: ["vy"], constraints: ["floor"],
/// #         parameters: &[], inputs: &[], source: "", op_count: 0,
/// #     };
/// #     fn mass(&self, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
/// #     fn coriolis(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
/// #     fn gravity(&self, _: &Vector1<f64>) -> Vector1<f64> { Vector1::new(9.81) }
/// #     fn forces(&self, _: f64, q: &Vector1<f64>, _: &Vector1<f64>, _: &SVector<f64, 0>) -> Vector1<f64> {
/// #         self.gravity(q)
/// #     }
/// #     fn gaps(&self, q: &Vector1<f64>) -> Vector1<f64> { *q }
/// #     fn gap_jacobian(&self, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
/// #     fn restitution(&self) -> Vector1<f64> { Vector1::new(0.5) }
/// #     fn parameter(&self, _: usize) -> Option<f64> { None }
/// #     fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> { None }
/// # }
/// // the ball of the `ReducedOrder` example, position estimate 10 cm off
/// let y = |t: f64| 2.0 - 0.5 * 9.81 * t * t;
/// let params = ObserverParams::new(10.0, 20.0);
/// let gains = FullOrderGains::scalar(5.0, 25.0);
/// let mut observer = FullOrder::<f64, 1, 1>::new(params, gains, 0.0, Vector1::new(2.0), Vector1::new(1.0))?
///     .with_position_estimate(Vector1::new(2.1))?;
/// for k in 1..=500 {
///     let t = k as f64 * 1e-3;
///     observer.update(&Ball, t, &Vector1::new(y(t)), &SVector::zeros())?;
/// }
/// let estimate = observer.estimate();
/// assert!((estimate.v[0] + 9.81 * 0.5).abs() < 0.05);
/// assert!((estimate.q[0] - y(0.5)).abs() < 0.01);
/// # Ok::<(), moreau_runtime::ObserverError<f64>>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct FullOrder<T: RealField + Copy, const N: usize, const K: usize> {
    params: ObserverParams<T>,
    gains: FullOrderGains<T, N>,
    restitution: Option<SVector<T, K>>,
    lcp: Lcp<T>,
    t: T,
    q: SVector<T, N>,
    q_hat: SVector<T, N>,
    v: SVector<T, N>,
    report: UpdateReport<T, N, K>,
    /// The outliers refused since the last accepted measurement.
    outliers: Outliers<T, N>,
    /// Memos of the injection gain and of a constant `M`'s factor.
    cache: Cache<T, N>,
    /// Memo of the error flow of the last `(τ, M⁻¹ L_ρ1)`.
    flow: FlowMemo<T, N>,
}

/// The error flow [`error_flow`] of the last `(τ, M⁻¹ L_ρ1)` for a model
/// whose `M` is constant (`Λ` and `l_d` are fixed per observer): a pure
/// memo, so a hit returns the bits a recomputation would.
#[derive(Clone, Copy, Debug)]
struct FlowMemo<T: RealField + Copy, const N: usize> {
    last: Option<Flow<T, N>>,
}

/// One memoized error flow: its key `(τ, M⁻¹ L_ρ1)` and its value.
type Flow<T, const N: usize> = (T, SMatrix<T, N, N>, ErrorFlow<T, N>);

/// `exp(τA)` of the error system in `N × N` blocks.
type ErrorFlow<T, const N: usize> = [[SMatrix<T, N, N>; 2]; 2];

impl<T: RealField + Copy, const N: usize> FlowMemo<T, N> {
    const EMPTY: Self = Self { last: None };

    /// `error_flow(τ, Λ, l_d, M⁻¹ L_ρ1)`, recomputed only for a new key.
    fn get(
        &mut self,
        tau: T,
        chol: &Ldlt<T, N>,
        gains: &FullOrderGains<T, N>,
        l_d: T,
    ) -> ErrorFlow<T, N> {
        let stiffness = chol.solve(&gains.l_rho1);
        if let Some((key_tau, key, flow)) = self.last
            && key_tau == tau
            && key == stiffness
        {
            return flow;
        }
        let flow = error_flow(tau, &gains.lambda, l_d, &stiffness);
        self.last = Some((tau, stiffness, flow));
        flow
    }
}

impl<T: RealField + Copy, const N: usize, const K: usize> FullOrder<T, N, K> {
    /// An observer with these settings and gains, started at time `t0` from
    /// the first measurement `q0` (also the position estimate, unless
    /// [`with_position_estimate`](Self::with_position_estimate) says
    /// otherwise) and the initial velocity estimate `v0`.
    ///
    /// # Errors
    ///
    /// [`DataError::InvalidParams`](crate::DataError::InvalidParams) for a setting out of its range or a
    /// gain matrix that is not symmetric positive definite (`"lambda"`,
    /// `"l_rho1"`, with the offending eigenvalue),
    /// [`DataError::NonFinite`](crate::DataError::NonFinite) or
    /// [`ObserverError::InvalidTime`] for non-finite initial data.
    pub fn new(
        params: ObserverParams<T>,
        gains: FullOrderGains<T, N>,
        t0: T,
        q0: SVector<T, N>,
        v0: SVector<T, N>,
    ) -> Result<Self, ObserverError<T>> {
        params.check()?;
        gains.check()?;
        check_start(t0, &q0, &v0)?;
        Ok(Self {
            params,
            gains,
            restitution: None,
            lcp: Lcp::default(),
            t: t0,
            q: q0,
            q_hat: q0,
            v: v0,
            report: UpdateReport::new(t0, T::zero()),
            outliers: Outliers::NONE,
            cache: Cache::default(),
            flow: FlowMemo::EMPTY,
        })
    }

    /// The same observer started from the position estimate `q̂(0)`.
    ///
    /// # Errors
    ///
    /// [`DataError::NonFinite`](crate::DataError::NonFinite) (`"q_hat0"`).
    pub fn with_position_estimate(self, q_hat: SVector<T, N>) -> Result<Self, ObserverError<T>> {
        validate::finite_vector(&q_hat, "q_hat0")?;
        Ok(Self { q_hat, ..self })
    }

    /// The same observer with its own restitution coefficients `ê`
    /// (Section VI-D) instead of the model's.
    ///
    /// # Errors
    ///
    /// [`DataError::InvalidRestitution`](crate::DataError::InvalidRestitution) for a coefficient outside
    /// `[0, 1]`.
    pub fn with_restitution(self, restitution: SVector<T, K>) -> Result<Self, ObserverError<T>> {
        validate::restitution(&restitution)?;
        Ok(Self {
            restitution: Some(restitution),
            ..self
        })
    }

    /// The gains `Λ`, `L_ρ1`.
    pub fn gains(&self) -> &FullOrderGains<T, N> {
        &self.gains
    }

    /// The observer's restitution `ê`: its own, or `None` for the model's.
    pub fn restitution(&self) -> Option<SVector<T, K>> {
        self.restitution
    }

    /// The last measurement `q_k`.
    pub fn measurement(&self) -> SVector<T, N> {
        self.q
    }

    /// The observer state `(z₁, z₂) = (q̂, v̂ − l_d q̃)` of (36).
    pub fn z(&self) -> (SVector<T, N>, SVector<T, N>) {
        (self.q_hat, self.v - (self.q - self.q_hat) * self.params.l_d)
    }

    /// The impact-aware update: the prediction of the reduced-order
    /// observer, then the error flow of (36) over `τ` applied to the
    /// measurable errors `q̃_k` and `ṽ_k = d/τ` (see the
    /// module docs, "Discretization").
    fn impact_aware<M>(
        &self,
        interval: &Interval<'_, M, T, N, K>,
        memo: Option<ErrorFlow<T, N>>,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<(SVector<T, N>, SVector<T, N>), ObserverError<T>>
    where
        M: Model<N, K, Scalar = T>,
    {
        let tau = interval.tau;
        let v0 = saturate(&self.v, self.params.velocity_bound);
        let (p_end, w_end) = interval.predict(&v0, report)?;
        let innovation = interval.q1 - p_end;
        report.innovation = innovation;
        // the errors the samples reveal: q̃_k, and ṽ_k = ∫ṽ/τ = d/τ
        let q_tilde = self.q - self.q_hat;
        let v_tilde = innovation / tau;
        // their flow under q̃' = ṽ − Λq̃, ṽ' = −M⁻¹L_ρ1 q̃ − l_d ṽ, with M at
        // q_{k+1}
        let flow = match memo {
            Some(flow) => flow,
            None => {
                let mass = interval.model.mass(&interval.q1);
                let chol = factor_mass(&mass)?;
                let stiffness = chol.solve(&self.gains.l_rho1);
                error_flow(tau, &self.gains.lambda, self.params.l_d, &stiffness)
            }
        };
        let q_tilde_next = flow[0][0] * q_tilde + flow[0][1] * v_tilde;
        let v_tilde_next = flow[1][0] * q_tilde + flow[1][1] * v_tilde;
        // the prediction carried ṽ_k unchanged: v_{k+1} = w(τ) + ṽ_k
        let v = w_end + v_tilde - v_tilde_next;
        let v = interval.close_at_end(&v, report)?;
        Ok((interval.q1 - q_tilde_next, v))
    }

    /// The plain Section VII step of (36): `z₁ += τ (z₂ + L_d q̃')`,
    /// `z₂ −= τ M⁻¹ (F̄ − (L_ρ1 + M L_ρ2) q̃')` with everything at
    /// `q_{k+1}` and `q̃' = q_{k+1} − z₁`, then the LCP (41).
    fn section_vii<M>(
        &self,
        interval: &Interval<'_, M, T, N, K>,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<(SVector<T, N>, SVector<T, N>), ObserverError<T>>
    where
        M: Model<N, K, Scalar = T>,
    {
        let (l_d, tau) = (self.params.l_d, interval.tau);
        let q1 = &interval.q1;
        let (z1, z2) = self.z();
        let q_tilde = q1 - z1;
        let v_pre = z2 + q_tilde * l_d;
        let lambda = &self.gains.lambda;
        let z1_next = z1 + (z2 + q_tilde * l_d + lambda * q_tilde) * tau;
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
        let f2 = forces - (self.gains.l_rho1 + mass * lambda * l_d) * q_tilde;
        let z2_free = z2 - chol.solve(&f2) * tau;
        let v_free = z2_free + (q1 - z1_next) * l_d;
        report.innovation = q1 - self.q - self.v * tau;
        let v = section_vii_impact(interval, &chol, &self.v, &v_free, report)?;
        Ok((z1_next, v))
    }
}

impl<T: RealField + Copy, const N: usize, const K: usize> FullOrder<T, N, K> {
    /// The interval integrated by the chosen discretization, from `v̂_k`
    /// held to `C_v`; `Err` names a restart when that failed from the
    /// observer's own state.
    fn integrate<M>(
        &self,
        interval: &Interval<'_, M, T, N, K>,
        memo: Option<ErrorFlow<T, N>>,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<(SVector<T, N>, SVector<T, N>), Restart>
    where
        M: Model<N, K, Scalar = T>,
    {
        let result = match self.params.scheme {
            Discretization::ImpactAware => self.impact_aware(interval, memo, report),
            Discretization::SectionVii => self.section_vii(interval, report),
        };
        match result {
            Ok((q_hat, v)) if q_hat.iter().chain(v.iter()).all(|x| x.is_finite()) => Ok((q_hat, v)),
            // a failure from the observer's own state, or (no other error
            // arises past the checks of `begin`) anything else
            Ok(_) | Err(_) => Err(Restart::Infeasible),
        }
    }
}

/// `exp(τA)` in `N × N` blocks, for the error system of (36),
///
/// $$A = \begin{bmatrix} -\Lambda & I \\ -S & -l_d I \end{bmatrix},\qquad S = M^{-1} L_{\rho 1},$$
///
/// by scaling and squaring: the Taylor series to order 12 of
/// `exp(τA/2^s)`, `s` the least with `‖τA‖_∞ / 2^s ≤ 1/2` (truncation below
/// `2^{-13}/13! ≈ 2e-14` relative), then `s` squarings. Blocks, because
/// `2N` is not a type-level constant.
fn error_flow<T: RealField + Copy, const N: usize>(
    tau: T,
    lambda: &SMatrix<T, N, N>,
    l_d: T,
    stiffness: &SMatrix<T, N, N>,
) -> [[SMatrix<T, N, N>; 2]; 2] {
    let row_norm = |m: &SMatrix<T, N, N>| {
        (0..N).fold(T::zero(), |acc, i| {
            acc.max(m.row(i).iter().fold(T::zero(), |s, x| s + x.abs()))
        })
    };
    let norm = tau * (row_norm(lambda) + T::one()).max(row_norm(stiffness) + l_d);
    let half: T = nalgebra::convert(0.5);
    let mut squarings = 0u32;
    let mut scaled = norm;
    while scaled > half && squarings < 64 {
        scaled *= half;
        squarings += 1;
    }
    let mut h = tau;
    for _ in 0..squarings {
        h *= half;
    }
    // B = hA, in blocks; X·B computed block-wise
    let b11 = -lambda * h;
    let b21 = -stiffness * h;
    let (b12, b22) = (h, -l_d * h);
    let times_b = |x: &[[SMatrix<T, N, N>; 2]; 2]| {
        [
            [x[0][0] * b11 + x[0][1] * b21, x[0][0] * b12 + x[0][1] * b22],
            [x[1][0] * b11 + x[1][1] * b21, x[1][0] * b12 + x[1][1] * b22],
        ]
    };
    let identity = SMatrix::<T, N, N>::identity();
    let zero = SMatrix::<T, N, N>::zeros();
    let mut term = [[identity, zero], [zero, identity]];
    let mut sum = term;
    for j in 1..=12u32 {
        let next = times_b(&term);
        let inv_j = T::one() / nalgebra::convert::<f64, T>(f64::from(j));
        term = [
            [next[0][0] * inv_j, next[0][1] * inv_j],
            [next[1][0] * inv_j, next[1][1] * inv_j],
        ];
        for r in 0..2 {
            for c in 0..2 {
                sum[r][c] += term[r][c];
            }
        }
    }
    for _ in 0..squarings {
        let x = sum;
        sum = [
            [
                x[0][0] * x[0][0] + x[0][1] * x[1][0],
                x[0][0] * x[0][1] + x[0][1] * x[1][1],
            ],
            [
                x[1][0] * x[0][0] + x[1][1] * x[1][0],
                x[1][0] * x[0][1] + x[1][1] * x[1][1],
            ],
        ];
    }
    sum
}

impl<M, T, const N: usize, const K: usize> Observer<M, N, K> for FullOrder<T, N, K>
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
        let memory = Memory {
            params: &self.params,
            lcp: &self.lcp,
            t: self.t,
            q: self.q,
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
            Plan::Integrate => {
                // a constant M: its error flow depends on τ alone
                let memo = match (self.params.scheme, interval.mass) {
                    (Discretization::ImpactAware, Some(chol)) => {
                        Some(
                            self.flow
                                .get(interval.tau, &chol, &self.gains, self.params.l_d),
                        )
                    }
                    _ => None,
                };
                self.integrate(&interval, memo, &mut report)
            }
            Plan::Restart(why) => Err(why),
        };
        let (q_hat, v) = match integrated {
            Ok(estimate) => estimate,
            Err(why) => {
                report = fresh;
                let v = restart_velocity(&interval, &self.v, why, &mut report)?;
                (*q, v)
            }
        };
        // WRITEBACK: the velocity estimate held to C_v, as in ReducedOrder
        let v = write_back(&v, &self.params, (&self.q, q, t - self.t), &mut report);
        report.outliers = self.outliers.accept();
        (self.t, self.q, self.q_hat, self.v, self.report) = (t, *q, q_hat, v, report);
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

impl<T: RealField + Copy, const N: usize, const K: usize> FullOrder<T, N, K> {
    /// The current estimate `(q̂, v̂)` (also [`Observer::estimate`]).
    #[must_use]
    pub fn estimate(&self) -> Estimate<T, N> {
        Estimate {
            t: self.t,
            q: self.q_hat,
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
    use nalgebra::{Matrix1, Matrix2};

    /// In one dimension `A = [[−λ, 1], [−s, −l]]`; its exponential from the
    /// eigenvalues `μ± = (−(λ + l) ± √((λ − l)² − 4s))/2`:
    /// `exp(τA) = (e^{μ+τ}(A − μ−) − e^{μ−τ}(A − μ+))/(μ+ − μ−)`.
    #[test]
    fn error_flow_matches_the_closed_form() {
        for (lambda, s, l, tau) in [
            (5.0, 2.0, 10.0, 1e-3),
            (5.0, 2.0, 10.0, 0.3),
            (1.0, 0.1, 40.0, 2.0),
        ] {
            let flow = error_flow(tau, &Matrix1::new(lambda), l, &Matrix1::new(s));
            let disc: f64 = (lambda - l) * (lambda - l) - 4.0 * s;
            let (mp, mm) = (
                (-(lambda + l) + disc.sqrt()) / 2.0,
                (-(lambda + l) - disc.sqrt()) / 2.0,
            );
            let a = Matrix2::new(-lambda, 1.0, -s, -l);
            let id = Matrix2::identity();
            let exact =
                ((a - id * mm) * (mp * tau).exp() - (a - id * mp) * (mm * tau).exp()) / (mp - mm);
            let ours = Matrix2::new(flow[0][0][0], flow[0][1][0], flow[1][0][0], flow[1][1][0]);
            assert!(
                (ours - exact).amax() < 1e-13 * exact.amax().max(1.0),
                "{ours} vs {exact}"
            );
        }
    }
}
