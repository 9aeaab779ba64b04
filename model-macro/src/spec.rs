//! [`ModelSpec`]: the one data type between the front ends and the rest.
//!
//! Both front ends (YAML and inline) build it; after them nothing reads YAML
//! or syn tokens again. Every name, number and expression remembers its
//! [`Loc`], so later stages point at the user's text. Questions about the
//! model ("which coordinate is `th2`?") are answered here, once.

use proc_macro2::TokenStream;

use crate::expr::Expr;
use crate::loc::Loc;

/// A name with its location.
#[derive(Clone, Debug)]
pub(crate) struct Name {
    pub text: String,
    pub loc: Loc,
}

/// A number with its location.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Number {
    pub value: f64,
    pub loc: Loc,
}

/// A generalized coordinate and the name of its velocity.
#[derive(Clone, Debug)]
pub(crate) struct Coordinate {
    pub q: Name,
    pub v: Name,
    /// The URDF joint's own name, for a coordinate read from a URDF
    /// (`joint_8.0`, where `q` is `joint_8_0`: `front::urdf::identifier`).
    pub joint: Option<String>,
}

/// A parameter: a field of the generated type, with its default.
#[derive(Clone, Debug)]
pub(crate) struct Parameter {
    pub name: Name,
    pub default: Number,
    pub doc: Vec<String>,
}

/// A named subexpression (`definitions` in YAML, `let` inline).
#[derive(Clone, Debug)]
pub(crate) struct Definition {
    pub name: Name,
    pub expr: Expr,
}

/// An extra generalized force `Q_i`, acting on one coordinate.
#[derive(Clone, Debug)]
pub(crate) struct Applied {
    pub coordinate: Name,
    pub expr: Expr,
}

/// A unilateral constraint `h(q) ≥ 0`.
#[derive(Clone, Debug)]
pub(crate) struct Constraint {
    pub name: Name,
    pub h: Expr,
    pub restitution: Option<Number>,
    pub doc: Vec<String>,
}

/// The kind of a body's joint: what its coordinate does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum JointKind {
    /// A rotation by the coordinate (radians) about the axis.
    Revolute,
    /// A translation by the coordinate along the axis.
    Prismatic,
    /// No motion: the body is welded to its parent (no coordinate).
    Fixed,
}

/// The joint that attaches a body to its parent. Its frame is placed in the
/// parent's frame by `xyz` then `rpy` (URDF's `<origin>`: the rotation is
/// `Rz(yaw) Ry(pitch) Rx(roll)`); the body's frame is the joint's frame
/// moved by the coordinate.
#[derive(Clone, Debug)]
pub(crate) struct Joint {
    pub kind: JointKind,
    /// The index of its coordinate in `ModelSpec::coordinates` (not for
    /// fixed joints, nor for a joint that mimics another): the front ends
    /// declare one coordinate per moving joint.
    pub coordinate: Option<usize>,
    /// A moving joint without a coordinate of its own: it follows another's.
    pub mimic: Option<Mimic>,
    /// The axis in the joint's frame, as numbers (normalized when lowered).
    pub axis: [Number; 3],
    pub xyz: [Expr; 3],
    pub rpy: [Expr; 3],
}

/// A joint that follows another's coordinate (URDF's `<mimic>`: a
/// gripper's second finger, a coupled phalanx): its angle (or
/// displacement) is `multiplier · q + offset`, `q` the coordinate named
/// `coordinate`, and its velocity `multiplier · q̇`.
#[derive(Clone, Debug)]
pub(crate) struct Mimic {
    pub coordinate: Name,
    pub multiplier: Number,
    pub offset: Number,
}

/// A rigid body of the kinematic tree (`bodies`).
#[derive(Clone, Debug)]
pub(crate) struct Body {
    pub name: Name,
    /// The parent body; `None` for the world (the fixed base).
    pub parent: Option<Name>,
    pub joint: Joint,
    pub mass: Expr,
    /// The centre of mass in the body's frame.
    pub com: [Expr; 3],
    /// The inertia about the centre of mass, in the body's frame:
    /// `ixx, ixy, ixz, iyy, iyz, izz`.
    pub inertia: [Expr; 6],
}

/// Where the model was written.
#[derive(Clone, Debug)]
pub(crate) enum Origin {
    /// A YAML file: its absolute path (for `include_bytes!`, so that
    /// editing it rebuilds the model) and its text.
    Yaml { path: String, text: String },
    /// Inline tokens.
    Inline,
}

