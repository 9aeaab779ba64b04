//! Lagrangian mechanics: from `T`, `V`, `Q` and `h` to `M`, `C`, `G`, `F`, `J`.
//!
//! For coordinates `q`, velocities `v`, kinetic energy `T(q, v) = ½ vᵀ M(q) v`,
//! potential `V(q)`, extra generalized forces `Q` and gaps `h(q) ≥ 0`, the
//! equations of motion are `M(q) v̇ + F = 0` (the paper's (8)) with
//!
//! | quantity | formula |
//! |---|---|
//! | momentum | `p = ∂T/∂v` |
//! | mass matrix | `M_ij = ∂p_i/∂v_j`, symmetric, built for `i ≤ j` only |
//! | Coriolis matrix | `C_ij = Σ_k Γ_ijk v_k`, `Γ_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i)` |
//! | gravity | `G = ∂V/∂q` |
//! | total force | `F = C v + G − Q` |
//! | gap Jacobian | `J_ij = ∂h_i/∂q_j` |
//!
//! With the Christoffel symbols `Γ`, `Ṁ − 2C` is skew-symmetric, which the
//! observers' passivity argument needs.
//!
//! # Work sharing
//!
//! `T` is differentiated once per velocity (`p`), and `M` is differentiated
//! from `p`, not from `T` again. The `N²(N+1)/2` derivatives `∂M_ij/∂q_k`
//! (`i ≤ j`) are built once and shared by all Christoffel symbols; within one
//! symbol equal derivatives are merged before anything is built (so
//! `∂M_01/∂q_0 − ∂M_10/∂q_0` is never formed), and zero derivatives vanish.
//! `C v` reuses the entries of `C`. Zero entries stay the constant `0`, which
//! the emitter writes as a literal.
//!
//! # Quadratic kinetic energy
//!
//! `T` must be a quadratic form in `v`: `T = ½ vᵀ M(q) v` with no term linear
//! in `v` and no term free of `v` (such terms would be gyroscopic forces or a
//! potential that `F = C v + G − Q` does not contain). [`Mechanics::derive`]
//! checks, in this order, that no `M_ij` depends on a velocity
//! ([`MechanicsError::NotQuadratic`]: `T = vx^4`, `T = vx * vy * vx`), that
//! `∂T/∂v_k` vanishes at `v = 0` ([`MechanicsError::LinearTerm`]:
//! `T = m * vx^2 + vx`) and that `T` vanishes at `v = 0`
//! ([`MechanicsError::VelocityFreeTerm`]: `T = m * vx^2 + y`). Together they
//! are equivalent to `T − ½ vᵀ M v = 0`. The checks are symbolic: the
//! velocities are replaced by `0` and the result must simplify to the
//! constant `0`, so a term that vanishes only through an identity the
//! builders do not know (`sin²+cos²−1`) is reported. That `V`, `h` and the
//! definitions do not depend on velocities is checked by the macro.

use core::fmt;

use crate::graph::Graph;
use crate::node::{Id, Node, VarId};

/// The inputs of [`Mechanics::derive`]: a Lagrangian system with unilateral
/// constraints, as expressions of one [`Graph`].
#[derive(Clone, Copy, Debug)]
pub struct Lagrangian<'a> {
    /// The coordinates `q`, in order.
    pub q: &'a [VarId],
    /// The velocities `v`, `v[i]` the rate of `q[i]`.
    pub v: &'a [VarId],
    /// The kinetic energy `T(q, v)`, a quadratic form in `v`.
    pub kinetic: Id,
    /// The potential energy `V(q)`.
    pub potential: Id,
    /// The extra generalized forces `Q`, one per coordinate, or empty for
    /// none.
    pub forces: &'a [Id],
    /// The gaps `h_i(q) ≥ 0`.
    pub gaps: &'a [Id],
}

