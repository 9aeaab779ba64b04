//! The run-time half of moreau: the [`Model`] contract that the `model!` macro
//! implements, and (in later modules) the LCP solver, the Moreau–Jean plant
//! stepper and the paper's velocity observers.
//!
//! Everything here is fixed-size (`nalgebra` `SVector`/`SMatrix` over const
//! generics), lives on the stack, never allocates and never panics on data.
//! The crate is `no_std`; the default `std` feature only adds
//! `std::error::Error` impls.
#![cfg_attr(not(feature = "std"), no_std)]
#![warn(missing_docs)]

mod lcp;
mod linalg;
mod model;
mod observer;
mod stepper;

pub use lcp::{IndexSet, IndexSetIter, Lcp, LcpError, LcpSolution, lcp_residual, solve_lcp};
pub use model::{Linearization, Model, ModelInfo, Sensitivities, Terms};
pub use observer::{
    Blocks, KalmanParams, KalmanReport, Saltation, SaltationKalman, Tuning,
    constrained_flow_jacobian, flow_jacobian, saltation, transition, tune_process_noise,
};
pub use observer::{
    Design, Discretization, Estimate, FullOrder, FullOrderGains, GainRegion, ModelBounds, Observer,
    ObserverError, ObserverParams, ReducedOrder, UpdateReport,
};
pub use stepper::{
    ApproachVelocity, Impact, MoreauJean, State, StepError, StepParams, StepReport,
    predict_index_set,
};
