//! URDF models against Pinocchio: `tests/robots/ur5.yaml` (and the same
//! model written inline),
//! `tests/robots/panda.yaml` (URDFs from example-robot-data, shipped in
//! `tests/robots/urdf/`), `tests/robots/slider_arm.yaml` and
//! `tests/robots/serial_12.yaml` (URDFs written for the tests) compiled by `model!`, compared with the values that
//! `tests/pinocchio_reference.py` wrote with Pinocchio at 8 seeded
//! configurations each (`tests/fixtures/pinocchio/*.json`): the mass
//! matrix (Pinocchio's CRBA), `F = C v + G` (its nonlinear effects), `G`,
//! and the world positions and Jacobians of two points of two links (through
//! the constraints `h` and `J`), and that `C` is the Christoffel one
//! (`C(v) w = C(w) v`, with `C(v) v` Pinocchio's), every entry to 1e-10
//! relative (to the largest entry of the same quantity at the same
//! configuration). For two of the robots, the derivatives built from the
//! recursions (`∂F/∂q`, `∂F/∂v`, `∂(M v)/∂q`, `∂(J v)/∂q`) against central
//! differences, and `Ṁ − 2C` skew-symmetric.

mod common;

use common::central;

use moreau::{Model, Sensitivities};
use nalgebra::{SMatrix, SVector};
use serde_json::Value;

moreau::model!(file = "tests/robots/ur5.yaml");
moreau::model!(file = "tests/robots/panda.yaml");
moreau::model!(file = "tests/robots/slider_arm.yaml");
moreau::model!(file = "tests/robots/serial_12.yaml");

/// `tests/robots/ur5.yaml` written inline, the URDF named by `urdf = "...";`.
mod inline {
    moreau::model! {
        pub struct Ur5;
        urdf = "tests/robots/urdf/ur_description/ur5_robot.urdf";
        constraints {
            tool_x: position_x(tool0, 0.01, -0.02, 0.05) <= 1.0,
            tool_y: position_y(tool0, 0.01, -0.02, 0.05) <= 1.0,
            table: position_z(tool0, 0.01, -0.02, 0.05) + 0.5 >= 0,
            forearm_x: position_x(forearm_link) <= 1.0,
            forearm_y: position_y(forearm_link) <= 1.0,
            forearm_z: position_z(forearm_link) + 0.5 >= 0,
        }
        restitution = 0.2;
    }
}

const RTOL: f64 = 1e-10;

fn fixture(robot: &str) -> Value {
    let path = common::root().join(format!("tests/fixtures/pinocchio/{robot}.json"));
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    serde_json::from_str(&text).expect("fixture is JSON")
}

fn numbers(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(items) => items.iter().flat_map(numbers).collect(),
        x => vec![x.as_f64().expect("a number")],
    }
}

/// Every entry of `ours` within `RTOL` of Pinocchio's, relative to the
/// largest entry of the quantity.
fn agree(ours: &[f64], theirs: &[f64], what: &str) -> f64 {
    assert_eq!(ours.len(), theirs.len(), "{what}: sizes");
    let scale = theirs.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let mut worst = 0.0_f64;
    for (i, (a, b)) in ours.iter().zip(theirs).enumerate() {
        let err = (a - b).abs() / scale;
        assert!(
            err <= RTOL,
            "{what}[{i}]: generated {a} vs Pinocchio {b} (relative {err:e})"
        );
        worst = worst.max(err);
    }
    worst
}

/// Row-major entries of a matrix.
fn rows<const R: usize, const C: usize>(m: &nalgebra::SMatrix<f64, R, C>) -> Vec<f64> {
    m.transpose().as_slice().to_vec()
}

