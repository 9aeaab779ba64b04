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
//! A YAML scalar is cut into [`Tok`]s by [`tokenize_str`]; inline Rust tokens
//! by [`tokenize_stream`]. From there one parser, [`parse`], builds the
//! [`Expr`] tree. `^` means power in both: we parse the tokens ourselves, so
//! Rust's XOR (and its precedence) never applies.

use std::fmt;

use proc_macro2::{Delimiter, Spacing, TokenStream, TokenTree};

use crate::ctxt::{Ctxt, Loc};

/// The smooth functions of the model language.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Func {
    Sqrt,
    Exp,
    Ln,
    Sin,
    Cos,
    Tan,
    Atan2,
    Sinh,
    Cosh,
    Tanh,
}

impl Func {
    /// Every function, in the order the error message lists them.
    pub const ALL: [Func; 10] = [
        Func::Sqrt,
        Func::Exp,
        Func::Ln,
        Func::Sin,
        Func::Cos,
        Func::Tan,
        Func::Atan2,
        Func::Sinh,
        Func::Cosh,
        Func::Tanh,
    ];

    /// The function's name in the model language.
    pub fn name(self) -> &'static str {
        match self {
            Func::Sqrt => "sqrt",
            Func::Exp => "exp",
            Func::Ln => "ln",
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Atan2 => "atan2",
            Func::Sinh => "sinh",
            Func::Cosh => "cosh",
            Func::Tanh => "tanh",
        }
    }

    /// Number of arguments.
    pub fn arity(self) -> usize {
        match self {
            Func::Atan2 => 2,
            _ => 1,
        }
    }

    fn from_name(name: &str) -> Option<Func> {
        Func::ALL.into_iter().find(|f| f.name() == name)
    }
}

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
    fn symbol(self) -> &'static str {
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
#[derive(Clone, Debug)]
pub(crate) struct Expr {
    pub kind: ExprKind,
    pub loc: Loc,
}

/// The shape of an [`Expr`].
#[derive(Clone, Debug)]
pub(crate) enum ExprKind {
    Num(f64),
    Name(String),
    Neg(Box<Expr>),
    Binary(BinOp, Box<Expr>, Box<Expr>),
    Call(Func, Vec<Expr>),
}

impl Expr {
    /// Calls `f` on every name this expression uses, in reading order.
    pub fn visit_names<'a>(&'a self, f: &mut impl FnMut(&'a str, Loc)) {
        match &self.kind {
            ExprKind::Num(_) => {}
            ExprKind::Name(name) => f(name, self.loc),
            ExprKind::Neg(a) => a.visit_names(f),
            ExprKind::Binary(_, a, b) => {
                a.visit_names(f);
                b.visit_names(f);
            }
            ExprKind::Call(_, args) => args.iter().for_each(|a| a.visit_names(f)),
        }
    }

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
            ExprKind::Call(func, args) => {
                write!(f, "{}(", func.name())?;
                for (i, a) in args.iter().enumerate() {
                    if i > 0 {
                        f.write_str(", ")?;
                    }
                    write!(f, "{a}")?;
                }
                f.write_str(")")
            }
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

/// One token of an expression.
#[derive(Clone, Debug)]
pub(crate) struct Tok {
    pub kind: TokKind,
    pub loc: Loc,
}

/// The kinds of [`Tok`].
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum TokKind {
    Num(f64),
    Ident(String),
    /// One of `+ - * / ^`.
    Op(char),
    Open,
    Close,
    Comma,
}

/// Cuts the text of a YAML scalar into tokens; `loc` is the scalar's location
/// and each token's location is shifted by its byte offset in `text`.
/// Returns `None` after recording an error.
pub(crate) fn tokenize_str(cx: &Ctxt, text: &str, loc: Loc) -> Option<Vec<Tok>> {
    let bytes = text.as_bytes();
    let mut toks = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let at = loc.shifted(i);
        let start = i;
        let kind = match c {
            b' ' | b'\t' | b'\n' | b'\r' => {
                i += 1;
                continue;
            }
            b'0'..=b'9' | b'.' => {
                while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                    i += 1;
                }
                if i < bytes.len() && (bytes[i] == b'e' || bytes[i] == b'E') {
                    let mut j = i + 1;
                    if j < bytes.len() && (bytes[j] == b'+' || bytes[j] == b'-') {
                        j += 1;
                    }
                    if j < bytes.len() && bytes[j].is_ascii_digit() {
                        i = j;
                        while i < bytes.len() && bytes[i].is_ascii_digit() {
                            i += 1;
                        }
                    }
                }
                let literal = &text[start..i];
                match literal.parse::<f64>() {
                    Ok(x) => TokKind::Num(x),
                    Err(_) => {
                        cx.error(at, format!("`{literal}` is not a number"));
                        return None;
                    }
                }
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                    i += 1;
                }
                TokKind::Ident(text[start..i].to_string())
            }
            b'*' if bytes.get(i + 1) == Some(&b'*') => {
                cx.error(at, "`**` is not an operator here; write powers as `x^2`");
                return None;
            }
            b'+' | b'-' | b'*' | b'/' | b'^' => {
                i += 1;
                TokKind::Op(c as char)
            }
            b'(' => {
                i += 1;
                TokKind::Open
            }
            b')' => {
                i += 1;
                TokKind::Close
            }
            b',' => {
                i += 1;
                TokKind::Comma
            }
            _ => {
                let ch = text[start..].chars().next().unwrap_or('?');
                cx.error(at, format!("unexpected character `{ch}` in expression"));
                return None;
            }
        };
        toks.push(Tok { kind, loc: at });
    }
    Some(toks)
}

