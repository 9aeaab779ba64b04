//! Gain selection: the constants of Corollaries 2 and 3 estimated from a
//! model's generated code over a box of configurations, and the gain `l_d`
//! they ask for.
//!
//! # The constants
//!
//! Over the box `q_min ≤ q ≤ q_max` and the ball `|v| ≤ C_v`:
//!
//! - `λ_min = inf λ_min(M(q))` (and `λ_max = sup λ_max(M(q))`, for the
//!   constant `√(λ_max/λ_min)` of Theorem 2), by the Jacobi eigenvalues of
//!   `M(q)`;
//! - `C_M = sup ‖C(q, d)‖₂` over unit `d`: `C` is linear in `v`, so
//!   `‖C(q, v)‖ ≤ C_M |v|`, the property (P2);
//! - `C_F = sup ‖∂F/∂v(t, q, v)‖₂` over `|v| ≤ C_v`, from
//!   [`Model::linearization`]: `F̄(t, q, ·) = F(t, q, sat(·))` and `sat` is
//!   1-Lipschitz, so `C_F` is a Lipschitz constant of `F̄` in `v` on all of
//!   `ℝⁿ`. (A hand-written model that keeps the default `linearization`,
//!   whose Jacobians are zero, gets `C_F = 0`.)
//!
//! # Sampling
//!
//! Deterministic, so that the same model and box give the same bits:
//!
//! - configurations: the `2^N` corners of the box (for `N ≤ 10`), its
//!   centre, and the first [`GainRegion::configurations`] points of the
//!   Halton sequence in bases `2, 3, 5, …` (the first `N` primes), scaled
//!   to the box;
//! - directions: `±e_k`, and the first [`GainRegion::directions`] points
//!   of the Halton sequence in the next `N` prime bases, mapped to
//!   `[−1, 1]^N` and normalised;
//! - velocities for `C_F`: `v = 0`, and `C_v d`, `C_v d/2` for each
//!   direction (`∂F/∂v` of the Lagrangian part `C(q, v) v` is affine in
//!   `v`, so its norm is largest on the sphere; the half radius catches
//!   extra forces that are not).
//!
//! Sampling finds a supremum from below: the estimates are what the
//! samples show, not bounds. Where the guarantee matters, use
//! [`CertifiedBounds::certify`] (feature `std`), which proves them: interval
//! enclosures of the generated code in mean-value form, verified
//! eigenvalue and norm bounds, and a branch and bound within a budget of
//! cells, with a report of the worst box and the gap of each constant (see
//! its docs and `runtime/src/interval/`). The sampled estimate stays the
//! quick look: milliseconds, and within the proven bound.
//!
//! # The gain
//!
//! Corollary 2 (full order) asks `λ_min l_d > C_F + C_M C_v + β`,
//! Corollary 3 (reduced order) `λ_min l_d ≥ 2 C_v C_M + 2 C_F + β`.
//! [`ModelBounds::gain_for_margin`] returns the gain `l_d` at which the
//! condition holds with equality, [`ModelBounds::margin`] the margin `β` a
//! given `l_d` leaves; [`ModelBounds::gain_for_decay_rate`] the `l_d` of a
//! decay rate (below). `β` is not a rate: the names keep the three apart.
//!
//! The paper's `β` is a margin in the units of `M` over time: with
//! `W = ṽᵀ M ṽ`, the proof shows `dW/dt ≤ −2 l_d W + 2 (C_F + C_M C_v)|ṽ|²`
//! between impacts (and `W` does not grow at impacts), hence
//!
//! $$|\tilde v(t)|_M \le e^{-r t}\,|\tilde v(0)|_M,\qquad r = l_d - \frac{C_F + C_M C_v}{\underline\lambda_M},$$
//!
//! the rate [`ModelBounds::decay_rate`] returns, in 1/s: Corollary 2's `β`
//! over `λ_min`. When Corollary 3 holds (`β₃ ≥ 0`) and `λ_min ≤ 1`, it is
//! at least Corollary 3's `β₃`: with `c = C_F + C_M C_v ≤ λ l_d / 2`,
//! `r − β₃ = l_d (1 − λ) + c (2 − 1/λ)`, both terms non-negative for
//! `λ ≥ 1/2`, and at least `l_d (1 − λ) + l_d (λ − 1/2) = l_d/2` below. The
//! Euclidean error follows `r` up to the factor `√(λ_max/λ_min)`. For the
//! full-order observer, with `Λ = λI` and `L_ρ1 = ρI`, the Lyapunov
//! function of Theorem 2 decays at `min(λ, r)`.

use nalgebra::{RealField, SVector};

use crate::error::DataError;
use crate::linalg::{SymmetricEigen, spectral_norm};
use crate::model::Model;
#[cfg(feature = "std")]
use crate::{
    enclosure::{Enclose, Enclosure},
    interval::{
        Interval,
        branch::{Cell, Outcome, maximize},
        gradient::Gradient,
        matrix::{
            IMat, MeanValueMatrix, mean_value_eigen_bounds, norm_bound, symmetric_eigen_bounds,
        },
    },
};

use super::ObserverError;

/// Which observer the gain is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Design {
    /// The full-order observer (36), Corollary 2:
    /// `λ_min l_d > C_F + C_M C_v + β`.
    FullOrder,
    /// The reduced-order observer (38), Corollary 3:
    /// `λ_min l_d ≥ 2 C_v C_M + 2 C_F + β`.
    ReducedOrder,
}

/// Where the constants are estimated: a box of configurations, the
/// velocity bound `C_v`, and how densely to sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GainRegion<T: RealField + Copy, const N: usize> {
    /// Lower corner of the box of configurations.
    pub q_min: SVector<T, N>,
    /// Upper corner of the box of configurations.
    pub q_max: SVector<T, N>,
    /// The velocity bound `C_v > 0` of Assumption 1.
    pub velocity_bound: T,
    /// The time at which `F(t, q, v, u)` is evaluated (default `0`).
    pub t: T,
    /// Halton points in the box, besides its corners and centre (default
    /// `512`).
    pub configurations: usize,
    /// Halton directions, besides `±e_k` (default `64`).
    pub directions: usize,
}

impl<T: RealField + Copy, const N: usize> GainRegion<T, N> {
    /// The box `[q_min, q_max]` with velocity bound `C_v`, and the default
    /// sampling.
    #[must_use]
    pub fn new(q_min: SVector<T, N>, q_max: SVector<T, N>, velocity_bound: T) -> Self {
        Self {
            q_min,
            q_max,
            velocity_bound,
            t: T::zero(),
            configurations: 512,
            directions: 64,
        }
    }

