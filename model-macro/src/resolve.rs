//! Resolution: every name of a checked [`ModelSpec`] becomes a typed
//! [`Symbol`], once, and the model becomes a [`Resolved`] in which nothing
//! is looked up by name again and nothing required is optional. Lowering
//! and emission read only the resolved model.
//!
//! The [`Scope`] (`scope.rs`) is the one table from names to symbols; the
//! checks ask it, resolution maps every expression through it. A graph
//! variable is a [`Var`], numbered by [`VarLayout`] for `moreau-sym`.

use moreau_sym::VarId;

use crate::expr::Expr;
use crate::loc::Loc;
use crate::scope::{Scope, Symbol, Var};
use crate::spec::{JointKind, ModelSpec};

/// The numbering of the model's variables in the symbolic graph:
/// coordinates, velocities, time, inputs, parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct VarLayout {
    pub n: usize,
    pub inputs: usize,
    pub parameters: usize,
}

impl VarLayout {
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
        VarId(u32::try_from(index).unwrap_or(u32::MAX))
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

    /// Number of graph variables.
    pub fn len(&self) -> usize {
        2 * self.n + 1 + self.inputs + self.parameters
    }
}

/// A resolved model: the spec (for names, docs and locations) and every
/// expression with typed symbols, in the shape the mechanics need.
pub(crate) struct Resolved<'a> {
    pub spec: &'a ModelSpec,
    pub layout: VarLayout,
    /// The definitions in order; each refers only to earlier ones.
    pub definitions: Vec<Expr<Symbol>>,
    /// The kinetic energy as written; the tree's is added to it.
    pub kinetic: Option<Expr<Symbol>>,
    pub potential: Option<Expr<Symbol>>,
    /// Where the kinetic energy (or else the tree) was written: messages
    /// about `M` point here.
    pub energy_loc: Loc,
    /// The kinematic tree, parents before children.
    pub bodies: Vec<TreeBody>,
    /// The gravity vector of the tree's potential energy.
    pub gravity: [Expr<Symbol>; 3],
    /// The applied force on each coordinate, if any.
    pub applied: Vec<Option<Expr<Symbol>>>,
    /// The gap of each constraint.
    pub gaps: Vec<Expr<Symbol>>,
    /// The restitution coefficient of each constraint.
    pub restitution: Vec<f64>,
    /// Initial coordinates and velocities (0 where the model gives none).
    pub initial_q: Vec<f64>,
    pub initial_v: Vec<f64>,
}

impl Resolved<'_> {
    /// Number of degrees of freedom `N`.
    pub fn n(&self) -> usize {
        self.layout.n
    }

    /// Number of constraints `K`.
    pub fn k(&self) -> usize {
        self.gaps.len()
    }

    /// The user's name of a variable (`t` for the time).
    pub fn var_name(&self, var: Var) -> &str {
        let spec = self.spec;
        match var {
            Var::Coordinate(i) => &spec.coordinates[i].q.text,
            Var::Velocity(i) => &spec.coordinates[i].v.text,
            Var::Time => "t",
            Var::Input(i) => &spec.inputs[i].text,
            Var::Parameter(i) => &spec.parameters[i].name.text,
        }
    }
}

/// A body of the resolved tree.
pub(crate) struct TreeBody {
    /// The index of the body in `ModelSpec::bodies` (what `Symbol::Body`
    /// names).
    pub index: usize,
    /// The parent's position in `Resolved::bodies` (always earlier), or
    /// `None` for the world.
    pub parent: Option<usize>,
    pub kind: JointKind,
    /// The joint's coordinate, or the one it follows.
    pub coordinate: Option<usize>,
    /// The joint's angle (or displacement) is `scale · q + offset`, `q`
    /// its coordinate: `(1, 0)` but for a joint that mimics another.
    pub follow: (f64, f64),
    /// The unit axis.
    pub axis: [f64; 3],
    pub xyz: [Expr<Symbol>; 3],
    pub rpy: [Expr<Symbol>; 3],
    pub mass: Expr<Symbol>,
    pub com: [Expr<Symbol>; 3],
    pub inertia: [Expr<Symbol>; 6],
}

