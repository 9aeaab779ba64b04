//! Reverse-mode (adjoint) differentiation.
//!
//! [`Graph::diff`] is forward mode: one sweep per variable, each node's
//! derivative from its operands' ([`Graph::gradient`] over `n` variables is
//! `n` sweeps). Reverse mode sweeps once from the output down: the adjoint
//! `ē = ∂e/∂node` of every node under `e`, starting from `1` at `e`, each
//! node passing `ē ∂f/∂a` to each operand `a` and each operand summing what
//! its users pass. The adjoint of variable `v` is `∂e/∂v`. One sweep gives
//! the whole gradient, so for one output of many inputs (a gap `h(q)` of a
//! long chain) it builds far fewer nodes than `n` forward sweeps; for many
//! outputs of few inputs forward mode is the cheaper one (CasADi's
//! `jacobian` chooses from its estimates of the forward and adjoint sweeps
//! each mode needs, weighted by its `ad_weight` option).
//!
//! The local partials are the forward formulas of [`Graph::diff`] (one
//! function, `Graph::tangent`, serves both): the differential `df` is linear
//! in the operands' differentials, so `df` with `da = ē` and `db = 0` is
//! `ē ∂f/∂a`. Adjoints depend on the output, so they are not kept in the
//! graph's derivative cache; within a sweep each node is visited once, and
//! hash-consing shares equal terms between sweeps.

use std::collections::{HashMap, HashSet};

use crate::graph::Graph;
use crate::node::{Id, Node, VarId};

impl Graph {
    /// The gradient `[∂e/∂wrt[0], ∂e/∂wrt[1], ...]` by one reverse sweep: the
    /// same values as [`Graph::gradient`] up to rounding, usually in fewer
    /// operations when `wrt` is long (see the [module docs](self)).
    ///
    /// An entry is the constant `0` when `e` does not depend on that
    /// variable. Iterative (no recursion), so deep expressions cannot
    /// overflow the stack.
    ///
    /// ```
    /// use moreau_sym::{Graph, Schedule, VarId};
    /// let mut g = Graph::new();
    /// let vars: Vec<VarId> = (0..8).map(VarId).collect();
    /// let mut p = g.constant(1.0);
    /// for &v in &vars {
    ///     let x = g.var(v);
    ///     p = g.mul(p, x); // x0 x1 ... x7
    /// }
    /// let reverse = g.gradient_reverse(p, &vars);
    /// let forward = g.gradient(p, &vars);
    /// let at: Vec<f64> = (1..=8).map(f64::from).collect();
    /// assert_eq!(g.eval(&reverse, &at), g.eval(&forward, &at)); // 8! / k
    /// let ops = |outs: &[_]| Schedule::new(&g, outs).op_count();
    /// assert!(ops(&reverse) < ops(&forward));
    /// ```
    pub fn gradient_reverse(&mut self, e: Id, wrt: &[VarId]) -> Vec<Id> {
        let zero = self.constant(0.0);
        let one = self.constant(1.0);
        let mut grad = vec![zero; wrt.len()];
        let mut adjoint: HashMap<Id, Id> = HashMap::from([(e, one)]);
        for f in self.cone(e, wrt) {
            let Some(&bar) = adjoint.get(&f) else {
                continue;
            };
            if self.is_zero(bar) {
                continue;
            }
            let node = self.node(f);
            if let Node::Var(v) = node {
                for (k, _) in wrt.iter().enumerate().filter(|&(_, &w)| w == v) {
                    grad[k] = bar;
                }
                continue;
            }
            // Each distinct operand depending on `wrt` receives
            // `bar ∂f/∂a` (both seeds at once when both operands are `a`).
            let children = node.children();
            for (i, &a) in children.iter().enumerate() {
                if children[..i].contains(&a) || !self.depends_on_any(a, wrt) {
                    continue;
                }
                let mut seed = [zero; 2];
                for (s, &c) in seed.iter_mut().zip(children) {
                    if c == a {
                        *s = bar;
                    }
                }
                let term = self.tangent(f, seed);
                let sum = match adjoint.get(&a) {
                    Some(&acc) => self.add(acc, term),
                    None => term,
                };
                adjoint.insert(a, sum);
            }
        }
        grad
    }

