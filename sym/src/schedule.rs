//! One flat instruction list for a set of outputs (CasADi's `SXFunction`
//! algorithm).
//!
//! [`Schedule::new`] sorts the graph from the outputs: a depth-first walk,
//! outputs in order and operands left to right, emits each needed operation
//! once, after its operands. Hash-consing already merged equal
//! subexpressions, so this list is the CSE'd evaluation; nodes no output
//! needs are left out, and constants and variables are operands, not
//! instructions. The order depends only on the graph and the outputs, never on
//! hash-map iteration, so the same model always gives the same list.
//!
//! Everything downstream walks this list: the emitter (which inlines
//! temporaries used once, see [`Schedule::uses`]), the operation counter
//! ([`Schedule::op_count`]), the interpreter ([`Schedule::eval`]) and the
//! listing ([`Schedule::listing`]). Per-quantity evaluations are cut from the
//! fused list with [`Schedule::restrict`].

use core::fmt;

use crate::graph::Graph;
use crate::node::{Id, Node, Op, VarId};

/// An operand of an instruction or an output.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Operand {
    /// A constant (the emitter writes a literal).
    Const(f64),
    /// A variable, read from the inputs.
    Var(VarId),
    /// The result of instruction number `k`.
    Tmp(u32),
}

/// One operation: `op` applied to [`operands`](Instr::operands).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instr {
    /// The operation.
    pub op: Op,
    /// The operands; only the first [`op.arity()`](Op::arity) count, the
    /// second of a unary operation is `Operand::Const(0.0)`.
    pub args: [Operand; 2],
}

impl Instr {
    /// The operands that count (one or two).
    #[must_use]
    pub fn operands(&self) -> &[Operand] {
        &self.args[..self.op.arity()]
    }
}

/// A straight-line program computing a list of outputs.
///
/// ```
/// use moreau_sym::{Graph, Operand, Schedule, VarId};
/// let mut g = Graph::new();
/// let x = g.var(VarId(0));
/// let y = g.var(VarId(1));
/// let s = g.sin(x);
/// let a = g.mul(s, y); // y sin x
/// let b = g.add(s, y); // sin x + y
/// let zero = g.constant(0.0);
/// let sched = Schedule::new(&g, &[a, b, zero, x]);
/// assert_eq!(sched.op_count(), 3); // sin shared
/// assert_eq!(sched.outputs[2], Operand::Const(0.0));
/// assert_eq!(sched.eval(&[1.0, 2.0]), g.eval(&[a, b, zero, x], &[1.0, 2.0]));
/// assert_eq!(
///     sched.to_string(),
///     "t0 = sin(x0)\nt1 = t0 * x1\nt2 = t0 + x1\nout[0] = t1\nout[1] = t2\nout[2] = 0.0\nout[3] = x0\n"
/// );
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    /// The instructions, in execution order; instruction `k` defines
    /// `Operand::Tmp(k)` and uses only earlier temporaries.
    pub instrs: Vec<Instr>,
    /// The outputs, in the order asked for.
    pub outputs: Vec<Operand>,
}

impl Schedule {
    /// Lowers `outputs` of `g` to one instruction list.
    #[must_use]
    pub fn new(g: &Graph, outputs: &[Id]) -> Schedule {
        const NONE: u32 = u32::MAX;
        let mut tmp = vec![NONE; g.len()];
        let mut instrs = Vec::new();
        let operand = |tmp: &[u32], id: Id| match g.node(id) {
            Node::Const(bits) => Operand::Const(f64::from_bits(bits)),
            Node::Var(v) => Operand::Var(v),
            _ => Operand::Tmp(tmp[id.index()]),
        };
        // Iterative post-order: (node, operands already pushed).
        let mut stack: Vec<(Id, bool)> = Vec::new();
        for &out in outputs {
            stack.push((out, false));
            while let Some((id, expanded)) = stack.pop() {
                let node = g.node(id);
                let Some(op) = node.op() else { continue };
                if tmp[id.index()] != NONE {
                    continue;
                }
                if expanded {
                    let mut args = [Operand::Const(0.0); 2];
                    for (arg, &c) in args.iter_mut().zip(node.children()) {
                        *arg = operand(&tmp, c);
                    }
                    tmp[id.index()] = u32::try_from(instrs.len()).expect("too many instructions");
                    instrs.push(Instr { op, args });
                } else {
                    stack.push((id, true));
                    for &c in node.children().iter().rev() {
                        stack.push((c, false));
                    }
                }
            }
        }
        let outputs = outputs.iter().map(|&o| operand(&tmp, o)).collect();
        Schedule { instrs, outputs }
    }

