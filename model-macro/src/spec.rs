//! [`ModelSpec`]: the one data type between the front ends and the rest.
//!
//! Both front ends (YAML and inline) build it; after them nothing reads YAML
//! or syn tokens again. Every name, number and expression remembers its
//! [`Loc`], so later stages point at the user's text. Questions about the
//! model ("which coordinate is `th2`?") are answered here, once.

use proc_macro2::TokenStream;

use crate::ctxt::Loc;
use crate::expr::Expr;

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
pub(crate) struct Force {
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

/// Where the model was written.
#[derive(Clone, Debug)]
pub(crate) enum Origin {
    /// A YAML file: its absolute path (for `include_bytes!`) and its text.
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
    pub forces: Vec<Force>,
    pub constraints: Vec<Constraint>,
    pub restitution: Option<Number>,
    pub initial: Vec<(Name, Number)>,
    pub origin: Origin,
}

/// What a name in an expression stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Symbol {
    Coordinate(usize),
    Velocity(usize),
    Parameter(usize),
    Input(usize),
    Definition(usize),
    Time,
    Pi,
}

/// Names the language reserves: the time and the constant π.
pub(crate) const RESERVED: [&str; 2] = ["t", "pi"];

impl ModelSpec {
    /// Number of degrees of freedom `N`.
    pub fn dofs(&self) -> usize {
        self.coordinates.len()
    }

    /// Number of constraints `K`.
    pub fn constraint_count(&self) -> usize {
        self.constraints.len()
    }

    /// What `name` stands for, if anything. Definitions are found whatever
    /// their position; whether one is used before it is defined is a check.
    pub fn resolve(&self, name: &str) -> Option<Symbol> {
        if name == "t" {
            return Some(Symbol::Time);
        }
        if name == "pi" {
            return Some(Symbol::Pi);
        }
        fn find<'a>(mut names: impl Iterator<Item = &'a Name>, name: &str) -> Option<usize> {
            names.position(|n| n.text == name)
        }
        if let Some(i) = find(self.coordinates.iter().map(|c| &c.q), name) {
            return Some(Symbol::Coordinate(i));
        }
        if let Some(i) = find(self.coordinates.iter().map(|c| &c.v), name) {
            return Some(Symbol::Velocity(i));
        }
        if let Some(i) = find(self.parameters.iter().map(|p| &p.name), name) {
            return Some(Symbol::Parameter(i));
        }
        if let Some(i) = find(self.inputs.iter(), name) {
            return Some(Symbol::Input(i));
        }
        find(self.definitions.iter().map(|d| &d.name), name).map(Symbol::Definition)
    }

    /// Index of the coordinate called `name`.
    pub fn coordinate_index(&self, name: &str) -> Option<usize> {
        self.coordinates.iter().position(|c| c.q.text == name)
    }

    /// The restitution coefficient of constraint `i`: its own, else the
    /// model's, else none (a check reports that).
    pub fn restitution_of(&self, i: usize) -> Option<Number> {
        self.constraints[i].restitution.or(self.restitution)
    }

    /// The initial value of the coordinate or velocity called `name` (0 when
    /// the model gives none).
    pub fn initial_value(&self, name: &str) -> f64 {
        self.initial
            .iter()
            .find(|(n, _)| n.text == name)
            .map_or(0.0, |(_, x)| x.value)
    }

    /// The force expression on coordinate `i`, if the model gives one.
    pub fn force_on(&self, i: usize) -> Option<&Expr> {
        let name = &self.coordinates[i].q.text;
        self.forces
            .iter()
            .find(|f| &f.coordinate.text == name)
            .map(|f| &f.expr)
    }
}
