//! The derivatives of the hybrid flow that a covariance needs: the
//! Jacobian of the free dynamics, its transition over a piece of flight,
//! the saltation matrix of Newton's impact law, and the projection onto
//! the manifold of a persistent contact. All from the model's generated
//! derivatives ([`Model::linearization`](crate::Model::linearization), [`Sensitivities`]); nothing is
//! differentiated numerically.

use nalgebra::{RealField, SMatrix, SVector};

use crate::lcp::{IndexSet, OnSet};
use crate::linalg::Ldlt;
use crate::model::Sensitivities;

use super::super::ObserverError;
use super::Blocks;
use crate::error::DataError;
use crate::validate::{factor_mass, finite_model as finite};

type Result<X, T> = core::result::Result<X, ObserverError<T>>;

/// The Jacobian `A = ∂f/∂x` of the free dynamics `x' = f(x) = (v, a)`,
/// `a = −M(q)⁻¹ F(t, q, v, u)`, at one point, and `a` there:
///
/// $$A = \begin{pmatrix} 0 & I \\ -M^{-1}\big(\partial_q(M w)|_{w=a} + \partial_q F\big) & -M^{-1}\partial_v F \end{pmatrix}.$$
///
/// ```
/// use moreau_runtime::{flow_jacobian, Model, ModelInfo, Sensitivities};
/// use nalgebra::{Matrix1, SVector, Vector1};
///
/// /// A unit mass on a spring of stiffness 4: a = −4 y.
/// struct Spring;
/// impl Model<1, 0> for Spring {
///     type Scalar = f64;
///     type Input = SVector<f64, 0>;
///     const INFO: ModelInfo<1, 0> = ModelInfo {
///         name: "Spring", coordinates: ["y"], velocities: ["vy"], constraints: [],
///         parameters: &[], inputs: &[], source: "", op_count: 0,
///     };
///     fn mass(&self, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
///     fn coriolis(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
///     fn gravity(&self, q: &Vector1<f64>) -> Vector1<f64> { q * 4.0 }
///     fn forces(&self, _: f64, q: &Vector1<f64>, _: &Vector1<f64>, _: &SVector<f64, 0>) -> Vector1<f64> { q * 4.0 }
///     fn linearization(&self, t: f64, q: &Vector1<f64>, v: &Vector1<f64>, u: &SVector<f64, 0>)
///         -> moreau_runtime::Linearization<f64, 1> {
///         moreau_runtime::Linearization { mass: self.mass(q), forces: self.forces(t, q, v, u),
///             forces_dq: Matrix1::new(4.0), forces_dv: Matrix1::zeros() }
///     }
///     fn gaps(&self, _: &Vector1<f64>) -> SVector<f64, 0> { SVector::zeros() }
///     fn gap_jacobian(&self, _: &Vector1<f64>) -> nalgebra::SMatrix<f64, 0, 1> { nalgebra::SMatrix::zeros() }
///     fn restitution(&self) -> SVector<f64, 0> { SVector::zeros() }
///     fn parameter(&self, _: usize) -> Option<f64> { None }
///     fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> { None }
/// }
/// impl Sensitivities<1, 0> for Spring {
///     fn mass_dq(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
///     fn jacobian_dq(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> nalgebra::SMatrix<f64, 0, 1> {
///         nalgebra::SMatrix::zeros()
///     }
/// }
///
/// let (a, accel) = flow_jacobian(&Spring, 0.0, &Vector1::new(0.5), &Vector1::new(1.0), &SVector::zeros())?;
/// assert_eq!(a.entry(0, 1), 1.0);
/// assert_eq!(a.entry(1, 0), -4.0);
/// assert_eq!(accel[0], -2.0);
/// # Ok::<(), moreau_runtime::ObserverError<f64>>(())
/// ```
///
/// # Errors
///
/// [`DataError::NonFiniteModel`](crate::DataError::NonFiniteModel) or
/// [`DataError::MassNotPositiveDefinite`](crate::DataError::MassNotPositiveDefinite) where the model fails.
#[allow(clippy::type_complexity)]
pub fn flow_jacobian<M, T, const N: usize, const K: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    v: &SVector<T, N>,
    u: &M::Input,
) -> Result<(Blocks<T, N>, SVector<T, N>), T>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    let lin = model.linearization(t, q, v, u);
    finite(&lin.forces, "F")?;
    finite(&lin.forces_dq, "dF/dq")?;
    finite(&lin.forces_dv, "dF/dv")?;
    let chol = factor_mass(&lin.mass)?;
    let accel = -chol.solve(&lin.forces);
    let mass_dq = model.mass_dq(q, &accel);
    finite(&mass_dq, "d(Mw)/dq")?;
    let a = Blocks {
        qq: SMatrix::zeros(),
        qv: SMatrix::identity(),
        vq: -chol.solve(&(mass_dq + lin.forces_dq)),
        vv: -chol.solve(&lin.forces_dv),
    };
    Ok((a, accel))
}

