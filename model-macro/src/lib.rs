//! The `model!` procedural macro of moreau.
//!
//! It reads a Lagrangian model with unilateral constraints, either from a YAML
//! file (`model!(file = "models/parabola.yaml")`) or written inline
//! (`model! { pub struct Parabola; ... }`), and emits a fixed-size,
//! allocation-free implementation of `moreau::Model`. The stages are kept
//! apart, as in `serde_derive` and `thiserror-impl`:
//!
//! 1. **front ends** (`front::yaml`, `front::inline`) build one `ModelSpec`
//!    (`spec.rs`), in which every name and expression remembers where it
//!    came from;
//! 2. **checks** (`check`) validate the spec, reporting every problem at once;
//! 3. **lowering** (`lower`) builds the symbolic graph and derives the
//!    mechanics with `moreau-sym`;
//! 4. **emission** (`emit`) writes straight-line Rust from one instruction
//!    list shared by all outputs.
//!
//! Use it through the `moreau` crate, which re-exports it; the model language
//! is described in `models/README.md`.

mod check;
mod ctxt;
mod emit;
mod expand;
mod expr;
mod front;
mod keys;
mod loc;
mod lower;
mod render;
mod resolve;
mod spec;
mod tree;

use proc_macro::TokenStream;

/// Compiles a mechanical model into a type implementing `moreau::Model`.
///
/// See the `moreau` crate for the documentation and examples.
#[proc_macro]
pub fn model(input: TokenStream) -> TokenStream {
    expand::model(input.into()).into()
}
#[cfg(test)]
mod tests;
