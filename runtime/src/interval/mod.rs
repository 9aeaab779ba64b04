//! Closed intervals of `f64` with outward rounding: the [`Enclose`] type that
//! turns a model's generated [`Enclosure`](crate::Enclosure) into proofs.
//!
//! # Rounding
//!
//! Rust's floating-point arithmetic is IEEE 754 binary64 with rounding to
//! nearest (no other rounding mode is reachable from safe Rust), so every
//! `+ − × ÷` and `√` returns the exact result rounded to the nearest
//! double: within half a unit in the last place (ulp). An [`Interval`]
//! computes each bound to nearest and then steps it **one ulp outward**
//! (a hand-written `next_down`/`next_up` on the bit pattern, since
//! `f64::next_up` needs Rust 1.86 and the workspace MSRV is 1.85), which
//! always contains the exact bound. Three exceptions keep exact results
//! exact:
//!
//! - `a + b` and `a − b` use the error-free transformation TwoSum: the
//!   rounding error `e` of `s = a + b` is computed exactly, and the bound
//!   is stepped only when `e` points outward (`e < 0` for a lower bound,
//!   `e > 0` for an upper one), so sums of exactly representable values
//!   stay points;
//! - a product with a zero factor is exactly zero (also `0 × ∞ = 0`, the
//!   interval convention: bounds are limits of reals, never `∞` itself);
//! - negation is exact.
//!
//! An overflowed lower bound `+∞` becomes `f64::MAX` and an overflowed upper
//! bound `−∞` becomes `−f64::MAX`. Any NaN bound (an operation outside its
//! domain, `∞ − ∞`) becomes the infinite bound on its side: the result is
//! then wider, never wrong.
//!
//! # Elementary functions
//!
//! `√` is correctly rounded by IEEE 754 and is widened by one ulp. The
//! others come from the platform's `libm` (through `nalgebra`'s
//! `ComplexField`: `std`'s functions with the `std` feature, the `libm`
//! crate without), which is **not** correctly rounded: glibc and musl
//! document errors below 1 ulp for `sin`, `cos`, `exp`, `ln`, and at most
//! 2 ulps for `tan`, `sinh`, `cosh`, `tanh`, `atan2`, `powf`-free paths.
//! Their results are widened by [`LIBM_ULPS`] = 4 ulps each way, twice the
//! largest documented error. That is an assumption about the platform's
//! `libm`, stated here, not a theorem; everything else is.
//!
//! Each function uses its monotonicity or its extrema:
//!
//! - `exp`, `ln`, `√`, `sinh`, `tanh` are increasing: the image of
//!   `[a, b]` is `[f(a), f(b)]` (with `ln` and `√` cut to their domain:
//!   `ln` of an interval reaching `0` or below has lower bound `−∞`, and an
//!   interval entirely outside the domain gives the entire line);
//! - `cosh` is decreasing then increasing: `[1, max(cosh a, cosh b)]` when
//!   `0 ∈ [a, b]`;
//! - `sin` and `cos`: the images of the endpoints, plus `+1` when the
//!   interval contains a maximum (`π/2 + 2kπ` for `sin`, `2kπ` for `cos`)
//!   and `−1` when it contains a minimum; the test `∃k: a ≤ x₀ + kP ≤ b`
//!   is made on `(a − x₀)/P` and `(b − x₀)/P` widened by `1e-9`, so it can
//!   only answer "yes" wrongly (a wider result), never "no"; an interval of
//!   width `≥ 2π`, or with an endpoint beyond `|x| = 2²⁰`, gives `[−1, 1]`;
//!   the result is cut to `[−1, 1]`;
//! - `tan` is increasing between its poles: the entire line when the
//!   interval may contain a pole `π/2 + kπ` (same test) or is `π` wide;
//! - `atan2(y, x)` is evaluated at the four corners when the box avoids
//!   the branch cut `{x ≤ 0, y = 0}` (its gradient `(−y, x)/r²` never
//!   vanishes and keeps its sign along each edge, so the extremes are at
//!   corners), else it is `[−π, π]`;
//! - `xⁿ` for an integer `n` multiplies the magnitudes with directed
//!   rounding (monotone on `[0, ∞)`), then applies the sign (`[0, …]` for
//!   an even power of an interval containing `0`); `n < 0` divides `1` by
//!   it; `x^e` for a non-integer `e` is `exp(e ln x)`.
//!
//! Division by an interval containing `0` gives the entire line.