/// The Jacobian of the constrained flow `x' = (v, a)` with the
/// constraints of `set` held at acceleration level,
/// `M a = −F + J_Sᵀ λ`, `J_S a + c = 0`, `c_i = vᵀ ∇²h_i v`
/// (persistent contact: sliding or resting). With `W = J_S M⁻¹ J_Sᵀ`:
///
/// - `∂a/∂q = M⁻¹ (B + J_Sᵀ λ_q)`, `B = −∂F/∂q − ∂(M w)/∂q|_{w=a} + Σ λ_i ∇²h_i`,
///   `λ_q = −W⁻¹ (∂(J_S w)/∂q|_{w=a} + J_S M⁻¹ B)`;
/// - `∂a/∂v = M⁻¹ (−∂F/∂v + J_Sᵀ λ_v)`,
///   `λ_v = −W⁻¹ (2 ∂(J_S v)/∂q − J_S M⁻¹ ∂F/∂v)`.
///
/// `∂c/∂q` needs third derivatives of `h` and is left out: exact for gaps
/// of degree two (Example 1's parabola, the balls' distances, the
/// billiard's walls), a Jacobian error of order `|v|² |∇³h|` otherwise
/// (measured on the plastic UR5 sliding its tool at up to 21 rad/s:
/// adding the term by central differences moved the filter's velocity
/// NEES medians by at most 0.07; `docs/estimation-under-noise.md`, "The
/// level's variance in `P`").
/// Constraints of `set` whose multiplier `λ_i` is not positive (the
/// motion leaves them) are dropped. Falls back to [`flow_jacobian`] when
/// none is left.
///
/// # Errors
///
/// As [`flow_jacobian`].
#[allow(clippy::type_complexity)]
pub fn constrained_flow_jacobian<M, T, const N: usize, const K: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    v: &SVector<T, N>,
    u: &M::Input,
    set: IndexSet<K>,
) -> Result<(Blocks<T, N>, SVector<T, N>), T>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    let lin = model.linearization(t, q, v, u);
    finite(&lin.forces, "F")?;
    finite(&lin.forces_dq, "dF/dq")?;
    finite(&lin.forces_dv, "dF/dv")?;
    let chol = factor_mass(&lin.mass)?;
    let free = -chol.solve(&lin.forces);
    let (_, jac) = model.contact(q);
    finite(&jac, "J")?;
    let rate_dq = model.jacobian_dq(q, v);
    finite(&rate_dq, "d(Jv)/dq")?;
    let c = rate_dq * v;
    let mut active = IndexSet::<K>::EMPTY;
    for i in set {
        active.insert(i);
    }
    // λ on the active rows; drop those that pull, once
    let mut solved = None;
    for _ in 0..2 {
        let OnSet {
            rows: jac_a,
            minv_jt,
            delassus,
        } = OnSet::new(&jac, &chol, active);
        let Some(w_chol) = delassus else {
            break;
        };
        let mut rhs = -(jac_a * free);
        for i in active {
            rhs[i] -= c[i];
        }
        let lambda = w_chol.solve(&rhs);
        let pulling = active.iter().filter(|&i| lambda[i] <= T::zero()).fold(
            IndexSet::EMPTY,
            |mut acc, i| {
                acc.insert(i);
                acc
            },
        );
        if pulling.is_empty() {
            solved = Some((jac_a, minv_jt, w_chol, lambda));
            break;
        }
        active = active.difference(pulling);
        if active.is_empty() {
            break;
        }
    }
    let Some((jac_a, minv_jt, w_chol, lambda)) = solved else {
        return flow_jacobian(model, t, q, v, u);
    };
    let accel = free + minv_jt * lambda;
    let mut h_lambda = SMatrix::<T, N, N>::zeros();
    for k in 0..N {
        let e_k = SVector::<T, N>::from_fn(|i, _| if i == k { T::one() } else { T::zero() });
        h_lambda.set_column(k, &(model.jacobian_dq(q, &e_k).transpose() * lambda));
    }
    finite(&h_lambda, "d(Jv)/dq")?;
    let mass_dq = model.mass_dq(q, &accel);
    finite(&mass_dq, "d(Mw)/dq")?;
    let mut d_j = SMatrix::<T, K, N>::zeros();
    let mut c_v = SMatrix::<T, K, N>::zeros();
    let accel_dq = model.jacobian_dq(q, &accel);
    finite(&accel_dq, "d(Jv)/dq")?;
    for i in active {
        d_j.set_row(i, &accel_dq.row(i));
        c_v.set_row(i, &(rate_dq.row(i) * nalgebra::convert::<f64, T>(2.0)));
    }
    let b = h_lambda - lin.forces_dq - mass_dq;
    let minv_b = chol.solve(&b);
    let lambda_q = -w_chol.solve(&(d_j + jac_a * minv_b));
    let minv_fv = chol.solve(&lin.forces_dv);
    let lambda_v = -w_chol.solve(&(c_v - jac_a * minv_fv));
    let a = Blocks {
        qq: SMatrix::zeros(),
        qv: SMatrix::identity(),
        vq: minv_b + minv_jt * lambda_q,
        vv: -minv_fv + minv_jt * lambda_v,
    };
    Ok((a, accel))
}

