//! Lowering: a [`Resolved`] model becomes a symbolic graph, and the
//! mechanics (every quantity of `moreau_sym::Quantity`) are derived on it
//! with `moreau-sym`.
//!
//! Variables are numbered by the model's [`VarLayout`]. Definitions are not
//! variables: each is built once and its node reused wherever it is named.

use moreau_sym::graph::share_waves;
use moreau_sym::{
    Graph, Id, Lagrangian, Mechanics, MechanicsError, Node, Operand, Quantity, Recursive, Schedule,
    VarId,
};

use crate::ctxt::Ctxt;
use crate::expr::{BinOp, Expr, ExprKind, Fixed};
use crate::loc::Loc;
use crate::resolve::{Resolved, VarLayout};
use crate::scope::{Symbol, Var};
use crate::tree;

/// The lowered model: its graph, variable layout and derived mechanics.
pub(crate) struct Lowered {
    pub graph: Graph,
    pub mechanics: Mechanics,
    /// `mechanics.outputs()` with the sines and cosines of angle
    /// combinations shared across all of them
    /// ([`share_waves`](moreau_sym::graph::share_waves)), those of the fused
    /// evaluation first: what the code over the model's scalar computes.
    pub outputs: Vec<Id>,
}

/// Builds the graph and derives the mechanics. Records an error and returns
/// `None` when an expression folds to a non-finite constant or the kinetic
/// energy is not a quadratic form in the velocities.
pub(crate) fn lower(cx: &Ctxt, model: &Resolved<'_>) -> Option<Lowered> {
    let layout = model.layout;
    let mut b = Builder {
        cx,
        layout,
        graph: Graph::new(),
        definitions: Vec::with_capacity(model.definitions.len()),
        poses: vec![None; model.spec.bodies.len()],
    };
    // The tree first: its fields name only parameters, and definitions and
    // constraints may name its bodies' points.
    let built = b.tree(model)?;
    for d in &model.definitions {
        let id = b.expr(d)?;
        b.definitions.push(id);
    }
    // The tree's M, C v + G and G come from its recursions; T and V hold
    // only what the model writes besides it.
    let zero = b.graph.constant(0.0);
    let kinetic = match &model.kinetic {
        Some(k) => b.expr(k)?,
        None => zero,
    };
    let potential = match &model.potential {
        Some(p) => b.expr(p)?,
        None => zero,
    };
    let mut applied = Vec::with_capacity(layout.n);
    for a in &model.applied {
        applied.push(match a {
            Some(e) => b.expr(e)?,
            None => b.graph.constant(0.0),
        });
    }
    let gaps = b.gaps(model)?;
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
        applied: &applied,
        gaps: &gaps,
    };
    let recursive = (!model.bodies.is_empty()).then_some(Recursive {
        mass: built.dynamics.mass,
        bias: built.dynamics.bias,
        gravity: built.dynamics.gravity,
        coriolis: built.dynamics.coriolis,
    });
    match Mechanics::derive_with(&mut graph, &system, recursive.as_ref()) {
        Ok(mechanics) => {
            check_mass_diagonal(cx, model, &graph, &mechanics)?;
            check_finite_constants(cx, model, &graph, &mechanics)?;
            let outputs = mechanics.outputs();
            let eval = mechanics.layout().indices(&Quantity::EVAL);
            let fused: Vec<Id> = eval.iter().map(|&i| outputs[i]).collect();
            let outputs = share_waves(&mut graph, &outputs, &fused);
            Some(Lowered {
                graph,
                mechanics,
                outputs,
            })
        }
        Err(e) => {
            report(cx, model, &e);
            None
        }
    }
}

/// No derived quantity may hold a non-finite constant (the expressions are
/// checked as they are built; this is the net under differentiation).
fn check_finite_constants(
    cx: &Ctxt,
    model: &Resolved<'_>,
    graph: &Graph,
    mechanics: &Mechanics,
) -> Option<()> {
    let sched = Schedule::new(graph, &mechanics.outputs());
    let operands = sched
        .instrs
        .iter()
        .flat_map(|i| i.operands().iter().copied())
        .chain(sched.outputs.iter().copied());
    for operand in operands {
        if let Operand::Const(c) = operand
            && !c.is_finite()
        {
            cx.error(
                model.energy_loc,
                format!("a derived quantity of this model holds the constant {c}, which is not a finite number"),
            );
            return None;
        }
    }
    Some(())
}

