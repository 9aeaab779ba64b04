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
//! are accepted on the same ground as in CasADi.
//!
//! | builder | rules |
//! |---|---|
//! | all | constant folding with Rust's `f64` operations |
//! | [`add`](Graph::add) | `x + 0 → x`, `0 + x → x`, `a + (-b) → a - b`, `(-a) + b → b - a`, `x + x → 2 * x`, `c1 * x + c2 * x → (c1 + c2) * x`, `c * x + c * y → c * (x + y)`, canonical operand order (below) |
//! | [`sub`](Graph::sub) | `x - 0 → x`, `0 - x → -x`, `x - x → 0`, `a - (-b) → a + b`, `(-a) - b → -(a + b)`, `c1 * x - c2 * x → (c1 - c2) * x`, `c * x - c * y → c * (x - y)` |
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

use std::collections::{HashMap, HashSet};
use std::fmt;

use crate::node::{Func, Id, Node, Parity, VarId};

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

    /// `a + b`, simplified (see the [module docs](self)).
    ///
    /// ```
    /// use moreau_sym::{Graph, Node, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let two_x = g.add(x, x);
    /// let two = g.constant(2.0);
    /// assert_eq!(g.node(two_x), Node::Mul([two, x]));
    /// ```
    pub fn add(&mut self, a: Id, b: Id) -> Id {
        if let Some((x, y)) = self.consts(a, b) {
            return self.constant(x + y);
        }
        if self.is_zero(a) {
            return b;
        }
        if self.is_zero(b) {
            return a;
        }
        if let Node::Neg(y) = self.node(b) {
            return self.sub(a, y);
        }
        if let Node::Neg(x) = self.node(a) {
            return self.sub(b, x);
        }
        if self.as_const(a).is_none() && self.as_const(b).is_none() {
            let (c1, x) = self.split_coef(a);
            let (c2, y) = self.split_coef(b);
            if x == y {
                let c = self.constant(c1 + c2);
                return self.mul(c, x);
            }
            if c1 != 1.0 && c1 == c2 {
                let s = self.add(x, y);
                let c = self.constant(c1);
                return self.mul(c, s);
            }
            if c1 != 1.0 && c1 == -c2 {
                let s = self.sub(x, y);
                let c = self.constant(c1);
                return self.mul(c, s);
            }
        }
        let (a, b) = self.order(a, b);
        self.insert(Node::Add([a, b]))
    }

    /// `a - b`, simplified (see the [module docs](self)).
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let zero = g.constant(0.0);
    /// let minus_x = g.sub(zero, x);
    /// assert_eq!(minus_x, g.neg(x));
    /// ```
    pub fn sub(&mut self, a: Id, b: Id) -> Id {
        if let Some((x, y)) = self.consts(a, b) {
            return self.constant(x - y);
        }
        if self.is_zero(b) {
            return a;
        }
        if self.is_zero(a) {
            return self.neg(b);
        }
        if a == b {
            return self.constant(0.0);
        }
        if let Node::Neg(y) = self.node(b) {
            return self.add(a, y);
        }
        if let Node::Neg(x) = self.node(a) {
            let s = self.add(x, b);
            return self.neg(s);
        }
        if self.as_const(a).is_none() && self.as_const(b).is_none() {
            let (c1, x) = self.split_coef(a);
            let (c2, y) = self.split_coef(b);
            if x == y {
                let c = self.constant(c1 - c2);
                return self.mul(c, x);
            }
            if c1 != 1.0 && c1 == c2 {
                let s = self.sub(x, y);
                let c = self.constant(c1);
                return self.mul(c, s);
            }
            if c1 != 1.0 && c1 == -c2 {
                let s = self.add(x, y);
                let c = self.constant(c1);
                return self.mul(c, s);
            }
        }
        self.insert(Node::Sub([a, b]))
    }

    /// `a * b`, simplified (see the [module docs](self)).
    ///
    /// ```
    /// use moreau_sym::{Graph, Node, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let half = g.constant(0.5);
    /// let two = g.constant(2.0);
    /// let hx = g.mul(x, half); // constants move left: 0.5 * x
    /// assert_eq!(g.node(hx), Node::Mul([half, x]));
    /// assert_eq!(g.mul(two, hx), x); // 2 * (0.5 * x) = x
    /// ```
    pub fn mul(&mut self, a: Id, b: Id) -> Id {
        if let Some((x, y)) = self.consts(a, b) {
            return self.constant(x * y);
        }
        let (a, b) = self.order(a, b);
        if let Some(c) = self.as_const(a) {
            if c == 0.0 {
                return a;
            }
            if c == 1.0 {
                return b;
            }
            if c == -1.0 {
                return self.neg(b);
            }
            let (k, y) = match self.node(b) {
                Node::Mul([k, y]) => (self.as_const(k).map(|k| c * k), y),
                Node::Div([y, k]) => (self.as_const(k).map(|k| c / k), y),
                Node::Neg(y) => (Some(-c), y),
                _ => (None, b),
            };
            if let Some(k) = k {
                let k = self.constant(k);
                return self.mul(k, y);
            }
            return self.insert(Node::Mul([a, b]));
        }
        if let Node::Neg(x) = self.node(a) {
            let p = self.mul(x, b);
            return self.neg(p);
        }
        if let Node::Neg(y) = self.node(b) {
            let p = self.mul(a, y);
            return self.neg(p);
        }
        for (s, t) in [(a, b), (b, a)] {
            let (c, x) = self.split_coef(s);
            if c != 1.0 {
                let p = self.mul(x, t);
                let c = self.constant(c);
                return self.mul(c, p);
            }
        }
        let (x, m) = self.split_powi(a);
        let (y, n) = self.split_powi(b);
        if x == y && m > 0 && n > 0 {
            if let Some(k) = m.checked_add(n) {
                return self.powi(x, k);
            }
        }
        self.insert(Node::Mul([a, b]))
    }

    /// `a / b`, simplified (see the [module docs](self)). `0 / x` is folded
    /// to `0`, which is wrong for `x = 0`.
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let one = g.constant(1.0);
    /// assert_eq!(g.div(x, one), x);
    /// ```
    pub fn div(&mut self, a: Id, b: Id) -> Id {
        if let Some((x, y)) = self.consts(a, b) {
            return self.constant(x / y);
        }
        match self.as_const(b) {
            Some(1.0) => return a,
            Some(-1.0) => return self.neg(a),
            _ => {}
        }
        if self.is_zero(a) {
            return a;
        }
        if let Node::Neg(x) = self.node(a) {
            let q = self.div(x, b);
            return self.neg(q);
        }
        if let Node::Neg(y) = self.node(b) {
            let q = self.div(a, y);
            return self.neg(q);
        }
        let (c, x) = self.split_coef(a);
        if c != 1.0 {
            if let Some(d) = self.as_const(b) {
                let c = self.constant(c / d);
                return self.mul(c, x);
            }
            let q = self.div(x, b);
            let c = self.constant(c);
            return self.mul(c, q);
        }
        self.insert(Node::Div([a, b]))
    }

    /// `-a`, simplified (see the [module docs](self)).
    ///
    /// ```
    /// use moreau_sym::{Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let y = g.var(VarId(1));
    /// let n = g.neg(x);
    /// assert_eq!(g.neg(n), x);
    /// let d = g.sub(x, y);
    /// assert_eq!(g.neg(d), g.sub(y, x));
    /// ```
    pub fn neg(&mut self, a: Id) -> Id {
        if let Some(x) = self.as_const(a) {
            return self.constant(-x);
        }
        match self.node(a) {
            Node::Neg(x) => return x,
            Node::Sub([x, y]) => return self.sub(y, x),
            _ => {}
        }
        let (c, x) = self.split_coef(a);
        if c != 1.0 {
            let c = self.constant(-c);
            return self.mul(c, x);
        }
        self.insert(Node::Neg(a))
    }

    /// `a^n` for an integer `n`, simplified (see the [module docs](self)).
    ///
    /// ```
    /// use moreau_sym::{Graph, Node, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let x2 = g.powi(x, 2);
    /// let x6 = g.powi(x2, 3);
    /// assert_eq!(g.node(x6), Node::Powi(x, 6));
    /// assert_eq!(g.powi(x, 1), x);
    /// ```
    pub fn powi(&mut self, a: Id, n: i32) -> Id {
        if let Some(x) = self.as_const(a) {
            return self.constant(x.powi(n));
        }
        match n {
            0 => return self.constant(1.0),
            1 => return a,
            _ => {}
        }
        match self.node(a) {
            Node::Powi(x, m) if m.checked_mul(n).is_some() => self.powi(x, m * n),
            Node::Neg(x) => {
                let p = self.powi(x, n);
                if n % 2 == 0 { p } else { self.neg(p) }
            }
            _ => self.insert(Node::Powi(a, n)),
        }
    }

    /// `a^b`, simplified (see the [module docs](self)): a constant integer
    /// exponent gives [`powi`](Graph::powi), `0.5` gives `sqrt`.
    ///
    /// ```
    /// use moreau_sym::{Graph, Node, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let three = g.constant(3.0);
    /// let p = g.pow(x, three);
    /// assert_eq!(g.node(p), Node::Powi(x, 3));
    /// ```
    pub fn pow(&mut self, a: Id, b: Id) -> Id {
        if let Some((x, y)) = self.consts(a, b) {
            return self.constant(x.powf(y));
        }
        if let Some(e) = self.as_const(b) {
            if e.fract() == 0.0 && e >= f64::from(i32::MIN) && e <= f64::from(i32::MAX) {
                return self.powi(a, e as i32);
            }
            if e == 0.5 {
                return self.func(Func::Sqrt, a);
            }
        }
        self.insert(Node::Pow([a, b]))
    }

    /// `f(a)`, simplified (see the [module docs](self)).
    ///
    /// ```
    /// use moreau_sym::{Func, Graph, VarId};
    /// let mut g = Graph::new();
    /// let x = g.var(VarId(0));
    /// let m = g.neg(x);
    /// let c = g.func(Func::Cos, m);
    /// assert_eq!(c, g.func(Func::Cos, x)); // cos is even
    /// ```
    pub fn func(&mut self, f: Func, a: Id) -> Id {
        if let Some(x) = self.as_const(a) {
            return self.constant(f.apply(x));
        }
        if let Node::Neg(x) = self.node(a) {
            match f.parity() {
                Parity::Odd => {
                    let y = self.func(f, x);
                    return self.neg(y);
                }
                Parity::Even => return self.func(f, x),
                Parity::None => {}
            }
        }
        self.insert(Node::Func(f, a))
    }

    /// `atan2(y, x)`, the angle of the point `(x, y)`; constants fold.
    ///
    /// ```
    /// use moreau_sym::Graph;
    /// let mut g = Graph::new();
    /// let one = g.constant(1.0);
    /// let a = g.atan2(one, one);
    /// assert_eq!(g.as_const(a), Some(std::f64::consts::FRAC_PI_4));
    /// ```
    pub fn atan2(&mut self, y: Id, x: Id) -> Id {
        if let Some((y, x)) = self.consts(y, x) {
            return self.constant(y.atan2(x));
        }
        self.insert(Node::Atan2([y, x]))
    }

    /// `sqrt(a)`, shorthand for [`func`](Graph::func).
    pub fn sqrt(&mut self, a: Id) -> Id {
        self.func(Func::Sqrt, a)
    }

    /// `exp(a)`, shorthand for [`func`](Graph::func).
    pub fn exp(&mut self, a: Id) -> Id {
        self.func(Func::Exp, a)
    }

    /// `ln(a)`, shorthand for [`func`](Graph::func).
    pub fn ln(&mut self, a: Id) -> Id {
        self.func(Func::Ln, a)
    }

    /// `sin(a)`, shorthand for [`func`](Graph::func).
    pub fn sin(&mut self, a: Id) -> Id {
        self.func(Func::Sin, a)
    }

    /// `cos(a)`, shorthand for [`func`](Graph::func).
    pub fn cos(&mut self, a: Id) -> Id {
        self.func(Func::Cos, a)
    }

    /// `tan(a)`, shorthand for [`func`](Graph::func).
    pub fn tan(&mut self, a: Id) -> Id {
        self.func(Func::Tan, a)
    }

    /// `sinh(a)`, shorthand for [`func`](Graph::func).
    pub fn sinh(&mut self, a: Id) -> Id {
        self.func(Func::Sinh, a)
    }

    /// `cosh(a)`, shorthand for [`func`](Graph::func).
    pub fn cosh(&mut self, a: Id) -> Id {
        self.func(Func::Cosh, a)
    }

    /// `tanh(a)`, shorthand for [`func`](Graph::func).
    pub fn tanh(&mut self, a: Id) -> Id {
        self.func(Func::Tanh, a)
    }

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
                    let mut node = node;
                    match &mut node {
                        Node::Add(ab)
                        | Node::Sub(ab)
                        | Node::Mul(ab)
                        | Node::Div(ab)
                        | Node::Pow(ab)
                        | Node::Atan2(ab) => {
                            ab[0] = new[&ab[0]];
                            ab[1] = new[&ab[1]];
                        }
                        Node::Neg(a) | Node::Powi(a, _) | Node::Func(_, a) => *a = new[a],
                        Node::Const(_) | Node::Var(_) => unreachable!(),
                    }
                    self.build(node)
                }
            };
            new.insert(id, rebuilt);
        }
        new[&e]
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
mod tests {
    use super::*;

