//! Exact symbolic differentiation.
//!
//! One arm per [`Node`], each written next to the value it differentiates, as
//! in CasADi's `calculus.hpp` (`fcn` beside `der`). A partial derivative
//! reuses the nodes that already exist: the result `f` of the node itself
//! (`d exp(a) = exp(a) da`, `d sqrt(a) = da / (2 sqrt(a))`), its operands, and
//! the derivatives of its operands. The builders simplify every product with
//! a zero or unit factor, so derivatives stay as small as the expression.
//!
//! Derivatives are memoized per `(node, variable)` in the graph for its whole
//! life (the arena only grows, so a cached derivative never goes stale):
//! differentiating `∂T/∂v_i` with respect to `v_j` for every `j`, and then the
//! mass matrix with respect to every `q_k`, shares all common work.

use std::collections::HashSet;

use crate::graph::Graph;
use crate::node::{Func, Id, Node, VarId};

impl Graph {
    /// The exact partial derivative `∂e/∂wrt`.
    ///
    /// Returns the constant `0` when `e` does not depend on `wrt`. Iterative
    /// (no recursion), so deep expressions cannot overflow the stack.
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let y = g.var(VarId(1));
    /// let s = g.sin(x);
    /// let e = g.mul(s, y); // y sin x
    /// let dx = g.diff(e, VarId(0));
    /// let c = g.cos(x);
    /// assert_eq!(dx, g.mul(c, y)); // y cos x
    /// let dy = g.diff(e, VarId(1));
    /// assert_eq!(dy, s);
    /// let dz = g.diff(e, VarId(2));
    /// assert_eq!(g.as_const(dz), Some(0.0));
    /// ```
    pub fn diff(&mut self, e: Id, wrt: VarId) -> Id {
        if !self.depends_on(e, wrt) {
            return self.constant(0.0);
        }
        if let Some(&d) = self.dcache.get(&(e, wrt)) {
            return d;
        }
        // The nodes under `e` that depend on `wrt` and have no derivative
        // yet, differentiated children first (increasing id).
        let mut todo = Vec::new();
        let mut seen = HashSet::new();
        let mut stack = vec![e];
        while let Some(id) = stack.pop() {
            if !seen.insert(id) || !self.depends_on(id, wrt) || self.dcache.contains_key(&(id, wrt))
            {
                continue;
            }
            todo.push(id);
            stack.extend_from_slice(self.node(id).children());
        }
        todo.sort_unstable();
        for id in todo {
            let d = self.diff_node(id, wrt);
            self.dcache.insert((id, wrt), d);
        }
        self.dcache[&(e, wrt)]
    }

    /// The gradient `[∂e/∂wrt[0], ∂e/∂wrt[1], ...]`.
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let y = g.var(VarId(1));
    /// let e = g.mul(x, y);
    /// assert_eq!(g.gradient(e, &[VarId(0), VarId(1)]), vec![y, x]);
    /// ```
    pub fn gradient(&mut self, e: Id, wrt: &[VarId]) -> Vec<Id> {
        wrt.iter().map(|&v| self.diff(e, v)).collect()
    }

    /// The Jacobian matrix, row `i` the gradient of `es[i]`.
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let y = g.var(VarId(1));
    /// let s = g.add(x, y);
    /// let one = g.constant(1.0);
    /// let zero = g.constant(0.0);
    /// assert_eq!(
    ///     g.jacobian(&[s, y], &[VarId(0), VarId(1)]),
    ///     vec![vec![one, one], vec![zero, one]]
    /// );
    /// ```
    pub fn jacobian(&mut self, es: &[Id], wrt: &[VarId]) -> Vec<Vec<Id>> {
        es.iter().map(|&e| self.gradient(e, wrt)).collect()
    }

    /// The derivative of an operand: cached, or zero when independent.
    fn d(&mut self, id: Id, wrt: VarId) -> Id {
        if self.depends_on(id, wrt) {
            self.dcache[&(id, wrt)]
        } else {
            self.constant(0.0)
        }
    }

    /// The derivative of node `f`, whose operands' derivatives are known.
    fn diff_node(&mut self, f: Id, wrt: VarId) -> Id {
        match self.node(f) {
            // f = c
            Node::Const(_) => self.constant(0.0),
            // f = x
            Node::Var(v) => self.constant(if v == wrt { 1.0 } else { 0.0 }),
            node => {
                let zero = self.constant(0.0);
                let mut d = [zero; 2];
                for (d, &c) in d.iter_mut().zip(node.children()) {
                    *d = self.d(c, wrt);
                }
                self.tangent(f, d)
            }
        }
    }

