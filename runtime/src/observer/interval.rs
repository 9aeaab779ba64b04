//! One sampling interval `[t_k, t_{k+1}]` with impacts inside it: the
//! discretization both observers share (see the module docs of
//! [`observer`](crate::observer) for the derivation and the contact rule).
//!
//! Along the interval the local time is `s ∈ [0, τ]`; the predicted motion
//! `(p(s), w(s))` starts at the measured `q_k` with the estimate `v̂_k`.

use nalgebra::{RealField, SMatrix, SVector};

use crate::lcp::{IndexSet, Lcp, OnSet};
use crate::linalg::Ldlt;
use crate::model::Model;

use super::{ObserverError, ObserverParams, UpdateReport, check_update};
use crate::validate::{self, factor_mass, finite_model as finite};

type Result<X, T> = core::result::Result<X, ObserverError<T>>;

mod read;
mod retime;
mod traced;
pub(crate) use retime::Events;
pub(crate) use traced::{Flight, Jump, Tracer};

/// The radial saturation `sat(v) = v min(1, C_v/|v|)`: the projection onto
/// the ball `|v| ≤ C_v`, 1-Lipschitz, so `F̄(t, q, v) = F(t, q, sat(v))` is
/// the Lipschitz extension of Assumption 1.
///
/// The square root is taken only near the bound: `|v|² ≤ (15/16) C_v²`
/// (computed) puts the rounded `|v|` below `C_v`, where the result is `v`
/// itself, so the short path returns the very bits of the long one.
pub(crate) fn saturate<T: RealField + Copy, const N: usize>(
    v: &SVector<T, N>,
    bound: T,
) -> SVector<T, N> {
    let squared = v.norm_squared();
    let margin: T = nalgebra::convert(15.0 / 16.0);
    if squared.is_finite() && squared <= margin * (bound * bound) {
        return *v;
    }
    let n = squared.sqrt();
    if n > bound { v * (bound / n) } else { *v }
}

/// [`saturate`] for an estimate written back at the end of an update, and
/// whether the bound held it
/// ([`UpdateReport::at_velocity_bound`](super::UpdateReport::at_velocity_bound)).
pub(crate) fn hold_to_bound<T: RealField + Copy, const N: usize>(
    v: &SVector<T, N>,
    bound: T,
) -> (SVector<T, N>, bool) {
    let held = saturate(v, bound);
    (held, held != *v)
}

/// Whether two samples `τ` apart, each with noise `σ` per coordinate,
/// moved faster than the bound `C_v` (`params`): `|q₁ − q₀| > C_v τ + n_σ
/// √(2N) σ` (`√(2N) σ` the root mean square of the noise in the
/// displacement).
pub(crate) fn moved_past_bound<T: RealField + Copy, const N: usize>(
    params: &ObserverParams<T>,
    (q0, q1): (&SVector<T, N>, &SVector<T, N>),
    tau: T,
) -> bool {
    let spread: T = nalgebra::convert((2 * N) as f64);
    let reach = params.velocity_bound * tau + params.noise_sigmas * spread.sqrt() * params.noise;
    // (squared: no root on the path every update takes)
    (q1 - q0).norm_squared() > reach * reach
}

/// The velocity estimate written back at the end of an update: `v` held
/// to `C_v` ([`hold_to_bound`]), the report told whether the bound held it
/// or the samples `(q₀, q₁)`, `τ` apart, moved past it
/// ([`moved_past_bound`]).
pub(crate) fn write_back<T: RealField + Copy, const N: usize, const K: usize>(
    v: &SVector<T, N>,
    params: &ObserverParams<T>,
    (q0, q1, tau): (&SVector<T, N>, &SVector<T, N>, T),
    report: &mut UpdateReport<T, N, K>,
) -> SVector<T, N> {
    let (v, held) = hold_to_bound(v, params.velocity_bound);
    report.at_velocity_bound |= held || moved_past_bound(params, (q0, q1), tau);
    v
}

/// `F̄ = F(t, q, sat(v))` needs `sat(v)` only when `F` depends on `v`
/// ([`Structure::forces_velocity_free`](crate::Structure::forces_velocity_free)).
pub(crate) fn saturate_for<M, T, const N: usize, const K: usize>(
    v: &SVector<T, N>,
    bound: T,
) -> SVector<T, N>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    if M::STRUCTURE.forces_velocity_free {
        *v
    } else {
        saturate(v, bound)
    }
}

/// `1 − e^{−x}` over `τ`, the injection gain that integrates
/// `ṽ' = −l_d ṽ` exactly over an interval of length `τ` (`→ l_d` as `τ → 0`).
pub(crate) fn injection_gain<T: RealField + Copy>(l_d: T, tau: T) -> T {
    -(-(l_d * tau)).exp_m1() / tau
}

/// The rounding of a normal speed `J_i w` read at the velocity `w`, per
/// unit of `|J_i|`: `64 ε |w|`. The contact rule's speed tests leave it
/// out of every class (approaching, separating, resting) they compare.
pub(crate) fn speed_roundoff<T: RealField + Copy, const N: usize>(w: &SVector<T, N>) -> T {
    T::default_epsilon() * nalgebra::convert(64.0) * w.norm()
}

/// `h > |r| b` shown without the square root of `|r|`: `true` only when it
/// holds with a margin of two (`h² > 4 |r|² b²`), far beyond rounding, so
/// that `false` leaves the exact test `h ≤ |r| b` to the caller. Sound for
/// every finite input (an overflowing `h²` is a gap far open; an
/// underflowing one fails this test and goes to the exact one).
fn clearly_open<T: RealField + Copy>(h: T, row_norm_squared: T, band: T) -> bool {
    let four: T = nalgebra::convert(4.0);
    h > T::zero() && h * h > four * row_norm_squared * band * band
}

/// The change of the kinetic energy `½ wᵀ M w` when the impulses `λ`
/// took the normal velocities `J w⁻ = jw_minus` to `J w⁺ = jw_plus`: `½
/// λᵀ (J w⁺ + J w⁻)` (since `M (w⁺ − w⁻) = Jᵀ λ`; no `M` needed).
fn energy_change<T: RealField + Copy, const K: usize>(
    lambda: &SVector<T, K>,
    jw_minus: &SVector<T, K>,
    jw_plus: &SVector<T, K>,
) -> T {
    nalgebra::convert::<f64, T>(0.5) * lambda.dot(&(jw_plus + jw_minus))
}

/// Whether Newton's law put kinetic energy in ([`energy_change`]): more
/// than `√ε` times its dissipation scale `½ Σ λ_i |J_i w⁻|`, far above
/// rounding.
///
/// Newton's law `J_i w⁺ = −e_i J_i w⁻` on one constraint, or with one `e`
/// on several (then it is Moreau's law, `w⁺ = w_p + e (w_p − w⁻)` with
/// `w_p` the projection of `w⁻` onto the tangent cone in the metric of
/// `M`), never gains energy. With unequal restitutions on several
/// constraints it can: a closed constraint that was separating takes an
/// impulse to hold the rebound of another, and where their gradients are
/// nearly opposite (the double pendulum's tip in the corner at its full
/// reach) the impulses grow like the inverse of the angle between them
/// and (38)'s estimate went from (1.4, −1.2) to (−8.6, 8.5) rad/s, about
/// 35 times its kinetic energy (`M` taken at the stretched arm), along
/// the direction the two constraints do not see.
fn gains_energy<T: RealField + Copy, const K: usize>(
    lambda: &SVector<T, K>,
    jw_minus: &SVector<T, K>,
    jw_plus: &SVector<T, K>,
) -> bool {
    let scale = nalgebra::convert::<f64, T>(0.5) * lambda.dot(&jw_minus.abs());
    energy_change(lambda, jw_minus, jw_plus) > T::default_epsilon().sqrt() * scale
}

/// Whether the impulses `λ` of a closure on several constraints took far
/// more kinetic energy than the constraints' normal speeds carry: more
/// than four times `Σ ½ (J_i w⁻)² / W_ii` over those approaching (what
/// each would take alone, plastically), `W = J M⁻¹ Jᵀ` the Delassus
/// matrix. For two constraints the ratio is at most `1/(1 − |c|)`, `c`
/// the cosine between their normals in the metric of `M`; four means
/// normals within 41° of opposite.
///
/// Normals nearly opposite close a thin wedge, and a velocity outside it
/// is projected to about nothing, whatever its part along the wedge: a
/// body driven into a converging slot jams, but the tip of the double
/// pendulum in the corner at its full reach, where the wall's normal and
/// the floor's are nearly opposite in joint space and the wedge turns
/// over as the arm passes its stretched configuration, does not; its
/// bounces alternate between the two and the arm swings on at 1.3 rad/s.
/// There the estimate went to zero. Resolved one at a time
/// ([`Interval::one_at_a_time`]), each impulse takes only its own
/// constraint's normal speed, as the alternating bounces do, and what
/// remains approaching is met again along the prediction.
fn opposed<T: RealField + Copy, const K: usize>(
    set: IndexSet<K>,
    lambda: &SVector<T, K>,
    jw_minus: &SVector<T, K>,
    jw_plus: &SVector<T, K>,
    delassus: &SMatrix<T, K, K>,
) -> bool {
    let half: T = nalgebra::convert(0.5);
    let four: T = nalgebra::convert(4.0);
    let taken = -energy_change(lambda, jw_minus, jw_plus);
    let mut carried = T::zero();
    for i in set {
        let jw = jw_minus[i].min(T::zero());
        if delassus[(i, i)] > T::zero() {
            carried += half * jw * jw / delassus[(i, i)];
        }
    }
    taken > four * carried
}

