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
    let source = YamlSource {
        display: format!("models/{stem}.yaml"),
        text: text.clone(),
    };
    let root = source.parse().unwrap();
    let cx = Ctxt::with_locator(source);
    let spec = yaml::build(&cx, &root, Span::call_site(), &path, text).unwrap();
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
