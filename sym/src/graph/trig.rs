//! A trigonometric normal form: expressions as sums of monomials times one
//! `cos` or `sin` of an integer combination of angles.
//!
//! An expression built from `+ - *`, constant divisions, small positive
//! integer powers and `sin`/`cos` of integer combinations of angles
//! (`sin(q1 + q2)`, `cos(th1 - 2 th2)`) is a polynomial in its other
//! factors ("atoms": parameters, or any subexpression of another kind) whose
//! coefficients are finite Fourier series in the angles. Products of waves
//! are turned into sums by the product-to-sum identities
//!
//! | product | sum |
//! |---|---|
//! | `cos A cos B` | `½ cos(A − B) + ½ cos(A + B)` |
//! | `sin A sin B` | `½ cos(A − B) − ½ cos(A + B)` |
//! | `sin A cos B` | `½ sin(A + B) + ½ sin(A − B)` |
//!
//! with `cos(−A) = cos A`, `sin(−A) = −sin A`, `cos 0 = 1`, `sin 0 = 0`. The
//! result is canonical: two expressions equal as trigonometric polynomials
//! have the same form. So `sin²x + cos²x` is `1`, `sin a sin b + cos a cos b`
//! is `cos(a − b)`, and the mass matrix of a chain with absolute angles
//! `θ_i` comes out as constants times `cos(θ_i − θ_j)`; with relative angles
//! it does not depend on the first angle at all.
//!
//! The form is rebuilt into the graph with common atoms factored out greedily
//! (the atom of most monomials first, as a multivariate Horner scheme).
//! Expansion can blow up (a product of sums is expanded), so it gives up
//! past [`MAX_TERMS`] monomials in any subexpression and keeps the
//! expression as it was.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::rc::Rc;

use super::Graph;
use crate::node::{Func, Id, Node};

/// The largest number of monomials of any intermediate form; past it the
/// normal form is abandoned.
pub(crate) const MAX_TERMS: usize = 400;

/// The largest power expanded (`x^4` is `x·x·x·x`; `x^5` stays an atom).
const MAX_POWER: i32 = 4;

/// The largest multiple of an angle read as an integer combination
/// (`sin(3 x)` is a wave, `sin(7 x)` an atom).
const MAX_FREQ: f64 = 4.0;

/// An integer combination of angles `Σ k_i a_i`: `(angle, k)` sorted by
/// angle, no zero `k`.
type Freq = Vec<(Id, i32)>;

/// The trigonometric factor of a monomial.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
enum Wave {
    /// No trigonometric factor.
    One,
    /// `cos(Σ k_i a_i)`, first `k` positive.
    Cos(Freq),
    /// `sin(Σ k_i a_i)`, first `k` positive.
    Sin(Freq),
}

/// A monomial without its coefficient: atoms with positive exponents, sorted
/// by atom, and a wave.
type Mono = (Vec<(Id, u32)>, Wave);

/// A trigonometric polynomial: monomials and their nonzero coefficients.
type Poly = BTreeMap<Mono, f64>;

/// The normal form of expressions of one graph, with the forms of the
/// subexpressions already seen remembered (share one across the entries of
/// a matrix).
#[derive(Debug, Default)]
pub struct TrigForm {
    /// Form of each node seen, `None` when it exceeded [`MAX_TERMS`].
    memo: HashMap<Id, Option<Rc<Poly>>>,
    /// Rebuilt expression of each node normalised.
    done: HashMap<Id, Id>,
}

impl TrigForm {
    /// A normaliser with nothing remembered.
    #[must_use]
    pub fn new() -> TrigForm {
        TrigForm::default()
    }