/// Flattens inline Rust tokens into expression tokens. Parentheses become
/// [`TokKind::Open`]/[`TokKind::Close`]; any other delimiter, and `**`, is an
/// error. Returns `None` after recording an error.
pub(crate) fn tokenize_stream(cx: &Ctxt, stream: TokenStream) -> Option<Vec<Tok>> {
    let mut toks = Vec::new();
    let mut ok = true;
    flatten(cx, stream, &mut toks, &mut ok);
    ok.then_some(toks)
}

fn flatten(cx: &Ctxt, stream: TokenStream, toks: &mut Vec<Tok>, ok: &mut bool) {
    let mut iter = stream.into_iter().peekable();
    while let Some(tree) = iter.next() {
        let loc = Loc::span(tree.span());
        let kind = match tree {
            TokenTree::Ident(ident) => TokKind::Ident(ident.to_string()),
            TokenTree::Literal(lit) => {
                let text = lit.to_string();
                match text.parse::<f64>() {
                    Ok(x) if x.is_finite() => TokKind::Num(x),
                    _ => {
                        cx.error(
                            loc,
                            format!("`{text}` is not a number the model language accepts (write plain numbers such as `2`, `0.5` or `1e-3`)"),
                        );
                        *ok = false;
                        continue;
                    }
                }
            }
            TokenTree::Punct(p) => {
                let c = p.as_char();
                if c == '*'
                    && p.spacing() == Spacing::Joint
                    && matches!(iter.peek(), Some(TokenTree::Punct(n)) if n.as_char() == '*')
                {
                    cx.error(loc, "`**` is not an operator here; write powers as `x^2`");
                    *ok = false;
                    iter.next();
                    continue;
                }
                match c {
                    '+' | '-' | '*' | '/' | '^' => TokKind::Op(c),
                    ',' => TokKind::Comma,
                    _ => {
                        cx.error(loc, format!("unexpected `{c}` in expression"));
                        *ok = false;
                        continue;
                    }
                }
            }
            TokenTree::Group(group) => {
                if group.delimiter() == Delimiter::Parenthesis {
                    toks.push(Tok {
                        kind: TokKind::Open,
                        loc: Loc::span(group.span_open()),
                    });
                    flatten(cx, group.stream(), toks, ok);
                    toks.push(Tok {
                        kind: TokKind::Close,
                        loc: Loc::span(group.span_close()),
                    });
                } else if group.delimiter() == Delimiter::None {
                    flatten(cx, group.stream(), toks, ok);
                } else {
                    cx.error(loc, "only parentheses may group an expression");
                    *ok = false;
                }
                continue;
            }
        };
        toks.push(Tok { kind, loc });
    }
}