    fn names(v: VarId) -> String {
        ["x", "y", "z", "w"][v.index()].to_string()
    }

    /// A graph with variables x, y, z.
    fn xyz() -> (Graph, Id, Id, Id) {
        let mut g = Graph::new();
        let x = g.var(VarId(0));
        let y = g.var(VarId(1));
        let z = g.var(VarId(2));
        (g, x, y, z)
    }

    fn show(g: &Graph, id: Id) -> String {
        g.to_infix(id, &names)
    }

    #[test]
    fn hash_consing_shares_equal_nodes() {
        let (mut g, x, y, _) = xyz();
        let a = g.add(x, y);
        let b = g.add(y, x);
        assert_eq!(a, b);
        let n = g.len();
        let s1 = g.sin(a);
        let s2 = g.sin(b);
        assert_eq!(s1, s2);
        assert_eq!(g.len(), n + 1);
        assert_eq!(g.mul(x, y), g.mul(y, x));
        assert_eq!(g.var(VarId(0)), x);
        let c1 = g.constant(1.5);
        assert_eq!(g.constant(1.5), c1);
    }

    #[test]
    fn constants_canonical_zero_and_nan() {
        let mut g = Graph::new();
        let z = g.constant(0.0);
        assert_eq!(g.constant(-0.0), z);
        let n = g.constant(f64::NAN);
        assert_eq!(g.constant(-f64::NAN), n);
    }