/// Why a system was rejected. Indices refer to the order of
/// [`Lagrangian::q`] and [`Lagrangian::v`].
///
/// ```
/// use moreau_sym::{Graph, Lagrangian, Mechanics, MechanicsError, VarId};
/// let mut g = Graph::new();
/// let vx = g.var(VarId(1));
/// let t = g.powi(vx, 4);
/// let zero = g.constant(0.0);
/// let sys = Lagrangian {
///     q: &[VarId(0)],
///     v: &[VarId(1)],
///     kinetic: t,
///     potential: zero,
///     forces: &[],
///     gaps: &[],
/// };
/// let err = Mechanics::derive(&mut g, &sys).unwrap_err();
/// assert_eq!(err, MechanicsError::NotQuadratic { row: 0, col: 0, velocity: 0 });
/// assert_eq!(err.describe(&["vx"]), "the kinetic energy is not quadratic in the \
///     velocities: M[0,0] = ∂²T/∂vx∂vx depends on vx");
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MechanicsError {
    /// `M[row, col] = ∂²T/∂v_row ∂v_col` depends on `v[velocity]`, so `T` has
    /// terms of degree three or more in `v` (or is not polynomial in `v`).
    NotQuadratic {
        /// Row of the mass matrix entry.
        row: usize,
        /// Column of the mass matrix entry (`row ≤ col`).
        col: usize,
        /// The velocity it depends on.
        velocity: usize,
    },
    /// `T` has a term linear in `v[velocity]`: `∂T/∂v_velocity` does not
    /// vanish at `v = 0`.
    LinearTerm {
        /// The velocity of the linear term.
        velocity: usize,
    },
    /// `T` does not vanish at `v = 0`: it has a term free of velocities.
    VelocityFreeTerm,
    /// A slice of [`Lagrangian`] has the wrong length.
    Shape {
        /// The field: `"v"` or `"forces"`.
        what: &'static str,
        /// The length it should have (the number of coordinates).
        expected: usize,
        /// Its length.
        found: usize,
    },
}

impl MechanicsError {
    /// The message, naming velocities by `velocity_names[k]` (the error's
    /// [`Display`](fmt::Display) writes `v0`, `v1`, ...).
    #[must_use]
    pub fn describe(&self, velocity_names: &[&str]) -> String {
        let name = |k: usize| {
            velocity_names
                .get(k)
                .map_or_else(|| format!("v{k}"), |n| (*n).to_string())
        };
        match *self {
            MechanicsError::NotQuadratic { row, col, velocity } => format!(
                "the kinetic energy is not quadratic in the velocities: \
                 M[{row},{col}] = ∂²T/∂{}∂{} depends on {}",
                name(row),
                name(col),
                name(velocity)
            ),
            MechanicsError::LinearTerm { velocity } => format!(
                "the kinetic energy has a term linear in {}: T must be a quadratic \
                 form ½ vᵀ M(q) v, without terms of degree 1 in the velocities",
                name(velocity)
            ),
            MechanicsError::VelocityFreeTerm => "the kinetic energy has a term free of \
                 velocities: T must vanish when the velocities do (move position-only \
                 terms to the potential, with the opposite sign)"
                .to_string(),
            MechanicsError::Shape {
                what,
                expected,
                found,
            } => format!("`{what}` has {found} entries, expected {expected}"),
        }
    }
}

impl fmt::Display for MechanicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.describe(&[]))
    }
}

impl std::error::Error for MechanicsError {}

/// One of the quantities a model provides, for naming and cutting outputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Quantity {
    /// The mass matrix `M` (only `row ≤ col` appears in [`Mechanics::flat`]).
    Mass,
    /// The Coriolis matrix `C`.
    Coriolis,
    /// The gravity vector `G = ∂V/∂q`.
    Gravity,
    /// The total force `F = C v + G − Q`.
    Force,
    /// The gaps `h`.
    Gap,
    /// The gap Jacobian `J = ∂h/∂q`.
    Jacobian,
}

impl Quantity {
    /// Every quantity, in the order of [`Mechanics::flat`].
    pub const ALL: [Quantity; 6] = [
        Quantity::Mass,
        Quantity::Coriolis,
        Quantity::Gravity,
        Quantity::Force,
        Quantity::Gap,
        Quantity::Jacobian,
    ];
}

/// Where one output of [`Mechanics::flat`] belongs: a quantity and an entry
/// (`col` is 0 for vectors).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Slot {
    /// The quantity.
    pub quantity: Quantity,
    /// The row (the index for vectors).
    pub row: usize,
    /// The column (0 for vectors).
    pub col: usize,
}

