//! URDF models against Pinocchio: `tests/robots/ur5.yaml` (and the same
//! model written inline),
//! `tests/robots/panda.yaml` (URDFs from example-robot-data, shipped in
//! `tests/robots/urdf/`), `tests/robots/slider_arm.yaml` and
//! `tests/robots/serial_12.yaml` (URDFs written for the tests) and
//! `tests/robots/go1.yaml` (Unitree Go1's legs, example-robot-data),
//! `tests/robots/so100.yaml` (a link and a joint of the same name),
//! `tests/robots/allegro.yaml` (names that are not identifiers) and
//! `tests/robots/panda_fingers.yaml` (a joint that mimics another) compiled
//! by `model!`, compared with the values that
//! `tests/pinocchio_reference.py` wrote with Pinocchio at 8 seeded
//! configurations each (`tests/fixtures/pinocchio/*.json`): the mass
//! matrix (Pinocchio's CRBA), `F = C v + G` (its nonlinear effects), `G`,
//! and the world positions and Jacobians of two points of two links (through
//! the constraints `h` and `J`), and that `C` is the Christoffel one
//! (`C(v) w = C(w) v`, with `C(v) v` Pinocchio's), every entry to 1e-10
//! relative (to the largest entry of the same quantity at the same
//! configuration); Pinocchio's joints are taken in the model's order (they
//! differ where a link has several children, Go1's trunk). For three of the
//! robots, the derivatives built from the
//! recursions (`∂F/∂q`, `∂F/∂v`, `∂(M v)/∂q`, `∂(J v)/∂q`) against central
//! differences, and `Ṁ − 2C` skew-symmetric.

use crate::common::central;

use moreau::{Model, Sensitivities};
use nalgebra::{SMatrix, SVector};
use serde_json::Value;

use crate::{Allegro, Go1, Panda, PandaFingers, Serial12, SliderArm, So100, Ur5};

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
    let path = crate::common::root().join(format!("tests/fixtures/pinocchio/{robot}.json"));
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