    #[test]
    fn constant_folding_uses_f64_ops() {
        let mut g = Graph::new();
        let a = g.constant(0.1);
        let b = g.constant(0.2);
        let checks = [
            (g.add(a, b), 0.1 + 0.2),
            (g.sub(a, b), 0.1 - 0.2),
            (g.mul(a, b), 0.1 * 0.2),
            (g.div(a, b), 0.1 / 0.2),
            (g.neg(a), -0.1),
            (g.powi(a, 3), 0.1f64.powi(3)),
            (g.pow(a, b), 0.1f64.powf(0.2)),
            (g.sin(a), 0.1f64.sin()),
            (g.atan2(a, b), 0.1f64.atan2(0.2)),
        ];
        for (id, want) in checks {
            assert_eq!(g.as_const(id).map(f64::to_bits), Some(want.to_bits()));
        }
    }

    #[test]
    fn add_zero_either_side() {
        let (mut g, x, _, _) = xyz();
        let zero = g.constant(0.0);
        assert_eq!(g.add(x, zero), x);
        assert_eq!(g.add(zero, x), x);
    }

    #[test]
    fn add_negation_becomes_sub() {
        let (mut g, x, y, _) = xyz();
        let ny = g.neg(y);
        let s = g.add(x, ny);
        assert_eq!(g.node(s), Node::Sub([x, y]));
        let nx = g.neg(x);
        let s = g.add(nx, y);
        assert_eq!(g.node(s), Node::Sub([y, x]));
    }