    /// The differential `df` of the operation `f` given the differentials
    /// of its operands (`[da]` or `[da, db]`, the second ignored for a
    /// unary operation). Linear in `(da, db)`, so it is also the local
    /// partial of reverse mode: `tangent(f, [ā, 0])` is `ā ∂f/∂a`.
    ///
    /// # Panics
    /// If `f` is a constant or a variable (no operands).
    pub(crate) fn tangent(&mut self, f: Id, [da, db]: [Id; 2]) -> Id {
        match self.node(f) {
            Node::Const(_) | Node::Var(_) => unreachable!("a leaf has no operands"),
            // f = a + b: df = da + db
            Node::Add(_) => self.add(da, db),
            // f = a - b: df = da - db
            Node::Sub(_) => self.sub(da, db),
            // f = a b: df = da b + a db
            Node::Mul([a, b]) => {
                let t = self.mul(da, b);
                let u = self.mul(a, db);
                self.add(t, u)
            }
            // f = a / b: df = (da - f db) / b
            Node::Div([_, b]) => {
                let t = self.mul(f, db);
                let n = self.sub(da, t);
                self.div(n, b)
            }
            // f = -a: df = -da
            Node::Neg(_) => self.neg(da),
            // f = a^n: df = n a^(n-1) da
            Node::Powi(a, n) => {
                let p = match n.checked_sub(1) {
                    Some(m) => self.powi(a, m),
                    None => {
                        let m = self.constant(f64::from(n) - 1.0);
                        self.pow(a, m)
                    }
                };
                let c = self.constant(f64::from(n));
                let t = self.mul(c, p);
                self.mul(t, da)
            }
            Node::Pow([a, b]) => self.pow_tangent(f, [a, b], [da, db]),
            Node::Func(func, a) => self.diff_func(func, f, a, da),
            // f = atan2(y, x): df = (x dy - y dx) / (x^2 + y^2)
            Node::Atan2([y, x]) => {
                let (dy, dx) = (da, db);
                let t = self.mul(x, dy);
                let u = self.mul(y, dx);
                let n = self.sub(t, u);
                let x2 = self.powi(x, 2);
                let y2 = self.powi(y, 2);
                let r2 = self.add(x2, y2);
                self.div(n, r2)
            }
        }
    }

    /// `f = a^b`: `df = b a^(b-1) da + f ln(a) db` (second term dropped
    /// when `db` is zero, first when `da` is).
    fn pow_tangent(&mut self, f: Id, [a, b]: [Id; 2], [da, db]: [Id; 2]) -> Id {
        let mut df = self.constant(0.0);
        if !self.is_zero(da) {
            let one = self.constant(1.0);
            let bm1 = self.sub(b, one);
            let p = self.pow(a, bm1);
            let t = self.mul(b, p);
            df = self.mul(t, da);
        }
        if !self.is_zero(db) {
            let l = self.ln(a);
            let t = self.mul(f, l);
            let t = self.mul(t, db);
            df = self.add(df, t);
        }
        df
    }

