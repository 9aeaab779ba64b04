use proc_macro2::Span;

use super::*;
use crate::ctxt::Ctxt;
use crate::expand;
use crate::front::{yaml, yaml_tree::YamlSource};

/// Reads a shipped model file and runs `f` on it compiled.
fn shipped<R>(stem: &str, f: impl FnOnce(&Resolved<'_>, &Lowered) -> R) -> R {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let path = dir.join(format!("{stem}.yaml"));
    let text = std::fs::read_to_string(&path).unwrap();
    compiled(&path, text, f)
}

/// Compiles the YAML model `text` (read from `path`) and runs `f` on it.
fn compiled<R>(
    path: &std::path::Path,
    text: String,
    f: impl FnOnce(&Resolved<'_>, &Lowered) -> R,
) -> R {
    let source = YamlSource {
        display: path.display().to_string(),
        text: text.clone(),
    };
    let root = source.parse().unwrap();
    let cx = Ctxt::with_locator(source);
    let spec = yaml::build(&cx, &root, Span::call_site(), path, text).unwrap();
    let compiled = expand::compile(&cx, &spec);
    cx.check().unwrap();
    let (model, lowered) = compiled.unwrap();
    f(&model, &lowered)
}

const SHIPPED: [&str; 5] = [
    "parabola",
    "three_balls",
    "billiard",
    "double_pendulum",
    "arm3",
];

/// The fused evaluation of each shipped model, as text, against its
/// snapshot in `model-macro/snapshots/` (rewrite them with
/// `UPDATE_SNAPSHOTS=1`, then read the diff).
#[test]
fn fused_listing_matches_snapshot() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("snapshots");
    let mut stale = Vec::new();
    for stem in SHIPPED {
        let text = shipped(stem, listing);
        let path = dir.join(format!("{stem}.txt"));
        if std::env::var_os("UPDATE_SNAPSHOTS").is_some() {
            std::fs::write(&path, &text).unwrap();
        } else if std::fs::read_to_string(&path).ok().as_deref() != Some(text.as_str()) {
            stale.push(stem);
        }
    }
    assert!(
        stale.is_empty(),
        "listings changed for {stale:?}; rerun with UPDATE_SNAPSHOTS=1 and review the diff"
    );
}

/// The same model emits the same bytes every time (no hash-map order
/// leaks into the output).
#[test]
fn emission_is_deterministic() {
    for stem in SHIPPED {
        let once = shipped(stem, |m, l| emit(m, l).to_string());
        let twice = shipped(stem, |m, l| emit(m, l).to_string());
        assert_eq!(once, twice, "{stem}");
    }
}

#[test]
fn output_entries_are_named_after_their_slot() {
    use names::Local;
    let outputs = Layout::new(3, 1);
    let m21 = Slot {
        quantity: Quantity::Mass,
        row: 2,
        col: 1,
    };
    shipped("arm3", |model, _| {
        let name = |slot| Local::Output(slot).readable(model, 0.0);
        assert_eq!(name(outputs.slot(outputs.index(m21))), "m_1_2");
        let j02 = Slot {
            quantity: Quantity::Jacobian,
            row: 0,
            col: 2,
        };
        assert_eq!(
            (name(j02), j02.describe()),
            ("j_0_2".into(), "J[0,2]".into())
        );
        let g1 = Slot {
            quantity: Quantity::Gravity,
            row: 1,
            col: 0,
        };
        assert_eq!(name(g1), "g_1");
    });
}

/// CasADi's operation count for a model, from the JSON its reference script
/// wrote (`casadi_op_count`).
fn casadi_ops(json: &str) -> usize {
    let text = std::fs::read_to_string(json).unwrap();
    let key = "\"casadi_op_count\":";
    let at = text.find(key).unwrap() + key.len();
    let digits: String = text[at..]
        .trim_start()
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    digits.parse().unwrap()
}

/// The fused evaluation (M, C, G, F, h, J) counts at most as many operations
/// as CasADi's generated C for the same model (`tests/casadi_reference.py`,
/// SX with CSE), on every shipped model and the planar chains N = 2..12.
#[test]
fn op_counts_at_most_casadis() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut cases: Vec<(String, String)> = SHIPPED
        .iter()
        .map(|s| (s.to_string(), format!("tests/fixtures/casadi/{s}.json")))
        .collect();
    for n in 2..=12 {
        cases.push((
            format!("chains/chain{n:02}"),
            format!("benches/casadi/chains/chain{n:02}.json"),
        ));
    }
    let mut over = Vec::new();
    for (stem, json) in cases {
        let ours = shipped(&stem, |model, lowered| {
            Emitter::new(model, lowered).op_count()
        });
        let theirs = casadi_ops(root.join(json).to_str().unwrap());
        eprintln!("{stem}: moreau {ours}, CasADi {theirs}");
        if ours > theirs {
            over.push((stem, ours, theirs));
        }
    }
    assert!(over.is_empty(), "more operations than CasADi: {over:?}");
}

