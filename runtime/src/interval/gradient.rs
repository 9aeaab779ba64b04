//! Interval gradients: an [`Enclose`] type carrying, beside the interval
//! value of a term over a box `Q`, an enclosure of its gradient with respect
//! to the `N` configuration variables over the same box (forward-mode
//! automatic differentiation in interval arithmetic). It gives the
//! **mean-value form**
//!
//! $$f(Q) \subseteq f(c) + \sum_k \partial_k f(Q)\,(Q_k - c_k),$$
//!
//! whose overestimation shrinks quadratically with the box width, where the
//! plain interval value's only shrinks linearly. It matters for generated
//! code: a kinetic energy written with `sin²(p) + cos²(p)` hidden in it
//! evaluates, in plain intervals, to a width of the order of the term
//! itself on any box; its derivative cancels to first order.
//!
//! Every rule is the chain rule with the derivative enclosed over the whole
//! box (`sin` → `cos(x)·x'`, `x·y` → `x'y + xy'`, …), which is what the
//! mean-value theorem needs.

use core::ops::{Add, Div, Mul, Neg, Sub};

use super::Interval;
use crate::enclosure::Enclose;

/// A value and its gradient over `N` variables, both as intervals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Gradient<const N: usize> {
    pub v: Interval,
    pub g: [Interval; N],
}

impl<const N: usize> Gradient<N> {
    /// The variable `k` over the interval `x`.
    pub fn variable(x: Interval, k: usize) -> Self {
        let mut g = [Interval::point(0.0); N];
        g[k] = Interval::point(1.0);
        Self { v: x, g }
    }

    /// A constant (zero gradient) over the interval `x`.
    pub fn constant(x: Interval) -> Self {
        Self {
            v: x,
            g: [Interval::point(0.0); N],
        }
    }

    /// `f(x)` with `f'` enclosed by `d` over the box.
    fn chain(self, v: Interval, d: Interval) -> Self {
        Self {
            v,
            g: self.g.map(|g| d * g),
        }
    }

    /// The mean-value enclosure `f(c) + Σ_k g_k (Q_k − c_k)`, intersected
    /// with the plain value (both contain the range).
    pub fn mean_value(self, at_centre: Interval, q: &[Interval; N], c: &[Interval; N]) -> Interval {
        let mut s = at_centre;
        for k in 0..N {
            s = s + self.g[k] * (q[k] - c[k]);
        }
        s.intersect(self.v).unwrap_or(s)
    }
}

impl<const N: usize> Add for Gradient<N> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            v: self.v + o.v,
            g: core::array::from_fn(|k| self.g[k] + o.g[k]),
        }
    }
}

impl<const N: usize> Sub for Gradient<N> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self {
            v: self.v - o.v,
            g: core::array::from_fn(|k| self.g[k] - o.g[k]),
        }
    }
}

impl<const N: usize> Neg for Gradient<N> {
    type Output = Self;
    fn neg(self) -> Self {
        Self {
            v: -self.v,
            g: self.g.map(|g| -g),
        }
    }
}

// the product and quotient rules use `+`, `−` and `×` of the parts
#[allow(clippy::suspicious_arithmetic_impl)]
impl<const N: usize> Mul for Gradient<N> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        Self {
            v: self.v * o.v,
            g: core::array::from_fn(|k| self.g[k] * o.v + self.v * o.g[k]),
        }
    }
}

#[allow(clippy::suspicious_arithmetic_impl)]
impl<const N: usize> Div for Gradient<N> {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        let v = self.v / o.v;
        let b2 = o.v.powi(2);
        Self {
            v,
            g: core::array::from_fn(|k| (self.g[k] * o.v - self.v * o.g[k]) / b2),
        }
    }
}

impl<const N: usize> Enclose for Gradient<N> {
    fn point(x: f64) -> Self {
        Self::constant(Interval::point(x))
    }

    fn entire() -> Self {
        Self {
            v: Interval::ENTIRE,
            g: [Interval::ENTIRE; N],
        }
    }

