//! The `bodies` section: a kinematic tree compiled to the same mechanics as
//! the energies written by hand. `tests/robots/two_link.yaml` (a tree with
//! a fixed tip body and `position_x`/`position_z` constraints) against
//! `tests/robots/two_link_energies.yaml` (the same arm, T and V by hand):
//! M, C, G, F, h and J agree at seeded configurations to 1e-12 relative.

use moreau::Model;
use nalgebra::{SVector, Vector2};

moreau::model!(file = "tests/robots/two_link.yaml");
moreau::model!(file = "tests/robots/two_link_energies.yaml");

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
