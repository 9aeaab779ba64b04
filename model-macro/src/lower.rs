//! Lowering: a checked [`ModelSpec`] becomes a symbolic graph, and the
//! mechanics (M, C, G, F, h, J) are derived on it with `moreau-sym`.
//!
//! Variables are numbered in one fixed layout ([`Layout`]): coordinates,
//! velocities, time, inputs, parameters. Definitions are not variables: each
//! is built once and its node reused wherever its name appears.

use moreau_sym::{Graph, Id, Lagrangian, Mechanics, MechanicsError, VarId};

use crate::ctxt::{Ctxt, Loc};
use crate::expr::{BinOp, Expr, ExprKind, Func};
use crate::spec::{ModelSpec, Symbol};

/// The numbering of the model's variables in the graph.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Layout {
    pub n: usize,
    pub inputs: usize,
}

/// What a graph variable stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Var {
    Coordinate(usize),
    Velocity(usize),
    Time,
    Input(usize),
    Parameter(usize),
}

impl Layout {
    fn of(spec: &ModelSpec) -> Layout {
        Layout {
            n: spec.dofs(),
            inputs: spec.inputs.len(),
        }
    }

    /// The graph variable of `var`.
    pub fn id(&self, var: Var) -> VarId {
        let n = self.n;
        let index = match var {
            Var::Coordinate(i) => i,
            Var::Velocity(i) => n + i,
            Var::Time => 2 * n,
            Var::Input(i) => 2 * n + 1 + i,
            Var::Parameter(i) => 2 * n + 1 + self.inputs + i,
        };
        VarId(index as u32)
    }

    /// What graph variable `id` stands for.
    pub fn var(&self, id: VarId) -> Var {
        let (n, i) = (self.n, id.index());
        if i < n {
            Var::Coordinate(i)
        } else if i < 2 * n {
            Var::Velocity(i - n)
        } else if i == 2 * n {
            Var::Time
        } else if i < 2 * n + 1 + self.inputs {
            Var::Input(i - 2 * n - 1)
        } else {
            Var::Parameter(i - 2 * n - 1 - self.inputs)
        }
    }
}

/// The lowered model: its graph, variable layout and derived mechanics.
pub(crate) struct Lowered {
    pub graph: Graph,
    pub layout: Layout,
    pub mechanics: Mechanics,
}

/// Builds the graph and derives the mechanics. Records an error and returns
/// `None` when the kinetic energy is not a quadratic form in the velocities.
pub(crate) fn lower(cx: &Ctxt, spec: &ModelSpec) -> Option<Lowered> {
    let layout = Layout::of(spec);
    let mut b = Builder {
        spec,
        layout,
        graph: Graph::new(),
        definitions: Vec::new(),
    };
    for d in &spec.definitions {
        let id = b.expr(&d.expr);
        b.definitions.push(id);
    }
    let kinetic_expr = spec.kinetic.as_ref()?;
    let kinetic = b.expr(kinetic_expr);
    let potential = match &spec.potential {
        Some(p) => b.expr(p),
        None => b.graph.constant(0.0),
    };
    let forces: Vec<Id> = (0..layout.n)
        .map(|i| match spec.force_on(i) {
            Some(f) => b.expr(f),
            None => b.graph.constant(0.0),
        })
        .collect();
    let gaps: Vec<Id> = spec.constraints.iter().map(|c| b.expr(&c.h)).collect();
    let q: Vec<VarId> = (0..layout.n)
        .map(|i| layout.id(Var::Coordinate(i)))
        .collect();
    let v: Vec<VarId> = (0..layout.n).map(|i| layout.id(Var::Velocity(i))).collect();
    let mut graph = b.graph;
    let system = Lagrangian {
        q: &q,
        v: &v,
        kinetic,
        potential,
        forces: &forces,
        gaps: &gaps,
    };
    let mechanics = match Mechanics::derive(&mut graph, &system) {
        Ok(m) => m,
        Err(e) => {
            let names: Vec<&str> = spec.coordinates.iter().map(|c| c.v.text.as_str()).collect();
            let culprit = match e {
                MechanicsError::NotQuadratic { velocity, .. }
                | MechanicsError::LinearTerm { velocity } => Some(velocity),
                _ => None,
            };
            let loc = culprit
                .and_then(|k| first_use(spec, kinetic_expr, names[k]))
                .unwrap_or(kinetic_expr.loc);
            cx.error(loc, e.describe(&names));
            return None;
        }
    };
    Some(Lowered {
        graph,
        layout,
        mechanics,
    })
}