/// The points of the fixtures are read through the constraints: the first
/// three give `1 − x`, `1 − y`, `z + 0.5` of the first point, the next three
/// those of the second.
fn compare<M: Model<N, 6, Scalar = f64, Input = SVector<f64, 0>>, const N: usize>(
    model: &M,
    robot: &str,
    joints: [&str; N],
) {
    let data = fixture(robot);
    let names: Vec<&str> = data["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap())
        .collect();
    assert_eq!(
        names, joints,
        "the coordinates are Pinocchio's joints, in its order"
    );
    let samples = data["samples"].as_array().expect("samples");
    assert_eq!(samples.len(), 8);
    let mut worst = 0.0_f64;
    for (k, s) in samples.iter().enumerate() {
        let q = SVector::<f64, N>::from_iterator(numbers(&s["q"]));
        let v = SVector::<f64, N>::from_iterator(numbers(&s["v"]));
        let u = SVector::<f64, 0>::zeros();
        let at = |what: &str| format!("{robot} sample {k}: {what}");
        worst = worst.max(agree(&rows(&model.mass(&q)), &numbers(&s["M"]), &at("M")));
        let f = model.forces(0.0, &q, &v, &u);
        worst = worst.max(agree(f.as_slice(), &numbers(&s["nle"]), &at("C v + G")));
        let cv = model.coriolis(&q, &v) * v;
        // The Christoffel C is the one with C(v) w = C(w) v (Γ_ijk
        // symmetric in j, k) and C(v) v the velocity terms.
        let w = SVector::<f64, N>::from_fn(|i, _| (0.7 * i as f64 + 0.3).sin());
        let cvw = model.coriolis(&q, &v) * w;
        let cwv = model.coriolis(&q, &w) * v;
        worst = worst.max(agree(
            cvw.as_slice(),
            cwv.as_slice(),
            &at("C(v) w = C(w) v"),
        ));
        let cv_ref: Vec<f64> = numbers(&s["nle"])
            .iter()
            .zip(numbers(&s["G"]))
            .map(|(n, g)| n - g)
            .collect();
        worst = worst.max(agree(cv.as_slice(), &cv_ref, &at("C v")));
        worst = worst.max(agree(
            model.gravity(&q).as_slice(),
            &numbers(&s["G"]),
            &at("G"),
        ));
        let h = model.gaps(&q);
        let j = model.gap_jacobian(&q);
        for (p, point) in s["points"].as_array().unwrap().iter().enumerate() {
            let r = 3 * p;
            let position = [1.0 - h[r], 1.0 - h[r + 1], h[r + 2] - 0.5];
            worst = worst.max(agree(
                &position,
                &numbers(&point["position"]),
                &at("point position"),
            ));
            let mut jac = Vec::with_capacity(3 * N);
            for (row, sign) in [(r, -1.0), (r + 1, -1.0), (r + 2, 1.0)] {
                jac.extend((0..N).map(|c| sign * j[(row, c)]));
            }
            worst = worst.max(agree(
                &jac,
                &numbers(&point["jacobian"]),
                &at("point Jacobian"),
            ));
        }
    }
    println!(
        "{robot}: largest relative difference to Pinocchio {worst:.1e} ({} operations in the fused evaluation)",
        M::INFO.op_count
    );
}

const UR5_JOINTS: [&str; 6] = [
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
];

#[test]
fn ur5_matches_pinocchio() {
    compare(&Ur5::<f64>::new(), "ur5", UR5_JOINTS);
}

/// The same URDF through the inline front end.
#[test]
fn inline_ur5_matches_pinocchio() {
    compare(&inline::Ur5::<f64>::new(), "ur5", UR5_JOINTS);
}

#[test]
fn panda_matches_pinocchio() {
    compare(
        &Panda::<f64>::new(),
        "panda",
        [
            "panda_joint1",
            "panda_joint2",
            "panda_joint3",
            "panda_joint4",
            "panda_joint5",
            "panda_joint6",
            "panda_joint7",
        ],
    );
}

/// A URDF written for the tests: prismatic joints (one on a skewed axis),
/// a continuous joint, joint frames and inertias turned by roll-pitch-yaw,
/// a branch.
#[test]
fn slider_arm_matches_pinocchio() {
    compare(
        &SliderArm::<f64>::new(),
        "slider_arm",
        ["slide", "shoulder", "elbow", "side_slide"],
    );
}

/// A generated chain of 12 revolute joints on six different axes
/// (`tests/robots/urdf/synthetic/serial/gen.py`).
#[test]
fn serial_12_matches_pinocchio() {
    compare(
        &Serial12::<f64>::new(),
        "serial_12",
        [
            "j1", "j2", "j3", "j4", "j5", "j6", "j7", "j8", "j9", "j10", "j11", "j12",
        ],
    );
}

#[test]
fn coordinates_are_the_urdf_joints_with_generated_velocities() {
    let info = Ur5::<f64>::INFO;
    assert_eq!(info.coordinates[0], "shoulder_pan_joint");
    assert_eq!(info.velocities[0], "dshoulder_pan_joint");
    assert_eq!(Panda::<f64>::INFO.constraints[2], "table");
}

/// The derivatives the graph builds from the recursions (`∂F/∂q`, `∂F/∂v`,
/// `∂(M v)/∂q`, `∂(J v)/∂q`) against central differences of the generated
/// `F`, `M v` and `J v`, and `Ṁ − 2C` skew-symmetric (`Ṁ` by central
/// differences along `v`), at the fixture's states; 1e-6 relative to the
/// largest entry, well above a central difference's O(1e-10) error.
fn derivatives_match_finite_differences<M, const N: usize>(model: &M, robot: &str)
where
    M: Model<N, 6, Scalar = f64, Input = SVector<f64, 0>> + Sensitivities<N, 6>,
{
    let data = fixture(robot);
    let u = SVector::<f64, 0>::zeros();
    for (k, s) in data["samples"].as_array().unwrap().iter().enumerate() {
        let q = SVector::<f64, N>::from_iterator(numbers(&s["q"]));
        let v = SVector::<f64, N>::from_iterator(numbers(&s["v"]));
        let lin = model.linearization(0.0, &q, &v, &u);
        let mass_dq = model.mass_dq(&q, &v);
        let jacobian_dq = model.jacobian_dq(&q, &v);
        let mut fd = [
            SMatrix::<f64, N, N>::zeros(),
            SMatrix::zeros(),
            SMatrix::zeros(),
        ];
        let mut fd_jv = SMatrix::<f64, 6, N>::zeros();
        for j in 0..N {
            fd[0].set_column(j, &central(|x| model.forces(0.0, x, &v, &u), &q, j));
            fd[1].set_column(j, &central(|x| model.forces(0.0, &q, x, &u), &v, j));
            fd[2].set_column(j, &central(|x| model.mass(x) * v, &q, j));
            fd_jv.set_column(j, &central(|x| model.gap_jacobian(x) * v, &q, j));
        }
        let step = 1e-6;
        let mdot = (model.mass(&(q + step * v)) - model.mass(&(q - step * v))) / (2.0 * step);
        let c = model.coriolis(&q, &v);
        let skew = mdot - 2.0 * c;
        let minus_transpose = -skew.transpose();
        let pairs: [(&str, &[f64], &[f64]); 5] = [
            ("∂F/∂q", lin.forces_dq.as_slice(), fd[0].as_slice()),
            ("∂F/∂v", lin.forces_dv.as_slice(), fd[1].as_slice()),
            ("∂(M v)/∂q", mass_dq.as_slice(), fd[2].as_slice()),
            ("∂(J v)/∂q", jacobian_dq.as_slice(), fd_jv.as_slice()),
            ("Ṁ − 2C", skew.as_slice(), minus_transpose.as_slice()),
        ];
        for (what, ours, reference) in pairs {
            let scale = reference
                .iter()
                .chain(ours)
                .fold(1e-300_f64, |m, x| m.max(x.abs()));
            for (a, b) in ours.iter().zip(reference) {
                assert!(
                    (a - b).abs() <= 1e-6 * scale,
                    "{robot} sample {k}: {what}: {a} vs {b}"
                );
            }
        }
    }
}

#[test]
fn slider_arm_derivatives_match_finite_differences() {
    derivatives_match_finite_differences(&SliderArm::<f64>::new(), "slider_arm");
}

#[test]
fn serial_12_derivatives_match_finite_differences() {
    derivatives_match_finite_differences(&Serial12::<f64>::new(), "serial_12");
}
