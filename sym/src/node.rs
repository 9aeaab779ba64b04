//! The nodes of the expression graph and the scalar operations they stand for.
//!
//! A [`Node`] is a small `Copy` enum whose operands are [`Id`]s of nodes built
//! before it (egg's `Language`, CasADi's `SXNode`). Constants are stored as the
//! bits of an `f64` so that nodes are `Eq + Hash` and can be hash-consed.
//!
//! [`Op`] is the operation of a non-leaf node without its operands; it is what
//! a [`Schedule`](crate::Schedule) instruction carries, and [`Op::apply`] is
//! the single place where an operation is evaluated on `f64`, shared by
//! [`Graph::eval`](crate::Graph::eval) and
//! [`Schedule::eval`](crate::Schedule::eval) so that the two agree bit for bit.

use core::fmt;

/// The index of a node in a [`Graph`](crate::Graph) arena.
///
/// Ids are handed out by the graph's builders; a node's operands always have
/// smaller ids than the node itself. Two ids of the same graph are equal if
/// and only if they denote structurally equal expressions (hash-consing).
///
/// ```
/// use moreau_sym::{Graph, VarId};
/// let mut g = Graph::new();
/// let x = g.var(VarId(0));
/// let s = g.sin(x);
/// assert!(x < s);
/// assert_eq!(s.index(), 1);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Id(pub(crate) u32);

impl Id {
    /// The position of the node in its graph's arena.
    #[must_use]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

impl fmt::Display for Id {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{}", self.0)
    }
}

/// A symbolic input of an expression: a coordinate, velocity, parameter,
/// input or the time.
///
/// The numbering is the caller's; [`Graph::eval`](crate::Graph::eval) reads
/// variable `VarId(k)` from `vars[k]`. Keep the numbering dense: the graph
/// stores a dependency bit set of `max(k) + 1` bits per node.
///
/// ```
/// use moreau_sym::{Graph, VarId};
/// let mut g = Graph::new();
/// let x = g.var(VarId(3));
/// assert_eq!(g.eval(&[x], &[0.0, 0.0, 0.0, 7.5]), vec![7.5]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct VarId(pub u32);

impl VarId {
    /// The position of the variable in the `vars` slice of the evaluators.
    #[must_use]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

impl fmt::Display for VarId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "x{}", self.0)
    }
}

/// An elementary function of one argument, as named in the model language.
///
/// ```
/// use moreau_sym::Func;
/// assert_eq!(Func::from_name("ln"), Some(Func::Ln));
/// assert_eq!(Func::Ln.name(), "ln");
/// assert_eq!(Func::Exp.apply(0.0), 1.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Func {
    /// `sqrt(x)`, [`f64::sqrt`].
    Sqrt,
    /// `exp(x)`, [`f64::exp`].
    Exp,
    /// `ln(x)`, the natural logarithm, [`f64::ln`].
    Ln,
    /// `sin(x)`, [`f64::sin`].
    Sin,
    /// `cos(x)`, [`f64::cos`].
    Cos,
    /// `tan(x)`, [`f64::tan`].
    Tan,
    /// `sinh(x)`, [`f64::sinh`].
    Sinh,
    /// `cosh(x)`, [`f64::cosh`].
    Cosh,
    /// `tanh(x)`, [`f64::tanh`].
    Tanh,
}

/// Symmetry of a function under `x → -x`, used to pull negations out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Parity {
    /// `f(-x) = -f(x)`.
    Odd,
    /// `f(-x) = f(x)`.
    Even,
    /// Neither.
    None,
}

impl Func {
    /// Every function, in declaration order.
    pub const ALL: [Func; 9] = [
        Func::Sqrt,
        Func::Exp,
        Func::Ln,
        Func::Sin,
        Func::Cos,
        Func::Tan,
        Func::Sinh,
        Func::Cosh,
        Func::Tanh,
    ];

    /// The function's name in the model language, which is also the name of
    /// the `f64` method that evaluates it.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Func::Sqrt => "sqrt",
            Func::Exp => "exp",
            Func::Ln => "ln",
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Sinh => "sinh",
            Func::Cosh => "cosh",
            Func::Tanh => "tanh",
        }
    }

    /// The function called `name` in the model language, if any.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Func> {
        Func::ALL.into_iter().find(|f| f.name() == name)
    }

    /// Evaluates the function with the `f64` method of the same name.
    #[must_use]
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Func::Sqrt => x.sqrt(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.tan(),
            Func::Sinh => x.sinh(),
            Func::Cosh => x.cosh(),
            Func::Tanh => x.tanh(),
        }
    }

    pub(crate) fn parity(self) -> Parity {
        match self {
            Func::Sin | Func::Tan | Func::Sinh | Func::Tanh => Parity::Odd,
            Func::Cos | Func::Cosh => Parity::Even,
            Func::Sqrt | Func::Exp | Func::Ln => Parity::None,
        }
    }
}

