//! The kinematic tree on the symbolic graph: each body's world pose, the
//! world position of its points (`position_x(body, …)`) and the tree's
//! kinetic and potential energies, built as expressions of the graph from
//! the joint coordinates, so that the Lagrangian route of
//! `moreau_sym::Mechanics::derive` derives `M`, `C v` and `G` from them as
//! from energies written by hand.
//!
//! Conventions (URDF's): a joint's frame is placed in its parent's frame by
//! the translation `xyz` and the rotation `Rz(yaw) Ry(pitch) Rx(roll)`; a
//! revolute joint then rotates the body's frame by its coordinate about the
//! unit axis (Rodrigues' formula), a prismatic joint translates it by its
//! coordinate along the axis. For each body, with `R` and `p` its world
//! rotation and origin, `ω` its world angular velocity and `v` the world
//! velocity of its origin:
//!
//! ```text
//! R = R_parent R_origin R_joint(q)        p = p_parent + R_parent (xyz + R_origin a q)   (a q: prismatic only)
//! ω = ω_parent + R a q̇   (revolute)       v = v_parent + ω_parent × (p − p_parent) + R a q̇   (prismatic)
//! c = p + R com                           v_c = v + ω × (R com)
//! T = Σ ½ m |v_c|² + ½ Ωᵀ I Ω   with Ω = Rᵀ ω the angular velocity in the body's frame
//! V = − Σ m gᵀ c
//! ```
//!
//! The graph shares every subexpression (hash-consing), so a rotation is
//! built once per body and reused by its children. The size of `T` grows
//! with the square of the depth of the tree (each body's velocity sums its
//! ancestors' contributions), and differentiating it twice for `M` costs
//! more again; a composite-rigid-body (for `M`) and recursive Newton–Euler
//! (for `C v + G`) route would grow linearly and is the follow-up for trees
//! of more than a dozen joints.

use moreau_sym::{Graph, Id};

use crate::resolve::{TreeBody, VarLayout};
use crate::scope::Var;
use crate::spec::JointKind;

type V3 = [Id; 3];
type M3 = [[Id; 3]; 3];

/// A body's world pose and velocity, as graph nodes.
#[derive(Clone, Copy)]
pub(crate) struct Pose {
    /// World rotation (body frame to world).
    pub r: M3,
    /// World position of the body's origin.
    pub p: V3,
    /// World angular velocity.
    pub w: V3,
    /// World velocity of the body's origin.
    pub v: V3,
}

/// The numeric fields of a body, already lowered to graph nodes.
pub(crate) struct BodyFields {
    pub xyz: V3,
    pub rpy: V3,
    pub mass: Id,
    pub com: V3,
    pub inertia: [Id; 6],
}

/// The lowered tree: each body's pose (in the order of `Resolved::bodies`)
/// and the tree's energies.
pub(crate) struct Tree {
    pub poses: Vec<Pose>,
    pub kinetic: Id,
    pub potential: Id,
}

/// Builds every body's pose and the energies of the tree. `fields[i]` and
/// `bodies[i]` describe the same body; parents come before children.
pub(crate) fn build(
    g: &mut Graph,
    layout: VarLayout,
    bodies: &[TreeBody],
    fields: &[BodyFields],
    gravity: V3,
) -> Tree {
    let zero = g.constant(0.0);
    let one = g.constant(1.0);
    let world = Pose {
        r: [[one, zero, zero], [zero, one, zero], [zero, zero, one]],
        p: [zero; 3],
        w: [zero; 3],
        v: [zero; 3],
    };
    let mut poses: Vec<Pose> = Vec::with_capacity(bodies.len());
    let mut kinetic = zero;
    let mut potential = zero;
    for (b, f) in bodies.iter().zip(fields) {
        let parent = b.parent.map_or(world, |i| poses[i]);
        let r_origin = rpy(g, f.rpy);
        let r_joint_frame = mat_mul(g, &parent.r, &r_origin);
        let axis = b.axis.map(|a| g.constant(a));
        let (q, dq) = match b.coordinate {
            Some(i) => (
                g.var(layout.id(Var::Coordinate(i))),
                g.var(layout.id(Var::Velocity(i))),
            ),
            None => (zero, zero),
        };
        // The axis in world coordinates (a revolute joint does not turn its
        // own axis).
        let world_axis = mat_vec(g, &r_joint_frame, axis);
        let (r, offset) = match b.kind {
            JointKind::Revolute => {
                let rot = rodrigues(g, b.axis, q);
                (mat_mul(g, &r_joint_frame, &rot), f.xyz)
            }
            JointKind::Prismatic => {
                let slide = scale(g, axis, q);
                let local = mat_vec(g, &r_origin, slide);
                (r_joint_frame, add(g, f.xyz, local))
            }
            JointKind::Fixed => (r_joint_frame, f.xyz),
        };
        let arm = mat_vec(g, &parent.r, offset);
        let p = add(g, parent.p, arm);
        let carried = cross(g, parent.w, arm);
        let mut v = add(g, parent.v, carried);
        let mut w = parent.w;
        match b.kind {
            JointKind::Revolute => {
                let turn = scale(g, world_axis, dq);
                w = add(g, w, turn);
            }
            JointKind::Prismatic => {
                let slide = scale(g, world_axis, dq);
                v = add(g, v, slide);
            }
            JointKind::Fixed => {}
        }
        let pose = Pose { r, p, w, v };
        let (t, work) = energies(g, &pose, f, gravity);
        kinetic = g.add(kinetic, t);
        potential = g.sub(potential, work);
        poses.push(pose);
    }
    Tree {
        poses,
        kinetic,
        potential,
    }
}