    fn check(&self) -> Result<(), ObserverError<T>> {
        let bad = |name, value| Err(super::invalid(name, value));
        for i in 0..N {
            let (lo, hi) = (self.q_min[i], self.q_max[i]);
            if !(lo.is_finite() && hi.is_finite()) {
                return bad("q_min/q_max", if lo.is_finite() { hi } else { lo });
            }
            if lo > hi {
                return bad("q_min", lo);
            }
        }
        if !(self.velocity_bound > T::zero() && self.velocity_bound.is_finite()) {
            return bad("velocity_bound", self.velocity_bound);
        }
        if !self.t.is_finite() {
            return bad("t", self.t);
        }
        Ok(())
    }

    /// Configuration sample `index` (corners, centre, then Halton).
    fn configuration(&self, index: usize) -> SVector<T, N> {
        let corners = if N <= 10 { 1usize << N } else { 0 };
        let span = self.q_max - self.q_min;
        if index < corners {
            let mut q = self.q_min;
            for j in 0..N {
                if index >> j & 1 == 1 {
                    q[j] = self.q_max[j];
                }
            }
            return q;
        }
        let k = index - corners;
        let mut q = self.q_min;
        for j in 0..N {
            let x = if k == 0 {
                0.5
            } else {
                radical_inverse(k as u64, prime(j))
            };
            q[j] += span[j] * nalgebra::convert::<f64, T>(x);
        }
        q
    }

    fn configuration_count(&self) -> usize {
        (if N <= 10 { 1usize << N } else { 0 }) + 1 + self.configurations
    }

    /// Unit direction `index` (`±e_k`, then Halton), or `None` for a Halton
    /// point too close to the origin to normalise.
    fn direction(&self, index: usize) -> Option<SVector<T, N>> {
        if index < 2 * N {
            let mut d = SVector::zeros();
            d[index / 2] = if index % 2 == 0 { T::one() } else { -T::one() };
            return Some(d);
        }
        let k = (index - 2 * N + 1) as u64;
        let mut d = SVector::<T, N>::zeros();
        for j in 0..N {
            d[j] = nalgebra::convert(2.0 * radical_inverse(k, prime(N + j)) - 1.0);
        }
        let n = d.norm();
        (n > nalgebra::convert(1e-3)).then(|| d / n)
    }
}

/// The constants of Corollaries 2 and 3 estimated over a [`GainRegion`].
///
/// ```
/// use moreau_runtime::{Design, GainRegion, Model, ModelBounds, ModelInfo};
/// use nalgebra::{Matrix2, SMatrix, SVector, Vector2};
///
/// /// A point mass m with viscous damping b in the plane, no constraint.
/// struct Puck { m: f64, b: f64 }
/// impl Model<2, 0> for Puck {
///     type Scalar = f64;
///     type Input = SVector<f64, 0>;
///     const INFO: ModelInfo<2, 0> = ModelInfo {
///         name: "Puck", coordinates: ["x", "y"], velocities: ["vx", "vy"], constraints: [],
///         parameters: &[], inputs: &[], source: "", op_count: 0,
///     };
///     fn mass(&self, _: &Vector2<f64>) -> Matrix2<f64> { Matrix2::identity() * self.m }
///     fn coriolis(&self, _: &Vector2<f64>, _: &Vector2<f64>) -> Matrix2<f64> { Matrix2::zeros() }
///     fn gravity(&self, _: &Vector2<f64>) -> Vector2<f64> { Vector2::zeros() }
///     fn forces(&self, _: f64, _: &Vector2<f64>, v: &Vector2<f64>, _: &SVector<f64, 0>) -> Vector2<f64> {
///         v * self.b
///     }
///     fn gaps(&self, _: &Vector2<f64>) -> SVector<f64, 0> { SVector::zeros() }
///     fn gap_jacobian(&self, _: &Vector2<f64>) -> SMatrix<f64, 0, 2> { SMatrix::zeros() }
///     fn restitution(&self) -> SVector<f64, 0> { SVector::zeros() }
///     fn parameter(&self, _: usize) -> Option<f64> { None }
///     fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> { None }
///     fn linearization(&self, t: f64, q: &Vector2<f64>, v: &Vector2<f64>, u: &SVector<f64, 0>)
///         -> moreau_runtime::Linearization<f64, 2> {
///         moreau_runtime::Linearization {
///             mass: self.mass(q),
///             forces: self.forces(t, q, v, u),
///             forces_dq: Matrix2::zeros(),
///             forces_dv: Matrix2::identity() * self.b,
///         }
///     }
/// }
///
/// let region = GainRegion::new(Vector2::new(-1.0, -1.0), Vector2::new(1.0, 1.0), 5.0);
/// let bounds = ModelBounds::estimate(&Puck { m: 2.0, b: 0.5 }, &region, &SVector::zeros())?;
/// assert_eq!((bounds.mass_min, bounds.coriolis, bounds.force_lipschitz), (2.0, 0.0, 0.5));
/// // the gain for Corollary 3 with margin β = 10 kg/s: 2 l_d ≥ 2·0.5 + 10
/// let l_d = bounds.gain_for_margin(Design::ReducedOrder, 10.0);
/// assert_eq!(l_d, 5.5);
/// // the velocity error of l_d = 5.5 decays at least like e^{-(5.5 - 0.5/2) t}
/// assert_eq!(bounds.decay_rate(l_d), 5.25);
/// // and the other way: the gain for a decay rate of 5.25 /s
/// assert_eq!(bounds.gain_for_decay_rate(5.25), 5.5);
/// # Ok::<(), moreau_runtime::ObserverError<f64>>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelBounds<T> {
    /// `λ_min`: the smallest eigenvalue of `M(q)` seen.
    pub mass_min: T,
    /// `λ_max`: the largest eigenvalue of `M(q)` seen.
    pub mass_max: T,
    /// `C_M`: the largest `‖C(q, d)‖₂` seen over unit directions `d`.
    pub coriolis: T,
    /// `C_F`: the largest `‖∂F/∂v‖₂` seen over `|v| ≤ C_v`.
    pub force_lipschitz: T,
    /// The velocity bound `C_v` of the region.
    pub velocity_bound: T,
    /// Configurations sampled.
    pub configurations: usize,
    /// Model evaluations made (mass, Coriolis and linearization).
    pub evaluations: usize,
}

