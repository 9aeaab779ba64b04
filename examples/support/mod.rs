//! Shared by the examples: figures and CSV files.
#![allow(dead_code)] // each example uses a part

pub mod plot;
