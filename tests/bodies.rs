//! The `bodies` section: a kinematic tree compiled to the same mechanics as
//! the energies written by hand. `tests/robots/two_link.yaml` (a tree with
//! a fixed tip body and `position_x`/`position_z` constraints) against
//! `tests/robots/two_link_energies.yaml` (the same arm, T and V by hand):
//! M, C, G, F, ∂F/∂q, ∂F/∂v, h and J agree at seeded configurations to
//! 1e-12 relative;
//! the same tree written inline gives the same values bit for bit; energies
//! written beside the tree add their hand-derived Lagrangian terms.

use moreau::Model;
use nalgebra::{SVector, Vector2};

moreau::model!(file = "tests/robots/two_link.yaml");
moreau::model!(file = "tests/robots/two_link_energies.yaml");

moreau::model! {
    /// `tests/robots/two_link.yaml`, written inline.
    pub struct TwoLinkInline;
    parameters { m1: 1.5, m2: 0.7, l1: 0.9, l2: 0.6, g: 9.81 }
    gravity = [0, 0, -g];
    bodies {
        upper: {
            parent: world,
            joint: revolute(a1: w1),
            axis: [0, -1, 0],
            xyz: [0, 0, 0.3],
            mass: m1,
            com: [0, 0, -l1 / 2],
            inertia: [m1 * l1^2 / 12, 0, 0, m1 * l1^2 / 12, 0, 0],
        },
        lower: {
            parent: upper,
            joint: revolute(a2),
            axis: [0, -2, 0],
            xyz: [0, 0, -l1],
            mass: m2,
            com: [0, 0, -l2 / 2],
            inertia: [m2 * l2^2 / 12, 0, 0, m2 * l2^2 / 12, 0, 0],
        },
        tip: { parent: lower, joint: fixed, xyz: [0, 0, -l2], rpy: [0.3, -0.2, 1.1], mass: 0.25 },
    }
    applied { a2: -0.1 * da2 }
    constraints {
        floor: position_z(tip) + 1.2 >= 0,
        wall: 1.1 - position_x(lower, 0, 0, -l2) >= 0,
    }
    restitution = 0.5;
}

moreau::model! {
    /// `TwoLinkInline` with energies written beside the tree: a term
    /// `½ μ a1² da2²` in `T` and a spring `½ k a2²` in `V`.
    pub struct TwoLinkMixed;
    parameters { m1: 1.5, m2: 0.7, l1: 0.9, l2: 0.6, g: 9.81, mu: 0.3, k: 2.0 }
    gravity = [0, 0, -g];
    bodies {
        upper: {
            parent: world,
            joint: revolute(a1: w1),
            axis: [0, -1, 0],
            xyz: [0, 0, 0.3],
            mass: m1,
            com: [0, 0, -l1 / 2],
            inertia: [m1 * l1^2 / 12, 0, 0, m1 * l1^2 / 12, 0, 0],
        },
        lower: {
            parent: upper,
            joint: revolute(a2),
            axis: [0, -2, 0],
            xyz: [0, 0, -l1],
            mass: m2,
            com: [0, 0, -l2 / 2],
            inertia: [m2 * l2^2 / 12, 0, 0, m2 * l2^2 / 12, 0, 0],
        },
        tip: { parent: lower, joint: fixed, xyz: [0, 0, -l2], rpy: [0.3, -0.2, 1.1], mass: 0.25 },
    }
    kinetic = 0.5 * mu * a1^2 * da2^2;
    potential = 0.5 * k * a2^2;
    applied { a2: -0.1 * da2 }
    constraints {
        floor: position_z(tip) + 1.2 >= 0,
        wall: 1.1 - position_x(lower, 0, 0, -l2) >= 0,
    }
    restitution = 0.5;
}

/// A small deterministic generator (xorshift), so the configurations are
/// the same on every run.
fn uniform(state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}

fn close(a: f64, b: f64, what: &str) {
    let scale = a.abs().max(b.abs()).max(1.0);
    assert!(
        (a - b).abs() <= 1e-12 * scale,
        "{what}: tree {a} vs by hand {b}"
    );
}