impl<T: RealField + Copy> ModelBounds<T> {
    /// Estimates the constants of `model` over `region` with the known
    /// input `u` (see "Sampling" in the module docs of
    /// `runtime/src/observer/gains.rs`).
    ///
    /// # Errors
    ///
    /// [`ObserverError::Data`] with [`DataError::InvalidParams`] for a
    /// region that is not a finite box with `C_v > 0`,
    /// [`DataError::MassNotPositiveDefinite`] where `M(q)` is not,
    /// [`DataError::NonFiniteModel`] where the model evaluates to NaN,
    /// [`DataError::NonFiniteInput`] for a non-finite `u`.
    pub fn estimate<M, const N: usize, const K: usize>(
        model: &M,
        region: &GainRegion<T, N>,
        u: &M::Input,
    ) -> Result<Self, ObserverError<T>>
    where
        M: Model<N, K, Scalar = T>,
    {
        region.check()?;
        if let Some(index) = u.as_ref().iter().position(|x| !x.is_finite()) {
            return Err(DataError::NonFiniteInput { index }.into());
        }
        let c_v = region.velocity_bound;
        let half: T = nalgebra::convert(0.5);
        let mut bounds = Self {
            mass_min: T::zero(),
            mass_max: T::zero(),
            coriolis: T::zero(),
            force_lipschitz: T::zero(),
            velocity_bound: c_v,
            configurations: region.configuration_count(),
            evaluations: 0,
        };
        let mut first = true;
        let directions = 2 * N + region.directions;
        for index in 0..bounds.configurations {
            let q = region.configuration(index);
            let mass = model.mass(&q);
            let eigen =
                SymmetricEigen::new(&mass).ok_or(DataError::NonFiniteModel { which: "M" })?;
            // finite (the matrix was), so `≤ 0` is the whole test
            if eigen.min() <= T::zero() {
                return Err(DataError::MassNotPositiveDefinite.into());
            }
            if first {
                (bounds.mass_min, bounds.mass_max, first) = (eigen.min(), eigen.max(), false);
            } else {
                bounds.mass_min = bounds.mass_min.min(eigen.min());
                bounds.mass_max = bounds.mass_max.max(eigen.max());
            }
            let lin = model.linearization(region.t, &q, &SVector::zeros(), u);
            bounds.force_lipschitz = bounds.force_lipschitz.max(norm(&lin.forces_dv, "dF/dv")?);
            bounds.evaluations += 2;
            for d in (0..directions).filter_map(|j| region.direction(j)) {
                let c = model.coriolis(&q, &d);
                bounds.coriolis = bounds.coriolis.max(norm(&c, "C")?);
                for radius in [c_v, c_v * half] {
                    let lin = model.linearization(region.t, &q, &(d * radius), u);
                    let dv = norm(&lin.forces_dv, "dF/dv")?;
                    bounds.force_lipschitz = bounds.force_lipschitz.max(dv);
                }
                bounds.evaluations += 3;
            }
        }
        Ok(bounds)
    }

    /// The gain `l_d` (1/s) at which `design`'s corollary holds with
    /// equality for the margin `β` (in the units of `M` per second, kg/s for
    /// a mass; not a rate): `(C_F + C_M C_v + β)/λ_min` (Corollary 2; its
    /// strict inequality holds for any larger `l_d`) or
    /// `(2 C_v C_M + 2 C_F + β)/λ_min` (Corollary 3). For a decay rate, see
    /// [`gain_for_decay_rate`](Self::gain_for_decay_rate).
    pub fn gain_for_margin(&self, design: Design, beta: T) -> T {
        (self.coupling(design) + beta) / self.mass_min
    }

    /// The gain `l_d` (1/s) whose guaranteed decay rate
    /// ([`decay_rate`](Self::decay_rate)) is `rate` (1/s):
    /// `rate + (C_F + C_M C_v)/λ_min`.
    pub fn gain_for_decay_rate(&self, rate: T) -> T {
        rate + self.coupling(Design::FullOrder) / self.mass_min
    }

    /// The margin `β = λ_min l_d − (C_F + C_M C_v)` (Corollary 2) or
    /// `λ_min l_d − 2 (C_v C_M + C_F)` (Corollary 3) that the gain `l_d`
    /// leaves; negative when `l_d` is too small for the corollary.
    pub fn margin(&self, design: Design, l_d: T) -> T {
        self.mass_min * l_d - self.coupling(design)
    }

    /// The guaranteed exponential decay rate (1/s) of the velocity error
    /// in the kinetic metric, `r = l_d − (C_F + C_M C_v)/λ_min` (see the
    /// module docs of `runtime/src/observer/gains.rs`: Corollary 2's `β`
    /// over `λ_min`).
    pub fn decay_rate(&self, l_d: T) -> T {
        l_d - self.coupling(Design::FullOrder) / self.mass_min
    }

    /// `C_F + C_M C_v`, twice that for Corollary 3.
    fn coupling(&self, design: Design) -> T {
        let c = self.force_lipschitz + self.coriolis * self.velocity_bound;
        match design {
            Design::FullOrder => c,
            Design::ReducedOrder => c + c,
        }
    }
}

// ---------------------------------------------------------------------------
// Certified constants

/// How much work the branch and bound of
/// [`CertifiedBounds::certify`] may do, for each of the four constants.
#[cfg(feature = "std")]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// Cells bounded at most per constant (default `20 000`): each costs one
    /// evaluation of the model's enclosure and a few 2×2 to N×N verified
    /// eigenvalue bounds.
    pub boxes: usize,
    /// Stop once the proven bound is within this fraction of the worst
    /// value seen at a point (default `0.01`).
    pub tolerance: f64,
}

#[cfg(feature = "std")]
impl Default for Budget {
    fn default() -> Self {
        Self {
            boxes: 20_000,
            tolerance: 0.02,
        }
    }
}

/// One proven constant, with where it came from and how tight it is.
#[cfg(feature = "std")]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CertifiedConstant<const N: usize> {
    /// The proven bound: a lower bound for `λ_min`, an upper bound for the
    /// others.
    pub bound: f64,
    /// The worst value the search met at a point (computed in floating
    /// point, not proven): the constant lies between `witness` and
    /// `bound`.
    pub witness: f64,
    /// The configurations of the cell that gave the bound (the worst box).
    pub worst_q: [Interval; N],
    /// The directions `d` (for `C_M`) or velocities `v` (for `C_F`) of that
    /// cell; points `0` for `λ_min`, `λ_max`.
    pub worst_w: [Interval; N],
    /// Cells bounded.
    pub boxes: usize,
    /// Whether the search stopped at the tolerance (else at the budget).
    pub converged: bool,
}