    /// `e` in the trigonometric normal form (a sum of monomials in its
    /// non-trigonometric factors times `cos` or `sin` of an integer
    /// combination of angles, rebuilt with common factors pulled out), or
    /// `e` itself when some subexpression's form would exceed 400 monomials.
    ///
    /// ```
    /// use moreau_sym::{graph::TrigForm, Graph, VarId};
    /// let mut g = Graph::new();
    /// let (a, b) = (g.var(VarId(0)), g.var(VarId(1)));
    /// let (sa, ca, sb, cb) = (g.sin(a), g.cos(a), g.sin(b), g.cos(b));
    /// let (ss, cc) = (g.mul(sa, sb), g.mul(ca, cb));
    /// let e = g.add(ss, cc); // sin a sin b + cos a cos b
    /// let n = TrigForm::new().normal(&mut g, e);
    /// let d = g.sub(a, b);
    /// assert_eq!(n, g.cos(d));
    /// let (s2, c2) = (g.powi(sa, 2), g.powi(ca, 2));
    /// let one = g.add(s2, c2);
    /// let n = TrigForm::new().normal(&mut g, one);
    /// assert_eq!(g.as_const(n), Some(1.0));
    /// ```
    pub fn normal(&mut self, g: &mut Graph, e: Id) -> Id {
        if let Some(&n) = self.done.get(&e) {
            return n;
        }
        let n = match self.form(g, e) {
            Some(p) => rebuild(g, &p),
            None => e,
        };
        self.done.insert(e, n);
        n
    }

    /// Every entry of `entries` in the normal form, each wave one call on
    /// its combination (`sin(q2 + q3)`, the fewest operations and the
    /// tightest interval enclosure). Whether a wave is better built from
    /// other waves by the addition formulas is decided later, once for all
    /// quantities of a model, by [`share_waves`].
    pub fn normal_all(&mut self, g: &mut Graph, entries: &[Id]) -> Vec<Id> {
        entries.iter().map(|&e| self.normal(g, e)).collect()
    }

    /// The form of `e`, `None` past [`MAX_TERMS`].
    fn form(&mut self, g: &Graph, e: Id) -> Option<Rc<Poly>> {
        if let Some(p) = self.memo.get(&e) {
            return p.clone();
        }
        // Children first, without recursion depth proportional to the DAG.
        let mut stack = vec![(e, false)];
        while let Some((id, expanded)) = stack.pop() {
            if self.memo.contains_key(&id) {
                continue;
            }
            if expanded {
                let p = self.form_of_node(g, id).map(Rc::new);
                self.memo.insert(id, p);
            } else {
                stack.push((id, true));
                for c in operands(g, id) {
                    if !self.memo.contains_key(&c) {
                        stack.push((c, false));
                    }
                }
            }
        }
        self.memo.get(&e).cloned().flatten()
    }

    /// The form of node `id`, its operands' forms being known.
    fn form_of_node(&self, g: &Graph, id: Id) -> Option<Poly> {
        let get = |c: &Id| self.memo.get(c).cloned().flatten();
        let p = match g.node(id) {
            Node::Const(_) => constant(g.as_const(id).unwrap_or(f64::NAN)),
            Node::Add([a, b]) => add(&*get(&a)?, &*get(&b)?, 1.0),
            Node::Sub([a, b]) => add(&*get(&a)?, &*get(&b)?, -1.0),
            Node::Neg(a) => scale(&*get(&a)?, -1.0),
            Node::Mul([a, b]) => mul(&*get(&a)?, &*get(&b)?)?,
            Node::Div([a, b]) => match g.as_const(b) {
                Some(d) if d != 0.0 => scale(&*get(&a)?, 1.0 / d),
                _ => atom(id),
            },
            Node::Powi(a, n) if (1..=MAX_POWER).contains(&n) => {
                let x: Poly = (*get(&a)?).clone();
                let mut p = x.clone();
                for _ in 1..n {
                    p = mul(&p, &x)?;
                }
                p
            }
            Node::Func(f @ (Func::Sin | Func::Cos), a) => match angle(g, a) {
                Some(freq) => wave(f, freq),
                None => atom(id),
            },
            _ => atom(id),
        };
        (p.len() <= MAX_TERMS).then_some(p)
    }
}

/// The operands whose forms [`TrigForm::form_of_node`] reads.
fn operands(g: &Graph, id: Id) -> Vec<Id> {
    match g.node(id) {
        Node::Add([a, b]) | Node::Sub([a, b]) | Node::Mul([a, b]) => vec![a, b],
        Node::Div([a, b]) if g.as_const(b).is_some() => vec![a],
        Node::Neg(a) => vec![a],
        Node::Powi(a, n) if (1..=MAX_POWER).contains(&n) => vec![a],
        _ => Vec::new(),
    }
}

/// The single monomial `c`.
fn constant(c: f64) -> Poly {
    let mut p = Poly::new();
    if c != 0.0 {
        p.insert((Vec::new(), Wave::One), c);
    }
    p
}