/// The constraint of `left` that `w` approaches fastest, the most
/// negative normal speed `J_i w < 0`, and that speed; `None` when none
/// approaches. The order in which [`Interval::one_at_a_time`] meets a set's
/// constraints, and in which the filter composes their saltations.
pub(crate) fn fastest_approach<T: RealField + Copy, const N: usize, const K: usize>(
    jac: &SMatrix<T, K, N>,
    w: &SVector<T, N>,
    left: IndexSet<K>,
) -> Option<(usize, T)> {
    left.iter()
        .map(|i| (i, jac.row(i).dot(&w.transpose())))
        .filter(|&(_, jw)| jw < T::zero())
        .min_by(|a, b| a.1.partial_cmp(&b.1).unwrap_or(core::cmp::Ordering::Equal))
}

/// Whether a constraint inside the band but still open (`h > 0`),
/// approached at the normal speed `J_i w = jw < 0`, is turned back by its
/// own normal acceleration `α = J_i a + J̇_i w > 0` before its gap is
/// deeper than the band `depth = |J_i| b`: the lowest gap ahead, `h −
/// jw²/(2α)`, is at least `−depth`.
///
/// Such a constraint is grazed, not hit: the free motion curves away from
/// it (a mass passing under a ceiling at the top of its arc; the tip of
/// the double pendulum swept along the floor to its full reach, where it
/// touches the wall at the corner with the two constraints' gradients
/// opposite). Closing it plastically, as a slow approach inside the band
/// otherwise is, would take its normal speed away, and where its gradient
/// is opposite to that of another closed constraint the two closures
/// together leave only their common tangent cone, a thin wedge that the
/// motion need not lie in: the double pendulum's estimate went from 0.7
/// rad/s to zero that way, at every pass of its tip through the corner.
/// Within the band the gap is not known better than the band anyway.
fn turns_within_band<T: RealField + Copy>(h: T, jw: T, alpha: T, depth: T) -> bool {
    let two: T = nalgebra::convert(2.0);
    h > T::zero() && jw < T::zero() && alpha > T::zero() && h - jw * jw / (two * alpha) >= -depth
}

/// What an observer remembers only to skip work: pure memos of functions
/// of their keys, so that a hit returns the very bits a recomputation
/// would (an observer's value, and its `==`, ignore them).
///
/// * the injection gain [`injection_gain`]`(l_d, τ)` of the last four
///   distinct `τ` (on a grid `t_k = kτ`, `t_{k+1} − t_k` takes a handful of
///   values a few ulps apart, and `l_d` is fixed per observer);
/// * for a model whose `M` the compiler proved constant
///   ([`Structure::mass_constant`](crate::Structure::mass_constant)), `M`
///   and its `L D Lᵀ` factor, reused while `M` evaluates to the same bits
///   (a parameter changed through `parameter_mut` gives another `M`, and a
///   new factorization);
/// * for a model whose `F` also depends on none of `t`, `q`, `v`, `u`,
///   the free acceleration `−M⁻¹F` with that factor, reused while `F`
///   evaluates to the same bits.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cache<T: RealField + Copy, const N: usize> {
    gains: [(T, T); 4],
    next: usize,
    mass: Option<(SMatrix<T, N, N>, Ldlt<T, N>)>,
    /// `(F, −M⁻¹F)` for the factor in `mass` (cleared with it).
    accel: Option<(SVector<T, N>, SVector<T, N>)>,
}

impl<T: RealField + Copy, const N: usize> Default for Cache<T, N> {
    fn default() -> Self {
        Self {
            // τ = 0 is never a key: an update's τ is positive
            gains: [(T::zero(), T::zero()); 4],
            next: 0,
            mass: None,
            accel: None,
        }
    }
}

impl<T: RealField + Copy, const N: usize> PartialEq for Cache<T, N> {
    /// Memos are not part of an observer's value.
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl<T: RealField + Copy, const N: usize> Cache<T, N> {
    /// [`injection_gain`]`(l_d, τ)`, recomputed only for a new `τ`.
    fn gain(&mut self, l_d: T, tau: T) -> T {
        if let Some(&(_, gain)) = self.gains.iter().find(|(key, _)| *key == tau) {
            return gain;
        }
        let gain = injection_gain(l_d, tau);
        self.gains[self.next] = (tau, gain);
        self.next = (self.next + 1) % self.gains.len();
        gain
    }

    /// For a model with a constant `M`, its factor: from the memo when `M`
    /// is unchanged, else factored now. `None` (the caller factors `M` where
    /// it evaluates it, and reports a failure there) for any other model or
    /// when `M` does not factor.
    #[inline]
    fn mass<M, const K: usize>(&mut self, model: &M, q: &SVector<T, N>) -> Option<Ldlt<T, N>>
    where
        M: Model<N, K, Scalar = T>,
    {
        if !M::STRUCTURE.mass_constant {
            return None;
        }
        let mass = model.mass(q);
        match self.mass {
            Some((key, chol)) if key == mass => Some(chol),
            _ => {
                self.accel = None;
                let chol = factor_mass(&mass).ok()?;
                self.mass = Some((mass, chol));
                Some(chol)
            }
        }
    }

    /// For a model whose `F` depends on none of `t`, `q`, `v`, `u`, with `M`
    /// factored as `chol` (constant, from [`mass`](Self::mass)): the free
    /// acceleration `−M⁻¹F`, the same bits at every point, from the memo
    /// while `F` is unchanged (`None` for another model, or a non-finite
    /// `F`).
    #[inline]
    fn constant_free<M, const K: usize>(
        &mut self,
        model: &M,
        u: &M::Input,
        t: T,
        q: &SVector<T, N>,
        chol: Ldlt<T, N>,
    ) -> Option<Free<T, N>>
    where
        M: Model<N, K, Scalar = T>,
    {
        let s = M::STRUCTURE;
        let constant = s.acceleration_state_free() && s.forces_time_free && s.forces_input_free;
        if !constant {
            return None;
        }
        let forces = model.forces(t, q, &SVector::zeros(), u);
        finite(&forces, "F").ok()?;
        let accel = match self.accel {
            Some((key, accel)) if key == forces => accel,
            _ => {
                let accel = -chol.solve(&forces);
                self.accel = Some((forces, accel));
                accel
            }
        };
        Some(Free { chol, accel })
    }
}

/// Rejects non-finite gaps `h` or Jacobian `J`.
#[inline(always)]
pub(crate) fn check_contact<T: RealField + Copy, const N: usize, const K: usize>(
    h: &SVector<T, K>,
    jac: &SMatrix<T, K, N>,
) -> Result<(), T> {
    finite(h, "h")?;
    finite(jac, "J")?;
    Ok(())
}

/// The mass matrix factored and the free acceleration `−M⁻¹ F̄` at one
/// point of the predicted motion.
#[derive(Clone, Copy)]
pub(crate) struct Free<T: RealField + Copy, const N: usize> {
    pub chol: Ldlt<T, N>,
    pub accel: SVector<T, N>,
}

/// A point `(s, p, w)` of the predicted motion, with `M` factored and the
/// free acceleration there.
#[derive(Clone, Copy)]
struct Point<'a, T: RealField + Copy, const N: usize> {
    /// Local time `s`.
    s: T,
    p: &'a SVector<T, N>,
    w: &'a SVector<T, N>,
    free: &'a Free<T, N>,
}

/// The impact law that gave `w⁺` at a [`Jump`] (the contact rule in
/// `runtime/src/observer/mod.rs`), so that the filter maps its covariance
/// through that law's saltation matrix rather than guess the law from
/// `w⁺`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Law<T> {
    /// Newton's law on the set, each constraint with its own restitution
    /// (the LCP's outcome).
    Newton,
    /// Moreau's law with the one restitution `e` (the least of the set),
    /// where Newton's would have put energy in ([`gains_energy`]): on the
    /// constraints that take an impulse, Newton's law with `e` on each.
    Moreau(T),
    /// The constraints met one at a time, the fastest approach first
    /// ([`Interval::one_at_a_time`]): opposed gradients ([`opposed`]), or
    /// no solution in floating point.
    OneAtATime,
}

/// Where Newton's law acts: local time `s`, the pre-impact velocity `w`,
/// and `J`, `M` (factored) evaluated there.
#[derive(Clone, Copy)]
struct Contact<'a, T: RealField + Copy, const N: usize, const K: usize> {
    s: T,
    w: &'a SVector<T, N>,
    jac: &'a SMatrix<T, K, N>,
    chol: &'a Ldlt<T, N>,
}

/// The end of a piece of predicted motion, and the contact impulse
/// `∫ λ ds` that acted along it.
struct Arc<T: RealField + Copy, const N: usize, const K: usize> {
    p: SVector<T, N>,
    w: SVector<T, N>,
    impulse: SVector<T, K>,
}

