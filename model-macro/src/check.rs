//! Validation of a [`ModelSpec`]: one `check_*` function per rule, its rule
//! in the comment above it. Checks only record errors; they never stop each
//! other, so every mistake is reported at once.
//!
//! The one rule that needs calculus, "`T` is quadratic in `v`", is checked
//! while lowering (`lower.rs`), where the derivatives exist.

use crate::ctxt::{Ctxt, Loc};
use crate::expr::Expr;
use crate::front::keys;
use crate::spec::{ModelSpec, Name, RESERVED, Symbol};

/// Runs every check.
pub(crate) fn check(cx: &Ctxt, spec: &ModelSpec) {
    check_name_forms(cx, spec);
    check_duplicates(cx, spec);
    check_coordinates_present(cx, spec);
    check_unknown_names(cx, spec);
    check_dependencies(cx, spec);
    check_forces(cx, spec);
    check_restitution(cx, spec);
    check_initial(cx, spec);
    check_numbers_finite(cx, spec);
}

const RUST_KEYWORDS: [&str; 52] = [
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn", "for",
    "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return",
    "self", "Self", "static", "struct", "super", "trait", "true", "type", "unsafe", "use", "where",
    "while", "async", "await", "dyn", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "typeof", "unsized", "virtual", "yield", "try", "gen",
];

/// Whether `text` can name a field of the generated type: an identifier,
/// not a keyword, not reserved.
pub(crate) fn is_field_name(text: &str) -> bool {
    is_identifier(text)
        && !RUST_KEYWORDS.contains(&text)
        && !RESERVED.contains(&text)
        && text != keys::RESTITUTION
        && !text.starts_with("__")
}

fn is_identifier(text: &str) -> bool {
    let mut chars = text.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && text != "_"
}

// Every declared name becomes a Rust identifier (a field, a binding or the
// type), so it must be one and must not be a keyword; `t` and `pi` are the
// language's own; a parameter may not be called `restitution` (that field
// holds the coefficients); names starting with `__` are left to the macro.
fn check_name_forms(cx: &Ctxt, spec: &ModelSpec) {
    let check = |name: &Name, what: &str| {
        if !is_identifier(&name.text) {
            cx.error(
                name.loc,
                format!("`{}` cannot name {what}: names are letters, digits and `_`, not starting with a digit", name.text),
            );
        } else if RUST_KEYWORDS.contains(&name.text.as_str()) {
            cx.error(
                name.loc,
                format!("`{}` is a Rust keyword and cannot name {what}", name.text),
            );
        } else if name.text.starts_with("__") {
            cx.error(
                name.loc,
                format!("`{}`: names starting with `__` are reserved", name.text),
            );
        }
    };
    if spec.name.text.is_empty() {
        // a missing name is reported by the front end
    } else {
        check(&spec.name, "the model");
    }
    for c in &spec.coordinates {
        check(&c.q, "a coordinate");
        check(&c.v, "a velocity");
    }
    for p in &spec.parameters {
        check(&p.name, "a parameter");
        if p.name.text == keys::RESTITUTION {
            cx.error(
                p.name.loc,
                "a parameter cannot be called `restitution`: the generated type's `restitution` field holds the coefficients",
            );
        }
    }
    for i in &spec.inputs {
        check(i, "an input");
    }
    for d in &spec.definitions {
        check(&d.name, "a definition");
    }
    for c in &spec.constraints {
        check(&c.name, "a constraint");
    }
    let declared = spec
        .coordinates
        .iter()
        .flat_map(|c| [&c.q, &c.v])
        .chain(spec.parameters.iter().map(|p| &p.name))
        .chain(spec.inputs.iter())
        .chain(spec.definitions.iter().map(|d| &d.name));
    for name in declared {
        if RESERVED.contains(&name.text.as_str()) {
            cx.error(
                name.loc,
                format!(
                    "`{}` is reserved ({}) and cannot be declared",
                    name.text,
                    if name.text == "t" {
                        "the time"
                    } else {
                        "the constant π"
                    }
                ),
            );
        }
    }
}