#[cfg(feature = "std")]
impl<const N: usize> CertifiedConstant<N> {
    /// `|bound − witness| / |witness|`: how much of the bound may be
    /// overestimation (`0` when both are `0`).
    #[must_use]
    pub fn gap(&self) -> f64 {
        let d = (self.bound - self.witness).abs();
        if d == 0.0 {
            0.0
        } else {
            d / self.witness.abs()
        }
    }

    fn from_outcome(o: Outcome<N>, negate: bool) -> Self {
        let s = if negate { -1.0 } else { 1.0 };
        Self {
            bound: s * o.bound,
            witness: s * o.witness,
            worst_q: o.worst.q,
            worst_w: o.worst.w,
            boxes: o.boxes,
            converged: o.converged,
        }
    }
}

/// Why [`CertifiedBounds::certify`] found no bound.
#[cfg(feature = "std")]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CertifyError<const N: usize> {
    /// A region that is not a finite box with `C_v > 0`, a bad budget
    /// (`"budget.boxes"`, `"budget.tolerance"`), a non-finite `t`.
    Region(ObserverError<f64>),
    /// `M(q)` could not be proven positive definite over the box: the best
    /// proven lower bound of `λ_min` is `lower ≤ 0`, given by the cell
    /// `worst` (`M` is singular there, or so close to it that the budget
    /// did not separate it from `0`).
    MassNotPositiveDefinite {
        /// The proven lower bound of `λ_min(M)`.
        lower: f64,
        /// The cell that gave it.
        worst: [Interval; N],
    },
    /// An enclosure was unbounded on the cell `worst` (`"M"`, `"C"`,
    /// `"dF/dv"`): the model divides by a term that may vanish there, or an
    /// input the caller left as any real enters the term.
    Unbounded {
        /// Which term.
        which: &'static str,
        /// The cell.
        worst: [Interval; N],
    },
}

#[cfg(feature = "std")]
impl<const N: usize> core::fmt::Display for CertifyError<N> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Region(e) => e.fmt(f),
            Self::MassNotPositiveDefinite { lower, worst } => write!(
                f,
                "M(q) is not certifiably positive definite: λ_min ≥ {lower:e} only, on q ∈ {}",
                BoxDisplay(worst)
            ),
            Self::Unbounded { which, worst } => write!(
                f,
                "the enclosure of {which} is unbounded on q ∈ {}",
                BoxDisplay(worst)
            ),
        }
    }
}

#[cfg(feature = "std")]
impl<const N: usize> std::error::Error for CertifyError<N> {}

#[cfg(feature = "std")]
impl<const N: usize> From<ObserverError<f64>> for CertifyError<N> {
    fn from(e: ObserverError<f64>) -> Self {
        Self::Region(e)
    }
}

/// A box printed as `[a, b] × [c, d]`.
#[cfg(feature = "std")]
struct BoxDisplay<'a, const N: usize>(&'a [Interval; N]);

#[cfg(feature = "std")]
impl<const N: usize> core::fmt::Display for BoxDisplay<'_, N> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        for (k, x) in self.0.iter().enumerate() {
            if k > 0 {
                f.write_str(" × ")?;
            }
            write!(f, "[{:.4}, {:.4}]", x.lo(), x.hi())?;
        }
        Ok(())
    }
}

