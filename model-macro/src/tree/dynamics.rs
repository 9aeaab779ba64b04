//! The tree's mass matrix by the composite-rigid-body algorithm, its bias
//! forces `C v + G` by recursive Newton–Euler and its Coriolis matrix by
//! Newton–Euler passes polarized in the velocities ([`coriolis`]), on the
//! graph, in world
//! coordinates (Featherstone, *Rigid Body Dynamics Algorithms*, 2008,
//! chapters 5 and 6, with every spatial quantity expressed in the fixed
//! world frame at its origin, so that no transform is needed between
//! bodies).
//!
//! Spatial vectors are `(angular, linear)`: a motion `(ω, v)` with `v` the
//! velocity of the body point at the world origin, a force `(n, f)` with
//! `n` the moment about the origin. A body's spatial inertia about the
//! origin is its mass `m`, first moment `h = m c` (`c` its centre of mass)
//! and rotational inertia `I_O = R I Rᵀ + m (|c|² 1 − c cᵀ)`; it maps a
//! motion to the momentum `(I_O ω + h × v, m v − h × ω)`. With `S_i` the
//! motion axis of joint `i` (`tree` module docs), `V` velocities, `A`
//! accelerations and `f` forces:
//!
//! ```text
//! V_i = V_parent + S_i q̇_i               A_i = A_parent + (V_i ×m S_i) q̇_i,  A_world = (0, −g)
//! f_i = I_i A_i + V_i ×f (I_i V_i)        f_parent += f_i  (children first)      (C v + G)_i = S_i · f_i
//! Ic_i = I_i + Σ_children Ic_child        M_ji = S_j · (Ic_i S_i)  for j = i and every ancestor j of i
//! G_i = S_i · (Ic_i A_world)
//! ```
//!
//! with `V ×m X = (ω × X_ω, ω × X_v + v × X_ω)` and
//! `V ×f F = (ω × F_n + v × F_f, ω × F_f)`. The Newton–Euler pass (with
//! `q̈ = 0`) costs a fixed number of operations per body; `M` costs one
//! six-term dot product per pair (joint, ancestor). Starting from
//! `V_world = 0`, the builders drop every product with a zero, so the first
//! bodies cost less.
//!
//! Why recursions rather than energies: `T` of a chain of `n` joints sums,
//! per body, velocities that gather all its ancestors' terms, and its second
//! derivatives multiply that out; Panda (7 joints) took 36,495 operations
//! and 5.5 s of expansion through the energies. The recursions share every
//! ancestor's velocity, acceleration and composite inertia instead (Panda:
//! 10,106 operations, 0.34 s; a 12-joint chain: 24,990, 1.0 s).

use moreau_sym::{Graph, Id};

use super::{Axis, BodyFields, M3, Pose, V3, add, cross, dot, mat_mul, mat_vec, scale};
use crate::resolve::{TreeBody, VarLayout};
use crate::scope::Var;

/// A spatial vector: `(angular, linear)`.
type Sv = [V3; 2];

/// The tree's quantities, one row per coordinate of the model (rows of
/// coordinates no joint moves are zero).
pub(crate) struct Dynamics {
    /// `M`, symmetric.
    pub mass: Vec<Vec<Id>>,
    /// `C v + G`.
    pub bias: Vec<Id>,
    /// `G`.
    pub gravity: Vec<Id>,
    /// The Coriolis matrix of the Christoffel symbols of `M`.
    pub coriolis: Vec<Vec<Id>>,
}

/// A spatial inertia about the world origin, in world coordinates.
#[derive(Clone, Copy)]
struct Inertia {
    m: Id,
    /// First moment `m c`.
    h: V3,
    /// Rotational inertia about the origin (symmetric).
    i: M3,
}

/// Runs the passes over the posed tree. `axes[i]` is body `i`'s joint.
pub(super) fn build(
    g: &mut Graph,
    layout: VarLayout,
    bodies: &[TreeBody],
    fields: &[BodyFields],
    poses: &[Pose],
    axes: &[Axis],
    gravity: V3,
) -> Dynamics {
    let inertias: Vec<Inertia> = poses
        .iter()
        .zip(fields)
        .map(|(pose, f)| body_inertia(g, pose, f))
        .collect();
    let zero = g.constant(0.0);
    let down = [g.neg(gravity[0]), g.neg(gravity[1]), g.neg(gravity[2])];
    let a_world: Sv = [[zero; 3], down];
    let parents: Vec<Option<usize>> = bodies.iter().map(|b| b.parent).collect();
    let n = layout.n;
    let (bias, motion) = newton_euler(g, layout, &parents, &inertias, axes, a_world, n);
    let coriolis = coriolis(g, &parents, &inertias, axes, &motion, n);
    let composite = composite(g, &parents, &inertias);
    let mut gravity = vec![zero; n];
    for (axis, ic) in axes.iter().zip(&composite) {
        if let Some((c, s)) = *axis {
            let weight = apply(g, ic, a_world);
            let gi = sdot(g, s, weight);
            gravity[c] = g.add(gravity[c], gi);
        }
    }
    let mass = mass_matrix(g, &parents, &composite, axes, n);
    Dynamics {
        mass,
        bias,
        gravity,
        coriolis,
    }
}

