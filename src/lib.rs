//! moreau: compile a declarative mechanical model into fixed-size Rust and run
//! Moreau–Jean simulators and velocity observers on it.
pub use moreau_runtime::*;
