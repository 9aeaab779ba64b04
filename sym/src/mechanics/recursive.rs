//! The quantities of a kinematic tree that recursions build directly on the
//! graph, so that they need not be derived from energies.
//!
//! Differentiating the kinetic energy of a tree twice (the Lagrangian
//! route) gives expressions whose size grows combinatorially with the depth
//! of the tree. A composite-rigid-body pass (`M`) and a recursive
//! Newton–Euler pass (`C v + G`) build the same values with a number of
//! operations linear (bias, gravity) and quadratic (`M`, one entry per pair
//! of joints) in the number of joints; the caller builds them (the macro's
//! `tree` module) and [`Mechanics::derive_with`](super::Mechanics::derive_with)
//! takes them from there:
//!
//! | quantity | from |
//! |---|---|
//! | `M` | the tree's `M` plus `∂²T/∂v²` of the written `T` |
//! | `G` | the tree's `G` plus `∂V/∂q` of the written `V` |
//! | `C` | the tree's `C` (Christoffel, built by the caller) when no `T` is written besides the tree; the Christoffel symbols of the total `M` otherwise |
//! | `F` | the tree's bias `C v + G` plus `∂V/∂q − Q` when no `T` is written besides the tree; `C v + G − Q` from the total `M` otherwise |
//! | `∂F/∂v` | `2 C − ∂Q/∂v` when no `T` is written besides the tree (the bias is quadratic in `v` through the Christoffel symbols); differentiation of `F` otherwise |
//! | `∂F/∂q`, `∂(M v)/∂q`, `J`, `∂(J v)/∂q` | differentiation of the above on the graph |
//!
//! The graph's derivatives are forward-mode and memoized per node, so each
//! derivative of a recursion costs at most a constant times the nodes that
//! depend on the variable: differentiating stays polynomial. A row of `J`
//! is built in reverse mode instead when that adds fewer operations (see
//! the [`Gap Jacobian`](super#gap-jacobian) section).

use crate::graph::Graph;
use crate::node::Id;

use super::{Lagrangian, MechanicsError};

/// A kinematic tree's mass matrix, bias forces and gravity, built by the
/// caller (by recursions) as expressions of the graph.
///
/// ```
/// use moreau_sym::{Graph, Lagrangian, Mechanics, Recursive, VarId};
/// // A point mass m on a line under a constant force m g, given as a
/// // "tree": M = m, C v + G = m g, G = m g.
/// let mut g = Graph::new();
/// let (x, vx, m) = (VarId(0), VarId(1), VarId(2));
/// let me = g.var(m);
/// let w = g.constant(9.81);
/// let weight = g.mul(me, w);
/// let zero = g.constant(0.0);
/// let tree = Recursive { mass: vec![vec![me]], bias: vec![weight], gravity: vec![weight], coriolis: vec![vec![zero]] };
/// let sys = Lagrangian { q: &[x], v: &[vx], kinetic: zero, potential: zero, applied: &[], gaps: &[] };
/// let mech = Mechanics::derive_with(&mut g, &sys, Some(&tree)).unwrap();
/// assert_eq!(mech.mass[0][0], me);
/// assert_eq!(mech.forces[0], weight);
/// assert!(g.is_zero(mech.coriolis[0][0]));
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Recursive {
    /// The mass matrix `M(q)`, `N × N`, symmetric.
    pub mass: Vec<Vec<Id>>,
    /// The bias forces `C(q, v) v + G(q)`, `N`.
    pub bias: Vec<Id>,
    /// The gravity forces `G(q)`, `N`.
    pub gravity: Vec<Id>,
    /// The Coriolis matrix `C(q, v)` of the Christoffel symbols of `mass`,
    /// `N × N` (`C v` is the velocity part of `bias`).
    pub coriolis: Vec<Vec<Id>>,
}

impl Recursive {
    /// Every quantity has one row (and `M` one column) per coordinate.
    pub(super) fn check(&self, n: usize) -> Result<(), MechanicsError> {
        let rows = [
            ("tree mass", self.mass.len()),
            ("tree bias", self.bias.len()),
            ("tree gravity", self.gravity.len()),
            ("tree coriolis", self.coriolis.len()),
        ];
        let cols = self
            .mass
            .iter()
            .map(|r| ("tree mass row", r.len()))
            .chain(self.coriolis.iter().map(|r| ("tree coriolis row", r.len())));
        for (what, found) in rows.into_iter().chain(cols) {
            if found != n {
                return Err(MechanicsError::Shape {
                    what,
                    expected: n,
                    found,
                });
            }
        }
        Ok(())
    }

    /// The momentum, mass matrix and gravity of the written `T` and `V`
    /// with the tree's added (`p += M_tree v`).
    pub(super) fn add_to(
        &self,
        g: &mut Graph,
        sys: &Lagrangian<'_>,
        (momentum, mass, gravity): (Vec<Id>, Vec<Vec<Id>>, &[Id]),
    ) -> (Vec<Id>, Vec<Vec<Id>>, Vec<Id>) {
        let mass: Vec<Vec<Id>> = mass
            .iter()
            .zip(&self.mass)
            .map(|(a, b)| a.iter().zip(b).map(|(&x, &y)| g.add(x, y)).collect())
            .collect();
        let momentum = momentum
            .iter()
            .zip(&self.mass)
            .map(|(&p, row)| {
                let mut p = p;
                for (&m, &v) in row.iter().zip(sys.v) {
                    let v = g.var(v);
                    let mv = g.mul(m, v);
                    p = g.add(p, mv);
                }
                p
            })
            .collect();
        let gravity = gravity
            .iter()
            .zip(&self.gravity)
            .map(|(&a, &b)| g.add(a, b))
            .collect();
        (momentum, mass, gravity)
    }

    /// `∂F/∂v = 2 C − ∂Q/∂v`: the velocity terms of `bias` are
    /// `n(v) = Σ_jk Γ_ijk v_j v_k` with `Γ` symmetric in `j, k`, so
    /// `∂n_i/∂v_j = 2 Σ_k Γ_ijk v_k = 2 C_ij`, and `∂V/∂q` does not depend
    /// on `v`. Saves differentiating the Newton–Euler pass in `v`.
    pub(super) fn forces_dv(
        &self,
        g: &mut Graph,
        sys: &Lagrangian<'_>,
        coriolis: &[Vec<Id>],
    ) -> Vec<Vec<Id>> {
        let two = g.constant(2.0);
        (0..coriolis.len())
            .map(|i| {
                let dq: Vec<Id> = match sys.applied.get(i) {
                    Some(&q) => g.gradient(q, sys.v),
                    None => Vec::new(),
                };
                (0..coriolis.len())
                    .map(|j| {
                        let c = g.mul(two, coriolis[i][j]);
                        match dq.get(j) {
                            Some(&d) => g.sub(c, d),
                            None => c,
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// `F = bias + ∂V/∂q − Q`, `written` the gradient of the written `V`.
    pub(super) fn forces(&self, g: &mut Graph, sys: &Lagrangian<'_>, written: &[Id]) -> Vec<Id> {
        (0..self.bias.len())
            .map(|i| {
                let f = g.add(self.bias[i], written[i]);
                match sys.applied.get(i) {
                    Some(&q) => g.sub(f, q),
                    None => f,
                }
            })
            .collect()
    }
}
