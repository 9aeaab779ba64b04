//! Emission: straight-line Rust from one instruction list.
//!
//! Every output of the model is an entry of one [`Schedule`], built once
//! from `Mechanics::outputs` (in the one output layout of
//! `moreau_sym::Layout`) after common-subexpression elimination. Each
//! generated method evaluates the sub-list its quantities need, so `eval`
//! shares every temporary and `mass` computes nothing else.
//!
//! | file | emits |
//! |---|---|
//! | `names.rs` | what a binding is ([`Local`](names::Local)) and its printed name |
//! | `body.rs` | one method's straight-line body, from the schedule |
//! | `print.rs` | the one printer: tokens for the code, text for the listing |
//! | `items.rs` | the generated type: struct, `Default`, inherent items, trait impls, docs |
//! | `fallback.rs` | the struct and stub impls for a model with errors |
//!
//! The code is written as a careful person would: inputs unpacked once at
//! the top under the model's own names (`let th1 = q[0];`), temporaries
//! used once folded into their one consumer, the others bound to names that
//! say what they hold (`m_0_1` for `M[0,1]`, `sin_th1`, `a7` for anonymous
//! shared ones), constants bound once (`k_0_5`), and the symmetric `M`
//! filled from its upper triangle.

mod body;
mod fallback;
mod items;
mod names;
mod print;

pub(crate) use fallback::fallback;

use moreau_sym::{Id, Layout, Quantity, Schedule, Slot, VarId};
use proc_macro2::{Literal, TokenStream};
use quote::quote;

use crate::lower::Lowered;
use crate::resolve::Resolved;
use crate::scope::Var;
use body::Body;
use print::{Scalar, Text, Tokens};

/// The generated items for a resolved, lowered model.
pub(crate) fn emit(model: &Resolved<'_>, lowered: &Lowered) -> TokenStream {
    Emitter::new(model, lowered).items()
}

/// The fused evaluation as annotated text (the snapshot tests read it).
#[cfg(test)]
pub(crate) fn listing(model: &Resolved<'_>, lowered: &Lowered) -> String {
    Emitter::new(model, lowered).listing()
}

/// The longest method body, in operations of the instruction list, that
/// the generated code hints `#[inline]` ([`Emitter::inline`]): above every
/// hand-written model's and the 2- to 11-link chains' `eval`, below every
/// robot's.
const INLINE_OPS: usize = 1000;

/// Everything emission needs about one model.
pub(crate) struct Emitter<'a, 'm> {
    model: &'a Resolved<'m>,
    outputs: Layout,
    /// Every output, sines and cosines of angle combinations shared
    /// (`moreau_sym::graph::share_waves`): the code over the model's scalar.
    full: Schedule,
    /// Every output as derived, each wave one call on its combination: the
    /// code over an enclosure type, where a wave built by the addition
    /// formulas from its angles' would enclose a wider set (the product of
    /// two intervals forgets that they are the sine and cosine of one
    /// angle; with them the double pendulum's certification in
    /// `tests/certified.rs` took 128 ms instead of 14).
    enclosed: Schedule,
    facts: Facts,
}

/// Structural facts read off the symbolic form (the generated
/// `Model::STRUCTURE`).
#[derive(Clone, Copy, Debug)]
struct Facts {
    mass_constant: bool,
    mass_diagonal: bool,
    forces_velocity_free: bool,
    forces_configuration_free: bool,
    forces_time_free: bool,
    forces_input_free: bool,
    jacobian_constant: bool,
}

impl Facts {
    fn of(model: &Resolved<'_>, lowered: &Lowered) -> Facts {
        let (g, mech, l) = (&lowered.graph, &lowered.mechanics, model.layout);
        let coordinates: Vec<_> = (0..l.n).map(|i| l.id(Var::Coordinate(i))).collect();
        let inputs: Vec<_> = (0..l.inputs).map(|i| l.id(Var::Input(i))).collect();
        let free_of = |ids: Vec<Id>, vars: &[VarId]| {
            ids.iter()
                .all(|&id| vars.iter().all(|&x| !g.depends_on(id, x)))
        };
        let zero = |ids: Vec<Id>| ids.iter().all(|&id| g.is_zero(id));
        let flat = |m: &[Vec<Id>]| m.iter().flatten().copied().collect::<Vec<Id>>();
        let off_diagonal: Vec<Id> = (0..l.n)
            .flat_map(|i| (0..l.n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| mech.mass[i][j])
            .collect();
        Facts {
            mass_constant: free_of(flat(&mech.mass), &coordinates),
            mass_diagonal: zero(off_diagonal),
            forces_velocity_free: zero(flat(&mech.force_dv)),
            forces_configuration_free: zero(flat(&mech.force_dq)),
            forces_time_free: free_of(mech.forces.clone(), &[l.id(Var::Time)]),
            forces_input_free: free_of(mech.forces.clone(), &inputs),
            jacobian_constant: free_of(flat(&mech.jacobian), &coordinates),
        }
    }
}

impl<'a, 'm> Emitter<'a, 'm> {
    fn new(model: &'a Resolved<'m>, lowered: &Lowered) -> Self {
        let mech = &lowered.mechanics;
        Emitter {
            model,
            outputs: mech.layout(),
            full: Schedule::new(&lowered.graph, &lowered.outputs),
            enclosed: Schedule::new(&lowered.graph, &mech.outputs()),
            facts: Facts::of(model, lowered),
        }
    }

    /// The instruction list of the code over `scalar`.
    fn schedule(&self, scalar: Scalar) -> &Schedule {
        match scalar {
            Scalar::Model => &self.full,
            Scalar::Enclosure => &self.enclosed,
        }
    }

