//! The one printer of method bodies, with two sinks: Rust tokens for the
//! generated code ([`Tokens`]) and text for the listing in the type's docs
//! and the snapshot tests ([`Text`]). Both read the same [`Body`] through
//! the same functions, so the listing is the code.
//!
//! Hygiene: user names are printed with the call-site span (they are the
//! user's identifiers), locals and the methods' arguments with
//! `Span::mixed_site()`, so that nothing the macro binds can capture a name
//! of the user's crate. Printed names are distinct anyway ([`Names`]).

use moreau_sym::{Func, Op};
use proc_macro2::{Delimiter, Group, Ident, Literal, Punct, Spacing, Span, TokenStream, TokenTree};
use quote::{ToTokens, quote};

use super::body::{Body, Code, Let};
use super::names::{Local, Names};
use crate::expr::fmt_number;
use crate::resolve::Resolved;
use crate::scope::Var;

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
    /// Input `i` (`u[i]`).
    fn input(&mut self, i: usize);
    /// The scalar constant `x` (`cst(x)`).
    fn cst(&mut self, x: f64);
    /// An integer literal.
    fn int(&mut self, n: i32);
    /// A binary operator `+ - * /`, unary `-` when `unary`, or the comma
    /// between the names of a tuple.
    fn op(&mut self, op: char, unary: bool);
    /// `.name(` args `)`.
    fn method(&mut self, name: &str, args: &mut dyn FnMut(&mut Self));
    /// `sin a`, `cos a` or the pair `(sin a, cos a)` (`name` `"sin"`,
    /// `"cos"`, `"sin_cos"`) of the operand `a`: `name(a)`, the runtime's
    /// function of that name for the model's scalar (one implementation of
    /// each for `f64` and `f32`, so a sine is the same bits whether it was
    /// computed alone or in a pair), `a.name()` for an enclosure (`a`
    /// parenthesised where a method would bind tighter: `wrap`).
    fn trig(&mut self, name: &str, a: &mut dyn FnMut(&mut Self), wrap: bool);
    /// `(` inner `)`.
    fn paren(&mut self, inner: &mut dyn FnMut(&mut Self));
    /// A part of a long body: `let [outs] = part([ins]);` around a nested
    /// function holding `body` (names with `true` are the user's).
    fn part(
        &mut self,
        live_in: &[(&str, bool)],
        live_out: &[(&str, bool)],
        body: &mut dyn FnMut(&mut Self),
    );
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
        Code::Func(f @ (Func::Sin | Func::Cos), a) => s.trig(
            f.name(),
            &mut |s| self::code(s, names, model, a),
            a.precedence() < 4,
        ),
        Code::Func(f, a) => {
            operand(s, a, a.precedence() < 4);
            s.method(f.name(), &mut |_| {});
        }
        Code::SinCos(a) => s.trig(
            "sin_cos",
            &mut |s| self::code(s, names, model, a),
            a.precedence() < 4,
        ),
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
/// every binding in order; a body heavier than [`PART`] in parts, each
/// binding the constants it reads itself.
pub(crate) fn statements<S: Sink>(s: &mut S, model: &Resolved<'_>, body: &Body) {
    for &var in &body.unpack {
        s.binding(
            &mut |s| s.user(model.var_name(var)),
            false,
            &mut |s| match var {
                Var::Coordinate(i) => index(s, "q", i),
                Var::Velocity(i) => index(s, "v", i),
                Var::Time => s.internal("t"),
                Var::Input(i) => s.input(i),
                Var::Parameter(_) => s.field(model.var_name(var)),
            },
            None,
        );
    }
    let weight: usize =
        body.constants.len() + body.lets.iter().map(|l| l.code.size()).sum::<usize>();
    if weight <= PART {
        constants(s, body, 0..body.constants.len());
        lets(s, model, body, &body.lets);
        return;
    }
    let (parts, top_constants) = parts(body);
    constants(s, body, top_constants);
    for part in parts {
        let name = |local: &Local| match local {
            Local::Var(var) => (model.var_name(*var), true),
            other => (body.names.get(*other), false),
        };
        let live_in: Vec<(&str, bool)> = part.live_in.iter().map(name).collect();
        let live_out: Vec<(&str, bool)> = part.live_out.iter().map(name).collect();
        s.part(&live_in, &live_out, &mut |s| {
            constants(s, body, part.constants.iter().copied());
            lets(s, model, body, &body.lets[part.range.clone()]);
        });
    }
}

/// `let k: T = cst(x);` for each of the constants `which`.
fn constants<S: Sink>(s: &mut S, body: &Body, which: impl IntoIterator<Item = usize>) {
    for i in which {
        let name = body.names.get(Local::Const(i));
        let value = body.constants[i];
        s.binding(&mut |s| s.internal(name), true, &mut |s| s.cst(value), None);
    }
}

fn lets<S: Sink>(s: &mut S, model: &Resolved<'_>, body: &Body, lets: &[Let]) {
    for l in lets {
        let name = body.names.get(l.local);
        let pair = l.pair.map(|p| body.names.get(p));
        s.binding(
            &mut |s| match pair {
                Some(second) => s.paren(&mut |s| {
                    s.internal(name);
                    s.op(',', false);
                    s.internal(second);
                }),
                None => s.internal(name),
            },
            false,
            &mut |s| code(s, &body.names, model, &l.code),
            l.entry.as_deref(),
        );
    }
}

