use super::*;
use proc_macro2::{Span, TokenStream};

use crate::ctxt::Ctxt;

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
        node: Some(crate::loc::YamlPos { node: 7, offset: 0 }),
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

/// The value of a numeric expression, for checking tree shapes.
fn value(e: &Expr) -> f64 {
    match &e.kind {
        ExprKind::Num(x) => *x,
        ExprKind::Neg(a) => -value(a),
        ExprKind::Binary(op, a, b) => {
            let (a, b) = (value(a), value(b));
            match op {
                BinOp::Add => a + b,
                BinOp::Sub => a - b,
                BinOp::Mul => a * b,
                BinOp::Div => a / b,
                BinOp::Pow => a.powf(b),
            }
        }
        _ => f64::NAN,
    }
}

fn depth(e: &Expr) -> usize {
    match &e.kind {
        ExprKind::Neg(a) | ExprKind::Func(_, a) => 1 + depth(a),
        ExprKind::Binary(_, a, b) | ExprKind::Atan2(a, b) => 1 + depth(a).max(depth(b)),
        _ => 1,
    }
}

/// A chain of thousands of terms is a balanced tree of the same value (so
/// that no later stage recurses thousands of levels); a short one keeps the
/// left-deep shape of the text.
#[test]
fn long_chains_are_balanced_and_keep_their_value() {
    let terms: Vec<String> = (0..3000)
        .map(|i| format!("{} {}", if i % 3 == 0 { "-" } else { "+" }, 1 + i % 17))
        .collect();
    let text = format!("1 {}", terms.join(" "));
    let e = parse_text(&text).unwrap();
    let exact: f64 = 1.0
        + (0..3000)
            .map(|i| if i % 3 == 0 { -1.0 } else { 1.0 } * f64::from(1 + i % 17))
            .sum::<f64>();
    assert_eq!(value(&e), exact); // small integers: exact in any order
    assert!(depth(&e) <= 14, "depth {}", depth(&e));
    let factors: Vec<String> = (0..200)
        .map(|i| format!("{} {}", if i % 2 == 0 { "*" } else { "/" }, 2))
        .collect();
    let e = parse_text(&format!("3 {}", factors.join(" "))).unwrap();
    assert_eq!(value(&e), 3.0);
    let short = parse_text("1 - 2 - 3 + 4").unwrap();
    assert_eq!(depth(&short), 4);
    assert_eq!(short.to_string(), "1 - 2 - 3 + 4");
}
