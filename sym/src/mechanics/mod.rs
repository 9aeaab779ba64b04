//! Lagrangian mechanics: from `T`, `V`, `Q` and `h` to `M`, `C`, `G`, `F`, `J`.
//!
//! For coordinates `q`, velocities `v`, kinetic energy `T(q, v) = ½ vᵀ M(q) v`,
//! potential `V(q)`, applied generalized forces `Q` and gaps `h(q) ≥ 0`, the
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
//! # Gap Jacobian
//!
//! A row of `J` is the gradient of one gap over all `N` coordinates: forward
//! mode ([`Graph::gradient`]) sweeps the gap's expression once per
//! coordinate, reverse mode ([`Graph::gradient_reverse`]) once in all. For
//! the tip of a chain of `N` joints reverse mode is the smaller, by a factor
//! growing with `N`; for a gap of few coordinates, or rows sharing their
//! forward derivatives (three components of one point), forward mode can be.
//! Neither count is known before building, so each row is built both ways
//! and the one adding fewer operations to the fused evaluation (`M`, `C`,
//! `G`, `F`, `h` and the rows before it, counted with sharing by
//! [`Schedule`]) is kept, forward on a tie: `J` never costs more than
//! forward mode alone. The two agree up to rounding.
//!
//! Each `M_ij` and `V` are put in the trigonometric normal form of
//! [`TrigForm`] before they are differentiated, so that `sin² + cos²` of an
//! angle cancels and products of `sin`/`cos` become waves of angle sums and
//! differences: a chain's `M` depends on differences of its absolute angles
//! only, or not on its first relative angle.
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

mod layout;
mod lincomb;
mod recursive;

pub use layout::{Layout, Quantity, Slot};
pub use recursive::Recursive;

use crate::graph::{Graph, TrigForm};
use crate::node::{Id, VarId};
use crate::schedule::Schedule;
use lincomb::{lincomb, sum};

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
    /// The applied generalized forces `Q`, one per coordinate, or empty for
    /// none.
    pub applied: &'a [Id],
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
///     applied: &[],
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
        /// The field: `"v"` or `"applied"`.
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
/// let sys = Lagrangian { q: &[x], v: &[vx], kinetic: t, potential: v, applied: &[], gaps: &[xe] };
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
    /// `∂F/∂q`, `N × N`, row `i` = `∇_q F_i`.
    pub force_dq: Vec<Vec<Id>>,
    /// `∂F/∂v`, `N × N`, row `i` = `∇_v F_i`.
    pub force_dv: Vec<Vec<Id>>,
    /// `∂(M v)/∂q` at fixed `v`, `N × N`: `Σ_k ∂M_ik/∂q_j v_k`.
    pub mass_dq: Vec<Vec<Id>>,
    /// `∂(J v)/∂q` at fixed `v`, `K × N`: `Σ_k ∂J_ik/∂q_j v_k`.
    pub jacobian_dq: Vec<Vec<Id>>,
}

impl Mechanics {
    /// Derives `M`, `C`, `G`, `F` and `J` of `sys` in `g`, after checking
    /// that `T` is a quadratic form in `v` (see the [module docs](self)).
    ///
    /// # Errors
    /// [`MechanicsError::Shape`] if `v` or `applied` (unless empty) do not have
    /// one entry per coordinate; [`MechanicsError::NotQuadratic`],
    /// [`MechanicsError::LinearTerm`] or [`MechanicsError::VelocityFreeTerm`]
    /// if `T` is not a quadratic form in `v`.
    pub fn derive(g: &mut Graph, sys: &Lagrangian<'_>) -> Result<Mechanics, MechanicsError> {
        Mechanics::derive_with(g, sys, None)
    }