/// The single monomial `x` for an opaque node `x`.
fn atom(x: Id) -> Poly {
    let mut p = Poly::new();
    p.insert((vec![(x, 1)], Wave::One), 1.0);
    p
}

/// `c a`.
fn scale(a: &Poly, c: f64) -> Poly {
    if c == 0.0 {
        return Poly::new();
    }
    a.iter().map(|(m, &k)| (m.clone(), k * c)).collect()
}

/// Adds `c k` to the coefficient of `m`, dropping it when the sum cancels
/// (to rounding: coefficients like `1/3` come from divisions).
fn accumulate(p: &mut Poly, m: Mono, k: f64) {
    match p.get_mut(&m) {
        Some(old) => {
            let sum = *old + k;
            if sum.abs() <= 1e-14 * (old.abs() + k.abs()) {
                p.remove(&m);
            } else {
                *old = sum;
            }
        }
        None if k != 0.0 => {
            p.insert(m, k);
        }
        None => {}
    }
}

/// `a + c b`.
fn add(a: &Poly, b: &Poly, c: f64) -> Poly {
    let mut p = a.clone();
    for (m, &k) in b {
        accumulate(&mut p, m.clone(), c * k);
    }
    p
}

/// `a b`, `None` past [`MAX_TERMS`] products.
fn mul(a: &Poly, b: &Poly) -> Option<Poly> {
    if a.len().saturating_mul(b.len()) > MAX_TERMS * 4 {
        return None;
    }
    let mut p = Poly::new();
    for ((xa, wa), &ka) in a {
        for ((xb, wb), &kb) in b {
            let atoms = merge_atoms(xa, xb);
            for (k, w) in wave_product(wa, wb) {
                accumulate(&mut p, (atoms.clone(), w), ka * kb * k);
            }
        }
    }
    (p.len() <= MAX_TERMS).then_some(p)
}

/// The product of two sorted atom lists.
fn merge_atoms(a: &[(Id, u32)], b: &[(Id, u32)]) -> Vec<(Id, u32)> {
    let mut out: Vec<(Id, u32)> = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        let next = match (a.get(i), b.get(j)) {
            (Some(&(x, m)), Some(&(y, n))) if x == y => {
                i += 1;
                j += 1;
                (x, m + n)
            }
            (Some(&x), Some(&y)) if x.0 < y.0 => {
                i += 1;
                x
            }
            (Some(&x), None) => {
                i += 1;
                x
            }
            (_, Some(&y)) => {
                j += 1;
                y
            }
            (None, None) => unreachable!(),
        };
        out.push(next);
    }
    out
}

/// `Σ k_i a_i + s Σ l_i a_i`.
fn combine(a: &Freq, b: &Freq, s: i32) -> Freq {
    let mut map: BTreeMap<Id, i32> = a.iter().copied().collect();
    for &(x, l) in b {
        *map.entry(x).or_insert(0) += s * l;
    }
    map.into_iter().filter(|&(_, k)| k != 0).collect()
}

/// `f(freq)` as `(coefficient, wave)` in canonical sign, or `None` for the
/// zero `sin 0`.
fn canonical(f: Func, freq: Freq) -> Option<(f64, Wave)> {
    let Some(&(_, first)) = freq.first() else {
        return (f == Func::Cos).then_some((1.0, Wave::One));
    };
    let (sign, freq) = if first < 0 {
        (-1.0, freq.into_iter().map(|(x, k)| (x, -k)).collect())
    } else {
        (1.0, freq)
    };
    Some(match f {
        Func::Cos => (1.0, Wave::Cos(freq)),
        _ => (sign, Wave::Sin(freq)),
    })
}