use core::fmt;
use core::ops::{Add, Div, Mul, Neg, Sub};

use nalgebra::ComplexField;

use crate::enclosure::Enclose;

#[cfg(feature = "std")]
pub(crate) mod branch;
#[cfg(feature = "std")]
pub(crate) mod gradient;
#[cfg(feature = "std")]
pub(crate) mod matrix;

/// Ulps by which each `libm` result is widened each way (see "Elementary
/// functions" in the module docs of `runtime/src/interval/mod.rs`).
pub const LIBM_ULPS: u32 = 4;

/// The next `f64` above `x` (`x` itself for `+∞` and NaN): `f64::next_up`,
/// written out for Rust 1.85.
#[must_use]
#[inline]
pub fn next_up(x: f64) -> f64 {
    if x.is_nan() || x == f64::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let bits = x.to_bits();
    f64::from_bits(if x > 0.0 { bits + 1 } else { bits - 1 })
}

/// The next `f64` below `x` (`x` itself for `−∞` and NaN).
#[must_use]
#[inline]
pub fn next_down(x: f64) -> f64 {
    -next_up(-x)
}

fn up_by(mut x: f64, ulps: u32) -> f64 {
    for _ in 0..ulps {
        x = next_up(x);
    }
    x
}

fn down_by(mut x: f64, ulps: u32) -> f64 {
    for _ in 0..ulps {
        x = next_down(x);
    }
    x
}

/// `a + b` rounded toward `−∞` (TwoSum: stepped only when inexact downward).
#[inline]
pub(crate) fn add_down(a: f64, b: f64) -> f64 {
    let s = a + b;
    if !s.is_finite() {
        return next_down(s);
    }
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    if e < 0.0 { next_down(s) } else { s }
}

/// `a + b` rounded toward `+∞`.
#[inline]
pub(crate) fn add_up(a: f64, b: f64) -> f64 {
    -add_down(-a, -b)
}

/// Veltkamp's split of `a` into two halves of 26 bits each.
#[inline]
fn split(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a; // 2^27 + 1
    let h = c - (c - a);
    (h, a - h)
}

/// `a · b` to nearest, and the sign of its rounding error
/// (`exact − rounded`): Dekker's TwoProduct, exact when no partial product
/// overflows or underflows; outside `2^−900 ≤ |a·b|`, `|a|, |b| ≤ 2^900` the
/// sign is reported as unknown (`None`).
#[inline]
fn mul_err(a: f64, b: f64) -> (f64, Option<f64>) {
    const BIG: f64 = 8.452_712_498_170_644e270; // 2^900
    const SMALL: f64 = 1.183_052_186_166_774_7e-271; // 2^−900
    let p = a * b;
    if !(a.abs() <= BIG && b.abs() <= BIG && p.abs() >= SMALL && p.abs() <= BIG) {
        return (p, None);
    }
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    let e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
    (p, Some(e))
}

/// `a · b` toward `−∞` (exact products, a zero factor among them, stay).
pub(crate) fn mul_down(a: f64, b: f64) -> f64 {
    if a == 0.0 || b == 0.0 {
        return 0.0;
    }
    match mul_err(a, b) {
        (p, Some(e)) if e >= 0.0 => p,
        (p, _) => next_down(p),
    }
}

/// `a · b` toward `−∞` and toward `+∞`, from one TwoProduct: the same
/// pair as `(mul_down(a, b), mul_up(a, b))`.
#[inline]
fn mul_down_up(a: f64, b: f64) -> (f64, f64) {
    if a == 0.0 || b == 0.0 {
        return (0.0, 0.0);
    }
    match mul_err(a, b) {
        (p, Some(e)) => (
            if e >= 0.0 { p } else { next_down(p) },
            if e <= 0.0 { p } else { next_up(p) },
        ),
        (p, None) => (next_down(p), next_up(p)),
    }
}