impl fmt::Display for Func {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A function of the model language: an elementary [`Func`] of one
/// argument, or `atan2(y, x)`. This is the one list of the language's
/// functions; the macro's parser, its messages and its emitter read it.
///
/// ```
/// use moreau_sym::{Func, Function};
/// assert_eq!(Function::from_name("atan2"), Some(Function::Atan2));
/// assert_eq!(Function::from_name("cos"), Some(Function::Unary(Func::Cos)));
/// assert_eq!(Function::Atan2.arity(), 2);
/// assert_eq!(Function::ALL.len(), 10);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Function {
    /// An elementary function of one argument.
    Unary(Func),
    /// `atan2(y, x)`, [`f64::atan2`].
    Atan2,
}

impl Function {
    /// Every function of the language, in the order messages list them.
    pub const ALL: [Function; 10] = [
        Function::Unary(Func::Sqrt),
        Function::Unary(Func::Exp),
        Function::Unary(Func::Ln),
        Function::Unary(Func::Sin),
        Function::Unary(Func::Cos),
        Function::Unary(Func::Tan),
        Function::Atan2,
        Function::Unary(Func::Sinh),
        Function::Unary(Func::Cosh),
        Function::Unary(Func::Tanh),
    ];

    /// The function's name in the model language (and of the `f64` method
    /// that evaluates it).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Function::Unary(f) => f.name(),
            Function::Atan2 => "atan2",
        }
    }

    /// Number of arguments.
    #[must_use]
    pub fn arity(self) -> usize {
        match self {
            Function::Unary(_) => 1,
            Function::Atan2 => 2,
        }
    }

    /// The function called `name` in the model language, if any.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Function> {
        Function::ALL.into_iter().find(|f| f.name() == name)
    }
}

impl fmt::Display for Function {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One node of the expression graph.
///
/// Subtraction is a node of its own (rather than `a + (-b)`) so that
/// generated code reads `a - b`; the builders turn `a + (-b)` into `a - b`.
/// `Powi` is the power to a constant integer, which compiles to a few
/// multiplications; `Pow` is the general power `a^b`.
///
/// ```
/// use moreau_sym::{Graph, Node, VarId};
/// let mut g = Graph::new();
/// let x = g.var(VarId(0));
/// let y = g.var(VarId(1));
/// let d = g.sub(x, y);
/// assert_eq!(g.node(d), Node::Sub([x, y]));
/// assert_eq!(g.node(d).children(), &[x, y]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Node {
    /// A constant, as the bits of an `f64` ([`f64::to_bits`]). The graph
    /// stores `-0.0` as `0.0` and every NaN as [`f64::NAN`].
    Const(u64),
    /// A variable.
    Var(VarId),
    /// `a + b`.
    Add([Id; 2]),
    /// `a - b`.
    Sub([Id; 2]),
    /// `a * b`.
    Mul([Id; 2]),
    /// `a / b`.
    Div([Id; 2]),
    /// `-a`.
    Neg(Id),
    /// `a^n` for a constant integer `n`, [`f64::powi`].
    Powi(Id, i32),
    /// `a^b`, [`f64::powf`].
    Pow([Id; 2]),
    /// `f(a)` for an elementary function `f`.
    Func(Func, Id),
    /// `atan2(y, x)`, the angle of the point `(x, y)`, [`f64::atan2`].
    Atan2([Id; 2]),
}

impl Node {
    /// The operands of the node, in order (empty for leaves).
    #[must_use]
    pub fn children(&self) -> &[Id] {
        match self {
            Node::Const(_) | Node::Var(_) => &[],
            Node::Add(ab)
            | Node::Sub(ab)
            | Node::Mul(ab)
            | Node::Div(ab)
            | Node::Pow(ab)
            | Node::Atan2(ab) => ab,
            Node::Neg(a) | Node::Powi(a, _) | Node::Func(_, a) => core::slice::from_ref(a),
        }
    }

    /// The same operation on the operands `f` maps each operand to (leaves
    /// unchanged).
    ///
    /// ```
    /// use moreau_sym::{Func, Graph, Node, VarId};
    /// let mut g = Graph::new();
    /// let (x, y) = (g.var(VarId(0)), g.var(VarId(1)));
    /// let s = g.sin(x);
    /// assert_eq!(g.node(s).map_children(|_| y), Node::Func(Func::Sin, y));
    /// assert_eq!(g.node(x).map_children(|_| y), Node::Var(VarId(0)));
    /// ```
    #[must_use]
    pub fn map_children(mut self, mut f: impl FnMut(Id) -> Id) -> Node {
        match &mut self {
            Node::Const(_) | Node::Var(_) => {}
            Node::Add(ab)
            | Node::Sub(ab)
            | Node::Mul(ab)
            | Node::Div(ab)
            | Node::Pow(ab)
            | Node::Atan2(ab) => *ab = [f(ab[0]), f(ab[1])],
            Node::Neg(a) | Node::Powi(a, _) | Node::Func(_, a) => *a = f(*a),
        }
        self
    }