/// `C v + G` by recursive Newton–Euler with `q̈ = 0`.
fn newton_euler(
    g: &mut Graph,
    layout: VarLayout,
    parents: &[Option<usize>],
    inertias: &[Inertia],
    axes: &[Axis],
    a_world: Sv,
    n: usize,
) -> (Vec<Id>, Vec<[Sv; 3]>) {
    let zero = g.constant(0.0);
    let still: Sv = [[zero; 3]; 2];
    let mut vel: Vec<Sv> = Vec::with_capacity(axes.len());
    let mut forces: Vec<Sv> = Vec::with_capacity(axes.len());
    let mut acc: Vec<Sv> = Vec::with_capacity(axes.len());
    let mut motion = Vec::with_capacity(axes.len());
    for (i, axis) in axes.iter().enumerate() {
        let (mut v, mut a) = parents[i].map_or((still, a_world), |p| (vel[p], acc[p]));
        let mut joint = still;
        if let Some((c, s)) = *axis {
            let dq = g.var(layout.id(Var::Velocity(c)));
            joint = sscale(g, s, dq);
            v = sadd(g, v, joint);
            let turn = cross_motion(g, v, joint);
            a = sadd(g, a, turn);
        }
        let momentum = apply(g, &inertias[i], v);
        let inert = apply(g, &inertias[i], a);
        let gyro = cross_force(g, v, momentum);
        forces.push(sadd(g, inert, gyro));
        vel.push(v);
        motion.push([v, momentum, joint]);
        acc.push(a);
    }
    let mut bias = vec![zero; n];
    for i in (0..axes.len()).rev() {
        let f = forces[i];
        if let Some((c, s)) = axes[i] {
            let t = sdot(g, s, f);
            bias[c] = g.add(bias[c], t);
        }
        if let Some(p) = parents[i] {
            forces[p] = sadd(g, forces[p], f);
        }
    }
    (bias, motion)
}

/// The Coriolis matrix of the Christoffel symbols, column by column: column
/// `j` is `c(v, e_j)`, the polarization `c(v, w) = ½ (n(v + w) − n(v) −
/// n(w))` of the Newton–Euler pass's velocity terms `n(v) = C(v) v`
/// (gravity off), which is `Σ_k Γ_ijk v_k w_k` with `Γ` symmetric in `j,
/// k`: the Christoffel `C`. Each of the pass's products of two velocities
/// is polarized: with `W` the velocities of `w = e_j` (`S_j` on the subtree
/// of joint `j`, zero elsewhere),
///
/// ```text
/// 2 A_i = 2 A_parent + V_i ×m S_i w_i + W_i ×m S_i v_i
/// 2 f_i = I_i (2 A_i) + V_i ×f (I_i W_i) + W_i ×f (I_i V_i)         C_kj = ½ S_k · Σ_subtree(k) 2 f
/// ```
///
/// Outside the subtree of joint `j`, `W` and `A` vanish, so a column costs
/// the size of that subtree plus the path to the root. `motion[i]` is body
/// `i`'s velocity, momentum and joint velocity `(V_i, I_i V_i, S_i v_i)`.
fn coriolis(
    g: &mut Graph,
    parents: &[Option<usize>],
    inertias: &[Inertia],
    axes: &[Axis],
    motion: &[[Sv; 3]],
    n: usize,
) -> Vec<Vec<Id>> {
    let zero = g.constant(0.0);
    let half = g.constant(0.5);
    let mut c = vec![vec![zero; n]; n];
    let columns: Vec<usize> = axes.iter().filter_map(|a| a.map(|(c, _)| c)).collect();
    for (col, &j) in columns.iter().enumerate() {
        if columns[..col].contains(&j) {
            continue;
        }
        // (W_i, 2 A_i) per body; `None` where both vanish.
        let mut state: Vec<Option<[Sv; 2]>> = Vec::with_capacity(axes.len());
        let mut forces: Vec<Option<Sv>> = Vec::with_capacity(axes.len());
        for (i, axis) in axes.iter().enumerate() {
            let mut here = parents[i].and_then(|p| state[p]);
            if let Some((ci, s)) = *axis {
                let [v, _, dq] = motion[i];
                let [mut w, mut a] = here.unwrap_or([[[zero; 3]; 2]; 2]);
                let mut moved = here.is_some();
                if ci == j {
                    w = sadd(g, w, s);
                    let turn = cross_motion(g, v, s);
                    a = sadd(g, a, turn);
                    moved = true;
                }
                if moved {
                    let carry = cross_motion(g, w, dq);
                    a = sadd(g, a, carry);
                    here = Some([w, a]);
                }
            }
            state.push(here);
            forces.push(here.map(|[w, a]| {
                let [v, iv, _] = motion[i];
                let iw = apply(g, &inertias[i], w);
                let ia = apply(g, &inertias[i], a);
                let x = cross_force(g, v, iw);
                let y = cross_force(g, w, iv);
                let xy = sadd(g, x, y);
                sadd(g, ia, xy)
            }));
        }
        for i in (0..axes.len()).rev() {
            let Some(f) = forces[i] else { continue };
            if let Some((ci, s)) = axes[i] {
                let t = sdot(g, s, f);
                let t = g.mul(half, t);
                c[ci][j] = g.add(c[ci][j], t);
            }
            if let Some(p) = parents[i] {
                forces[p] = Some(match forces[p] {
                    Some(fp) => sadd(g, fp, f),
                    None => f,
                });
            }
        }
    }
    c
}