/// The derived quantities of a [`Lagrangian`] system, as expressions of the
/// graph they were derived in.
///
/// Matrices are rows of entries. `mass[i][j]` and `mass[j][i]` are the same
/// node. Entries that are identically zero are the constant `0`.
///
/// ```
/// use moreau_sym::{Graph, Lagrangian, Mechanics, VarId};
/// // A unit mass on a line, a spring to the origin, a floor at x = 0.
/// let (x, vx, m, k) = (VarId(0), VarId(1), VarId(2), VarId(3));
/// let mut g = Graph::new();
/// let (xe, ve, me, ke) = (g.var(x), g.var(vx), g.var(m), g.var(k));
/// let half = g.constant(0.5);
/// let v2 = g.powi(ve, 2);
/// let t = g.mul(me, v2);
/// let t = g.mul(half, t); // T = ½ m vx²
/// let x2 = g.powi(xe, 2);
/// let v = g.mul(ke, x2);
/// let v = g.mul(half, v); // V = ½ k x²
/// let sys = Lagrangian { q: &[x], v: &[vx], kinetic: t, potential: v, forces: &[], gaps: &[xe] };
/// let mech = Mechanics::derive(&mut g, &sys).unwrap();
/// assert_eq!(mech.mass, vec![vec![me]]);
/// assert!(g.is_zero(mech.coriolis[0][0]));
/// assert_eq!(mech.gravity[0], g.mul(ke, xe)); // k x
/// assert_eq!(mech.forces, mech.gravity);
/// assert!(g.as_const(mech.jacobian[0][0]) == Some(1.0));
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mechanics {
    /// The generalized momentum `p = ∂T/∂v = M v`.
    pub momentum: Vec<Id>,
    /// The mass matrix `M = ∂²T/∂v²`, `N × N`, symmetric.
    pub mass: Vec<Vec<Id>>,
    /// The Coriolis matrix `C`, `N × N`, from the Christoffel symbols.
    pub coriolis: Vec<Vec<Id>>,
    /// The gravity vector `G = ∂V/∂q`.
    pub gravity: Vec<Id>,
    /// The total force `F = C v + G − Q`.
    pub forces: Vec<Id>,
    /// The gaps `h`, as given.
    pub gaps: Vec<Id>,
    /// The gap Jacobian `J = ∂h/∂q`, `K × N`.
    pub jacobian: Vec<Vec<Id>>,
}

impl Mechanics {
    /// Derives `M`, `C`, `G`, `F` and `J` of `sys` in `g`, after checking
    /// that `T` is a quadratic form in `v` (see the [module docs](self)).
    ///
    /// # Errors
    /// [`MechanicsError::Shape`] if `v` or `forces` (unless empty) do not have
    /// one entry per coordinate; [`MechanicsError::NotQuadratic`],
    /// [`MechanicsError::LinearTerm`] or [`MechanicsError::VelocityFreeTerm`]
    /// if `T` is not a quadratic form in `v`.
    // Index loops mirror the formulas' indices (M_ij, Γ_ijk).
    #[allow(clippy::needless_range_loop)]
    pub fn derive(g: &mut Graph, sys: &Lagrangian<'_>) -> Result<Mechanics, MechanicsError> {
        let n = sys.q.len();
        for (what, found) in [("v", sys.v.len()), ("forces", sys.forces.len())] {
            if found != n && !(what == "forces" && found == 0) {
                return Err(MechanicsError::Shape {
                    what,
                    expected: n,
                    found,
                });
            }
        }
        let zero = g.constant(0.0);

        // p = ∂T/∂v, M_ij = ∂p_i/∂v_j for i ≤ j.
        let momentum = g.gradient(sys.kinetic, sys.v);
        let mut mass = vec![vec![zero; n]; n];
        for i in 0..n {
            for j in i..n {
                let m = g.diff(momentum[i], sys.v[j]);
                if let Some(k) = sys.v.iter().position(|&v| g.depends_on(m, v)) {
                    return Err(MechanicsError::NotQuadratic {
                        row: i,
                        col: j,
                        velocity: k,
                    });
                }
                mass[i][j] = m;
                mass[j][i] = m;
            }
        }
        check_form(g, sys, &momentum)?;

        // dm[i][j][k] = ∂M_ij/∂q_k, for i ≤ j (and mirrored).
        let mut dm = vec![vec![Vec::new(); n]; n];
        for i in 0..n {
            for j in i..n {
                let d = g.gradient(mass[i][j], sys.q);
                dm[j][i].clone_from(&d);
                dm[i][j] = d;
            }
        }
        let mut coriolis = vec![vec![zero; n]; n];
        for (i, row) in coriolis.iter_mut().enumerate() {
            for (j, c) in row.iter_mut().enumerate() {
                let mut terms = Vec::new();
                for k in 0..n {
                    let gamma = lincomb(
                        g,
                        &[(0.5, dm[i][j][k]), (0.5, dm[i][k][j]), (-0.5, dm[j][k][i])],
                    );
                    if !g.is_zero(gamma) {
                        let vk = g.var(sys.v[k]);
                        terms.push(g.mul(gamma, vk));
                    }
                }
                *c = sum(g, &terms);
            }
        }

        let gravity = g.gradient(sys.potential, sys.q);
        let mut forces = Vec::with_capacity(n);
        for i in 0..n {
            let mut terms = Vec::new();
            for j in 0..n {
                if !g.is_zero(coriolis[i][j]) {
                    let vj = g.var(sys.v[j]);
                    terms.push(g.mul(coriolis[i][j], vj));
                }
            }
            let cv = sum(g, &terms);
            let f = g.add(cv, gravity[i]);
            forces.push(match sys.forces.get(i) {
                Some(&q) => g.sub(f, q),
                None => f,
            });
        }
        let jacobian = g.jacobian(sys.gaps, sys.q);
        Ok(Mechanics {
            momentum,
            mass,
            coriolis,
            gravity,
            forces,
            gaps: sys.gaps.to_vec(),
            jacobian,
        })
    }