    #[test]
    fn add_like_terms() {
        let (mut g, x, y, _) = xyz();
        let xx = g.add(x, x);
        assert_eq!(show(&g, xx), "2 * x");
        let three = g.constant(3.0);
        let four = g.constant(4.0);
        let a = g.mul(three, x);
        let b = g.mul(x, four);
        let s = g.add(a, b);
        assert_eq!(show(&g, s), "7 * x");
        let s = g.add(a, x);
        assert_eq!(show(&g, s), "4 * x");
        let p = g.mul(x, y);
        let a = g.mul(three, p);
        let b = g.mul(three, y);
        let s = g.add(a, b);
        assert_eq!(show(&g, s), "3 * (x * y + y)");
        let m3 = g.constant(-3.0);
        let b = g.mul(m3, y);
        let s = g.add(a, b);
        assert_eq!(show(&g, s), "3 * (x * y - y)");
    }

    #[test]
    fn add_constants_left_and_commutes() {
        let (mut g, x, y, _) = xyz();
        let one = g.constant(1.0);
        let s = g.add(x, one);
        assert_eq!(g.node(s), Node::Add([one, x]));
        let a = g.add(y, x);
        assert_eq!(g.node(a), Node::Add([x, y]));
    }

    #[test]
    fn sub_zero_and_self() {
        let (mut g, x, _, _) = xyz();
        let zero = g.constant(0.0);
        assert_eq!(g.sub(x, zero), x);
        let m = g.sub(zero, x);
        assert_eq!(g.node(m), Node::Neg(x));
        assert_eq!(g.sub(x, x), zero);
    }

