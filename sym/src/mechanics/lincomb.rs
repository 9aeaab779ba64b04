//! Linear combinations of expressions: the Christoffel symbols are sums of
//! three derivatives of `M` whose parts often merge or cancel.

use crate::graph::Graph;
use crate::node::{Id, Node};

/// Appends `c e` to `out` as a list of terms `(coefficient, expression)`,
/// looking through sums, differences, negations and constant multiples.
/// Gives up (returns `false`) after visiting `budget` nodes, so that a DAG
/// of sums cannot blow up into a huge tree.
fn flatten(g: &Graph, c: f64, e: Id, out: &mut Vec<(f64, Id)>, budget: &mut usize) -> bool {
    if *budget == 0 {
        return false;
    }
    *budget -= 1;
    match g.node(e) {
        Node::Add([a, b]) => flatten(g, c, a, out, budget) && flatten(g, c, b, out, budget),
        Node::Sub([a, b]) => flatten(g, c, a, out, budget) && flatten(g, -c, b, out, budget),
        Node::Neg(a) => flatten(g, -c, a, out, budget),
        Node::Mul([k, x]) => match g.as_const(k) {
            Some(k) => flatten(g, c * k, x, out, budget),
            None => {
                out.push((c, e));
                true
            }
        },
        Node::Const(_) if g.is_zero(e) => true,
        _ => {
            out.push((c, e));
            true
        }
    }
}

/// `terms` with equal expressions merged (coefficients added) and zero
/// terms dropped, in order of first appearance.
fn merge(g: &Graph, terms: &[(f64, Id)]) -> Vec<(f64, Id)> {
    let mut merged: Vec<(f64, Id)> = Vec::new();
    for &(c, e) in terms {
        if g.is_zero(e) {
            continue;
        }
        match merged.iter_mut().find(|(_, f)| *f == e) {
            Some((d, _)) => *d += c,
            None => merged.push((c, e)),
        }
    }
    merged.retain(|&(c, _)| c != 0.0);
    merged
}

/// `Σ c_m e_m`, with equal expressions merged first and zero terms dropped;
/// a common magnitude of the coefficients is factored out
/// (`½ a + ½ b − ½ c = ½ (a + b − c)`).
///
/// The terms are also expanded through sums and constant multiples; when
/// that expansion lets some terms merge or cancel (`∂M_ij/∂q_k` are often
/// sums whose parts cancel in a Christoffel symbol), the expanded form is
/// built instead, otherwise the given expressions are reused whole.
pub(super) fn lincomb(g: &mut Graph, terms: &[(f64, Id)]) -> Id {
    let mut flat = Vec::new();
    let mut budget = 256;
    let expanded = terms
        .iter()
        .all(|&(c, e)| flatten(g, c, e, &mut flat, &mut budget));
    let deep = merge(g, &flat);
    let mut merged = if expanded && deep.len() < flat.len() {
        deep
    } else {
        merge(g, terms)
    };
    let Some(&(c0, _)) = merged.first() else {
        return g.constant(0.0);
    };
    let common = merged.iter().all(|&(c, _)| c.abs() == c0.abs());
    let scale = if common { c0.abs() } else { 1.0 };
    // Positive terms first, so that the sum reads a + b - c.
    merged.sort_by_key(|&(c, _)| c < 0.0);
    let mut acc: Option<Id> = None;
    for (c, e) in merged {
        let mag = c.abs() / scale;
        let t = if mag == 1.0 {
            e
        } else {
            let k = g.constant(mag);
            g.mul(k, e)
        };
        acc = Some(match (acc, c < 0.0) {
            (None, false) => t,
            (None, true) => g.neg(t),
            (Some(a), false) => g.add(a, t),
            (Some(a), true) => g.sub(a, t),
        });
    }
    let acc = acc.unwrap_or_else(|| g.constant(0.0));
    let k = g.constant(scale);
    g.mul(k, acc)
}

/// `Σ terms`, `0` when empty.
pub(super) fn sum(g: &mut Graph, terms: &[Id]) -> Id {
    let mut acc = g.constant(0.0);
    for &t in terms {
        acc = g.add(acc, t);
    }
    acc
}
