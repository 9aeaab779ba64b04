//! The compile errors of [`moreau::model!`] for malformed models.
//!
//! This crate holds no code: it is the home of `tests/compile_fail.rs`,
//! which compiles every case under `tests/ui/<class>/` with trybuild and
//! compares the errors with the `.stderr` file beside it (the token's span
//! for an inline model, `file:line:column` for YAML; several mistakes in
//! one model are reported together). It is a crate of its own so that
//! trybuild's project, which takes every dependency of the crate that
//! calls it, depends on `moreau` alone.
//!
//! ```text
//! cargo test --release -p moreau-macro-errors
//! TRYBUILD=overwrite cargo test --release -p moreau-macro-errors   # refresh the .stderr files, then read the diff
//! ```
#![no_std]