/// Parses a whole token list as one expression; `whole` locates the
/// expression for errors at its end. Returns `None` after recording an error.
pub(crate) fn parse(cx: &Ctxt, toks: &[Tok], whole: Loc) -> Option<Expr> {
    let mut p = Parser {
        cx,
        toks,
        pos: 0,
        whole,
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
    Some(e)
}

struct Parser<'a> {
    cx: &'a Ctxt,
    toks: &'a [Tok],
    pos: usize,
    whole: Loc,
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
        let mut lhs = self.term()?;
        while let Some((c, loc)) = self.eat_op(&['+', '-']) {
            let op = if c == '+' { BinOp::Add } else { BinOp::Sub };
            let rhs = self.term()?;
            lhs = binary(op, lhs, rhs, loc);
        }
        Some(lhs)
    }

    fn term(&mut self) -> Option<Expr> {
        let mut lhs = self.unary()?;
        while let Some((c, loc)) = self.eat_op(&['*', '/']) {
            let op = if c == '*' { BinOp::Mul } else { BinOp::Div };
            let rhs = self.unary()?;
            lhs = binary(op, lhs, rhs, loc);
        }
        Some(lhs)
    }

    fn unary(&mut self) -> Option<Expr> {
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
        let func = Func::from_name(&name);
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
        let Some(func) = func else {
            let names: Vec<&str> = Func::ALL.iter().map(|f| f.name()).collect();
            self.cx.error(
                loc,
                format!(
                    "unsupported function `{name}`; the model language has {}",
                    names.join(", ")
                ),
            );
            return None;
        };
        if args.len() != func.arity() {
            self.cx.error(
                loc,
                format!(
                    "`{}` takes {} argument{}, found {}",
                    func.name(),
                    func.arity(),
                    if func.arity() == 1 { "" } else { "s" },
                    args.len()
                ),
            );
            return None;
        }
        Some(Expr {
            kind: ExprKind::Call(func, args),
            loc,
        })
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

#[cfg(test)]
mod tests {
    use super::*;
    use proc_macro2::Span;

    fn parse_text(text: &str) -> Result<Expr, String> {
        let cx = Ctxt::new();
        let loc = Loc::span(Span::call_site());
        let e = tokenize_str(&cx, text, loc).and_then(|t| parse(&cx, &t, loc));
        match cx.check() {
            Ok(()) => Ok(e.expect("no error but no expression")),
            Err(err) => Err(err.to_string()),
        }
    }

    fn round_trip(text: &str) -> String {
        parse_text(text).unwrap().to_string()
    }

    #[test]
    fn power_binds_tighter_than_unary_minus_and_is_right_associative() {
        assert_eq!(round_trip("-x^2"), "-x ^ 2");
        assert!(matches!(parse_text("-x^2").unwrap().kind, ExprKind::Neg(_)));
        assert_eq!(round_trip("x^y^z"), "x ^ y ^ z");
        assert_eq!(round_trip("(x^y)^z"), "(x ^ y) ^ z");
        assert_eq!(round_trip("x^-2"), "x ^ -2");
    }

    #[test]
    fn precedence_and_left_associativity() {
        assert_eq!(round_trip("a - (b - c)"), "a - (b - c)");
        assert_eq!(round_trip("(a - b) - c"), "a - b - c");
        assert_eq!(round_trip("a / (b * c)"), "a / (b * c)");
        assert_eq!(round_trip("2 * v^2 + 1"), "2 * v ^ 2 + 1");
        assert_eq!(round_trip("-(a + b)"), "-(a + b)");
        assert_eq!(round_trip("atan2(y, x) * 1e-3"), "atan2(y, x) * 0.001");
    }

    #[test]
    fn printed_form_parses_back_to_the_same_text() {
        for text in [
            "0.5 * m * (vx^2 + vy^2)",
            "-(m1 + m2) * g * l1 * cos(th1) - m2 * g * l2 * cos(th2)",
            "x^(1 / 3) - -y",
            "(a + b)^2 / (c - d)^-1",
        ] {
            let once = round_trip(text);
            assert_eq!(round_trip(&once), once);
        }
    }

    #[test]
    fn errors_name_the_problem() {
        assert!(parse_text("x ** 2").unwrap_err().contains("`**`"));
        assert!(
            parse_text("foo(x)")
                .unwrap_err()
                .contains("unsupported function `foo`")
        );
        assert!(
            parse_text("atan2(x)")
                .unwrap_err()
                .contains("takes 2 arguments")
        );
        assert!(parse_text("(x + 1").unwrap_err().contains("never closed"));
        assert!(
            parse_text("x y")
                .unwrap_err()
                .contains("expected an operator")
        );
        assert!(parse_text("x + ").unwrap_err().contains("operand"));
        assert!(
            parse_text("x % 2")
                .unwrap_err()
                .contains("unexpected character `%`")
        );
        assert!(parse_text("").unwrap_err().contains("found nothing"));
    }

    #[test]
    fn yaml_token_locations_carry_their_offset() {
        let cx = Ctxt::new();
        let loc = Loc {
            span: Span::call_site(),
            node: Some(crate::ctxt::YamlPos { node: 7, offset: 0 }),
        };
        let toks = tokenize_str(&cx, "y - x^2", loc).unwrap();
        cx.check().unwrap();
        let offsets: Vec<usize> = toks.iter().map(|t| t.loc.node.unwrap().offset).collect();
        assert_eq!(offsets, [0, 2, 4, 5, 6]);
    }

    #[test]
    fn inline_tokens_parse_like_text() {
        let cx = Ctxt::new();
        let stream: TokenStream = "0.5 * m * (vx^2 + vy^2) - atan2(y, x)".parse().unwrap();
        let toks = tokenize_stream(&cx, stream).unwrap();
        let e = parse(&cx, &toks, Loc::span(Span::call_site())).unwrap();
        cx.check().unwrap();
        assert_eq!(e.to_string(), "0.5 * m * (vx ^ 2 + vy ^ 2) - atan2(y, x)");
    }

    #[test]
    fn inline_double_star_is_rejected() {
        let cx = Ctxt::new();
        let stream: TokenStream = "x ** 2".parse().unwrap();
        assert!(tokenize_stream(&cx, stream).is_none());
        assert!(cx.check().unwrap_err().to_string().contains("`**`"));
    }
}