    /// The Jacobian matrix by reverse mode, row `i` the
    /// [`gradient_reverse`](Graph::gradient_reverse) of `es[i]`: one sweep
    /// per output, the cheaper mode when outputs are fewer than inputs.
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let y = g.var(VarId(1));
    /// let s = g.mul(x, y);
    /// let zero = g.constant(0.0);
    /// assert_eq!(g.jacobian_reverse(&[s, y], &[VarId(0), VarId(1)])[0], vec![y, x]);
    /// assert_eq!(g.jacobian_reverse(&[x], &[VarId(1)]), vec![vec![zero]]);
    /// ```
    pub fn jacobian_reverse(&mut self, es: &[Id], wrt: &[VarId]) -> Vec<Vec<Id>> {
        es.iter().map(|&e| self.gradient_reverse(e, wrt)).collect()
    }

    /// Whether `id` depends on any of `vars`.
    fn depends_on_any(&self, id: Id, vars: &[VarId]) -> bool {
        vars.iter().any(|&v| self.depends_on(id, v))
    }

    /// The nodes under `e` that depend on `wrt`, users before operands
    /// (decreasing id: every operand comes before its users in the arena).
    fn cone(&self, e: Id, wrt: &[VarId]) -> Vec<Id> {
        let mut cone = Vec::new();
        let mut seen = HashSet::new();
        let mut stack = vec![e];
        while let Some(id) = stack.pop() {
            if !seen.insert(id) || !self.depends_on_any(id, wrt) {
                continue;
            }
            cone.push(id);
            stack.extend_from_slice(self.node(id).children());
        }
        cone.sort_unstable_by(|a, b| b.cmp(a));
        cone
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Schedule;
    use crate::testing::Rng;

    /// Random expressions of `vars` variables: `size` nodes, each a random
    /// operation on two earlier ones (or a variable), every operation kind
    /// the tangent formulas cover, on values where all are defined.
    fn random_expr(g: &mut Graph, rng: &mut Rng, vars: u32, size: usize) -> Id {
        let mut pool: Vec<Id> = (0..vars).map(|v| g.var(VarId(v))).collect();
        for _ in 0..size {
            let pick = |rng: &mut Rng, pool: &[Id]| {
                pool[(rng.uniform(0.0, pool.len() as f64) as usize).min(pool.len() - 1)]
            };
            let (a, b) = (pick(rng, &pool), pick(rng, &pool));
            let e = match (rng.uniform(0.0, 10.0)) as u32 {
                0 => g.add(a, b),
                1 => g.sub(a, b),
                2 | 3 => g.mul(a, b),
                4 => {
                    // a / (2 + b^2): no division by zero
                    let two = g.constant(2.0);
                    let b2 = g.powi(b, 2);
                    let d = g.add(two, b2);
                    g.div(a, d)
                }
                5 => g.sin(a),
                6 => g.cos(a),
                7 => g.atan2(a, b),
                8 => {
                    // (1 + a^2)^(0.1 b): pow with both operands variable
                    let one = g.constant(1.0);
                    let a2 = g.powi(a, 2);
                    let base = g.add(one, a2);
                    let k = g.constant(0.1);
                    let ex = g.mul(k, b);
                    g.pow(base, ex)
                }
                _ => g.neg(a),
            };
            pool.push(e);
        }
        let last = pool.len() - 1;
        pool[last]
    }

    #[test]
    fn reverse_agrees_with_forward_on_random_expressions() {
        let mut rng = Rng::new(0xad70);
        for trial in 0..40 {
            let mut g = Graph::new();
            let e = random_expr(&mut g, &mut rng, 5, 30);
            let wrt: Vec<VarId> = (0..6).map(VarId).collect(); // VarId(5) unused
            let rev = g.gradient_reverse(e, &wrt);
            let fwd = g.gradient(e, &wrt);
            assert!(g.is_zero(rev[5]));
            for _ in 0..5 {
                let p: Vec<f64> = (0..6).map(|_| rng.uniform(-1.5, 1.5)).collect();
                let (r, f) = (g.eval(&rev, &p), g.eval(&fwd, &p));
                for (k, (r, f)) in r.iter().zip(&f).enumerate() {
                    assert!(
                        (r - f).abs() <= 1e-10 * (1.0 + f.abs()),
                        "trial {trial}, d/dx{k}: reverse {r}, forward {f}"
                    );
                }
            }
        }
    }

    #[test]
    fn repeated_operand_gets_both_partials() {
        // x / x is not simplified: its derivative is 0; x^x is x^x (1 + ln x)
        let mut g = Graph::new();
        let x = g.var(VarId(0));
        let q = g.div(x, x);
        let d = g.gradient_reverse(q, &[VarId(0)]);
        assert_eq!(g.eval(&d, &[1.7]), vec![0.0]);
        let p = g.pow(x, x);
        let d = g.gradient_reverse(p, &[VarId(0)]);
        let want = 1.7f64.powf(1.7) * (1.0 + 1.7f64.ln());
        assert!((g.eval(&d, &[1.7])[0] - want).abs() < 1e-12);
    }

    #[test]
    fn repeated_variable_in_wrt_gets_the_same_entry() {
        let mut g = Graph::new();
        let x = g.var(VarId(0));
        let s = g.sin(x);
        let c = g.cos(x);
        assert_eq!(g.gradient_reverse(s, &[VarId(0), VarId(0)]), vec![c, c]);
    }

    #[test]
    fn one_sweep_is_linear_in_the_chain_length() {
        // sin(sin(... sin(x0 + x1 + ... + x_{n-1}))): forward mode
        // differentiates the whole chain of sines once per variable (the
        // cosines are shared, the products are not): ~n² operations; one
        // reverse sweep: ~n, each ∂/∂x_k is the same adjoint.
        let n = 40;
        let mut g = Graph::new();
        let vars: Vec<VarId> = (0..n).map(VarId).collect();
        let mut e = g.var(vars[0]);
        for &v in &vars[1..] {
            let x = g.var(v);
            e = g.add(e, x);
            e = g.sin(e);
        }
        let rev = g.gradient_reverse(e, &vars);
        let fwd = g.gradient(e, &vars);
        let ops = |g: &Graph, outs: &[Id]| Schedule::new(g, outs).op_count();
        let (r, f) = (ops(&g, &rev), ops(&g, &fwd));
        assert!(r < 6 * n as usize, "reverse {r}");
        assert!(f > n as usize * n as usize / 4, "forward {f}");
        let p: Vec<f64> = (0..n).map(|k| 0.01 * f64::from(k)).collect();
        assert_eq!(g.eval(&rev, &p).len(), n as usize);
        for (r, f) in g.eval(&rev, &p).iter().zip(g.eval(&fwd, &p)) {
            assert!((r - f).abs() <= 1e-12 * (1.0 + f.abs()), "{r} vs {f}");
        }
    }

    #[test]
    fn deep_expression_does_not_overflow_the_stack() {
        let mut g = Graph::new();
        let x = g.var(VarId(0));
        let y = g.var(VarId(1));
        let mut e = x;
        for _ in 0..100_000 {
            let s = g.sin(e);
            e = g.add(s, y);
        }
        let d = g.gradient_reverse(e, &[VarId(0), VarId(1)]);
        let v = g.eval(&d, &[0.1, 0.2]);
        assert!(v.iter().all(|v| v.is_finite()), "{v:?}");
    }
}
