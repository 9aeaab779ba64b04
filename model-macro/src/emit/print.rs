//! The one printer of method bodies, with two sinks: Rust tokens for the
//! generated code ([`Tokens`]) and text for the listing in the type's docs
//! and the snapshot tests ([`Text`]). Both read the same [`Body`] through
//! the same functions, so the listing is the code.
//!
//! Hygiene: user names are printed with the call-site span (they are the
//! user's identifiers), locals and the methods' arguments with
//! `Span::mixed_site()`, so that nothing the macro binds can capture a name
//! of the user's crate. Printed names are distinct anyway ([`Names`]).

use moreau_sym::Op;
use proc_macro2::{Delimiter, Group, Ident, Literal, Punct, Spacing, Span, TokenStream, TokenTree};
use quote::{ToTokens, quote};

use super::body::{Body, Code};
use super::names::{Local, Names};
use crate::expr::fmt_number;
use crate::resolve::{Resolved, Var};

/// Where printed code goes.
pub(crate) trait Sink {
    /// A name of the user's model.
    fn user(&mut self, name: &str);
    /// A name the macro made (a local or a method's argument).
    fn internal(&mut self, name: &str);
    /// `self.name` for a parameter field.
    fn field(&mut self, name: &str);
    /// `[i]`.
    fn index(&mut self, i: usize);
    /// The scalar constant `x` (`cst(x)`).
    fn cst(&mut self, x: f64);
    /// An integer literal.
    fn int(&mut self, n: i32);
    /// A binary operator `+ - * /`, or unary `-` when `unary`.
    fn op(&mut self, op: char, unary: bool);
    /// `.name(` args `)`.
    fn method(&mut self, name: &str, args: &mut dyn FnMut(&mut Self));
    /// `(` inner `)`.
    fn paren(&mut self, inner: &mut dyn FnMut(&mut Self));
    /// `let name[: T] = value;` with an optional comment (text only).
    fn binding(
        &mut self,
        name: &mut dyn FnMut(&mut Self),
        typed: bool,
        value: &mut dyn FnMut(&mut Self),
        comment: Option<&str>,
    );
}

/// Prints `code`, with the parentheses it needs and no others.
pub(crate) fn code<S: Sink>(s: &mut S, names: &Names, model: &Resolved<'_>, code: &Code) {
    let operand = |s: &mut S, inner: &Code, paren: bool| {
        if paren {
            s.paren(&mut |s| self::code(s, names, model, inner));
        } else {
            self::code(s, names, model, inner);
        }
    };
    match code {
        Code::Local(Local::Var(var)) => s.user(model.var_name(*var)),
        Code::Local(local) => s.internal(names.get(*local)),
        Code::Binary(op, a, b) => {
            let p = code.precedence();
            operand(s, a, a.precedence() < p);
            s.op(infix(*op), false);
            // Floating-point operations do not reassociate: keep the right
            // operand grouped when it binds no tighter.
            operand(s, b, b.precedence() <= p);
        }
        Code::Neg(a) => {
            s.op('-', true);
            operand(s, a, a.precedence() < 4);
        }
        Code::Powi(a, n) => {
            operand(s, a, a.precedence() < 4);
            s.method("powi", &mut |s| s.int(*n));
        }
        Code::Func(f, a) => {
            operand(s, a, a.precedence() < 4);
            s.method(f.name(), &mut |_| {});
        }
        Code::Powf(a, b) | Code::Atan2(a, b) => {
            let name = if matches!(code, Code::Powf(..)) {
                "powf"
            } else {
                "atan2"
            };
            operand(s, a, a.precedence() < 4);
            s.method(name, &mut |s| self::code(s, names, model, b));
        }
    }
}

fn infix(op: Op) -> char {
    match op {
        Op::Add => '+',
        Op::Sub => '-',
        Op::Mul => '*',
        _ => '/',
    }
}

/// Prints the statements of `body`: unpacked variables, constants, then
/// every binding in order.
pub(crate) fn statements<S: Sink>(s: &mut S, model: &Resolved<'_>, body: &Body) {
    for &var in &body.unpack {
        s.binding(
            &mut |s| s.user(model.var_name(var)),
            false,
            &mut |s| match var {
                Var::Coordinate(i) => index(s, "q", i),
                Var::Velocity(i) => index(s, "v", i),
                Var::Time => s.internal("t"),
                Var::Input(i) => index(s, "u", i),
                Var::Parameter(_) => s.field(model.var_name(var)),
            },
            None,
        );
    }
    for (i, &value) in body.constants.iter().enumerate() {
        let name = body.names.get(Local::Const(i));
        s.binding(&mut |s| s.internal(name), true, &mut |s| s.cst(value), None);
    }
    for l in &body.lets {
        let name = body.names.get(l.local);
        s.binding(
            &mut |s| s.internal(name),
            false,
            &mut |s| code(s, &body.names, model, &l.code),
            l.entry.as_deref(),
        );
    }
}