/// Where `e` first uses the variable `name`, directly or through a
/// definition (then the definition's use is given).
fn first_use(spec: &ModelSpec, e: &Expr, name: &str) -> Option<Loc> {
    let mut found = None;
    e.visit_names(&mut |used, loc| {
        if found.is_some() {
            return;
        }
        let through_definition = match spec.resolve(used) {
            Some(Symbol::Definition(i)) => {
                first_use(spec, &spec.definitions[i].expr, name).is_some()
            }
            _ => false,
        };
        if used == name || through_definition {
            found = Some(loc);
        }
    });
    found
}

struct Builder<'a> {
    spec: &'a ModelSpec,
    layout: Layout,
    graph: Graph,
    definitions: Vec<Id>,
}

impl Builder<'_> {
    fn expr(&mut self, e: &Expr) -> Id {
        match &e.kind {
            ExprKind::Num(x) => self.graph.constant(*x),
            ExprKind::Name(name) => self.name(name),
            ExprKind::Neg(a) => {
                let a = self.expr(a);
                self.graph.neg(a)
            }
            ExprKind::Binary(op, a, b) => {
                let (a, b) = (self.expr(a), self.expr(b));
                match op {
                    BinOp::Add => self.graph.add(a, b),
                    BinOp::Sub => self.graph.sub(a, b),
                    BinOp::Mul => self.graph.mul(a, b),
                    BinOp::Div => self.graph.div(a, b),
                    BinOp::Pow => self.graph.pow(a, b),
                }
            }
            ExprKind::Call(func, args) => {
                let args: Vec<Id> = args.iter().map(|a| self.expr(a)).collect();
                match func {
                    Func::Atan2 => self.graph.atan2(args[0], args[1]),
                    Func::Sqrt => self.graph.sqrt(args[0]),
                    Func::Exp => self.graph.exp(args[0]),
                    Func::Ln => self.graph.ln(args[0]),
                    Func::Sin => self.graph.sin(args[0]),
                    Func::Cos => self.graph.cos(args[0]),
                    Func::Tan => self.graph.tan(args[0]),
                    Func::Sinh => self.graph.sinh(args[0]),
                    Func::Cosh => self.graph.cosh(args[0]),
                    Func::Tanh => self.graph.tanh(args[0]),
                }
            }
        }
    }

    fn name(&mut self, name: &str) -> Id {
        let var = match self.spec.resolve(name) {
            Some(Symbol::Coordinate(i)) => Var::Coordinate(i),
            Some(Symbol::Velocity(i)) => Var::Velocity(i),
            Some(Symbol::Parameter(i)) => Var::Parameter(i),
            Some(Symbol::Input(i)) => Var::Input(i),
            Some(Symbol::Time) => Var::Time,
            Some(Symbol::Pi) => return self.graph.constant(std::f64::consts::PI),
            Some(Symbol::Definition(i)) => return self.definitions[i],
            None => unreachable!("unknown names are rejected by the checks"),
        };
        let id = self.layout.id(var);
        self.graph.var(id)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_round_trips_every_variable() {
        let layout = Layout { n: 3, inputs: 2 };
        let mut all = Vec::new();
        for i in 0..3 {
            all.push(Var::Coordinate(i));
            all.push(Var::Velocity(i));
        }
        all.push(Var::Time);
        all.extend((0..2).map(Var::Input));
        all.extend((0..4).map(Var::Parameter));
        for (index, var) in all.into_iter().enumerate() {
            assert_eq!(layout.var(layout.id(var)), var);
            assert!(layout.id(var).index() < 2 * 3 + 1 + 2 + 4, "{index}");
        }
    }
}
