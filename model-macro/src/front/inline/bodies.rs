//! The inline front end's reading of a kinematic tree:
//! `bodies { name: { parent, joint, axis, xyz, rpy, mass, com, inertia } }`
//! (and `mimic`, `multiplier`, `offset` for a joint that follows another's
//! coordinate: `joint: revolute, mimic: q1, multiplier: -1`),
//! `gravity = [x, y, z];`, and a URDF: `urdf = "path";`, `locked { j1 }`,
//! `limits { j2 }`, imported by `front/urdf_keys.rs` exactly as the YAML
//! keys `urdf`, `locked` and `limits` are.

use super::*;
use crate::front::follows;
use crate::front::urdf_keys::import_urdf;

/// The URDF items of an inline model, kept until every item is read.
#[derive(Default)]
pub(super) struct UrdfItems {
    /// `urdf = "path";`: the path, located at its literal.
    path: Option<Name>,
    /// Whether `urdf` was written at all (its path perhaps unreadable).
    written: bool,
    /// `locked { ... }`: the joints held at zero.
    locked: Vec<Name>,
    /// `limits { ... }`: the joints whose `<limit>` become constraints.
    limits: Vec<Name>,
    /// Where `locked` and `limits` were written, with the key.
    keys: Vec<(Loc, &'static str)>,
}

impl UrdfItems {
    /// Reads the item `key rest` when `key` is `urdf`, `locked` or
    /// `limits`; `false` (and nothing read) for any other key.
    pub(super) fn read(&mut self, cx: &Ctxt, key: &str, loc: Loc, rest: &[TokenTree]) -> bool {
        self.written |= key == keys::URDF;
        match (key, rest) {
            (keys::URDF, [eq, TokenTree::Literal(lit)]) if is_punct(eq, '=') => {
                match syn::parse2::<syn::LitStr>(TokenTree::Literal(lit.clone()).into()) {
                    Ok(path) => {
                        self.path = Some(Name {
                            text: path.value(),
                            loc: Loc::span(path.span()),
                        });
                    }
                    Err(_) => cx.error(
                        Loc::span(lit.span()),
                        "expected the URDF's path as a string, `urdf = \"path/to/robot.urdf\";` (relative to the crate's directory)",
                    ),
                }
            }
            (keys::URDF, _) => cx.error(
                loc,
                "expected `urdf = \"path/to/robot.urdf\";` (relative to the crate's directory)",
            ),
            (keys::LOCKED | keys::LIMITS, [TokenTree::Group(g)]) => {
                let names = names(cx, g, "a joint name of the URDF");
                if key == keys::LOCKED {
                    self.locked = names;
                    self.keys.push((loc, keys::LOCKED));
                } else {
                    self.limits = names;
                    self.keys.push((loc, keys::LIMITS));
                }
            }
            (keys::LOCKED | keys::LIMITS, _) => cx.error(
                loc,
                format!("expected `{key} {{ joint1, joint2 }}`: joint names of the URDF"),
            ),
            _ => return false,
        }
        true
    }