/// A piece of predicted motion of length `h`, with its cubic Hermite
/// interpolant (fourth-order accurate in position) for root finding.
struct Segment<T: RealField + Copy, const N: usize> {
    p0: SVector<T, N>,
    w0: SVector<T, N>,
    p1: SVector<T, N>,
    w1: SVector<T, N>,
    h: T,
}

impl<T: RealField + Copy, const N: usize> Segment<T, N> {
    /// Position at the fraction `x = σ/h ∈ [0, 1]` of the segment (no
    /// division: the root search works in fractions).
    fn position(&self, x: T) -> SVector<T, N> {
        let one = T::one();
        let two: T = nalgebra::convert(2.0);
        let three: T = nalgebra::convert(3.0);
        let (x2, x3) = (x * x, x * x * x);
        let h00 = two * x3 - three * x2 + one;
        let h10 = x3 - two * x2 + x;
        let h01 = -two * x3 + three * x2;
        let h11 = x3 - x2;
        self.p0 * h00 + self.w0 * (h10 * self.h) + self.p1 * h01 + self.w1 * (h11 * self.h)
    }

    /// Position and velocity at `σ ∈ [0, h]`.
    fn at(&self, sigma: T) -> (SVector<T, N>, SVector<T, N>) {
        let one = T::one();
        let two: T = nalgebra::convert(2.0);
        let three: T = nalgebra::convert(3.0);
        let x = sigma / self.h;
        let x2 = x * x;
        let p = self.position(x);
        let six: T = nalgebra::convert(6.0);
        let four: T = nalgebra::convert(4.0);
        let d00 = six * x2 - six * x;
        let d10 = three * x2 - four * x + one;
        let d11 = three * x2 - two * x;
        let v = (self.p0 - self.p1) * (d00 / self.h) + self.w0 * d10 + self.w1 * d11;
        (p, v)
    }
}

/// The root in `(0, 1)` of the cubic Hermite interpolant of a function
/// with values `f0 > 0 ≥ f1` and slopes `d0`, `d1` at `0` and `1`.
///
/// It starts at the root of the quadratic through `f0`, `d0` and `f1`
/// (the interpolant when the cubic coefficient vanishes: a gap quadratic
/// in `q` along a flight of constant acceleration, such as Example 1's),
/// by the form of the quadratic formula that does not cancel, or at the
/// secant point when that quadratic has no root in the bracket; then
/// Newton steps on the cubic, kept inside the bracket of its sign
/// (bisection when a step would leave it), until a step is under `tol`;
/// none when the cubic coefficient is at the rounding of the data.
fn hermite_root<T: RealField + Copy>((f0, d0): (T, T), (f1, d1): (T, T), tol: T) -> T {
    let (zero, one) = (T::zero(), T::one());
    let two: T = nalgebra::convert(2.0);
    let three: T = nalgebra::convert(3.0);
    let half: T = nalgebra::convert(0.5);
    // p(x) = f0 + d0 x + c2 x² + c3 x³
    let df = f1 - f0;
    let c2 = three * df - two * d0 - d1;
    let c3 = d0 + d1 - two * df;
    // the quadratic f0 + d0 x + a x², a = f1 − f0 − d0: its root in
    // (0, 1) is 2 f0 / (−d0 + √(d0² − 4 a f0)) (f0 > 0, so the
    // discriminant exceeds d0² when a < 0)
    let a = df - d0;
    let disc = d0 * d0 - two * two * a * f0;
    let root = two * f0 / (disc.max(zero).sqrt() - d0);
    let quadratic = disc >= zero && root > zero && root < one;
    // a cubic coefficient at the rounding of the data: the quadratic's
    // root is the interpolant's
    let rounding = T::default_epsilon() * nalgebra::convert(8.0);
    if quadratic && c3.abs() <= rounding * (f0.abs() + d0.abs() + f1.abs() + d1.abs()) {
        return root;
    }
    let (mut lo, mut hi) = (zero, one);
    let mut x = if quadratic { root } else { f0 / (f0 - f1) };
    for _ in 0..8 {
        let p = f0 + x * (d0 + x * (c2 + x * c3));
        if p == zero {
            break;
        }
        if p > zero {
            lo = x;
        } else {
            hi = x;
        }
        let dp = d0 + x * (two * c2 + x * three * c3);
        let step = p / dp;
        let next = x - step;
        // (a NaN step ends the search too)
        let converged = step.abs().partial_cmp(&tol) != Some(core::cmp::Ordering::Greater);
        x = if next > lo && next < hi {
            next
        } else if converged {
            x
        } else {
            (lo + hi) * half
        };
        if converged {
            break;
        }
    }
    x
}

/// How each constraint stands at the start of a piece of motion.
#[derive(Clone, Copy, Default)]
struct Classes<const K: usize> {
    /// Open (`h_i` above the band): watched for a crossing.
    free: IndexSet<K>,
    /// The closed constraints an impact's Newton's law acts on (within
    /// the band, or just reached): all but those that have just bounced
    /// and depart faster than the resting speed ([`Interval::classify`]).
    contact: IndexSet<K>,
    /// Closed and approaching: Newton's law now.
    approaching: IndexSet<K>,
    /// Approaching faster than the resting speed: `ê_i` applies.
    elastic: IndexSet<K>,
    /// Closed, normal speed within the resting speed: persistent contact.
    sliding: IndexSet<K>,
    /// Those of `sliding` that rest on their constraint, pushed onto it or
    /// not: not grazed, and not accelerated off it within the interval
    /// faster than the estimate's velocity noise (`α_i τ ≤ g_i u_v`, with
    /// `α_i` the free normal acceleration, positive away). Glued bodies
    /// in free flight are: no force holds them together, and none pulls
    /// them apart.
    resting: IndexSet<K>,
    /// Closed and separating: watched for a return.
    departing: IndexSet<K>,
}

/// How the prediction came to a point, as far as the contact rule there
/// needs it.
#[derive(Clone, Copy, Default)]
struct Path<const K: usize> {
    /// Reached by a root at this point: closed whatever the sign of their
    /// gap.
    touched: IndexSet<K>,
    /// Held along the piece that led here: closed as well.
    held: IndexSet<K>,
    /// Those of `held` that their contact force pressed on along that
    /// piece: contacts that may hover a hair above their constraint,
    /// unlike bodies glued with no force (`Interval::unheld`).
    pressed: IndexSet<K>,
    /// Given an elastic impulse (a bounce) earlier in the interval, or an
    /// impulse in the last update's interval: constraints that may have
    /// just bounced.
    bounced: IndexSet<K>,
}

/// What the search along a piece of motion found first: these
/// constraints close (or, for a departing one that never opened, turn
/// back) at `at`, relative to the piece's start.
struct Crossing<T, const K: usize> {
    at: T,
    set: IndexSet<K>,
}

/// One sampling interval: the model, the two measurements around it and
/// the settings.
pub(crate) struct Interval<'a, M, T, const N: usize, const K: usize>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    pub model: &'a M,
    pub u: &'a M::Input,
    pub params: &'a ObserverParams<T>,
    pub lcp: &'a Lcp<T>,
    /// `t_k`.
    pub t0: T,
    /// `τ = t_{k+1} − t_k`.
    pub tau: T,
    /// The measured `q_k`.
    pub q0: SVector<T, N>,
    /// The measured `q_{k+1}`.
    pub q1: SVector<T, N>,
    /// The observer's restitution `ê`.
    pub restitution: SVector<T, K>,
    /// The injection gain `(1 − e^{−l_d τ}) / τ` of this interval
    /// ([`injection_gain`], computed once per update).
    pub gain: T,
    /// How well the estimate knows the velocity: the correction the last
    /// update's innovation made, `|d_k| (1 − e^{−l_d τ_k}) / τ_k` (0 before
    /// the first update). A closed constraint approaching slower than that
    /// cannot be told from a resting one. The filter sets it to its own
    /// velocity noise `n_σ σ_v` with exact samples and to zero under
    /// noise, where that noise is already the resting speed's `ν`.
    pub uncertainty: T,
    /// The contact rule's band `b_i` of each constraint, in units of `q`:
    /// [`ObserverParams::contact_band`] for every constraint (set by
    /// [`begin`](Self::begin)); the filter sets each from the uncertainty
    /// of that constraint's own gap.
    pub bands: SVector<T, K>,
    /// The velocity noise `ν` of the contact rule: for the observers
    /// `n_σ √2 σ (1 − e^{−l_d τ})/τ`, the injection passing the noise of
    /// two samples with the gain of one interval (set by
    /// [`begin`](Self::begin)); the filter sets it from its covariance.
    pub noise_speed: T,
    /// The factor of `M` when the model's `M` is constant (the same at
    /// every point of the interval): one factorization, or none, per update.
    pub mass: Option<Ldlt<T, N>>,
    /// `M` factored and the free acceleration `−M⁻¹F`, the same at every
    /// point, for a model whose `M` is constant and whose `F` depends on
    /// none of `t`, `q`, `v`, `u` ([`Structure`](crate::Structure)): one
    /// evaluation of `F` and one solve per update (`None` for any other
    /// model, or when `F` is not finite: the stages then evaluate it and
    /// report the failure where they always did).
    pub constant: Option<Free<T, N>>,
    /// Whether a closed constraint separating slower than its resting
    /// speed but faster than that speed without the band's fall term
    /// `√(4 A_i g_i b)` is departing (free, watched for a return) instead
    /// of a persistent contact (`false` from [`begin`](Self::begin)). The
    /// fall term bounds how fast a sample that noise put outside the band
    /// falls back in. A separation is no such fall, and a held contact
    /// starts each piece settled ([`settled`](Self::settled)): held, a
    /// real bounce would lose the whole of its normal speed. (Before the
    /// settle it kept that speed over the whole interval instead of
    /// losing `A_i τ` of it.) The same rule when `σ = 0` (the band is
    /// then `d` alone).
    /// From [`Memory`]: set by the observers (36) and (38), not by the
    /// filter (whose band is its own position deviation, far below `σ`).
    pub release_departures: bool,
    /// The constraints given an impulse in the last update's interval
    /// (from [`Memory`]): with the bounces of this one, those that may
    /// have just bounced ([`Path::bounced`]).
    pub last_impacted: IndexSet<K>,
}