/// The product of two waves as a sum of at most two waves.
fn wave_product(a: &Wave, b: &Wave) -> Vec<(f64, Wave)> {
    let (fa, x) = match a {
        Wave::One => return vec![(1.0, b.clone())],
        Wave::Cos(x) => (Func::Cos, x),
        Wave::Sin(x) => (Func::Sin, x),
    };
    let (fb, y) = match b {
        Wave::One => return vec![(1.0, a.clone())],
        Wave::Cos(y) => (Func::Cos, y),
        Wave::Sin(y) => (Func::Sin, y),
    };
    let (diff, sum) = (combine(x, y, -1), combine(x, y, 1));
    let parts = match (fa, fb) {
        (Func::Cos, Func::Cos) => [(0.5, Func::Cos, diff), (0.5, Func::Cos, sum)],
        (Func::Sin, Func::Sin) => [(0.5, Func::Cos, diff), (-0.5, Func::Cos, sum)],
        // sin x cos y = ½ sin(x + y) + ½ sin(x − y)
        (Func::Sin, _) => [(0.5, Func::Sin, sum), (0.5, Func::Sin, diff)],
        // cos x sin y = ½ sin(x + y) − ½ sin(x − y)
        _ => [(0.5, Func::Sin, sum), (-0.5, Func::Sin, diff)],
    };
    parts
        .into_iter()
        .filter_map(|(k, f, freq)| canonical(f, freq).map(|(s, w)| (k * s, w)))
        .collect()
}

/// `f(freq)` as a form.
fn wave(f: Func, freq: Freq) -> Poly {
    let mut p = Poly::new();
    if let Some((k, w)) = canonical(f, freq) {
        p.insert((Vec::new(), w), k);
    }
    p
}

/// `e` as an integer combination of angles (`q1 + q2`, `th1 - 2 * th2`), or
/// `None`. An angle is any non-constant subexpression that is not a sum, a
/// difference, a negation or a constant multiple; a constant term (`q + 1`)
/// or a non-integer multiple makes the whole argument an atom.
fn angle(g: &Graph, e: Id) -> Option<Freq> {
    let mut terms = Vec::new();
    if !linear(g, 1.0, e, &mut terms, &mut 32) {
        return None;
    }
    let mut map: BTreeMap<Id, i32> = BTreeMap::new();
    for (c, x) in terms {
        if c.fract() != 0.0 || c.abs() > MAX_FREQ {
            return None;
        }
        *map.entry(x).or_insert(0) += c as i32;
    }
    Some(map.into_iter().filter(|&(_, k)| k != 0).collect())
}

/// Appends `c e` to `out` as terms `(coefficient, angle)`; `false` on a
/// constant term or after `budget` nodes.
fn linear(g: &Graph, c: f64, e: Id, out: &mut Vec<(f64, Id)>, budget: &mut usize) -> bool {
    if *budget == 0 {
        return false;
    }
    *budget -= 1;
    match g.node(e) {
        Node::Add([a, b]) => linear(g, c, a, out, budget) && linear(g, c, b, out, budget),
        Node::Sub([a, b]) => linear(g, c, a, out, budget) && linear(g, -c, b, out, budget),
        Node::Neg(a) => linear(g, -c, a, out, budget),
        Node::Mul([k, x]) if g.as_const(k).is_some() => {
            linear(g, c * g.as_const(k).unwrap_or(1.0), x, out, budget)
        }
        Node::Const(_) => false,
        _ => {
            out.push((c, e));
            true
        }
    }
}

/// The expression of a form: atoms factored out greedily, each wave built
/// once (so `sin` and `cos` of one combination share its argument).
fn rebuild(g: &mut Graph, p: &Poly) -> Id {
    let terms: Vec<(f64, Vec<(Id, u32)>)> = p
        .iter()
        .map(|((atoms, w), &k)| {
            let mut atoms = atoms.clone();
            match w {
                Wave::One => {}
                Wave::Cos(x) => atoms.push((combination(g, Func::Cos, x), 1)),
                Wave::Sin(x) => atoms.push((combination(g, Func::Sin, x), 1)),
            }
            (k, atoms)
        })
        .collect();
    horner(g, terms)
}

/// `f(Σ k_i a_i)` as one call on the combination.
fn combination(g: &mut Graph, f: Func, freq: &Freq) -> Id {
    let mut acc: Option<Id> = None;
    // Positive multiples first, so that the argument reads a + b - c.
    let mut freq = freq.clone();
    freq.sort_by_key(|&(x, k)| (k < 0, x));
    for (x, k) in freq {
        let t = if k.abs() == 1 {
            x
        } else {
            let c = g.constant(f64::from(k.abs()));
            g.mul(c, x)
        };
        acc = Some(match (acc, k < 0) {
            (None, false) => t,
            (None, true) => g.neg(t),
            (Some(a), false) => g.add(a, t),
            (Some(a), true) => g.sub(a, t),
        });
    }
    let arg = acc.expect("a wave has an angle");
    g.func(f, arg)
}