/// The constants of Corollaries 2 and 3 **proven** over a [`GainRegion`]:
/// `λ_min` from below, `λ_max`, `C_M`, `C_F` from above, for every
/// configuration of the box and every velocity of the ball `|v| ≤ C_v`.
///
/// # How
///
/// The model's [`Enclosure`] (generated by `model!` from the same
/// instructions as its `f64` code) is evaluated over cells in
/// [`Interval`] arithmetic (outward rounding; see
/// `runtime/src/interval/mod.rs`), in the mean-value form over the cell's
/// configurations (the value at the centre plus interval gradients times
/// the half-widths, `runtime/src/interval/gradient.rs`, intersected with
/// the plain enclosure), and each cell's matrices are bounded by verified
/// eigenvalue and norm bounds (`runtime/src/interval/matrix.rs`: a
/// congruence by the midpoint's approximate eigenvectors, an interval
/// Cholesky that proves the shift, Ostrowski for the non-orthogonality of
/// the eigenvectors; midpoint–radius for norms). A best-first branch and
/// bound (`runtime/src/interval/branch.rs`) bisects the cell with the worst
/// bound until the bound is within [`Budget::tolerance`] of the worst value
/// seen at a point, or the [`Budget::boxes`] are spent. Mass cells are
/// bisected along the configuration the bounded eigenvalue depends on most
/// (its eigenvector's slope times the width), the others along the
/// coordinate widest relative to the region:
///
/// - `λ_min`, `λ_max`: over the box of configurations;
/// - `C_M = sup ‖C(q, d)‖₂`, `|d| ≤ 1`: over the box × the directions
///   `[0, 1] × [−1, 1]^{N−1}` (`‖C(q, −d)‖ = ‖C(q, d)‖`, `C` being linear
///   in `d`; cells entirely outside the unit ball are dropped, cells across
///   its sphere are cut coordinate-wise to the ball's reach, and the bound
///   also covers what is left of their corners outside);
/// - `C_F = sup ‖∂F/∂v‖₂`, `|v| ≤ C_v`: over the box × `[−C_v, C_v]^N`,
///   cells outside the ball dropped likewise.
///
/// The search allocates (a heap of cells): it is a design-time tool, built
/// with the `std` feature only. The witness values are the model's
/// enclosure at a point (to rounding, the `f64` value there).
///
/// The gain methods round their results in the safe direction (the gain
/// up, the margin and the rate down), in interval arithmetic.
///
/// ```
/// use moreau_runtime::{Budget, CertifiedBounds, Design, Enclose, Enclosure, GainRegion, Interval};
/// # use moreau_runtime::{Model, ModelInfo};
/// # use nalgebra::{Matrix1, SMatrix, SVector, Vector1};
/// /// A bead of mass m on a rod rotating... here simply: M(q) = 1 + q², no C, no F.
/// struct Bead;
/// # impl Model<1, 0> for Bead {
/// #     type Scalar = f64;
/// #     type Input = SVector<f64, 0>;
/// #     const INFO: ModelInfo<1, 0> = ModelInfo {
/// #         name: "Bead", coordinates: ["q"], velocities: ["v"], constraints: [],
/// #         parameters: &[], inputs: &[], source: "", op_count: 0,
/// #     };
/// #     fn mass(&self, q: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0 + q[0] * q[0]) }
/// #     fn coriolis(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
/// #     fn gravity(&self, _: &Vector1<f64>) -> Vector1<f64> { Vector1::zeros() }
/// #     fn forces(&self, _: f64, _: &Vector1<f64>, _: &Vector1<f64>, _: &SVector<f64, 0>) -> Vector1<f64> { Vector1::zeros() }
/// #     fn gaps(&self, _: &Vector1<f64>) -> SVector<f64, 0> { SVector::zeros() }
/// #     fn gap_jacobian(&self, _: &Vector1<f64>) -> SMatrix<f64, 0, 1> { SMatrix::zeros() }
/// #     fn restitution(&self) -> SVector<f64, 0> { SVector::zeros() }
/// #     fn parameter(&self, _: usize) -> Option<f64> { None }
/// #     fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> { None }
/// # }
/// impl Enclosure<1, 0> for Bead {
///     fn mass_enclosure<I: Enclose>(&self, q: &[I; 1]) -> [[I; 1]; 1] {
///         [[I::point(1.0) + q[0].powi(2)]]
///     }
///     fn coriolis_enclosure<I: Enclose>(&self, _: &[I; 1], _: &[I; 1]) -> [[I; 1]; 1] {
///         [[I::point(0.0)]]
///     }
///     fn forces_dv_enclosure<I: Enclose>(&self, _: I, _: &[I; 1], _: &[I; 1], _: &[I]) -> [[I; 1]; 1] {
///         [[I::point(0.0)]]
///     }
/// }
///
/// let region = GainRegion::new(Vector1::new(-1.0), Vector1::new(2.0), 1.0);
/// let proven = CertifiedBounds::certify(&Bead, &region, &[], &Budget::default())?;
/// // λ_min = 1 at q = 0, λ_max = 5 at q = 2
/// assert!(proven.mass_min.bound <= 1.0 && proven.mass_min.bound > 0.99);
/// assert!(proven.mass_max.bound >= 5.0 && proven.mass_max.bound < 5.06);
/// assert_eq!((proven.coriolis.bound, proven.force_lipschitz.bound), (0.0, 0.0));
/// // a proven gain for Corollary 3 with margin β = 2: l_d ≥ 2/λ_min
/// let l_d = proven.gain_for_margin(Design::ReducedOrder, 2.0);
/// assert!(l_d >= 2.0 && proven.margin(Design::ReducedOrder, l_d) >= 2.0 * (1.0 - 1e-12));
/// # Ok::<(), moreau_runtime::CertifyError<1>>(())
/// ```
#[cfg(feature = "std")]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CertifiedBounds<const N: usize> {
    /// `λ_min`: proven lower bound of the smallest eigenvalue of `M(q)`.
    pub mass_min: CertifiedConstant<N>,
    /// `λ_max`: proven upper bound of the largest eigenvalue of `M(q)`.
    pub mass_max: CertifiedConstant<N>,
    /// `C_M`: proven upper bound of `‖C(q, d)‖₂` over unit `d`.
    pub coriolis: CertifiedConstant<N>,
    /// `C_F`: proven upper bound of `‖∂F/∂v‖₂` over `|v| ≤ C_v`.
    pub force_lipschitz: CertifiedConstant<N>,
    /// The velocity bound `C_v` of the region.
    pub velocity_bound: f64,
}