    /// The derivative of `f = func(a)` given `da`.
    fn diff_func(&mut self, func: Func, f: Id, a: Id, da: Id) -> Id {
        match func {
            // f = sqrt(a): df = da / (2 f)
            Func::Sqrt => {
                let two = self.constant(2.0);
                let t = self.mul(two, f);
                self.div(da, t)
            }
            // f = exp(a): df = f da
            Func::Exp => self.mul(f, da),
            // f = ln(a): df = da / a
            Func::Ln => self.div(da, a),
            // f = sin(a): df = cos(a) da
            Func::Sin => {
                let c = self.cos(a);
                self.mul(c, da)
            }
            // f = cos(a): df = -sin(a) da
            Func::Cos => {
                let s = self.sin(a);
                let t = self.mul(s, da);
                self.neg(t)
            }
            // f = tan(a): df = (1 + f^2) da
            Func::Tan => {
                let one = self.constant(1.0);
                let f2 = self.powi(f, 2);
                let t = self.add(one, f2);
                self.mul(t, da)
            }
            // f = sinh(a): df = cosh(a) da
            Func::Sinh => {
                let c = self.cosh(a);
                self.mul(c, da)
            }
            // f = cosh(a): df = sinh(a) da
            Func::Cosh => {
                let s = self.sinh(a);
                self.mul(s, da)
            }
            // f = tanh(a): df = (1 - f^2) da
            Func::Tanh => {
                let one = self.constant(1.0);
                let f2 = self.powi(f, 2);
                let t = self.sub(one, f2);
                self.mul(t, da)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Rng;

    const X: VarId = VarId(0);

    /// Builds an expression of `x` and `y`.
    type Build<'a> = &'a dyn Fn(&mut Graph, Id, Id) -> Id;
    const Y: VarId = VarId(1);

    /// Checks `∂e/∂wrt` against a central finite difference and, when given,
    /// against a closed form, at `n` random points of `[lo, hi]²`.
    fn check(
        build: impl Fn(&mut Graph, Id, Id) -> Id,
        closed: Option<Build<'_>>,
        wrt: VarId,
        lo: f64,
        hi: f64,
    ) {
        let mut g = Graph::new();
        let x = g.var(X);
        let y = g.var(Y);
        let e = build(&mut g, x, y);
        let d = g.diff(e, wrt);
        let want = closed.map(|c| c(&mut g, x, y));
        let mut rng = Rng::new(0x5eed ^ u64::from(wrt.0));
        for _ in 0..20 {
            let p = [rng.uniform(lo, hi), rng.uniform(lo, hi)];
            let got = g.eval(&[d], &p)[0];
            let h = 1e-6 * (1.0 + p[wrt.index()].abs());
            let (mut pp, mut pm) = (p, p);
            pp[wrt.index()] += h;
            pm[wrt.index()] -= h;
            let fd = (g.eval(&[e], &pp)[0] - g.eval(&[e], &pm)[0]) / (2.0 * h);
            let scale = 1.0 + got.abs();
            assert!(
                (got - fd).abs() <= 1e-6 * scale,
                "{}: d/d{wrt} = {got}, finite difference {fd} at {p:?}",
                g.to_infix(e, &|v| ["x", "y"][v.index()].into())
            );
            if let Some(want) = want {
                let w = g.eval(&[want], &p)[0];
                assert!(
                    (got - w).abs() <= 1e-12 * (1.0 + w.abs()),
                    "closed form {w}, got {got} at {p:?}"
                );
            }
        }
    }

    #[test]
    fn derivative_of_add_sub_mul_div() {
        check(|g, x, y| g.add(x, y), None, X, -2.0, 2.0);
        check(|g, x, y| g.sub(x, y), None, Y, -2.0, 2.0);
        check(|g, x, y| g.mul(x, y), Some(&|_, _, y| y), X, -2.0, 2.0);
        check(
            |g, x, y| {
                let s = g.sin(x);
                g.mul(s, y)
            },
            None,
            X,
            -2.0,
            2.0,
        );
        // d(x/y)/dy = -x / y^2
        check(
            |g, x, y| g.div(x, y),
            Some(&|g, x, y| {
                let y2 = g.powi(y, 2);
                let q = g.div(x, y2);
                g.neg(q)
            }),
            Y,
            0.5,
            2.0,
        );
        check(|g, x, y| g.div(x, y), None, X, 0.5, 2.0);
        check(
            |g, x, _| {
                let s = g.sin(x);
                g.div(s, x)
            },
            None,
            X,
            0.5,
            2.0,
        );
    }

    #[test]
    fn derivative_of_neg_and_powers() {
        check(|g, x, _| g.neg(x), None, X, -2.0, 2.0);
        for n in [-3, -1, 2, 3, 7] {
            // d x^n = n x^(n-1)
            check(
                move |g, x, _| g.powi(x, n),
                Some(&move |g, x, _| {
                    let c = g.constant(f64::from(n));
                    let p = g.powi(x, n - 1);
                    g.mul(c, p)
                }),
                X,
                0.5,
                2.0,
            );
        }
        // d x^y / dx = y x^(y-1), d x^y / dy = x^y ln x
        check(|g, x, y| g.pow(x, y), None, X, 0.5, 2.0);
        check(
            |g, x, y| g.pow(x, y),
            Some(&|g, x, y| {
                let p = g.pow(x, y);
                let l = g.ln(x);
                g.mul(p, l)
            }),
            Y,
            0.5,
            2.0,
        );
        check(
            |g, x, _| {
                let e = g.constant(1.5);
                g.pow(x, e)
            },
            Some(&|g, x, _| {
                let s = g.sqrt(x);
                let c = g.constant(1.5);
                g.mul(c, s)
            }),
            X,
            0.5,
            2.0,
        );
        check(
            |g, _, y| {
                let two = g.constant(2.0);
                g.pow(two, y)
            },
            None,
            Y,
            -2.0,
            2.0,
        );
    }

    #[test]
    fn derivative_of_each_function() {
        type Closed = fn(&mut Graph, Id, Id) -> Id;
        let closed: [(Func, Closed, f64, f64); 9] = [
            (
                Func::Sqrt,
                |g, x, _| {
                    let s = g.sqrt(x);
                    let two = g.constant(2.0);
                    let d = g.mul(two, s);
                    let one = g.constant(1.0);
                    g.div(one, d)
                },
                0.5,
                3.0,
            ),
            (Func::Exp, |g, x, _| g.exp(x), -2.0, 2.0),
            (
                Func::Ln,
                |g, x, _| {
                    let one = g.constant(1.0);
                    g.div(one, x)
                },
                0.5,
                3.0,
            ),
            (Func::Sin, |g, x, _| g.cos(x), -3.0, 3.0),
            (
                Func::Cos,
                |g, x, _| {
                    let s = g.sin(x);
                    g.neg(s)
                },
                -3.0,
                3.0,
            ),
            (
                Func::Tan,
                |g, x, _| {
                    let c = g.cos(x);
                    g.powi(c, -2)
                },
                -1.2,
                1.2,
            ),
            (Func::Sinh, |g, x, _| g.cosh(x), -2.0, 2.0),
            (Func::Cosh, |g, x, _| g.sinh(x), -2.0, 2.0),
            (
                Func::Tanh,
                |g, x, _| {
                    let c = g.cosh(x);
                    g.powi(c, -2)
                },
                -2.0,
                2.0,
            ),
        ];
        for (f, c, lo, hi) in closed {
            check(move |g, x, _| g.func(f, x), Some(&c), X, lo, hi);
            // chain rule through an inner function of both variables
            check(
                move |g, x, y| {
                    let p = g.mul(x, y);
                    let p = g.mul(p, y);
                    g.func(f, p)
                },
                None,
                Y,
                0.5,
                1.0,
            );
        }
    }

    #[test]
    fn derivative_of_atan2() {
        // d atan2(y, x) = (x dy - y dx) / (x^2 + y^2)
        let closed_dy: Build<'_> = &|g, x, y| {
            let x2 = g.powi(x, 2);
            let y2 = g.powi(y, 2);
            let r = g.add(x2, y2);
            g.div(x, r)
        };
        check(|g, x, y| g.atan2(y, x), Some(closed_dy), Y, -2.0, 2.0);
        check(|g, x, y| g.atan2(y, x), None, X, -2.0, 2.0);
    }

    #[test]
    fn derivative_reuses_nodes() {
        let mut g = Graph::new();
        let x = g.var(X);
        let e = g.exp(x);
        assert_eq!(g.diff(e, X), e);
        let s = g.sqrt(x);
        let n = g.len();
        let d = g.diff(s, X);
        // 2 and 2 sqrt(x) and 1 / (2 sqrt(x)): three new nodes, sqrt reused
        assert!(g.len() <= n + 3, "{}", g.len() - n);
        assert_eq!(g.eval(&[d], &[4.0]), vec![0.25]);
    }

    #[test]
    fn derivative_memoized_across_calls() {
        let mut g = Graph::new();
        let x = g.var(X);
        let y = g.var(Y);
        let s = g.sin(x);
        let e = g.mul(s, y);
        let d1 = g.diff(e, X);
        let n = g.len();
        assert_eq!(g.diff(e, X), d1);
        assert_eq!(g.len(), n);
        // the same expression built again is the same node, same derivative
        let s2 = g.sin(x);
        let e2 = g.mul(y, s2);
        assert_eq!(g.diff(e2, X), d1);
    }

    #[test]
    fn second_derivatives_of_a_quadratic_form() {
        // T = 0.5 m v^2: dT/dv = m v, d2T/dv2 = m
        let mut g = Graph::new();
        let m = g.var(VarId(0));
        let v = g.var(VarId(1));
        let half = g.constant(0.5);
        let hm = g.mul(half, m);
        let v2 = g.powi(v, 2);
        let t = g.mul(hm, v2);
        let p = g.diff(t, VarId(1));
        assert_eq!(p, g.mul(m, v));
        assert_eq!(g.diff(p, VarId(1)), m);
    }

    #[test]
    fn deep_expression_does_not_overflow_the_stack() {
        let mut g = Graph::new();
        let x = g.var(X);
        let mut e = x;
        for _ in 0..100_000 {
            let s = g.sin(e);
            e = g.add(s, x);
        }
        let d = g.diff(e, X);
        assert!(g.eval(&[d], &[0.1])[0].is_finite());
    }
}