/// Where each of the model's coordinates `joints` (the URDF's moving joints,
/// depth first, a link's children in the order of the file) is in the
/// fixture's, Pinocchio's, order (depth first too, but a link's children in
/// the order of their joints' names: urdfdom keeps the joints in a sorted
/// map). The two orders are the same joints.
fn pinocchio_order<const N: usize>(data: &Value, joints: [&str; N]) -> [usize; N] {
    let mut names: Vec<&str> = data["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap())
        .collect();
    let order = joints.map(|j| {
        names
            .iter()
            .position(|n| *n == j)
            .unwrap_or_else(|| panic!("`{j}` is not one of Pinocchio's joints {names:?}"))
    });
    let mut ours = joints.to_vec();
    ours.sort_unstable();
    names.sort_unstable();
    assert_eq!(ours, names, "the same joints as Pinocchio's");
    order
}

/// The entries `(rows[i], cols[j])` of a row-major matrix with `n`
/// columns, row-major.
fn pick(m: &[f64], n: usize, rows: &[usize], cols: &[usize]) -> Vec<f64> {
    rows.iter()
        .flat_map(|r| cols.iter().map(move |c| m[r * n + c]))
        .collect()
}

/// A fixture's sample `q`, `v` in the model's order.
fn state<const N: usize>(s: &Value, order: &[usize; N]) -> (SVector<f64, N>, SVector<f64, N>) {
    let (q, v) = (numbers(&s["q"]), numbers(&s["v"]));
    (
        SVector::from_fn(|i, _| q[order[i]]),
        SVector::from_fn(|i, _| v[order[i]]),
    )
}

/// The points of the fixtures are read through the constraints: the first
/// three give `1 − x`, `1 − y`, `z + floor` of the first point, the next
/// three those of the second (any constraints after them are not read).
/// `joints` are the model's coordinates, in its order; Pinocchio's values
/// are taken in that order.
fn compare<
    M: Model<N, K, Scalar = f64, Input = SVector<f64, 0>>,
    const N: usize,
    const K: usize,
>(
    model: &M,
    robot: &str,
    joints: [&str; N],
    floor: f64,
) {
    compare_named(model, robot, joints, joints, floor);
}

/// [`compare`] where the model's coordinates (`coordinates`) are not the
/// URDF's joint names (`joints`, Pinocchio's): names that are not
/// identifiers.
fn compare_named<
    M: Model<N, K, Scalar = f64, Input = SVector<f64, 0>>,
    const N: usize,
    const K: usize,
>(
    model: &M,
    robot: &str,
    coordinates: [&str; N],
    joints: [&str; N],
    floor: f64,
) {
    let data = fixture(robot);
    assert_eq!(
        M::INFO.coordinates,
        coordinates,
        "the coordinates are the URDF's moving joints"
    );
    let order = pinocchio_order(&data, joints);
    let samples = data["samples"].as_array().expect("samples");
    assert_eq!(samples.len(), 8);
    let mut worst = 0.0_f64;
    for (k, s) in samples.iter().enumerate() {
        let (q, v) = state(s, &order);
        let u = SVector::<f64, 0>::zeros();
        let at = |what: &str| format!("{robot} sample {k}: {what}");
        let mass = pick(&numbers(&s["M"]), N, &order, &order);
        worst = worst.max(agree(&rows(&model.mass(&q)), &mass, &at("M")));
        let nle = pick(&numbers(&s["nle"]), N, &[0], &order);
        let gravity = pick(&numbers(&s["G"]), N, &[0], &order);
        let f = model.forces(0.0, &q, &v, &u);
        worst = worst.max(agree(f.as_slice(), &nle, &at("C v + G")));
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
        let cv_ref: Vec<f64> = nle.iter().zip(&gravity).map(|(n, g)| n - g).collect();
        worst = worst.max(agree(cv.as_slice(), &cv_ref, &at("C v")));
        worst = worst.max(agree(model.gravity(&q).as_slice(), &gravity, &at("G")));
        let h = model.gaps(&q);
        let j = model.gap_jacobian(&q);
        for (p, point) in s["points"].as_array().unwrap().iter().enumerate() {
            let r = 3 * p;
            let position = [1.0 - h[r], 1.0 - h[r + 1], h[r + 2] - floor];
            worst = worst.max(agree(
                &position,
                &numbers(&point["position"]),
                &at("point position"),
            ));
            let mut jac = Vec::with_capacity(3 * N);
            for (row, sign) in [(r, -1.0), (r + 1, -1.0), (r + 2, 1.0)] {
                jac.extend((0..N).map(|c| sign * j[(row, c)]));
            }
            let reference = pick(&numbers(&point["jacobian"]), N, &[0, 1, 2], &order);
            worst = worst.max(agree(&jac, &reference, &at("point Jacobian")));
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
    compare(&Ur5::<f64>::new(), "ur5", UR5_JOINTS, 0.5);
}

/// The same URDF through the inline front end.
#[test]
fn inline_ur5_matches_pinocchio() {
    compare(&inline::Ur5::<f64>::new(), "ur5", UR5_JOINTS, 0.5);
}

/// The Panda's seven arm joints.
const PANDA_ARM: [&str; 7] = [
    "panda_joint1",
    "panda_joint2",
    "panda_joint3",
    "panda_joint4",
    "panda_joint5",
    "panda_joint6",
    "panda_joint7",
];

#[test]
fn panda_matches_pinocchio() {
    compare(&Panda::<f64>::new(), "panda", PANDA_ARM, 0.5);
}

/// The Panda with its fingers as the URDF has them: the second finger's
/// joint mimics the first's, so the eighth coordinate opens both
/// (`tests/robots/panda_fingers.yaml`), beside Pinocchio's model read with
/// `mimic=True`; a point on each finger, the right one on the mimicking
/// joint.
#[test]
fn panda_with_mimicking_fingers_matches_pinocchio() {
    compare(
        &PandaFingers::<f64>::new(),
        "panda_mimic",
        std::array::from_fn(|i| PANDA_ARM.get(i).copied().unwrap_or("panda_finger_joint1")),
        0.5,
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
        0.5,
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
        0.5,
    );
}

/// The coordinates of `tests/robots/go1.yaml`: the legs in the URDF's order
/// (FR, FL, RR, RL), which Pinocchio's (FL, FR, RL, RR) permutes.
const GO1_JOINTS: [&str; 12] = [
    "FR_hip_joint",
    "FR_thigh_joint",
    "FR_calf_joint",
    "FL_hip_joint",
    "FL_thigh_joint",
    "FL_calf_joint",
    "RR_hip_joint",
    "RR_thigh_joint",
    "RR_calf_joint",
    "RL_hip_joint",
    "RL_thigh_joint",
    "RL_calf_joint",
];

/// Unitree Go1's 12 leg joints with the trunk fixed (example-robot-data's
/// URDF: fixed rotor, IMU and foot links, branches at the trunk); the feet's
/// centres above a ground 0.4 m down, less their radius 0.02.
#[test]
fn go1_matches_pinocchio() {
    compare(&Go1::<f64>::new(), "go1", GO1_JOINTS, 0.4 - 0.02);
}

/// The SO-100 arm: its jaw's joint and the link it moves are both called
/// `gripper`, and `position_x(gripper, ...)` (`tests/robots/so100.yaml`)
/// is the link's point, as Pinocchio's frame of the link `gripper` is.
#[test]
fn so100_matches_pinocchio() {
    compare(
        &So100::<f64>::new(),
        "so100",
        [
            "shoulder_pan",
            "shoulder_lift",
            "elbow_flex",
            "wrist_flex",
            "wrist_roll",
            "gripper",
        ],
        0.5,
    );
}

/// The Allegro hand: its joints `joint_0.0`, ... are the coordinates
/// `joint_0_0`, ..., its links `link_3.0_tip`, ... the bodies
/// `link_3_0_tip`, ... (`tests/robots/allegro.yaml`); the fingers in the
/// file's order (8–11, 4–7, 0–3, 12–15), which Pinocchio sorts by name.
/// The generated `JOINT_NAMES` keep the URDF's names, and Pinocchio's
/// model is matched by them.
#[test]
fn allegro_matches_pinocchio() {
    let fingers = [8, 4, 0, 12];
    let ours: Vec<String> = fingers
        .iter()
        .flat_map(|f| (*f..f + 4).map(|j| format!("joint_{j}_0")))
        .collect();
    compare_named(
        &Allegro::<f64>::new(),
        "allegro",
        std::array::from_fn::<_, 16, _>(|i| ours[i].as_str()),
        Allegro::<f64>::JOINT_NAMES,
        0.5,
    );
    assert_eq!(Allegro::<f64>::JOINT_NAMES[0], "joint_8.0");
    assert_eq!(Allegro::<f64>::coordinate_index("joint_15.0"), Some(15));
    assert_eq!(Allegro::<f64>::INFO.velocities[0], "djoint_8_0");
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
    let order = pinocchio_order(&data, M::INFO.coordinates);
    let u = SVector::<f64, 0>::zeros();
    for (k, s) in data["samples"].as_array().unwrap().iter().enumerate() {
        let (q, v) = state(s, &order);
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

#[test]
fn go1_derivatives_match_finite_differences() {
    derivatives_match_finite_differences(&Go1::<f64>::new(), "go1");
}
