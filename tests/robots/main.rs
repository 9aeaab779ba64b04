//! The robots of this folder (URDFs with the YAML around them) in one test
//! binary: against CasADi (`casadi`), against Pinocchio (`pinocchio`),
//! written inline against written in YAML (`yaml_vs_inline`), and the
//! saltation Kalman filter following them under noise (`kalman`).
//!
//! One binary, because a robot's generated code is long (the Panda's
//! `eval` is about 10 000 operations) and compiling it is most of the test
//! build: in four binaries the same robot was compiled up to four times.
//! Each robot is compiled once, here, and the modules share it.
//!
//! `cargo test --release --test robots -- --nocapture kalman::` runs one
//! module, and prints what its tests measure.

#[path = "../common/mod.rs"]
mod common;

mod casadi;
mod kalman;
mod pinocchio;
mod yaml_vs_inline;

moreau::model!(file = "tests/robots/two_link.yaml");
moreau::model!(file = "tests/robots/two_link_energies.yaml");
moreau::model!(file = "tests/robots/slider_arm.yaml");
moreau::model!(file = "tests/robots/slider_arm_limits.yaml");
moreau::model!(file = "tests/robots/slider_arm_mixed.yaml");
moreau::model!(file = "tests/robots/ur5.yaml");
moreau::model!(file = "examples/ur5_table.yaml");
moreau::model!(file = "tests/robots/panda.yaml");
moreau::model!(file = "tests/robots/serial_12.yaml");
moreau::model!(file = "tests/robots/go1.yaml");
moreau::model!(file = "tests/robots/so100.yaml");
moreau::model!(file = "tests/robots/allegro.yaml");
moreau::model!(file = "tests/robots/panda_fingers.yaml");
moreau::model!(file = "tests/robots/panda_fingers_free.yaml");