#[cfg(feature = "std")]
impl<const N: usize> CertifiedBounds<N> {
    /// Proves the constants of `model` over `region` (its box, `C_v` and
    /// `t`; its sampling settings are not used) with the inputs `u` (one
    /// box per input, from the first; a missing one is any real), within
    /// `budget` (see the type's docs).
    ///
    /// # Errors
    ///
    /// [`CertifyError::Region`] for a bad region or budget,
    /// [`CertifyError::MassNotPositiveDefinite`] when `λ_min > 0` cannot be
    /// proven, [`CertifyError::Unbounded`] when an enclosure is unbounded
    /// (the bound of that constant would be `∞`).
    pub fn certify<Mo, const K: usize>(
        model: &Mo,
        region: &GainRegion<f64, N>,
        u: &[Interval],
        budget: &Budget,
    ) -> Result<Self, CertifyError<N>>
    where
        Mo: Enclosure<N, K>,
    {
        region.check()?;
        if budget.boxes == 0 {
            return Err(super::invalid("budget.boxes", 0.0).into());
        }
        if !(budget.tolerance >= 0.0 && budget.tolerance.is_finite()) {
            return Err(super::invalid("budget.tolerance", budget.tolerance).into());
        }
        let zero = [Interval::point(0.0); N];
        let q_root: [Interval; N] = core::array::from_fn(|i| {
            Interval::new(region.q_min[i], region.q_max[i]).unwrap_or(Interval::ENTIRE)
        });
        let c_v = region.velocity_bound;
        let t = Interval::point(region.t);
        let (boxes, tol) = (budget.boxes, budget.tolerance);
        let points = |x: &[Interval; N]| -> [Interval; N] {
            core::array::from_fn(|i| Interval::point(x[i].mid()))
        };
        let u_mid: std::vec::Vec<Interval> = u.iter().map(|x| Interval::point(x.mid())).collect();
        let u_grad: std::vec::Vec<Gradient<N>> = u.iter().map(|&x| Gradient::constant(x)).collect();
        let t_grad = Gradient::constant(t);
        let vars = |x: &[Interval; N]| -> [Gradient<N>; N] {
            core::array::from_fn(|k| Gradient::variable(x[k], k))
        };
        let consts = |x: &[Interval; N]| -> [Gradient<N>; N] { x.map(Gradient::constant) };
        // the mean-value form over the cell's q (see interval/gradient.rs)
        let mean_value =
            |g: [[Gradient<N>; N]; N], centre: IMat<N>, q: &[Interval; N]| -> IMat<N> {
                let c = points(q);
                core::array::from_fn(|i| {
                    core::array::from_fn(|j| g[i][j].mean_value(centre[i][j], q, &c))
                })
            };
        let mass = |q: &[Interval; N]| {
            let g = model.mass_enclosure(&vars(q));
            let c = points(q);
            MeanValueMatrix {
                centre: model.mass_enclosure(&c),
                slopes: core::array::from_fn(|m| g.map(|row| row.map(|x| x.g[m]))),
                delta: core::array::from_fn(|m| q[m] - c[m]),
                plain: g.map(|row| row.map(|x| x.v)),
            }
        };

        // λ_min: maximise −λ
        let root = Cell { q: q_root, w: zero };
        let lmin = maximize(root, false, boxes, tol, |c| {
            let m = mass(&c.q);
            let (lo, _) = mean_value_eigen_bounds(&m);
            let (at, _) = symmetric_eigen_bounds(&m.centre);
            (-lo, Some(-at), Some(m.smear(true)))
        });
        let mass_min = CertifiedConstant::from_outcome(lmin, true);
        if mass_min.bound == f64::NEG_INFINITY {
            return Err(CertifyError::Unbounded {
                which: "M",
                worst: mass_min.worst_q,
            });
        }
        // NaN cannot occur (the search reads a NaN bound as +∞, so −∞ here)
        if mass_min.bound <= 0.0 {
            return Err(CertifyError::MassNotPositiveDefinite {
                lower: mass_min.bound,
                worst: mass_min.worst_q,
            });
        }
        let lmax = maximize(root, false, boxes, tol, |c| {
            let m = mass(&c.q);
            let (_, hi) = mean_value_eigen_bounds(&m);
            let (_, at) = symmetric_eigen_bounds(&m.centre);
            (hi, Some(at), Some(m.smear(false)))
        });
        let mass_max = CertifiedConstant::from_outcome(lmax, false);

        // C_M over the half cube of directions
        let mut d_root = [Interval::new(-1.0, 1.0).unwrap_or(Interval::ENTIRE); N];
        if N > 0 {
            d_root[0] = Interval::new(0.0, 1.0).unwrap_or(Interval::ENTIRE);
        }
        let cm_root = Cell {
            q: q_root,
            w: d_root,
        };
        let cm = maximize(cm_root, true, boxes, tol, |c| {
            if outside_ball(&c.w, 1.0) {
                return (f64::NEG_INFINITY, None, None);
            }
            let w = contract_to_ball(&c.w, 1.0);
            let slopes = model.coriolis_enclosure(&vars(&c.q), &consts(&w));
            let hint = live_widest(c, &cm_root, &slopes);
            let enclosure = mean_value(slopes, model.coriolis_enclosure(&points(&c.q), &w), &c.q);
            let d = unit_centre(&c.w, 1.0);
            let at = norm_bound(&model.coriolis_enclosure(&points(&c.q), &points(&d)));
            (norm_bound(&enclosure), Some(at), hint)
        });
        let coriolis = CertifiedConstant::from_outcome(cm, false);

        // C_F over the velocity cube ∩ ball
        let v_root = [Interval::new(-c_v, c_v).unwrap_or(Interval::ENTIRE); N];
        let cf_root = Cell {
            q: q_root,
            w: v_root,
        };
        let cf = maximize(cf_root, true, boxes, tol, |c| {
            if outside_ball(&c.w, c_v) {
                return (f64::NEG_INFINITY, None, None);
            }
            let w = contract_to_ball(&c.w, c_v);
            let slopes = model.forces_dv_enclosure(t_grad, &vars(&c.q), &consts(&w), &u_grad);
            let hint = live_widest(c, &cf_root, &slopes);
            let enclosure = mean_value(
                slopes,
                model.forces_dv_enclosure(t, &points(&c.q), &w, u),
                &c.q,
            );
            let v = unit_centre(&c.w, c_v);
            let at = norm_bound(&model.forces_dv_enclosure(t, &points(&c.q), &points(&v), &u_mid));
            (norm_bound(&enclosure), Some(at), hint)
        });
        let force_lipschitz = CertifiedConstant::from_outcome(cf, false);
        for (which, c) in [
            ("M", &mass_max),
            ("C", &coriolis),
            ("dF/dv", &force_lipschitz),
        ] {
            if !c.bound.is_finite() {
                return Err(CertifyError::Unbounded {
                    which,
                    worst: c.worst_q,
                });
            }
        }
        Ok(Self {
            mass_min,
            mass_max,
            coriolis,
            force_lipschitz,
            velocity_bound: c_v,
        })
    }

    /// The proven bounds as a [`ModelBounds`] (for code written against
    /// the sampled estimate; its gain methods round to nearest, those of
    /// `CertifiedBounds` in the safe direction). `configurations` and
    /// `evaluations` count the cells bounded.
    #[must_use]
    pub fn bounds(&self) -> ModelBounds<f64> {
        let cells = self.mass_min.boxes
            + self.mass_max.boxes
            + self.coriolis.boxes
            + self.force_lipschitz.boxes;
        ModelBounds {
            mass_min: self.mass_min.bound,
            mass_max: self.mass_max.bound,
            coriolis: self.coriolis.bound,
            force_lipschitz: self.force_lipschitz.bound,
            velocity_bound: self.velocity_bound,
            configurations: cells,
            evaluations: 2 * cells,
        }
    }

    /// `C_F + C_M C_v` (twice that for Corollary 3), rounded up.
    fn coupling(&self, design: Design) -> Interval {
        let c = Interval::point(self.force_lipschitz.bound)
            + Interval::point(self.coriolis.bound) * Interval::point(self.velocity_bound);
        let c = Interval::point(c.hi());
        match design {
            Design::FullOrder => c,
            Design::ReducedOrder => c + c,
        }
    }

    fn lambda(&self) -> Interval {
        Interval::point(self.mass_min.bound)
    }

    /// The proven gain `l_d` (1/s) for the margin `β` of `design`'s
    /// corollary (see [`ModelBounds::gain_for_margin`]), rounded up: every
    /// `l_d` at least this satisfies the corollary over the region (for
    /// Corollary 2's strict inequality, any larger one).
    #[must_use]
    pub fn gain_for_margin(&self, design: Design, beta: f64) -> f64 {
        ((self.coupling(design) + Interval::point(beta)) / self.lambda()).hi()
    }

    /// The margin `β` that `l_d` leaves in `design`'s corollary (see
    /// [`ModelBounds::margin`]), rounded down: proven.
    #[must_use]
    pub fn margin(&self, design: Design, l_d: f64) -> f64 {
        (self.lambda() * Interval::point(l_d) - self.coupling(design)).lo()
    }