/// Each body's composite inertia: its own plus its descendants'.
fn composite(g: &mut Graph, parents: &[Option<usize>], inertias: &[Inertia]) -> Vec<Inertia> {
    let mut ic = inertias.to_vec();
    for i in (0..ic.len()).rev() {
        if let Some(p) = parents[i] {
            let (a, b) = (ic[p], ic[i]);
            ic[p] = Inertia {
                m: g.add(a.m, b.m),
                h: add(g, a.h, b.h),
                i: [
                    add(g, a.i[0], b.i[0]),
                    add(g, a.i[1], b.i[1]),
                    add(g, a.i[2], b.i[2]),
                ],
            };
        }
    }
    ic
}

/// `M_ji = S_j · (Ic_i S_i)` for each joint `i` and each joint `j` on the
/// path from `i` to the root, summed into the entries of their coordinates.
fn mass_matrix(
    g: &mut Graph,
    parents: &[Option<usize>],
    composite: &[Inertia],
    axes: &[Axis],
    n: usize,
) -> Vec<Vec<Id>> {
    let zero = g.constant(0.0);
    let mut mass = vec![vec![zero; n]; n];
    for (i, axis) in axes.iter().enumerate() {
        let Some((ci, si)) = *axis else { continue };
        let fi = apply(g, &composite[i], si);
        let mut j = Some(i);
        while let Some(k) = j {
            if let Some((cj, sj)) = axes[k] {
                let m = sdot(g, sj, fi);
                mass[cj][ci] = g.add(mass[cj][ci], m);
                if k != i {
                    mass[ci][cj] = g.add(mass[ci][cj], m);
                }
            }
            j = parents[k];
        }
    }
    mass
}

/// A body's spatial inertia about the world origin, at `pose`.
fn body_inertia(g: &mut Graph, pose: &Pose, f: &BodyFields) -> Inertia {
    let arm = mat_vec(g, &pose.r, f.com);
    let c = add(g, pose.p, arm);
    let h = scale(g, c, f.mass);
    let [ixx, ixy, ixz, iyy, iyz, izz] = f.inertia;
    let local = [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]];
    let ri = mat_mul(g, &pose.r, &local);
    // I_O = R I Rᵀ + m (|c|² 1 − c cᵀ), whose entries are (R I Rᵀ)_ab +
    // (h · c) δ_ab − h_a c_b.
    let hc = dot(g, h, c);
    let mut i = [[hc; 3]; 3];
    for a in 0..3 {
        for b in a..3 {
            let rot = dot(g, ri[a], pose.r[b]);
            let shift = g.mul(h[a], c[b]);
            let mut e = g.sub(rot, shift);
            if a == b {
                e = g.add(e, hc);
            }
            i[a][b] = e;
            i[b][a] = e;
        }
    }
    Inertia { m: f.mass, h, i }
}

/// The momentum `(I_O ω + h × v, m v − h × ω)` of the motion `(ω, v)`.
fn apply(g: &mut Graph, inertia: &Inertia, [w, v]: Sv) -> Sv {
    let iw = mat_vec(g, &inertia.i, w);
    let hv = cross(g, inertia.h, v);
    let mv = scale(g, v, inertia.m);
    let hw = cross(g, inertia.h, w);
    let n = add(g, iw, hv);
    let f = [
        g.sub(mv[0], hw[0]),
        g.sub(mv[1], hw[1]),
        g.sub(mv[2], hw[2]),
    ];
    [n, f]
}

/// `V ×m X = (ω × X_ω, ω × X_v + v × X_ω)`.
fn cross_motion(g: &mut Graph, [w, v]: Sv, [xw, xv]: Sv) -> Sv {
    let a = cross(g, w, xw);
    let b = cross(g, w, xv);
    let c = cross(g, v, xw);
    [a, add(g, b, c)]
}

/// `V ×f F = (ω × F_n + v × F_f, ω × F_f)`.
fn cross_force(g: &mut Graph, [w, v]: Sv, [n, f]: Sv) -> Sv {
    let a = cross(g, w, n);
    let b = cross(g, v, f);
    let c = cross(g, w, f);
    [add(g, a, b), c]
}

fn sadd(g: &mut Graph, a: Sv, b: Sv) -> Sv {
    [add(g, a[0], b[0]), add(g, a[1], b[1])]
}

fn sscale(g: &mut Graph, a: Sv, s: Id) -> Sv {
    [scale(g, a[0], s), scale(g, a[1], s)]
}

fn sdot(g: &mut Graph, a: Sv, b: Sv) -> Id {
    let x = dot(g, a[0], b[0]);
    let y = dot(g, a[1], b[1]);
    g.add(x, y)
}
