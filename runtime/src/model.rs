//! The model contract: what a compiled mechanical model provides to the
//! simulator and the observers.
//!
//! A model describes the paper's system (1) and (8),
//!
//! $$M(q)\,\ddot q + F(t, q, \dot q) = 0, \qquad h_i(q) \ge 0,\ i = 1..K,$$
//!
//! with `N` degrees of freedom and `K` unilateral constraints. The `model!`
//! macro generates implementations from a Lagrangian (kinetic energy `T(q, v)`,
//! potential `V(q)`, extra generalized forces `Q(t, q, v, u)`):
//!
//! - `M(q) = ∂²T/∂v²` (symmetric positive definite),
//! - `C(q, v)` from the Christoffel symbols of `M`, so that `Ṁ − 2C` is skew,
//! - `G(q) = ∂V/∂q`,
//! - `F(t, q, v, u) = C(q, v) v + G(q) − Q(t, q, v, u)`,
//! - `h(q)` and its Jacobian `J(q) = ∂h/∂q` (row `i` is `∇h_iᵀ`).
//!
//! Every method is a straight-line evaluation on the stack; none allocates.

use nalgebra::{RealField, SMatrix, SVector};

/// Structural facts about a model, decided by the compiler from the
/// model's symbolic form (each `true` is a proof, each `false` says only
/// that it could not be shown).
///
/// ```
/// use moreau_runtime::Structure;
/// let s = Structure::GENERAL;
/// assert!(!s.mass_constant && !s.forces_velocity_free);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Structure {
    /// `M` does not depend on `q` (nor on parameters changing at run time:
    /// it may depend on parameters, which are constant during a run).
    pub mass_constant: bool,
    /// `M` is diagonal.
    pub mass_diagonal: bool,
    /// `F` does not depend on `v` (`∂F/∂v = 0`).
    pub forces_velocity_free: bool,
    /// `F` does not depend on `q` (`∂F/∂q = 0`).
    pub forces_configuration_free: bool,
    /// `F` does not depend on the time `t`.
    pub forces_time_free: bool,
    /// `F` does not depend on the inputs `u` (or there are none).
    pub forces_input_free: bool,
    /// `J` does not depend on `q` (every gap is affine in `q`).
    pub jacobian_constant: bool,
}

impl Structure {
    /// Nothing known: every flag `false`.
    pub const GENERAL: Structure = Structure {
        mass_constant: false,
        mass_diagonal: false,
        forces_velocity_free: false,
        forces_configuration_free: false,
        forces_time_free: false,
        forces_input_free: false,
        jacobian_constant: false,
    };

    /// Whether the free acceleration `a = −M⁻¹F` depends on neither `q`
    /// nor `v`: `M` constant and `F` free of both (point masses under
    /// constant forces). Its flow's Jacobian is then `(0, I; 0, 0)`.
    pub(crate) const fn acceleration_state_free(&self) -> bool {
        self.mass_constant && self.forces_configuration_free && self.forces_velocity_free
    }
}

/// Static facts about a model: names, the model text and the size of its
/// generated code.
///
/// Available without an instance as [`Model::INFO`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ModelInfo<const N: usize, const K: usize> {
    /// The model's name (the generated type's name).
    pub name: &'static str,
    /// Names of the generalized coordinates `q`, in order.
    pub coordinates: [&'static str; N],
    /// Names of the generalized velocities `v`, in the order of `q`.
    pub velocities: [&'static str; N],
    /// Names of the constraints `h_i`, in order.
    pub constraints: [&'static str; K],
    /// Names of the parameters, in the order of [`Model::parameter`].
    pub parameters: &'static [&'static str],
    /// Names of the inputs `u`, in the order of [`Model::Input`].
    pub inputs: &'static [&'static str],
    /// The model text in the YAML model language, whichever front end the
    /// model was written in. Feed it to `tests/casadi_reference.py` to check
    /// the generated derivatives of any model against CasADi.
    pub source: &'static str,
    /// Number of arithmetic operations in the fused evaluation
    /// [`Model::eval`] after common-subexpression elimination (comparable
    /// with the instruction count of a CasADi `SX` function, leaving out its
    /// input, output and constant instructions).
    pub op_count: usize,
}