    /// The proven decay rate (1/s) of the velocity error in the kinetic
    /// metric, `l_d − (C_F + C_M C_v)/λ_min` (see
    /// [`ModelBounds::decay_rate`]), rounded down.
    #[must_use]
    pub fn decay_rate(&self, l_d: f64) -> f64 {
        (Interval::point(l_d) - self.coupling(Design::FullOrder) / self.lambda()).lo()
    }

    /// The gain `l_d` (1/s) whose proven decay rate is `rate` (1/s),
    /// rounded up.
    #[must_use]
    pub fn gain_for_decay_rate(&self, rate: f64) -> f64 {
        (Interval::point(rate) + self.coupling(Design::FullOrder) / self.lambda()).hi()
    }

    /// Whether each proven bound holds against a sampled estimate (which
    /// it must, up to the sampled values' own rounding): `λ_min` proven `≤`
    /// sampled, the others `≥`.
    #[must_use]
    pub fn encloses(&self, sampled: &ModelBounds<f64>) -> bool {
        self.mass_min.bound <= sampled.mass_min
            && self.mass_max.bound >= sampled.mass_max
            && self.coriolis.bound >= sampled.coriolis
            && self.force_lipschitz.bound >= sampled.force_lipschitz
    }

    /// How much more pessimistic than `sampled` each proven bound is, as a
    /// factor `≥ 1` (`1` when both are `0`): `λ_min` sampled / proven,
    /// then `λ_max`, `C_M`, `C_F` proven / sampled.
    #[must_use]
    pub fn tightness(&self, sampled: &ModelBounds<f64>) -> [f64; 4] {
        let ratio = |a: f64, b: f64| if a == b { 1.0 } else { a / b };
        [
            ratio(sampled.mass_min, self.mass_min.bound),
            ratio(self.mass_max.bound, sampled.mass_max),
            ratio(self.coriolis.bound, sampled.coriolis),
            ratio(self.force_lipschitz.bound, sampled.force_lipschitz),
        ]
    }
}

/// The report: each constant, its proven bound, the worst value seen at a
/// point, the gap between them, the cells used and the worst box.
#[cfg(feature = "std")]
impl<const N: usize> core::fmt::Display for CertifiedBounds<N> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        writeln!(
            f,
            "constant   proven          seen at a point  gap      cells   worst box"
        )?;
        for (name, c) in [
            ("λ_min ≥", &self.mass_min),
            ("λ_max ≤", &self.mass_max),
            ("C_M   ≤", &self.coriolis),
            ("C_F   ≤", &self.force_lipschitz),
        ] {
            write!(
                f,
                "{name}    {:<15.9} {:<16.9} {:<8.2e} {:<7} q ∈ {}",
                c.bound,
                c.witness,
                c.gap(),
                c.boxes,
                BoxDisplay(&c.worst_q)
            )?;
            if !c.converged {
                f.write_str(" (budget spent)")?;
            }
            writeln!(f)?;
        }
        write!(f, "C_v = {}", self.velocity_bound)
    }
}

/// Whether the box `w` lies entirely outside the ball `|w| ≤ r` (proven:
/// `inf |w|²` rounded down exceeds `r²` rounded up).
#[cfg(feature = "std")]
fn outside_ball<const N: usize>(w: &[Interval; N], r: f64) -> bool {
    let inf = w.iter().fold(0.0, |s, x| {
        let m = x.mig();
        crate::interval::add_down(s, crate::interval::mul_down(m, m))
    });
    inf > crate::interval::mul_up(r, r)
}

/// The box `w` cut to the ball `|w| ≤ r` coordinate by coordinate: a point
/// of the ball in `w` has `w_k² ≤ r² − Σ_{j≠k} min_{w_j} w_j²` (rounded
/// up), so the cut box still holds every point of `w ∩ ball`.
#[cfg(feature = "std")]
fn contract_to_ball<const N: usize>(w: &[Interval; N], r: f64) -> [Interval; N] {
    use crate::interval::{add_down, add_up, mul_down, mul_up};
    let r2 = mul_up(r, r);
    let mig2: [f64; N] = core::array::from_fn(|k| mul_down(w[k].mig(), w[k].mig()));
    core::array::from_fn(|k| {
        let others = (0..N)
            .filter(|&j| j != k)
            .fold(0.0, |s, j| add_down(s, mig2[j]));
        let room = add_up(r2, -others);
        let bound = if room <= 0.0 {
            0.0
        } else {
            crate::interval::next_up(room.sqrt())
        };
        w[k].intersect(Interval::new(-bound, bound).unwrap_or(w[k]))
            .unwrap_or(w[k])
    })
}

/// The centre of `w`, pulled back onto the ball `|w| ≤ r` (pushed out to
/// its sphere for directions, `r = 1`, so that the value is a `‖C(q, d)‖`
/// at a unit `d`).
#[cfg(feature = "std")]
fn unit_centre<const N: usize>(w: &[Interval; N], r: f64) -> [Interval; N] {
    let c: [f64; N] = core::array::from_fn(|i| w[i].mid());
    let n = c.iter().map(|x| x * x).sum::<f64>().sqrt();
    let scale = if r == 1.0 {
        if n > 0.0 { 1.0 / n } else { 0.0 }
    } else if n > r {
        r / n
    } else {
        1.0
    };
    core::array::from_fn(|i| Interval::point(c[i] * scale))
}

/// `‖m‖₂`, or the error naming the model term that was not finite.
fn norm<T: RealField + Copy, const N: usize>(
    m: &nalgebra::SMatrix<T, N, N>,
    which: &'static str,
) -> Result<T, ObserverError<T>> {
    spectral_norm(m).ok_or(DataError::NonFiniteModel { which }.into())
}

/// The first 64 primes: the Halton bases.
const PRIMES: [u64; 64] = [
    2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97,
    101, 103, 107, 109, 113, 127, 131, 137, 139, 149, 151, 157, 163, 167, 173, 179, 181, 191, 193,
    197, 199, 211, 223, 227, 229, 233, 239, 241, 251, 257, 263, 269, 271, 277, 281, 283, 293, 307,
    311,
];

/// The Halton base of coordinate `j` (bases repeat past the 64th).
fn prime(j: usize) -> u64 {
    PRIMES[j % PRIMES.len()]
}