    /// [`Mechanics::derive`], with the mass matrix, bias forces and gravity
    /// of a kinematic tree built by recursions ([`Recursive`]) added to
    /// those derived from `T` and `V` (which then hold only what the model
    /// writes besides the tree). With no `T` written besides the tree, `C`
    /// and `F = C v + G − Q` take the tree's `C` and bias; otherwise both
    /// come from the Christoffel symbols of the total `M` (see the
    /// [`Recursive`] docs).
    ///
    /// # Errors
    /// As [`Mechanics::derive`]; also [`MechanicsError::Shape`] if the
    /// tree's quantities do not have one row per coordinate.
    pub fn derive_with(
        g: &mut Graph,
        sys: &Lagrangian<'_>,
        tree: Option<&Recursive>,
    ) -> Result<Mechanics, MechanicsError> {
        let n = sys.q.len();
        if let Some(t) = tree {
            t.check(n)?;
        }
        for (what, found) in [("v", sys.v.len()), ("applied", sys.applied.len())] {
            if found != n && !(what == "applied" && found == 0) {
                return Err(MechanicsError::Shape {
                    what,
                    expected: n,
                    found,
                });
            }
        }
        let (momentum, mass) = mass_matrix(g, sys)?;
        check_form(g, sys, &momentum)?;
        let written_t = !g.is_zero(sys.kinetic);
        let potential = TrigForm::new().normal(g, sys.potential);
        let written_g = g.gradient(potential, sys.q);
        let (momentum, mass, gravity) = match tree {
            Some(t) => t.add_to(g, sys, (momentum, mass, &written_g)),
            None => (momentum, mass, written_g.clone()),
        };
        // dm[i][j][k] = ∂M_ij/∂q_k, shared by C and ∂(M v)/∂q.
        let dm = mass_derivatives(g, sys, &mass);
        let coriolis = match tree {
            Some(t) if !written_t => t.coriolis.clone(),
            _ => coriolis(g, sys, &dm),
        };
        let forces = match tree {
            // The tree's bias comes from the recursion; what the written
            // `V` adds is its gradient alone.
            Some(t) if !written_t => t.forces(g, sys, &written_g),
            _ => total_forces(g, sys, &coriolis, &gravity),
        };
        let eval: Vec<Id> = [&mass, &coriolis]
            .into_iter()
            .flatten()
            .flatten()
            .chain([&gravity, &forces].into_iter().flatten())
            .chain(sys.gaps)
            .copied()
            .collect();
        let jacobian = gap_jacobian(g, sys, eval);
        let force_dq = g.jacobian(&forces, sys.q);
        let force_dv = match tree {
            Some(t) if !written_t => t.forces_dv(g, sys, &coriolis),
            _ => g.jacobian(&forces, sys.v),
        };
        // ∂(M v)_i/∂q_j = Σ_k ∂M_ik/∂q_j v_k.
        let mass_dq = (0..n)
            .map(|i| (0..n).map(|j| contract(g, sys, &|k| dm[i][k][j])).collect())
            .collect();
        // ∂(J v)_i/∂q_j = Σ_k ∂J_ik/∂q_j v_k.
        let jacobian_dq = jacobian
            .iter()
            .map(|row: &Vec<Id>| {
                let d: Vec<Vec<Id>> = row.iter().map(|&jk| g.gradient(jk, sys.q)).collect();
                (0..n).map(|j| contract(g, sys, &|k| d[k][j])).collect()
            })
            .collect();
        Ok(Mechanics {
            momentum,
            mass,
            coriolis,
            gravity,
            forces,
            gaps: sys.gaps.to_vec(),
            jacobian,
            force_dq,
            force_dv,
            mass_dq,
            jacobian_dq,
        })
    }

    /// The layout of this system's outputs.
    #[must_use]
    pub fn layout(&self) -> Layout {
        Layout::new(self.mass.len(), self.gaps.len())
    }

    /// The expression of one entry.
    ///
    /// # Panics
    /// If the slot is outside the quantity's shape.
    #[must_use]
    pub fn get(&self, slot: Slot) -> Id {
        let (i, j) = (slot.row, slot.col);
        match slot.quantity {
            Quantity::Mass => self.mass[i][j],
            Quantity::Coriolis => self.coriolis[i][j],
            Quantity::Gravity => self.gravity[i],
            Quantity::Force => self.forces[i],
            Quantity::Gap => self.gaps[i],
            Quantity::Jacobian => self.jacobian[i][j],
            Quantity::ForceDq => self.force_dq[i][j],
            Quantity::ForceDv => self.force_dv[i][j],
            Quantity::MassDq => self.mass_dq[i][j],
            Quantity::JacobianDq => self.jacobian_dq[i][j],
        }
    }

    /// Every output in the order of [`Layout`]: entry `k` is the expression
    /// of [`Layout::slot`]`(k)`. This is the list the fused schedule is built
    /// from; a method's schedule is
    /// [`Schedule::restrict`](crate::Schedule::restrict) to
    /// [`Layout::indices`] of its quantities.
    ///
    /// ```
    /// use moreau_sym::{Graph, Lagrangian, Mechanics, Quantity, Schedule, VarId};
    /// let mut g = Graph::new();
    /// let v = g.var(VarId(1));
    /// let t = g.powi(v, 2); // T = v², M = 2
    /// let zero = g.constant(0.0);
    /// let sys = Lagrangian { q: &[VarId(0)], v: &[VarId(1)], kinetic: t, potential: zero, applied: &[], gaps: &[] };
    /// let mech = Mechanics::derive(&mut g, &sys).unwrap();
    /// let outputs = mech.outputs();
    /// assert_eq!(outputs.len(), 7); // M, C, G, F, ∂F/∂q, ∂F/∂v, ∂(Mv)/∂q
    /// let fused = Schedule::new(&g, &outputs);
    /// let mass = mech.layout().indices(&[Quantity::Mass]);
    /// assert_eq!(fused.restrict(&mass).eval(&[0.0, 0.0]), vec![2.0]);
    /// ```
    #[must_use]
    pub fn outputs(&self) -> Vec<Id> {
        let layout = self.layout();
        Quantity::ALL
            .iter()
            .flat_map(|&q| layout.slots(q))
            .map(|slot| self.get(slot))
            .collect()
    }
}