/// What an observer remembers between updates, as the interval needs it.
pub(crate) struct Memory<'a, T: RealField + Copy, const N: usize, const K: usize> {
    pub params: &'a ObserverParams<T>,
    pub lcp: &'a Lcp<T>,
    /// `t_k` and the measured `q_k`.
    pub t: T,
    pub q: SVector<T, N>,
    /// The observer's own `ê`, if it has one.
    pub restitution: Option<&'a SVector<T, K>>,
    /// The last update's report.
    pub report: &'a UpdateReport<T, N, K>,
    /// [`Interval::release_departures`].
    pub release_departures: bool,
}

impl<'a, M, T, const N: usize, const K: usize> Interval<'a, M, T, N, K>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    /// Checks one update's data (the measurement `q` at `t`, the input
    /// `u`, the model's parameters and restitution) and opens the interval
    /// `[t_k, t]` with an empty report; `cache` holds the observer's memos.
    #[inline]
    pub fn begin(
        model: &'a M,
        u: &'a M::Input,
        memory: Memory<'a, T, N, K>,
        cache: &mut Cache<T, N>,
        t: T,
        q: &SVector<T, N>,
    ) -> Result<(Self, UpdateReport<T, N, K>), T> {
        let tau = check_update(model, memory.t, t, q, u)?;
        let restitution = match memory.restitution {
            Some(own) => *own,
            None => model.restitution(),
        };
        validate::restitution(&restitution)?;
        let gain = cache.gain(memory.params.l_d, tau);
        let mass = cache.mass::<M, K>(model, &memory.q);
        let constant =
            mass.and_then(|chol| cache.constant_free::<M, K>(model, u, memory.t, &memory.q, chol));
        let interval = Interval {
            model,
            u,
            params: memory.params,
            lcp: memory.lcp,
            t0: memory.t,
            tau,
            q0: memory.q,
            q1: *q,
            restitution,
            uncertainty: memory.report.uncertainty(),
            bands: SVector::repeat(memory.params.contact_band()),
            noise_speed: memory.params.noise_sigmas
                * memory.params.noise
                * nalgebra::convert::<f64, T>(core::f64::consts::SQRT_2)
                * gain,
            gain,
            mass,
            constant,
            release_departures: memory.release_departures,
            last_impacted: memory.report.impacted,
        };
        let mut report = UpdateReport::new(t, tau);
        report.gain = gain;
        Ok((interval, report))
    }
}