/// All terms of the model at one point, from one fused evaluation.
///
/// See [`Model::eval`]. Field names follow the paper: `mass` is `M(q)`,
/// `forces` is `F(t, q, v, u)`.
#[allow(non_snake_case)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Terms<T: RealField + Copy, const N: usize, const K: usize> {
    /// Mass matrix `M(q)`, symmetric (both triangles filled).
    pub mass: SMatrix<T, N, N>,
    /// Coriolis matrix `C(q, v)` (Christoffel form, `Ṁ − 2C` skew).
    pub coriolis: SMatrix<T, N, N>,
    /// Gravity (potential) forces `G(q) = ∂V/∂q`.
    pub gravity: SVector<T, N>,
    /// Total force `F = C v + G − Q`.
    pub forces: SVector<T, N>,
    /// Gaps `h(q)`; admissible when every entry is `≥ 0`.
    pub gaps: SVector<T, K>,
    /// Gap Jacobian `J(q) = ∂h/∂q`, row `i` is `∇h_iᵀ`.
    pub jacobian: SMatrix<T, K, N>,
}

/// Mass matrix, total force and the force's Jacobians at one point: what an
/// implicit time step needs (see [`Model::linearization`]).
#[allow(non_snake_case)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linearization<T: RealField + Copy, const N: usize> {
    /// Mass matrix `M(q)`.
    pub mass: SMatrix<T, N, N>,
    /// Total force `F(t, q, v, u)`.
    pub forces: SVector<T, N>,
    /// `∂F/∂q`, entry `(i, j)` is `∂F_i/∂q_j`.
    pub forces_dq: SMatrix<T, N, N>,
    /// `∂F/∂v`, entry `(i, j)` is `∂F_i/∂v_j`.
    pub forces_dv: SMatrix<T, N, N>,
}

/// A Lagrangian system with `N` coordinates and `K` frictionless unilateral
/// constraints: the paper's system (8).
///
/// Generated by `moreau::model!`; it can also be written by hand, as this
/// one-degree-of-freedom ball bouncing on the floor `h = y ≥ 0`:
///
/// ```
/// use moreau_runtime::{Model, ModelInfo};
/// use nalgebra::{SMatrix, SVector, Vector1, Matrix1};
///
/// /// A ball of mass `m` above the floor.
/// struct Ball { m: f64, g: f64 }
///
/// impl Model<1, 1> for Ball {
///     type Scalar = f64;
///     type Input = SVector<f64, 0>;
///     const INFO: ModelInfo<1, 1> = ModelInfo {
///         name: "Ball",
///         coordinates: ["y"],
///         velocities: ["vy"],
///         constraints: ["floor"],
///         parameters: &["m", "g"],
///         inputs: &[],
///         source: "",
///         op_count: 1,
///     };
///     fn mass(&self, _q: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(self.m) }
///     fn coriolis(&self, _q: &Vector1<f64>, _v: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
///     fn gravity(&self, _q: &Vector1<f64>) -> Vector1<f64> { Vector1::new(self.m * self.g) }
///     fn forces(&self, _t: f64, q: &Vector1<f64>, _v: &Vector1<f64>, _u: &SVector<f64, 0>) -> Vector1<f64> {
///         self.gravity(q)
///     }
///     fn gaps(&self, q: &Vector1<f64>) -> Vector1<f64> { *q }
///     fn gap_jacobian(&self, _q: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
///     fn restitution(&self) -> Vector1<f64> { Vector1::new(0.5) }
///     fn parameter(&self, index: usize) -> Option<f64> {
///         match index { 0 => Some(self.m), 1 => Some(self.g), _ => None }
///     }
///     fn parameter_mut(&mut self, index: usize) -> Option<&mut f64> {
///         match index { 0 => Some(&mut self.m), 1 => Some(&mut self.g), _ => None }
///     }
/// }
///
/// let ball = Ball { m: 2.0, g: 9.81 };
/// let q = Vector1::new(0.3);
/// let terms = ball.eval(0.0, &q, &Vector1::new(-1.0), &SVector::zeros());
/// assert_eq!(terms.forces[0], 2.0 * 9.81);
/// assert_eq!(terms.gaps[0], 0.3);
/// assert_eq!(Ball::parameter_index("g"), Some(1));
/// ```
pub trait Model<const N: usize, const K: usize> {
    /// The scalar type: `f64`, or `f32` on embedded targets.
    type Scalar: RealField + Copy;
    /// The known inputs `u`, an `SVector<Scalar, NU>` (`NU = 0` when the
    /// model has none).
    type Input: Copy + AsRef<[Self::Scalar]>;

    /// Names, model text and operation count.
    const INFO: ModelInfo<N, K>;

