//! The hash-consed expression arena and its simplifying builders.
//!
//! Every expression lives in one [`Graph`]: a `Vec<Node>` whose nodes only
//! refer to nodes before them (egg's `RecExpr`), plus a memo `Node → Id`
//! consulted on insertion (egg's `EGraph::add`), so equal subexpressions are
//! one node by construction and common-subexpression elimination needs no
//! separate pass.
//!
//! The builders ([`Graph::add`], [`Graph::mul`], ...) simplify before they
//! insert, as CasADi's `SXElem::binary` does. Each rule is an identity of real
//! arithmetic that holds for every finite value of its operands (so it never
//! changes a finite result, though it may change the last bits of rounding,
//! e.g. when two constant coefficients are merged). The only rule with a
//! caveat is `0 / x → 0`, which is wrong for `x = 0` (where `0 / 0` is NaN);
//! a model dividing zero by zero is broken anyway. Rules whose value differs
//! on non-finite inputs (`x * 0 → 0` for `x = ∞`, `x - x → 0` for `x = NaN`)
//! are accepted on the same ground as in CasADi, and so are the
//! cancellations `a + (b - a) → b` and their kin (`∞ + (b - ∞)` is NaN).
//!
//! | builder | rules |
//! |---|---|
//! | all | constant folding with Rust's `f64` operations |
//! | [`add`](Graph::add) | `x + 0 → x`, `0 + x → x`, `a + (b - a) → b`, `(b - a) + a → b`, `a + (-b) → a - b`, `(-a) + b → b - a`, `x + x → 2 * x`, `c1 * x + c2 * x → (c1 + c2) * x`, `c * x + c * y → c * (x + y)`, canonical operand order (below) |
//! | [`sub`](Graph::sub) | `x - 0 → x`, `0 - x → -x`, `x - x → 0`, `(x + y) - x → y`, `(x + y) - y → x`, `a - (a - y) → y`, `a - (-b) → a + b`, `(-a) - b → -(a + b)`, `c1 * x - c2 * x → (c1 - c2) * x`, `c * x - c * y → c * (x - y)` |
//! | [`mul`](Graph::mul) | `x * 0 → 0`, `x * 1 → x`, `x * (-1) → -x`, canonical operand order (below), `c1 * (c2 * x) → (c1 c2) * x`, `c1 * (x / c2) → (c1 / c2) * x`, `c * (-x) → (-c) * x`, `(-a) * b → -(a * b)`, `(c * x) * y → c * (x * y)`, `x * x → x^2`, `x^m * x^n → x^(m+n)` for `m, n > 0` |
//! | [`div`](Graph::div) | `x / 1 → x`, `x / (-1) → -x`, `0 / x → 0` (caveat above), `(-a) / b → -(a / b)`, `a / (-b) → -(a / b)`, `(c1 * x) / c2 → (c1 / c2) * x`, `(c * x) / y → c * (x / y)` |
//! | [`neg`](Graph::neg) | `--x → x`, `-(a - b) → b - a`, `-(c * x) → (-c) * x` |
//! | [`powi`](Graph::powi) | `x^0 → 1`, `x^1 → x`, `(x^a)^b → x^(a b)`, `(-x)^n → ±x^n` |
//! | [`pow`](Graph::pow) | `x^c → powi(x, c)` for an integer constant `c`, `x^0.5 → sqrt(x)` |
//! | [`func`](Graph::func) | `f(-x) → -f(x)` for odd `f` (`sin tan sinh tanh`), `f(-x) → f(x)` for even `f` (`cos cosh`) |
//!
//! The operands of `+` and `*` are put in a canonical order, so that `a + b`
//! and `b + a` are one node: a constant first (`2 * x`, `1 + x`), then
//! compound expressions by id, then variables by [`VarId`] (so the chain
//! `(m * l) * g` reads `m * l * g`).
//!
//! Pulling constants and negations outwards makes them meet and fold: the
//! derivative of `0.5 * m * v^2` is `m * v`, and its second derivative is `m`.
//! (`(c * x) * y → c * (x * y)` costs one operation more when `c * x` is also
//! used elsewhere; on the shipped models it saves far more than it costs.)

mod simplify;
mod trig;

pub use trig::{TrigForm, share_waves};

use std::collections::{HashMap, HashSet};
use std::fmt;

use crate::node::{Id, Node, VarId};