/// The transition `Φ(h) = Σ_{j ≤ 4} (A h)^j / j!` of `x' = A x` over `h`:
/// classical Runge–Kutta applied to the variational equation `Φ' = A Φ`
/// with `A` held at the start of the piece (for a constant `A` this is
/// exactly what the fourth-order Runge–Kutta prediction does to a
/// perturbation of its initial point). No matrix exponential.
///
/// ```
/// use moreau_runtime::{Blocks, transition};
/// use nalgebra::Matrix1;
///
/// // q' = v, v' = 0: Φ(h) = [[1, h], [0, 1]] exactly
/// let a = Blocks { qq: Matrix1::zeros(), qv: Matrix1::identity(), vq: Matrix1::zeros(), vv: Matrix1::zeros() };
/// let phi = transition(&a, 0.25_f64);
/// assert_eq!((phi.entry(0, 0), phi.entry(0, 1), phi.entry(1, 0), phi.entry(1, 1)), (1.0, 0.25, 0.0, 1.0));
/// ```
pub fn transition<T: RealField + Copy, const N: usize>(a: &Blocks<T, N>, h: T) -> Blocks<T, N> {
    if a.qq == SMatrix::<T, N, N>::zeros() && a.qv == SMatrix::<T, N, N>::identity() {
        flow_transition(a, h)
    } else {
        general_transition(a, h)
    }
}

