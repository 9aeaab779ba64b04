//! The items of the generated type: the struct and its docs, `Default`, the
//! inherent items (`N`, `K`, `new`, `initial_state`), `impl Model` and
//! `impl Sensitivities`. Method bodies come from [`Emitter::method_body`].

use moreau_sym::Quantity;
use moreau_sym::Quantity::{
    Coriolis, Force, ForceDq, ForceDv, Gap, Gravity, Jacobian, JacobianDq, Mass, MassDq,
};
use proc_macro2::{Ident, Span, TokenStream};
use quote::quote;

use super::print::{Scalar, float};
use super::{Emitter, int, matrix};
use crate::expr::fmt_number;
use crate::render;
use crate::spec::Origin;

/// The type's scalar bound.
fn bound() -> TokenStream {
    quote!(T: ::moreau::__private::RealField + ::core::marker::Copy)
}

/// `SVector<T, len>`.
fn vector(len: usize) -> TokenStream {
    let len = int(len);
    quote!(::moreau::__private::SVector<T, #len>)
}

/// `SMatrix<T, rows, cols>`.
fn mat(rows: usize, cols: usize) -> TokenStream {
    let (rows, cols) = (int(rows), int(cols));
    quote!(::moreau::__private::SMatrix<T, #rows, #cols>)
}

/// The methods' arguments `q`, `v`, `t`, `u`, with mixed-site hygiene.
fn args() -> (Ident, Ident, Ident, Ident) {
    let id = |s: &str| Ident::new(s, Span::mixed_site());
    (id("q"), id("v"), id("t"), id("u"))
}

impl Emitter<'_, '_> {
    /// Every item of the generated type.
    pub(super) fn items(&self) -> TokenStream {
        let strukt = self.struct_item();
        let reads = &self.model.spec.reads;
        let mut tracking = quote! { #(const _: &[u8] = ::core::include_bytes!(#reads);)* };
        if let Origin::Yaml { path, .. } = &self.model.spec.origin {
            tracking.extend(quote! { const _: &[u8] = ::core::include_bytes!(#path); });
        }
        let inherent = self.inherent_items();
        let model = self.model_impl();
        let sensitivities = self.sensitivities_impl();
        let enclosure = self.enclosure_impl();
        quote! { #strukt #tracking #inherent #model #sensitivities #enclosure }
    }

    fn name(&self) -> Ident {
        let name = &self.model.spec.name;
        Ident::new(&name.text, name.loc.span)
    }

    /// The struct, its docs and `Default`.
    fn struct_item(&self) -> TokenStream {
        let (name, vis, bound) = (self.name(), &self.model.spec.vis, bound());
        let doc = self.doc();
        let fields = self.fields();
        let mut defaults = TokenStream::new();
        for p in &self.model.spec.parameters {
            let field = Ident::new(&p.name.text, Span::call_site());
            let value = float(p.default.value);
            defaults.extend(quote!(#field: ::moreau::__private::cst(#value),));
        }
        let restitution = matrix(self.model.k(), 1, |i, _| {
            let e = float(self.model.restitution[i]);
            quote!(::moreau::__private::cst(#e))
        });
        quote! {
            #doc
            #[derive(Clone, Copy, Debug, PartialEq)]
            #[allow(non_snake_case)]
            #vis struct #name<T = f64> {
                #fields
            }

            impl<#bound> ::core::default::Default for #name<T> {
                fn default() -> Self {
                    #[allow(non_snake_case)]
                    Self { #defaults restitution: #restitution }
                }
            }
        }
    }

    /// The parameter fields and `restitution`, with their docs.
    fn fields(&self) -> TokenStream {
        let spec = self.model.spec;
        let mut out = TokenStream::new();
        for p in &spec.parameters {
            let name = Ident::new(&p.name.text, Span::call_site());
            let mut doc = format!(
                "Parameter `{}` (default `{}`).",
                p.name.text,
                fmt_number(p.default.value)
            );
            for line in &p.doc {
                doc.push(' ');
                doc.push_str(line);
            }
            out.extend(quote!(#[doc = #doc] pub #name: T,));
        }
        let k = self.model.k();
        let doc = if k == 0 {
            "Restitution coefficients (the model has no constraints).".to_string()
        } else {
            let names: Vec<String> = spec
                .constraints
                .iter()
                .zip(&self.model.restitution)
                .map(|(c, e)| format!("`{}` ({})", c.name.text, fmt_number(*e)))
                .collect();
            format!(
                "Restitution coefficient of each constraint, defaults: {}.",
                names.join(", ")
            )
        };
        let k = int(k);
        out.extend(quote!(#[doc = #doc] pub restitution: ::moreau::__private::SVector<T, #k>,));
        out
    }

    /// `N`, `K`, `new`, `initial_state`, `JOINT_NAMES` and
    /// `coordinate_index`.
    fn inherent_items(&self) -> TokenStream {
        let (name, bound) = (self.name(), bound());
        let (n, k) = (self.model.n(), self.model.k());
        let vec_n = vector(n);
        let initial = |values: &[f64]| {
            matrix(n, 1, |i, _| {
                let x = float(values[i]);
                quote!(::moreau::__private::cst(#x))
            })
        };
        let q0 = initial(&self.model.initial_q);
        let v0 = initial(&self.model.initial_v);
        let coordinates = &self.model.spec.coordinates;
        let joints = coordinates
            .iter()
            .map(|c| c.joint.as_deref().unwrap_or(&c.q.text));
        let (n, k) = (int(n), int(k));
        quote! {
            #[allow(non_snake_case, dead_code)]
            impl<#bound> #name<T> {
                /// Number of degrees of freedom `N`.
                pub const N: usize = #n;
                /// Number of constraints `K`.
                pub const K: usize = #k;

                /// The model with its default parameters.
                #[must_use]
                pub fn new() -> Self {
                    ::core::default::Default::default()
                }

                /// The initial state `(q0, v0)` the model gives (zeros where it
                /// gives none).
                #[must_use]
                pub fn initial_state() -> (#vec_n, #vec_n) {
                    (#q0, #v0)
                }

                /// Each coordinate's name as the model's source writes it: for
                /// a coordinate read from a URDF, its joint's own name there
                /// (`joint_8.0`, where `ModelInfo::coordinates` holds the
                /// model's `joint_8_0`); for any other, the coordinate's name.
                pub const JOINT_NAMES: [&'static str; #n] = [#(#joints),*];

                /// The index of the coordinate `name` names, by its source's
                /// name (`JOINT_NAMES`: what a ROS `JointState` message
                /// carries for a URDF joint) or by the model's; `None` if
                /// neither.
                #[must_use]
                pub fn coordinate_index(name: &str) -> ::core::option::Option<usize> {
                    let model = <Self as ::moreau::__private::Model<#n, #k>>::INFO.coordinates;
                    Self::JOINT_NAMES
                        .iter()
                        .position(|&joint| joint == name)
                        .or_else(|| model.iter().position(|&coordinate| coordinate == name))
                }
            }
        }
    }

    /// `ModelInfo`: names, the model text and the operation count.
    fn info(&self) -> TokenStream {
        let spec = self.model.spec;
        let strs = |names: Vec<&String>| quote!([#(#names),*]);
        let coordinates = strs(spec.coordinates.iter().map(|c| &c.q.text).collect());
        let velocities = strs(spec.coordinates.iter().map(|c| &c.v.text).collect());
        let constraints = strs(spec.constraints.iter().map(|c| &c.name.text).collect());
        let parameters = strs(spec.parameters.iter().map(|p| &p.name.text).collect());
        let inputs = strs(spec.inputs.iter().map(|i| &i.text).collect());
        let source = render::source(spec);
        let model_name = &spec.name.text;
        let op_count = int(self.op_count());
        quote!(::moreau::__private::ModelInfo {
            name: #model_name,
            coordinates: #coordinates,
            velocities: #velocities,
            constraints: #constraints,
            parameters: &#parameters,
            inputs: &#inputs,
            source: #source,
            op_count: #op_count,
        })
    }

    /// One quantity's method body, returning its matrix.
    fn one(&self, q: Quantity) -> TokenStream {
        self.method_body(&[q], |m| m[0].clone())
    }

    /// `impl Model`: every quantity, its fused cuts, and the parameters.
    fn model_impl(&self) -> TokenStream {
        let (name, bound) = (self.name(), bound());
        let (n, k, nu) = (self.model.n(), self.model.k(), self.model.layout.inputs);
        let (q, v, t, u) = args();
        let (vec_n, vec_k, mat_nn, mat_kn, input) =
            (vector(n), vector(k), mat(n, n), mat(k, n), vector(nu));
        let (mass, coriolis, gravity) = (self.one(Mass), self.one(Coriolis), self.one(Gravity));
        let (forces, gaps, jacobian) = (self.one(Force), self.one(Gap), self.one(Jacobian));
        let dynamics = self.method_body(&[Mass, Force], |m| {
            let (mm, f) = (&m[0], &m[1]);
            quote!((#mm, #f))
        });
        let contact = self.method_body(&[Gap, Jacobian], |m| {
            let (h, j) = (&m[0], &m[1]);
            quote!((#h, #j))
        });
        let linearization = self.method_body(&[Mass, Force, ForceDq, ForceDv], |m| {
            let (mm, f, fq, fv) = (&m[0], &m[1], &m[2], &m[3]);
            quote!(::moreau::__private::Linearization { mass: #mm, forces: #f, forces_dq: #fq, forces_dv: #fv })
        });
        let eval = self.method_body(&Quantity::EVAL, |m| {
            let (mm, c, g, f, h, j) = (&m[0], &m[1], &m[2], &m[3], &m[4], &m[5]);
            quote!(::moreau::__private::Terms { mass: #mm, coriolis: #c, gravity: #g, forces: #f, gaps: #h, jacobian: #j })
        });
        let hint = |qs: &[Quantity]| self.inline(Scalar::Model, qs);
        let (i_mass, i_coriolis, i_gravity) = (hint(&[Mass]), hint(&[Coriolis]), hint(&[Gravity]));
        let (i_forces, i_gaps, i_jacobian) = (hint(&[Force]), hint(&[Gap]), hint(&[Jacobian]));
        let (i_dynamics, i_contact) = (hint(&[Mass, Force]), hint(&[Gap, Jacobian]));
        let i_linearization = hint(&[Mass, Force, ForceDq, ForceDv]);
        let i_eval = hint(&Quantity::EVAL);
        let info = self.info();
        let structure = self.structure();
        let parameters = self.parameter_arms();
        let (n, k) = (int(n), int(k));
        quote! {
            #[allow(non_snake_case, unused_variables, clippy::all)]
            impl<#bound> ::moreau::__private::Model<#n, #k> for #name<T> {
                type Scalar = T;
                type Input = #input;

                const INFO: ::moreau::__private::ModelInfo<#n, #k> = #info;
                const STRUCTURE: ::moreau::__private::Structure = #structure;

                #i_mass
                fn mass(&self, #q: &#vec_n) -> #mat_nn { #mass }
                #i_coriolis
                fn coriolis(&self, #q: &#vec_n, #v: &#vec_n) -> #mat_nn { #coriolis }
                #i_gravity
                fn gravity(&self, #q: &#vec_n) -> #vec_n { #gravity }
                #i_forces
                fn forces(&self, #t: T, #q: &#vec_n, #v: &#vec_n, #u: &#input) -> #vec_n { #forces }
                #i_gaps
                fn gaps(&self, #q: &#vec_n) -> #vec_k { #gaps }
                #i_jacobian
                fn gap_jacobian(&self, #q: &#vec_n) -> #mat_kn { #jacobian }
                #[inline]
                fn restitution(&self) -> #vec_k { self.restitution }
                #parameters
                #i_dynamics
                fn dynamics(&self, #t: T, #q: &#vec_n, #v: &#vec_n, #u: &#input) -> (#mat_nn, #vec_n) { #dynamics }
                #i_linearization
                fn linearization(&self, #t: T, #q: &#vec_n, #v: &#vec_n, #u: &#input) -> ::moreau::__private::Linearization<T, #n> { #linearization }
                #i_contact
                fn contact(&self, #q: &#vec_n) -> (#vec_k, #mat_kn) { #contact }
                #i_eval
                fn eval(&self, #t: T, #q: &#vec_n, #v: &#vec_n, #u: &#input) -> ::moreau::__private::Terms<T, #n, #k> { #eval }
            }
        }
    }

    /// `parameter` and `parameter_mut`: a `match` on the index.
    fn parameter_arms(&self) -> TokenStream {
        let fields: Vec<Ident> = self
            .model
            .spec
            .parameters
            .iter()
            .map(|p| Ident::new(&p.name.text, Span::call_site()))
            .collect();
        let index = (0..fields.len()).map(int);
        let index_mut = index.clone();
        quote! {
            #[inline]
            fn parameter(&self, index: usize) -> ::core::option::Option<T> {
                match index { #(#index => ::core::option::Option::Some(self.#fields),)* _ => ::core::option::Option::None }
            }
            #[inline]
            fn parameter_mut(&mut self, index: usize) -> ::core::option::Option<&mut T> {
                match index { #(#index_mut => ::core::option::Option::Some(&mut self.#fields),)* _ => ::core::option::Option::None }
            }
        }
    }

    /// `impl Sensitivities`: `∂(M w)/∂q` and `∂(J v)/∂q`. The vector `w`
    /// takes the velocities' place in the schedule (`M` does not depend on
    /// them), so the argument is named `v` in both.
    fn sensitivities_impl(&self) -> TokenStream {
        let (name, bound) = (self.name(), bound());
        let (n, k) = (self.model.n(), self.model.k());
        let (q, v, _, _) = args();
        let (vec_n, mat_nn, mat_kn) = (vector(n), mat(n, n), mat(k, n));
        let (mass_dq, jacobian_dq) = (self.one(MassDq), self.one(JacobianDq));
        let (i_mass_dq, i_jacobian_dq) = (
            self.inline(Scalar::Model, &[MassDq]),
            self.inline(Scalar::Model, &[JacobianDq]),
        );
        let (n, k) = (int(n), int(k));
        quote! {
            #[allow(non_snake_case, unused_variables, clippy::all)]
            impl<#bound> ::moreau::__private::Sensitivities<#n, #k> for #name<T> {
                #i_mass_dq
                fn mass_dq(&self, #q: &#vec_n, #v: &#vec_n) -> #mat_nn { #mass_dq }
                #i_jacobian_dq
                fn jacobian_dq(&self, #q: &#vec_n, #v: &#vec_n) -> #mat_kn { #jacobian_dq }
            }
        }
    }

    /// `impl Enclosure`: `M`, `C` and `∂F/∂v` over boxes, from the same
    /// instruction list, over any `I: Enclose`.
    fn enclosure_impl(&self) -> TokenStream {
        let (name, bound) = (self.name(), bound());
        let (n, k) = (self.model.n(), self.model.k());
        let (q, v, t, u) = args();
        let over = |qs: &[Quantity]| self.method_body_over(Scalar::Enclosure, qs, |m| m[0].clone());
        let (mass, coriolis, forces_dv) = (over(&[Mass]), over(&[Coriolis]), over(&[ForceDv]));
        let hint = |qs: &[Quantity]| self.inline(Scalar::Enclosure, qs);
        let (i_mass, i_coriolis, i_forces_dv) =
            (hint(&[Mass]), hint(&[Coriolis]), hint(&[ForceDv]));
        let (n, k) = (int(n), int(k));
        quote! {
            #[allow(non_snake_case, unused_variables, clippy::all)]
            impl<#bound> ::moreau::__private::Enclosure<#n, #k> for #name<T> {
                #i_mass
                fn mass_enclosure<I: ::moreau::__private::Enclose>(&self, #q: &[I; #n]) -> [[I; #n]; #n] { #mass }
                #i_coriolis
                fn coriolis_enclosure<I: ::moreau::__private::Enclose>(&self, #q: &[I; #n], #v: &[I; #n]) -> [[I; #n]; #n] { #coriolis }
                #i_forces_dv
                fn forces_dv_enclosure<I: ::moreau::__private::Enclose>(&self, #t: I, #q: &[I; #n], #v: &[I; #n], #u: &[I]) -> [[I; #n]; #n] { #forces_dv }
            }
        }
    }

    /// `Structure`: what the symbolic form shows of `M`, `F` and `J`.
    fn structure(&self) -> TokenStream {
        let s = self.facts;
        let flags = [
            s.mass_constant,
            s.mass_diagonal,
            s.forces_velocity_free,
            s.forces_configuration_free,
            s.forces_time_free,
            s.forces_input_free,
            s.jacobian_constant,
        ];
        let [a, b, c, d, e, f, g] = flags;
        quote!(::moreau::__private::Structure {
            mass_constant: #a,
            mass_diagonal: #b,
            forces_velocity_free: #c,
            forces_configuration_free: #d,
            forces_time_free: #e,
            forces_input_free: #f,
            jacobian_constant: #g,
        })
    }

    /// The type's documentation, ending with the listing of `eval`.
    fn doc(&self) -> TokenStream {
        let spec = self.model.spec;
        let mut lines: Vec<String> = spec.doc.iter().map(|l| format!(" {l}")).collect();
        if !lines.is_empty() {
            lines.push(String::new());
        }
        let origin = match &spec.origin {
            Origin::Yaml { .. } => "a YAML model file",
            Origin::Inline => "an inline model",
        };
        let names = |v: Vec<&String>| {
            v.iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        lines.push(format!(
            " Generated by `moreau::model!` from {origin}: coordinates {}, velocities {}.",
            names(spec.coordinates.iter().map(|c| &c.q.text).collect()),
            names(spec.coordinates.iter().map(|c| &c.v.text).collect()),
        ));
        if !spec.constraints.is_empty() {
            lines.push(String::new());
            lines.push(" Constraints `h(q) ≥ 0`:".into());
            for c in &spec.constraints {
                let doc = if c.doc.is_empty() {
                    String::new()
                } else {
                    format!(" {}", c.doc.join(" "))
                };
                lines.push(format!(" - `{}`: `{} ≥ 0`.{doc}", c.name.text, c.h));
            }
        }
        lines.push(String::new());
        lines.push(" The fused evaluation [`Model::eval`](::moreau::Model::eval) generated for this model:".into());
        lines.push(String::new());
        lines.push(" ```text".into());
        lines.extend(self.listing().lines().map(|l| format!(" {l}")));
        lines.push(" ```".into());
        quote!(#(#[doc = #lines])*)
    }
}