    /// The body computing every entry of `qs` over `scalar`.
    fn body(&self, scalar: Scalar, qs: &[Quantity]) -> (Vec<usize>, Body) {
        let indices = self.outputs.indices(qs);
        let body = body::build(self.model, self.schedule(scalar), &self.outputs, &indices);
        (indices, body)
    }

    /// Number of operations of the code computing `qs` over `scalar`.
    fn ops(&self, scalar: Scalar, qs: &[Quantity]) -> usize {
        self.schedule(scalar)
            .restrict(&self.outputs.indices(qs))
            .op_count()
    }

    /// Number of operations of the fused evaluation (`ModelInfo::op_count`).
    fn op_count(&self) -> usize {
        self.ops(Scalar::Model, &Quantity::EVAL)
    }

    /// `#[inline]` for a method computing `qs` over `scalar` when its body
    /// has at most [`INLINE_OPS`] operations, nothing when it has more.
    ///
    /// A short body (from Example 1's `eval`, 5 operations in 2 ns, to the
    /// 11-link chain's, 923 in 130 ns) is hinted: there a call and the
    /// stores of its result are a visible share, and inlined, the caller
    /// keeps the entries in registers. A robot's bodies run to thousands
    /// (the UR5's `linearization` 10 392, the Panda's `eval` 10 106), where
    /// the call is lost in the body, and the hint only costs compile time:
    /// rustc copies an `#[inline]` generic into every codegen unit that
    /// calls it, where LLVM optimises each copy again. Without it the body
    /// is compiled once per crate. Measured on the test binaries
    /// `robots_casadi` and `kalman_robots` (since merged into `robots`)
    /// built together (`cargo test --release --no-run`, 2 cores): 370 s of
    /// CPU with every method hinted, 326 s without the hint above 1 000
    /// operations, and the run time of `kalman_robots`'s robots unchanged
    /// (43 to 48 s before, 42 to 43 s after, for
    /// `the_filter_follows_the_other_robots`).
    fn inline(&self, scalar: Scalar, qs: &[Quantity]) -> TokenStream {
        if self.ops(scalar, qs) <= INLINE_OPS {
            quote!(#[inline])
        } else {
            TokenStream::new()
        }
    }

    /// One method body computing the quantities `qs` and returning them as
    /// `ret` builds from the matrix of each quantity, in the order of `qs`.
    fn method_body(
        &self,
        qs: &[Quantity],
        ret: impl FnOnce(&[TokenStream]) -> TokenStream,
    ) -> TokenStream {
        self.method_body_over(Scalar::Model, qs, ret)
    }

    /// [`method_body`](Self::method_body) over the model's scalar (each
    /// quantity an `SMatrix`) or an enclosure type (each an array of rows).
    fn method_body_over(
        &self,
        scalar: Scalar,
        qs: &[Quantity],
        ret: impl FnOnce(&[TokenStream]) -> TokenStream,
    ) -> TokenStream {
        let (indices, body) = self.body(scalar, qs);
        let model = self.model;
        let statements = Tokens::of(scalar, |t| print::statements(t, model, &body));
        let entry = |slot: Slot| {
            let index = self.outputs.index(slot);
            let pos = indices.iter().position(|&i| i == index).unwrap_or(0);
            Tokens::of(scalar, |t| {
                print::code(t, &body.names, model, &body.outputs[pos])
            })
        };
        let (n, k) = (model.n(), model.k());
        let matrices: Vec<TokenStream> = qs
            .iter()
            .map(|&quantity| {
                let (rows, cols) = quantity.shape(n, k);
                let at = |row, col| entry(Slot { quantity, row, col });
                match scalar {
                    Scalar::Model => matrix(rows, cols, at),
                    Scalar::Enclosure => rows_array(rows, cols, at),
                }
            })
            .collect();
        let value = ret(&matrices);
        quote! { #statements #value }
    }

    /// The fused evaluation as text, with comments naming matrix entries.
    fn listing(&self) -> String {
        let (indices, body) = self.body(Scalar::Model, &Quantity::EVAL);
        let mut text = Text(format!(
            "// {}: fused evaluation of M, C, G, F, h, J ({} operations)\n",
            self.model.spec.name.text,
            self.op_count()
        ));
        print::statements(&mut text, self.model, &body);
        for (&index, code) in indices.iter().zip(&body.outputs) {
            let slot = self.outputs.slot(index);
            let mut value = Text::default();
            print::code(&mut value, &body.names, self.model, code);
            if value.0 != body.names.get(names::Local::Output(slot)) {
                text.0
                    .push_str(&format!("// {} = {}\n", slot.describe(), value.0));
            }
        }
        text.0
    }
}

/// A column-major `SMatrix` of `rows × cols` from entries `at(i, j)`.
fn matrix(rows: usize, cols: usize, at: impl Fn(usize, usize) -> TokenStream) -> TokenStream {
    let columns = (0..cols).map(|j| {
        let entries = (0..rows).map(|i| at(i, j));
        quote!([#(#entries),*])
    });
    quote!(::moreau::__private::SMatrix::from_array_storage(
        ::moreau::__private::ArrayStorage([#(#columns),*])
    ))
}

/// `[[a00, a01], [a10, a11]]`: rows of entries `at(i, j)`.
fn rows_array(rows: usize, cols: usize, at: impl Fn(usize, usize) -> TokenStream) -> TokenStream {
    let rows = (0..rows).map(|i| {
        let entries = (0..cols).map(|j| at(i, j));
        quote!([#(#entries),*])
    });
    quote!([#(#rows),*])
}

/// An integer literal without a suffix (`2`, not `2usize`).
fn int(n: usize) -> Literal {
    Literal::usize_unsuffixed(n)
}

#[cfg(test)]
mod tests;