/// `Σ k_m Π x^e` with the factor of most terms pulled out first.
fn horner(g: &mut Graph, terms: Vec<(f64, Vec<(Id, u32)>)>) -> Id {
    if terms.len() > 1 {
        let mut count: BTreeMap<Id, usize> = BTreeMap::new();
        for (_, atoms) in &terms {
            for &(x, _) in atoms {
                *count.entry(x).or_insert(0) += 1;
            }
        }
        let best = count
            .iter()
            .max_by_key(|&(&x, &n)| (n, std::cmp::Reverse(x)));
        if let Some((&x, &n)) = best {
            if n >= 2 {
                let (with, rest): (Vec<_>, Vec<_>) = terms
                    .into_iter()
                    .partition(|(_, atoms)| atoms.iter().any(|&(y, _)| y == x));
                let low = with
                    .iter()
                    .flat_map(|(_, atoms)| atoms.iter().filter(|&&(y, _)| y == x))
                    .map(|&(_, e)| e)
                    .min()
                    .unwrap_or(1);
                let reduced = with
                    .into_iter()
                    .map(|(k, atoms)| {
                        let atoms = atoms
                            .into_iter()
                            .filter_map(|(y, e)| match (y == x, e == low) {
                                (true, true) => None,
                                (true, false) => Some((y, e - low)),
                                _ => Some((y, e)),
                            })
                            .collect();
                        (k, atoms)
                    })
                    .collect();
                let inner = horner(g, reduced);
                let power = g.powi(x, low as i32);
                let factored = g.mul(power, inner);
                let rest = horner(g, rest);
                return g.add(factored, rest);
            }
        }
    }
    let mut acc: Option<Id> = None;
    for (k, atoms) in terms {
        let mut m: Option<Id> = None;
        for (x, e) in atoms {
            let p = g.powi(x, e as i32);
            m = Some(m.map_or(p, |m| g.mul(m, p)));
        }
        let mag = g.constant(k.abs());
        let t = m.map_or(mag, |m| g.mul(mag, m));
        acc = Some(match (acc, k < 0.0) {
            (None, false) => t,
            (None, true) => g.neg(t),
            (Some(a), false) => g.add(a, t),
            (Some(a), true) => g.sub(a, t),
        });
    }
    acc.unwrap_or_else(|| g.constant(0.0))
}

