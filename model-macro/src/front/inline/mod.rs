//! The inline front end: `model! { pub struct Parabola; ... }`.
//!
//! ```text
//! /// docs
//! pub struct Parabola;
//! coordinates { x: vx, y: vy }
//! parameters { m: 1.0, g: 9.81 }
//! inputs { u }
//! let x_tip = l * sin(th);
//! kinetic = 0.5 * m * (vx^2 + vy^2);
//! potential = m * g * y;
//! applied { x: -b * vx }
//! constraints { floor: y - x^2 >= 0, #[restitution = 0.5] ceiling: y <= c }
//! restitution = 0.9;
//! initial { x: 1.0, vx: 3.0 }
//! bodies { link: { joint: revolute(th: w), axis: [0, 1, 0], mass: m, com: [0, 0, -l] } }
//! gravity = [0, 0, -g];
//! urdf = "robots/arm.urdf";
//! locked { finger }
//! limits { elbow }
//! ```
//!
//! The body is cut into items by hand (a brace group, or everything up to
//! `;`), so one malformed item is reported and the others are still read.
//! The kinematic tree (`bodies`, `gravity`, and `urdf`, `locked`, `limits`,
//! which mean what the YAML keys mean) is read in `bodies.rs`.

mod bodies;

use proc_macro2::{Delimiter, Group, Spacing, Span, TokenStream, TokenTree};

use crate::ctxt::Ctxt;
use crate::expr::{self, BinOp, Expr, ExprKind};
use crate::keys;
use crate::loc::Loc;
use crate::spec::{
    Applied, Body, Constraint, Coordinate, Definition, Joint, JointKind, ModelSpec, Name, Number,
    Origin, Parameter,
};