/// `a · b` toward `+∞`.
pub(crate) fn mul_up(a: f64, b: f64) -> f64 {
    if a == 0.0 || b == 0.0 {
        return 0.0;
    }
    match mul_err(a, b) {
        (p, Some(e)) if e <= 0.0 => p,
        (p, _) => next_up(p),
    }
}

/// A closed interval `[lo, hi]` of reals, `lo ≤ hi`, possibly unbounded
/// (`lo = −∞`, `hi = +∞`), never empty, never NaN. Every operation returns
/// an interval containing the exact result for every pair of points of its
/// operands (see the module docs of `runtime/src/interval/mod.rs` for the
/// rounding and the elementary functions).
///
/// ```
/// use moreau_runtime::{Enclose, Interval};
///
/// let x = Interval::new(0.1, 0.2).unwrap();
/// let y = x * x - x; // dependency: wider than the true range [−0.25, −0.08]
/// assert!(y.lo() <= -0.16 && y.hi() >= -0.06);
/// // 0.1 is not a double: the enclosure of 0.1 + 0.2 contains the real sum
/// let s = Interval::point(0.1) + Interval::point(0.2);
/// assert!(s.lo() < s.hi() && s.contains(0.30000000000000004));
/// // sin over an interval containing π/2 reaches 1
/// assert_eq!(Interval::new(1.0, 2.0).unwrap().sin().hi(), 1.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    lo: f64,
    hi: f64,
}

