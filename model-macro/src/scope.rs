//! The model's name tables: what each name of an expression stands for,
//! as a typed [`Symbol`], built once from the declarations of a
//! [`ModelSpec`] (hash maps: no stage searches names linearly). The checks
//! ask them; resolution maps every expression through them.
//!
//! There are two namespaces ([`Space`]): the values (coordinates,
//! velocities, parameters, inputs, definitions, `t` and `pi`) and the
//! bodies, which an expression names only as the first argument of
//! `position_x` and its kin, and a body as another's parent. A URDF names
//! its links and its joints apart, and a link often shares its joint's
//! name (ANYmal C's `LF_HAA`, the SO-100's `gripper`): in one namespace
//! such a robot could not be imported.

use std::collections::HashMap;

use crate::expr::Space;
use crate::spec::{ModelSpec, Name};

/// A variable of the model: what the generated code reads from its
/// arguments or its fields.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Var {
    Coordinate(usize),
    Velocity(usize),
    Time,
    Input(usize),
    Parameter(usize),
}

/// What a name in an expression stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Symbol {
    Var(Var),
    /// The `i`-th definition, in order.
    Definition(usize),
    /// The constant π.
    Pi,
    /// The `i`-th body of the kinematic tree, in the order written (only
    /// as the first argument of `position_x` and its kin, in
    /// [`Space::Body`]).
    Body(usize),
}

/// The name tables of a model: declared names (first declaration wins;
/// duplicates are a check) and the reserved `t` and `pi`, and the bodies.
pub(crate) struct Scope<'a> {
    names: HashMap<&'a str, Symbol>,
    bodies: HashMap<&'a str, usize>,
}

impl<'a> Scope<'a> {
    /// The scope of `spec`'s declarations.
    pub fn new(spec: &'a ModelSpec) -> Scope<'a> {
        let mut names = HashMap::new();
        names.insert("t", Symbol::Var(Var::Time));
        names.insert("pi", Symbol::Pi);
        let mut add = |name: &'a Name, symbol| {
            names.entry(name.text.as_str()).or_insert(symbol);
        };
        for (i, c) in spec.coordinates.iter().enumerate() {
            add(&c.q, Symbol::Var(Var::Coordinate(i)));
            add(&c.v, Symbol::Var(Var::Velocity(i)));
        }
        for (i, p) in spec.parameters.iter().enumerate() {
            add(&p.name, Symbol::Var(Var::Parameter(i)));
        }
        for (i, u) in spec.inputs.iter().enumerate() {
            add(u, Symbol::Var(Var::Input(i)));
        }
        for (i, d) in spec.definitions.iter().enumerate() {
            add(&d.name, Symbol::Definition(i));
        }
        let mut bodies = HashMap::new();
        for (i, b) in spec.bodies.iter().enumerate() {
            bodies.entry(b.name.text.as_str()).or_insert(i);
        }
        Scope { names, bodies }
    }

    /// What `name` stands for as a value, if anything.
    pub fn get(&self, name: &str) -> Option<Symbol> {
        self.names.get(name).copied()
    }

    /// The index of the body called `name`, if there is one.
    pub fn body(&self, name: &str) -> Option<usize> {
        self.bodies.get(name).copied()
    }

    /// What `name` stands for in `space`, if anything.
    pub fn lookup(&self, name: &str, space: Space) -> Option<Symbol> {
        match space {
            Space::Value => self.get(name),
            Space::Body => self.body(name).map(Symbol::Body),
        }
    }

    /// The index of the coordinate called `name`, if it is one.
    pub fn coordinate(&self, name: &str) -> Option<usize> {
        match self.get(name) {
            Some(Symbol::Var(Var::Coordinate(i))) => Some(i),
            _ => None,
        }
    }
}