/// The heaviest one function of the generated code gets, in operations
/// and names of its bindings ([`Code::size`](super::body::Code::size)) plus
/// its constants: a heavier body (a potential of thousands of terms) is cut
/// into parts of about this weight, each a nested `#[inline(never)]`
/// function that binds the constants it reads, takes the other values it
/// reads and returns those read after it, so that the compiler never sees
/// one huge function (rustc's type checking, borrow checking and MIR
/// optimisation of one function grow faster than linearly in its size).
/// With folded expressions bounded by
/// [`MAX_FOLD_SIZE`](super::body::MAX_FOLD_SIZE), a part weighs at most
/// `PART + 2 MAX_FOLD_SIZE` plus its constants. The cut costs time at run
/// time (the parts do not inline into each other), so it is kept for large
/// bodies: the 10-link chain (weight 2 663) is one function, the 11-link
/// one (3 309, 550 bindings) two, as with the former cut at 512 bindings.
pub(crate) const PART: usize = 3000;

/// One part of a long body: its bindings, the constants and the locals it
/// reads from before it, and the locals it defines that are read after it.
pub(super) struct Part {
    pub range: std::ops::Range<usize>,
    pub constants: Vec<usize>,
    pub live_in: Vec<Local>,
    pub live_out: Vec<Local>,
}

/// Cuts `body.lets` into consecutive parts of weight about [`PART`]; also
/// returns the constants the outputs read (bound before the parts).
pub(super) fn parts(body: &Body) -> (Vec<Part>, Vec<usize>) {
    use std::collections::{HashMap, HashSet};
    // part of each binding: a new part starts once the weight reaches PART
    let mut part_of = Vec::with_capacity(body.lets.len());
    let (mut part, mut weight) = (0, 0);
    for l in &body.lets {
        if weight >= PART {
            (part, weight) = (part + 1, 0);
        }
        weight += l.code.size();
        part_of.push(part);
    }
    let count = part + 1;
    let defined: HashMap<Local, usize> = body
        .lets
        .iter()
        .zip(&part_of)
        .flat_map(|(l, &p)| {
            core::iter::once(l.local)
                .chain(l.pair)
                .map(move |local| (local, p))
        })
        .collect();
    let mut live_in: Vec<Vec<Local>> = vec![Vec::new(); count];
    let mut live_out: Vec<Vec<Local>> = vec![Vec::new(); count];
    let mut consts: Vec<Vec<usize>> = vec![Vec::new(); count + 1];
    let mut seen_in: Vec<HashSet<Local>> = vec![HashSet::new(); count + 1];
    let mut seen_out: Vec<HashSet<Local>> = vec![HashSet::new(); count];
    let mut read = |reader: Option<usize>, local: Local| {
        if let Local::Const(i) = local {
            // constants are bound where they are read: the outputs' at the top
            let at = reader.unwrap_or(count);
            if seen_in[at].insert(local) {
                consts[at].push(i);
            }
            return;
        }
        let home = defined.get(&local).copied();
        if let Some(p) = reader
            && home != Some(p)
            && seen_in[p].insert(local)
        {
            live_in[p].push(local);
        }
        if let Some(h) = home
            && reader != Some(h)
            && seen_out[h].insert(local)
        {
            live_out[h].push(local);
        }
    };
    for (l, &p) in body.lets.iter().zip(&part_of) {
        l.code.visit_locals(&mut |local| read(Some(p), local));
    }
    for out in &body.outputs {
        out.visit_locals(&mut |local| read(None, local));
    }
    let top = std::mem::take(&mut consts[count]);
    let mut start = 0;
    let parts = (0..count)
        .map(|p| {
            let end = start + part_of[start..].iter().take_while(|&&q| q == p).count();
            let range = start..end;
            start = end;
            Part {
                range,
                constants: std::mem::take(&mut consts[p]),
                live_in: std::mem::take(&mut live_in[p]),
                live_out: std::mem::take(&mut live_out[p]),
            }
        })
        .collect();
    (parts, top)
}

fn index<S: Sink>(s: &mut S, arg: &str, i: usize) {
    s.internal(arg);
    s.index(i);
}

/// The scalar of generated code: the model's `T`, or an enclosure type
/// `I: Enclose` (interval evaluation, `Enclosure`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum Scalar {
    #[default]
    Model,
    Enclosure,
}

/// The token sink.
#[derive(Default)]
pub(crate) struct Tokens(pub TokenStream, pub Scalar);

impl Tokens {
    fn push(&mut self, t: impl Into<TokenTree>) {
        self.0.extend([t.into()]);
    }

    fn group(&mut self, d: Delimiter, inner: &mut dyn FnMut(&mut Self)) {
        let mut sub = Tokens(TokenStream::new(), self.1);
        inner(&mut sub);
        self.push(Group::new(d, sub.0));
    }

