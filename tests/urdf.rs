//! URDF import beyond the dynamics (which `tests/robots/pinocchio.rs` checks):
//! joint limits turned into constraints on request, and the URDF's names
//! that are not the model's. The limits are those written in
//! `tests/robots/urdf/synthetic/slider_arm.urdf` (`slide` in [-1, 1],
//! `shoulder` in [-3, 3]) and `tests/robots/urdf/synthetic/names.urdf`
//! (`joint.1` in [-2, 2], `type` in [0, 0.1]).

use moreau::Model;
use nalgebra::SVector;

moreau::model!(file = "tests/robots/slider_arm_limits.yaml");
moreau::model!(file = "tests/robots/names.yaml");

/// `names.yaml` written inline: `locked` and `limits` take the joints by
/// their coordinates' names here, by the URDF's there.
mod inline {
    moreau::model! {
        pub struct Names;
        urdf = "tests/robots/urdf/synthetic/names.urdf";
        limits { joint_1, type_ }
        constraints {
            wall: position_x(tool_tip) <= 0.5,
            elbow_bent: elbow + 1 >= 0,
            elbow_up: position_y(elbow) >= 0,
        }
        restitution = 0.1;
    }

    moreau::model! {
        pub struct Locked;
        urdf = "tests/robots/urdf/synthetic/names.urdf";
        locked { joint_1 }
        constraints { wall: position_x(tool_tip) <= 0.5 }
        restitution = 0.1;
    }
}

moreau::model!(file = "tests/robots/names_locked.yaml");

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

/// A URDF name that is not an identifier becomes one (every other character
/// `_`, a keyword with a `_` after it); a link may share a joint's name,
/// and `position_x(elbow)` is the link's origin while `elbow` alone is the
/// joint's angle.
#[test]
fn urdf_names_become_the_models_and_links_keep_their_own() {
    let info = Names::<f64>::INFO;
    assert_eq!(info.coordinates, ["joint_1", "elbow", "type_"]);
    // the URDF's own names are kept beside them, and either finds the
    // coordinate (a ROS `JointState` carries the URDF's)
    assert_eq!(Names::<f64>::JOINT_NAMES, ["joint.1", "elbow", "type"]);
    assert_eq!(inline::Names::<f64>::JOINT_NAMES, Names::<f64>::JOINT_NAMES);
    for (name, index) in [
        ("joint.1", 0),
        ("joint_1", 0),
        ("elbow", 1),
        ("type", 2),
        ("type_", 2),
    ] {
        assert_eq!(Names::<f64>::coordinate_index(name), Some(index), "{name}");
    }
    assert_eq!(Names::<f64>::coordinate_index("joint.2"), None);
    assert_eq!(info.velocities, ["djoint_1", "delbow", "dtype_"]);
    assert_eq!(
        info.constraints,
        [
            "wall",
            "elbow_bent",
            "elbow_up",
            "joint_1_lower",
            "joint_1_upper",
            "type__lower",
            "type__upper"
        ]
    );
    let model = Names::<f64>::new();
    let (a, b, s) = (0.3, -0.7, 0.04);
    let q = SVector::<f64, 3>::new(a, b, s);
    let h = model.gaps(&q);
    // The link `elbow` sits 0.2 along the first link, turned by `joint.1`;
    // the tool 0.2 further and `type` along the second, turned by both.
    let elbow_y = 0.2 * a.sin();
    let tool_x = 0.2 * a.cos() + (0.2 + s) * (a + b).cos();
    let expected = [0.5 - tool_x, b + 1.0, elbow_y, a + 2.0, 2.0 - a, s, 0.1 - s];
    for (i, (got, want)) in h.iter().zip(expected).enumerate() {
        assert!(
            (got - want).abs() < 1e-14,
            "h[{i}] = {got}, expected {want}"
        );
    }
    let inline = inline::Names::<f64>::new();
    assert_eq!(inline::Names::<f64>::INFO.constraints, info.constraints);
    assert_eq!(inline.gaps(&q), h, "the same model, written inline");
}

/// `locked` takes a joint by its URDF name (`"joint.1"` in YAML) or by its
/// coordinate's (`joint_1` inline): the same model either way.
#[test]
fn a_joint_is_locked_by_either_name() {
    assert_eq!(
        LockedByUrdfName::<f64>::INFO.coordinates,
        ["elbow", "type_"]
    );
    assert_eq!(inline::Locked::<f64>::INFO.coordinates, ["elbow", "type_"]);
    let q = SVector::<f64, 2>::new(0.4, 0.05);
    let (yaml, inline) = (LockedByUrdfName::<f64>::new(), inline::Locked::<f64>::new());
    assert_eq!(yaml.gaps(&q), inline.gaps(&q));
    assert_eq!(yaml.mass(&q), inline.mass(&q));
    // held at zero: the tool's x is 0.2 + (0.2 + s) cos(elbow)
    assert!((yaml.gaps(&q)[0] - (0.5 - 0.2 - 0.25 * 0.4_f64.cos())).abs() < 1e-14);
}

/// A model written without a URDF names each coordinate once:
/// `JOINT_NAMES` are its `ModelInfo::coordinates`, and
/// `coordinate_index` finds them.
#[test]
fn a_model_without_a_urdf_keeps_its_coordinates_names() {
    use moreau_models::Parabola;
    assert_eq!(
        Parabola::<f64>::JOINT_NAMES,
        Parabola::<f64>::INFO.coordinates
    );
    assert_eq!(Parabola::<f64>::JOINT_NAMES, ["x", "y"]);
    assert_eq!(Parabola::<f64>::coordinate_index("y"), Some(1));
    assert_eq!(Parabola::<f64>::coordinate_index("z"), None);
}