/// [`transition`] of a flow's `A` (`q' = v`: `A_qq = 0`, `A_qv = I`, as
/// [`flow_jacobian`] and [`constrained_flow_jacobian`] give it). Each
/// Horner step `I + (h/k) A Φ` needs `A Φ = (Φ_vq, Φ_vv; A_vq Φ_qq + A_vv
/// Φ_vq, A_vq Φ_qv + A_vv Φ_vv)`: half the block products of the general
/// one, and (a product by an exact `0` or `1` adding nothing) the same
/// bits for finite entries (docs/estimation-under-noise.md, "Cost
/// re-runs": with [`Blocks::joseph_position_update`], 10 % fewer
/// instructions per filter update in free flight on Example 1). The
/// filter's propagation calls it directly: the Jacobians it holds are a
/// flow's by construction, so no piece tests the blocks again.
pub(crate) fn flow_transition<T: RealField + Copy, const N: usize>(
    a: &Blocks<T, N>,
    h: T,
) -> Blocks<T, N> {
    debug_assert!(
        a.qq == SMatrix::<T, N, N>::zeros() && a.qv == SMatrix::<T, N, N>::identity(),
        "not a flow's A"
    );
    let id = Blocks::identity();
    let c = h / nalgebra::convert::<f64, T>(4.0);
    let mut phi = id.add(&Blocks {
        qq: SMatrix::<T, N, N>::zeros(),
        qv: SMatrix::<T, N, N>::identity() * c,
        vq: a.vq * c,
        vv: a.vv * c,
    });
    for k in [3.0, 2.0, 1.0] {
        let c = h / nalgebra::convert::<f64, T>(k);
        let (vq, vv) = (a.vq * c, a.vv * c);
        phi = id.add(&Blocks {
            qq: phi.vq * c,
            qv: phi.vv * c,
            vq: vq * phi.qq + vv * phi.vq,
            vv: vq * phi.qv + vv * phi.vv,
        });
    }
    phi
}

/// [`transition`] of any `A`, by Horner's rule on the blocks.
fn general_transition<T: RealField + Copy, const N: usize>(a: &Blocks<T, N>, h: T) -> Blocks<T, N> {
    let scaled = |k: f64| {
        let c = h / nalgebra::convert::<f64, T>(k);
        Blocks {
            qq: a.qq * c,
            qv: a.qv * c,
            vq: a.vq * c,
            vv: a.vv * c,
        }
    };
    let id = Blocks::identity();
    let mut phi = id.add(&scaled(4.0));
    for k in [3.0, 2.0, 1.0] {
        phi = id.add(&scaled(k).mul(&phi));
    }
    phi
}

/// Newton's law on a set of active constraints and its saltation matrix
/// (see [`saltation`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Saltation<T: RealField + Copy, const N: usize, const K: usize> {
    /// The post-impact velocity `v⁺`.
    pub v_plus: SVector<T, N>,
    /// The impulses `λ` (zero off the active set).
    pub lambda: SVector<T, K>,
    /// `∂v⁺/∂v⁻`, the reset's velocity block `R`.
    pub reset_dv: SMatrix<T, N, N>,
    /// `∂v⁺/∂q` at fixed `v⁻`, the reset's configuration block `X`.
    pub reset_dq: SMatrix<T, N, N>,
    /// The saltation matrix `Ξ`: a perturbation `δx⁻` of the state just
    /// before the impact becomes `Ξ δx⁻` just after it.
    pub matrix: Blocks<T, N>,
    /// How the state just after the impact moves when the impact itself
    /// comes later by `δt` with the state before it unchanged:
    /// `(DΔ f⁻ − f⁺) δt`, as its position and velocity parts. The position
    /// part is the velocity jump `v⁻ − v⁺`; the velocity part the change
    /// of acceleration the jump makes. A real impact is not instantaneous
    /// (contact compliance, a time-stepping plant's grid), and this is the
    /// direction in which its timing shows.
    pub timing: (SVector<T, N>, SVector<T, N>),
}

impl<T: RealField + Copy, const N: usize, const K: usize> Saltation<T, N, K> {
    /// `DΔ = [[I, 0], [X, R]]`, the reset's Jacobian: the saltation of the
    /// same impact at a fixed instant.
    pub(crate) fn reset(&self) -> Blocks<T, N> {
        reset_map(&self.reset_dq, &self.reset_dv)
    }
}

