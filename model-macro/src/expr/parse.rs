//! The parser: one recursive descent over [`Tok`]s for both front ends.

use moreau_sym::Function;

use super::{BinOp, Expr, ExprKind, Tok, TokKind, fmt_number};
use crate::ctxt::Ctxt;
use crate::loc::Loc;

/// How deeply an expression may nest (parentheses, unary minus, powers and
/// calls each count one level). Every later stage recurses over the tree,
/// so this bound is what keeps them all within the stack.
pub(crate) const MAX_DEPTH: usize = 256;

/// Parses a whole token list as one expression; `whole` locates the
/// expression for errors at its end. Returns `None` after recording an error.
///
/// An unsupported function is reported and parsing goes on, so that every
/// unsupported function of an expression is reported at once.
pub(crate) fn parse(cx: &Ctxt, toks: &[Tok], whole: Loc) -> Option<Expr> {
    let mut p = Parser {
        cx,
        toks,
        pos: 0,
        whole,
        depth: 0,
        failed: false,
    };
    if toks.is_empty() {
        cx.error(whole, "expected an expression, found nothing");
        return None;
    }
    let e = p.expr()?;
    if let Some(t) = p.peek() {
        let what = describe(&t.kind);
        cx.error(t.loc, format!("expected an operator, found {what}"));
        return None;
    }
    (!p.failed).then_some(e)
}

struct Parser<'a> {
    cx: &'a Ctxt,
    toks: &'a [Tok],
    pos: usize,
    whole: Loc,
    /// Current nesting depth, bounded by [`MAX_DEPTH`].
    depth: usize,
    /// An error was recorded but parsing went on.
    failed: bool,
}

