//! The struct and stub impls for a model with errors, so that the user's
//! other uses of the type do not add errors of their own.

use proc_macro2::{Ident, Span, TokenStream};
use quote::quote;

use super::int;
use crate::spec::{ModelSpec, is_field_name};

/// The struct and a stub `impl Model` for a model with errors, so that the
/// user's other uses of the type do not add errors of their own.
pub(crate) fn fallback(spec: &ModelSpec) -> TokenStream {
    if !is_field_name(&spec.name.text) || spec.name.text == "T" {
        return TokenStream::new();
    }
    let name = Ident::new(&spec.name.text, spec.name.loc.span);
    let vis = &spec.vis;
    let (n, k, nu) = (
        int(spec.dofs()),
        int(spec.constraint_count()),
        int(spec.inputs.len()),
    );
    // Only parameters that make valid, distinct fields: the stub must add no
    // error of its own.
    let mut names: Vec<&str> = Vec::new();
    for p in &spec.parameters {
        let text = p.name.text.as_str();
        if is_field_name(text) && !names.contains(&text) {
            names.push(text);
        }
    }
    let fields = names.iter().map(|n| {
        let id = Ident::new(n, Span::call_site());
        quote!(pub #id: T,)
    });
    quote! {
        #[allow(non_snake_case, dead_code)]
        #vis struct #name<T = f64> { #(#fields)* pub restitution: ::moreau::__private::SVector<T, #k> }
        #[allow(unused_variables)]
        impl<T: ::moreau::__private::RealField + ::core::marker::Copy> ::moreau::__private::Model<#n, #k> for #name<T> {
            type Scalar = T;
            type Input = ::moreau::__private::SVector<T, #nu>;
            const INFO: ::moreau::__private::ModelInfo<#n, #k> = ::core::unimplemented!();
            fn mass(&self, q: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SMatrix<T, #n, #n> { ::core::unimplemented!() }
            fn coriolis(&self, q: &::moreau::__private::SVector<T, #n>, v: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SMatrix<T, #n, #n> { ::core::unimplemented!() }
            fn gravity(&self, q: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SVector<T, #n> { ::core::unimplemented!() }
            fn forces(&self, t: T, q: &::moreau::__private::SVector<T, #n>, v: &::moreau::__private::SVector<T, #n>, u: &Self::Input) -> ::moreau::__private::SVector<T, #n> { ::core::unimplemented!() }
            fn gaps(&self, q: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SVector<T, #k> { ::core::unimplemented!() }
            fn gap_jacobian(&self, q: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SMatrix<T, #k, #n> { ::core::unimplemented!() }
            fn restitution(&self) -> ::moreau::__private::SVector<T, #k> { ::core::unimplemented!() }
            fn parameter(&self, index: usize) -> ::core::option::Option<T> { ::core::unimplemented!() }
            fn parameter_mut(&mut self, index: usize) -> ::core::option::Option<&mut T> { ::core::unimplemented!() }
        }
        #[allow(unused_variables)]
        impl<T: ::moreau::__private::RealField + ::core::marker::Copy> ::moreau::__private::Enclosure<#n, #k> for #name<T> {
            fn mass_enclosure<I: ::moreau::__private::Enclose>(&self, q: &[I; #n]) -> [[I; #n]; #n] { ::core::unimplemented!() }
            fn coriolis_enclosure<I: ::moreau::__private::Enclose>(&self, q: &[I; #n], v: &[I; #n]) -> [[I; #n]; #n] { ::core::unimplemented!() }
            fn forces_dv_enclosure<I: ::moreau::__private::Enclose>(&self, t: I, q: &[I; #n], v: &[I; #n], u: &[I]) -> [[I; #n]; #n] { ::core::unimplemented!() }
        }
        #[allow(unused_variables)]
        impl<T: ::moreau::__private::RealField + ::core::marker::Copy> ::moreau::__private::Sensitivities<#n, #k> for #name<T> {
            fn mass_dq(&self, q: &::moreau::__private::SVector<T, #n>, w: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SMatrix<T, #n, #n> { ::core::unimplemented!() }
            fn jacobian_dq(&self, q: &::moreau::__private::SVector<T, #n>, v: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SMatrix<T, #k, #n> { ::core::unimplemented!() }
        }
    }
}