impl Interval {
    /// The entire real line.
    pub const ENTIRE: Self = Self {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// `[lo, hi]`, or `None` when a bound is NaN or `lo > hi`.
    #[must_use]
    pub fn new(lo: f64, hi: f64) -> Option<Self> {
        (lo <= hi).then_some(Self { lo, hi })
    }

    /// `[lo, hi]` from computed bounds: a NaN bound becomes infinite on its
    /// side, an overflowed bound the largest finite one.
    #[inline]
    fn from_bounds(lo: f64, hi: f64) -> Self {
        let lo = if lo.is_nan() {
            f64::NEG_INFINITY
        } else if lo == f64::INFINITY {
            f64::MAX
        } else {
            lo
        };
        let hi = if hi.is_nan() {
            f64::INFINITY
        } else if hi == f64::NEG_INFINITY {
            -f64::MAX
        } else {
            hi
        };
        if lo <= hi {
            Self { lo, hi }
        } else {
            Self::ENTIRE
        }
    }

    /// The lower bound.
    #[must_use]
    pub fn lo(self) -> f64 {
        self.lo
    }

    /// The upper bound.
    #[must_use]
    pub fn hi(self) -> f64 {
        self.hi
    }

    /// `hi − lo`, rounded up.
    #[must_use]
    pub fn width(self) -> f64 {
        add_up(self.hi, -self.lo)
    }

    /// A point inside (the midpoint to rounding; `0` for the entire line,
    /// the finite bound for a half line).
    #[must_use]
    pub fn mid(self) -> f64 {
        match (self.lo.is_finite(), self.hi.is_finite()) {
            (true, true) => {
                let m = 0.5 * self.lo + 0.5 * self.hi;
                m.clamp(self.lo, self.hi)
            }
            (true, false) => self.lo,
            (false, true) => self.hi,
            (false, false) => 0.0,
        }
    }

    /// The largest `|x|` over the interval.
    #[must_use]
    pub fn mag(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// The smallest `|x|` over the interval.
    #[must_use]
    pub fn mig(self) -> f64 {
        if self.lo > 0.0 {
            self.lo
        } else if self.hi < 0.0 {
            -self.hi
        } else {
            0.0
        }
    }

    /// Whether `x` is in the interval.
    #[must_use]
    pub fn contains(self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// The two halves `[lo, m]`, `[m, hi]` at the midpoint `m`.
    #[must_use]
    pub fn bisect(self) -> (Self, Self) {
        let m = self.mid();
        (Self { lo: self.lo, hi: m }, Self { lo: m, hi: self.hi })
    }

    /// The intersection, or `None` when empty.
    #[must_use]
    pub fn intersect(self, other: Self) -> Option<Self> {
        Self::new(self.lo.max(other.lo), self.hi.min(other.hi))
    }

    /// Whether both bounds are finite.
    #[must_use]
    pub fn is_finite(self) -> bool {
        self.lo.is_finite() && self.hi.is_finite()
    }

    /// `[lo, hi]` widened by `ulps` each way (a `libm` result).
    fn widened(lo: f64, hi: f64, ulps: u32) -> Self {
        Self::from_bounds(down_by(lo, ulps), up_by(hi, ulps))
    }

    /// The image of an increasing `libm` function.
    fn increasing(self, f: fn(f64) -> f64) -> Self {
        Self::widened(f(self.lo), f(self.hi), LIBM_ULPS)
    }

    /// `xⁿ` for `x ≥ 0` and `n ≥ 1`, rounded down and up.
    fn pow_nonneg(x: f64, n: u32) -> (f64, f64) {
        let (mut base_lo, mut base_hi, mut acc_lo, mut acc_hi, mut n) = (x, x, 1.0, 1.0, n);
        while n > 0 {
            if n & 1 == 1 {
                acc_lo = mul_down(acc_lo, base_lo);
                acc_hi = mul_up(acc_hi, base_hi);
            }
            n >>= 1;
            if n > 0 {
                base_lo = mul_down(base_lo, base_lo);
                base_hi = mul_up(base_hi, base_hi);
            }
        }
        (acc_lo.max(0.0), acc_hi)
    }

    /// The image under `sin(x + shift)`-like periodic functions: the
    /// endpoint values of `f`, plus `1` if a maximum `max_at + 2kπ` may lie
    /// inside and `−1` if a minimum `max_at + π + 2kπ` may.
    fn periodic(self, f: fn(f64) -> f64, max_at: f64) -> Self {
        use core::f64::consts::{PI, TAU};
        if !(self.lo.is_finite() && self.hi.is_finite())
            || self.hi - self.lo >= TAU
            || self.mag() > (1u64 << 20) as f64
        {
            return Self { lo: -1.0, hi: 1.0 };
        }
        let (a, b) = (f(self.lo), f(self.hi));
        let mut r = Self::widened(a.min(b), a.max(b), LIBM_ULPS);
        if self.may_contain(max_at, TAU) {
            r.hi = 1.0;
        }
        if self.may_contain(max_at + PI, TAU) {
            r.lo = -1.0;
        }
        Self {
            lo: r.lo.max(-1.0),
            hi: r.hi.min(1.0),
        }
    }

    /// Whether `x₀ + k·period` may lie in the interval for some integer
    /// `k`: never "no" wrongly (see the module docs).
    fn may_contain(self, x0: f64, period: f64) -> bool {
        let ta = (self.lo - x0) / period - 1e-9;
        let tb = (self.hi - x0) / period + 1e-9;
        ComplexField::floor(tb) >= ta
    }
}

impl Default for Interval {
    fn default() -> Self {
        Self::point(0.0)
    }
}

impl fmt::Display for Interval {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match f.precision() {
            Some(p) => write!(f, "[{:.*}, {:.*}]", p, self.lo, p, self.hi),
            None => write!(f, "[{}, {}]", self.lo, self.hi),
        }
    }
}

impl Add for Interval {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self::from_bounds(add_down(self.lo, o.lo), add_up(self.hi, o.hi))
    }
}

impl Sub for Interval {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self::from_bounds(add_down(self.lo, -o.hi), add_up(self.hi, -o.lo))
    }
}

impl Neg for Interval {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self {
            lo: -self.hi,
            hi: -self.lo,
        }
    }
}