    fn powi(self, n: i32) -> Self {
        if n == 0 {
            return Self::point(1.0);
        }
        let d = Interval::point(f64::from(n)) * self.v.powi(n - 1);
        self.chain(self.v.powi(n), d)
    }

    fn powf(self, e: Self) -> Self {
        // x^e = exp(e ln x)
        (e * self.ln()).exp()
    }

    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        self.chain(r, Interval::point(1.0) / (Interval::point(2.0) * r))
    }

    fn exp(self) -> Self {
        let r = self.v.exp();
        self.chain(r, r)
    }

    fn ln(self) -> Self {
        self.chain(self.v.ln(), Interval::point(1.0) / self.v)
    }

    fn sin(self) -> Self {
        self.chain(self.v.sin(), self.v.cos())
    }

    fn cos(self) -> Self {
        self.chain(self.v.cos(), -self.v.sin())
    }

    fn tan(self) -> Self {
        let t = self.v.tan();
        self.chain(t, Interval::point(1.0) + t.powi(2))
    }

    fn sinh(self) -> Self {
        self.chain(self.v.sinh(), self.v.cosh())
    }

    fn cosh(self) -> Self {
        self.chain(self.v.cosh(), self.v.sinh())
    }

    fn tanh(self) -> Self {
        let t = self.v.tanh();
        self.chain(t, Interval::point(1.0) - t.powi(2))
    }

    fn atan2(self, x: Self) -> Self {
        // d atan2(y, x) = (x dy − y dx)/(x² + y²)
        let r2 = x.v.powi(2) + self.v.powi(2);
        Self {
            v: self.v.atan2(x.v),
            g: core::array::from_fn(|k| (x.v * self.g[k] - self.v * x.g[k]) / r2),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_value_form_cancels_sin_squared_plus_cos_squared() {
        let q = [Interval::new(0.2, 0.7).unwrap()];
        let c = [Interval::point(q[0].mid())];
        let f = |x: Gradient<1>| x.sin().powi(2) + x.cos().powi(2);
        let plain = f(Gradient::constant(q[0])).v;
        assert!(plain.width() > 0.3, "{plain}");
        let g = f(Gradient::variable(q[0], 0));
        let at = f(Gradient::constant(c[0])).v;
        let mv = g.mean_value(at, &q, &c);
        assert!(
            mv.contains(1.0) && mv.width() < plain.width(),
            "{mv} vs {plain}"
        );
        // narrower boxes: quadratic
        let q = [Interval::new(0.4, 0.41).unwrap()];
        let c = [Interval::point(q[0].mid())];
        let mv = f(Gradient::variable(q[0], 0)).mean_value(f(Gradient::constant(c[0])).v, &q, &c);
        assert!(mv.contains(1.0) && mv.width() < 1e-3, "{mv}");
    }

    #[test]
    fn derivatives_of_the_elementary_functions() {
        let x = Gradient::<1>::variable(Interval::point(0.5), 0);
        let cases: [(Gradient<1>, f64); 7] = [
            (x.sin(), 0.5f64.cos()),
            (x.cos(), -0.5f64.sin()),
            (x.exp(), 0.5f64.exp()),
            (x.ln(), 2.0),
            (x.sqrt(), 0.5 / 0.5f64.sqrt()),
            (x.powi(3), 3.0 * 0.25),
            (x.tanh(), 1.0 - 0.5f64.tanh().powi(2)),
        ];
        for (g, d) in cases {
            assert!(
                g.g[0].contains(d) || (g.g[0].mid() - d).abs() < 1e-14,
                "{g:?} {d}"
            );
            assert!(g.g[0].width() < 1e-12);
        }
        let y = Gradient::<2>::variable(Interval::point(1.0), 0);
        let x = Gradient::<2>::variable(Interval::point(2.0), 1);
        let a = y.atan2(x);
        assert!(
            a.g[0].contains(0.4) && a.g[1].contains(-0.2) || (a.g[1].mid() + 0.2).abs() < 1e-15
        );
        let q = y / x;
        assert!(q.g[0].contains(0.5) && q.g[1].contains(-0.25));
    }
}