// Coordinates, velocities, parameters, inputs and definitions share one
// namespace (expressions refer to all of them by name); constraint names must
// differ from each other.
fn check_duplicates(cx: &Ctxt, spec: &ModelSpec) {
    let mut seen: Vec<(&Name, &str)> = Vec::new();
    let symbols = spec
        .coordinates
        .iter()
        .flat_map(|c| [(&c.q, "a coordinate"), (&c.v, "a velocity")])
        .chain(spec.parameters.iter().map(|p| (&p.name, "a parameter")))
        .chain(spec.inputs.iter().map(|i| (i, "an input")))
        .chain(spec.definitions.iter().map(|d| (&d.name, "a definition")));
    for (name, what) in symbols {
        if let Some((_, first)) = seen.iter().find(|(n, _)| n.text == name.text) {
            cx.error(
                name.loc,
                format!(
                    "duplicate name `{}`: already declared as {first}",
                    name.text
                ),
            );
        } else {
            seen.push((name, what));
        }
    }
    let mut constraints: Vec<&str> = Vec::new();
    for c in &spec.constraints {
        if constraints.contains(&c.name.text.as_str()) {
            cx.error(
                c.name.loc,
                format!("duplicate constraint `{}`", c.name.text),
            );
        } else {
            constraints.push(&c.name.text);
        }
    }
}

// A model has at least one coordinate.
fn check_coordinates_present(cx: &Ctxt, spec: &ModelSpec) {
    if spec.coordinates.is_empty() && spec.kinetic.is_some() {
        cx.error(spec.name.loc, "a model needs at least one coordinate");
    }
}

/// Every expression of the model with a label for messages.
fn expressions(spec: &ModelSpec) -> Vec<(String, &Expr)> {
    let mut all: Vec<(String, &Expr)> = Vec::new();
    for d in &spec.definitions {
        all.push((format!("definition `{}`", d.name.text), &d.expr));
    }
    if let Some(k) = &spec.kinetic {
        all.push((format!("`{}`", keys::KINETIC), k));
    }
    if let Some(p) = &spec.potential {
        all.push((format!("`{}`", keys::POTENTIAL), p));
    }
    for f in &spec.forces {
        all.push((format!("force on `{}`", f.coordinate.text), &f.expr));
    }
    for c in &spec.constraints {
        all.push((format!("constraint `{}`", c.name.text), &c.h));
    }
    all
}

// Every name in an expression is declared; a definition is used only after
// it is defined (definitions are read in order, so none is recursive).
fn check_unknown_names(cx: &Ctxt, spec: &ModelSpec) {
    for (i, d) in spec.definitions.iter().enumerate() {
        d.expr.visit_names(&mut |name, loc| match spec.resolve(name) {
            None => unknown(cx, name, loc),
            Some(Symbol::Definition(j)) if j >= i => cx.error(
                loc,
                format!("definition `{name}` is used before it is defined (definitions are read in order)"),
            ),
            Some(_) => {}
        });
    }
    for (_, e) in expressions(spec).into_iter().skip(spec.definitions.len()) {
        e.visit_names(&mut |name, loc| {
            if spec.resolve(name).is_none() {
                unknown(cx, name, loc);
            }
        });
    }
}

fn unknown(cx: &Ctxt, name: &str, loc: Loc) {
    cx.error(
        loc,
        format!("unknown name `{name}`: not a coordinate, velocity, parameter, input or definition of this model"),
    );
}

/// What an expression may depend on.
#[derive(Clone, Copy, Default)]
struct Deps {
    velocity: bool,
    time: bool,
    input: bool,
}

/// The first name in `e` (looking through definitions) that makes it depend
/// on something `bad` rejects, with the definition it hides behind.
fn offending<'a>(
    spec: &'a ModelSpec,
    defs: &[Deps],
    e: &'a Expr,
    bad: &dyn Fn(Deps) -> bool,
) -> Option<(&'a str, Loc, Option<&'a str>)> {
    let mut found = None;
    e.visit_names(&mut |name, loc| {
        if found.is_some() {
            return;
        }
        let deps = match spec.resolve(name) {
            Some(Symbol::Velocity(_)) => Deps {
                velocity: true,
                ..Deps::default()
            },
            Some(Symbol::Time) => Deps {
                time: true,
                ..Deps::default()
            },
            Some(Symbol::Input(_)) => Deps {
                input: true,
                ..Deps::default()
            },
            Some(Symbol::Definition(j)) if j < defs.len() => {
                if bad(defs[j]) {
                    // find the culprit inside the definition
                    let inner = offending(spec, &defs[..j], &spec.definitions[j].expr, bad);
                    let culprit = inner.map_or(name, |(n, _, _)| n);
                    found = Some((culprit, loc, Some(name)));
                }
                return;
            }
            _ => Deps::default(),
        };
        if bad(deps) {
            found = Some((name, loc, None));
        }
    });
    found
}

