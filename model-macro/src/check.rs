//! Validation: one `check_*` function per rule, its rule in the comment
//! above it. Checks only record errors; they never stop each other, so
//! every mistake is reported at once.
//!
//! Names are looked up in the model's one [`Scope`] (a hash map built
//! once). The rules that need calculus ("`T` is quadratic in `v`", "`M` has
//! a positive diagonal", "`h` depends on `q`") are checked while lowering,
//! where the derivatives exist.

use std::collections::HashSet;

use crate::ctxt::Ctxt;
use crate::expr::{Expr, ExprKind};
use crate::keys;
use crate::loc::Loc;
use crate::scope::{Scope, Symbol, Var};
use crate::spec::{ModelSpec, Name, PRELUDE_VALUES, RESERVED, RUST_KEYWORDS, is_identifier};

/// Runs every check.
pub(crate) fn check(cx: &Ctxt, spec: &ModelSpec, scope: &Scope<'_>) {
    check_name_forms(cx, spec);
    check_duplicates(cx, spec);
    check_coordinates_present(cx, spec);
    check_unknown_names(cx, spec, scope);
    check_dependencies(cx, spec, scope);
    check_applied(cx, spec, scope);
    check_restitution(cx, spec);
    check_initial(cx, spec, scope);
    check_numbers_finite(cx, spec);
    check_tree(cx, spec, scope);
    check_body_fields(cx, spec, scope);
    check_body_references(cx, spec, scope);
    check_mimics(cx, spec, scope);
}

