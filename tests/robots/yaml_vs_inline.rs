//! Written in YAML or inline around the same URDF, a robot compiles to the
//! same code: the UR5 on a table, the Panda with locked fingers and the
//! slider arm with joint limits, each written inline here, against the YAML
//! files the other tests of this binary compile.

use crate::common::same_info;
use moreau::{Model, Sensitivities};
use nalgebra::SVector;

/// The UR5 of `examples/ur5_table.yaml` written inline: the URDF, with
/// parameters, joint damping, a contact, a restitution and initial values
/// beside it.
mod ur5_table {
    moreau::model! {
        pub struct Ur5Table;
        urdf = "tests/robots/urdf/ur_description/ur5_robot.urdf";
        parameters { b: 0.5, table: 0.2 }
        applied {
            shoulder_pan_joint: -b * dshoulder_pan_joint,
            shoulder_lift_joint: -b * dshoulder_lift_joint,
            elbow_joint: -b * delbow_joint,
            wrist_1_joint: -b * dwrist_1_joint,
            wrist_2_joint: -b * dwrist_2_joint,
            wrist_3_joint: -b * dwrist_3_joint,
        }
        constraints { tool_on_table: position_z(tool0, 0, 0, 0.05) - table >= 0 }
        restitution = 0.3;
        initial { shoulder_lift_joint: -1.0, elbow_joint: 1.0, wrist_1_joint: -1.57, wrist_2_joint: -1.57 }
    }
}

/// `tests/robots/panda.yaml` written inline: two joints `locked`.
mod panda {
    moreau::model! {
        pub struct Panda;
        urdf = "tests/robots/urdf/panda_description/panda.urdf";
        locked { panda_finger_joint1, panda_finger_joint2 }
        constraints {
            hand_x: position_x(panda_hand, 0, 0, 0.1) <= 1.0,
            hand_y: position_y(panda_hand, 0, 0, 0.1) <= 1.0,
            table: position_z(panda_hand, 0, 0, 0.1) + 0.5 >= 0,
            elbow_x: 1.0 - position_x(panda_link4, 0.03, 0, -0.02) >= 0,
            elbow_y: 1.0 - position_y(panda_link4, 0.03, 0, -0.02) >= 0,
            elbow_z: position_z(panda_link4, 0.03, 0, -0.02) + 0.5 >= 0,
        }
        restitution = 0.2;
    }
}

/// `tests/robots/slider_arm_limits.yaml` written inline: the `limits` of
/// two joints as constraints, written before the URDF they name.
mod slider_arm_limits {
    moreau::model! {
        pub struct SliderArmLimits;
        limits { slide, shoulder }
        urdf = "tests/robots/urdf/synthetic/slider_arm.urdf";
        constraints { table: position_z(tool) + 0.5 >= 0 }
        restitution = 0.1;
    }
}

/// Written in YAML or inline around the same URDF, a robot compiles to the
/// same code: at 50 configurations and velocities, every output of `eval`,
/// `linearization`, `mass_dq` and `jacobian_dq` agrees to the last bit, as
/// do the restitutions, the structure flags and the names and operation
/// count of `INFO`.
fn urdf_models_agree<Y, I, const N: usize, const K: usize>(yaml: &Y, inline: &I)
where
    Y: Sensitivities<N, K> + Model<N, K, Scalar = f64, Input = SVector<f64, 0>>,
    I: Sensitivities<N, K> + Model<N, K, Scalar = f64, Input = SVector<f64, 0>>,
{
    let u = SVector::<f64, 0>::zeros();
    for k in 1..=50 {
        // a Weyl sequence in [-1.5, 1.5]^N × [-2, 2]^N
        let f = |i: usize, scale: f64| {
            let a = (2.0_f64 + i as f64).sqrt().fract();
            scale * (((k as f64) * a).fract() * 2.0 - 1.0)
        };
        let q = SVector::<f64, N>::from_fn(|i, _| f(i, 1.5));
        let v = SVector::<f64, N>::from_fn(|i, _| f(i + N, 2.0));
        let t = 0.1 * k as f64;
        assert_eq!(yaml.eval(t, &q, &v, &u), inline.eval(t, &q, &v, &u));
        assert_eq!(
            yaml.linearization(t, &q, &v, &u),
            inline.linearization(t, &q, &v, &u)
        );
        assert_eq!(yaml.mass_dq(&q, &v), inline.mass_dq(&q, &v));
        assert_eq!(yaml.jacobian_dq(&q, &v), inline.jacobian_dq(&q, &v));
    }
    assert_eq!(yaml.restitution(), inline.restitution());
    assert_eq!(Y::STRUCTURE, I::STRUCTURE);
    same_info(&Y::INFO, &I::INFO);
}

#[test]
fn inline_ur5_table_is_the_yaml_one() {
    urdf_models_agree(
        &crate::Ur5Table::<f64>::new(),
        &ur5_table::Ur5Table::<f64>::new(),
    );
    assert_eq!(
        crate::Ur5Table::<f64>::initial_state(),
        ur5_table::Ur5Table::<f64>::initial_state()
    );
    // the coordinates are the URDF's joints, the damping reads the
    // generated velocities
    assert_eq!(
        ur5_table::Ur5Table::<f64>::INFO.coordinates[..2],
        ["shoulder_pan_joint", "shoulder_lift_joint"]
    );
}

#[test]
fn inline_panda_with_locked_fingers_is_the_yaml_one() {
    urdf_models_agree(&crate::Panda::<f64>::new(), &panda::Panda::<f64>::new());
    assert!(
        !panda::Panda::<f64>::INFO
            .coordinates
            .iter()
            .any(|c| c.contains("finger"))
    );
}

#[test]
fn inline_limits_are_the_yaml_ones() {
    urdf_models_agree(
        &crate::SliderArmLimits::<f64>::new(),
        &slider_arm_limits::SliderArmLimits::<f64>::new(),
    );
    assert_eq!(
        slider_arm_limits::SliderArmLimits::<f64>::INFO.constraints,
        [
            "table",
            "slide_lower",
            "slide_upper",
            "shoulder_lower",
            "shoulder_upper"
        ]
    );
}