    /// Prints with a fresh token sink over `scalar` and returns the tokens.
    pub fn of(scalar: Scalar, f: impl FnOnce(&mut Tokens)) -> TokenStream {
        let mut t = Tokens(TokenStream::new(), scalar);
        f(&mut t);
        t.0
    }

    /// The scalar type's name (`T` or `I`).
    fn scalar_type(&self) -> Ident {
        match self.1 {
            Scalar::Model => Ident::new("T", Span::call_site()),
            Scalar::Enclosure => Ident::new("I", Span::call_site()),
        }
    }

    /// The bound of the scalar type.
    fn scalar_bound(&self) -> TokenStream {
        match self.1 {
            Scalar::Model => quote!(::moreau::__private::RealField + ::core::marker::Copy),
            Scalar::Enclosure => quote!(::moreau::__private::Enclose),
        }
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
        match self.1 {
            Scalar::Model => self.0.extend(quote!(self.#field)),
            Scalar::Enclosure => self
                .0
                .extend(quote!(::moreau::__private::point::<T, I>(self.#field))),
        }
    }
    fn input(&mut self, i: usize) {
        let u = Ident::new("u", Span::mixed_site());
        let i = Literal::usize_unsuffixed(i);
        match self.1 {
            Scalar::Model => self.0.extend(quote!(#u[#i])),
            Scalar::Enclosure => self
                .0
                .extend(quote!(#u.get(#i).copied().unwrap_or_else(I::entire))),
        }
    }
    fn index(&mut self, i: usize) {
        let i = Literal::usize_unsuffixed(i);
        self.push(Group::new(Delimiter::Bracket, i.into_token_stream()));
    }
    fn cst(&mut self, x: f64) {
        let x = float(x);
        match self.1 {
            Scalar::Model => self.0.extend(quote!(::moreau::__private::cst(#x))),
            Scalar::Enclosure => self.0.extend(quote!(I::point(#x))),
        }
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
    fn trig(&mut self, name: &str, a: &mut dyn FnMut(&mut Self), wrap: bool) {
        match self.1 {
            Scalar::Model => {
                let name = Ident::new(name, Span::call_site());
                self.0.extend(quote!(::moreau::__private::#name));
                self.group(Delimiter::Parenthesis, a);
            }
            Scalar::Enclosure => {
                if wrap {
                    self.group(Delimiter::Parenthesis, a);
                } else {
                    a(self);
                }
                self.method(name, &mut |_| {});
            }
        }
    }
    fn paren(&mut self, inner: &mut dyn FnMut(&mut Self)) {
        self.group(Delimiter::Parenthesis, inner);
    }
    fn part(
        &mut self,
        live_in: &[(&str, bool)],
        live_out: &[(&str, bool)],
        body: &mut dyn FnMut(&mut Self),
    ) {
        let ident = |&(name, user): &(&str, bool)| {
            Ident::new(
                name,
                if user {
                    Span::call_site()
                } else {
                    Span::mixed_site()
                },
            )
        };
        let ins: Vec<Ident> = live_in.iter().map(ident).collect();
        let outs: Vec<Ident> = live_out.iter().map(ident).collect();
        let (nin, nout) = (
            Literal::usize_unsuffixed(ins.len()),
            Literal::usize_unsuffixed(outs.len()),
        );
        let inner = Tokens::of(self.1, |t| body(t));
        let (part, input) = (
            Ident::new("part", Span::mixed_site()),
            Ident::new("input", Span::mixed_site()),
        );
        let (ty, bound) = (self.scalar_type(), self.scalar_bound());
        self.0.extend(quote! {
            let [#(#outs),*] = {
                #[inline(never)]
                fn #part<#ty: #bound>(#input: [#ty; #nin]) -> [#ty; #nout] {
                    let [#(#ins),*] = #input;
                    #inner
                    [#(#outs),*]
                }
                #part([#(#ins),*])
            };
        });
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
            let ty = self.scalar_type();
            self.0.extend(quote!(: #ty));
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
    fn input(&mut self, i: usize) {
        self.0.push_str(&format!("u[{i}]"));
    }
    fn cst(&mut self, x: f64) {
        self.0.push_str(&format!("cst({})", fmt_number(x)));
    }
    fn int(&mut self, n: i32) {
        self.0.push_str(&n.to_string());
    }
    fn op(&mut self, op: char, unary: bool) {
        if op == ',' {
            self.0.push_str(", ");
        } else if unary {
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
    fn trig(&mut self, name: &str, a: &mut dyn FnMut(&mut Self), _wrap: bool) {
        self.0.push_str(name);
        self.paren(a);
    }
    fn paren(&mut self, inner: &mut dyn FnMut(&mut Self)) {
        self.0.push('(');
        inner(self);
        self.0.push(')');
    }
    fn part(
        &mut self,
        live_in: &[(&str, bool)],
        live_out: &[(&str, bool)],
        body: &mut dyn FnMut(&mut Self),
    ) {
        let names = |v: &[(&str, bool)]| v.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ");
        self.0.push_str(&format!(
            "// part ({}) -> ({})\n",
            names(live_in),
            names(live_out)
        ));
        body(self);
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
