//! URDF import beyond the dynamics (which `tests/robots/pinocchio.rs` checks):
//! joint limits turned into constraints on request. The limits are those
//! written in `tests/robots/urdf/synthetic/slider_arm.urdf`: `slide` in
//! [-1, 1], `shoulder` in [-3, 3].

use moreau::Model;
use nalgebra::SVector;

moreau::model!(file = "tests/robots/slider_arm_limits.yaml");

#[test]
fn limits_become_constraints_after_the_written_ones() {
    let info = SliderArmLimits::<f64>::INFO;
    assert_eq!(
        info.constraints,
        [
            "table",
            "slide_lower",
            "slide_upper",
            "shoulder_lower",
            "shoulder_upper"
        ]
    );
    assert_eq!(
        info.coordinates,
        ["slide", "shoulder", "elbow", "side_slide"]
    );
}

#[test]
fn limit_gaps_and_jacobians_are_the_urdf_numbers() {
    let model = SliderArmLimits::<f64>::new();
    let q = SVector::<f64, 4>::new(0.25, -1.0, 2.0, 0.5);
    let h = model.gaps(&q);
    assert_eq!(
        [h[1], h[2], h[3], h[4]],
        [0.25 + 1.0, 1.0 - 0.25, -1.0 + 3.0, 3.0 + 1.0]
    );
    let j = model.gap_jacobian(&q);
    for (row, column, sign) in [(1, 0, 1.0), (2, 0, -1.0), (3, 1, 1.0), (4, 1, -1.0)] {
        for c in 0..4 {
            let expected = if c == column { sign } else { 0.0 };
            assert_eq!(j[(row, c)], expected, "J[{row}, {c}]");
        }
    }
    // Every constraint takes the model's restitution.
    assert!(model.restitution().iter().all(|&e| e == 0.1));
}