impl<M, T, const N: usize, const K: usize> Interval<'_, M, T, N, K>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    /// Newton's law at `at` ([`Contact`]), `ê` on `elastic` and `0` on
    /// the rest of `set`: returns `w⁺`. A set met `together` takes one law
    /// however opposed its gradients ([`checked`](Self::checked)).
    fn newton(
        &self,
        at: &Contact<'_, T, N, K>,
        (set, elastic): (IndexSet<K>, IndexSet<K>),
        together: bool,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<(SVector<T, N>, Law<T>), T> {
        let Contact { s, w, jac, chol } = *at;
        let jw = jac * w;
        // the restitution each constraint of the set takes: `ê_i` if elastic
        let mut e = SVector::<T, K>::zeros();
        for i in elastic {
            e[i] = self.restitution[i];
        }
        let before = report.impulses;
        let (dv, law) = match self.impulse(jac, chol, w, &e.component_mul(&jw), set, report) {
            Ok(dv) if set.len() > 1 => {
                self.checked(at, (set, &e, &jw), (before, together), dv, report)?
            }
            Ok(dv) => (dv, Law::Newton),
            // gradients nearly dependent (see `opposed`) can leave the
            // problem without a solution in floating point
            Err(_) if set.len() > 1 => {
                let minv_jt = chol.solve(&jac.transpose());
                let dv = self.one_at_a_time(at, &minv_jt, set, &e, report);
                (dv, Law::OneAtATime)
            }
            Err(e) => return Err(e),
        };
        // an impact when an elastic (fast) approach received an impulse; a
        // plastic closure of a resting contact is a contact
        if elastic.iter().any(|i| report.impulses[i] > before[i]) {
            report.impacts += 1;
            if report.first_impact.is_none() {
                report.first_impact = Some(self.t0 + s);
            }
        } else {
            report.contacts = report.contacts.union(set);
        }
        Ok((w + dv, law))
    }

    /// Newton's law on several constraints (`set`, restitutions `e`,
    /// normal speeds `jw = J w⁻`), its solution `dv = w⁺ − w` checked: where it put energy in
    /// ([`gains_energy`]), Moreau's law with the least restitution of the
    /// set, `w⁺ = w_p + e (w_p − w)` with `w_p` the plastic projection,
    /// takes its place; where the closure is of nearly opposite
    /// constraints ([`opposed`]), the constraints are met one at a time
    /// ([`one_at_a_time`](Self::one_at_a_time)), unless the set is met
    /// `together`: a fast impact beside a contact held along the piece
    /// before it and not separating from it, or a set widened by a constraint its impulse turned
    /// back (`Interval::meet`), which a time-stepping plant's step meets
    /// with one law. The impulses recorded since `before` are those of
    /// the law kept, which is returned with `dv`.
    fn checked(
        &self,
        at: &Contact<'_, T, N, K>,
        (set, e, jw): (IndexSet<K>, &SVector<T, K>, &SVector<T, K>),
        (before, together): (SVector<T, K>, bool),
        mut dv: SVector<T, N>,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<(SVector<T, N>, Law<T>), T> {
        let Contact { w, jac, chol, .. } = *at;
        let mut law = Law::Newton;
        if gains_energy(&(report.impulses - before), jw, &(jac * (w + dv))) {
            let least = set.iter().fold(T::one(), |least, i| least.min(e[i]));
            report.impulses = before;
            let plastic = self.impulse(jac, chol, w, &SVector::zeros(), set, report)?;
            let scale = T::one() + least;
            report.impulses = before + (report.impulses - before) * scale;
            dv = plastic * scale;
            law = Law::Moreau(least);
        }
        let minv_jt = chol.solve(&jac.transpose());
        let lambda = report.impulses - before;
        if !together && opposed(set, &lambda, jw, &(jac * (w + dv)), &(jac * minv_jt)) {
            report.impulses = before;
            dv = self.one_at_a_time(at, &minv_jt, set, e, report);
            law = Law::OneAtATime;
        }
        Ok((dv, law))
    }

    /// Newton's law on the constraints of `set` (restitutions `e`) one at
    /// a time, the fastest approach first, each once, on the velocity the
    /// ones before left (see [`opposed`]): returns `w⁺ − w` and records the
    /// impulses.
    fn one_at_a_time(
        &self,
        at: &Contact<'_, T, N, K>,
        minv_jt: &SMatrix<T, N, K>,
        set: IndexSet<K>,
        e: &SVector<T, K>,
        report: &mut UpdateReport<T, N, K>,
    ) -> SVector<T, N> {
        let mut dv = SVector::<T, N>::zeros();
        let mut left = set;
        while let Some((i, jw)) = fastest_approach(at.jac, &(at.w + dv), left) {
            left.remove(i);
            let delassus = at.jac.row(i).dot(&minv_jt.column(i).transpose());
            let lambda = -(T::one() + e[i]) * jw / delassus;
            if lambda > T::zero() && lambda.is_finite() {
                dv += minv_jt.column(i) * lambda;
                report.impulses[i] += lambda;
                report.impacted.insert(i);
            }
        }
        dv
    }

    /// Solves `0 ≤ λ ⊥ J (w_free + M⁻¹Jᵀλ) + approach ≥ 0` on `set` and
    /// returns `M⁻¹Jᵀλ`; records `λ` as impulses.
    pub fn impulse(
        &self,
        jac: &SMatrix<T, K, N>,
        chol: &Ldlt<T, N>,
        w_free: &SVector<T, N>,
        approach: &SVector<T, K>,
        set: IndexSet<K>,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<SVector<T, N>, T> {
        if set.is_empty() {
            return Ok(SVector::zeros());
        }
        let minv_jt = chol.solve(&jac.transpose());
        let delassus = jac * minv_jt;
        let half: T = nalgebra::convert(0.5);
        let delassus = (delassus + delassus.transpose()) * half;
        let b = jac * w_free + approach;
        let solution = self.lcp.solve(&delassus, &b, set)?;
        report.lcp_solves += 1;
        report.lcp_trials += solution.trials;
        report.lcp_residual = report.lcp_residual.max(solution.residual);
        report.active = report.active.union(set);
        for i in set {
            if solution.lambda[i] > T::zero() {
                report.impacted.insert(i);
            }
        }
        report.impulses += solution.lambda;
        Ok(minv_jt * solution.lambda)
    }

    /// `M` factored and `−M⁻¹ F̄(t_k + s, p, w)` (the interval's
    /// [`constant`](Self::constant) when it has one).
    pub fn free(
        &self,
        s: T,
        p: &SVector<T, N>,
        w: &SVector<T, N>,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<Free<T, N>, T> {
        report.evaluations += 1;
        if let Some(free) = self.constant {
            return Ok(free);
        }
        let w_bar = saturate_for::<M, T, N, K>(w, self.params.velocity_bound);
        let (chol, forces) = self.dynamics(self.t0 + s, p, &w_bar)?;
        let accel = -chol.solve(&forces);
        Ok(Free { chol, accel })
    }

    /// `M(p)` factored and `F(t, p, w)`, checked: `M` from the interval's
    /// factor when it is constant, evaluated with `F` otherwise.
    pub fn dynamics(
        &self,
        t: T,
        p: &SVector<T, N>,
        w: &SVector<T, N>,
    ) -> Result<(Ldlt<T, N>, SVector<T, N>), T> {
        if let Some(chol) = self.mass {
            let forces = self.model.forces(t, p, w, self.u);
            finite(&forces, "F")?;
            return Ok((chol, forces));
        }
        let (mass, forces) = self.model.dynamics(t, p, w, self.u);
        finite(&forces, "F")?;
        Ok((factor_mass(&mass)?, forces))
    }

    /// `(h(p), J(p))`, checked.
    pub fn contact(&self, p: &SVector<T, N>) -> Result<(SVector<T, K>, SMatrix<T, K, N>), T> {
        let (h, jac) = self.model.contact(p);
        check_contact(&h, &jac)?;
        Ok((h, jac))
    }

    /// `J̇ w = (∂J/∂q · w) w` by a central difference along `w`:
    /// `|w| (J(p + δŵ) − J(p − δŵ)) w / (2δ)` with `δ = ε^⅓ max(1, |p|∞)`,
    /// the step that balances truncation `O(δ²)` and round-off `O(ε/δ)`
    /// (both about `ε^⅔ ≈ 4e-11` relative in `f64`; exact for the gaps of
    /// degree two, whose `J` is affine).
    fn jacobian_rate(&self, p: &SVector<T, N>, w: &SVector<T, N>) -> Result<SVector<T, K>, T> {
        let n = w.norm();
        if n == T::zero() {
            return Ok(SVector::zeros());
        }
        let delta = crate::linalg::cbrt_epsilon::<T>() * p.amax().max(T::one());
        let d = w / n;
        let plus = self.model.gap_jacobian(&(p + d * delta));
        let minus = self.model.gap_jacobian(&(p - d * delta));
        finite(&plus, "J")?;
        finite(&minus, "J")?;
        Ok((plus - minus) * w * (n / (delta + delta)))
    }

    /// The velocity `w` with the separating normal speed of the held
    /// constraints that push taken out, in the metric of the mass matrix:
    /// with `S` the constraints of `sliding` that `w` leaves (`J_i w > 0`)
    /// while their acceleration-level law pushes (`lambda_i > 0`, the
    /// multipliers at `(p, w)`: the piece's first Runge–Kutta stage),
    /// `w − M⁻¹J_Sᵀ (J_S M⁻¹J_Sᵀ)⁻¹ J_S w`; `None` when there is no such
    /// constraint, when their rows are dependent, or when rounding made
    /// the result's kinetic energy larger than `w`'s (the projection
    /// cannot, in exact arithmetic).
    ///
    /// Why: the contact rule holds a closed constraint that separates
    /// slower than its resting speed (it cannot tell that from noise on a
    /// resting contact), and the acceleration-level law then pushes with
    /// `λ_i > 0` on a body that moves away from the constraint at
    /// `J_i w`: the force does the work `λ_i J_i w` and the estimate gains
    /// energy (Example 1 sliding at 5.8 m/s on the curved floor, the mass
    /// hopping at 0.04 m/s: the contact force of about 60 m/s² put 1.2e-3
    /// J/kg into the filter's estimate in one millisecond, a tangential
    /// speed 2.4e-4 m/s too high, which the slide then kept for most of a
    /// second; `tests/kalman.rs`,
    /// `a_held_contact_does_no_work_on_a_separating_estimate`). Taken out
    /// first, as a plastic closure takes out an approach, the held motion
    /// stays on the contact and the force does no work; the kinetic
    /// energy drops by `½ (J_S w)ᵀ (J_S M⁻¹J_Sᵀ)⁻¹ J_S w` and never rises.
    /// The filter projects its state onto the contacts that push at the
    /// end of the piece in the same metric, so the normal speed taken out
    /// here is the one it would have taken out there.
    ///
    /// For the observers (36) and (38) the same force broke the
    /// monotonicity their guarantee rests on. Holding `S` is the rule's
    /// judgement that the plant slides on it, `J_S v = 0`; the error's
    /// energy `½ ṽᵀMṽ` then changes at the rate `(J_S ṽ)ᵀ(λ − λ̂) + …`
    /// with `J_S ṽ = −J_S v̂`: the plant's force takes energy out, the
    /// estimate's puts `(J_S v̂)ᵀλ̂ > 0` in. The paper's `η̂` comes from the
    /// normal cone at the estimate's velocity, which is `{0}` along a
    /// constraint the velocity leaves, so that term is not in (38). The
    /// projection is onto `{J_S w = 0}`, a subspace that holds `v`, in the
    /// metric of `M`, so `|P v̂ − v|_M = |P ṽ|_M ≤ |ṽ|_M`: the settle never
    /// raises the error's energy. What the held force had kept instead was
    /// the separating part of each injection's normal noise: sliding on
    /// Example 1 at `σ = 1e-6`, the normal error had a median of 1.3 ×
    /// `√2 l_d σ`, the whole of (38)'s excess over its noise floor
    /// (`tests/observer.rs`, `noise_sets_the_error_level`,
    /// `a_held_contact_takes_no_separating_speed_into_the_slide`). A held constraint
    /// with no force on it (a grazed wall, a resting contact the motion
    /// leaves) does no work and keeps its speed: at the double pendulum's
    /// full reach, where the wall's and the floor's gradients are nearly
    /// opposite, taking the grazed wall's out with the floor's took the
    /// estimate to rest (`the_double_pendulum_passes_the_corner_at_its_full_reach`).
    fn settled(
        &self,
        at: &Point<'_, T, N>,
        jac: &SMatrix<T, K, N>,
        sliding: IndexSet<K>,
        lambda: &SVector<T, K>,
    ) -> Option<SVector<T, N>> {
        let w = at.w;
        let mut set = IndexSet::<K>::EMPTY;
        let mut speed = SVector::<T, K>::zeros();
        for i in sliding.iter().filter(|&i| lambda[i] > T::zero()) {
            let jw = jac.row(i).dot(&w.transpose());
            if jw > T::zero() {
                set.insert(i);
                speed[i] = jw;
            }
        }
        if set.is_empty() {
            return None;
        }
        let OnSet {
            minv_jt, delassus, ..
        } = OnSet::new(jac, &at.free.chol, set);
        let settled = w - minv_jt * delassus?.solve(&speed);
        // the projection cannot raise the kinetic energy; where rounding
        // in a nearly singular `J_S M⁻¹J_Sᵀ` made it, keep `w` (the
        // energies from the factor of `M` the point already has)
        let energy = |v: &SVector<T, N>| at.free.chol.quadratic_form(v);
        let slack = T::one() + T::default_epsilon() * nalgebra::convert(64.0);
        (energy(&settled) <= energy(w) * slack).then_some(settled)
    }

    /// The acceleration with the persistent contacts `sliding` held by
    /// their acceleration-level law `0 ≤ λ ⊥ J a + J̇ w ≥ 0`,
    /// `a = −M⁻¹F̄ + M⁻¹Jᵀλ`; returns `(a, λ)`.
    fn constrained(
        &self,
        p: &SVector<T, N>,
        w: &SVector<T, N>,
        sliding: IndexSet<K>,
        free: &Free<T, N>,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<(SVector<T, N>, SVector<T, K>), T> {
        if sliding.is_empty() {
            return Ok((free.accel, SVector::zeros()));
        }
        let jac = self.model.gap_jacobian(p);
        finite(&jac, "J")?;
        let rate = self.jacobian_rate(p, w)?;
        let minv_jt = free.chol.solve(&jac.transpose());
        let delassus = jac * minv_jt;
        let half: T = nalgebra::convert(0.5);
        let delassus = (delassus + delassus.transpose()) * half;
        let b = jac * free.accel + rate;
        let solution = self.lcp.solve(&delassus, &b, sliding)?;
        report.lcp_solves += 1;
        report.lcp_trials += solution.trials;
        report.lcp_residual = report.lcp_residual.max(solution.residual);
        report.active = report.active.union(sliding);
        Ok((free.accel + minv_jt * solution.lambda, solution.lambda))
    }

    /// The motion over `[s0, s0 + h]` from `start`, with the persistent
    /// contacts `sliding` held, `first` the first stage at `start`
    /// ([`rk4`](Self::rk4)). In free flight under a
    /// constant acceleration `a` (the interval's `constant`) the four
    /// stages all take `a`, and the same arithmetic is done here, inlined,
    /// without the calls for the stages (the same bits: `tests/memo.rs`).
    #[inline(always)]
    fn advance(
        &self,
        start: &Point<'_, T, N>,
        h: T,
        sliding: IndexSet<K>,
        first: &(SVector<T, N>, SVector<T, K>),
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<Arc<T, N, K>, T> {
        if !self.one_step_exact(sliding) {
            return self.rk4(start, h, sliding, first, report);
        }
        // the three further stages' points, served by the memo
        report.evaluations += 3;
        let (p0, w0, a) = (start.p, start.w, start.free.accel);
        let half = h * nalgebra::convert::<f64, T>(0.5);
        let two: T = nalgebra::convert(2.0);
        let sixth = h / nalgebra::convert(6.0);
        let w2 = w0 + a * half;
        let w4 = w0 + a * h;
        Ok(Arc {
            p: p0 + (w0 + w2 * two + w2 * two + w4) * sixth,
            w: w0 + (a + a * two + a * two + a) * sixth,
            impulse: SVector::zeros(),
        })
    }

    /// Whether one Runge–Kutta step over any length is exact: a constant
    /// acceleration (the interval's `constant`) and no contact held.
    fn one_step_exact(&self, sliding: IndexSet<K>) -> bool {
        sliding.is_empty() && self.constant.is_some()
    }

    /// The length of the next Runge–Kutta step when `left` of the interval
    /// remains with the contacts `sliding` held: `left` itself where one
    /// step is exact ([`one_step_exact`](Self::one_step_exact)) or up to
    /// one and a half times the longest step
    /// ([`ObserverParams::max_step`]), else `left` split evenly into steps
    /// of at most it (the step after then splits what is left again, to
    /// the same length).
    pub(crate) fn piece(&self, left: T, sliding: IndexSet<K>) -> T {
        if self.one_step_exact(sliding) {
            return left;
        }
        let max = self.params.max_step;
        let limit = max * nalgebra::convert(1.5);
        if left <= limit {
            return left;
        }
        left / (left / max).ceil()
    }

    /// Classical fourth-order Runge–Kutta for `p' = w`, `w' = a(s, p, w)`
    /// over `[s0, s0 + h]` from `start`, with the persistent contacts
    /// `sliding` held; `stage` is the acceleration and the multipliers at
    /// `start` ([`constrained`](Self::constrained)), computed once by the
    /// caller for every piece that starts there.
    fn rk4(
        &self,
        start: &Point<'_, T, N>,
        h: T,
        sliding: IndexSet<K>,
        stage: &(SVector<T, N>, SVector<T, K>),
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<Arc<T, N, K>, T> {
        let Point {
            s: s0,
            p: p0,
            w: w0,
            free: first,
        } = *start;
        let half = h * nalgebra::convert::<f64, T>(0.5);
        let two: T = nalgebra::convert(2.0);
        let sixth = h / nalgebra::convert(6.0);
        if sliding.is_empty() {
            // free flight: the free accelerations, no contact force
            let k1 = first.accel;
            let (p2, w2) = (p0 + w0 * half, w0 + k1 * half);
            let k2 = self.free(s0 + half, &p2, &w2, report)?.accel;
            let (p3, w3) = (p0 + w2 * half, w0 + k2 * half);
            let k3 = self.free(s0 + half, &p3, &w3, report)?.accel;
            let (p4, w4) = (p0 + w3 * h, w0 + k3 * h);
            let k4 = self.free(s0 + h, &p4, &w4, report)?.accel;
            return Ok(Arc {
                p: p0 + (w0 + w2 * two + w3 * two + w4) * sixth,
                w: w0 + (k1 + k2 * two + k3 * two + k4) * sixth,
                impulse: SVector::zeros(),
            });
        }
        let (k1, l1) = *stage;
        let (p2, w2) = (p0 + w0 * half, w0 + k1 * half);
        let f2 = self.free(s0 + half, &p2, &w2, report)?;
        let (k2, l2) = self.constrained(&p2, &w2, sliding, &f2, report)?;
        let (p3, w3) = (p0 + w2 * half, w0 + k2 * half);
        let f3 = self.free(s0 + half, &p3, &w3, report)?;
        let (k3, l3) = self.constrained(&p3, &w3, sliding, &f3, report)?;
        let (p4, w4) = (p0 + w3 * h, w0 + k3 * h);
        let f4 = self.free(s0 + h, &p4, &w4, report)?;
        let (k4, l4) = self.constrained(&p4, &w4, sliding, &f4, report)?;
        Ok(Arc {
            p: p0 + (w0 + w2 * two + w3 * two + w4) * sixth,
            w: w0 + (k1 + k2 * two + k3 * two + k4) * sixth,
            impulse: (l1 + l2 * two + l3 * two + l4) * sixth,
        })
    }

    /// Sorts the constraints at a point `(p, w)` of the predicted motion
    /// (the contact rule of the module docs).
    ///
    /// With `g_i = |∇h_i|`, the band `b_i = g_i (d + n_σ σ)`, the normal
    /// acceleration of the free motion relative to the constraint
    /// `A_i = |J_i a + J̇_i w|` and the velocity noise `ν`
    /// ([`noise_speed`](Self::noise_speed); `n_σ √2 σ φ_l` for the observers),
    /// the resting speed is
    ///
    /// `v_rest,i = ρ τ A_i + √(4 A_i b_i) + g_i ν + 64 ε g_i |w|`:
    ///
    /// what the forces build over `ρτ`, what a fall through twice the band
    /// builds (a sample that noise puts outside the band falls back in that
    /// fast, and is no impact), the noise of the estimate, round-off. A
    /// closed constraint approaching faster than that while its gap is
    /// still positive is left open, so that the root of its gap along the
    /// predicted motion times the impact. A closed constraint gets its
    /// restitution only when it approaches faster than
    /// `v_rest,i + g_i u`, with `u` the estimate's [`uncertainty`](Self::uncertainty):
    /// slower, it is closed plastically.
    ///
    /// Constraints `touched` (reached by a root here) and `held` (held
    /// along the piece that led here) are closed whatever the sign of
    /// their gap: a held contact keeps the normal speed the rule took for
    /// rest (a separating one is taken out where the contact pushes,
    /// [`settled`](Self::settled), not where it does not), and drifts by it
    /// (on exact samples of the billiard, 8e-9 m in 0.8 ms), so that a
    /// band of zero would read it open at the next event and resolve an
    /// impact on another constraint without it.
    ///
    /// A closed constraint that may have just bounced (an elastic impulse
    /// earlier in the interval, or any impulse in the last update's:
    /// [`Path::bounced`]), separating faster than `v_rest,i + g_i u` (the
    /// speed an approach needs for its restitution), and not held takes
    /// no part in Newton's law on the others: it has just
    /// bounced, and if their impulse turns it back it is met on its own
    /// at its root, with its own restitution, as the plant meets it. Under
    /// noise the band is about `σ` wide, and a ball that bounced off the
    /// billiard's floor and reached a wall 0.14 ms later (2e-5 m up) still
    /// had the floor within it: the floor then took a plastic share of the
    /// wall's impulse, and both estimators left the corner 0.13 m/s off,
    /// where the plant bounced floor, wall, floor
    /// (`tests/kalman.rs`, `a_wall_just_left_takes_no_part_in_the_impact_on_the_next`).
    /// Any other stays in the law's set: a persistent contact whose
    /// estimate lifts off by noise (for (38), between its `depart` and
    /// `v_rest,i`), or a pair that travels together (the three balls'
    /// glued pair, its estimate of `v₂ − v₃` still converging), which must
    /// not come apart on its estimate's error any more than bounce on it
    /// (`tests/observer.rs`, `glued_balls_hit_the_wall_together_in_both_observers`).
    #[inline(always)]
    fn classify(
        &self,
        at: &Point<'_, T, N>,
        (h, jac): (&SVector<T, K>, &SMatrix<T, K, N>),
        resolved: IndexSet<K>,
        path: Path<K>,
    ) -> Result<Classes<K>, T> {
        let Path {
            touched,
            held,
            bounced,
            ..
        } = path;
        let (p, w, accel) = (at.p, at.w, &at.free.accel);
        let mut c = Classes::default();
        let noise_speed = self.noise_speed;
        let roundoff = speed_roundoff(w);
        let four: T = nalgebra::convert(4.0);
        let mut closed = IndexSet::<K>::EMPTY;
        let kept = touched.union(held);
        for i in 0..K {
            let row = jac.row(i);
            if !kept.contains(i) && clearly_open(h[i], row.norm_squared(), self.bands[i]) {
                c.free.insert(i);
                continue;
            }
            let g = row.norm();
            if h[i] <= g * self.bands[i] || kept.contains(i) {
                closed.insert(i);
            } else {
                c.free.insert(i);
            }
        }
        if closed.is_empty() {
            return Ok(c);
        }
        let rate = self.jacobian_rate(p, w)?;
        // the closed constraints' normal speeds `J_i w` and signed normal
        // accelerations `J_i a + J̇_i w` of the free motion
        let (mut speed, mut alpha) = (SVector::<T, K>::zeros(), SVector::<T, K>::zeros());
        for i in closed {
            speed[i] = jac.row(i).dot(&w.transpose());
            alpha[i] = jac.row(i).dot(&accel.transpose()) + rate[i];
        }
        let grazed = self.grazed(at, (h, jac, &rate), (&speed, &alpha), (closed, touched))?;
        for i in closed {
            let row = jac.row(i);
            let g = row.norm();
            let jw = speed[i];
            let normal_accel = alpha[i].abs();
            if grazed.contains(i) {
                // no impact and no closure: held at acceleration level,
                // where the law gives it no force
                c.sliding.insert(i);
                continue;
            }
            let floor = roundoff * g;
            let rest = self.params.rest_factor * self.tau * normal_accel
                + (four * normal_accel * g * self.bands[i]).sqrt()
                + g * noise_speed
                + floor;
            // separating: see `release_departures`
            let depart = if self.release_departures {
                self.params.rest_factor * self.tau * normal_accel
                    + (four * normal_accel * g * self.params.contact_distance).sqrt()
                    + g * noise_speed
                    + floor
            } else {
                rest
            };
            if jw < -rest && h[i] > T::zero() && !touched.contains(i) {
                // a fast approach still outside: its root along the
                // predicted motion says when it closes (the band only
                // says that it is near)
                c.free.insert(i);
                continue;
            }
            if jw < -floor && !resolved.contains(i) {
                c.contact.insert(i);
                c.approaching.insert(i);
                // restitution only for an approach the estimate can tell
                // from rest: a closed pair that travels together (glued
                // balls) must not bounce on the round-off of its estimate,
                // or a later simultaneous impact is resolved as a sequence
                if jw < -(rest + g * self.uncertainty) {
                    c.elastic.insert(i);
                }
            } else if jw <= depart {
                c.contact.insert(i);
                c.sliding.insert(i);
                // resting: the free motion does not leave it within the
                // interval faster than the estimate's velocity noise
                if alpha[i] * self.tau <= g * noise_speed + floor {
                    c.resting.insert(i);
                }
            } else {
                if !bounced.contains(i) || held.contains(i) || jw <= rest + g * self.uncertainty {
                    c.contact.insert(i);
                }
                c.departing.insert(i);
            }
        }
        Ok(c)
    }

    /// The closed constraints (`closed`, less those just `touched` by a
    /// root) that the motion grazes: each approached (`J_i w < 0`, its
    /// `speed`) but turned back before its gap is more than the band deep
    /// ([`turns_within_band`]) by its normal acceleration, first under the
    /// free motion (`alpha`, with the rates `J̇_i w`) and then, where other
    /// constraints are closed, under the motion with all of them held at
    /// acceleration level, in which it must take no force. (A ball wedged
    /// in a cusp under gravity is pulled away from one wall by the free
    /// motion, but pressed into it once the other wall holds.)
    fn grazed(
        &self,
        at: &Point<'_, T, N>,
        (h, jac, rate): (&SVector<T, K>, &SMatrix<T, K, N>, &SVector<T, K>),
        (speed, alpha): (&SVector<T, K>, &SVector<T, K>),
        (closed, touched): (IndexSet<K>, IndexSet<K>),
    ) -> Result<IndexSet<K>, T> {
        let turns = |i: usize, alpha: T| {
            turns_within_band(h[i], speed[i], alpha, jac.row(i).norm() * self.bands[i])
        };
        let mut grazed = IndexSet::EMPTY;
        for i in closed.difference(touched) {
            if turns(i, alpha[i]) {
                grazed.insert(i);
            }
        }
        if grazed.is_empty() || closed.len() < 2 {
            return Ok(grazed);
        }
        let mut scratch = UpdateReport::new(self.t0, self.tau);
        let Ok((held, lambda)) = self.constrained(at.p, at.w, closed, at.free, &mut scratch) else {
            // no held motion to check against (a contact problem without
            // a solution): none is taken for grazed
            return Ok(IndexSet::EMPTY);
        };
        for i in grazed {
            if lambda[i] > T::zero() || !turns(i, jac.row(i).dot(&held.transpose()) + rate[i]) {
                grazed.remove(i);
            }
        }
        Ok(grazed)
    }

    /// [`classify`](Self::classify), with its common case first and
    /// inlined: every constraint clearly open and none touched or held, so all
    /// free (the classes built whole where they are read: set one entry at
    /// a time in `classify`, they cost a store-forwarding stall there).
    #[inline(always)]
    fn classes(
        &self,
        at: &Point<'_, T, N>,
        (h, jac): (&SVector<T, K>, &SMatrix<T, K, N>),
        resolved: IndexSet<K>,
        path: Path<K>,
    ) -> Result<Classes<K>, T> {
        if path.touched.is_empty()
            && path.held.is_empty()
            && (0..K).all(|i| clearly_open(h[i], jac.row(i).norm_squared(), self.bands[i]))
        {
            return Ok(Classes {
                free: IndexSet::full(K),
                ..Classes::default()
            });
        }
        self.classify(at, (h, jac), resolved, path)
    }

    /// How close in time the search locates a crossing, and how close two
    /// crossings must be to count as simultaneous: `max(1024 ε, ε^⅔) τ`.
    ///
    /// A gap is known only to its rounding, about `ε` times the size of
    /// its terms (Example 1's `y − x²` near `x = 2.5`: 1.5e-15 m), so a
    /// root is known to that over the approach speed; at `1024 ε τ`
    /// (2.3e-16 s at 1 kHz in `f64`) the search spent its last evaluations
    /// in that rounding noise. `ε^⅔ τ` (3.7e-14 s at 1 kHz, a position
    /// 3.7e-13 m off at 10 m/s) lies above it for approach speeds above a
    /// few mm/s; in `f32` the bound is `1024 ε τ`, as before.
    fn crossing_tolerance(&self) -> T {
        let eps = T::default_epsilon();
        let third = crate::linalg::cbrt_epsilon::<T>();
        (eps * nalgebra::convert(1024.0)).max(third * third) * self.tau
    }

    /// `h_i` along the segment at the fraction `x = σ/h` of it.
    #[inline(always)]
    fn gap_at_fraction(&self, seg: &Segment<T, N>, i: usize, x: T) -> Result<T, T> {
        let h = self.model.gaps(&seg.position(x));
        finite(&h, "h")?;
        Ok(h[i])
    }

    /// Root of `h_i` along the segment between the fractions `a` and `b`
    /// of it, `f(a) > 0 ≥ f(b)`: returns `σ = x h` at a fraction `x` with
    /// `f(x) ≤ 0` within the [crossing tolerance](Self::crossing_tolerance)
    /// (in time) of one where `f > 0`.
    ///
    /// Brent's method (inverse quadratic interpolation and secant steps,
    /// safeguarded by bisection, and a step of at least the tolerance, so
    /// that an exact estimate closes the bracket with one more evaluation).
    /// With the slopes `d0`, `d1` of `f` at the two ends (in fractions:
    /// `h_i`'s rate times `h`), its first point is the root of `f`'s own
    /// cubic Hermite interpolant ([`hermite_root`]), good to `O(h⁴)` along
    /// the segment's fourth-order motion and exact for a gap quadratic in
    /// `q` along a flight of constant acceleration (Example 1's): two
    /// evaluations of the gaps then locate the impact, where the regula
    /// falsi from the bracket's ends to `1024 ε τ` took seven.
    fn root(
        &self,
        seg: &Segment<T, N>,
        i: usize,
        bracket: [(T, T); 2],
        slopes: Option<(T, T)>,
    ) -> Result<T, T> {
        let zero = T::zero();
        let half: T = nalgebra::convert(0.5);
        let two: T = nalgebra::convert(2.0);
        let three: T = nalgebra::convert(3.0);
        let eps = T::default_epsilon();
        // `|c − b| ≤ 4 ε |b| + t ≤ tol` at the end, with `|b| ≤ 1`
        let tol = self.crossing_tolerance() / seg.h;
        let t = tol * half;
        let [(left, f_left), (right, f_right)] = bracket;
        // `b` the best point, `c` the other side of the root, `a` the
        // point before `b`
        let (mut a, mut fa, mut b, mut fb, mut c, mut fc) =
            (left, f_left, right, f_right, left, f_left);
        if let Some((d0, d1)) = slopes {
            let guess = hermite_root((f_left, d0), (f_right, d1), t * half);
            if guess > left && guess < right {
                let f_guess = self.gap_at_fraction(seg, i, guess)?;
                (b, fb) = (guess, f_guess);
                ((a, fa), (c, fc)) = if f_guess > zero {
                    ((left, f_left), (right, f_right))
                } else {
                    ((right, f_right), (left, f_left))
                };
            }
        }
        let (mut d, mut e) = (b - a, b - a);
        for _ in 0..128 {
            if fc.abs() < fb.abs() {
                (a, fa) = (b, fb);
                (b, fb) = (c, fc);
                (c, fc) = (a, fa);
            }
            let tol1 = two * eps * b.abs() + half * t;
            let xm = half * (c - b);
            if xm.abs() <= tol1 || fb == zero {
                break;
            }
            if e.abs() >= tol1 && fa.abs() > fb.abs() {
                let s = fb / fa;
                let (mut p, mut q) = if a == c {
                    // secant
                    (two * xm * s, T::one() - s)
                } else {
                    // inverse quadratic interpolation
                    let (q, r) = (fa / fc, fb / fc);
                    (
                        s * (two * xm * q * (q - r) - (b - a) * (r - T::one())),
                        (q - T::one()) * (r - T::one()) * (s - T::one()),
                    )
                };
                if p > zero {
                    q = -q;
                } else {
                    p = -p;
                }
                let last = e;
                e = d;
                if two * p < three * xm * q - (tol1 * q).abs() && p < (half * last * q).abs() {
                    d = p / q;
                } else {
                    (d, e) = (xm, xm);
                }
            } else {
                (d, e) = (xm, xm);
            }
            (a, fa) = (b, fb);
            b += if d.abs() > tol1 {
                d
            } else if xm > zero {
                tol1
            } else {
                -tol1
            };
            fb = self.gap_at_fraction(seg, i, b)?;
            if (fb > zero) == (fc > zero) {
                (c, fc) = (a, fa);
                (d, e) = (b - a, b - a);
            }
        }
        // the side where the gap is closed
        Ok(if fb > zero { c } else { b } * seg.h)
    }

    /// The extremum of `h_i` along the segment in `[a, b]`, where its rate
    /// `∇h_i · p'` changes sign, by bisection; returns `(σ, h_i(σ))`.
    fn extremum(&self, seg: &Segment<T, N>, i: usize, mut a: T, mut b: T) -> Result<(T, T), T> {
        let half: T = nalgebra::convert(0.5);
        let tol = T::default_epsilon().sqrt() * self.tau;
        let rate = |sigma: T| -> Result<T, T> {
            let (p, v) = seg.at(sigma);
            let jac = self.model.gap_jacobian(&p);
            finite(&jac, "J")?;
            Ok(jac.row(i).dot(&v.transpose()))
        };
        let falling_at_a = rate(a)? < T::zero();
        for _ in 0..64 {
            if b - a <= tol {
                break;
            }
            let m = (a + b) * half;
            if (rate(m)? < T::zero()) == falling_at_a {
                a = m;
            } else {
                b = m;
            }
        }
        let m = (a + b) * half;
        Ok((m, self.gap_at_fraction(seg, i, m / seg.h)?))
    }

    /// The first constraint to close along the segment (see the module
    /// docs: an open gap that ends closed, an open gap that dips below zero
    /// and reopens, a separating contact that comes back; the contact band of
    /// constraint `i` at the segment's start is `|J_i| b_i`, from `J` and
    /// [`bands`](Self::bands)).
    fn first_crossing(
        &self,
        seg: &Segment<T, N>,
        c: &Classes<K>,
        jac: &SMatrix<T, K, N>,
        start: (&SVector<T, K>, &SVector<T, K>),
        end: (&SVector<T, K>, &SVector<T, K>),
    ) -> Result<Option<Crossing<T, K>>, T> {
        let (h0, rate0) = start;
        let (h1, rate1) = end;
        let (zero, one) = (T::zero(), T::one());
        let mut best: Option<(T, IndexSet<K>)> = None;
        let tol = self.crossing_tolerance();
        let mut record = |at: T, i: usize| match &mut best {
            Some((s, set)) if (at - *s).abs() <= tol => {
                set.insert(i);
            }
            Some((s, _)) if at > *s => {}
            _ => {
                let mut set = IndexSet::new();
                set.insert(i);
                best = Some((at, set));
            }
        };
        for i in c.free {
            if h1[i] <= zero {
                let slopes = (rate0[i] * seg.h, rate1[i] * seg.h);
                record(
                    self.root(seg, i, [(zero, h0[i]), (one, h1[i])], Some(slopes))?,
                    i,
                );
            } else if rate0[i] < zero && rate1[i] > zero {
                let (m, fm) = self.extremum(seg, i, zero, seg.h)?;
                if fm <= zero {
                    record(
                        self.root(seg, i, [(zero, h0[i]), (m / seg.h, fm)], None)?,
                        i,
                    );
                }
            }
        }
        for i in c.departing {
            if h1[i] <= zero && rate1[i] < zero {
                // it turns back: past the band it opened, and closes again
                // at a root; within the band it never opened, and from its
                // turning point (normal speed zero) it is a persistent
                // contact
                let (m, fm) = self.extremum(seg, i, zero, seg.h)?;
                if fm > jac.row(i).norm() * self.bands[i] {
                    record(self.root(seg, i, [(m / seg.h, fm), (one, h1[i])], None)?, i);
                } else {
                    record(m, i);
                }
            }
        }
        Ok(best.map(|(at, set)| Crossing { at, set }))
    }

    /// The predicted motion over the whole interval from `(q_k, v̂_k)`, with
    /// every impact located inside it: returns the predicted end
    /// `(p(τ), w(τ⁻))`.
    pub fn predict(
        &self,
        v0: &SVector<T, N>,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<(SVector<T, N>, SVector<T, N>), T> {
        self.predict_traced(v0, report, &mut traced::NoTrace)
    }

    /// Newton's law at the end of the interval, at the measured `q_{k+1}`,
    /// for the closed constraints the estimate `v` approaches: the
    /// estimate leaves every update with `v̂_e ∈ V(q_{k+1})`, as (20) asks.
    pub fn close_at_end(
        &self,
        v: &SVector<T, N>,
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<SVector<T, N>, T> {
        // (the terms checked apart from the call: a checked pair returned
        // through `Result` costs a store-forwarding stall on reading it)
        let (h, jac) = self.model.contact(&self.q1);
        check_contact(&h, &jac)?;
        let scale = T::default_epsilon() * nalgebra::convert(64.0);
        // the cheap tests first: a constraint the estimate does not
        // approach (`J_i v ≥ 0`), or a gap clearly open, needs no norm
        let approaching = (0..K).any(|i| {
            let row = jac.row(i);
            let jv = row.dot(&v.transpose());
            // (`jv ≥ 0` or NaN: not approaching)
            if jv.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Less)
                || clearly_open(h[i], row.norm_squared(), self.bands[i])
            {
                return false;
            }
            let g = row.norm();
            h[i] <= g * self.bands[i] && jv < -(scale * v.norm()) * g
        });
        if !approaching {
            return Ok(*v);
        }
        let free = self.free(self.tau, &self.q1, v, report)?;
        let point = Point {
            s: self.tau,
            p: &self.q1,
            w: v,
            free: &free,
        };
        let c = self.classify(&point, (&h, &jac), IndexSet::EMPTY, Path::default())?;
        let at = Contact {
            s: self.tau,
            w: v,
            jac: &jac,
            chol: &free.chol,
        };
        Ok(self.newton(&at, (c.contact, c.elastic), false, report)?.0)
    }
}

#[cfg(test)]
mod tests {
    use super::hermite_root;

    /// The interpolant of a quadratic is the quadratic: its root comes
    /// from the formula, to rounding.
    #[test]
    fn hermite_root_of_a_quadratic_is_its_root() {
        // f = 0.3 − 0.1 x − 0.9 x², root (−0.1 + √(0.01 + 1.08)) / 1.8
        let f = |x: f64| 0.3 - 0.1 * x - 0.9 * x * x;
        let df = |x: f64| -0.1 - 1.8 * x;
        let root = hermite_root((f(0.0), df(0.0)), (f(1.0), df(1.0)), 1e-16);
        let exact = (-0.1 + (0.01_f64 + 1.08).sqrt()) / 1.8;
        assert!((root - exact).abs() <= 4.0 * f64::EPSILON, "{root} {exact}");
    }

    /// A true cubic: Newton from the quadratic's root, to its tolerance;
    /// an iterate that lands on the root exactly (`p = 0`) is kept, not
    /// bisected away (that bug put the billiard's first guess at half its
    /// root).
    #[test]
    fn hermite_root_of_a_cubic_converges_and_keeps_an_exact_root() {
        // p = (0.5 − x)(1 + x²): p(0.5) = 0 exactly
        let p = |x: f64| (0.5 - x) * (1.0 + x * x);
        let dp = |x: f64| -(1.0 + x * x) + (0.5 - x) * 2.0 * x;
        let root = hermite_root((p(0.0), dp(0.0)), (p(1.0), dp(1.0)), 1e-15);
        assert!((root - 0.5).abs() <= 1e-15, "{root}");
        // another cubic, in f32
        let q = |x: f32| 0.2 - x + 0.3 * x * x * x;
        let dq = |x: f32| -1.0 + 0.9 * x * x;
        let root = hermite_root((q(0.0), dq(0.0)), (q(1.0), dq(1.0)), 1e-7);
        assert!(q(root).abs() <= 4.0 * f32::EPSILON, "{root} {}", q(root));
    }
}