/// Resolves every expression of a checked `spec` through `scope`. The
/// checks have reported every name that stands for nothing and every
/// definition used before it is defined; `None` if one is met anyway, or
/// when the kinetic energy is missing (which the front ends report), and
/// the caller then reports an internal error rather than emit wrong code.
pub(crate) fn resolve<'a>(spec: &'a ModelSpec, scope: &Scope<'_>) -> Option<Resolved<'a>> {
    let mut definitions = Vec::with_capacity(spec.definitions.len());
    for (i, d) in spec.definitions.iter().enumerate() {
        let e = d.expr.try_map(
            &mut |name: &String, _, space| match scope.lookup(name, space)? {
                Symbol::Definition(j) if j >= i => None,
                found => Some(found),
            },
        )?;
        definitions.push(e);
    }
    let expr = |e: &Expr| e.try_map(&mut |name: &String, _, space| scope.lookup(name, space));
    let kinetic = match &spec.kinetic {
        Some(k) => Some(expr(k)?),
        None => None,
    };
    let potential = match &spec.potential {
        Some(p) => Some(expr(p)?),
        None => None,
    };
    let energy_loc = match (&spec.kinetic, spec.bodies_loc) {
        (Some(k), _) => k.loc,
        (None, Some(loc)) => loc,
        (None, None) => return None,
    };
    let bodies = tree(spec, scope)?;
    let gravity = match &spec.gravity {
        Some([x, y, z]) => [expr(x)?, expr(y)?, expr(z)?],
        None => {
            let g = |x: f64| Expr {
                kind: crate::expr::ExprKind::Num(x),
                loc: energy_loc,
            };
            [g(0.0), g(0.0), g(-9.81)]
        }
    };
    let mut applied: Vec<Option<Expr<Symbol>>> = vec![None; spec.dofs()];
    for a in &spec.applied {
        applied[scope.coordinate(&a.coordinate.text)?] = Some(expr(&a.expr)?);
    }
    let mut gaps = Vec::with_capacity(spec.constraint_count());
    for c in &spec.constraints {
        gaps.push(expr(&c.h)?);
    }
    let mut initial_q = vec![0.0; spec.dofs()];
    let mut initial_v = vec![0.0; spec.dofs()];
    for (name, x) in &spec.initial {
        match scope.get(&name.text)? {
            Symbol::Var(Var::Coordinate(i)) => initial_q[i] = x.value,
            Symbol::Var(Var::Velocity(i)) => initial_v[i] = x.value,
            _ => return None,
        }
    }
    Some(Resolved {
        spec,
        layout: VarLayout {
            n: spec.dofs(),
            inputs: spec.inputs.len(),
            parameters: spec.parameters.len(),
        },
        definitions,
        kinetic,
        potential,
        energy_loc,
        bodies,
        gravity,
        applied,
        gaps,
        restitution: (0..spec.constraint_count())
            .map(|i| spec.restitution_of(i).map_or(0.0, |e| e.value))
            .collect(),
        initial_q,
        initial_v,
    })
}

/// The bodies of a checked spec, parents before children (a stable
/// topological order: among the bodies whose parent is placed, the first
/// written comes first). `None` on a cycle or an unknown parent (reported
/// by the checks).
fn tree(spec: &ModelSpec, scope: &Scope<'_>) -> Option<Vec<TreeBody>> {
    let expr = |e: &Expr| e.try_map(&mut |name: &String, _, space| scope.lookup(name, space));
    let three = |e: &[Expr; 3]| Some([expr(&e[0])?, expr(&e[1])?, expr(&e[2])?]);
    let parents: Vec<Option<usize>> = spec
        .bodies
        .iter()
        .map(|b| match &b.parent {
            None => Some(None),
            Some(p) => Some(Some(scope.body(&p.text)?)),
        })
        .collect::<Option<_>>()?;
    let mut placed: Vec<Option<usize>> = vec![None; spec.bodies.len()];
    let mut order = Vec::with_capacity(spec.bodies.len());
    while order.len() < spec.bodies.len() {
        let next = (0..spec.bodies.len())
            .find(|&i| placed[i].is_none() && parents[i].is_none_or(|p| placed[p].is_some()))?;
        placed[next] = Some(order.len());
        order.push(next);
    }
    order
        .into_iter()
        .map(|i| {
            let b = &spec.bodies[i];
            let a = b.joint.axis.map(|n| n.value);
            let norm = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            let i6 = &b.inertia;
            Some(TreeBody {
                index: i,
                parent: parents[i].map(|p| placed[p].expect("parents are placed first")),
                kind: b.joint.kind,
                coordinate: match &b.joint.mimic {
                    Some(m) => Some(scope.coordinate(&m.coordinate.text)?),
                    None => b.joint.coordinate,
                },
                follow: b
                    .joint
                    .mimic
                    .as_ref()
                    .map_or((1.0, 0.0), |m| (m.multiplier.value, m.offset.value)),
                axis: a.map(|x| x / norm),
                xyz: three(&b.joint.xyz)?,
                rpy: three(&b.joint.rpy)?,
                mass: expr(&b.mass)?,
                com: three(&b.com)?,
                inertia: [
                    expr(&i6[0])?,
                    expr(&i6[1])?,
                    expr(&i6[2])?,
                    expr(&i6[3])?,
                    expr(&i6[4])?,
                    expr(&i6[5])?,
                ],
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_round_trips_every_variable() {
        let layout = VarLayout {
            n: 3,
            inputs: 2,
            parameters: 4,
        };
        let mut all = Vec::new();
        for i in 0..3 {
            all.push(Var::Coordinate(i));
            all.push(Var::Velocity(i));
        }
        all.push(Var::Time);
        all.extend((0..2).map(Var::Input));
        all.extend((0..4).map(Var::Parameter));
        for var in all {
            assert_eq!(layout.var(layout.id(var)), var);
            assert!(layout.id(var).index() < layout.len());
        }
    }
}