impl Parser<'_> {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos)
    }

    fn eat_op(&mut self, ops: &[char]) -> Option<(char, Loc)> {
        match self.peek() {
            Some(Tok {
                kind: TokKind::Op(c),
                loc,
            }) if ops.contains(c) => {
                let found = (*c, *loc);
                self.pos += 1;
                Some(found)
            }
            _ => None,
        }
    }

    fn expr(&mut self) -> Option<Expr> {
        let first = self.term()?;
        let mut rest = Vec::new();
        while let Some((c, loc)) = self.eat_op(&['+', '-']) {
            rest.push((c == '+', loc, self.term()?));
        }
        Some(chain(first, rest, BinOp::Add, BinOp::Sub))
    }

    fn term(&mut self) -> Option<Expr> {
        let first = self.unary()?;
        let mut rest = Vec::new();
        while let Some((c, loc)) = self.eat_op(&['*', '/']) {
            rest.push((c == '*', loc, self.unary()?));
        }
        Some(chain(first, rest, BinOp::Mul, BinOp::Div))
    }

    /// Enters one level of nesting; an error past [`MAX_DEPTH`].
    fn nest(&mut self, loc: Loc) -> Option<()> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            self.cx.error(
                loc,
                format!(
                    "expression nested more than {MAX_DEPTH} levels deep; split it with definitions"
                ),
            );
            return None;
        }
        Some(())
    }

    fn unary(&mut self) -> Option<Expr> {
        let loc = self.peek().map_or(self.whole, |t| t.loc);
        self.nest(loc)?;
        let e = self.unary_inner();
        self.depth -= 1;
        e
    }

    fn unary_inner(&mut self) -> Option<Expr> {
        if let Some((_, loc)) = self.eat_op(&['-']) {
            let inner = self.unary()?;
            return Some(Expr {
                kind: ExprKind::Neg(Box::new(inner)),
                loc,
            });
        }
        if let Some((_, loc)) = self.eat_op(&['+']) {
            self.cx.error(loc, "unary `+` is not allowed; remove it");
            return None;
        }
        self.power()
    }

    fn power(&mut self) -> Option<Expr> {
        let base = self.atom()?;
        if let Some((_, loc)) = self.eat_op(&['^']) {
            let exponent = self.unary()?;
            return Some(binary(BinOp::Pow, base, exponent, loc));
        }
        Some(base)
    }

    fn atom(&mut self) -> Option<Expr> {
        let Some(tok) = self.peek().cloned() else {
            self.cx.error(
                self.end_loc(),
                "expression ends where an operand is expected",
            );
            return None;
        };
        self.pos += 1;
        match tok.kind {
            TokKind::Num(x) => Some(Expr {
                kind: ExprKind::Num(x),
                loc: tok.loc,
            }),
            TokKind::Ident(name) => {
                if matches!(
                    self.peek(),
                    Some(Tok {
                        kind: TokKind::Open,
                        ..
                    })
                ) {
                    self.pos += 1;
                    self.call(name, tok.loc)
                } else {
                    Some(Expr {
                        kind: ExprKind::Name(name),
                        loc: tok.loc,
                    })
                }
            }
            TokKind::Open => {
                let inner = self.expr()?;
                self.close(tok.loc)?;
                Some(inner)
            }
            other => {
                let what = describe(&other);
                self.cx.error(
                    tok.loc,
                    format!("expected a number, a name or `(`, found {what}"),
                );
                None
            }
        }
    }

    fn call(&mut self, name: String, loc: Loc) -> Option<Expr> {
        let func = Function::from_name(&name);
        let mut args = vec![self.expr()?];
        while matches!(
            self.peek(),
            Some(Tok {
                kind: TokKind::Comma,
                ..
            })
        ) {
            self.pos += 1;
            args.push(self.expr()?);
        }
        self.close(loc)?;
        if let Some((kind, axis)) = super::Fixed::of(&name) {
            return self.frame(kind, axis, &name, args, loc);
        }
        let Some(func) = func else {
            let names: Vec<&str> = Function::ALL.iter().map(|f| f.name()).collect();
            self.cx.error(
                loc,
                format!(
                    "unsupported function `{name}`; the model language has {}",
                    names.join(", ")
                ),
            );
            // Go on: later unsupported functions are reported too.
            self.failed = true;
            return Some(Expr {
                kind: ExprKind::Num(0.0),
                loc,
            });
        };
        let kind = match func {
            Function::Unary(f) => match <[Expr; 1]>::try_from(args) {
                Ok([a]) => ExprKind::Func(f, Box::new(a)),
                Err(args) => return self.arity_error(func, args.len(), loc),
            },
            Function::Atan2 => match <[Expr; 2]>::try_from(args) {
                Ok([y, x]) => ExprKind::Atan2(Box::new(y), Box::new(x)),
                Err(args) => return self.arity_error(func, args.len(), loc),
            },
        };
        Some(Expr { kind, loc })
    }

    /// `position_x(body)`, `position_x(body, x, y, z)` or
    /// `direction_x(body, x, y, z)` (a direction has no default).
    fn frame(
        &mut self,
        kind: super::Fixed,
        axis: usize,
        name: &str,
        args: Vec<Expr>,
        loc: Loc,
    ) -> Option<Expr> {
        let zero = || Expr {
            kind: ExprKind::Num(0.0),
            loc,
        };
        let mut args = args.into_iter();
        let body = args.next()?;
        let point: Vec<Expr> = args.collect();
        let point = match (point.len(), kind) {
            (0, super::Fixed::Point) => [zero(), zero(), zero()],
            (3, _) => <[Expr; 3]>::try_from(point).ok()?,
            (found, super::Fixed::Point) => {
                self.cx.error(
                    loc,
                    format!("`{name}` takes a body and, optionally, the point's three coordinates in the body's frame (`{name}(body, x, y, z)`); found {} argument{}", found + 1, if found == 0 { "" } else { "s" }),
                );
                return None;
            }
            (found, super::Fixed::Direction) => {
                self.cx.error(
                    loc,
                    format!("`{name}` takes a body and the direction's three coordinates in the body's frame (`{name}(body, x, y, z)`); found {} argument{}", found + 1, if found == 0 { "" } else { "s" }),
                );
                return None;
            }
        };
        let ExprKind::Name(body_name) = body.kind else {
            self.cx.error(
                body.loc,
                format!("the first argument of `{name}` is the name of a body"),
            );
            return None;
        };
        Some(Expr {
            kind: ExprKind::Frame(kind, axis, body_name, Box::new(point)),
            loc,
        })
    }

    fn arity_error(&self, func: Function, found: usize, loc: Loc) -> Option<Expr> {
        let arity = func.arity();
        let plural = if arity == 1 { "" } else { "s" };
        self.cx.error(
            loc,
            format!("`{func}` takes {arity} argument{plural}, found {found}"),
        );
        None
    }

    fn close(&mut self, open: Loc) -> Option<()> {
        match self.peek() {
            Some(Tok {
                kind: TokKind::Close,
                ..
            }) => {
                self.pos += 1;
                Some(())
            }
            Some(t) => {
                let what = describe(&t.kind);
                self.cx.error(t.loc, format!("expected `)`, found {what}"));
                None
            }
            None => {
                self.cx.error(open, "this `(` is never closed");
                None
            }
        }
    }

    fn end_loc(&self) -> Loc {
        self.toks.last().map_or(self.whole, |t| t.loc)
    }
}