/// A whole model, as written, before any check.
#[derive(Clone, Debug)]
pub(crate) struct ModelSpec {
    pub name: Name,
    /// The visibility of the generated type, as tokens (`pub`, `pub(crate)`,
    /// or nothing).
    pub vis: TokenStream,
    pub doc: Vec<String>,
    pub coordinates: Vec<Coordinate>,
    pub parameters: Vec<Parameter>,
    pub inputs: Vec<Name>,
    pub definitions: Vec<Definition>,
    pub kinetic: Option<Expr>,
    pub potential: Option<Expr>,
    pub applied: Vec<Applied>,
    pub constraints: Vec<Constraint>,
    pub restitution: Option<Number>,
    pub initial: Vec<(Name, Number)>,
    /// The kinematic tree (`bodies`), in the order written.
    pub bodies: Vec<Body>,
    /// The gravity vector of the tree's potential energy (`gravity`);
    /// `None` is `[0, 0, -9.81]`.
    pub gravity: Option<[Expr; 3]>,
    /// Where `bodies` was written (for messages about the tree as a whole).
    pub bodies_loc: Option<Loc>,
    pub origin: Origin,
    /// The absolute paths of the other files the model reads (a URDF),
    /// tracked by `include_bytes!` like a YAML model's file.
    pub reads: Vec<String>,
    /// Definitions whose expression could not be read (the front end has
    /// reported why): their uses are not reported again as unknown names.
    pub unreadable: Vec<Name>,
}

/// Names the language reserves: the time and the constant π.
pub(crate) const RESERVED: [&str; 2] = ["t", "pi"];

/// Rust's keywords, strict and reserved: none can name anything in a model.
pub(crate) const RUST_KEYWORDS: [&str; 52] = [
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn", "for",
    "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return",
    "self", "Self", "static", "struct", "super", "trait", "true", "type", "unsafe", "use", "where",
    "while", "async", "await", "dyn", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "typeof", "unsized", "virtual", "yield", "try", "gen",
];

/// Names of the prelude that a `let` binding or a field cannot take without
/// changing meaning (`let None = …` is a pattern, not a binding).
pub(crate) const PRELUDE_VALUES: [&str; 4] = ["None", "Some", "Ok", "Err"];

/// Whether `text` is an identifier of the language: ASCII letters, digits
/// and `_`, not starting with a digit, not `_` alone.
///
/// Non-ASCII names are not accepted: rustc compares identifiers after NFC
/// normalization (`Å`, U+212B, and `Å`, U+00C5, are one identifier to it),
/// which the macro could not reproduce without Unicode tables, so two names
/// it thinks distinct could be one binding in the generated code.
pub(crate) fn is_identifier(text: &str) -> bool {
    let mut chars = text.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && text != "_"
}

/// Whether `text` can name a field of the generated type: an identifier,
/// not a keyword, not reserved, not a prelude value, not `restitution`.
pub(crate) fn is_field_name(text: &str) -> bool {
    is_identifier(text)
        && !RUST_KEYWORDS.contains(&text)
        && !RESERVED.contains(&text)
        && !PRELUDE_VALUES.contains(&text)
        && text != crate::keys::RESTITUTION
        && !text.starts_with("__")
}

impl ModelSpec {
    /// Number of degrees of freedom `N`.
    pub fn dofs(&self) -> usize {
        self.coordinates.len()
    }

    /// Number of constraints `K`.
    pub fn constraint_count(&self) -> usize {
        self.constraints.len()
    }

    /// The restitution coefficient of constraint `i`: its own, else the
    /// model's, else none (a check reports that).
    pub fn restitution_of(&self, i: usize) -> Option<Number> {
        self.constraints[i].restitution.or(self.restitution)
    }

    /// Every name the model declares in the namespace of values
    /// (coordinates, velocities, parameters, inputs, definitions), with
    /// what it is, in declaration order.
    pub fn values(&self) -> impl Iterator<Item = (&Name, &'static str)> {
        self.coordinates
            .iter()
            .flat_map(|c| [(&c.q, "a coordinate"), (&c.v, "a velocity")])
            .chain(self.parameters.iter().map(|p| (&p.name, "a parameter")))
            .chain(self.inputs.iter().map(|i| (i, "an input")))
            .chain(self.definitions.iter().map(|d| (&d.name, "a definition")))
    }

    /// Every name the model declares: the values, then the bodies (their
    /// own namespace: `scope.rs`).
    pub fn declared(&self) -> impl Iterator<Item = (&Name, &'static str)> {
        self.values()
            .chain(self.bodies.iter().map(|b| (&b.name, "a body")))
    }
}
