//! Tests of the whole pipeline, from model text to emitted tokens.

mod adversarial;
mod fuzz;
mod interp;

use std::str::FromStr;

use moreau_sym::Slot;
use proc_macro2::TokenStream;

use crate::ctxt::Ctxt;
use crate::front::inline;
use crate::lower::Lowered;
use crate::{emit, expand};

/// A model compiled through every stage, with what the tests need to
/// evaluate it independently.
pub(crate) struct Compiled {
    pub tokens: TokenStream,
    pub lowered: Lowered,
    pub n: usize,
    pub k: usize,
    pub inputs: usize,
    /// Parameter fields and their defaults.
    pub fields: Vec<(String, f64)>,
}

impl Compiled {
    /// The graph's variable values (coordinates, velocities, time, inputs,
    /// parameters at their defaults).
    pub fn variables(&self, q: &[f64], v: &[f64], t: f64, u: &[f64]) -> Vec<f64> {
        let mut vars = q.to_vec();
        vars.extend(v);
        vars.push(t);
        vars.extend(u);
        vars.extend(self.fields.iter().map(|(_, x)| x));
        vars
    }

    /// One output, by `moreau-sym`'s evaluator.
    pub fn reference(&self, slot: Slot, vars: &[f64]) -> f64 {
        let id = self.lowered.mechanics.get(slot);
        self.lowered.graph.eval(&[id], vars)[0]
    }
}

/// Compiles an inline model (the macro's input tokens as text); the errors
/// as text when it has some.
pub(crate) fn compile_inline(text: &str) -> Result<Compiled, String> {
    let input = TokenStream::from_str(text).map_err(|e| e.to_string())?;
    let cx = Ctxt::new();
    let Some(spec) = inline::build(&cx, input) else {
        return Err(cx.check().err().map_or_else(String::new, |e| e.to_string()));
    };
    let compiled = expand::compile(&cx, &spec);
    cx.check().map_err(|e| e.to_string())?;
    let (model, lowered) = compiled.ok_or("a stage failed without an error")?;
    let tokens = emit::emit(&model, &lowered);
    Ok(Compiled {
        tokens,
        n: model.n(),
        k: model.k(),
        inputs: model.layout.inputs,
        fields: spec
            .parameters
            .iter()
            .map(|p| (p.name.text.clone(), p.default.value))
            .collect(),
        lowered,
    })
}

/// SplitMix64: reproducible draws for the generated test cases, without a
/// dependency.
pub(crate) struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`0` for `n = 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    /// Uniform in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64)
    }

    /// One of `items`.
    pub fn pick<'a>(&mut self, items: &[&'a str]) -> &'a str {
        items[self.below(items.len())]
    }
}
