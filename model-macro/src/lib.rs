//! The `model!` procedural macro of moreau.
//!
//! It reads a Lagrangian model with unilateral constraints, either from a YAML
//! file (`model!(file = "models/parabola.yaml")`) or written inline
//! (`model! { pub struct Parabola; ... }`), either perhaps naming a URDF,
//! and emits a fixed-size,
//! allocation-free implementation of `moreau::Model` (plus
//! `Sensitivities` and `Enclosure`). The stages are kept apart, as in
//! `serde_derive` and `thiserror-impl`, each reading only the data type the
//! stage before it produced:
//!
//! | stage | module | reads | produces |
//! |---|---|---|---|
//! | front ends | `front::yaml`, `front::inline` (a URDF, for both, through `front::urdf_keys` and `front::urdf`) | YAML text, or tokens | `ModelSpec` (`spec.rs`): the model as written, every name and expression with its location |
//! | checks | `check` | `ModelSpec` and its `Scope` | errors (every one at once), nothing else |
//! | resolution | `resolve` | a checked `ModelSpec` | `Resolved` (`resolve.rs`): expressions over typed `Symbol`s, `kinetic` required, per-coordinate applied forces |
//! | lowering | `lower` (a kinematic tree's M, C, G, C v + G by recursions: `tree`) | `Resolved` | the symbolic graph and every derived quantity (`moreau_sym::Mechanics`, laid out by `moreau_sym::Layout`) |
//! | emission | `emit` | `Resolved` and the lowered graph | tokens: the type, its `impl`s, its docs (with the listing of `eval`) |
//!
//! `expand` chains them (`expand::compile`), and on error emits the
//! struct and stub impls (`emit::fallback`) beside the errors. Supporting
//! modules sit below every stage: `loc` (where things came from), `ctxt`
//! (the error collector; the YAML front end hands it its locator as a
//! value), `scope` (the one name table), `keys` (the language's vocabulary), `expr` (the grammar and the
//! one parser), `render` (an inline model's text in the YAML language).
//!
//! Follow a user name, say the coordinate `th1` of `models/double_pendulum.yaml`:
//! the YAML front end reads it into `Coordinate { q: Name { text: "th1",
//! loc }, .. }`; `Scope::new` maps `"th1"` to `Symbol::Var(Var::Coordinate(0))`;
//! resolution rewrites every `Name("th1")` into that symbol; lowering turns
//! it into the graph variable `VarLayout::id(Var::Coordinate(0))` (`VarId(0)`);
//! emission binds it as `Local::Var(Var::Coordinate(0))`, printed as the
//! user's own identifier `th1` (call-site span) in `let th1 = q[0];`; a shared
//! `cos(th1)` would be `Local::Role(Role::Func(Cos), Var::Coordinate(0))`,
//! printed `cos_th1` unless a name of the model already took that text
//! (then `cos_th1_2`: `emit::names`).
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
mod scope;
mod spec;
mod tree;

use proc_macro::TokenStream;

/// Compiles a mechanical model into a type implementing `moreau::Model`.
///
/// The model is a YAML file (`model!(file = "models/parabola.yaml")`) or
/// written inline (`model! { pub struct Name; ... }`); either may name a
/// URDF (`urdf: path` in YAML, `urdf = "path";` inline) beside its
/// constraints. See the `moreau` crate for the documentation and examples.
#[proc_macro]
pub fn model(input: TokenStream) -> TokenStream {
    expand::model(input.into()).into()
}

#[cfg(test)]
mod tests;