/// `M` must be positive definite; what can be decided from its structure is
/// decided here: a diagonal entry that is a constant `≤ 0` (a velocity absent
/// from `T`, `T = −½ vy²`, `T = vx vy`, `T = 0`) makes it singular or
/// indefinite everywhere. Reported at the kinetic energy, naming the
/// velocity.
fn check_mass_diagonal(
    cx: &Ctxt,
    model: &Resolved<'_>,
    graph: &Graph,
    mechanics: &Mechanics,
) -> Option<()> {
    let mut ok = true;
    for i in 0..model.n() {
        let Some(m) = graph.as_const(mechanics.mass[i][i]) else {
            continue;
        };
        if m <= 0.0 {
            let v = model.var_name(Var::Velocity(i));
            let moved_by_joint = model.bodies.iter().any(|b| b.coordinate == Some(i));
            let why = if m == 0.0 && moved_by_joint {
                let q = model.var_name(Var::Coordinate(i));
                format!(
                    "the joint of coordinate `{q}` moves no mass or inertia (M[{i},{i}] = 0; a massless link of a URDF: lock the joint)"
                )
            } else if m == 0.0 {
                format!("the kinetic energy has no term in `{v}`^2 (M[{i},{i}] = ∂²T/∂{v}² = 0)")
            } else {
                format!("M[{i},{i}] = ∂²T/∂{v}² = {m} is negative")
            };
            let loc = model
                .kinetic
                .as_ref()
                .and_then(|k| first_use(model, k, Var::Velocity(i)))
                .unwrap_or(model.energy_loc);
            cx.error(
                loc,
                format!("{why}: the mass matrix is not positive definite"),
            );
            ok = false;
        }
    }
    ok.then_some(())
}

/// Reports a mechanics error at the first use of the velocity it names.
fn report(cx: &Ctxt, model: &Resolved<'_>, e: &MechanicsError) {
    let names: Vec<&str> = (0..model.n())
        .map(|i| model.var_name(Var::Velocity(i)))
        .collect();
    let culprit = match *e {
        MechanicsError::NotQuadratic { velocity, .. } | MechanicsError::LinearTerm { velocity } => {
            Some(velocity)
        }
        _ => None,
    };
    let loc = culprit
        .zip(model.kinetic.as_ref())
        .and_then(|(k, kinetic)| first_use(model, kinetic, Var::Velocity(k)))
        .unwrap_or(model.energy_loc);
    cx.error(loc, e.describe(&names));
}

/// Where `e` first uses `var`, directly or through a definition (then the
/// definition's use is given).
fn first_use(model: &Resolved<'_>, e: &Expr<Symbol>, var: Var) -> Option<Loc> {
    let mut found = None;
    e.visit(&mut |symbol, loc| {
        if found.is_some() {
            return;
        }
        let hit = match *symbol {
            Symbol::Var(v) => v == var,
            Symbol::Definition(i) => first_use(model, &model.definitions[i], var).is_some(),
            Symbol::Pi | Symbol::Body(_) => false,
        };
        if hit {
            found = Some(loc);
        }
    });
    found
}

struct Builder<'a> {
    cx: &'a Ctxt,
    layout: VarLayout,
    graph: Graph,
    definitions: Vec<Id>,
    /// The pose of each body, by its index in `ModelSpec::bodies`.
    poses: Vec<Option<tree::Pose>>,
}