    /// The number of arithmetic instructions: every `Add`, `Sub`, `Mul`,
    /// `Div`, `Neg`, `Powi`, `Pow`, elementary function and `Atan2` counts
    /// one; constants, inputs and outputs count nothing. Comparable with
    /// CasADi's `n_instructions()` less its `OP_CONST`, `OP_INPUT` and
    /// `OP_OUTPUT` instructions.
    #[must_use]
    pub fn op_count(&self) -> usize {
        self.instrs.len()
    }

    /// How many times each temporary is used, by instructions and outputs
    /// together (`use_counts()[k]` is [`uses(k)`](Schedule::uses)).
    #[must_use]
    pub fn use_counts(&self) -> Vec<usize> {
        let mut counts = vec![0; self.instrs.len()];
        let args = self.instrs.iter().flat_map(Instr::operands);
        for a in args.chain(&self.outputs) {
            if let Operand::Tmp(t) = *a {
                counts[t as usize] += 1;
            }
        }
        counts
    }

    /// How many times temporary `tmp` is used, as an operand of an
    /// instruction or as an output. A temporary used once and not an output
    /// can be written inline in its consumer.
    ///
    /// ```
    /// use moreau_sym::{Graph, Schedule, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let s = g.sin(x);
    /// let p = g.mul(s, s); // sin(x)^2
    /// let q = g.add(p, s);
    /// let sched = Schedule::new(&g, &[q]);
    /// assert_eq!(sched.uses(0), 2); // sin x: in sin(x)^2 and in the sum
    /// assert_eq!(sched.uses(2), 1); // the sum: output 0
    /// ```
    #[must_use]
    pub fn uses(&self, tmp: u32) -> usize {
        let args = self.instrs.iter().flat_map(Instr::operands);
        args.chain(&self.outputs)
            .filter(|a| **a == Operand::Tmp(tmp))
            .count()
    }

    /// The schedule of the outputs numbered `outputs` (indices into
    /// [`Schedule::outputs`], in the order given): the instructions they
    /// need, in their original order, renumbered.
    ///
    /// # Panics
    /// If an index is out of range.
    ///
    /// ```
    /// use moreau_sym::{Graph, Schedule, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let s = g.sin(x);
    /// let c = g.cos(x);
    /// let full = Schedule::new(&g, &[s, c]);
    /// let cut = full.restrict(&[1]);
    /// assert_eq!(cut.op_count(), 1);
    /// assert_eq!(cut.eval(&[0.3]), vec![0.3f64.cos()]);
    /// ```
    #[must_use]
    pub fn restrict(&self, outputs: &[usize]) -> Schedule {
        let mut needed = vec![false; self.instrs.len()];
        for &o in outputs {
            if let Operand::Tmp(t) = self.outputs[o] {
                needed[t as usize] = true;
            }
        }
        for k in (0..self.instrs.len()).rev() {
            if needed[k] {
                for a in self.instrs[k].operands() {
                    if let Operand::Tmp(t) = *a {
                        needed[t as usize] = true;
                    }
                }
            }
        }
        let mut renumber = vec![u32::MAX; self.instrs.len()];
        let map = |renumber: &[u32], a: Operand| match a {
            Operand::Tmp(t) => Operand::Tmp(renumber[t as usize]),
            a => a,
        };
        let mut instrs = Vec::new();
        for (k, instr) in self.instrs.iter().enumerate() {
            if needed[k] {
                renumber[k] = instrs.len() as u32;
                let args = [map(&renumber, instr.args[0]), map(&renumber, instr.args[1])];
                instrs.push(Instr { op: instr.op, args });
            }
        }
        let outputs = outputs
            .iter()
            .map(|&o| map(&renumber, self.outputs[o]))
            .collect();
        Schedule { instrs, outputs }
    }

    /// Runs the list with variable `VarId(k)` set to `vars[k]`. Agrees bit
    /// for bit with [`Graph::eval`] on the outputs the schedule was built
    /// from: both apply [`Op::apply`] to the same operands.
    ///
    /// # Panics
    /// If the list reads a variable `VarId(k)` with `k >= vars.len()`.
    #[must_use]
    pub fn eval(&self, vars: &[f64]) -> Vec<f64> {
        let mut values = Vec::with_capacity(self.instrs.len());
        let read = |values: &[f64], a: Operand| match a {
            Operand::Const(c) => c,
            Operand::Var(v) => *vars.get(v.index()).unwrap_or_else(|| {
                panic!("variable {v} needed but only {} values given", vars.len())
            }),
            Operand::Tmp(t) => values[t as usize],
        };
        for instr in &self.instrs {
            let a = read(&values, instr.args[0]);
            let b = if instr.op.arity() == 2 {
                read(&values, instr.args[1])
            } else {
                0.0
            };
            values.push(instr.op.apply(a, b));
        }
        self.outputs.iter().map(|&o| read(&values, o)).collect()
    }

