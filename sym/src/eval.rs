//! A reference interpreter over the graph.
//!
//! The test oracle for everything else: derivative checks, the schedule's own
//! interpreter (which must agree bit for bit, since both evaluate every
//! operation through [`Op::apply`]) and the macro's tests of
//! generated code.

use crate::graph::Graph;
use crate::node::{Id, Node, Op};

impl Graph {
    /// Evaluates `outputs` with variable `VarId(k)` set to `vars[k]`.
    ///
    /// Only the nodes the outputs need are evaluated, in arena order, each
    /// once, with Rust's `f64` operations ([`Op::apply`]).
    ///
    /// # Panics
    /// If an output needs a variable `VarId(k)` with `k >= vars.len()`.
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let y = g.var(VarId(1));
    /// let s = g.add(x, y);
    /// let p = g.mul(x, y);
    /// assert_eq!(g.eval(&[s, p, x], &[2.0, 5.0]), vec![7.0, 10.0, 2.0]);
    /// ```
    #[must_use]
    pub fn eval(&self, outputs: &[Id], vars: &[f64]) -> Vec<f64> {
        let Some(last) = outputs.iter().max() else {
            return Vec::new();
        };
        // Mark the needed nodes: walking the arena downwards, a node is needed
        // when an output or a needed parent uses it.
        let mut needed = vec![false; last.index() + 1];
        for &o in outputs {
            needed[o.index()] = true;
        }
        for i in (0..needed.len()).rev() {
            if needed[i] {
                for c in self.nodes()[i].children() {
                    needed[c.index()] = true;
                }
            }
        }
        let mut values = vec![0.0; needed.len()];
        for (i, &node) in self.nodes()[..needed.len()].iter().enumerate() {
            if !needed[i] {
                continue;
            }
            values[i] = match node {
                Node::Const(bits) => f64::from_bits(bits),
                Node::Var(v) => *vars.get(v.index()).unwrap_or_else(|| {
                    panic!("variable {v} needed but only {} values given", vars.len())
                }),
                _ => {
                    let op: Op = node.op().expect("non-leaf nodes have an operation");
                    let args = node.children();
                    let a = values[args[0].index()];
                    let b = args.get(1).map_or(0.0, |b| values[b.index()]);
                    op.apply(a, b)
                }
            };
        }
        outputs.iter().map(|o| values[o.index()]).collect()
    }
}

#[cfg(test)]
mod tests {
    use crate::graph::Graph;
    use crate::node::VarId;

    #[test]
    fn eval_skips_unneeded_variables() {
        let mut g = Graph::new();
        let x = g.var(VarId(0));
        let y = g.var(VarId(5));
        let _unused = g.sin(y);
        let e = g.cos(x);
        // VarId(5) is not needed, so two values are not too few
        assert_eq!(g.eval(&[e], &[0.0]), vec![1.0]);
        assert!(g.eval(&[], &[]).is_empty());
    }

    #[test]
    #[should_panic(expected = "variable x5 needed")]
    fn eval_reports_missing_variable() {
        let mut g = Graph::new();
        let y = g.var(VarId(5));
        let _ = g.eval(&[y], &[0.0]);
    }

    #[test]
    fn eval_every_operation() {
        let mut g = Graph::new();
        let x = g.var(VarId(0));
        let y = g.var(VarId(1));
        let outs = [
            g.add(x, y),
            g.sub(x, y),
            g.mul(x, y),
            g.div(x, y),
            g.neg(x),
            g.powi(x, 3),
            g.pow(x, y),
            g.sqrt(x),
            g.atan2(y, x),
        ];
        let (a, b) = (1.7f64, 0.3f64);
        let want = [
            a + b,
            a - b,
            a * b,
            a / b,
            -a,
            a.powi(3),
            a.powf(b),
            a.sqrt(),
            b.atan2(a),
        ];
        assert_eq!(g.eval(&outs, &[a, b]), want);
    }
}