impl Builder<'_> {
    fn three(&mut self, e: &[Expr<Symbol>; 3]) -> Option<[Id; 3]> {
        Some([self.expr(&e[0])?, self.expr(&e[1])?, self.expr(&e[2])?])
    }

    /// The kinematic tree's T, V and body poses, its fields built first.
    fn tree(&mut self, model: &Resolved<'_>) -> Option<tree::Tree> {
        let mut fields = Vec::with_capacity(model.bodies.len());
        for body in &model.bodies {
            fields.push(tree::BodyFields {
                xyz: self.three(&body.xyz)?,
                rpy: self.three(&body.rpy)?,
                mass: self.expr(&body.mass)?,
                com: self.three(&body.com)?,
                inertia: [
                    self.expr(&body.inertia[0])?,
                    self.expr(&body.inertia[1])?,
                    self.expr(&body.inertia[2])?,
                    self.expr(&body.inertia[3])?,
                    self.expr(&body.inertia[4])?,
                    self.expr(&body.inertia[5])?,
                ],
            });
        }
        let gravity = self.three(&model.gravity)?;
        let built = tree::build(
            &mut self.graph,
            self.layout,
            &model.bodies,
            &fields,
            gravity,
        );
        for (body, pose) in model.bodies.iter().zip(&built.poses) {
            self.poses[body.index] = Some(*pose);
        }
        Some(built)
    }

    /// The gaps, each of which must move with the configuration.
    fn gaps(&mut self, model: &Resolved<'_>) -> Option<Vec<Id>> {
        let mut gaps = Vec::with_capacity(model.k());
        for (h, c) in model.gaps.iter().zip(&model.spec.constraints) {
            let id = self.expr(h)?;
            // A gap that does not move with the configuration constrains nothing
            // (`0 >= 1` is always violated or always satisfied).
            let moves = (0..self.layout.n).any(|i| {
                self.graph
                    .depends_on(id, self.layout.id(Var::Coordinate(i)))
            });
            if !moves {
                self.cx.error(
                    h.loc,
                    format!("constraint `{}` does not depend on any coordinate: it can never be reached or left", c.name.text),
                );
                return None;
            }
            gaps.push(id);
        }
        Some(gaps)
    }

    /// The node of `e`; `None` after reporting a subexpression that folds
    /// to a non-finite constant (`1/0`, `ln(0)`, `2^1024`).
    fn expr(&mut self, e: &Expr<Symbol>) -> Option<Id> {
        let before = self.graph.len();
        let g = &mut self.graph;
        let id = match &e.kind {
            ExprKind::Num(x) => g.constant(*x),
            ExprKind::Name(Symbol::Var(var)) => g.var(self.layout.id(*var)),
            ExprKind::Name(Symbol::Definition(i)) => self.definitions[*i],
            ExprKind::Name(Symbol::Pi) => g.constant(std::f64::consts::PI),
            // The checks report a body named outside `position_x`.
            ExprKind::Name(Symbol::Body(_)) => return None,
            ExprKind::Frame(kind, axis, Symbol::Body(i), point) => {
                let pose = self.poses[*i]?;
                let local = self.three(point)?;
                match kind {
                    Fixed::Point => tree::point(&mut self.graph, &pose, local)[*axis],
                    Fixed::Direction => tree::direction(&mut self.graph, &pose, local)[*axis],
                }
            }
            // The checks report a `position_x` of something not a body.
            ExprKind::Frame(..) => return None,
            ExprKind::Neg(a) => {
                let a = self.expr(a)?;
                self.graph.neg(a)
            }
            ExprKind::Func(f, a) => {
                let a = self.expr(a)?;
                self.graph.func(*f, a)
            }
            ExprKind::Atan2(y, x) => {
                let (y, x) = (self.expr(y)?, self.expr(x)?);
                self.graph.atan2(y, x)
            }
            ExprKind::Binary(op, a, b) => {
                let (a, b) = (self.expr(a)?, self.expr(b)?);
                if *op == BinOp::Div && self.graph.as_const(b) == Some(0.0) {
                    self.cx.error(e.loc, "division by zero");
                    return None;
                }
                let g = &mut self.graph;
                match op {
                    BinOp::Add => g.add(a, b),
                    BinOp::Sub => g.sub(a, b),
                    BinOp::Mul => g.mul(a, b),
                    BinOp::Div => g.div(a, b),
                    BinOp::Pow => g.pow(a, b),
                }
            }
        };
        // A new non-finite constant: the whole value (`ln(0)`), or a part
        // the simplifier made (`x / 0` becomes `inf * x`).
        let bad = self.graph.nodes()[before..].iter().find_map(|n| match *n {
            Node::Const(bits) if !f64::from_bits(bits).is_finite() => Some(f64::from_bits(bits)),
            _ => None,
        });
        match bad {
            Some(c) => {
                self.cx.error(
                    e.loc,
                    format!(
                        "this expression folds to the constant {c}, which is not a finite number"
                    ),
                );
                None
            }
            None => Some(id),
        }
    }
}