    /// A readable listing, one instruction per line (`t3 = sin(th1)`), then
    /// one line per output (`out[0] = t3`), variables named by `name`.
    ///
    /// ```
    /// use moreau_sym::{Graph, Schedule, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let e = g.powi(x, 3);
    /// let e = g.neg(e);
    /// let sched = Schedule::new(&g, &[e]);
    /// let names = |_: VarId| "th1".to_string();
    /// assert_eq!(sched.listing(&names), "t0 = powi(th1, 3)\nt1 = -t0\nout[0] = t1\n");
    /// ```
    #[must_use]
    pub fn listing(&self, name: &dyn Fn(VarId) -> String) -> String {
        use fmt::Write;
        let mut out = String::new();
        let show = |a: &Operand| match *a {
            Operand::Const(c) => format!("{c:?}"),
            Operand::Var(v) => name(v),
            Operand::Tmp(t) => format!("t{t}"),
        };
        for (k, instr) in self.instrs.iter().enumerate() {
            let a = show(&instr.args[0]);
            let b = show(&instr.args[1]);
            let rhs = match instr.op {
                Op::Neg => format!("-{a}"),
                Op::Powi(n) => format!("powi({a}, {n})"),
                Op::Pow => format!("pow({a}, {b})"),
                Op::Func(f) => format!("{f}({a})"),
                Op::Atan2 => format!("atan2({a}, {b})"),
                op => format!("{a} {} {b}", op.infix().unwrap_or("?")),
            };
            writeln!(out, "t{k} = {rhs}").expect("writing to a String cannot fail");
        }
        for (k, o) in self.outputs.iter().enumerate() {
            writeln!(out, "out[{k}] = {}", show(o)).expect("writing to a String cannot fail");
        }
        out
    }
}

