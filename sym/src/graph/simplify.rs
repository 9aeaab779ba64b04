//! The simplifying builders of [`Graph`]: one function per operation, each
//! applying the rules of the table in the [module docs](super) before it
//! inserts.

use super::Graph;
use crate::node::{Func, Id, Node, Parity};

impl Graph {
    /// `a + b`, simplified (see the [module docs](super)).
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
        // a + (b - a) → b and (b - a) + a → b (`c + (1 - c)` of a rotation
        // about a coordinate axis is `1`)
        match (self.node(a), self.node(b)) {
            (_, Node::Sub([y, x])) if x == a => return y,
            (Node::Sub([y, x]), _) if x == b => return y,
            _ => {}
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

    /// `a - b`, simplified (see the [module docs](super)).
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
        // (x + y) - x → y, (x + y) - y → x, a - (a - y) → y
        match (self.node(a), self.node(b)) {
            (Node::Add([x, y]), _) if x == b => return y,
            (Node::Add([x, y]), _) if y == b => return x,
            (_, Node::Sub([x, y])) if x == a => return y,
            _ => {}
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

    /// `a * b`, simplified (see the [module docs](super)).
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

    /// `a / b`, simplified (see the [module docs](super)). `0 / x` is folded
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

    /// `-a`, simplified (see the [module docs](super)).
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

    /// `a^n` for an integer `n`, simplified (see the [module docs](super)).
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

    /// `a^b`, simplified (see the [module docs](super)): a constant integer
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

    /// `f(a)`, simplified (see the [module docs](super)).
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
}