#[test]
fn tree_matches_energies_written_by_hand() {
    let tree = TwoLinkTree::<f64>::new();
    let hand = TwoLinkEnergies::<f64>::new();
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    for _ in 0..20 {
        let q = Vector2::new(3.0 * uniform(&mut seed), 3.0 * uniform(&mut seed));
        let v = Vector2::new(2.0 * uniform(&mut seed), 2.0 * uniform(&mut seed));
        let u = SVector::<f64, 0>::zeros();
        let pairs = [
            (
                "M",
                tree.mass(&q).as_slice().to_vec(),
                hand.mass(&q).as_slice().to_vec(),
            ),
            (
                "C",
                tree.coriolis(&q, &v).as_slice().to_vec(),
                hand.coriolis(&q, &v).as_slice().to_vec(),
            ),
            (
                "G",
                tree.gravity(&q).as_slice().to_vec(),
                hand.gravity(&q).as_slice().to_vec(),
            ),
            (
                "F",
                tree.forces(0.0, &q, &v, &u).as_slice().to_vec(),
                hand.forces(0.0, &q, &v, &u).as_slice().to_vec(),
            ),
            (
                "∂F/∂q",
                tree.linearization(0.0, &q, &v, &u)
                    .forces_dq
                    .as_slice()
                    .to_vec(),
                hand.linearization(0.0, &q, &v, &u)
                    .forces_dq
                    .as_slice()
                    .to_vec(),
            ),
            (
                "∂F/∂v",
                tree.linearization(0.0, &q, &v, &u)
                    .forces_dv
                    .as_slice()
                    .to_vec(),
                hand.linearization(0.0, &q, &v, &u)
                    .forces_dv
                    .as_slice()
                    .to_vec(),
            ),
            (
                "h",
                tree.gaps(&q).as_slice().to_vec(),
                hand.gaps(&q).as_slice().to_vec(),
            ),
            (
                "J",
                tree.gap_jacobian(&q).as_slice().to_vec(),
                hand.gap_jacobian(&q).as_slice().to_vec(),
            ),
        ];
        for (what, a, b) in pairs {
            for (x, y) in a.iter().zip(&b) {
                close(*x, *y, what);
            }
        }
    }
}

/// The inline form builds the same model as the YAML form: the same
/// values, bit for bit.
#[test]
fn inline_bodies_are_the_yaml_bodies() {
    let yaml = TwoLinkTree::<f64>::new();
    let inline = TwoLinkInline::<f64>::new();
    assert_eq!(TwoLinkInline::<f64>::INFO.velocities, ["w1", "da2"]);
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    for _ in 0..10 {
        let q = Vector2::new(3.0 * uniform(&mut seed), 3.0 * uniform(&mut seed));
        let v = Vector2::new(2.0 * uniform(&mut seed), 2.0 * uniform(&mut seed));
        let u = SVector::<f64, 0>::zeros();
        assert_eq!(yaml.mass(&q), inline.mass(&q));
        assert_eq!(yaml.forces(0.0, &q, &v, &u), inline.forces(0.0, &q, &v, &u));
        assert_eq!(yaml.gaps(&q), inline.gaps(&q));
        assert_eq!(yaml.gap_jacobian(&q), inline.gap_jacobian(&q));
    }
}

#[test]
fn joint_coordinates_and_generated_velocity_names() {
    let info = TwoLinkTree::<f64>::INFO;
    assert_eq!(info.coordinates, ["a1", "a2"]);
    assert_eq!(info.velocities, ["w1", "da2"]);
}

#[test]
fn body_numbers_follow_their_parameters() {
    // A heavier lower link changes M as the hand-written model says.
    let mut tree = TwoLinkTree::<f64>::new();
    let mut hand = TwoLinkEnergies::<f64>::new();
    tree.m2 = 2.5;
    hand.m2 = 2.5;
    let q = Vector2::new(0.4, -1.3);
    for (x, y) in tree.mass(&q).iter().zip(hand.mass(&q).iter()) {
        close(*x, *y, "M with m2 = 2.5");
    }
    assert!((tree.mass(&q)[(1, 1)] - TwoLinkTree::<f64>::new().mass(&q)[(1, 1)]).abs() > 0.1);
}