/// `[[I, 0], [X, R]]` from the reset's blocks `X = ∂v⁺/∂q`, `R = ∂v⁺/∂v⁻`.
fn reset_map<T: RealField + Copy, const N: usize>(
    reset_dq: &SMatrix<T, N, N>,
    reset_dv: &SMatrix<T, N, N>,
) -> Blocks<T, N> {
    Blocks {
        qq: SMatrix::identity(),
        qv: SMatrix::zeros(),
        vq: *reset_dq,
        vv: *reset_dv,
    }
}

/// Newton's law on the active set `active` (the constraints that end the
/// impact with a positive impulse: the LCP's outcome) with the
/// coefficients `e` (`e_i` as applied: `ê_i` for an elastic impact, `0`
/// for a plastic closure), at `(t, q)` for the pre-impact velocity `v⁻`,
/// and its saltation matrix for the impact triggered by the gap
/// `h_guard` reaching zero.
///
/// With `J_A` the rows of `J(q)` on `A`, `W = J_A M⁻¹ J_Aᵀ` and
/// `E = diag(e_A)`, the law `J_A (v⁺ + E v⁻) = 0`,
/// `M (v⁺ − v⁻) = J_Aᵀ λ` gives `λ = −W⁻¹ (I + E) J_A v⁻` and the reset
/// `Δ(q, v⁻) = (q, v⁺)` with
///
/// - `R = ∂v⁺/∂v⁻ = I − M⁻¹ J_Aᵀ W⁻¹ (I + E) J_A`,
/// - `X = ∂v⁺/∂q = M⁻¹ (H_λ − D_M + J_Aᵀ Λ)`,
///   `Λ = −W⁻¹ (D_J + J_A M⁻¹ (H_λ − D_M))`,
///
/// where `H_λ = Σ λ_i ∇²h_i` (from [`Sensitivities::jacobian_dq`] along
/// the unit vectors), `D_M = ∂(M w)/∂q` at `w = v⁺ − v⁻`
/// ([`Sensitivities::mass_dq`]) and row `i` of `D_J` is
/// `∂(J_i (v⁺ + e_i v⁻))/∂q`. The impact time moves with the state: with
/// `g = h_guard`, `f^∓ = (v^∓, a^∓)` the free vector fields on both sides
/// and `DΔ = [[I, 0], [X, R]]`,
///
/// $$\Xi = D\Delta + \frac{(f^+ - D\Delta\, f^-)\,\nabla g^{\mathsf T}}{\nabla g \cdot f^-}.$$
///
/// With `guard = None` (a closed constraint met approaching, or an
/// approach too slow to time) `Ξ = DΔ`. Several constraints may be
/// active at once (a ball hitting a resting pair); the guard is the one
/// whose crossing timed the impact.
///
/// ```
/// use moreau_runtime::{saltation, IndexSet, Model, ModelInfo, Sensitivities};
/// use nalgebra::{Matrix1, SVector, Vector1};
///
/// /// A unit ball above the floor y ≥ 0 under gravity 10.
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
///     fn gravity(&self, _: &Vector1<f64>) -> Vector1<f64> { Vector1::new(10.0) }
///     fn forces(&self, _: f64, _: &Vector1<f64>, _: &Vector1<f64>, _: &SVector<f64, 0>) -> Vector1<f64> {
///         Vector1::new(10.0)
///     }
///     fn gaps(&self, q: &Vector1<f64>) -> Vector1<f64> { *q }
///     fn gap_jacobian(&self, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
///     fn restitution(&self) -> Vector1<f64> { Vector1::new(0.5) }
///     fn parameter(&self, _: usize) -> Option<f64> { None }
///     fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> { None }
/// }
/// impl Sensitivities<1, 1> for Ball {
///     fn mass_dq(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
///     fn jacobian_dq(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
/// }
///
/// // landing at 4 m/s with e = 1/2: the classical bouncing-ball saltation
/// // [[−e, 0], [(1 + e) g / |v⁻|, −e]]
/// let s = saltation(&Ball, 0.0, &Vector1::new(0.0), &Vector1::new(-4.0), &SVector::zeros(),
///                   IndexSet::full(1), &Vector1::new(0.5), Some(0))?;
/// assert_eq!(s.v_plus[0], 2.0);
/// let x = s.matrix;
/// assert_eq!((x.entry(0, 0), x.entry(0, 1), x.entry(1, 0), x.entry(1, 1)), (-0.5, 0.0, 3.75, -0.5));
/// // an impact δt late moves the state after it by (−6, 15) δt: the ball
/// // sinks 4 δt, leaves at 2 + 5 δt and has lost 2 δt of climb (by hand)
/// assert_eq!(s.timing, (Vector1::new(-6.0), Vector1::new(15.0)));
/// # Ok::<(), moreau_runtime::ObserverError<f64>>(())
/// ```
///
/// # Errors
///
/// [`DataError::NonFiniteModel`](crate::DataError::NonFiniteModel) or
/// [`DataError::MassNotPositiveDefinite`](crate::DataError::MassNotPositiveDefinite) where the model fails,
/// [`DataError::InvalidParams`](crate::DataError::InvalidParams) (`"active"`) when the active rows of
/// `J` are dependent (`W` singular).
#[allow(clippy::too_many_arguments)]
pub fn saltation<M, T, const N: usize, const K: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    v_minus: &SVector<T, N>,
    u: &M::Input,
    active: IndexSet<K>,
    e: &SVector<T, K>,
    guard: Option<usize>,
) -> Result<Saltation<T, N, K>, T>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    let (mass, forces_minus) = model.dynamics(t, q, v_minus, u);
    finite(&forces_minus, "F")?;
    let chol = factor_mass(&mass)?;
    let (_, jac) = model.contact(q);
    finite(&jac, "J")?;
    // rows off the active set are zero, and W gets 1 on their diagonal
    let mut e_a = SVector::<T, K>::zeros();
    for i in active {
        e_a[i] = e[i];
    }
    let OnSet {
        rows: jac_a,
        minv_jt,
        delassus,
    } = OnSet::new(&jac, &chol, active);
    let w_chol = delassus.ok_or(ObserverError::Data(DataError::InvalidParams {
        name: "active",
        value: T::zero(),
    }))?;
    let one_plus_e = SMatrix::<T, K, K>::from_diagonal(&e_a.add_scalar(T::one()));
    // λ and v⁺
    let lambda = -w_chol.solve(&(one_plus_e * jac_a * v_minus));
    let du = minv_jt * lambda;
    let v_plus = v_minus + du;
    // R = ∂v⁺/∂v⁻
    let reset_dv = SMatrix::<T, N, N>::identity() - minv_jt * w_chol.solve(&(one_plus_e * jac_a));
    // X = ∂v⁺/∂q
    let mut h_lambda = SMatrix::<T, N, N>::zeros();
    for k in 0..N {
        let col = model
            .jacobian_dq(
                q,
                &SVector::<T, N>::from_fn(|i, _| if i == k { T::one() } else { T::zero() }),
            )
            .transpose()
            * lambda;
        h_lambda.set_column(k, &col);
    }
    finite(&h_lambda, "d(Jv)/dq")?;
    let d_m = model.mass_dq(q, &du);
    finite(&d_m, "d(Mw)/dq")?;
    let dj_plus = model.jacobian_dq(q, &v_plus);
    let dj_minus = model.jacobian_dq(q, v_minus);
    let mut d_j = SMatrix::<T, K, N>::zeros();
    for i in active {
        d_j.set_row(i, &(dj_plus.row(i) + dj_minus.row(i) * e_a[i]));
    }
    finite(&d_j, "d(Jv)/dq")?;
    let base = chol.solve(&(h_lambda - d_m));
    let big_lambda = -w_chol.solve(&(d_j + jac_a * base));
    let reset_dq = base + minv_jt * big_lambda;
    let mut matrix = reset_map(&reset_dq, &reset_dv);
    let accel_minus = -chol.solve(&forces_minus);
    let forces_plus = model.forces(t, q, &v_plus, u);
    finite(&forces_plus, "F")?;
    let accel_plus = -chol.solve(&forces_plus);
    // f⁺ − DΔ f⁻
    let shift_q = v_plus - v_minus;
    let shift_v = accel_plus - reset_dq * v_minus - reset_dv * accel_minus;
    if let Some(g) = guard.filter(|&g| g < K) {
        let row = jac.row(g);
        let rate = row.dot(&v_minus.transpose());
        if rate < T::zero() {
            matrix.qq += (shift_q / rate) * row;
            matrix.vq += (shift_v / rate) * row;
        }
    }
    Ok(Saltation {
        v_plus,
        lambda,
        reset_dv,
        reset_dq,
        matrix,
        timing: (-shift_q, -shift_v),
    })
}