/// Sines and cosines of integer combinations of angles shared across every
/// expression of `roots`: each combination that is a sum or a difference
/// of two combinations already at hand is built from their sines and
/// cosines by the addition formulas (four products and two sums for both),
/// the others by one call on the combination (which the emitter pairs into
/// one `sin_cos`).
///
/// This is the one place that decides how a wave is built, for all
/// quantities at once: a two-link chain's `M` holds `cos(θ1 − θ2)` while
/// its `G` and gaps hold `sin θ1`, `cos θ1`, `sin θ2`, `cos θ2`; the
/// three-link arm's `M` holds waves of `q2`, `q3` and `q2 + q3`, its
/// gaps waves of `q1`, `q1 + q2` and `q1 + q2 + q3`. Taken one quantity
/// at a time neither repeats a call; taken together three `sin_cos`
/// calls give all six combinations of the arm (a call costs about 5 ns,
/// the formulas a fraction of one).
///
/// The combinations (the reachable `sin` and `cos` of an integer
/// combination, sign-normalised) are taken in order of their size
/// (`Σ |k_i|`, then number of angles), so single angles are called and
/// sums and differences derived; those reachable from `first` (the fused
/// evaluation) are all taken before the others and derived only from each
/// other, so that `first` never computes a call for the sake of the rest
/// (the derivatives). Among several ways to derive one, the shallowest
/// (fewest formulas stacked on a call) is taken: a derived value carries
/// an absolute error of a few units in the last place per level.
///
/// Returns `roots` rebuilt; an expression without such a wave comes back
/// as it was.
///
/// ```
/// use moreau_sym::{graph::share_waves, Graph, VarId};
/// let mut g = Graph::new();
/// let (a, b) = (g.var(VarId(0)), g.var(VarId(1)));
/// let d = g.sub(a, b);
/// let (sa, ca, sb, cb, cd) = (g.sin(a), g.cos(a), g.sin(b), g.cos(b), g.cos(d));
/// let shared = share_waves(&mut g, &[sa, ca, sb, cb, cd], &[]);
/// // cos(a − b) is now cos a cos b + sin a sin b: no fifth call
/// let cc = g.mul(ca, cb);
/// let ss = g.mul(sa, sb);
/// assert_eq!(shared[4], g.add(cc, ss));
/// assert_eq!(shared[..4], [sa, ca, sb, cb]);
/// ```
pub fn share_waves(g: &mut Graph, roots: &[Id], first: &[Id]) -> Vec<Id> {
    let size = |f: &Freq| {
        (
            f.iter().map(|&(_, k)| k.unsigned_abs()).sum::<u32>(),
            f.len(),
        )
    };
    let mut hand: BTreeMap<Freq, Hand> = BTreeMap::new();
    // each sin/cos node of a combination: its function, combination, and
    // whether the combination was negated
    let mut nodes: HashMap<Id, (Func, Freq, bool)> = HashMap::new();
    for phase in [first, roots] {
        let mut fresh: BTreeSet<Freq> = BTreeSet::new();
        for id in g.reachable(phase) {
            let Node::Func(f @ (Func::Sin | Func::Cos), a) = g.node(id) else {
                continue;
            };
            let Some((freq, flipped)) = angle(g, a).and_then(leading_positive) else {
                continue;
            };
            if !hand.contains_key(&freq) {
                fresh.insert(freq.clone());
            }
            nodes.insert(id, (f, freq, flipped));
        }
        // by size; the set's order among equal sizes
        let mut fresh: Vec<Freq> = fresh.into_iter().collect();
        fresh.sort_by_key(size);
        for freq in fresh {
            let built = derive(g, &hand, &freq).unwrap_or_else(|| {
                let sin = combination(g, Func::Sin, &freq);
                let cos = combination(g, Func::Cos, &freq);
                (sin, cos, 0)
            });
            hand.insert(freq, built);
        }
    }
    let mut map: HashMap<Id, Id> = HashMap::new();
    for (id, (f, freq, flipped)) in nodes {
        let (sin, cos, _) = hand[&freq];
        let new = match (f, flipped) {
            (Func::Cos, _) => cos,
            (_, false) => sin,
            (_, true) => g.neg(sin),
        };
        if new != id {
            map.insert(id, new);
        }
    }
    g.replace(roots, &map)
}

/// A combination at hand in [`share_waves`]: its `sin`, its `cos`, and how
/// many formulas stand between it and a call.
type Hand = (Id, Id, u32);

/// `freq` with its first coefficient positive, and whether it was negated;
/// `None` for the empty combination.
fn leading_positive(freq: Freq) -> Option<(Freq, bool)> {
    let &(_, first) = freq.first()?;
    Some(if first < 0 {
        (freq.into_iter().map(|(x, k)| (x, -k)).collect(), true)
    } else {
        (freq, false)
    })
}

/// `(sin, cos)` of `freq` from two combinations at hand whose sum or
/// difference it is, the shallowest such pair; `None` if there is none.
fn derive(g: &mut Graph, hand: &BTreeMap<Freq, Hand>, freq: &Freq) -> Option<Hand> {
    let mut best: Option<(u32, &Freq, Freq, bool)> = None;
    for (x, &(_, _, dx)) in hand {
        // freq = x + s·y with y at hand in canonical sign
        let Some((y, minus)) = leading_positive(combine(freq, x, -1)) else {
            continue;
        };
        let Some(&(_, _, dy)) = hand.get(&y) else {
            continue;
        };
        let depth = dx.max(dy) + 1;
        if best.as_ref().is_none_or(|b| depth < b.0) {
            best = Some((depth, x, y, minus));
        }
    }
    let (depth, x, y, minus) = best?;
    let (sx, cx, _) = hand[x];
    let (sy, cy, _) = hand[&y];
    // sin(x ± y) = sin x cos y ± cos x sin y, cos(x ± y) = cos x cos y ∓ sin x sin y
    let (a, b) = (g.mul(sx, cy), g.mul(cx, sy));
    let (c, d) = (g.mul(cx, cy), g.mul(sx, sy));
    let (sin, cos) = if minus {
        (g.sub(a, b), g.add(c, d))
    } else {
        (g.add(a, b), g.sub(c, d))
    };
    Some((sin, cos, depth))
}