/// Energies written beside a tree add their Lagrangian terms to the tree's:
/// `M` gains `μ a1²` at `[1,1]`, `G` and `F` gain `k a2` in row 1, and `C`
/// gains the Christoffel matrix of that `M`, `μ a1 [[0, −da2], [da2, w1]]`
/// (worked out by hand), at seeded states.
#[test]
fn energies_written_beside_a_tree_add_to_it() {
    let (mu, k) = (0.3, 2.0);
    let tree = TwoLinkInline::<f64>::new();
    let mixed = TwoLinkMixed::<f64>::new();
    let mut seed = 0x1234_5678_9abc_def1_u64;
    for _ in 0..20 {
        let q = Vector2::new(3.0 * uniform(&mut seed), 3.0 * uniform(&mut seed));
        let v = Vector2::new(2.0 * uniform(&mut seed), 2.0 * uniform(&mut seed));
        let u = SVector::<f64, 0>::zeros();
        let mut m = tree.mass(&q);
        m[(1, 1)] += mu * q[0] * q[0];
        let mut c = tree.coriolis(&q, &v);
        c[(0, 1)] -= mu * q[0] * v[1];
        c[(1, 0)] += mu * q[0] * v[1];
        c[(1, 1)] += mu * q[0] * v[0];
        let mut g = tree.gravity(&q);
        g[1] += k * q[1];
        let f = tree.forces(0.0, &q, &v, &u) + Vector2::new(0.0, k * q[1]) + c * v
            - tree.coriolis(&q, &v) * v;
        let pairs = [
            (
                "M",
                mixed.mass(&q).as_slice().to_vec(),
                m.as_slice().to_vec(),
            ),
            (
                "C",
                mixed.coriolis(&q, &v).as_slice().to_vec(),
                c.as_slice().to_vec(),
            ),
            (
                "G",
                mixed.gravity(&q).as_slice().to_vec(),
                g.as_slice().to_vec(),
            ),
            (
                "F",
                mixed.forces(0.0, &q, &v, &u).as_slice().to_vec(),
                f.as_slice().to_vec(),
            ),
        ];
        for (what, a, b) in pairs {
            for (x, y) in a.iter().zip(&b) {
                close(*x, *y, what);
            }
        }
    }
}

moreau::model! {
    /// `TwoLinkInline`'s tree with its `tip`'s orientation read through
    /// the gaps: the world components of the directions `[0.6, 0, 0.8]`
    /// and `[0, 1, 0]` fixed in the tip, and of the tip's point at
    /// `[0.6, 0, 0.8]` less its origin (each gap is the value plus 2; the
    /// `y` gaps also add `a1`: the joints turn about `y`, which leaves the
    /// `y` components constant, and a constant gap is rejected).
    pub struct TwoLinkOriented;
    parameters { m1: 1.5, m2: 0.7, l1: 0.9, l2: 0.6, g: 9.81 }
    gravity = [0, 0, -g];
    bodies {
        upper: {
            parent: world,
            joint: revolute(a1: w1),
            axis: [0, -1, 0],
            xyz: [0, 0, 0.3],
            mass: m1,
            com: [0, 0, -l1 / 2],
            inertia: [m1 * l1^2 / 12, 0, 0, m1 * l1^2 / 12, 0, 0],
        },
        lower: {
            parent: upper,
            joint: revolute(a2),
            axis: [0, -2, 0],
            xyz: [0, 0, -l1],
            mass: m2,
            com: [0, 0, -l2 / 2],
            inertia: [m2 * l2^2 / 12, 0, 0, m2 * l2^2 / 12, 0, 0],
        },
        tip: { parent: lower, joint: fixed, xyz: [0, 0, -l2], rpy: [0.3, -0.2, 1.1], mass: 0.25 },
    }
    constraints {
        ux: direction_x(tip, 0.6, 0, 0.8) + 2 >= 0,
        uy: direction_y(tip, 0.6, 0, 0.8) + a1 + 2 >= 0,
        uz: direction_z(tip, 0.6, 0, 0.8) + 2 >= 0,
        wx: direction_x(tip, 0, 1, 0) + 2 >= 0,
        wy: direction_y(tip, 0, 1, 0) + a1 + 2 >= 0,
        wz: direction_z(tip, 0, 1, 0) + 2 >= 0,
        px: position_x(tip, 0.6, 0, 0.8) - position_x(tip) + 2 >= 0,
        py: position_y(tip, 0.6, 0, 0.8) - position_y(tip) + a1 + 2 >= 0,
        pz: position_z(tip, 0.6, 0, 0.8) - position_z(tip) + 2 >= 0,
    }
    restitution = 0.5;
}