fn index<S: Sink>(s: &mut S, arg: &str, i: usize) {
    s.internal(arg);
    s.index(i);
}

/// The token sink.
#[derive(Default)]
pub(crate) struct Tokens(pub TokenStream);

impl Tokens {
    fn push(&mut self, t: impl Into<TokenTree>) {
        self.0.extend([t.into()]);
    }

    fn group(&mut self, d: Delimiter, inner: &mut dyn FnMut(&mut Self)) {
        let mut sub = Tokens::default();
        inner(&mut sub);
        self.push(Group::new(d, sub.0));
    }

    /// Prints with a fresh token sink and returns the tokens.
    pub fn of(f: impl FnOnce(&mut Tokens)) -> TokenStream {
        let mut t = Tokens::default();
        f(&mut t);
        t.0
    }
}

impl Sink for Tokens {
    fn user(&mut self, name: &str) {
        self.push(Ident::new(name, Span::call_site()));
    }
    fn internal(&mut self, name: &str) {
        self.push(Ident::new(name, Span::mixed_site()));
    }
    fn field(&mut self, name: &str) {
        let field = Ident::new(name, Span::call_site());
        self.0.extend(quote!(self.#field));
    }
    fn index(&mut self, i: usize) {
        let i = Literal::usize_unsuffixed(i);
        self.push(Group::new(Delimiter::Bracket, i.into_token_stream()));
    }
    fn cst(&mut self, x: f64) {
        let x = float(x);
        self.0.extend(quote!(::moreau::__private::cst(#x)));
    }
    fn int(&mut self, n: i32) {
        self.push(Literal::i32_unsuffixed(n));
    }
    fn op(&mut self, op: char, _unary: bool) {
        self.push(Punct::new(op, Spacing::Alone));
    }
    fn method(&mut self, name: &str, args: &mut dyn FnMut(&mut Self)) {
        self.push(Punct::new('.', Spacing::Alone));
        self.push(Ident::new(name, Span::call_site()));
        self.group(Delimiter::Parenthesis, args);
    }
    fn paren(&mut self, inner: &mut dyn FnMut(&mut Self)) {
        self.group(Delimiter::Parenthesis, inner);
    }
    fn binding(
        &mut self,
        name: &mut dyn FnMut(&mut Self),
        typed: bool,
        value: &mut dyn FnMut(&mut Self),
        _comment: Option<&str>,
    ) {
        self.0.extend(quote!(let));
        name(self);
        if typed {
            self.0.extend(quote!(: T));
        }
        self.push(Punct::new('=', Spacing::Alone));
        value(self);
        self.push(Punct::new(';', Spacing::Alone));
    }
}

/// A float literal without a suffix (`0.5`, not `0.5f64`); a non-finite
/// value (which the checks keep out of models) as the `f64` constant.
pub(crate) fn float(x: f64) -> TokenStream {
    if x.is_finite() {
        Literal::f64_unsuffixed(x).into_token_stream()
    } else if x.is_nan() {
        quote!(::core::f64::NAN)
    } else if x > 0.0 {
        quote!(::core::f64::INFINITY)
    } else {
        quote!(::core::f64::NEG_INFINITY)
    }
}

/// The text sink: the listing, one statement a line.
#[derive(Default)]
pub(crate) struct Text(pub String);

impl Sink for Text {
    fn user(&mut self, name: &str) {
        self.0.push_str(name);
    }
    fn internal(&mut self, name: &str) {
        self.0.push_str(name);
    }
    fn field(&mut self, name: &str) {
        self.0.push_str("self.");
        self.0.push_str(name);
    }
    fn index(&mut self, i: usize) {
        self.0.push_str(&format!("[{i}]"));
    }
    fn cst(&mut self, x: f64) {
        self.0.push_str(&format!("cst({})", fmt_number(x)));
    }
    fn int(&mut self, n: i32) {
        self.0.push_str(&n.to_string());
    }
    fn op(&mut self, op: char, unary: bool) {
        if unary {
            self.0.push(op);
        } else {
            self.0.push_str(&format!(" {op} "));
        }
    }
    fn method(&mut self, name: &str, args: &mut dyn FnMut(&mut Self)) {
        self.0.push('.');
        self.0.push_str(name);
        self.paren(args);
    }
    fn paren(&mut self, inner: &mut dyn FnMut(&mut Self)) {
        self.0.push('(');
        inner(self);
        self.0.push(')');
    }
    fn binding(
        &mut self,
        name: &mut dyn FnMut(&mut Self),
        typed: bool,
        value: &mut dyn FnMut(&mut Self),
        comment: Option<&str>,
    ) {
        self.0.push_str("let ");
        name(self);
        if typed {
            self.0.push_str(": T");
        }
        self.0.push_str(" = ");
        value(self);
        self.0.push(';');
        if let Some(c) = comment {
            self.0.push_str("  // ");
            self.0.push_str(c);
        }
        self.0.push('\n');
    }
}