    /// The operation of a non-leaf node, `None` for constants and variables.
    #[must_use]
    pub fn op(&self) -> Option<Op> {
        Some(match *self {
            Node::Const(_) | Node::Var(_) => return None,
            Node::Add(_) => Op::Add,
            Node::Sub(_) => Op::Sub,
            Node::Mul(_) => Op::Mul,
            Node::Div(_) => Op::Div,
            Node::Neg(_) => Op::Neg,
            Node::Powi(_, n) => Op::Powi(n),
            Node::Pow(_) => Op::Pow,
            Node::Func(f, _) => Op::Func(f),
            Node::Atan2(_) => Op::Atan2,
        })
    }

    /// The value of a constant node.
    #[must_use]
    pub fn as_const(&self) -> Option<f64> {
        match *self {
            Node::Const(bits) => Some(f64::from_bits(bits)),
            _ => None,
        }
    }
}

/// The operation of a non-leaf [`Node`], without its operands.
///
/// ```
/// use moreau_sym::{Func, Op};
/// assert_eq!(Op::Sub.apply(5.0, 3.0), 2.0);
/// assert_eq!(Op::Powi(3).apply(2.0, 0.0), 8.0);
/// assert_eq!(Op::Func(Func::Sqrt).arity(), 1);
/// assert_eq!(Op::Atan2.to_string(), "atan2");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Op {
    /// `a + b`.
    Add,
    /// `a - b`.
    Sub,
    /// `a * b`.
    Mul,
    /// `a / b`.
    Div,
    /// `-a`.
    Neg,
    /// `a^n`, [`f64::powi`].
    Powi(i32),
    /// `a^b`, [`f64::powf`].
    Pow,
    /// `f(a)`.
    Func(Func),
    /// `atan2(a, b)`, [`f64::atan2`] with `a` the ordinate.
    Atan2,
}

impl Op {
    /// The number of operands, 1 or 2.
    #[must_use]
    pub fn arity(self) -> usize {
        match self {
            Op::Neg | Op::Powi(_) | Op::Func(_) => 1,
            Op::Add | Op::Sub | Op::Mul | Op::Div | Op::Pow | Op::Atan2 => 2,
        }
    }

    /// Evaluates the operation with Rust's `f64` arithmetic; `b` is ignored by
    /// unary operations. Every evaluator of this crate goes through here.
    #[must_use]
    pub fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Op::Add => a + b,
            Op::Sub => a - b,
            Op::Mul => a * b,
            Op::Div => a / b,
            Op::Neg => -a,
            Op::Powi(n) => a.powi(n),
            Op::Pow => a.powf(b),
            Op::Func(f) => f.apply(a),
            Op::Atan2 => a.atan2(b),
        }
    }

    /// The infix symbol of a binary arithmetic operation (`+ - * /`), if it
    /// has one.
    #[must_use]
    pub fn infix(self) -> Option<&'static str> {
        match self {
            Op::Add => Some("+"),
            Op::Sub => Some("-"),
            Op::Mul => Some("*"),
            Op::Div => Some("/"),
            _ => None,
        }
    }
}

impl fmt::Display for Op {
    /// The operation's symbol (`+`, `-`, `*`, `/`, `neg`) or function name
    /// (`powi`, `pow`, `sin`, ..., `atan2`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Op::Neg => f.write_str("neg"),
            Op::Powi(_) => f.write_str("powi"),
            Op::Pow => f.write_str("pow"),
            Op::Func(func) => f.write_str(func.name()),
            Op::Atan2 => f.write_str("atan2"),
            op => f.write_str(op.infix().unwrap_or("?")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn func_names_round_trip() {
        for f in Func::ALL {
            assert_eq!(Func::from_name(f.name()), Some(f));
            assert_eq!(Op::Func(f).to_string(), f.name());
        }
        assert_eq!(Func::from_name("atan2"), None);
    }

    #[test]
    fn parity_matches_values() {
        for f in Func::ALL {
            let x = 0.37;
            match f.parity() {
                Parity::Odd => assert_eq!(f.apply(-x), -f.apply(x), "{f}"),
                Parity::Even => assert_eq!(f.apply(-x), f.apply(x), "{f}"),
                Parity::None => {}
            }
        }
    }

    #[test]
    fn arity_matches_children() {
        let a = Id(0);
        let b = Id(1);
        let nodes = [
            Node::Add([a, b]),
            Node::Sub([a, b]),
            Node::Mul([a, b]),
            Node::Div([a, b]),
            Node::Neg(a),
            Node::Powi(a, 3),
            Node::Pow([a, b]),
            Node::Func(Func::Sin, a),
            Node::Atan2([a, b]),
        ];
        for n in nodes {
            assert_eq!(n.op().unwrap().arity(), n.children().len(), "{n:?}");
        }
        assert_eq!(Node::Const(0).op(), None);
        assert_eq!(Node::Var(VarId(0)).children(), &[]);
    }
}