/// Chains longer than this are built as balanced trees.
const LONG_CHAIN: usize = 64;

/// `first op₁ t₁ op₂ t₂ …` for a left-associative pair of operators (`+ -`
/// or `* /`; `true` in `rest` is the first of the pair). Up to
/// [`LONG_CHAIN`] operands it is the left-deep tree of the text. A longer
/// chain (a potential of 2000 terms) is built as a balanced tree of the same
/// value in exact arithmetic (`a - b - c = a - (b + c)`), so that its depth,
/// and the recursion of every later stage over it, grows with the logarithm
/// of its length, not the length.
fn chain(first: Expr, rest: Vec<(bool, Loc, Expr)>, direct: BinOp, inverse: BinOp) -> Expr {
    if rest.len() < LONG_CHAIN {
        return rest.into_iter().fold(first, |lhs, (is_direct, loc, rhs)| {
            binary(if is_direct { direct } else { inverse }, lhs, rhs, loc)
        });
    }
    // Signed operands; the first is direct, and a pair whose left operand
    // is direct is direct, so the whole chain comes out direct.
    let mut items = vec![(true, first.loc, first)];
    items.extend(rest);
    balanced(items, direct, inverse).2
}

/// Combines signed operands (at least one) pairwise, halves first.
fn balanced(mut items: Vec<(bool, Loc, Expr)>, direct: BinOp, inverse: BinOp) -> (bool, Loc, Expr) {
    if items.len() == 1 {
        return items.remove(0);
    }
    let right = items.split_off(items.len() / 2);
    let (da, la, a) = balanced(items, direct, inverse);
    let (db, lb, b) = balanced(right, direct, inverse);
    // (+a, +b) → +(a∘b); (+a, −b) → +(a∘⁻¹b); (−a, +b) → +(b∘⁻¹a);
    // (−a, −b) → −(a∘b)
    match (da, db) {
        (true, true) => (true, la, binary(direct, a, b, lb)),
        (true, false) => (true, la, binary(inverse, a, b, lb)),
        (false, true) => (true, lb, binary(inverse, b, a, la)),
        (false, false) => (false, la, binary(direct, a, b, lb)),
    }
}

fn binary(op: BinOp, a: Expr, b: Expr, loc: Loc) -> Expr {
    Expr {
        kind: ExprKind::Binary(op, Box::new(a), Box::new(b)),
        loc,
    }
}

fn describe(kind: &TokKind) -> String {
    match kind {
        TokKind::Num(x) => format!("the number `{}`", fmt_number(*x)),
        TokKind::Ident(name) => format!("`{name}`"),
        TokKind::Op(c) => format!("`{c}`"),
        TokKind::Open => "`(`".into(),
        TokKind::Close => "`)`".into(),
        TokKind::Comma => "`,`".into(),
    }
}