/// A potential of `N` terms `c sin(x + i)` (issue 9's compile-cost model):
/// no folded expression outgrows [`body::MAX_FOLD_SIZE`] (its operands are
/// at most that size), the fused body is cut into parts of weight at most
/// [`print::PART`] plus one binding, each part binds only constants its
/// own bindings read, and the parts are as many as the weight asks for:
/// what rustc receives per function is bounded, whatever `N`.
#[test]
fn long_bodies_are_cut_into_bounded_parts() {
    use body::MAX_FOLD_SIZE;
    use print::PART;
    let n = 3000;
    let terms: Vec<String> = (0..n)
        .map(|i| format!("{}.5 * sin(x + {i})", i % 7 + 1))
        .collect();
    let text = format!(
        "name: Big\ncoordinates:\n  - x: vx\nkinetic: 0.5 * vx^2\npotential: {}\n\
         constraints:\n  - name: floor\n    h: x + 1\nrestitution: 0.5\n",
        terms.join(" + ")
    );
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("big.yaml");
    compiled(&path, text, |model, lowered| {
        let (_, body) = Emitter::new(model, lowered).body(Scalar::Model, &Quantity::EVAL);
        let largest = body.lets.iter().map(|l| l.code.size()).max().unwrap();
        assert!(largest <= 2 * MAX_FOLD_SIZE, "{largest}");
        let weight: usize = body.lets.iter().map(|l| l.code.size()).sum();
        let (parts, top) = print::parts(&body);
        assert!(
            parts.len() >= weight / (PART + 2 * MAX_FOLD_SIZE),
            "{}",
            parts.len()
        );
        assert!(parts.len() <= weight / PART + 1, "{}", parts.len());
        for part in &parts {
            let lets = &body.lets[part.range.clone()];
            let w: usize = lets.iter().map(|l| l.code.size()).sum();
            assert!(w <= PART + 2 * MAX_FOLD_SIZE, "{w}");
            for &c in &part.constants {
                let mut read = false;
                for l in lets {
                    l.code
                        .visit_locals(&mut |local| read |= local == names::Local::Const(c));
                }
                assert!(read, "constant {c} bound in a part that does not read it");
            }
        }
        assert!(top.len() <= body.outputs.len(), "{}", top.len());
        let ranges: usize = parts.iter().map(|p| p.range.len()).sum();
        assert_eq!(ranges, body.lets.len());
    });
}

/// A method is hinted `#[inline]` when its body has at most `INLINE_OPS`
/// operations: every method of Example 1; of the 12-link chain, `mass`
/// (277 operations) but not `eval` (1 103) nor `linearization` (1 707).
#[test]
fn only_short_bodies_are_hinted_inline() {
    let hinted = |stem: &str, method: &str| {
        let code = shipped(stem, |model, lowered| Emitter::new(model, lowered).items()).to_string();
        let at = code.find(&format!("fn {method} ")).unwrap();
        code[..at].trim_end().ends_with("# [inline]")
    };
    for method in ["mass", "eval", "linearization", "mass_dq", "mass_enclosure"] {
        assert!(hinted("parabola", method), "parabola {method}");
    }
    assert!(hinted("chains/chain12", "mass"));
    assert!(!hinted("chains/chain12", "eval"));
    assert!(!hinted("chains/chain12", "linearization"));
}