/// One body's kinetic energy `½ (m |v_c|² + Ωᵀ I Ω)` (`Ω = Rᵀω` in the
/// body frame) and its potential energy's opposite `m gᵀ c`, at `pose`.
fn energies(g: &mut Graph, pose: &Pose, f: &BodyFields, gravity: V3) -> (Id, Id) {
    let Pose { r, p, w, v } = *pose;
    let com_world = mat_vec(g, &r, f.com);
    let c = add(g, p, com_world);
    let spin = cross(g, w, com_world);
    let vc = add(g, v, spin);
    let omega = mat_t_vec(g, &r, w);
    let [ixx, ixy, ixz, iyy, iyz, izz] = f.inertia;
    let inertia = [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]];
    let i_omega = mat_vec(g, &inertia, omega);
    let rot = dot(g, omega, i_omega);
    let lin = dot(g, vc, vc);
    let lin = g.mul(f.mass, lin);
    let twice = g.add(lin, rot);
    let half = g.constant(0.5);
    let t = g.mul(half, twice);
    let height = dot(g, gravity, c);
    let work = g.mul(f.mass, height);
    (t, work)
}

/// The world position of the point `local` of a body at `pose`.
pub(crate) fn point(g: &mut Graph, pose: &Pose, local: V3) -> V3 {
    let arm = mat_vec(g, &pose.r, local);
    add(g, pose.p, arm)
}

/// `Rz(yaw) Ry(pitch) Rx(roll)`.
fn rpy(g: &mut Graph, [roll, pitch, yaw]: V3) -> M3 {
    let (sr, cr) = (g.sin(roll), g.cos(roll));
    let (sp, cp) = (g.sin(pitch), g.cos(pitch));
    let (sy, cy) = (g.sin(yaw), g.cos(yaw));
    let zero = g.constant(0.0);
    let one = g.constant(1.0);
    let nsr = g.neg(sr);
    let nsp = g.neg(sp);
    let nsy = g.neg(sy);
    let rx = [[one, zero, zero], [zero, cr, nsr], [zero, sr, cr]];
    let ry = [[cp, zero, sp], [zero, one, zero], [nsp, zero, cp]];
    let rz = [[cy, nsy, zero], [sy, cy, zero], [zero, zero, one]];
    let zy = mat_mul(g, &rz, &ry);
    mat_mul(g, &zy, &rx)
}

/// The rotation by `angle` about the unit `axis`:
/// `cos θ I + sin θ [a]× + (1 − cos θ) a aᵀ`.
fn rodrigues(g: &mut Graph, a: [f64; 3], angle: Id) -> M3 {
    let (s, c) = (g.sin(angle), g.cos(angle));
    let one = g.constant(1.0);
    let k = g.sub(one, c);
    let cross = [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]];
    let mut r = [[c; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let outer = g.constant(a[i] * a[j]);
            let outer = g.mul(k, outer);
            let skew = g.constant(cross[i][j]);
            let skew = g.mul(s, skew);
            let diag = if i == j { c } else { g.constant(0.0) };
            let sum = g.add(diag, skew);
            r[i][j] = g.add(sum, outer);
        }
    }
    r
}

fn dot(g: &mut Graph, a: V3, b: V3) -> Id {
    let x = g.mul(a[0], b[0]);
    let y = g.mul(a[1], b[1]);
    let z = g.mul(a[2], b[2]);
    let xy = g.add(x, y);
    g.add(xy, z)
}

fn add(g: &mut Graph, a: V3, b: V3) -> V3 {
    [g.add(a[0], b[0]), g.add(a[1], b[1]), g.add(a[2], b[2])]
}

fn scale(g: &mut Graph, a: V3, s: Id) -> V3 {
    [g.mul(a[0], s), g.mul(a[1], s), g.mul(a[2], s)]
}

fn cross(g: &mut Graph, a: V3, b: V3) -> V3 {
    let mut term = |i: usize, j: usize| {
        let x = g.mul(a[i], b[j]);
        let y = g.mul(a[j], b[i]);
        g.sub(x, y)
    };
    [term(1, 2), term(2, 0), term(0, 1)]
}

fn mat_vec(g: &mut Graph, m: &M3, x: V3) -> V3 {
    [dot(g, m[0], x), dot(g, m[1], x), dot(g, m[2], x)]
}

/// `mᵀ x`.
fn mat_t_vec(g: &mut Graph, m: &M3, x: V3) -> V3 {
    let col = |j: usize| [m[0][j], m[1][j], m[2][j]];
    [dot(g, col(0), x), dot(g, col(1), x), dot(g, col(2), x)]
}

fn mat_mul(g: &mut Graph, a: &M3, b: &M3) -> M3 {
    let mut out = [[a[0][0]; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, cell) in row.iter_mut().enumerate() {
            *cell = dot(g, a[i], [b[0][j], b[1][j], b[2][j]]);
        }
    }
    out
}