    /// Every output, tagged with its place, in a fixed order: `M` (upper
    /// triangle `i ≤ j`, row by row), `C` (row by row), `G`, `F`, `h`, `J`
    /// (row by row). This is the order of the fused evaluation; a
    /// per-quantity schedule is [`Schedule::restrict`](crate::Schedule::restrict)
    /// to the indices of one quantity.
    ///
    /// ```
    /// use moreau_sym::{Graph, Lagrangian, Mechanics, Quantity, Schedule, VarId};
    /// let mut g = Graph::new();
    /// let v = g.var(VarId(1));
    /// let t = g.powi(v, 2); // T = v², M = 2
    /// let zero = g.constant(0.0);
    /// let sys = Lagrangian { q: &[VarId(0)], v: &[VarId(1)], kinetic: t, potential: zero, forces: &[], gaps: &[] };
    /// let mech = Mechanics::derive(&mut g, &sys).unwrap();
    /// let flat = mech.flat();
    /// assert_eq!(flat.len(), 4); // M, C, G, F
    /// let ids: Vec<_> = flat.iter().map(|(_, id)| *id).collect();
    /// let fused = Schedule::new(&g, &ids);
    /// let mass: Vec<usize> = (0..flat.len()).filter(|&i| flat[i].0.quantity == Quantity::Mass).collect();
    /// assert_eq!(fused.restrict(&mass).eval(&[0.0, 0.0]), vec![2.0]);
    /// ```
    #[must_use]
    pub fn flat(&self) -> Vec<(Slot, Id)> {
        let mut out = Vec::new();
        let mut push = |quantity, row, col, id| {
            out.push((Slot { quantity, row, col }, id));
        };
        for (i, r) in self.mass.iter().enumerate() {
            for (j, &m) in r.iter().enumerate().skip(i) {
                push(Quantity::Mass, i, j, m);
            }
        }
        for (i, r) in self.coriolis.iter().enumerate() {
            for (j, &c) in r.iter().enumerate() {
                push(Quantity::Coriolis, i, j, c);
            }
        }
        for (i, &e) in self.gravity.iter().enumerate() {
            push(Quantity::Gravity, i, 0, e);
        }
        for (i, &e) in self.forces.iter().enumerate() {
            push(Quantity::Force, i, 0, e);
        }
        for (i, &e) in self.gaps.iter().enumerate() {
            push(Quantity::Gap, i, 0, e);
        }
        for (i, r) in self.jacobian.iter().enumerate() {
            for (j, &e) in r.iter().enumerate() {
                push(Quantity::Jacobian, i, j, e);
            }
        }
        out
    }
}

/// Checks that `T = ½ vᵀ M v` given that `M` is free of velocities: `p` and
/// `T` must vanish at `v = 0`.
fn check_form(g: &mut Graph, sys: &Lagrangian<'_>, momentum: &[Id]) -> Result<(), MechanicsError> {
    let zero = g.constant(0.0);
    let at_rest: Vec<(VarId, Id)> = sys.v.iter().map(|&v| (v, zero)).collect();
    for (k, &p) in momentum.iter().enumerate() {
        let p0 = g.subst(p, &at_rest);
        if !g.is_zero(p0) {
            return Err(MechanicsError::LinearTerm { velocity: k });
        }
    }
    let t0 = g.subst(sys.kinetic, &at_rest);
    if !g.is_zero(t0) {
        return Err(MechanicsError::VelocityFreeTerm);
    }
    Ok(())
}