impl Mul for Interval {
    type Output = Self;
    /// The product by the sign cases of the operands: only the corners that
    /// can hold the smallest and the largest product are rounded (two
    /// TwoProducts unless both operands straddle zero), each down or up as
    /// `mul_down` and `mul_up` would.
    #[inline]
    fn mul(self, o: Self) -> Self {
        let (a, b, c, d) = (self.lo, self.hi, o.lo, o.hi);
        let down = |x, y| mul_down_up(x, y).0;
        let up = |x, y| mul_down_up(x, y).1;
        let (lo, hi) = if a >= 0.0 {
            if c >= 0.0 {
                (down(a, c), up(b, d))
            } else if d <= 0.0 {
                (down(b, c), up(a, d))
            } else {
                (down(b, c), up(b, d))
            }
        } else if b <= 0.0 {
            if c >= 0.0 {
                (down(a, d), up(b, c))
            } else if d <= 0.0 {
                (down(b, d), up(a, c))
            } else {
                (down(a, d), up(a, c))
            }
        } else if c >= 0.0 {
            (down(a, d), up(b, d))
        } else if d <= 0.0 {
            (down(b, c), up(a, c))
        } else {
            let (ad, bc) = (mul_down_up(a, d), mul_down_up(b, c));
            let (ac, bd) = (mul_down_up(a, c), mul_down_up(b, d));
            (ad.0.min(bc.0), ac.1.max(bd.1))
        };
        Self::from_bounds(lo, hi)
    }
}

impl Div for Interval {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        if o.contains(0.0) {
            return Self::ENTIRE;
        }
        let q = |x: f64, y: f64| (x / y, x == 0.0);
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for (x, y) in [
            (self.lo, o.lo),
            (self.lo, o.hi),
            (self.hi, o.lo),
            (self.hi, o.hi),
        ] {
            let (v, exact) = q(x, y);
            let (l, h) = if exact || v.is_nan() {
                (v, v)
            } else {
                (next_down(v), next_up(v))
            };
            lo = lo.min(l);
            hi = hi.max(h);
        }
        // ∞/∞ corners (NaN, skipped by min/max) only occur with unbounded
        // operands: fall back to the entire line then
        if !(self.is_finite() && o.is_finite()) && (lo.is_nan() || hi.is_nan() || lo > hi) {
            return Self::ENTIRE;
        }
        Self::from_bounds(lo, hi)
    }
}

impl Enclose for Interval {
    fn point(x: f64) -> Self {
        if x.is_nan() {
            Self::ENTIRE
        } else {
            Self { lo: x, hi: x }
        }
    }

    fn entire() -> Self {
        Self::ENTIRE
    }

    fn powi(self, n: i32) -> Self {
        if n == 0 {
            return Self::point(1.0);
        }
        if n < 0 {
            return Self::point(1.0) / self.powi(n.unsigned_abs().min(i32::MAX as u32) as i32);
        }
        let n = n as u32;
        let even = n % 2 == 0;
        if self.lo >= 0.0 {
            let (lo, _) = Self::pow_nonneg(self.lo, n);
            let (_, hi) = Self::pow_nonneg(self.hi, n);
            Self::from_bounds(lo, hi)
        } else if self.hi <= 0.0 {
            let (lo, _) = Self::pow_nonneg(-self.hi, n);
            let (_, hi) = Self::pow_nonneg(-self.lo, n);
            if even {
                Self::from_bounds(lo, hi)
            } else {
                Self::from_bounds(-hi, -lo)
            }
        } else if even {
            let (_, hi) = Self::pow_nonneg(self.mag(), n);
            Self::from_bounds(0.0, hi)
        } else {
            let (_, neg) = Self::pow_nonneg(-self.lo, n);
            let (_, pos) = Self::pow_nonneg(self.hi, n);
            Self::from_bounds(-neg, pos)
        }
    }

    fn powf(self, e: Self) -> Self {
        if e.lo == e.hi && e.lo.abs() <= i32::MAX as f64 && ComplexField::floor(e.lo) == e.lo {
            return self.powi(e.lo as i32);
        }
        (e * self.ln()).exp()
    }