    #[test]
    fn sub_negations() {
        let (mut g, x, y, _) = xyz();
        let ny = g.neg(y);
        let s = g.sub(x, ny);
        assert_eq!(g.node(s), Node::Add([x, y]));
        let nx = g.neg(x);
        let s = g.sub(nx, y);
        assert_eq!(show(&g, s), "-(x + y)");
    }

    #[test]
    fn sub_like_terms() {
        let (mut g, x, y, _) = xyz();
        let three = g.constant(3.0);
        let a = g.mul(three, x);
        let s = g.sub(a, x);
        assert_eq!(show(&g, s), "2 * x");
        let s = g.sub(x, a);
        assert_eq!(show(&g, s), "-2 * x");
        let s = g.sub(a, a);
        assert_eq!(g.as_const(s), Some(0.0));
        let b = g.mul(three, y);
        let s = g.sub(a, b);
        assert_eq!(show(&g, s), "3 * (x - y)");
    }

    #[test]
    fn mul_zero_one_minus_one() {
        let (mut g, x, _, _) = xyz();
        let zero = g.constant(0.0);
        let one = g.constant(1.0);
        let m1 = g.constant(-1.0);
        assert_eq!(g.mul(x, zero), zero);
        assert_eq!(g.mul(zero, x), zero);
        assert_eq!(g.mul(x, one), x);
        assert_eq!(g.mul(one, x), x);
        let n = g.mul(x, m1);
        assert_eq!(g.node(n), Node::Neg(x));
    }

    #[test]
    fn mul_constants_left_and_merge() {
        let (mut g, x, y, _) = xyz();
        let two = g.constant(2.0);
        let three = g.constant(3.0);
        let a = g.mul(x, two);
        assert_eq!(g.node(a), Node::Mul([two, x]));
        let b = g.mul(a, three);
        assert_eq!(show(&g, b), "6 * x");
        let q = g.div(x, two);
        let b = g.mul(three, q);
        assert_eq!(show(&g, b), "1.5 * x");
        let p = g.mul(a, y);
        assert_eq!(show(&g, p), "2 * (x * y)");
        let b3 = g.mul(three, y);
        let p = g.mul(a, b3);
        assert_eq!(show(&g, p), "6 * (x * y)");
    }