/// Builds the model from the macro's tokens. Returns `None` only when the
/// `struct Name;` header cannot be read.
pub(crate) fn build(cx: &Ctxt, input: TokenStream) -> Option<ModelSpec> {
    let trees: Vec<TokenTree> = input.into_iter().collect();
    let header_end = trees
        .iter()
        .position(|t| is_punct(t, ';'))
        .map_or(trees.len(), |i| i + 1);
    let header = header(cx, &trees, header_end)?;
    let mut spec = ModelSpec {
        name: Name {
            text: header.ident.to_string(),
            loc: Loc::span(header.ident.span()),
        },
        vis: {
            let vis = header.vis;
            quote::quote!(#vis)
        },
        doc: docs(&header.attrs),
        coordinates: Vec::new(),
        parameters: Vec::new(),
        inputs: Vec::new(),
        definitions: Vec::new(),
        kinetic: None,
        potential: None,
        applied: Vec::new(),
        constraints: Vec::new(),
        restitution: None,
        initial: Vec::new(),
        bodies: Vec::new(),
        gravity: None,
        bodies_loc: None,
        origin: Origin::Inline,
        reads: Vec::new(),
        unreadable: Vec::new(),
    };
    let mut seen: Vec<String> = Vec::new();
    let mut urdf = bodies::UrdfItems::default();
    let mut rest = &trees[header_end..];
    while !rest.is_empty() {
        let (item, after) = next_item(rest);
        rest = after;
        read_item(cx, &mut spec, &mut seen, &mut urdf, item);
    }
    // Read after the other items, whatever their order, as in YAML.
    urdf.import(cx, &mut spec);
    let has_bodies = seen.iter().any(|s| s == keys::BODIES || s == keys::URDF);
    for (key, what) in [
        (keys::COORDINATES, "its coordinates (or `bodies`)"),
        (keys::KINETIC, "its kinetic energy (or `bodies`)"),
    ] {
        if !has_bodies && !seen.iter().any(|s| s == key) {
            cx.error(
                spec.name.loc,
                format!("missing `{key}`: a model needs {what}"),
            );
        }
    }
    Some(spec)
}

/// Reads `/// docs pub struct Name;`, the first `end` trees; `None` after
/// reporting what is wrong.
fn header(cx: &Ctxt, trees: &[TokenTree], end: usize) -> Option<Header> {
    let header: TokenStream = trees[..end].iter().cloned().collect();
    match syn::parse2(header) {
        Ok(h) => Some(h),
        Err(e) => {
            let message = match trees {
                [TokenTree::Ident(k), eq, ..] if k == keys::URDF && is_punct(eq, '=') => {
                    "an inline model starts with its name, then names its URDF: `pub struct Robot; urdf = \"path/to/robot.urdf\"; ...`".to_string()
                }
                _ => format!(
                    "{e}; an inline model starts with `pub struct Name;` (or `model!(file = \"...\")` for a YAML file)"
                ),
            };
            cx.error(Loc::span(e.span()), message);
            None
        }
    }
}

struct Header {
    attrs: Vec<syn::Attribute>,
    vis: syn::Visibility,
    ident: syn::Ident,
}

impl syn::parse::Parse for Header {
    fn parse(input: syn::parse::ParseStream<'_>) -> syn::Result<Self> {
        let attrs = input.call(syn::Attribute::parse_outer)?;
        let vis = input.parse()?;
        input.parse::<syn::Token![struct]>()?;
        let ident = input.parse()?;
        input.parse::<syn::Token![;]>()?;
        Ok(Header { attrs, vis, ident })
    }
}

/// One item of the body: `key { ... }`, or tokens up to and without `;`.
fn next_item(trees: &[TokenTree]) -> (&[TokenTree], &[TokenTree]) {
    if let [TokenTree::Ident(_), TokenTree::Group(g), ..] = trees {
        if g.delimiter() == Delimiter::Brace {
            let after = &trees[2..];
            let after = match after.first() {
                Some(t) if is_punct(t, ';') || is_punct(t, ',') => &after[1..],
                _ => after,
            };
            return (&trees[..2], after);
        }
    }
    match trees.iter().position(|t| is_punct(t, ';')) {
        Some(i) => (&trees[..i], &trees[i + 1..]),
        None => (trees, &[]),
    }
}

fn read_item(
    cx: &Ctxt,
    spec: &mut ModelSpec,
    seen: &mut Vec<String>,
    urdf: &mut bodies::UrdfItems,
    item: &[TokenTree],
) {
    let Some(first) = item.first() else { return };
    let TokenTree::Ident(key) = first else {
        cx.error(
            Loc::span(first.span()),
            "expected an item such as `kinetic = ...;` or `constraints { ... }`",
        );
        return;
    };
    let key_text = key.to_string();
    let loc = Loc::span(key.span());
    if key_text == "let" {
        match definition(cx, &item[1..], loc) {
            Ok(definition) => spec.definitions.push(definition),
            Err(Some(name)) => spec.unreadable.push(name),
            Err(None) => {}
        }
        return;
    }
    if seen.contains(&key_text) {
        cx.error(loc, format!("duplicate `{key_text}`"));
        return;
    }
    seen.push(key_text.clone());
    if !urdf.read(cx, &key_text, loc, &item[1..]) {
        read_keyed(cx, spec, &key_text, loc, &item[1..]);
    }
}

/// Reads the item `key ...` (`rest` is what follows the key).
fn read_keyed(cx: &Ctxt, spec: &mut ModelSpec, key_text: &str, loc: Loc, rest: &[TokenTree]) {
    match (key_text, rest) {
        (keys::COORDINATES, [TokenTree::Group(g)]) => {
            let mut written: Vec<Coordinate> = entries(cx, g)
                .into_iter()
                .filter_map(|e| {
                    let v = e.single_name(cx, "its velocity's name, as in `x: vx`")?;
                    Some(Coordinate {
                        q: e.name,
                        v,
                        joint: None,
                    })
                })
                .collect();
            // Joint coordinates (when `bodies` came first) go after the
            // written ones.
            let shift = written.len();
            for b in &mut spec.bodies {
                if let Some(c) = &mut b.joint.coordinate {
                    *c += shift;
                }
            }
            written.append(&mut spec.coordinates);
            spec.coordinates = written;
        }
        (keys::BODIES, [TokenTree::Group(g)]) => bodies::bodies(cx, spec, g, loc),
        (keys::GRAVITY, [eq, TokenTree::Group(g)]) if is_punct(eq, '=') => {
            spec.gravity = bodies::vector::<3>(cx, g, loc, "`gravity`");
        }
        (keys::GRAVITY, _) => cx.error(loc, "expected `gravity = [x, y, z];`"),
        (keys::PARAMETERS, [TokenTree::Group(g)]) => spec.parameters = parameters(cx, g),
        (keys::INPUTS, [TokenTree::Group(g)]) => spec.inputs = names(cx, g, "an input name"),
        (keys::APPLIED, [TokenTree::Group(g)]) => spec.applied = applied(cx, g),
        (keys::CONSTRAINTS, [TokenTree::Group(g)]) => {
            spec.constraints = entries(cx, g)
                .into_iter()
                .filter_map(|e| constraint(cx, e))
                .collect();
        }
        (keys::INITIAL, [TokenTree::Group(g)]) => spec.initial = initial(cx, g),
        (keys::KINETIC, rest) => spec.kinetic = assigned_expr(cx, rest, loc, keys::KINETIC),
        (keys::POTENTIAL, rest) => spec.potential = assigned_expr(cx, rest, loc, keys::POTENTIAL),
        (keys::RESTITUTION, [eq, value @ ..]) if is_punct(eq, '=') => {
            spec.restitution = number(cx, value, loc);
        }
        (keys::RESTITUTION, _) => cx.error(loc, "expected `restitution = <number>;`"),
        (
            keys::COORDINATES
            | keys::PARAMETERS
            | keys::INPUTS
            | keys::APPLIED
            | keys::CONSTRAINTS
            | keys::INITIAL
            | keys::BODIES,
            _,
        ) => cx.error(loc, format!("expected `{key_text} {{ ... }}`")),
        (keys::FORCES_RENAMED, _) => cx.error(loc, keys::forces_renamed()),
        (other, _) => cx.error(
            loc,
            format!(
                "unknown item `{other}`; a model has coordinates, parameters, inputs, let, urdf, locked, limits, bodies, gravity, kinetic, potential, applied, constraints, restitution, initial"
            ),
        ),
    }
}

/// `parameters { m: 1.0, ... }`, each with its doc comments.
fn parameters(cx: &Ctxt, g: &Group) -> Vec<Parameter> {
    entries(cx, g)
        .into_iter()
        .filter_map(|e| {
            let default = e.number(cx)?;
            Some(Parameter {
                doc: e.doc,
                name: e.name,
                default,
            })
        })
        .collect()
}

/// `applied { q: expr, ... }`.
fn applied(cx: &Ctxt, g: &Group) -> Vec<Applied> {
    entries(cx, g)
        .into_iter()
        .filter_map(|e| {
            let expr = e.expr(cx)?;
            Some(Applied {
                coordinate: e.name,
                expr,
            })
        })
        .collect()
}

/// `initial { q: 1.0, ... }`.
fn initial(cx: &Ctxt, g: &Group) -> Vec<(Name, Number)> {
    entries(cx, g)
        .into_iter()
        .filter_map(|e| {
            let x = e.number(cx)?;
            Some((e.name, x))
        })
        .collect()
}

/// `inputs { u1, u2 }` (and `locked`, `limits`): names only; `what` says
/// what a name should be, in the message for anything else.
fn names(cx: &Ctxt, g: &Group, what: &str) -> Vec<Name> {
    split_commas(g.stream())
        .into_iter()
        .filter_map(|tokens| match tokens.as_slice() {
            [TokenTree::Ident(i)] => Some(Name {
                text: i.to_string(),
                loc: Loc::span(i.span()),
            }),
            _ => {
                let span = tokens.first().map_or(g.span(), TokenTree::span);
                cx.error(Loc::span(span), format!("expected {what}"));
                None
            }
        })
        .collect()
}

fn assigned_expr(cx: &Ctxt, rest: &[TokenTree], loc: Loc, key: &str) -> Option<Expr> {
    match rest {
        [eq, value @ ..] if is_punct(eq, '=') => expression(cx, value, Loc::span(eq.span())),
        _ => {
            cx.error(loc, format!("expected `{key} = <expression>;`"));
            None
        }
    }
}

/// `let name = expr;`; the name alone when the expression could not be
/// read (after reporting why).
fn definition(cx: &Ctxt, rest: &[TokenTree], loc: Loc) -> Result<Definition, Option<Name>> {
    match rest {
        [TokenTree::Ident(name), eq, value @ ..] if is_punct(eq, '=') => {
            let name = Name {
                text: name.to_string(),
                loc: Loc::span(name.span()),
            };
            match expression(cx, value, Loc::span(eq.span())) {
                Some(expr) => Ok(Definition { name, expr }),
                None => Err(Some(name)),
            }
        }
        _ => {
            cx.error(loc, "expected `let name = <expression>;`");
            Err(None)
        }
    }
}

fn expression(cx: &Ctxt, tokens: &[TokenTree], whole: Loc) -> Option<Expr> {
    let toks = expr::tokenize_stream(cx, tokens.iter().cloned().collect())?;
    expr::parse(cx, &toks, whole)
}

fn number(cx: &Ctxt, tokens: &[TokenTree], whole: Loc) -> Option<Number> {
    let e = expression(cx, tokens, whole)?;
    let value = match &e.kind {
        ExprKind::Num(x) => *x,
        ExprKind::Neg(inner) => match inner.kind {
            ExprKind::Num(x) => -x,
            _ => f64::NAN,
        },
        _ => f64::NAN,
    };
    if value.is_nan() {
        cx.error(e.loc, "expected a number");
        return None;
    }
    Some(Number { value, loc: e.loc })
}

/// A `#[attrs] name: value` entry of a section.
struct Entry {
    name: Name,
    value: Vec<TokenTree>,
    colon: Span,
    doc: Vec<String>,
    restitution: Option<Number>,
}

impl Entry {
    fn expr(&self, cx: &Ctxt) -> Option<Expr> {
        expression(cx, &self.value, Loc::span(self.colon))
    }

    fn number(&self, cx: &Ctxt) -> Option<Number> {
        number(cx, &self.value, Loc::span(self.colon))
    }

    fn single_name(&self, cx: &Ctxt, what: &str) -> Option<Name> {
        match self.value.as_slice() {
            [TokenTree::Ident(i)] => Some(Name {
                text: i.to_string(),
                loc: Loc::span(i.span()),
            }),
            _ => {
                cx.error(Loc::span(self.colon), format!("expected {what}"));
                None
            }
        }
    }
}

fn entries(cx: &Ctxt, group: &Group) -> Vec<Entry> {
    split_commas(group.stream())
        .into_iter()
        .filter_map(|tokens| entry(cx, &tokens))
        .collect()
}

fn entry(cx: &Ctxt, mut tokens: &[TokenTree]) -> Option<Entry> {
    let mut doc = Vec::new();
    let mut restitution = None;
    while let [hash, TokenTree::Group(attr), rest @ ..] = tokens {
        if !is_punct(hash, '#') || attr.delimiter() != Delimiter::Bracket {
            break;
        }
        tokens = rest;
        let inner: Vec<TokenTree> = attr.stream().into_iter().collect();
        match inner.as_slice() {
            [TokenTree::Ident(k), eq, value @ ..] if k == "doc" && is_punct(eq, '=') => {
                if let Ok(lit) = syn::parse2::<syn::LitStr>(value.iter().cloned().collect()) {
                    doc.push(lit.value().trim().to_string());
                }
            }
            [TokenTree::Ident(k), eq, value @ ..] if k == keys::RESTITUTION && is_punct(eq, '=') => {
                restitution = number(cx, value, Loc::span(k.span()));
            }
            _ => cx.error(
                Loc::span(attr.span()),
                "unknown attribute; an entry may carry doc comments and, on a constraint, `#[restitution = e]`",
            ),
        }
    }
    match tokens {
        [TokenTree::Ident(name), colon, value @ ..] if is_punct(colon, ':') => {
            if value.is_empty() {
                cx.error(
                    Loc::span(colon.span()),
                    format!("expected a value after `{name}:`"),
                );
                return None;
            }
            Some(Entry {
                name: Name {
                    text: name.to_string(),
                    loc: Loc::span(name.span()),
                },
                value: value.to_vec(),
                colon: colon.span(),
                doc,
                restitution,
            })
        }
        [first, ..] => {
            cx.error(Loc::span(first.span()), "expected an entry `name: value`");
            None
        }
        [] => None,
    }
}

/// `name: lhs >= rhs` (gap `lhs - rhs`) or `name: lhs <= rhs` (gap
/// `rhs - lhs`); `rhs` is usually `0`.
fn constraint(cx: &Ctxt, e: Entry) -> Option<Constraint> {
    let split = e.value.windows(2).position(|w| {
        matches!(&w[0], TokenTree::Punct(p) if (p.as_char() == '>' || p.as_char() == '<') && p.spacing() == Spacing::Joint)
            && is_punct(&w[1], '=')
    });
    let Some(at) = split else {
        cx.error(
            Loc::span(e.colon),
            format!(
                "constraint `{}` must be an inequality such as `y - x^2 >= 0` or `y <= c`",
                e.name.text
            ),
        );
        return None;
    };
    let op = &e.value[at];
    let greater = is_punct(op, '>');
    let op_loc = Loc::span(op.span());
    let lhs = expression(cx, &e.value[..at], Loc::span(e.colon));
    let rhs = expression(cx, &e.value[at + 2..], op_loc);
    let (lhs, rhs) = (lhs?, rhs?);
    let is_zero = |x: &Expr| matches!(x.kind, ExprKind::Num(z) if z == 0.0);
    let h = match (greater, is_zero(&lhs), is_zero(&rhs)) {
        (true, _, true) => lhs,
        (false, true, _) => rhs,
        (true, _, _) => sub(lhs, rhs, op_loc),
        (false, _, _) => sub(rhs, lhs, op_loc),
    };
    Some(Constraint {
        name: e.name,
        h,
        restitution: e.restitution,
        doc: e.doc,
    })
}

/// `a - b`, written `a + c` when `b` is `-c` (so `x >= -w` reads `x + w`).
fn sub(a: Expr, b: Expr, loc: Loc) -> Expr {
    let kind = match b.kind {
        ExprKind::Neg(c) => ExprKind::Binary(BinOp::Add, Box::new(a), c),
        kind => ExprKind::Binary(BinOp::Sub, Box::new(a), Box::new(Expr { kind, loc: b.loc })),
    };
    Expr { kind, loc }
}

fn split_commas(stream: TokenStream) -> Vec<Vec<TokenTree>> {
    let mut parts = vec![Vec::new()];
    for tree in stream {
        if is_punct(&tree, ',') {
            parts.push(Vec::new());
        } else if let Some(last) = parts.last_mut() {
            last.push(tree);
        }
    }
    parts.retain(|p| !p.is_empty());
    parts
}

fn is_punct(tree: &TokenTree, c: char) -> bool {
    matches!(tree, TokenTree::Punct(p) if p.as_char() == c)
}

fn docs(attrs: &[syn::Attribute]) -> Vec<String> {
    attrs
        .iter()
        .filter(|a| a.path().is_ident("doc"))
        .filter_map(|a| match &a.meta {
            syn::Meta::NameValue(nv) => match &nv.value {
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Str(s),
                    ..
                }) => Some(s.value().trim().to_string()),
                _ => None,
            },
            _ => None,
        })
        .collect()
}
