//! Tokenizers: a YAML scalar's text, or inline Rust tokens, cut into the
//! expression tokens the parser reads.

use proc_macro2::{Delimiter, Spacing, TokenStream, TokenTree};

use crate::ctxt::Ctxt;
use crate::loc::Loc;

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