/// The van der Corput radical inverse of `index` in `base`: its digits
/// mirrored about the radix point, in `[0, 1)`.
fn radical_inverse(mut index: u64, base: u64) -> f64 {
    let (mut scale, mut x) = (1.0, 0.0);
    while index > 0 {
        scale /= base as f64;
        x += scale * (index % base) as f64;
        index /= base;
    }
    x
}

/// Where to bisect a cell of the `C_M` or `C_F` search: the coordinate
/// widest relative to the root box, among the directions or velocities and
/// the configurations the matrix depends on over the cell (a `q_m` whose
/// slope enclosure is exactly zero in every entry, as the first angle of a
/// chain with relative angles, is never split: that would only double the
/// cells). `None` (the search's own rule) when nothing is left.
#[cfg(feature = "std")]
fn live_widest<const N: usize>(
    cell: &Cell<N>,
    root: &Cell<N>,
    slopes: &[[Gradient<N>; N]; N],
) -> Option<usize> {
    let live = |m: usize| slopes.iter().flatten().any(|x| x.g[m].mag() != 0.0);
    let mut best: Option<(f64, usize)> = None;
    for k in 0..2 * N {
        let (x, r) = if k < N {
            (cell.q[k], root.q[k])
        } else {
            (cell.w[k - N], root.w[k - N])
        };
        if r.width() > 0.0 && (k >= N || live(k)) {
            let rel = x.width() / r.width();
            if best.is_none_or(|(b, _)| rel > b) {
                best = Some((rel, k));
            }
        }
    }
    best.map(|(_, k)| k)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Polar;
    use nalgebra::Vector2;

    /// The sup over unit `(ṙ, θ̇)` of `‖[[0, −θ̇], [θ̇, ṙ]]‖₂`: with
    /// `y = θ̇²`, `σ² = (1 + y + √(1 + 2y − 3y²))/2`, largest at `y = 2/3`,
    /// `σ² = 4/3`.
    const POLAR_SIGMA: f64 = 1.154_700_538_379_251_5; // √(4/3)

    #[test]
    fn polar_particle_constants_match_their_closed_form() {
        let model = Polar { m: 2.0 };
        let (r_min, r_max, c_v) = (0.5, 1.5, 3.0);
        let region = GainRegion::new(Vector2::new(r_min, -3.0), Vector2::new(r_max, 3.0), c_v);
        let b = ModelBounds::estimate(&model, &region, &SVector::zeros()).unwrap();
        // λ(M) = {m, m r²}: the corners attain both extremes exactly
        assert_eq!(b.mass_min, 2.0 * r_min * r_min);
        assert_eq!(b.mass_max, 2.0 * r_max * r_max);
        // C_M = m r_max √(4/3): sampled from below, within 1e-3 with the
        // default 64 Halton directions
        let c_m = 2.0 * r_max * POLAR_SIGMA;
        assert!(b.coriolis <= c_m * (1.0 + 1e-12), "{} > {c_m}", b.coriolis);
        assert!(b.coriolis >= c_m * (1.0 - 1e-3), "{} vs {c_m}", b.coriolis);
        // ∂F/∂v = 2C(q, v): C_F = 2 C_M C_v
        let c_f = 2.0 * c_m * c_v;
        assert!(b.force_lipschitz <= c_f * (1.0 + 1e-12));
        assert!(b.force_lipschitz >= c_f * (1.0 - 1e-3));
        assert_eq!(b.configurations, 4 + 1 + 512);
        // the corollaries, both ways
        let l_d = b.gain_for_margin(Design::ReducedOrder, 1.0);
        assert!((b.margin(Design::ReducedOrder, l_d) - 1.0).abs() < 1e-12);
        let l_d = b.gain_for_margin(Design::FullOrder, 1.0);
        assert!((b.margin(Design::FullOrder, l_d) - 1.0).abs() < 1e-12);
        // r = β₂ / λ_min
        assert!((b.decay_rate(l_d) - 1.0 / b.mass_min).abs() < 1e-12);
    }

    #[test]
    fn sampling_is_deterministic_and_in_the_box() {
        let region = GainRegion::new(Vector2::new(-1.0, 2.0), Vector2::new(1.0, 3.0), 1.0);
        for i in 0..region.configuration_count() {
            let q = region.configuration(i);
            assert!(q[0] >= -1.0 && q[0] <= 1.0 && q[1] >= 2.0 && q[1] <= 3.0);
        }
        assert_eq!(region.configuration(4), Vector2::new(0.0, 2.5)); // the centre
        assert_eq!(radical_inverse(6, 2), 0.375); // 110₂ → 0.011₂
        for j in 0..2 * 2 + region.directions {
            if let Some(d) = region.direction(j) {
                let n: f64 = d.norm();
                assert!((n - 1.0).abs() < 1e-15);
            }
        }
        let model = Polar { m: 1.0 };
        let region = GainRegion::new(Vector2::new(0.5, 0.0), Vector2::new(1.0, 1.0), 2.0);
        let a = ModelBounds::estimate(&model, &region, &SVector::zeros()).unwrap();
        let b = ModelBounds::estimate(&model, &region, &SVector::zeros()).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn a_bad_region_is_an_error() {
        let model = Polar { m: 1.0 };
        let u = SVector::zeros();
        let region = GainRegion::new(Vector2::new(1.0, 0.0), Vector2::new(0.5, 1.0), 2.0);
        assert!(matches!(
            ModelBounds::estimate(&model, &region, &u),
            Err(ObserverError::Data(DataError::InvalidParams {
                name: "q_min",
                ..
            }))
        ));
        let region = GainRegion::new(Vector2::new(0.5, 0.0), Vector2::new(1.0, 1.0), 0.0);
        assert!(matches!(
            ModelBounds::estimate(&model, &region, &u),
            Err(ObserverError::Data(DataError::InvalidParams {
                name: "velocity_bound",
                ..
            }))
        ));
        let region = GainRegion::new(Vector2::new(f64::NAN, 0.0), Vector2::new(1.0, 1.0), 1.0);
        assert!(ModelBounds::estimate(&model, &region, &u).is_err());
        // r = 0 makes M singular
        let region = GainRegion::new(Vector2::new(0.0, 0.0), Vector2::new(1.0, 1.0), 1.0);
        assert_eq!(
            ModelBounds::estimate(&model, &region, &u),
            Err(ObserverError::Data(DataError::MassNotPositiveDefinite))
        );
    }
}