/// `p = ∂T/∂v` and `M_ij = ∂p_i/∂v_j` (built for `i ≤ j`, mirrored), after
/// checking that no entry depends on a velocity.
#[allow(clippy::needless_range_loop)]
fn mass_matrix(
    g: &mut Graph,
    sys: &Lagrangian<'_>,
) -> Result<(Vec<Id>, Vec<Vec<Id>>), MechanicsError> {
    let n = sys.q.len();
    let zero = g.constant(0.0);
    let momentum = g.gradient(sys.kinetic, sys.v);
    let mut raw = Vec::new();
    for (i, &p) in momentum.iter().enumerate() {
        for j in i..n {
            let m = g.diff(p, sys.v[j]);
            if let Some(k) = sys.v.iter().position(|&v| g.depends_on(m, v)) {
                return Err(MechanicsError::NotQuadratic {
                    row: i,
                    col: j,
                    velocity: k,
                });
            }
            raw.push((i, j, m));
        }
    }
    let entries: Vec<Id> = raw.iter().map(|&(_, _, m)| m).collect();
    let normal = TrigForm::new().normal_all(g, &entries);
    let mut mass = vec![vec![zero; n]; n];
    for (&(i, j, _), m) in raw.iter().zip(normal) {
        mass[i][j] = m;
        mass[j][i] = m;
    }
    Ok((momentum, mass))
}

/// `J = ∂h/∂q`, each row by forward or by reverse mode, whichever adds
/// fewer operations to `eval` (the rest of the fused evaluation) and the
/// rows already chosen; forward on a tie (see the [module docs](self)).
fn gap_jacobian(g: &mut Graph, sys: &Lagrangian<'_>, mut eval: Vec<Id>) -> Vec<Vec<Id>> {
    let mut jacobian = Vec::with_capacity(sys.gaps.len());
    for &h in sys.gaps {
        let forward = g.gradient(h, sys.q);
        let reverse = g.gradient_reverse(h, sys.q);
        let cost = |row: &[Id]| {
            let outputs: Vec<Id> = eval.iter().chain(row).copied().collect();
            Schedule::new(g, &outputs).op_count()
        };
        let row = if cost(&reverse) < cost(&forward) {
            reverse
        } else {
            forward
        };
        eval.extend_from_slice(&row);
        jacobian.push(row);
    }
    jacobian
}

/// `dm[i][j][k] = ∂M_ij/∂q_k`, built for `i ≤ j` and mirrored.
// Index loops mirror the formulas' indices (M_ij, Γ_ijk).
#[allow(clippy::needless_range_loop)]
fn mass_derivatives(g: &mut Graph, sys: &Lagrangian<'_>, mass: &[Vec<Id>]) -> Vec<Vec<Vec<Id>>> {
    let n = mass.len();
    let mut dm = vec![vec![Vec::new(); n]; n];
    for i in 0..n {
        for j in i..n {
            let d = g.gradient(mass[i][j], sys.q);
            dm[j][i].clone_from(&d);
            dm[i][j] = d;
        }
    }
    dm
}

// Index loops mirror the formulas' indices (M_ij, Γ_ijk).
#[allow(clippy::needless_range_loop)]
/// `C_ij = Σ_k Γ_ijk v_k` with `Γ_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i)`.
fn coriolis(g: &mut Graph, sys: &Lagrangian<'_>, dm: &[Vec<Vec<Id>>]) -> Vec<Vec<Id>> {
    let n = dm.len();
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let row = (0..n)
            .map(|j| {
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
                sum(g, &terms)
            })
            .collect();
        out.push(row);
    }
    out
}

/// `F = C v + G − Q`, reusing the entries of `C`.
fn total_forces(
    g: &mut Graph,
    sys: &Lagrangian<'_>,
    coriolis: &[Vec<Id>],
    gravity: &[Id],
) -> Vec<Id> {
    let mut forces = Vec::with_capacity(coriolis.len());
    for (i, row) in coriolis.iter().enumerate() {
        let mut terms = Vec::new();
        for (j, &c) in row.iter().enumerate() {
            if !g.is_zero(c) {
                let vj = g.var(sys.v[j]);
                terms.push(g.mul(c, vj));
            }
        }
        let cv = sum(g, &terms);
        let f = g.add(cv, gravity[i]);
        forces.push(match sys.applied.get(i) {
            Some(&q) => g.sub(f, q),
            None => f,
        });
    }
    forces
}

/// `Σ_k d(k) v_k`, skipping zero terms.
fn contract(g: &mut Graph, sys: &Lagrangian<'_>, d: &dyn Fn(usize) -> Id) -> Id {
    let mut terms = Vec::new();
    for (k, &v) in sys.v.iter().enumerate() {
        if !g.is_zero(d(k)) {
            let vk = g.var(v);
            terms.push(g.mul(d(k), vk));
        }
    }
    sum(g, &terms)
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

#[cfg(test)]
mod tests;