    #[test]
    fn mul_negations_move_out() {
        let (mut g, x, y, _) = xyz();
        let nx = g.neg(x);
        let two = g.constant(2.0);
        let p = g.mul(two, nx);
        assert_eq!(show(&g, p), "-2 * x");
        let p = g.mul(nx, y);
        assert_eq!(show(&g, p), "-(x * y)");
        let ny = g.neg(y);
        let p = g.mul(nx, ny);
        assert_eq!(g.node(p), Node::Mul([x, y]));
    }

    #[test]
    fn mul_square_and_powers() {
        let (mut g, x, _, _) = xyz();
        let sq = g.mul(x, x);
        assert_eq!(g.node(sq), Node::Powi(x, 2));
        let cube = g.mul(sq, x);
        assert_eq!(g.node(cube), Node::Powi(x, 3));
        let p = g.mul(sq, cube);
        assert_eq!(g.node(p), Node::Powi(x, 5));
        // negative exponents are left alone (x^-1 * x is not x at 0)
        let inv = g.powi(x, -1);
        let p = g.mul(inv, x);
        assert!(matches!(g.node(p), Node::Mul(_)));
    }

    #[test]
    fn div_one_minus_one_zero() {
        let (mut g, x, _, _) = xyz();
        let one = g.constant(1.0);
        let m1 = g.constant(-1.0);
        let zero = g.constant(0.0);
        assert_eq!(g.div(x, one), x);
        let n = g.div(x, m1);
        assert_eq!(g.node(n), Node::Neg(x));
        assert_eq!(g.div(zero, x), zero);
    }

    #[test]
    fn div_negations_and_coefficients() {
        let (mut g, x, y, _) = xyz();
        let nx = g.neg(x);
        let q = g.div(nx, y);
        assert_eq!(show(&g, q), "-(x / y)");
        let ny = g.neg(y);
        let q = g.div(x, ny);
        assert_eq!(show(&g, q), "-(x / y)");
        let three = g.constant(3.0);
        let two = g.constant(2.0);
        let a = g.mul(three, x);
        let q = g.div(a, two);
        assert_eq!(show(&g, q), "1.5 * x");
        let q = g.div(a, y);
        assert_eq!(show(&g, q), "3 * (x / y)");
        let q = g.div(x, two);
        assert_eq!(show(&g, q), "x / 2");
    }

    #[test]
    fn neg_rules() {
        let (mut g, x, y, _) = xyz();
        let n = g.neg(x);
        assert_eq!(g.neg(n), x);
        let d = g.sub(x, y);
        let n = g.neg(d);
        assert_eq!(g.node(n), Node::Sub([y, x]));
        let two = g.constant(2.0);
        let p = g.mul(two, x);
        let n = g.neg(p);
        assert_eq!(show(&g, n), "-2 * x");
        let c = g.constant(2.5);
        let n = g.neg(c);
        assert_eq!(g.as_const(n), Some(-2.5));
    }

    #[test]
    fn powi_zero_one_nested_negated() {
        let (mut g, x, _, _) = xyz();
        let p = g.powi(x, 0);
        assert_eq!(g.as_const(p), Some(1.0));
        assert_eq!(g.powi(x, 1), x);
        let p2 = g.powi(x, 2);
        let p = g.powi(p2, -3);
        assert_eq!(g.node(p), Node::Powi(x, -6));
        let nx = g.neg(x);
        let p = g.powi(nx, 2);
        assert_eq!(p, p2);
        let p = g.powi(nx, 3);
        assert_eq!(show(&g, p), "-x^3");
        // overflowing exponent products are kept nested
        let big = g.powi(x, 1 << 20);
        let p = g.powi(big, 1 << 20);
        assert_eq!(g.node(p), Node::Powi(big, 1 << 20));
    }