/// `direction_x/_y/_z(body, x, y, z)` is the body's rotation applied to
/// `[x, y, z]`: against the rotation written by hand (the tip turns about
/// `−y` by `a1 + a2`, the joints' axes normalised as URDF does, then by its
/// roll-pitch-yaw), to 1e-12; the directions keep their lengths and their
/// right angle; a point's offset from its body's origin is its direction;
/// and the generated Jacobian of each is its derivative (central
/// differences, 1e-7).
#[test]
fn directions_are_the_bodys_rotation() {
    use nalgebra::{Rotation3, Vector3};
    let model = TwoLinkOriented::<f64>::new();
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    for _ in 0..20 {
        let q = Vector2::new(3.0 * uniform(&mut seed), 3.0 * uniform(&mut seed));
        let mut h = model.gaps(&q).add_scalar(-2.0);
        for i in [1, 4, 7] {
            h[i] -= q[0];
        }
        let (u, w, p) = (
            Vector3::new(h[0], h[1], h[2]),
            Vector3::new(h[3], h[4], h[5]),
            Vector3::new(h[6], h[7], h[8]),
        );
        let rotation = Rotation3::from_axis_angle(&Vector3::y_axis(), -(q[0] + q[1]))
            * Rotation3::from_euler_angles(0.3, -0.2, 1.1);
        let (u_hand, w_hand) = (
            rotation * Vector3::new(0.6, 0.0, 0.8),
            rotation * Vector3::new(0.0, 1.0, 0.0),
        );
        for i in 0..3 {
            close(u[i], u_hand[i], "direction [0.6, 0, 0.8]");
            close(w[i], w_hand[i], "direction [0, 1, 0]");
            close(p[i], u[i], "point offset against direction");
        }
        close(u.norm(), 1.0, "|R u|");
        close(w.norm(), 1.0, "|R w|");
        close(u.dot(&w), 0.0, "R u · R w");
        let jac = model.gap_jacobian(&q);
        for k in 0..2 {
            let dq = Vector2::from_fn(|i, _| if i == k { 1e-6 } else { 0.0 });
            let fd = (model.gaps(&(q + dq)) - model.gaps(&(q - dq))) / 2e-6;
            for i in 0..9 {
                assert!(
                    (jac[(i, k)] - fd[i]).abs() < 1e-7,
                    "J[{i}, {k}] {} against {}",
                    jac[(i, k)],
                    fd[i]
                );
            }
        }
    }
}

moreau::model! {
    /// Two point masses on a planar arm whose elbow mimics its shoulder:
    /// the elbow turns by `k θ + o` when the shoulder turns by `θ`
    /// (`mimic`, as URDF's `<mimic>`), so the arm has one coordinate.
    pub struct Coupled;
    parameters { m1: 1.2, m2: 0.8, l1: 0.7, l2: 0.5, g: 9.81 }
    gravity = [0, -g, 0];
    bodies {
        upper: { joint: revolute(th: dth), axis: [0, 0, 1], mass: m1, com: [l1, 0, 0] },
        lower: {
            parent: upper,
            joint: revolute,
            mimic: th,
            multiplier: -0.4,
            offset: 0.3,
            axis: [0, 0, 1],
            xyz: [l1, 0, 0],
            mass: m2,
            com: [l2, 0, 0],
        },
    }
    constraints { floor: position_y(lower, l2, 0, 0) + 1 >= 0 }
    restitution = 0.5;
}

/// A joint that mimics another (`mimic: th, multiplier: k, offset: o`):
/// the arm's one-coordinate mass matrix, gravity, forces and tip against
/// the closed form of two point masses, the elbow at `φ = (1 + k) θ + o`
/// in the world: `M = m1 l1² + m2 (l1² + (1 + k)² l2² + 2 (1 + k) l1 l2
/// cos(φ − θ))`, `G = g (m1 l1 cos θ + m2 (l1 cos θ + (1 + k) l2 cos φ))`.
#[test]
fn a_mimicking_joint_follows_its_coordinate() {
    let model = Coupled::<f64>::new();
    assert_eq!(Coupled::<f64>::INFO.coordinates, ["th"]);
    let (m1, m2, l1, l2, g, k, o) = (1.2, 0.8, 0.7, 0.5, 9.81, -0.4, 0.3);
    let mut state = 7_u64;
    for _ in 0..8 {
        let th = 3.0 * uniform(&mut state);
        let dth = 2.0 * uniform(&mut state);
        let (q, v) = (SVector::<f64, 1>::new(th), SVector::<f64, 1>::new(dth));
        let phi = (1.0 + k) * th + o;
        let mass = m1 * l1 * l1
            + m2 * (l1 * l1
                + (1.0 + k) * (1.0 + k) * l2 * l2
                + 2.0 * (1.0 + k) * l1 * l2 * (phi - th).cos());
        let gravity = g * (m1 * l1 * th.cos() + m2 * (l1 * th.cos() + (1.0 + k) * l2 * phi.cos()));
        // C v = ½ M'(θ) θ̇² for one coordinate; M' = −2 m2 (1 + k) k l1 l2 sin(φ − θ)
        let dmass = -2.0 * m2 * (1.0 + k) * k * l1 * l2 * (phi - th).sin();
        close(model.mass(&q)[(0, 0)], mass, "M");
        close(model.gravity(&q)[0], gravity, "G");
        let u = SVector::<f64, 0>::zeros();
        close(
            model.forces(0.0, &q, &v, &u)[0],
            0.5 * dmass * dth * dth + gravity,
            "F = C v + G",
        );
        let tip = l1 * th.sin() + l2 * phi.sin();
        close(model.gaps(&q)[0], tip + 1.0, "h");
        let dtip = l1 * th.cos() + l2 * (1.0 + k) * phi.cos();
        close(model.gap_jacobian(&q)[(0, 0)], dtip, "J");
    }
}