impl fmt::Display for Schedule {
    /// The [`listing`](Schedule::listing) with variables named `x0`, `x1`, ...
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.listing(&|v| v.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::Quantity;
    use crate::testing::{ARM3, DOUBLE_PENDULUM, PARABOLA, Rng, Spec};

    /// Builds a model, derives it and schedules the fused outputs of
    /// `quantities`.
    fn fused(spec: &Spec, quantities: &[Quantity]) -> (Graph, Vec<Id>, Schedule, String) {
        let mut b = spec.build();
        let mech = b.derive().unwrap();
        let layout = mech.layout();
        let all = mech.outputs();
        let ids: Vec<Id> = layout
            .indices(quantities)
            .into_iter()
            .map(|k| all[k])
            .collect();
        let sched = Schedule::new(&b.g, &ids);
        let listing = sched.listing(&|v| b.name(v));
        (b.g, ids, sched, listing)
    }

    #[test]
    fn op_count_of_a_small_expression() {
        // (x + y) * sin(x + y) - 2 * x: add, sin, mul, mul, sub
        let mut g = Graph::new();
        let x = g.var(VarId(0));
        let y = g.var(VarId(1));
        let s = g.add(x, y);
        let sn = g.sin(s);
        let p = g.mul(s, sn);
        let two = g.constant(2.0);
        let t = g.mul(two, x);
        let e = g.sub(p, t);
        let sched = Schedule::new(&g, &[e, s]);
        assert_eq!(sched.op_count(), 5);
        assert_eq!(sched.uses(0), 3); // x + y: sin, product, output 1
        assert_eq!(sched.use_counts(), vec![3, 1, 1, 1, 1]);
        assert_eq!(
            sched.listing(&|v| ["x", "y"][v.index()].to_string()),
            "t0 = x + y\nt1 = sin(t0)\nt2 = t0 * t1\nt3 = 2.0 * x\nt4 = t2 - t3\n\
             out[0] = t4\nout[1] = t0\n"
        );
    }

    #[test]
    fn unneeded_nodes_are_not_scheduled() {
        let mut g = Graph::new();
        let x = g.var(VarId(0));
        let _ = g.exp(x);
        let c = g.cos(x);
        let sched = Schedule::new(&g, &[c, c]);
        assert_eq!(sched.op_count(), 1);
        assert_eq!(sched.outputs, vec![Operand::Tmp(0), Operand::Tmp(0)]);
    }

    #[test]
    fn schedule_is_deterministic() {
        let all = Quantity::EVAL;
        let (_, _, a, la) = fused(&ARM3, &all);
        let (_, _, b, lb) = fused(&ARM3, &all);
        assert_eq!(a, b);
        assert_eq!(la, lb);
        let (_, _, _, la) = fused(&DOUBLE_PENDULUM, &all);
        let (_, _, _, lb) = fused(&DOUBLE_PENDULUM, &all);
        assert_eq!(la, lb);
    }

    #[test]
    fn schedule_eval_matches_graph_eval_bit_for_bit() {
        for spec in [&DOUBLE_PENDULUM, &ARM3, &PARABOLA] {
            let (g, ids, sched, _) = fused(spec, &Quantity::EVAL);
            let nvars = g
                .nodes()
                .iter()
                .filter_map(|n| match n {
                    Node::Var(v) => Some(v.index() + 1),
                    _ => None,
                })
                .max()
                .unwrap();
            let mut rng = Rng::new(3);
            for _ in 0..10 {
                let vars: Vec<f64> = (0..nvars).map(|_| rng.uniform(-2.0, 2.0)).collect();
                let a: Vec<u64> = sched.eval(&vars).into_iter().map(f64::to_bits).collect();
                let b: Vec<u64> = g.eval(&ids, &vars).into_iter().map(f64::to_bits).collect();
                assert_eq!(a, b);
            }
        }
    }

    #[test]
    fn restrict_gives_the_same_values_as_full() {
        let (_, ids, sched, _) = fused(&ARM3, &Quantity::EVAL);
        let mut rng = Rng::new(5);
        let vars: Vec<f64> = (0..18).map(|_| rng.uniform(0.5, 2.0)).collect();
        let full = sched.eval(&vars);
        let subsets: [Vec<usize>; 4] = [
            (0..6).collect(),          // M
            vec![ids.len() - 1, 0, 7], // any order
            (6..15).rev().collect(),   // C, reversed
            (0..ids.len()).step_by(2).collect(),
        ];
        for subset in subsets {
            let cut = sched.restrict(&subset);
            assert!(cut.op_count() <= sched.op_count());
            let want: Vec<f64> = subset.iter().map(|&k| full[k]).collect();
            assert_eq!(cut.eval(&vars), want);
            // instructions keep their order and only use earlier ones
            for (k, instr) in cut.instrs.iter().enumerate() {
                for a in instr.operands() {
                    if let Operand::Tmp(t) = a {
                        assert!((*t as usize) < k);
                    }
                }
            }
        }
        let all: Vec<usize> = (0..ids.len()).collect();
        assert_eq!(sched.restrict(&all), sched);
    }

    /// Op counts of CasADi 3.8.2 on the same models (SX, `hessian` for M,
    /// Christoffel symbols from `jacobian` of M, `gradient`, `jacobian`;
    /// `Function` with `cse: true`; instructions other than `OP_CONST`,
    /// `OP_INPUT`, `OP_OUTPUT`): `(model, M C G F fused, all six fused)`.
    const CASADI: [(&str, usize, usize); 3] = [
        ("double_pendulum", 37, 49),
        ("arm3", 431, 439),
        ("parabola", 1, 6),
    ];

    #[test]
    fn fused_op_counts_at_most_casadis() {
        use Quantity::{Coriolis, Force, Gravity, Mass};
        for (spec, (name, casadi_mcgf, casadi_all)) in
            [&DOUBLE_PENDULUM, &ARM3, &PARABOLA].into_iter().zip(CASADI)
        {
            let mcgf = fused(spec, &[Mass, Coriolis, Gravity, Force]).2.op_count();
            let all = fused(spec, &Quantity::EVAL).2.op_count();
            assert!(
                mcgf <= casadi_mcgf,
                "{name}: M C G F {mcgf} > {casadi_mcgf}"
            );
            assert!(all <= casadi_all, "{name}: all {all} > {casadi_all}");
        }
    }

    #[test]
    fn double_pendulum_op_counts() {
        use Quantity::{Coriolis, Force, Gravity, Mass};
        let count = |q: &[Quantity]| fused(&DOUBLE_PENDULUM, q).2.op_count();
        // M: m1 + m2, l1^2, (m1 + m2) l1^2, m2 l1, m2 l1 l2, th1 - th2, cos,
        // m2 l1 l2 cos, l2^2, l2^2 m2.
        assert_eq!(count(&[Mass]), 10);
        // C: th1 - th2, sin, m2 l1, m2 l1 l2, m2 l1 l2 sin, C01 = · w2, · w1,
        // C10 = -(· w1).
        assert_eq!(count(&[Coriolis]), 8);
        assert_eq!(count(&[Mass, Coriolis, Gravity, Force]), 33);
        assert_eq!(count(&Quantity::EVAL), 45);
    }
}
