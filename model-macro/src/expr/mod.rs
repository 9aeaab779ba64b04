//! The expression grammar both front ends share.
//!
//! ```text
//! expr  := term (('+' | '-') term)*
//! term  := unary (('*' | '/') unary)*
//! unary := '-' unary | power
//! power := atom ('^' unary)?          right-associative; -x^2 = -(x^2)
//! atom  := number | name | name '(' expr (',' expr)* ')' | '(' expr ')'
//! ```
//!
//! Two families of calls are not elementary functions: `position_x(body, x,
//! y, z)` (and `_y`, `_z`) is a world coordinate of the point `[x, y, z]` of
//! a body's frame, and `position_x(body)` that of the frame's origin;
//! `direction_x(body, x, y, z)` (and `_y`, `_z`) is a world coordinate of
//! the direction `[x, y, z]` fixed in the body's frame, rotated and not
//! moved: the body's orientation (`direction_z(hand, 0, 0, 1)` is the
//! vertical component of the hand's `z` axis, the entry `R_zz` of its
//! rotation).
//!
//! This is the grammar's one statement; `models/README.md` and the CasADi
//! reference parser (`tests/casadi_reference.py`) point here. The functions
//! are `moreau_sym::Function::ALL`.
//!
//! A YAML scalar is cut into [`Tok`]s by [`tokenize_str`]; inline Rust tokens
//! by [`tokenize_stream`] (both in `lex.rs`). From there one parser,
//! [`parse`] (`parse.rs`), builds the [`Expr`] tree. `^` means power in both:
//! we parse the tokens ourselves, so Rust's XOR (and its precedence) never
//! applies.
//!
//! An [`Expr`] is generic over what a name is: the front ends build
//! `Expr<String>` (names as written); resolution (`resolve.rs`) maps it to
//! `Expr<Symbol>`, where every name is a typed reference.

mod lex;
mod parse;
#[cfg(test)]
mod tests;

use std::fmt;

use moreau_sym::Func;

use crate::loc::Loc;

pub(crate) use lex::{Tok, TokKind, tokenize_str, tokenize_stream};
pub(crate) use parse::parse;

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

impl BinOp {
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Pow => "^",
        }
    }

    fn precedence(self) -> u8 {
        match self {
            BinOp::Add | BinOp::Sub => 1,
            BinOp::Mul | BinOp::Div => 2,
            BinOp::Pow => 4,
        }
    }
}

/// An expression of the model language, every node with its location.
/// `N` is what a name is: its text after the front ends, a typed
/// `Symbol` (`scope.rs`) after resolution.
#[derive(Clone, Debug)]
pub(crate) struct Expr<N = String> {
    pub kind: ExprKind<N>,
    pub loc: Loc,
}

/// The shape of an [`Expr`].
#[derive(Clone, Debug)]
pub(crate) enum ExprKind<N> {
    Num(f64),
    Name(N),
    Neg(Box<Expr<N>>),
    Binary(BinOp, Box<Expr<N>>, Box<Expr<N>>),
    /// An elementary function of one argument: `sin(x)`.
    Func(Func, Box<Expr<N>>),
    /// `atan2(y, x)`.
    Atan2(Box<Expr<N>>, Box<Expr<N>>),
    /// One world coordinate (0: x, 1: y, 2: z) of a point or a direction
    /// fixed in a body, given in the body's frame:
    /// `position_z(hand, 0, 0, 0.1)`, `direction_z(hand, 0, 0, 1)`. The body
    /// is a name of the bodies' own namespace (a URDF names its links and
    /// its joints apart, and a link may share its joint's name): [`Expr::visit`]
    /// does not see it, and [`Expr::try_map`] maps it by its own function.
    Frame(Fixed, usize, N, Box<[Expr<N>; 3]>),
}

/// The namespace a name of an expression is read in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Space {
    /// Coordinates, velocities, parameters, inputs, definitions, `t`, `pi`.
    Value,
    /// The bodies, named only as the first argument of `position_x` and
    /// its kin.
    Body,
}

/// What a body-frame call maps to the world.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Fixed {
    /// A point: rotated and moved with the body (`position_x`).
    Point,
    /// A direction: rotated with the body, not moved (`direction_x`).
    Direction,
}

impl Fixed {
    /// The calls of this kind, by axis.
    pub fn functions(self) -> [&'static str; 3] {
        match self {
            Fixed::Point => ["position_x", "position_y", "position_z"],
            Fixed::Direction => ["direction_x", "direction_y", "direction_z"],
        }
    }

