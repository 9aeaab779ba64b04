//! The kinematic tree on the symbolic graph: each body's world pose, the
//! world position of its points (`position_x(body, …)`), and the tree's
//! mass matrix, bias forces `C v + G` and gravity `G` by recursions
//! ([`dynamics`]), which `moreau_sym::Mechanics::derive_with` takes as they
//! are instead of deriving them from energies.
//!
//! Conventions (URDF's): a joint's frame is placed in its parent's frame by
//! the translation `xyz` and the rotation `Rz(yaw) Ry(pitch) Rx(roll)`; a
//! revolute joint then rotates the body's frame by its coordinate about the
//! unit axis (Rodrigues' formula), a prismatic joint translates it by its
//! coordinate along the axis. For each body, with `R` and `p` its world
//! rotation and origin and `a` the joint's axis in world coordinates:
//!
//! ```text
//! R = R_parent R_origin R_joint(q)        p = p_parent + R_parent (xyz + R_origin a q)   (a q: prismatic only)
//! S = (a, p × a)   (revolute)             S = (0, a)   (prismatic)
//! ```
//!
//! `S` is the joint's motion axis as a spatial vector (angular part, then
//! the velocity of the body point at the world origin) in world
//! coordinates, what the recursions of [`dynamics`] work with. The graph
//! shares every subexpression (hash-consing), so a rotation is built once
//! per body and reused by its children: one `sin`/`cos` pair per revolute
//! joint.

mod dynamics;

use moreau_sym::{Graph, Id};

use crate::resolve::{TreeBody, VarLayout};
use crate::spec::JointKind;

pub(crate) use dynamics::Dynamics;

type V3 = [Id; 3];
type M3 = [[Id; 3]; 3];

/// A body's world pose, as graph nodes.
#[derive(Clone, Copy)]
pub(crate) struct Pose {
    /// World rotation (body frame to world).
    pub r: M3,
    /// World position of the body's origin.
    pub p: V3,
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
/// and the tree's dynamics.
pub(crate) struct Tree {
    pub poses: Vec<Pose>,
    pub dynamics: Dynamics,
}

/// One body's joint as a spatial motion axis in world coordinates: its
/// coordinate and `S = (angular, linear)`. `None` for a fixed joint.
type Axis = Option<(usize, [V3; 2])>;

/// Builds every body's pose and the tree's dynamics. `fields[i]` and
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
    };
    let mut poses: Vec<Pose> = Vec::with_capacity(bodies.len());
    let mut axes: Vec<Axis> = Vec::with_capacity(bodies.len());
    for (b, f) in bodies.iter().zip(fields) {
        let parent = b.parent.map_or(world, |i| poses[i]);
        let (pose, axis) = place(g, layout, b, f, &parent);
        poses.push(pose);
        axes.push(axis);
    }
    let dynamics = dynamics::build(g, layout, bodies, fields, &poses, &axes, gravity);
    Tree { poses, dynamics }
}

/// A body's pose from its parent's, and its joint's motion axis.
fn place(
    g: &mut Graph,
    layout: VarLayout,
    b: &TreeBody,
    f: &BodyFields,
    parent: &Pose,
) -> (Pose, Axis) {
    let zero = g.constant(0.0);
    let r_origin = rpy(g, f.rpy);
    let r_joint_frame = mat_mul(g, &parent.r, &r_origin);
    let axis = b.axis.map(|a| g.constant(a));
    let q = match b.coordinate {
        Some(i) => g.var(layout.id(crate::scope::Var::Coordinate(i))),
        None => zero,
    };
    // A joint that mimics another: `scale · q + offset`, its axis `scale S`.
    let (multiplier, shift) = b.follow;
    let follows = (multiplier, shift) != (1.0, 0.0);
    let q = if follows {
        let (factor, shift) = (g.constant(multiplier), g.constant(shift));
        let scaled = g.mul(factor, q);
        g.add(scaled, shift)
    } else {
        q
    };
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
    // The axis in world coordinates (a revolute joint does not turn its
    // own axis).
    let a = mat_vec(g, &r_joint_frame, axis);
    let a = if follows {
        let factor = g.constant(multiplier);
        scale(g, a, factor)
    } else {
        a
    };
    let motion = match b.kind {
        JointKind::Revolute => Some([a, cross(g, p, a)]),
        JointKind::Prismatic => Some([[zero; 3], a]),
        JointKind::Fixed => None,
    };
    (Pose { r, p }, b.coordinate.zip(motion))
}

/// The world position of the point `local` of a body at `pose`.
pub(crate) fn point(g: &mut Graph, pose: &Pose, local: V3) -> V3 {
    let arm = direction(g, pose, local);
    add(g, pose.p, arm)
}

/// The world components of the direction `local` fixed in a body of pose
/// `pose`: `R local` (`direction_x(body, x, y, z)` and `_y`, `_z`).
pub(crate) fn direction(g: &mut Graph, pose: &Pose, local: V3) -> V3 {
    mat_vec(g, &pose.r, local)
}

/// `Rz(yaw) Ry(pitch) Rx(roll)`.
fn rpy(g: &mut Graph, [roll, pitch, yaw]: V3) -> M3 {
    let (sr, cr) = sin_cos(g, roll);
    let (sp, cp) = sin_cos(g, pitch);
    let (sy, cy) = sin_cos(g, yaw);
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

/// `(sin x, cos x)`; for a constant within 1e-12 of a multiple of π/2 (a
/// URDF's `1.5707963267948966`), the exact values `0` and `±1`, so that a
/// quarter turn folds to a permutation instead of leaving products with
/// `cos(π/2) = 6.1e-17` in the generated code (a change of at most 1e-12
/// in the entries of the rotation).
fn sin_cos(g: &mut Graph, x: Id) -> (Id, Id) {
    let Some(c) = g.as_const(x) else {
        return (g.sin(x), g.cos(x));
    };
    let turns = (c / std::f64::consts::FRAC_PI_2).round();
    let (s, c) = if (c - turns * std::f64::consts::FRAC_PI_2).abs() < 1e-12 {
        match turns.rem_euclid(4.0) as u8 {
            0 => (0.0, 1.0),
            1 => (1.0, 0.0),
            2 => (0.0, -1.0),
            _ => (-1.0, 0.0),
        }
    } else {
        c.sin_cos()
    };
    (g.constant(s), g.constant(c))
}

/// The rotation by `angle` about the unit `axis`:
/// `cos θ I + sin θ [a]× + (1 − cos θ) a aᵀ`. About a coordinate axis the
/// builders fold it to the exact rotation: the zero entries of `a` drop
/// their terms and `cos θ + (1 − cos θ)` is `1` (`a + (b − a) → b`).
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

fn mat_mul(g: &mut Graph, a: &M3, b: &M3) -> M3 {
    let mut out = [[a[0][0]; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, cell) in row.iter_mut().enumerate() {
            *cell = dot(g, a[i], [b[0][j], b[1][j], b[2][j]]);
        }
    }
    out
}