// `V`, every `h` and `T` may not depend on time or inputs; `V` and `h` may
// not depend on velocities (the paper's `V(q)` and `h(q)`); looked for
// through definitions.
fn check_dependencies(cx: &Ctxt, spec: &ModelSpec) {
    let mut defs: Vec<Deps> = Vec::new();
    for d in &spec.definitions {
        let mut deps = Deps::default();
        d.expr.visit_names(&mut |name, _| match spec.resolve(name) {
            Some(Symbol::Velocity(_)) => deps.velocity = true,
            Some(Symbol::Time) => deps.time = true,
            Some(Symbol::Input(_)) => deps.input = true,
            Some(Symbol::Definition(j)) if j < defs.len() => {
                deps.velocity |= defs[j].velocity;
                deps.time |= defs[j].time;
                deps.input |= defs[j].input;
            }
            _ => {}
        });
        defs.push(deps);
    }
    let report = |what: &str, e: &Expr, allow_velocity: bool| {
        let bad = |d: Deps| d.time || d.input || (d.velocity && !allow_velocity);
        if let Some((name, loc, through)) = offending(spec, &defs, e, &bad) {
            let kind = match spec.resolve(name) {
                Some(Symbol::Velocity(_)) => "the velocity",
                Some(Symbol::Time) => "the time",
                Some(Symbol::Input(_)) => "the input",
                _ => "",
            };
            let via = through.map_or(String::new(), |d| format!(" (through definition `{d}`)"));
            let rule = if allow_velocity {
                "may depend only on coordinates, velocities and parameters"
            } else {
                "may depend only on coordinates and parameters"
            };
            cx.error(
                loc,
                format!("{what} {rule}, but it uses {kind} `{name}`{via}"),
            );
        }
    };
    if let Some(k) = &spec.kinetic {
        report("the kinetic energy", k, true);
    }
    if let Some(p) = &spec.potential {
        report("the potential energy", p, false);
    }
    for c in &spec.constraints {
        report(&format!("constraint `{}`", c.name.text), &c.h, false);
    }
}

// A force acts on a declared coordinate, at most once per coordinate.
fn check_forces(cx: &Ctxt, spec: &ModelSpec) {
    for (i, f) in spec.forces.iter().enumerate() {
        if spec.coordinate_index(&f.coordinate.text).is_none() {
            cx.error(
                f.coordinate.loc,
                format!(
                    "`{}` is not a coordinate; forces are given per coordinate",
                    f.coordinate.text
                ),
            );
        } else if spec.forces[..i]
            .iter()
            .any(|g| g.coordinate.text == f.coordinate.text)
        {
            cx.error(
                f.coordinate.loc,
                format!("duplicate force on `{}`", f.coordinate.text),
            );
        }
    }
}

// Every constraint has a restitution coefficient (its own or the model's), and
// every coefficient lies in [0, 1].
fn check_restitution(cx: &Ctxt, spec: &ModelSpec) {
    let in_range = |e: &crate::spec::Number| {
        if !(0.0..=1.0).contains(&e.value) {
            cx.error(e.loc, format!("restitution {} is outside [0, 1]", e.value));
        }
    };
    if let Some(e) = &spec.restitution {
        in_range(e);
    }
    for (i, c) in spec.constraints.iter().enumerate() {
        if let Some(e) = &c.restitution {
            in_range(e);
        }
        if spec.restitution_of(i).is_none() {
            cx.error(
                c.name.loc,
                format!("constraint `{}` has no restitution coefficient: give the model one (`restitution`) or this constraint its own", c.name.text),
            );
        }
    }
}

// Initial values name a coordinate or a velocity, once each.
fn check_initial(cx: &Ctxt, spec: &ModelSpec) {
    for (i, (name, _)) in spec.initial.iter().enumerate() {
        match spec.resolve(&name.text) {
            Some(Symbol::Coordinate(_) | Symbol::Velocity(_)) => {
                if spec.initial[..i].iter().any(|(n, _)| n.text == name.text) {
                    cx.error(
                        name.loc,
                        format!("duplicate initial value for `{}`", name.text),
                    );
                }
            }
            _ => cx.error(
                name.loc,
                format!(
                    "`{}` is not a coordinate or a velocity; `initial` gives their starting values",
                    name.text
                ),
            ),
        }
    }
}

// Parameter defaults and initial values are finite numbers.
fn check_numbers_finite(cx: &Ctxt, spec: &ModelSpec) {
    let numbers = spec
        .parameters
        .iter()
        .map(|p| &p.default)
        .chain(spec.initial.iter().map(|(_, x)| x));
    for n in numbers {
        if !n.value.is_finite() {
            cx.error(n.loc, "expected a finite number");
        }
    }
}
