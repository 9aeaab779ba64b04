//! The symbolic engine behind moreau's model compiler.
//!
//! `moreau-macro` builds a model's expressions into a [`Graph`], derives the
//! mechanics with [`Mechanics::derive`] and lowers the results to one
//! [`Schedule`], which it prints as straight-line Rust. This crate has no
//! dependencies and knows nothing of `syn` or YAML.
//!
//! | module | job |
//! |---|---|
//! | [`node`] | [`Node`], [`Id`], [`VarId`], [`Func`], [`Op`]: the vocabulary |
//! | [`graph`] | [`Graph`]: hash-consed arena, simplifying builders, queries |
//! | [`diff`] | [`Graph::diff`]: exact derivatives, one rule per node |
//! | [`reverse`] | [`Graph::gradient_reverse`]: a gradient by one adjoint sweep |
//! | [`eval`] | [`Graph::eval`]: the reference interpreter |
//! | [`mechanics`] | [`Mechanics::derive`]: `M`, `C`, `G`, `F`, `J` and their derivatives from `T`, `V`, `Q`, `h`; [`Layout`], the one list of outputs |
//! | [`schedule`] | [`Schedule`]: one CSE'd instruction list for all outputs |
//!
//! ```
//! use moreau_sym::{Graph, Lagrangian, Mechanics, Quantity, Schedule, VarId};
//!
//! // A pendulum: q = th, v = w, parameters m, l, g.
//! let (th, w, m, l, g) = (VarId(0), VarId(1), VarId(2), VarId(3), VarId(4));
//! let mut gr = Graph::new();
//! let (the, we, me, le, ge) = (gr.var(th), gr.var(w), gr.var(m), gr.var(l), gr.var(g));
//! // T = 0.5 m l² w², V = -m g l cos th
//! let half = gr.constant(0.5);
//! let l2 = gr.powi(le, 2);
//! let w2 = gr.powi(we, 2);
//! let ml2 = gr.mul(me, l2);
//! let t = gr.mul(ml2, w2);
//! let t = gr.mul(half, t);
//! let mg = gr.mul(me, ge);
//! let mgl = gr.mul(mg, le);
//! let c = gr.cos(the);
//! let v = gr.mul(mgl, c);
//! let v = gr.neg(v);
//! let sys = Lagrangian { q: &[th], v: &[w], kinetic: t, potential: v, applied: &[], gaps: &[] };
//! let mech = Mechanics::derive(&mut gr, &sys).unwrap();
//!
//! let fused = Schedule::new(&gr, &mech.outputs());
//! // the fused evaluation: M, C, G, F (the pendulum has no gaps)
//! let sched = fused.restrict(&mech.layout().indices(&Quantity::EVAL));
//! let names = |v: VarId| ["th", "w", "m", "l", "g"][v.index()].to_string();
//! assert_eq!(
//!     sched.listing(&names),
//!     "t0 = powi(l, 2)\nt1 = t0 * m\nt2 = m * l\nt3 = t2 * g\nt4 = sin(th)\nt5 = t3 * t4\n\
//!      out[0] = t1\nout[1] = 0.0\nout[2] = t5\nout[3] = t5\n"
//! );
//! ```

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod diff;
pub mod eval;
pub mod graph;
pub mod mechanics;
pub mod node;
pub mod reverse;
pub mod schedule;
#[cfg(test)]
mod testing;

pub use graph::Graph;
pub use mechanics::{Lagrangian, Layout, Mechanics, MechanicsError, Quantity, Recursive, Slot};
pub use node::{Func, Function, Id, Node, Op, VarId};
pub use schedule::{Instr, Operand, Schedule};