    /// What the compiler knows of the model's structure (`M` constant or
    /// diagonal, forces free of `v`, ...), so that the runtime can take the
    /// short path where it holds. The default claims nothing.
    const STRUCTURE: Structure = Structure::GENERAL;

    /// Mass matrix `M(q) = ∂²T/∂v²`, symmetric positive definite.
    fn mass(&self, q: &SVector<Self::Scalar, N>) -> SMatrix<Self::Scalar, N, N>;

    /// Coriolis matrix `C(q, v)`, entry `C_ij = Σ_k Γ_ijk v_k` with the
    /// Christoffel symbols `Γ_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i)`,
    /// so that `Ṁ − 2C` is skew-symmetric (the paper's property (P1)).
    fn coriolis(
        &self,
        q: &SVector<Self::Scalar, N>,
        v: &SVector<Self::Scalar, N>,
    ) -> SMatrix<Self::Scalar, N, N>;

    /// Potential forces `G(q) = ∂V/∂q`.
    fn gravity(&self, q: &SVector<Self::Scalar, N>) -> SVector<Self::Scalar, N>;

    /// Total force of the paper's (1a), `F(t, q, v, u) = C(q, v) v + G(q) − Q(t, q, v, u)`,
    /// so that the unconstrained motion is `M(q) v̇ + F = 0`.
    fn forces(
        &self,
        t: Self::Scalar,
        q: &SVector<Self::Scalar, N>,
        v: &SVector<Self::Scalar, N>,
        u: &Self::Input,
    ) -> SVector<Self::Scalar, N>;

    /// Gaps `h(q)`; the configuration is admissible when all are `≥ 0`.
    fn gaps(&self, q: &SVector<Self::Scalar, N>) -> SVector<Self::Scalar, K>;

    /// Gap Jacobian `J(q) = ∂h/∂q`; row `i` is `∇h_i(q)ᵀ`.
    fn gap_jacobian(&self, q: &SVector<Self::Scalar, N>) -> SMatrix<Self::Scalar, K, N>;

    /// Restitution coefficients `e_i ∈ [0, 1]`, one per constraint.
    fn restitution(&self) -> SVector<Self::Scalar, K>;

    /// The parameter at `index` in [`ModelInfo::parameters`], or `None` past
    /// the end.
    fn parameter(&self, index: usize) -> Option<Self::Scalar>;

    /// The parameter at `index` in [`ModelInfo::parameters`], for writing, or
    /// `None` past the end.
    fn parameter_mut(&mut self, index: usize) -> Option<&mut Self::Scalar>;

    /// Index of the parameter called `name`, if there is one.
    fn parameter_index(name: &str) -> Option<usize> {
        Self::INFO.parameters.iter().position(|p| *p == name)
    }

    /// Mass matrix and total force together, `(M(q), F(t, q, v, u))`: what a
    /// time step needs. Generated models share every subexpression between
    /// the two.
    fn dynamics(
        &self,
        t: Self::Scalar,
        q: &SVector<Self::Scalar, N>,
        v: &SVector<Self::Scalar, N>,
        u: &Self::Input,
    ) -> (SMatrix<Self::Scalar, N, N>, SVector<Self::Scalar, N>) {
        (self.mass(q), self.forces(t, q, v, u))
    }

    /// Mass matrix, total force and the Jacobians `∂F/∂q`, `∂F/∂v`, as the
    /// Moreau–Jean iteration matrix `W = M + τθ ∂F/∂v + τ²θ² ∂F/∂q` needs
    /// them. Generated models compute all four from one instruction list.
    ///
    /// The default returns zero Jacobians: the step then treats forces
    /// explicitly (`W = M`), as Siconos does for a model that gives none.
    fn linearization(
        &self,
        t: Self::Scalar,
        q: &SVector<Self::Scalar, N>,
        v: &SVector<Self::Scalar, N>,
        u: &Self::Input,
    ) -> Linearization<Self::Scalar, N> {
        let (mass, forces) = self.dynamics(t, q, v, u);
        Linearization {
            mass,
            forces,
            forces_dq: SMatrix::zeros(),
            forces_dv: SMatrix::zeros(),
        }
    }

    /// Gaps and their Jacobian together, `(h(q), J(q))`. Generated models
    /// share every subexpression between the two.
    fn contact(
        &self,
        q: &SVector<Self::Scalar, N>,
    ) -> (SVector<Self::Scalar, K>, SMatrix<Self::Scalar, K, N>) {
        (self.gaps(q), self.gap_jacobian(q))
    }