/// What [`project_onto_contact`] returns.
pub(crate) struct Projection<T: RealField + Copy, const N: usize, const K: usize> {
    /// `B P Bᵀ`.
    pub p: Blocks<T, N>,
    /// The projector `B` itself.
    pub map: Blocks<T, N>,
    /// The state's move onto the manifold, position part.
    pub dq: SVector<T, N>,
    /// The state's move onto the manifold, velocity part.
    pub dv: SVector<T, N>,
    /// How the manifold moves with the levels `ℓ_S`: a change `δℓ` moves
    /// its points by `level.0 δℓ` (`J⁺`, so `J_S δq = δℓ`) and their
    /// velocities by `level.1 δℓ` (`−J⁺ D J⁺`, so `J_S v = 0` still holds
    /// to first order); zero columns off `set`.
    pub level: (SMatrix<T, N, K>, SMatrix<T, N, K>),
}

/// Projects the state's perturbations onto the tangent space of the
/// contact manifold `h_S(q) = 0`, `J_S(q) v = 0` at `(q, v)`, in the metric
/// of the mass matrix (the metric of Newton's law: a plastic impact
/// projects the velocity the same way). With `J⁺ = M⁻¹ J_Sᵀ (J_S M⁻¹
/// J_Sᵀ)⁻¹`, `Π = I − J⁺ J_S` and `D = ∂(J_S v)/∂q`:
///
/// $$B = \begin{pmatrix} \Pi & 0 \\ -J^{+} D\, \Pi & \Pi \end{pmatrix},$$
///
/// a projector (`B² = B`) whose range satisfies `J_S δq = 0` and
/// `D δq + J_S δv = 0`; `P ← B P Bᵀ` (a congruence: positive
/// semi-definite, its own rounding covered by
/// [`Blocks::congruence_covered`]). The state moves onto the
/// manifold along the same metric: `δq = −J⁺ h_S`, then
/// `δv = −J⁺ (J_S v + D δq)`. `h` is the gap to the manifold: `h(q) − ℓ`
/// for a contact held at the level `ℓ` (module `level`). Returns `None`
/// when the rows of `set` are dependent.
#[allow(clippy::too_many_arguments)]
pub(crate) fn project_onto_contact<T: RealField + Copy, const N: usize, const K: usize>(
    p: &Blocks<T, N>,
    mass: &Ldlt<T, N>,
    h: &SVector<T, K>,
    jac: &SMatrix<T, K, N>,
    rate: &SMatrix<T, K, N>,
    v: &SVector<T, N>,
    set: IndexSet<K>,
) -> Option<Projection<T, N, K>> {
    let mut d = SMatrix::<T, K, N>::zeros();
    let mut r_h = SVector::<T, K>::zeros();
    for i in set {
        d.set_row(i, &rate.row(i));
        r_h[i] = h[i];
    }
    let OnSet {
        rows: j,
        minv_jt,
        delassus,
    } = OnSet::new(jac, mass, set);
    let w_chol = delassus?;
    // J⁺ = M⁻¹Jᵀ W⁻¹ (N × K)
    let pinv = w_chol.solve(&minv_jt.transpose()).transpose();
    let pi = SMatrix::<T, N, N>::identity() - pinv * j;
    let b = Blocks {
        qq: pi,
        qv: SMatrix::zeros(),
        vq: -(pinv * d * pi),
        vv: pi,
    };
    let dq = -(pinv * r_h);
    let dv = -(pinv * (j * v + d * dq));
    Some(Projection {
        p: b.congruence_covered(p),
        map: b,
        dq,
        dv,
        level: (pinv, -(pinv * d * pinv)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix4};

    fn full(b: &Blocks<f64, 2>) -> Matrix4<f64> {
        Matrix4::from_fn(|i, j| b.entry(i, j))
    }

    /// The flow's short path gives the general path's bits, and both the
    /// Taylor polynomial `Σ_{j ≤ 4} (A h)^j / j!` of the full `4 × 4`
    /// matrix; an `A` that is not a flow's takes the general path.
    #[test]
    fn the_transition_of_a_flow_is_the_general_one_to_the_bit() {
        let flow = Blocks {
            qq: Matrix2::zeros(),
            qv: Matrix2::identity(),
            vq: Matrix2::new(-3.0, 0.5, 1.25, -0.75),
            vv: Matrix2::new(-0.2, 0.1, 0.05, -0.4),
        };
        let taylor = |a: &Blocks<f64, 2>, h: f64| {
            let ah = full(a) * h;
            let mut term = Matrix4::identity();
            let mut sum = Matrix4::identity();
            for j in 1..=4 {
                term = term * ah / f64::from(j);
                sum += term;
            }
            sum
        };
        for h in [1e-3, 0.37, 2.0] {
            let short = transition(&flow, h);
            assert_eq!(short, general_transition(&flow, h));
            assert!((full(&short) - taylor(&flow, h)).amax() <= 1e-14 * taylor(&flow, h).amax());
        }
        let other = Blocks {
            qq: Matrix2::new(0.1, 0.0, 0.0, 0.2),
            ..flow
        };
        assert_eq!(transition(&other, 0.37), general_transition(&other, 0.37));
        assert!((full(&transition(&other, 0.37)) - taylor(&other, 0.37)).amax() <= 1e-14);
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config::with_cases(200))]

        /// Where the acceleration depends on neither `q` nor `v` (`A = (0,
        /// I; 0, 0)`, as `flow_jacobian` gives it for such a model: `−M⁻¹
        /// 0`), the written-out transition and congruence give the general
        /// path's bits, on covariances `L Lᵀ` of three coordinates with
        /// entries of `L` over six orders of magnitude, and over steps from
        /// a microsecond to a second.
        #[test]
        fn the_ballistic_shortcut_is_the_general_flow_to_the_bit(
            entries in proptest::collection::vec((-1.0..1.0f64, -6.0..0.0f64), 21),
            h_exponent in -6.0..0.0f64,
        ) {
            use nalgebra::{Matrix3, Matrix6};
            let a = Blocks::<f64, 3> {
                qq: Matrix3::zeros(),
                qv: Matrix3::identity(),
                vq: -Matrix3::zeros(),
                vv: -Matrix3::zeros(),
            };
            // L lower-triangular, its 21 entries mantissa × 10^exponent
            let mut lower = entries.iter().map(|&(m, e)| m * 10f64.powf(e));
            let l = Matrix6::from_fn(|i, j| if j > i { 0.0 } else { lower.next().unwrap() });
            let full_p = l * l.transpose();
            let p = Blocks {
                qq: full_p.fixed_view::<3, 3>(0, 0).into_owned(),
                qv: full_p.fixed_view::<3, 3>(0, 3).into_owned(),
                vq: full_p.fixed_view::<3, 3>(3, 0).into_owned(),
                vv: full_p.fixed_view::<3, 3>(3, 3).into_owned(),
            };
            let h = 10f64.powf(h_exponent);
            let phi = flow_transition(&a, h);
            proptest::prop_assert_eq!(phi, Blocks::ballistic(h));
            proptest::prop_assert_eq!(p.ballistic_congruence_covered(h), phi.congruence_covered(&p));
        }
    }
}
