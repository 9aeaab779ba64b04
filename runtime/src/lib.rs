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

mod enclosure;
mod error;
mod interval;
mod lcp;
mod linalg;
mod model;
mod observer;
mod state;
mod stepper;
#[cfg(test)]
mod testing;
mod validate;

pub use enclosure::{Enclose, Enclosure};
pub use error::DataError;
pub use interval::{Interval, LIBM_ULPS, next_down, next_up};
pub use lcp::{IndexSet, IndexSetIter, Lcp, LcpError, LcpSolution, lcp_residual, solve_lcp};
pub use model::{Linearization, Model, ModelInfo, Sensitivities, Structure, Terms};
pub use observer::{
    Blocks, KalmanParams, KalmanReport, NoiseFactors, Picked, Saltation, SaltationKalman, Tuning,
    constrained_flow_jacobian, flow_jacobian, pick_by_likelihood, saltation, transition,
    tune_process_noise,
};
#[cfg(feature = "std")]
pub use observer::{Budget, CertifiedBounds, CertifiedConstant, CertifyError};
pub use observer::{
    Design, Discretization, FullOrder, FullOrderGains, GainRegion, ModelBounds, Observer,
    ObserverError, ObserverParams, ReducedOrder, Restart, UpdateReport,
};
pub use state::{Estimate, State};
pub use stepper::{
    ApproachVelocity, Impact, MoreauJean, StepError, StepParams, StepReport, predict_index_set,
};
