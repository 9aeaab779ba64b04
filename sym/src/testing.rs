//! Test helpers: a tiny deterministic pseudo-random generator.

/// SplitMix64, enough for drawing test points reproducibly without a
/// dependency.
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[lo, hi)`.
    pub(crate) fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
}

use crate::graph::Graph;
use crate::node::{Func, Id, VarId};

/// Parses an expression of the model language (see `models/README.md`) into
/// `g`, variable `names[k]` being `VarId(k)` and `defs` the definitions.
/// Test-only: the real front ends live in the macro crate.
pub(crate) fn parse(g: &mut Graph, names: &[&str], defs: &[(&str, Id)], src: &str) -> Id {
    let mut toks = Vec::new();
    let cs: Vec<char> = src.chars().collect();
    let mut i = 0;
    while i < cs.len() {
        let c = cs[i];
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || c == '.' {
            let s = i;
            while i < cs.len()
                && (cs[i].is_ascii_digit()
                    || cs[i] == '.'
                    || cs[i] == 'e'
                    || (cs[i] == '-' && cs[i - 1] == 'e'))
            {
                i += 1;
            }
            let text: String = cs[s..i].iter().collect();
            toks.push(Tok::Num(text.parse().expect("number")));
        } else if c.is_alphabetic() || c == '_' {
            let s = i;
            while i < cs.len() && (cs[i].is_alphanumeric() || cs[i] == '_') {
                i += 1;
            }
            toks.push(Tok::Name(cs[s..i].iter().collect()));
        } else {
            toks.push(Tok::Sym(c));
            i += 1;
        }
    }
    let mut p = Parser {
        g,
        names,
        defs,
        toks,
        pos: 0,
    };
    let e = p.expr();
    assert_eq!(p.pos, p.toks.len(), "trailing input in {src}");
    e
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Name(String),
    Sym(char),
}

struct Parser<'a> {
    g: &'a mut Graph,
    names: &'a [&'a str],
    defs: &'a [(&'a str, Id)],
    toks: Vec<Tok>,
    pos: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos)
    }

    fn eat(&mut self, c: char) -> bool {
        if self.peek() == Some(&Tok::Sym(c)) {
            self.pos += 1;
            true
        } else {
            false
        }
    }

    fn expr(&mut self) -> Id {
        let mut e = self.term();
        loop {
            if self.eat('+') {
                let t = self.term();
                e = self.g.add(e, t);
            } else if self.eat('-') {
                let t = self.term();
                e = self.g.sub(e, t);
            } else {
                return e;
            }
        }
    }

    fn term(&mut self) -> Id {
        let mut e = self.unary();
        loop {
            if self.eat('*') {
                let t = self.unary();
                e = self.g.mul(e, t);
            } else if self.eat('/') {
                let t = self.unary();
                e = self.g.div(e, t);
            } else {
                return e;
            }
        }
    }

    fn unary(&mut self) -> Id {
        if self.eat('-') {
            let u = self.unary();
            self.g.neg(u)
        } else {
            self.power()
        }
    }

    fn power(&mut self) -> Id {
        let a = self.atom();
        if self.eat('^') {
            let b = self.unary();
            self.g.pow(a, b)
        } else {
            a
        }
    }

    fn atom(&mut self) -> Id {
        let tok = self.toks[self.pos].clone();
        self.pos += 1;
        match tok {
            Tok::Num(x) => self.g.constant(x),
            Tok::Sym('(') => {
                let e = self.expr();
                assert!(self.eat(')'), "expected )");
                e
            }
            Tok::Name(name) if self.eat('(') => {
                let a = self.expr();
                let e = if name == "atan2" {
                    assert!(self.eat(','), "atan2 takes two arguments");
                    let b = self.expr();
                    self.g.atan2(a, b)
                } else {
                    let f = Func::from_name(&name).expect("known function");
                    self.g.func(f, a)
                };
                assert!(self.eat(')'), "expected )");
                e
            }
            Tok::Name(name) if name == "pi" => self.g.constant(std::f64::consts::PI),
            Tok::Name(name) if self.defs.iter().any(|(n, _)| *n == name) => self
                .defs
                .iter()
                .find(|(n, _)| *n == name)
                .map(|d| d.1)
                .unwrap_or_else(|| unreachable!()),
            Tok::Name(name) => {
                let k = self.names.iter().position(|n| *n == name);
                let k = k.unwrap_or_else(|| panic!("unknown name {name}"));
                self.g.var(VarId(k as u32))
            }
            Tok::Sym(c) => panic!("unexpected {c}"),
        }
    }
}

/// A model written as in a YAML file, for tests.
pub(crate) struct Spec {
    /// `(position, velocity)` names.
    pub coords: &'static [(&'static str, &'static str)],
    /// Parameters and inputs, in order.
    pub params: &'static [&'static str],
    /// Definitions, in order.
    pub defs: &'static [(&'static str, &'static str)],
    pub kinetic: &'static str,
    pub potential: &'static str,
    /// Applied generalized forces by coordinate name (missing = 0).
    pub applied: &'static [(&'static str, &'static str)],
    pub gaps: &'static [&'static str],
}

/// A [`Spec`] built into a graph: variables are the positions, then the
/// velocities, then the parameters.
pub(crate) struct Built {
    pub g: Graph,
    pub names: Vec<&'static str>,
    pub q: Vec<VarId>,
    pub v: Vec<VarId>,
    pub kinetic: Id,
    pub potential: Id,
    pub applied: Vec<Id>,
    pub gaps: Vec<Id>,
}

impl Built {
    /// Derives the mechanics of the model in its graph.
    pub(crate) fn derive(
        &mut self,
    ) -> Result<crate::mechanics::Mechanics, crate::mechanics::MechanicsError> {
        let sys = crate::mechanics::Lagrangian {
            q: &self.q,
            v: &self.v,
            kinetic: self.kinetic,
            potential: self.potential,
            applied: &self.applied,
            gaps: &self.gaps,
        };
        crate::mechanics::Mechanics::derive(&mut self.g, &sys)
    }

    pub(crate) fn name(&self, v: VarId) -> String {
        self.names[v.index()].to_string()
    }
}

impl Spec {
    pub(crate) fn build(&self) -> Built {
        let mut g = Graph::new();
        let n = self.coords.len();
        let mut names: Vec<&'static str> = self.coords.iter().map(|c| c.0).collect();
        names.extend(self.coords.iter().map(|c| c.1));
        names.extend(self.params.iter().copied());
        let q: Vec<VarId> = (0..n as u32).map(VarId).collect();
        let v: Vec<VarId> = (n as u32..2 * n as u32).map(VarId).collect();
        let mut defs: Vec<(&str, Id)> = Vec::new();
        for (name, src) in self.defs {
            let e = parse(&mut g, &names, &defs, src);
            defs.push((name, e));
        }
        let kinetic = parse(&mut g, &names, &defs, self.kinetic);
        let potential = parse(&mut g, &names, &defs, self.potential);
        let applied = self
            .coords
            .iter()
            .map(|(c, _)| match self.applied.iter().find(|f| f.0 == *c) {
                Some((_, src)) => parse(&mut g, &names, &defs, src),
                None => g.constant(0.0),
            })
            .collect();
        let gaps = self
            .gaps
            .iter()
            .map(|src| parse(&mut g, &names, &defs, src))
            .collect();
        Built {
            g,
            names,
            q,
            v,
            kinetic,
            potential,
            applied,
            gaps,
        }
    }
}

/// `models/double_pendulum.yaml`.
pub(crate) const DOUBLE_PENDULUM: Spec = Spec {
    coords: &[("th1", "w1"), ("th2", "w2")],
    params: &["m1", "m2", "l1", "l2", "g", "b", "wall", "floor"],
    defs: &[
        ("x_tip", "l1 * sin(th1) + l2 * sin(th2)"),
        ("y_tip", "-l1 * cos(th1) - l2 * cos(th2)"),
    ],
    kinetic: "0.5 * (m1 + m2) * l1^2 * w1^2 + 0.5 * m2 * l2^2 * w2^2
        + m2 * l1 * l2 * w1 * w2 * cos(th1 - th2)",
    potential: "-(m1 + m2) * g * l1 * cos(th1) - m2 * g * l2 * cos(th2)",
    applied: &[
        ("th1", "-b * w1 + b * (w2 - w1)"),
        ("th2", "-b * (w2 - w1)"),
    ],
    gaps: &["wall - x_tip", "y_tip + floor"],
};

/// `models/arm3.yaml`.
pub(crate) const ARM3: Spec = Spec {
    coords: &[("q1", "dq1"), ("q2", "dq2"), ("q3", "dq3")],
    params: &[
        "m1", "m2", "m3", "l1", "l2", "l3", "g", "b", "wall", "u1", "u2", "u3",
    ],
    defs: &[
        ("p1", "q1"),
        ("p2", "q1 + q2"),
        ("p3", "q1 + q2 + q3"),
        ("w1", "dq1"),
        ("w2", "dq1 + dq2"),
        ("w3", "dq1 + dq2 + dq3"),
        ("vx1", "-0.5 * l1 * sin(p1) * w1"),
        ("vy1", "0.5 * l1 * cos(p1) * w1"),
        ("vx2", "-l1 * sin(p1) * w1 - 0.5 * l2 * sin(p2) * w2"),
        ("vy2", "l1 * cos(p1) * w1 + 0.5 * l2 * cos(p2) * w2"),
        (
            "vx3",
            "-l1 * sin(p1) * w1 - l2 * sin(p2) * w2 - 0.5 * l3 * sin(p3) * w3",
        ),
        (
            "vy3",
            "l1 * cos(p1) * w1 + l2 * cos(p2) * w2 + 0.5 * l3 * cos(p3) * w3",
        ),
        ("y1", "0.5 * l1 * sin(p1)"),
        ("y2", "l1 * sin(p1) + 0.5 * l2 * sin(p2)"),
        ("y3", "l1 * sin(p1) + l2 * sin(p2) + 0.5 * l3 * sin(p3)"),
        ("x_tip", "l1 * cos(p1) + l2 * cos(p2) + l3 * cos(p3)"),
    ],
    kinetic: "0.5 * m1 * (vx1^2 + vy1^2) + 0.5 * m2 * (vx2^2 + vy2^2) + 0.5 * m3 * (vx3^2 + vy3^2)
        + (m1 * l1^2 * w1^2 + m2 * l2^2 * w2^2 + m3 * l3^2 * w3^2) / 24",
    potential: "g * (m1 * y1 + m2 * y2 + m3 * y3)",
    applied: &[
        ("q1", "u1 - b * dq1"),
        ("q2", "u2 - b * dq2"),
        ("q3", "u3 - b * dq3"),
    ],
    gaps: &["wall - x_tip"],
};

/// `models/parabola.yaml`.
pub(crate) const PARABOLA: Spec = Spec {
    coords: &[("x", "vx"), ("y", "vy")],
    params: &["m", "g", "c"],
    defs: &[],
    kinetic: "0.5 * m * (vx^2 + vy^2)",
    potential: "m * g * y",
    applied: &[],
    gaps: &["y - x^2", "c - y"],
};