    fn sqrt(self) -> Self {
        if self.hi < 0.0 {
            return Self::ENTIRE;
        }
        let lo = if self.lo <= 0.0 {
            0.0
        } else {
            next_down(ComplexField::sqrt(self.lo)).max(0.0)
        };
        Self::from_bounds(lo, next_up(ComplexField::sqrt(self.hi)))
    }

    fn exp(self) -> Self {
        let r = self.increasing(ComplexField::exp);
        Self::from_bounds(r.lo.max(0.0), r.hi)
    }

    fn ln(self) -> Self {
        if self.hi <= 0.0 {
            return Self::ENTIRE;
        }
        let hi = up_by(ComplexField::ln(self.hi), LIBM_ULPS);
        let lo = if self.lo <= 0.0 {
            f64::NEG_INFINITY
        } else {
            down_by(ComplexField::ln(self.lo), LIBM_ULPS)
        };
        Self::from_bounds(lo, hi)
    }

    fn sin(self) -> Self {
        self.periodic(ComplexField::sin, core::f64::consts::FRAC_PI_2)
    }

    fn cos(self) -> Self {
        self.periodic(ComplexField::cos, 0.0)
    }

    fn tan(self) -> Self {
        use core::f64::consts::{FRAC_PI_2, PI};
        if !self.is_finite() || self.hi - self.lo >= PI || self.may_contain(FRAC_PI_2, PI) {
            return Self::ENTIRE;
        }
        self.increasing(ComplexField::tan)
    }

    fn sinh(self) -> Self {
        self.increasing(ComplexField::sinh)
    }

    fn cosh(self) -> Self {
        let (a, b) = (ComplexField::cosh(self.lo), ComplexField::cosh(self.hi));
        let r = if self.contains(0.0) {
            Self::from_bounds(1.0, up_by(a.max(b), LIBM_ULPS))
        } else {
            Self::widened(a.min(b), a.max(b), LIBM_ULPS)
        };
        Self::from_bounds(r.lo.max(1.0), r.hi)
    }

    fn tanh(self) -> Self {
        let r = self.increasing(ComplexField::tanh);
        Self {
            lo: r.lo.max(-1.0),
            hi: r.hi.min(1.0),
        }
    }

    fn atan2(self, x: Self) -> Self {
        use core::f64::consts::PI;
        let all = Self::from_bounds(-next_up(PI), next_up(PI));
        let off_cut = x.lo > 0.0 || self.lo > 0.0 || self.hi < 0.0;
        if !(off_cut && self.is_finite() && x.is_finite()) {
            return all;
        }
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for (y, x) in [
            (self.lo, x.lo),
            (self.lo, x.hi),
            (self.hi, x.lo),
            (self.hi, x.hi),
        ] {
            let a = nalgebra::RealField::atan2(y, x);
            lo = lo.min(a);
            hi = hi.max(a);
        }
        let r = Self::widened(lo, hi, LIBM_ULPS);
        Self {
            lo: r.lo.max(all.lo),
            hi: r.hi.min(all.hi),
        }
    }
}

