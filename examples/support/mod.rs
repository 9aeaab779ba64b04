//! Shared by the examples: sampled plant trajectories, observer runs,
//! figures and CSV files.
#![allow(dead_code)] // each example uses a part

pub mod compare;
pub mod observe;
pub mod plot;
pub mod reference;