/// Appends `c e` to `out` as a list of terms `(coefficient, expression)`,
/// looking through sums, differences, negations and constant multiples.
/// Gives up (returns `false`) after visiting `budget` nodes, so that a DAG
/// of sums cannot blow up into a huge tree.
fn flatten(g: &Graph, c: f64, e: Id, out: &mut Vec<(f64, Id)>, budget: &mut usize) -> bool {
    if *budget == 0 {
        return false;
    }
    *budget -= 1;
    match g.node(e) {
        Node::Add([a, b]) => flatten(g, c, a, out, budget) && flatten(g, c, b, out, budget),
        Node::Sub([a, b]) => flatten(g, c, a, out, budget) && flatten(g, -c, b, out, budget),
        Node::Neg(a) => flatten(g, -c, a, out, budget),
        Node::Mul([k, x]) => match g.as_const(k) {
            Some(k) => flatten(g, c * k, x, out, budget),
            None => {
                out.push((c, e));
                true
            }
        },
        Node::Const(_) if g.is_zero(e) => true,
        _ => {
            out.push((c, e));
            true
        }
    }
}

/// `terms` with equal expressions merged (coefficients added) and zero
/// terms dropped, in order of first appearance.
fn merge(g: &Graph, terms: &[(f64, Id)]) -> Vec<(f64, Id)> {
    let mut merged: Vec<(f64, Id)> = Vec::new();
    for &(c, e) in terms {
        if g.is_zero(e) {
            continue;
        }
        match merged.iter_mut().find(|(_, f)| *f == e) {
            Some((d, _)) => *d += c,
            None => merged.push((c, e)),
        }
    }
    merged.retain(|&(c, _)| c != 0.0);
    merged
}

/// `Σ c_m e_m`, with equal expressions merged first and zero terms dropped;
/// a common magnitude of the coefficients is factored out
/// (`½ a + ½ b − ½ c = ½ (a + b − c)`).
///
/// The terms are also expanded through sums and constant multiples; when
/// that expansion lets some terms merge or cancel (`∂M_ij/∂q_k` are often
/// sums whose parts cancel in a Christoffel symbol), the expanded form is
/// built instead, otherwise the given expressions are reused whole.
fn lincomb(g: &mut Graph, terms: &[(f64, Id)]) -> Id {
    let mut flat = Vec::new();
    let mut budget = 256;
    let expanded = terms
        .iter()
        .all(|&(c, e)| flatten(g, c, e, &mut flat, &mut budget));
    let deep = merge(g, &flat);
    let mut merged = if expanded && deep.len() < flat.len() {
        deep
    } else {
        merge(g, terms)
    };
    let Some(&(c0, _)) = merged.first() else {
        return g.constant(0.0);
    };
    let common = merged.iter().all(|&(c, _)| c.abs() == c0.abs());
    let scale = if common { c0.abs() } else { 1.0 };
    // Positive terms first, so that the sum reads a + b - c.
    merged.sort_by_key(|&(c, _)| c < 0.0);
    let mut acc: Option<Id> = None;
    for (c, e) in merged {
        let mag = c.abs() / scale;
        let t = if mag == 1.0 {
            e
        } else {
            let k = g.constant(mag);
            g.mul(k, e)
        };
        acc = Some(match (acc, c < 0.0) {
            (None, false) => t,
            (None, true) => g.neg(t),
            (Some(a), false) => g.add(a, t),
            (Some(a), true) => g.sub(a, t),
        });
    }
    let acc = acc.unwrap_or_else(|| g.constant(0.0));
    let k = g.constant(scale);
    g.mul(k, acc)
}