/// A hash-consed arena of expression nodes with simplifying builders.
///
/// ```
/// use moreau_sym::{Graph, Node, VarId};
/// let mut g = Graph::new();
/// let x = g.var(VarId(0));
/// let y = g.var(VarId(1));
/// // a + b and b + a are one node
/// let s = g.add(x, y);
/// assert_eq!(g.add(y, x), s);
/// // simplification while building
/// let zero = g.constant(0.0);
/// assert_eq!(g.add(s, zero), s);
/// let d = g.sub(s, s);
/// assert_eq!(g.as_const(d), Some(0.0));
/// // evaluation
/// let p = g.mul(s, y);
/// assert_eq!(g.eval(&[p], &[2.0, 3.0]), vec![15.0]);
/// ```
#[derive(Clone, Debug, Default)]
pub struct Graph {
    /// The arena; children always come before their parents.
    nodes: Vec<Node>,
    /// Hash-consing memo: every node of the arena, to its id.
    memo: HashMap<Node, Id>,
    /// Variable dependencies: `words` bits-words per node, node after node.
    deps: Vec<u64>,
    /// Number of `u64` words of each node's dependency set.
    words: usize,
    /// Derivatives already built, by `(node, variable)`. The arena only
    /// grows, so an entry never goes stale.
    pub(crate) dcache: HashMap<(Id, VarId), Id>,
}

impl Graph {
    /// An empty graph.
    #[must_use]
    pub fn new() -> Graph {
        Graph::default()
    }

    /// The number of nodes in the arena.
    #[must_use]
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the arena is empty.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The node with id `id`.
    ///
    /// # Panics
    /// If `id` does not belong to this graph.
    #[must_use]
    pub fn node(&self, id: Id) -> Node {
        self.nodes[id.index()]
    }

    /// All nodes, in arena order (children before parents).
    #[must_use]
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The value of `id` if it is a constant node.
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let two = g.constant(2.0);
    /// let three = g.constant(3.0);
    /// let six = g.mul(two, three);
    /// assert_eq!(g.as_const(six), Some(6.0));
    /// let x = g.var(VarId(0));
    /// assert_eq!(g.as_const(x), None);
    /// ```
    #[must_use]
    pub fn as_const(&self, id: Id) -> Option<f64> {
        self.node(id).as_const()
    }

    /// Whether `id` is the constant zero.
    #[must_use]
    pub fn is_zero(&self, id: Id) -> bool {
        self.as_const(id) == Some(0.0)
    }

    /// Whether the expression `id` depends on the variable `var`.
    ///
    /// Answered in constant time from a dependency bit set built at insertion.
    /// The answer is structural: `x - x` was already folded to `0`, but
    /// `sin(x)^2 + cos(x)^2` still depends on `x`.
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let y = g.var(VarId(1));
    /// let e = g.sin(x);
    /// assert!(g.depends_on(e, VarId(0)));
    /// assert!(!g.depends_on(e, VarId(1)));
    /// let e = g.add(e, y);
    /// assert!(g.depends_on(e, VarId(1)));
    /// ```
    #[must_use]
    pub fn depends_on(&self, id: Id, var: VarId) -> bool {
        let (word, bit) = (var.index() / 64, var.index() % 64);
        word < self.words && self.deps[id.index() * self.words + word] >> bit & 1 == 1
    }