/// `√x` rounded up (`0` for `x ≤ 0`).
#[cfg(feature = "std")]
pub(crate) fn sqrt_up(x: f64) -> f64 {
    if x <= 0.0 {
        0.0
    } else {
        next_up(ComplexField::sqrt(x))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn iv(lo: f64, hi: f64) -> Interval {
        Interval::new(lo, hi).unwrap()
    }

    #[test]
    fn ulp_steps() {
        assert_eq!(next_up(1.0), 1.0 + f64::EPSILON);
        assert_eq!(next_down(1.0), 1.0 - f64::EPSILON / 2.0);
        assert_eq!(next_up(0.0), f64::from_bits(1));
        assert_eq!(next_up(-0.0), f64::from_bits(1));
        assert_eq!(next_down(0.0), -f64::from_bits(1));
        assert_eq!(next_up(-f64::from_bits(1)), -0.0);
        assert_eq!(next_up(f64::MAX), f64::INFINITY);
        assert_eq!(next_down(f64::INFINITY), f64::MAX);
        assert_eq!(next_up(f64::NEG_INFINITY), -f64::MAX);
        assert!(next_up(f64::NAN).is_nan());
    }

    /// The product by sign cases is the hull of the four corner products,
    /// each rounded outward (the textbook definition), on every pair of a
    /// grid of intervals with signs, zeros, infinities and inexact ends
    /// (bit for bit where TwoProduct is exact at every corner, else within
    /// it).
    #[test]
    fn products_by_sign_cases_equal_the_four_corner_hull() {
        let ends = [
            f64::NEG_INFINITY,
            -1e300,
            -3.7,
            -0.1,
            -0.0,
            0.0,
            1e-300,
            0.3,
            1.0 / 3.0,
            2.0,
            1e300,
            f64::INFINITY,
        ];
        let mut boxes = Vec::new();
        for &lo in &ends {
            for &hi in &ends {
                if let Some(x) = Interval::new(lo, hi) {
                    boxes.push(x);
                }
            }
        }
        for &x in &boxes {
            for &y in &boxes {
                let corners = [(x.lo, y.lo), (x.lo, y.hi), (x.hi, y.lo), (x.hi, y.hi)];
                let lo = corners
                    .iter()
                    .map(|&(a, b)| mul_down(a, b))
                    .fold(f64::INFINITY, f64::min);
                let hi = corners
                    .iter()
                    .map(|&(a, b)| mul_up(a, b))
                    .fold(f64::NEG_INFINITY, f64::max);
                let want = Interval::from_bounds(lo, hi);
                let got = x * y;
                // a corner out of TwoProduct's range is widened by an ulp
                // even where it is not the extreme one: there the sign
                // cases may be tighter, never wider
                let ranged = corners
                    .iter()
                    .all(|&(a, b)| a == 0.0 || b == 0.0 || mul_err(a, b).1.is_some());
                assert!(want.lo <= got.lo && got.hi <= want.hi, "{x:?} * {y:?}");
                if ranged {
                    assert_eq!(
                        (got.lo.to_bits(), got.hi.to_bits()),
                        (want.lo.to_bits(), want.hi.to_bits()),
                        "{x:?} * {y:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn exact_sums_stay_points_and_inexact_ones_widen() {
        let s = Interval::point(1.0) + Interval::point(2.0);
        assert_eq!((s.lo, s.hi), (3.0, 3.0));
        let s = Interval::point(0.1) + Interval::point(0.2);
        // 0.1 + 0.2 (the doubles) is 0.3000000000000000166…, which rounds up
        // to 0.30000000000000004: the lower bound steps down, the upper one
        // stays
        assert_eq!(s.hi, 0.1 + 0.2);
        assert_eq!(s.lo, next_down(0.1 + 0.2));
        // exact products stay points; 0.1 · 3 (the doubles) rounds up
        assert_eq!(
            Interval::point(1.5) * Interval::point(-4.0),
            Interval::point(-6.0)
        );
        let p = Interval::point(0.1) * Interval::point(3.0);
        assert_eq!((p.lo, p.hi), (next_down(0.1 * 3.0), 0.1 * 3.0));
        let p = Interval::point(3.0) * Interval::ENTIRE;
        assert_eq!(p, Interval::ENTIRE);
        let z = Interval::point(0.0) * Interval::ENTIRE;
        assert_eq!(z, Interval::point(0.0));
        assert_eq!(
            Interval::point(f64::MAX) + Interval::point(f64::MAX),
            Interval::from_bounds(f64::MAX, f64::INFINITY)
        );
    }

    #[test]
    fn division_and_powers() {
        assert_eq!(iv(1.0, 2.0) / iv(-1.0, 1.0), Interval::ENTIRE);
        let q = iv(1.0, 2.0) / iv(4.0, 8.0);
        assert!(q.contains(0.125) && q.contains(0.5) && q.lo > 0.12 && q.hi < 0.51);
        assert_eq!(iv(-2.0, 3.0).powi(2), iv(0.0, 9.0));
        assert_eq!(iv(-2.0, 3.0).powi(3), iv(-8.0, 27.0));
        assert_eq!(iv(-3.0, -2.0).powi(2), iv(4.0, 9.0));
        assert_eq!(iv(-3.0, -2.0).powi(3), iv(-27.0, -8.0));
        let r = iv(2.0, 4.0).powi(-1);
        assert!(r.contains(0.25) && r.contains(0.5));
        let h = iv(4.0, 9.0).powf(Interval::point(0.5));
        assert!(h.contains(2.0) && h.contains(3.0) && h.lo > 1.99 && h.hi < 3.01);
        assert_eq!(iv(4.0, 9.0).sqrt().lo(), next_down(2.0));
    }

    #[test]
    fn trigonometric_extrema() {
        use core::f64::consts::{FRAC_PI_2, PI};
        // no extremum inside: endpoint values, widened
        let s = iv(0.1, 0.2).sin();
        assert!(s.lo < 0.1f64.sin() && s.hi > 0.2f64.sin() && s.hi < 0.2);
        // a maximum inside
        assert_eq!(iv(1.0, 2.0).sin().hi, 1.0);
        assert_eq!(iv(-2.0, -1.0).sin().lo, -1.0);
        assert_eq!(iv(-0.1, 0.1).cos().hi, 1.0);
        assert_eq!(iv(3.0, 3.3).cos().lo, -1.0);
        // an extremum at an endpoint (π/2 as a double is below the real π/2)
        assert_eq!(iv(FRAC_PI_2, 2.0).sin().hi, 1.0);
        // the whole period
        assert_eq!(iv(0.0, 7.0).cos(), iv(-1.0, 1.0));
        // far from 0, a maximum 2kπ + π/2 with k = 100
        let x = 200.0 * PI + FRAC_PI_2;
        assert_eq!(iv(x - 0.01, x + 0.01).sin().hi, 1.0);
        // every sample is inside
        let box_ = iv(-2.3, 0.7);
        let (s, c) = (box_.sin(), box_.cos());
        for k in 0..=1000 {
            let x = -2.3 + 3.0 * k as f64 / 1000.0;
            assert!(s.contains(x.sin()) && c.contains(x.cos()), "{x}");
        }
        assert_eq!(iv(1.0, 2.0).tan(), Interval::ENTIRE);
        let t = iv(-1.0, 1.0).tan();
        assert!(t.contains(1.0f64.tan()) && t.contains(-(1.0f64.tan())));
    }

    #[test]
    fn other_functions_contain_their_samples() {
        let x = iv(-1.5, 2.0);
        type Pair = (fn(Interval) -> Interval, fn(f64) -> f64);
        let fs: [Pair; 4] = [
            (Interval::exp, f64::exp),
            (Interval::sinh, f64::sinh),
            (Interval::cosh, f64::cosh),
            (Interval::tanh, f64::tanh),
        ];
        for (fi, f) in fs {
            let y = fi(x);
            for k in 0..=100 {
                let t = -1.5 + 3.5 * k as f64 / 100.0;
                assert!(y.contains(f(t)), "{t}");
            }
        }
        assert_eq!(x.cosh().lo, 1.0);
        assert_eq!(iv(-1.0, 0.0).ln().lo, f64::NEG_INFINITY);
        let l = iv(1.0, 2.0).ln();
        assert!(l.contains(0.0) && l.contains(2.0f64.ln()));
        let a = iv(1.0, 2.0).atan2(iv(-1.0, 1.0));
        assert!(a.contains(1.0f64.atan2(-1.0)) && a.contains(2.0f64.atan2(1.0)));
        let all = iv(-1.0, 1.0).atan2(iv(-1.0, 1.0));
        assert!(all.contains(core::f64::consts::PI) && all.contains(-core::f64::consts::PI));
    }
}