    /// The kind and axis of a call's name, if it is one.
    pub fn of(name: &str) -> Option<(Fixed, usize)> {
        [Fixed::Point, Fixed::Direction]
            .into_iter()
            .find_map(|kind| {
                let axis = kind.functions().iter().position(|f| *f == name)?;
                Some((kind, axis))
            })
    }
}

impl<N> Expr<N> {
    /// Calls `f` on every name this expression uses as a value, in reading
    /// order (not the body of `position_x` and its kin: [`Space::Body`]).
    pub fn visit<'a>(&'a self, f: &mut impl FnMut(&'a N, Loc)) {
        match &self.kind {
            ExprKind::Num(_) => {}
            ExprKind::Name(name) => f(name, self.loc),
            ExprKind::Neg(a) | ExprKind::Func(_, a) => a.visit(f),
            ExprKind::Binary(_, a, b) | ExprKind::Atan2(a, b) => {
                a.visit(f);
                b.visit(f);
            }
            ExprKind::Frame(_, _, _, point) => point.iter().for_each(|c| c.visit(f)),
        }
    }

    /// The same expression with every name mapped by `f`, told the
    /// namespace the name is read in; `None` if `f` gives `None` for any
    /// name (after calling it on every name, so that every failure can be
    /// reported).
    pub fn try_map<M>(&self, f: &mut impl FnMut(&N, Loc, Space) -> Option<M>) -> Option<Expr<M>> {
        let kind = match &self.kind {
            ExprKind::Num(x) => ExprKind::Num(*x),
            ExprKind::Name(name) => ExprKind::Name(f(name, self.loc, Space::Value)?),
            ExprKind::Neg(a) => ExprKind::Neg(Box::new(a.try_map(f)?)),
            ExprKind::Func(func, a) => ExprKind::Func(*func, Box::new(a.try_map(f)?)),
            ExprKind::Binary(op, a, b) => {
                let (a, b) = (a.try_map(f), b.try_map(f));
                ExprKind::Binary(*op, Box::new(a?), Box::new(b?))
            }
            ExprKind::Atan2(a, b) => {
                let (a, b) = (a.try_map(f), b.try_map(f));
                ExprKind::Atan2(Box::new(a?), Box::new(b?))
            }
            ExprKind::Frame(kind, axis, body, point) => {
                let body = f(body, self.loc, Space::Body);
                let [x, y, z] = &**point;
                let (x, y, z) = (x.try_map(f), y.try_map(f), z.try_map(f));
                ExprKind::Frame(*kind, *axis, body?, Box::new([x?, y?, z?]))
            }
        };
        Some(Expr {
            kind,
            loc: self.loc,
        })
    }
}

impl<N> Expr<N> {
    fn precedence(&self) -> u8 {
        match &self.kind {
            ExprKind::Binary(op, ..) => op.precedence(),
            ExprKind::Neg(_) => 3,
            _ => 5,
        }
    }
}

/// Prints the expression back in the model language, with the parentheses
/// it needs and no others.
impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.kind {
            ExprKind::Num(x) => write!(f, "{}", fmt_number(*x)),
            ExprKind::Name(name) => f.write_str(name),
            ExprKind::Neg(a) => {
                f.write_str("-")?;
                write_operand(f, a, a.precedence() < 3)
            }
            ExprKind::Binary(op, a, b) => {
                let p = op.precedence();
                // `^` is right-associative, the others left-associative.
                let (paren_a, paren_b) = if *op == BinOp::Pow {
                    (a.precedence() <= p, b.precedence() < 3)
                } else {
                    (a.precedence() < p, b.precedence() <= p)
                };
                write_operand(f, a, paren_a)?;
                write!(f, " {} ", op.symbol())?;
                write_operand(f, b, paren_b)
            }
            ExprKind::Func(func, a) => write!(f, "{func}({a})"),
            ExprKind::Atan2(y, x) => write!(f, "atan2({y}, {x})"),
            ExprKind::Frame(kind, axis, body, p) => write!(
                f,
                "{}({body}, {}, {}, {})",
                kind.functions()[*axis],
                p[0],
                p[1],
                p[2]
            ),
        }
    }
}

fn write_operand(f: &mut fmt::Formatter<'_>, e: &Expr, paren: bool) -> fmt::Result {
    if paren {
        write!(f, "({e})")
    } else {
        write!(f, "{e}")
    }
}

/// Formats a number so that it reads back to the same `f64`: whole numbers
/// without a fraction (`2`), others in Rust's shortest round-trip form
/// (`0.5`, `1e-10`).
pub(crate) fn fmt_number(x: f64) -> String {
    if x.fract() == 0.0 && x.abs() < 1e15 {
        format!("{}", x as i64)
    } else {
        format!("{x:?}")
    }
}