    /// The variables `id` depends on, in increasing order.
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(4));
    /// let y = g.var(VarId(1));
    /// let e = g.mul(x, y);
    /// assert_eq!(g.free_vars(e), vec![VarId(1), VarId(4)]);
    /// ```
    #[must_use]
    pub fn free_vars(&self, id: Id) -> Vec<VarId> {
        let set = &self.deps[id.index() * self.words..(id.index() + 1) * self.words];
        let mut vars = Vec::new();
        for (w, &bits) in set.iter().enumerate() {
            for b in 0..64 {
                if bits >> b & 1 == 1 {
                    vars.push(VarId((w * 64 + b) as u32));
                }
            }
        }
        vars
    }

    /// Inserts `node` as it is (no simplification), or finds it in the memo.
    fn insert(&mut self, node: Node) -> Id {
        if let Some(&id) = self.memo.get(&node) {
            return id;
        }
        debug_assert!(
            node.children().iter().all(|c| c.index() < self.nodes.len()),
            "children must be built before their parents"
        );
        let id = Id(u32::try_from(self.nodes.len()).expect("more than u32::MAX nodes"));
        if let Node::Var(v) = node {
            self.grow_deps(v.index() / 64 + 1);
        }
        let base = self.deps.len();
        self.deps.resize(base + self.words, 0);
        if let Node::Var(v) = node {
            self.deps[base + v.index() / 64] |= 1 << (v.index() % 64);
        }
        for c in node.children() {
            for w in 0..self.words {
                self.deps[base + w] |= self.deps[c.index() * self.words + w];
            }
        }
        self.nodes.push(node);
        self.memo.insert(node, id);
        id
    }

    /// Widens every dependency set to `words` words.
    fn grow_deps(&mut self, words: usize) {
        if words <= self.words {
            return;
        }
        let mut deps = vec![0; self.nodes.len() * words];
        for i in 0..self.nodes.len() {
            deps[i * words..i * words + self.words]
                .copy_from_slice(&self.deps[i * self.words..(i + 1) * self.words]);
        }
        self.deps = deps;
        self.words = words;
    }

    /// The constant `c`. `-0.0` is stored as `0.0` and every NaN as
    /// [`f64::NAN`], so equal values are one node.
    pub fn constant(&mut self, c: f64) -> Id {
        let c = if c == 0.0 {
            0.0
        } else if c.is_nan() {
            f64::NAN
        } else {
            c
        };
        self.insert(Node::Const(c.to_bits()))
    }

    /// The variable `v`.
    pub fn var(&mut self, v: VarId) -> Id {
        self.insert(Node::Var(v))
    }

    /// Rebuilds `node` through the simplifying builder of its kind: the same
    /// as calling [`add`](Graph::add), [`mul`](Graph::mul), ... on its
    /// operands.
    ///
    /// ```
    /// use moreau_sym::{Graph, Node, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let zero = g.constant(0.0);
    /// assert_eq!(g.build(Node::Add([x, zero])), x);
    /// ```
    pub fn build(&mut self, node: Node) -> Id {
        match node {
            Node::Const(bits) => self.constant(f64::from_bits(bits)),
            Node::Var(v) => self.var(v),
            Node::Add([a, b]) => self.add(a, b),
            Node::Sub([a, b]) => self.sub(a, b),
            Node::Mul([a, b]) => self.mul(a, b),
            Node::Div([a, b]) => self.div(a, b),
            Node::Neg(a) => self.neg(a),
            Node::Powi(a, n) => self.powi(a, n),
            Node::Pow([a, b]) => self.pow(a, b),
            Node::Func(f, a) => self.func(f, a),
            Node::Atan2([y, x]) => self.atan2(y, x),
        }
    }

    /// Both constants, if both are.
    fn consts(&self, a: Id, b: Id) -> Option<(f64, f64)> {
        Some((self.as_const(a)?, self.as_const(b)?))
    }

    /// Canonical operand order of a commutative operation: a constant first,
    /// then compound expressions (by id), then variables (by [`VarId`]). So
    /// `x * 2` is `2 * x`, and the chain `(m * l) * g` prints as `m * l * g`
    /// rather than `g * (m * l)`.
    fn order(&self, a: Id, b: Id) -> (Id, Id) {
        let key = |id: Id| match self.node(id) {
            Node::Const(_) => (0, id.0),
            Node::Var(v) => (2, v.0),
            _ => (1, id.0),
        };
        if key(b) < key(a) { (b, a) } else { (a, b) }
    }

    /// `(c, x)` with `id = c * x` for a constant `c`, else `(1, id)`.
    fn split_coef(&self, id: Id) -> (f64, Id) {
        if let Node::Mul([c, x]) = self.node(id) {
            if let Some(c) = self.as_const(c) {
                return (c, x);
            }
        }
        (1.0, id)
    }

    /// `(x, n)` with `id = x^n`, else `(id, 1)`.
    fn split_powi(&self, id: Id) -> (Id, i32) {
        match self.node(id) {
            Node::Powi(x, n) => (x, n),
            _ => (id, 1),
        }
    }
}

impl Graph {
    /// The nodes reachable from `roots` (roots included), in increasing id
    /// order, which is an evaluation order.
    pub(crate) fn reachable(&self, roots: &[Id]) -> Vec<Id> {
        let mut seen = HashSet::new();
        let mut stack: Vec<Id> = roots.to_vec();
        while let Some(id) = stack.pop() {
            if seen.insert(id) {
                stack.extend_from_slice(self.node(id).children());
            }
        }
        let mut ids: Vec<Id> = seen.into_iter().collect();
        ids.sort_unstable();
        ids
    }

    /// `e` with the variables of `map` replaced by the given expressions,
    /// rebuilt through the simplifying builders.
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let y = g.var(VarId(1));
    /// let e = g.mul(x, y);
    /// let zero = g.constant(0.0);
    /// let e0 = g.subst(e, &[(VarId(1), zero)]);
    /// assert_eq!(g.as_const(e0), Some(0.0));
    /// ```
    pub fn subst(&mut self, e: Id, map: &[(VarId, Id)]) -> Id {
        if map.iter().all(|&(v, _)| !self.depends_on(e, v)) {
            return e;
        }
        let mut new: HashMap<Id, Id> = HashMap::new();
        for id in self.reachable(&[e]) {
            let node = self.node(id);
            let rebuilt = match node {
                Node::Var(v) => map.iter().find(|&&(w, _)| w == v).map_or(id, |&(_, r)| r),
                Node::Const(_) => id,
                _ if map.iter().all(|&(v, _)| !self.depends_on(id, v)) => id,
                _ => {
                    let node = node.map_children(|a| new[&a]);
                    self.build(node)
                }
            };
            new.insert(id, rebuilt);
        }
        new[&e]
    }