/// `Σ terms`, `0` when empty.
fn sum(g: &mut Graph, terms: &[Id]) -> Id {
    let mut acc = g.constant(0.0);
    for &t in terms {
        acc = g.add(acc, t);
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{ARM3, Built, DOUBLE_PENDULUM, PARABOLA, Rng, Spec};

    fn derive(b: &mut Built) -> Result<Mechanics, MechanicsError> {
        b.derive()
    }

    fn eval_matrix(g: &Graph, m: &[Vec<Id>], vars: &[f64]) -> Vec<Vec<f64>> {
        m.iter().map(|row| g.eval(row, vars)).collect()
    }

    /// A random point: angles and velocities in [-2, 2], parameters in
    /// [0.5, 2].
    fn point(rng: &mut Rng, b: &Built) -> Vec<f64> {
        (0..b.names.len())
            .map(|k| {
                if k < 2 * b.q.len() {
                    rng.uniform(-2.0, 2.0)
                } else {
                    rng.uniform(0.5, 2.0)
                }
            })
            .collect()
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn point_mass_under_gravity() {
        let mut b = Spec {
            coords: &[("x", "vx"), ("y", "vy")],
            params: &["m", "g"],
            defs: &[],
            kinetic: "0.5 * m * (vx^2 + vy^2)",
            potential: "m * g * y",
            forces: &[],
            gaps: &[],
        }
        .build();
        let mech = derive(&mut b).unwrap();
        let g = &mut b.g;
        let m = g.var(VarId(4));
        let grav = g.var(VarId(5));
        let zero = g.constant(0.0);
        assert_eq!(mech.mass, vec![vec![m, zero], vec![zero, m]]);
        assert_eq!(mech.coriolis, vec![vec![zero; 2]; 2]);
        assert_eq!(mech.gravity, vec![zero, g.mul(m, grav)]);
        assert_eq!(mech.forces, mech.gravity);
        let vx = g.var(VarId(2));
        assert_eq!(mech.momentum[0], g.mul(m, vx));
        assert!(mech.jacobian.is_empty());
    }

    #[test]
    fn double_pendulum_closed_forms() {
        let mut b = DOUBLE_PENDULUM.build();
        let mech = derive(&mut b).unwrap();
        let mut rng = Rng::new(7);
        for _ in 0..20 {
            let x = point(&mut rng, &b);
            let [th1, th2, w1, w2, m1, m2, l1, l2, grav, damp, wall, floor] = x[..] else {
                unreachable!()
            };
            let (s, c) = ((th1 - th2).sin(), (th1 - th2).cos());
            let mass = [
                [(m1 + m2) * l1 * l1, m2 * l1 * l2 * c],
                [m2 * l1 * l2 * c, m2 * l2 * l2],
            ];
            let cor = [[0.0, m2 * l1 * l2 * s * w2], [-m2 * l1 * l2 * s * w1, 0.0]];
            let grv = [
                (m1 + m2) * grav * l1 * th1.sin(),
                m2 * grav * l2 * th2.sin(),
            ];
            let q = [-damp * w1 + damp * (w2 - w1), -damp * (w2 - w1)];
            let h = [
                wall - l1 * th1.sin() - l2 * th2.sin(),
                floor - l1 * th1.cos() - l2 * th2.cos(),
            ];
            let jac = [
                [-l1 * th1.cos(), -l2 * th2.cos()],
                [l1 * th1.sin(), l2 * th2.sin()],
            ];
            let got_m = eval_matrix(&b.g, &mech.mass, &x);
            let got_c = eval_matrix(&b.g, &mech.coriolis, &x);
            let got_j = eval_matrix(&b.g, &mech.jacobian, &x);
            let got_g = b.g.eval(&mech.gravity, &x);
            let got_f = b.g.eval(&mech.forces, &x);
            let got_h = b.g.eval(&mech.gaps, &x);
            for i in 0..2 {
                for j in 0..2 {
                    assert!(close(got_m[i][j], mass[i][j], 1e-14), "M{i}{j}");
                    assert!(close(got_c[i][j], cor[i][j], 1e-14), "C{i}{j}");
                    assert!(close(got_j[i][j], jac[i][j], 1e-14), "J{i}{j}");
                }
                assert!(close(got_g[i], grv[i], 1e-14), "G{i}");
                let f = cor[i][0] * w1 + cor[i][1] * w2 + grv[i] - q[i];
                assert!(close(got_f[i], f, 1e-14), "F{i}");
                assert!(close(got_h[i], h[i], 1e-14), "h{i}");
            }
        }
        // Zero entries are literal zeros; C_01 is one product of shared nodes.
        assert!(b.g.is_zero(mech.coriolis[0][0]));
        assert!(b.g.is_zero(mech.coriolis[1][1]));
        let names = |v| b.name(v);
        assert_eq!(
            b.g.to_infix(mech.coriolis[0][1], &names),
            "m2 * l1 * l2 * sin(th1 - th2) * w2"
        );
        assert_eq!(b.g.to_infix(mech.mass[0][0], &names), "(m1 + m2) * l1^2");
    }

    /// Checks, at random points, that `Ṁ − 2C` is skew-symmetric (so
    /// `vᵀ (Ṁ − 2C) v = 0`), with `Ṁ = Σ_k ∂M/∂q_k v_k` by central
    /// differences of `M` along `v`, and that `F = Ṁ v − ∂T/∂q + G − Q`
    /// (the Euler–Lagrange equations), with `∂T/∂q` by central differences.
    fn check_skew_and_lagrange(spec: &Spec, seed: u64) {
        let mut b = spec.build();
        let mech = derive(&mut b).unwrap();
        let n = b.q.len();
        let mut rng = Rng::new(seed);
        for _ in 0..10 {
            let x = point(&mut rng, &b);
            let h = 1e-5;
            let shifted = |s: f64| {
                let mut y = x.clone();
                for k in 0..n {
                    y[k] += s * x[n + k];
                }
                eval_matrix(&b.g, &mech.mass, &y)
            };
            let (mp, mm) = (shifted(h), shifted(-h));
            let mdot: Vec<Vec<f64>> = (0..n)
                .map(|i| (0..n).map(|j| (mp[i][j] - mm[i][j]) / (2.0 * h)).collect())
                .collect();
            let c = eval_matrix(&b.g, &mech.coriolis, &x);
            let scale = 1.0 + mdot.iter().flatten().fold(0.0f64, |a, b| a.max(b.abs()));
            let mut vmv = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let a = mdot[i][j] - 2.0 * c[i][j];
                    let at = mdot[j][i] - 2.0 * c[j][i];
                    assert!(
                        (a + at).abs() <= 1e-7 * scale,
                        "skew at {i},{j}: {a} vs {at}"
                    );
                    vmv += x[n + i] * a * x[n + j];
                }
            }
            assert!(vmv.abs() <= 1e-7 * scale * 16.0, "vᵀ(Ṁ − 2C)v = {vmv}");
            let f = b.g.eval(&mech.forces, &x);
            let gr = b.g.eval(&mech.gravity, &x);
            let q = b.g.eval(&b.forces, &x);
            for i in 0..n {
                let mut tp = x.clone();
                let mut tm = x.clone();
                tp[i] += h;
                tm[i] -= h;
                let dtdq =
                    (b.g.eval(&[b.kinetic], &tp)[0] - b.g.eval(&[b.kinetic], &tm)[0]) / (2.0 * h);
                let mdv: f64 = (0..n).map(|j| mdot[i][j] * x[n + j]).sum();
                let want = mdv - dtdq + gr[i] - q[i];
                assert!(close(f[i], want, 1e-7), "F{i} = {}, E-L gives {want}", f[i]);
            }
        }
    }

    #[test]
    fn double_pendulum_mdot_minus_2c_is_skew() {
        check_skew_and_lagrange(&DOUBLE_PENDULUM, 11);
    }

    #[test]
    fn arm3_mdot_minus_2c_is_skew() {
        check_skew_and_lagrange(&ARM3, 13);
    }

    #[test]
    fn parabola_is_a_point_mass() {
        let mut b = PARABOLA.build();
        let mech = derive(&mut b).unwrap();
        let names = |v| b.name(v);
        let show = |e| b.g.to_infix(e, &names);
        assert_eq!(show(mech.jacobian[0][0]), "-2 * x");
        assert_eq!(show(mech.jacobian[0][1]), "1");
        assert_eq!(show(mech.jacobian[1][1]), "-1");
        assert_eq!(show(mech.forces[1]), "m * g");
    }

    fn kinetic_error(kinetic: &'static str) -> MechanicsError {
        let mut b = Spec {
            coords: &[("x", "vx"), ("y", "vy")],
            params: &["m"],
            defs: &[],
            kinetic,
            potential: "0",
            forces: &[],
            gaps: &[],
        }
        .build();
        derive(&mut b).unwrap_err()
    }

    #[test]
    fn quartic_kinetic_energy_is_not_quadratic() {
        assert_eq!(
            kinetic_error("vx^4"),
            MechanicsError::NotQuadratic {
                row: 0,
                col: 0,
                velocity: 0
            }
        );
    }

    #[test]
    fn cubic_product_kinetic_energy_is_not_quadratic() {
        assert_eq!(
            kinetic_error("vx * vy * vx"),
            MechanicsError::NotQuadratic {
                row: 0,
                col: 0,
                velocity: 1
            }
        );
    }

    #[test]
    fn mass_matrix_depending_on_velocity_is_rejected() {
        assert_eq!(
            kinetic_error("0.5 * m * vx^2 + cos(vx) * vy^2"),
            MechanicsError::NotQuadratic {
                row: 0,
                col: 0,
                velocity: 0
            }
        );
        assert_eq!(
            kinetic_error("0.5 * m * vx^2 + 0.5 * m * vy^2 * (1 + vx^2)"),
            MechanicsError::NotQuadratic {
                row: 0,
                col: 0,
                velocity: 1
            }
        );
    }

    #[test]
    fn linear_term_in_kinetic_energy_is_rejected() {
        let err = kinetic_error("m * vx^2 + vx");
        assert_eq!(err, MechanicsError::LinearTerm { velocity: 0 });
        assert!(err.describe(&["vx", "vy"]).contains("linear in vx"));
        assert_eq!(
            kinetic_error("m * vx^2 + x * vy"),
            MechanicsError::LinearTerm { velocity: 1 }
        );
    }

    #[test]
    fn velocity_free_term_in_kinetic_energy_is_rejected() {
        assert_eq!(
            kinetic_error("m * vx^2 + y^2"),
            MechanicsError::VelocityFreeTerm
        );
    }

    #[test]
    fn disguised_quadratic_forms_are_accepted() {
        let mut b = Spec {
            coords: &[("x", "vx")],
            params: &["m", "a"],
            defs: &[],
            kinetic: "0.5 * m * (vx + a)^2 - m * a * vx - 0.5 * m * a^2",
            potential: "0",
            forces: &[],
            gaps: &[],
        }
        .build();
        let mech = derive(&mut b).unwrap();
        assert_eq!(b.g.eval(&mech.mass[0], &[0.0, 0.0, 3.0, 5.0]), vec![3.0]);
    }

    #[test]
    fn shape_errors() {
        let mut g = Graph::new();
        let x = g.var(VarId(0));
        let sys = Lagrangian {
            q: &[VarId(0), VarId(1)],
            v: &[VarId(2)],
            kinetic: x,
            potential: x,
            forces: &[],
            gaps: &[],
        };
        assert_eq!(
            Mechanics::derive(&mut g, &sys),
            Err(MechanicsError::Shape {
                what: "v",
                expected: 2,
                found: 1
            })
        );
        let sys = Lagrangian {
            v: &[VarId(2), VarId(3)],
            forces: &[x],
            ..sys
        };
        let err = Mechanics::derive(&mut g, &sys).unwrap_err();
        assert_eq!(err.to_string(), "`forces` has 1 entries, expected 2");
    }

    #[test]
    fn lincomb_merges_and_factors() {
        let mut g = Graph::new();
        let a = g.var(VarId(0));
        let b = g.var(VarId(1));
        let c = g.var(VarId(2));
        let names = |v: VarId| ["a", "b", "c"][v.index()].to_string();
        let e = lincomb(&mut g, &[(0.5, a), (0.5, b), (-0.5, a)]);
        assert_eq!(g.to_infix(e, &names), "0.5 * b");
        let e = lincomb(&mut g, &[(0.5, a), (0.5, a), (-0.5, b)]);
        assert_eq!(g.to_infix(e, &names), "a - 0.5 * b");
        let e = lincomb(&mut g, &[(-0.5, c), (0.5, a), (0.5, b)]);
        assert_eq!(g.to_infix(e, &names), "0.5 * (a + b - c)");
        let e = lincomb(&mut g, &[(0.5, a), (-0.5, a)]);
        assert!(g.is_zero(e));
    }

    #[test]
    fn lincomb_cancels_inside_sums() {
        let mut g = Graph::new();
        let a = g.var(VarId(0));
        let b = g.var(VarId(1));
        let c = g.var(VarId(2));
        let names = |v: VarId| ["a", "b", "c"][v.index()].to_string();
        let half = g.constant(0.5);
        let hb = g.mul(half, b);
        let d1 = g.add(a, hb); // a + b/2
        let d2 = g.add(hb, c); // b/2 + c
        let e = lincomb(&mut g, &[(1.0, d1), (-1.0, d2)]);
        assert_eq!(g.to_infix(e, &names), "a - c");
        // without cancellation the sums are reused whole
        let e = lincomb(&mut g, &[(1.0, d1), (1.0, c)]);
        assert_eq!(g.to_infix(e, &names), "0.5 * b + a + c");
        assert_eq!(g.node(e), Node::Add([d1, c]));
    }

    #[test]
    fn lincomb_gives_up_on_exploding_sum_dags() {
        let mut g = Graph::new();
        let mut s = g.var(VarId(0));
        let y = g.var(VarId(1));
        for _ in 0..40 {
            let d = g.sub(s, y);
            s = g.add(s, d); // a DAG of 2^40 paths
        }
        let z = g.var(VarId(2));
        let e = lincomb(&mut g, &[(1.0, s), (1.0, z)]);
        assert_eq!(g.node(e), Node::Add([s, z]));
    }

    #[test]
    fn flat_layout_order() {
        let mut b = DOUBLE_PENDULUM.build();
        let mech = derive(&mut b).unwrap();
        let flat = mech.flat();
        let slots: Vec<(Quantity, usize, usize)> = flat
            .iter()
            .map(|(s, _)| (s.quantity, s.row, s.col))
            .collect();
        assert_eq!(flat.len(), 3 + 4 + 2 + 2 + 2 + 4);
        assert_eq!(slots[0], (Quantity::Mass, 0, 0));
        assert_eq!(slots[2], (Quantity::Mass, 1, 1));
        assert_eq!(slots[3], (Quantity::Coriolis, 0, 0));
        assert_eq!(slots[16], (Quantity::Jacobian, 1, 1));
        assert!(slots.windows(2).all(|w| w[0] < w[1]));
    }
}