// Every declared name becomes a Rust identifier (a field, a binding or the
// type), so it must be one (ASCII: see `spec::is_identifier`) and must not
// be a keyword or a prelude value (`let None = …` is a pattern); `t` and
// `pi` are the language's own; a parameter may not be called `restitution`
// (that field holds the coefficients); the model may not be called `T`
// (its scalar type parameter); names starting with `__` are left to the
// macro.
fn check_name_forms(cx: &Ctxt, spec: &ModelSpec) {
    let check = |name: &Name, what: &str| {
        if !is_identifier(&name.text) {
            cx.error(
                name.loc,
                format!("`{}` cannot name {what}: names are letters, digits and `_`, not starting with a digit", name.text),
            );
        } else if PRELUDE_VALUES.contains(&name.text.as_str()) {
            cx.error(
                name.loc,
                format!("`{}` is a value of Rust's prelude and cannot name {what}: the generated code would read it as that value", name.text),
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
    } else if spec.name.text == "T" {
        cx.error(
            spec.name.loc,
            "`T` cannot name the model: the generated type is generic over its scalar, called `T`",
        );
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
    for b in &spec.bodies {
        check(&b.name, "a body");
        if b.name.text == keys::WORLD {
            cx.error(
                b.name.loc,
                "`world` cannot name a body: it is the fixed base, the parent of the tree's roots",
            );
        }
    }
    for (name, _) in spec.declared() {
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
// namespace (expressions refer to all of them by name), and the bodies have
// their own (`scope.rs`); constraint names must differ from each other.
fn check_duplicates(cx: &Ctxt, spec: &ModelSpec) {
    let mut seen: std::collections::HashMap<&str, &str> = std::collections::HashMap::new();
    for (name, what) in spec.values() {
        if let Some(first) = seen.get(name.text.as_str()) {
            cx.error(
                name.loc,
                format!(
                    "duplicate name `{}`: already declared as {first}",
                    name.text
                ),
            );
        } else {
            seen.insert(&name.text, what);
        }
    }
    let mut bodies: HashSet<&str> = HashSet::new();
    for b in &spec.bodies {
        if !bodies.insert(&b.name.text) {
            cx.error(b.name.loc, format!("duplicate body `{}`", b.name.text));
        }
    }
    let mut constraints: HashSet<&str> = HashSet::new();
    for c in &spec.constraints {
        if !constraints.insert(&c.name.text) {
            cx.error(
                c.name.loc,
                format!("duplicate constraint `{}`", c.name.text),
            );
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
    for f in &spec.applied {
        all.push((format!("applied force on `{}`", f.coordinate.text), &f.expr));
    }
    for c in &spec.constraints {
        all.push((format!("constraint `{}`", c.name.text), &c.h));
    }
    all
}

// Every name in an expression is declared; a definition is used only after
// it is defined (definitions are read in order, so none is recursive). A
// body's name used as a value is `check_body_references`'s to report.
fn check_unknown_names(cx: &Ctxt, spec: &ModelSpec, scope: &Scope<'_>) {
    for (i, d) in spec.definitions.iter().enumerate() {
        d.expr.visit(&mut |name, loc| match scope.get(name) {
            None if scope.body(name).is_none() => unknown(cx, spec, name, loc),
            None => {}
            Some(Symbol::Definition(j)) if j >= i => cx.error(
                loc,
                format!("definition `{name}` is used before it is defined (definitions are read in order)"),
            ),
            Some(_) => {}
        });
    }
    for (_, e) in expressions(spec).into_iter().skip(spec.definitions.len()) {
        e.visit(&mut |name, loc| {
            if scope.get(name).is_none() && scope.body(name).is_none() {
                unknown(cx, spec, name, loc);
            }
        });
    }
}

fn unknown(cx: &Ctxt, spec: &ModelSpec, name: &str, loc: Loc) {
    if spec.unreadable.iter().any(|n| n.text == name) {
        return; // its definition's error is reported already
    }
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

impl Deps {
    fn of(symbol: Option<Symbol>, defs: &[Deps]) -> Deps {
        match symbol {
            Some(Symbol::Var(var)) => Deps {
                velocity: matches!(var, Var::Velocity(_)),
                time: var == Var::Time,
                input: matches!(var, Var::Input(_)),
            },
            Some(Symbol::Definition(j)) => defs.get(j).copied().unwrap_or_default(),
            _ => Deps::default(),
        }
    }

    fn or(self, other: Deps) -> Deps {
        Deps {
            velocity: self.velocity | other.velocity,
            time: self.time | other.time,
            input: self.input | other.input,
        }
    }
}

/// The culprit of a dependency: the name that brings it, where it is used,
/// and the definition it hides behind (if any).
type Culprit<'a> = (&'a str, Loc, Option<&'a str>);

/// The first name in `e` (looking through definitions) that makes it depend
/// on something `bad` rejects.
fn offending<'a>(
    spec: &'a ModelSpec,
    scope: &Scope<'_>,
    defs: &[Deps],
    e: &'a Expr,
    bad: &dyn Fn(Deps) -> bool,
) -> Option<Culprit<'a>> {
    let mut found = None;
    e.visit(&mut |name: &'a String, loc| {
        if found.is_some() {
            return;
        }
        let symbol = scope.get(name);
        match symbol {
            Some(Symbol::Definition(j)) if j < defs.len() && bad(defs[j]) => {
                let inner = offending(spec, scope, &defs[..j], &spec.definitions[j].expr, bad);
                let culprit = inner.map_or(name.as_str(), |(n, _, _)| n);
                found = Some((culprit, loc, Some(name.as_str())));
            }
            _ if bad(Deps::of(symbol, defs)) => found = Some((name, loc, None)),
            _ => {}
        }
    });
    found
}

// `V`, every `h` and `T` may not depend on time or inputs; `V` and `h` may
// not depend on velocities (the paper's `V(q)` and `h(q)`); looked for
// through definitions.
fn check_dependencies(cx: &Ctxt, spec: &ModelSpec, scope: &Scope<'_>) {
    let mut defs: Vec<Deps> = Vec::with_capacity(spec.definitions.len());
    for d in &spec.definitions {
        let mut deps = Deps::default();
        d.expr
            .visit(&mut |name, _| deps = deps.or(Deps::of(scope.get(name), &defs)));
        defs.push(deps);
    }
    let report = |what: &str, e: &Expr, allow_velocity: bool| {
        let bad = |d: Deps| d.time || d.input || (d.velocity && !allow_velocity);
        let Some((name, loc, through)) = offending(spec, scope, &defs, e, &bad) else {
            return;
        };
        let kind = match scope.get(name) {
            Some(Symbol::Var(Var::Velocity(_))) => "the velocity",
            Some(Symbol::Var(Var::Time)) => "the time",
            Some(Symbol::Var(Var::Input(_))) => "the input",
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

// An applied force acts on a declared coordinate, at most once per
// coordinate.
fn check_applied(cx: &Ctxt, spec: &ModelSpec, scope: &Scope<'_>) {
    let mut seen = HashSet::new();
    for f in &spec.applied {
        let name = &f.coordinate;
        match scope.coordinate(&name.text) {
            None => cx.error(
                name.loc,
                format!(
                    "`{}` is not a coordinate; applied forces are given per coordinate",
                    name.text
                ),
            ),
            Some(i) if !seen.insert(i) => cx.error(
                name.loc,
                format!("duplicate applied force on `{}`", name.text),
            ),
            Some(_) => {}
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
fn check_initial(cx: &Ctxt, spec: &ModelSpec, scope: &Scope<'_>) {
    let mut seen = HashSet::new();
    for (name, _) in &spec.initial {
        match scope.get(&name.text) {
            Some(Symbol::Var(Var::Coordinate(_) | Var::Velocity(_))) => {
                if !seen.insert(name.text.as_str()) {
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

// A body's parent is `world` or another body, and following parents from
// any body reaches `world` (the tree has no cycle).
fn check_tree(cx: &Ctxt, spec: &ModelSpec, scope: &Scope<'_>) {
    let parent_of = |i: usize| scope.body(&spec.bodies[i].parent.as_ref()?.text);
    for (i, b) in spec.bodies.iter().enumerate() {
        if let Some(p) = &b.parent
            && scope.body(&p.text).is_none()
        {
            cx.error(
                p.loc,
                format!(
                    "`{}` is not a body of this model; a body's parent is another body or `{}`",
                    p.text,
                    keys::WORLD
                ),
            );
            continue;
        }
        // A walk longer than the number of bodies has met a cycle.
        let mut at = i;
        for _ in 0..=spec.bodies.len() {
            match parent_of(at) {
                Some(j) if j == i => {
                    cx.error(
                        b.name.loc,
                        format!(
                            "body `{}` is its own ancestor: the bodies form a cycle, not a tree",
                            b.name.text
                        ),
                    );
                    break;
                }
                Some(j) => at = j,
                None => break,
            }
        }
    }
}

// A joint that mimics another follows a coordinate of the model (of another
// joint or written), by a finite multiplier and offset.
fn check_mimics(cx: &Ctxt, spec: &ModelSpec, scope: &Scope<'_>) {
    for b in &spec.bodies {
        let Some(m) = &b.joint.mimic else { continue };
        if scope.coordinate(&m.coordinate.text).is_none() {
            cx.error(
                m.coordinate.loc,
                format!(
                    "body `{}`'s joint mimics `{}`, which is not a coordinate of this model",
                    b.name.text, m.coordinate.text
                ),
            );
        }
        for n in [m.multiplier, m.offset] {
            if !n.value.is_finite() {
                cx.error(n.loc, "expected a finite number");
            }
        }
    }
}

// A body's numbers (placement, mass, centre of mass, inertia) and the
// gravity vector are constants of the model: they may name parameters
// (and `pi`), nothing else.
fn check_body_fields(cx: &Ctxt, spec: &ModelSpec, scope: &Scope<'_>) {
    let check = |e: &Expr, what: &str| {
        e.visit(&mut |name, loc| match scope.get(name) {
            None if scope.body(name).is_none() => unknown(cx, spec, name, loc),
            Some(Symbol::Var(Var::Parameter(_)) | Symbol::Pi) => {}
            _ => cx.error(
                loc,
                format!("{what} may name only parameters, but it uses `{name}`"),
            ),
        });
    };
    for b in &spec.bodies {
        let what = format!("a number of body `{}`", b.name.text);
        let j = &b.joint;
        let all = j
            .xyz
            .iter()
            .chain(&j.rpy)
            .chain([&b.mass])
            .chain(&b.com)
            .chain(&b.inertia);
        for e in all {
            check(e, &what);
        }
    }
    for e in spec.gravity.iter().flatten() {
        check(e, "`gravity`");
    }
}

// A body is named only as the first argument of `position_x`, `_y` or
// `_z`, and that argument names a body.
fn check_body_references(cx: &Ctxt, spec: &ModelSpec, scope: &Scope<'_>) {
    fn walk(cx: &Ctxt, scope: &Scope<'_>, e: &Expr) {
        match &e.kind {
            ExprKind::Num(_) => {}
            ExprKind::Name(name) => {
                if scope.get(name).is_none() && scope.body(name).is_some() {
                    cx.error(
                        e.loc,
                        format!("`{name}` is a body, not a number: use `position_x({name}, x, y, z)` (or `_y`, `_z`) for the world position of one of its points"),
                    );
                }
            }
            ExprKind::Neg(a) | ExprKind::Func(_, a) => walk(cx, scope, a),
            ExprKind::Binary(_, a, b) | ExprKind::Atan2(a, b) => {
                walk(cx, scope, a);
                walk(cx, scope, b);
            }
            ExprKind::Frame(kind, axis, body, point) => {
                let call = kind.functions()[*axis];
                match (scope.body(body), scope.get(body)) {
                    (Some(_), _) => {}
                    (None, Some(_)) => cx.error(
                        e.loc,
                        format!("`{body}` is not a body: the first argument of `{call}` names a body of `{}`", keys::BODIES),
                    ),
                    (None, None) => cx.error(
                        e.loc,
                        format!("unknown body `{body}`: the first argument of `{call}` names a body of `{}` (a link of the URDF)", keys::BODIES),
                    ),
                }
                point.iter().for_each(|c| walk(cx, scope, c));
            }
        }
    }
    for (_, e) in expressions(spec) {
        walk(cx, scope, e);
    }
}