    /// `roots` with the nodes of `map` replaced by the given expressions,
    /// everything above them rebuilt through the simplifying builders (a
    /// node none of whose operands changed is kept as it is).
    ///
    /// ```
    /// use std::collections::HashMap;
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let (x, y) = (g.var(VarId(0)), g.var(VarId(1)));
    /// let s = g.sin(x);
    /// let e = g.mul(s, y);
    /// let c = g.cos(x);
    /// let r = g.replace(&[e, y], &HashMap::from([(s, c)]));
    /// assert_eq!(r, vec![g.mul(c, y), y]);
    /// ```
    pub fn replace(&mut self, roots: &[Id], map: &HashMap<Id, Id>) -> Vec<Id> {
        if map.is_empty() {
            return roots.to_vec();
        }
        let mut new: HashMap<Id, Id> = HashMap::new();
        for id in self.reachable(roots) {
            let rebuilt = if let Some(&r) = map.get(&id) {
                r
            } else {
                let node = self.node(id);
                let mapped = node.map_children(|a| new[&a]);
                if mapped == node {
                    id
                } else {
                    self.build(mapped)
                }
            };
            new.insert(id, rebuilt);
        }
        roots.iter().map(|r| new[r]).collect()
    }

    /// Formats `id` as an expression of the model language, with variables
    /// named by `name`. The DAG is printed as a tree, so keep this for small
    /// expressions (messages, tests, debugging).
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let y = g.var(VarId(1));
    /// let s = g.add(x, y);
    /// let two = g.constant(2.0);
    /// let e = g.mul(two, s);
    /// let e = g.powi(e, 2);
    /// let names = |v: VarId| ["x", "y"][v.index()].to_string();
    /// assert_eq!(g.to_infix(e, &names), "(2 * (x + y))^2");
    /// ```
    #[must_use]
    pub fn to_infix(&self, id: Id, name: &dyn Fn(VarId) -> String) -> String {
        let mut out = String::new();
        self.write_infix(&mut out, id, 0, name)
            .expect("writing to a String cannot fail");
        out
    }

    /// Writes `id`, in parentheses when its precedence is below `min`
    /// (1 sums, 2 products, 3 negations, 4 powers, 5 atoms).
    fn write_infix(
        &self,
        out: &mut String,
        id: Id,
        min: u8,
        name: &dyn Fn(VarId) -> String,
    ) -> fmt::Result {
        use fmt::Write;
        let node = self.node(id);
        let prec = match node {
            Node::Const(_) if self.as_const(id).is_some_and(|c| c < 0.0) => 3,
            Node::Const(_) | Node::Var(_) | Node::Func(..) | Node::Atan2(_) => 5,
            Node::Add(_) | Node::Sub(_) => 1,
            Node::Mul(_) | Node::Div(_) => 2,
            Node::Neg(_) => 3,
            Node::Powi(..) | Node::Pow(_) => 4,
        };
        if prec < min {
            out.push('(');
        }
        match node {
            Node::Const(_) => write!(out, "{}", self.as_const(id).unwrap_or(f64::NAN))?,
            Node::Var(v) => out.push_str(&name(v)),
            Node::Add([a, b]) | Node::Sub([a, b]) | Node::Mul([a, b]) | Node::Div([a, b]) => {
                let op = node.op().and_then(|op| op.infix()).unwrap_or("?");
                self.write_infix(out, a, prec, name)?;
                write!(out, " {op} ")?;
                self.write_infix(out, b, prec + 1, name)?;
            }
            Node::Neg(a) => {
                out.push('-');
                self.write_infix(out, a, 3, name)?;
            }
            Node::Powi(a, n) => {
                self.write_infix(out, a, 5, name)?;
                write!(out, "^{n}")?;
            }
            Node::Pow([a, b]) => {
                self.write_infix(out, a, 5, name)?;
                out.push('^');
                self.write_infix(out, b, 3, name)?;
            }
            Node::Func(f, a) => {
                write!(out, "{f}(")?;
                self.write_infix(out, a, 0, name)?;
                out.push(')');
            }
            Node::Atan2([y, x]) => {
                out.push_str("atan2(");
                self.write_infix(out, y, 0, name)?;
                out.push_str(", ");
                self.write_infix(out, x, 0, name)?;
                out.push(')');
            }
        }
        if prec < min {
            out.push(')');
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
