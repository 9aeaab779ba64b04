//! The robots of `tests/robots/` against CasADi by the Lagrangian route.
//!
//! `tests/casadi_reference.py` reads each robot with its own readers (the
//! model language of `tests/reference/modellang.py`, the URDF with Python's
//! `xml.etree` in `tests/reference/tree.py`), poses every body by the chain
//! of its joints' transforms, writes the kinetic energy `Σ ½ m |ċ|² + ½
//! ω_bᵀ I ω_b` and the potential `−Σ m gᵀ c`, and lets CasADi differentiate
//! them: `M = ∂²T/∂v²`, `C` from the Christoffel symbols of `M`, `G =
//! ∂V/∂q`, `F = C v + G − Q` (checked against Lagrange's equations), `h`,
//! `J = ∂h/∂q`, `∂F/∂q`, `∂F/∂v`, `∂(M v)/∂q` and `∂(J v)/∂q`, at 32
//! seeded points per robot (`tests/fixtures/casadi/robots/`). moreau builds
//! the same quantities from the tree by composite-rigid-body and
//! Newton–Euler recursions; every generated method must agree to 1e-12,
//! the tolerance of the models written by hand (`tests/derivatives.rs`).
//! `slider_arm_mixed.yaml` exists for this test: what the other robots do
//! not use (a YAML body on a URDF link, a locked prismatic joint, tilted
//! gravity, `direction_x/_y/_z`, energies and an input beside the tree).

use crate::common::casadi::{against_casadi, defaults_match};

use crate::{
    Go1, Panda, Serial12, SliderArm, SliderArmLimits, SliderArmMixed, TwoLinkEnergies, TwoLinkTree,
    Ur5,
};

#[test]
fn two_link_tree_matches_casadi() {
    against_casadi::<TwoLinkTree, 2, 2, 0>("robots/two_link");
    defaults_match::<TwoLinkTree, 2, 2, 0>("robots/two_link");
}

#[test]
fn two_link_energies_match_casadi() {
    against_casadi::<TwoLinkEnergies, 2, 2, 0>("robots/two_link_energies");
    defaults_match::<TwoLinkEnergies, 2, 2, 0>("robots/two_link_energies");
}

#[test]
fn slider_arm_matches_casadi() {
    against_casadi::<SliderArm, 4, 6, 0>("robots/slider_arm");
    defaults_match::<SliderArm, 4, 6, 0>("robots/slider_arm");
}

#[test]
fn slider_arm_limits_match_casadi() {
    against_casadi::<SliderArmLimits, 4, 5, 0>("robots/slider_arm_limits");
    defaults_match::<SliderArmLimits, 4, 5, 0>("robots/slider_arm_limits");
}

#[test]
fn ur5_matches_casadi() {
    against_casadi::<Ur5, 6, 6, 0>("robots/ur5");
    defaults_match::<Ur5, 6, 6, 0>("robots/ur5");
}

#[test]
fn panda_matches_casadi() {
    against_casadi::<Panda, 7, 6, 0>("robots/panda");
    defaults_match::<Panda, 7, 6, 0>("robots/panda");
}

#[test]
fn serial_12_matches_casadi() {
    against_casadi::<Serial12, 12, 6, 0>("robots/serial_12");
    defaults_match::<Serial12, 12, 6, 0>("robots/serial_12");
}

#[test]
fn slider_arm_mixed_matches_casadi() {
    against_casadi::<SliderArmMixed, 5, 6, 1>("robots/slider_arm_mixed");
    defaults_match::<SliderArmMixed, 5, 6, 1>("robots/slider_arm_mixed");
}

#[test]
fn go1_matches_casadi() {
    against_casadi::<Go1, 12, 6, 0>("robots/go1");
    defaults_match::<Go1, 12, 6, 0>("robots/go1");
}