    #[test]
    fn pow_constant_exponents() {
        let (mut g, x, y, _) = xyz();
        let two = g.constant(2.0);
        let p = g.pow(x, two);
        assert_eq!(g.node(p), Node::Powi(x, 2));
        let m = g.constant(-1.0);
        let p = g.pow(x, m);
        assert_eq!(g.node(p), Node::Powi(x, -1));
        let half = g.constant(0.5);
        let p = g.pow(x, half);
        assert_eq!(g.node(p), Node::Func(Func::Sqrt, x));
        let e = g.constant(1.5);
        let p = g.pow(x, e);
        assert_eq!(g.node(p), Node::Pow([x, e]));
        let p = g.pow(x, y);
        assert_eq!(g.node(p), Node::Pow([x, y]));
        let zero = g.constant(0.0);
        let p = g.pow(x, zero);
        assert_eq!(g.as_const(p), Some(1.0));
    }

    #[test]
    fn func_parity() {
        let (mut g, x, _, _) = xyz();
        let nx = g.neg(x);
        for f in Func::ALL {
            let fx = g.func(f, x);
            let fnx = g.func(f, nx);
            match f.parity() {
                Parity::Odd => assert_eq!(g.node(fnx), Node::Neg(fx), "{f}"),
                Parity::Even => assert_eq!(fnx, fx, "{f}"),
                Parity::None => assert_eq!(g.node(fnx), Node::Func(f, nx), "{f}"),
            }
        }
        let c = g.constant(0.0);
        let e = g.exp(c);
        assert_eq!(g.as_const(e), Some(1.0));
    }

    #[test]
    fn depends_on_wide_variable_sets() {
        let mut g = Graph::new();
        let x = g.var(VarId(1));
        let s = g.sin(x);
        // a variable past the first word widens every set
        let y = g.var(VarId(130));
        let e = g.mul(s, y);
        assert!(g.depends_on(s, VarId(1)));
        assert!(!g.depends_on(s, VarId(130)));
        assert!(g.depends_on(e, VarId(130)));
        assert!(g.depends_on(e, VarId(1)));
        assert!(!g.depends_on(e, VarId(500)));
        assert_eq!(g.free_vars(e), vec![VarId(1), VarId(130)]);
        let c = g.constant(2.0);
        assert!(g.free_vars(c).is_empty());
    }

    #[test]
    fn depends_on_ten_thousand_nodes() {
        let mut g = Graph::new();
        let mut e = g.var(VarId(0));
        for k in 0..10_000 {
            let v = g.var(VarId(1 + k % 40));
            let s = g.sin(e);
            e = g.add(s, v);
        }
        assert!(g.len() > 20_000);
        for v in 0..41 {
            assert!(g.depends_on(e, VarId(v)));
        }
        assert!(!g.depends_on(e, VarId(41)));
    }

    #[test]
    fn subst_rebuilds_with_simplification() {
        let (mut g, x, y, z) = xyz();
        let s = g.sin(x);
        let p = g.mul(s, y);
        let e = g.add(p, z);
        let zero = g.constant(0.0);
        let e0 = g.subst(e, &[(VarId(1), zero)]);
        assert_eq!(e0, z);
        let e1 = g.subst(e, &[(VarId(2), x)]);
        assert_eq!(show(&g, e1), "sin(x) * y + x");
        assert_eq!(g.subst(e, &[(VarId(3), zero)]), e);
    }

    #[test]
    fn to_infix_parenthesizes_by_precedence() {
        let (mut g, x, y, z) = xyz();
        let s = g.sub(y, z);
        let d = g.sub(x, s);
        assert_eq!(show(&g, d), "x - (y - z)");
        let q = g.div(y, z);
        let q = g.div(x, q);
        assert_eq!(show(&g, q), "x / (y / z)");
        let n = g.neg(x);
        let p = g.pow(n, y);
        assert_eq!(show(&g, p), "(-x)^y");
        let a = g.atan2(x, y);
        let e = g.exp(a);
        assert_eq!(show(&g, e), "exp(atan2(x, y))");
    }
}