    /// Imports the URDF into `spec`, or reports `locked` and `limits`
    /// written without one.
    pub(super) fn import(self, cx: &Ctxt, spec: &mut ModelSpec) {
        match &self.path {
            Some(path) => import_urdf(cx, spec, path, &self.locked, &self.limits),
            // A malformed `urdf` item has been reported.
            None if self.written => {}
            None => {
                for (loc, key) in self.keys {
                    cx.error(
                        loc,
                        format!("`{key}` names joints of a URDF, but this model has no `urdf = \"...\";`"),
                    );
                }
            }
        }
    }
}

/// `[a, b, c]`: `K` expressions in brackets.
pub(super) fn vector<const K: usize>(
    cx: &Ctxt,
    g: &Group,
    loc: Loc,
    what: &str,
) -> Option<[Expr; K]> {
    let parts = split_commas(g.stream());
    if g.delimiter() != Delimiter::Bracket || parts.len() != K {
        cx.error(
            Loc::span(g.span()),
            format!("expected {K} expressions in brackets, `[..]`, for {what}"),
        );
        return None;
    }
    let all: Vec<Option<Expr>> = parts.iter().map(|p| expression(cx, p, loc)).collect();
    let all: Vec<Expr> = all.into_iter().collect::<Option<_>>()?;
    <[Expr; K]>::try_from(all).ok()
}

/// One body: `name: { parent: p, joint: revolute(q: v), axis: [..], xyz:
/// [..], rpy: [..], mass: m, com: [..], inertia: [..] }` (the inline form
/// of a YAML body, its joint's keys beside the body's). A moving joint
/// appends its coordinate to `spec.coordinates`.
fn body(cx: &Ctxt, spec: &mut ModelSpec, e: Entry) -> Option<Body> {
    let here = Loc::span(e.colon);
    let [TokenTree::Group(g)] = e.value.as_slice() else {
        cx.error(
            here,
            format!(
                "expected `{}: {{ joint: ..., mass: ..., ... }}`",
                e.name.text
            ),
        );
        return None;
    };
    let zero = || Expr {
        kind: ExprKind::Num(0.0),
        loc: here,
    };
    let (mut parent, mut joint, mut axis, mut mass) = (None, None, None, None);
    let (mut xyz, mut rpy, mut com, mut inertia) = (None, None, None, None);
    let (mut mimic, mut multiplier, mut offset) = (None, None, None);
    for f in entries(cx, g) {
        let at = Loc::span(f.colon);
        let group = match f.value.as_slice() {
            [TokenTree::Group(g)] => Some(g),
            _ => None,
        };
        match (f.name.text.as_str(), group) {
            (keys::PARENT, _) => parent = f.single_name(cx, "the parent body's name (or `world`)"),
            (keys::JOINT, _) => joint = Some((joint_kind(cx, &f)?, f.value.clone(), at)),
            (keys::AXIS, Some(g)) => axis = Some(joint_axis(cx, g, at)?),
            (keys::XYZ, Some(g)) => xyz = vector::<3>(cx, g, at, "`xyz`"),
            (keys::RPY, Some(g)) => rpy = vector::<3>(cx, g, at, "`rpy`"),
            (keys::COM, Some(g)) => com = vector::<3>(cx, g, at, "`com`"),
            (keys::INERTIA, Some(g)) => inertia = vector::<6>(cx, g, at, "`inertia` (ixx, ixy, ixz, iyy, iyz, izz)"),
            (keys::MASS, _) => mass = f.expr(cx),
            (keys::MIMIC, _) => mimic = f.single_name(cx, "the coordinate this joint follows"),
            (keys::MULTIPLIER, _) => multiplier = f.number(cx),
            (keys::OFFSET, _) => offset = f.number(cx),
            (other, _) => cx.error(
                f.name.loc,
                format!("unknown or malformed `{other}` in a body; a body has parent, joint, mimic, multiplier, offset, axis, xyz, rpy, mass, com, inertia"),
            ),
        }
    }
    let Some((kind, tokens, at)) = joint else {
        cx.error(here, format!("missing `joint` in body `{}`", e.name.text));
        return None;
    };
    let Some(mass) = mass else {
        cx.error(here, format!("missing `mass` in body `{}`", e.name.text));
        return None;
    };
    let mimic = follows(cx, kind, mimic, (multiplier, offset), at);
    let coordinate = match (&mimic, tokens.as_slice()) {
        (Some(_), [_]) => None,
        (Some(_), _) => {
            cx.error(
                at,
                "a joint that mimics another has no coordinate of its own: write `joint: revolute` (or `prismatic`) beside `mimic`",
            );
            return None;
        }
        (None, _) => joint_coordinate(cx, spec, kind, &tokens, at)?,
    };
    let axis = match (kind, axis) {
        (JointKind::Fixed, _) => [0.0, 0.0, 1.0].map(|value| Number { value, loc: here }),
        (_, Some(a)) => a,
        (_, None) => {
            cx.error(here, format!("missing `axis` in body `{}`", e.name.text));
            return None;
        }
    };
    Some(Body {
        name: e.name,
        parent: parent.filter(|p| p.text != keys::WORLD),
        joint: Joint {
            kind,
            coordinate,
            mimic,
            axis,
            xyz: xyz.unwrap_or_else(|| [zero(), zero(), zero()]),
            rpy: rpy.unwrap_or_else(|| [zero(), zero(), zero()]),
        },
        mass,
        com: com.unwrap_or_else(|| [zero(), zero(), zero()]),
        inertia: inertia.unwrap_or_else(|| std::array::from_fn(|_| zero())),
    })
}

/// The kind of `joint: revolute(...)`, `prismatic(...)` or `fixed`.
fn joint_kind(cx: &Ctxt, f: &Entry) -> Option<JointKind> {
    match f.value.first() {
        Some(TokenTree::Ident(i)) if i == "revolute" => Some(JointKind::Revolute),
        Some(TokenTree::Ident(i)) if i == "prismatic" => Some(JointKind::Prismatic),
        Some(TokenTree::Ident(i)) if i == "fixed" => Some(JointKind::Fixed),
        _ => {
            cx.error(
                Loc::span(f.colon),
                format!(
                    "expected a joint ({}), as in `revolute(q: dq)`",
                    keys::JOINT_TYPES.join(", ")
                ),
            );
            None
        }
    }
}

/// `(q)` or `(q: dq)`: the coordinate's name, then the velocity's if given.
fn entries_or_name(cx: &Ctxt, args: &Group) -> Option<Vec<Name>> {
    let name = |t: &TokenTree| match t {
        TokenTree::Ident(i) => Some(Name {
            text: i.to_string(),
            loc: Loc::span(i.span()),
        }),
        _ => None,
    };
    let trees: Vec<TokenTree> = args.stream().into_iter().collect();
    let names = match trees.as_slice() {
        [q] => name(q).map(|q| vec![q]),
        [q, colon, v] if is_punct(colon, ':') => name(q).zip(name(v)).map(|(q, v)| vec![q, v]),
        _ => None,
    };
    if names.is_none() {
        cx.error(
            Loc::span(args.span()),
            "expected the joint's coordinate, `(q)`, or coordinate and velocity, `(q: dq)`",
        );
    }
    names
}

/// A joint's axis: three numbers, finite and not all zero.
fn joint_axis(cx: &Ctxt, g: &Group, at: Loc) -> Option<[Number; 3]> {
    let parts = split_commas(g.stream());
    let numbers: Vec<Option<Number>> = parts.iter().map(|p| number(cx, p, at)).collect();
    let numbers: Option<Vec<Number>> = numbers.into_iter().collect();
    let axis = numbers.and_then(|n| <[Number; 3]>::try_from(n).ok());
    let norm = axis.map_or(0.0, |a| a.iter().map(|n| n.value * n.value).sum::<f64>());
    if !(norm.is_finite() && norm > 0.0) {
        cx.error(
            at,
            "a joint's axis is three numbers, finite and not all zero",
        );
        return None;
    }
    axis
}

/// The coordinate a joint declares (`revolute(q: dq)`): its index,
/// `Some(None)` for a fixed joint, `None` after reporting a problem.
fn joint_coordinate(
    cx: &Ctxt,
    spec: &mut ModelSpec,
    kind: JointKind,
    tokens: &[TokenTree],
    at: Loc,
) -> Option<Option<usize>> {
    match (kind, tokens) {
        (JointKind::Fixed, [_]) => Some(None),
        (JointKind::Fixed, _) => {
            cx.error(at, "a fixed joint has no coordinate: write `joint: fixed`");
            None
        }
        (_, [_, TokenTree::Group(args)]) => {
            let mut names = entries_or_name(cx, args)?;
            let q = names.remove(0);
            let v = names.pop().unwrap_or_else(|| Name {
                text: format!("d{}", q.text),
                loc: q.loc,
            });
            spec.coordinates.push(Coordinate { q, v, joint: None });
            Some(Some(spec.coordinates.len() - 1))
        }
        _ => {
            cx.error(
                at,
                "a moving joint names its coordinate: `revolute(q)` or `revolute(q: dq)`",
            );
            None
        }
    }
}

/// `bodies { name: { ... }, ... }`.
pub(super) fn bodies(cx: &Ctxt, spec: &mut ModelSpec, g: &Group, loc: Loc) {
    spec.bodies_loc = Some(loc);
    for e in entries(cx, g) {
        if let Some(body) = body(cx, spec, e) {
            spec.bodies.push(body);
        }
    }
}