    /// Every term at once, sharing all subexpressions (generated models
    /// evaluate one instruction list; see [`ModelInfo::op_count`]).
    fn eval(
        &self,
        t: Self::Scalar,
        q: &SVector<Self::Scalar, N>,
        v: &SVector<Self::Scalar, N>,
        u: &Self::Input,
    ) -> Terms<Self::Scalar, N, K> {
        Terms {
            mass: self.mass(q),
            coriolis: self.coriolis(q, v),
            gravity: self.gravity(q),
            forces: self.forces(t, q, v, u),
            gaps: self.gaps(q),
            jacobian: self.gap_jacobian(q),
        }
    }
}

/// The second derivatives a covariance-propagating estimator needs: the
/// Jacobian of the free acceleration `a = −M⁻¹(q) F` and the saltation
/// matrix of Newton's impact law, without differentiating numerically.
///
/// With `a = −M⁻¹ F`, `∂a/∂q = −M⁻¹ (∂(M w)/∂q|_{w = a} + ∂F/∂q)` and
/// `∂a/∂v = −M⁻¹ ∂F/∂v`; the impact law `J(q) v⁺ = −e J(q) v⁻` moved with
/// the configuration needs `∂(J(q) v)/∂q`. `model!` generates both from the
/// same instruction list as the rest of the model; a hand-written model
/// implements this trait only if it is used with such an estimator.
///
/// ```
/// use moreau_runtime::{Model, ModelInfo, Sensitivities};
/// use nalgebra::{SMatrix, SVector, Vector1, Matrix1};
///
/// /// A unit mass on a line whose gap is `1 − y²` (a wall at `|y| = 1`).
/// struct Slot;
///
/// impl Model<1, 1> for Slot {
///     type Scalar = f64;
///     type Input = SVector<f64, 0>;
///     const INFO: ModelInfo<1, 1> = ModelInfo {
///         name: "Slot", coordinates: ["y"], velocities: ["vy"], constraints: ["walls"],
///         parameters: &[], inputs: &[], source: "", op_count: 1,
///     };
///     fn mass(&self, _q: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
///     fn coriolis(&self, _q: &Vector1<f64>, _v: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
///     fn gravity(&self, _q: &Vector1<f64>) -> Vector1<f64> { Vector1::zeros() }
///     fn forces(&self, _t: f64, _q: &Vector1<f64>, _v: &Vector1<f64>, _u: &SVector<f64, 0>) -> Vector1<f64> {
///         Vector1::zeros()
///     }
///     fn gaps(&self, q: &Vector1<f64>) -> Vector1<f64> { Vector1::new(1.0 - q[0] * q[0]) }
///     fn gap_jacobian(&self, q: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(-2.0 * q[0]) }
///     fn restitution(&self) -> Vector1<f64> { Vector1::new(1.0) }
///     fn parameter(&self, _index: usize) -> Option<f64> { None }
///     fn parameter_mut(&mut self, _index: usize) -> Option<&mut f64> { None }
/// }
///
/// impl Sensitivities<1, 1> for Slot {
///     fn mass_dq(&self, _q: &Vector1<f64>, _w: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
///     fn jacobian_dq(&self, _q: &Vector1<f64>, v: &Vector1<f64>) -> Matrix1<f64> {
///         Matrix1::new(-2.0 * v[0]) // ∂(−2 y v)/∂y
///     }
/// }
///
/// assert_eq!(Slot.jacobian_dq(&Vector1::new(0.5), &Vector1::new(3.0))[0], -6.0);
/// ```
pub trait Sensitivities<const N: usize, const K: usize>: Model<N, K> {
    /// `∂(M(q) w)/∂q` at fixed `w`: entry `(i, j)` is `Σ_k ∂M_ik/∂q_j w_k`.
    fn mass_dq(
        &self,
        q: &SVector<Self::Scalar, N>,
        w: &SVector<Self::Scalar, N>,
    ) -> SMatrix<Self::Scalar, N, N>;

    /// `∂(J(q) v)/∂q` at fixed `v`: entry `(i, j)` is
    /// `Σ_k ∂²h_i/∂q_j ∂q_k v_k`.
    fn jacobian_dq(
        &self,
        q: &SVector<Self::Scalar, N>,
        v: &SVector<Self::Scalar, N>,
    ) -> SMatrix<Self::Scalar, K, N>;
}
