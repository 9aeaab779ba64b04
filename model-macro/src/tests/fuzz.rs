//! Macro fuzz: random and adversarial model texts through both front ends
//! and every later stage, as a library (not through rustc). Whatever the
//! text, the pipeline returns tokens or errors; it never panics, and a
//! rejected model always carries at least one message.
//!
//! Cases: mutations of valid models (bytes inserted, deleted, duplicated),
//! deep nesting, huge and non-finite constants, adversarial names, random
//! bytes as YAML. `MOREAU_FUZZ_CASES` runs longer (default 400 per front
//! end), `MOREAU_FUZZ_SEED` picks another seed.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::str::FromStr;

use proc_macro2::{Span, TokenStream};

use super::Rng;
use crate::ctxt::Ctxt;
use crate::front::yaml_tree::YamlSource;
use crate::front::{inline, yaml};
use crate::{emit, expand};

/// Runs every stage on a spec-producing front end; `Ok(())` when the model
/// compiled, `Err(message)` when it was rejected.
fn run(cx: Ctxt, spec: Option<crate::spec::ModelSpec>) -> Result<(), String> {
    let Some(spec) = spec else {
        return match cx.check() {
            Err(e) => Err(e.to_string()),
            Ok(()) => Err(String::new()),
        };
    };
    let compiled = expand::compile(&cx, &spec);
    match (cx.check(), compiled) {
        (Ok(()), Some((model, lowered))) => {
            let _ = emit::emit(&model, &lowered);
            Ok(())
        }
        (Err(e), _) => {
            let _ = emit::fallback(&spec);
            Err(e.to_string())
        }
        (Ok(()), None) => Err(String::new()),
    }
}

fn inline_text(text: &str) -> Result<(), String> {
    let Ok(tokens) = TokenStream::from_str(text) else {
        return Err("not Rust tokens".into()); // rustc's lexer would reject it first
    };
    let cx = Ctxt::new();
    let spec = inline::build(&cx, tokens);
    run(cx, spec)
}

fn yaml_text(text: &str) -> Result<(), String> {
    let source = YamlSource {
        display: "fuzz.yaml".into(),
        text: text.to_string(),
    };
    let root = match source.parse() {
        Ok(root) => root,
        Err(e) => return Err(e.to_string()),
    };
    let cx = Ctxt::with_locator(source);
    let spec = yaml::build(
        &cx,
        &root,
        Span::call_site(),
        Path::new("fuzz.yaml"),
        text.into(),
    );
    run(cx, spec)
}

const INLINE: &str = "pub struct Arm; coordinates { th1: w1, th2: w2 }
    parameters { m: 1.0, l: 2.0, g: 9.81 }
    let c = cos(th1 - th2);
    kinetic = 0.5 * m * l^2 * (w1^2 + w2^2 + 2 * c * w1 * w2) + 0.5 * w1^2;
    potential = -m * g * l * (cos(th1) + cos(th2));
    applied { th1: -0.1 * w1 }
    constraints { floor: l * (cos(th1) + cos(th2)) + 1.5 >= 0 }
    restitution = 0.5;";

const YAML: &str = "name: Arm
coordinates:
  - th1: w1
  - th2: w2
parameters:
  m: 1.0
  l: 2.0
definitions:
  c: cos(th1 - th2)
kinetic: 0.5 * m * l^2 * (w1^2 + w2^2 + 2 * c * w1 * w2) + 0.5 * w1^2
potential: -m * 9.81 * l * (cos(th1) + cos(th2))
applied:
  th1: -0.1 * w1
constraints:
  - name: floor
    h: l * (cos(th1) + cos(th2)) + 1.5
restitution: 0.5
";

/// Pieces a mutation inserts: operators, brackets, adversarial names,
/// huge and non-finite constants, deep nesting, keywords, unicode.
const PIECES: [&str; 28] = [
    "(",
    ")",
    "^",
    "*",
    "/ 0",
    "+",
    "-",
    ",",
    ";",
    ":",
    "{",
    "}",
    "1e308 * 1e308",
    "ln(0)",
    "sqrt(-1)",
    "2^1024",
    "sin_x_sq",
    "a0",
    "match",
    "None",
    "θ",
    "é",
    "\n",
    "  ",
    "#",
    "1e999",
    "((((((((((((((((((((x))))))))))))))))))))",
    "0 / 0",
];

/// A char boundary of `s` at or before `i`.
fn boundary(s: &str, mut i: usize) -> usize {
    i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn mutate(rng: &mut Rng, base: &str) -> String {
    let mut s = base.to_string();
    for _ in 0..1 + rng.below(4) {
        let at = boundary(&s, rng.below(s.len() + 1));
        match rng.below(5) {
            0 => s.insert_str(at, PIECES[rng.below(PIECES.len())]),
            1 => {
                let end = boundary(&s, at + rng.below(12));
                s.replace_range(at..end, "");
            }
            2 => {
                let end = boundary(&s, at + rng.below(20));
                let piece = s[at..end].to_string();
                s.insert_str(end, &piece);
            }
            3 => {
                let depth = 1 + rng.below(400);
                let nested = format!("{}x{}", "(".repeat(depth), ")".repeat(depth));
                s.insert_str(at, &nested);
            }
            _ => {
                let byte = (rng.next() & 0x7f) as u8 as char;
                s.insert(at, byte);
            }
        }
    }
    s
}

fn cases() -> (usize, u64) {
    let var = |k: &str| std::env::var(k).ok().and_then(|s| s.parse::<u64>().ok());
    let n = var("MOREAU_FUZZ_CASES").unwrap_or(400);
    (
        usize::try_from(n).unwrap_or(usize::MAX),
        var("MOREAU_FUZZ_SEED").unwrap_or(7),
    )
}

/// One case: no panic, and a rejection says something.
fn check(front: &str, text: &str, f: fn(&str) -> Result<(), String>) {
    match catch_unwind(AssertUnwindSafe(|| f(text))) {
        Ok(Ok(())) => {}
        Ok(Err(message)) => assert!(
            !message.is_empty(),
            "{front}: rejected without a message:\n{text}"
        ),
        Err(_) => panic!("{front}: the pipeline panicked on:\n{text}"),
    }
}

#[test]
fn mutated_inline_models_never_panic() {
    let (n, seed) = cases();
    let mut rng = Rng(seed);
    assert!(inline_text(INLINE).is_ok(), "the base model compiles");
    for _ in 0..n {
        check("inline", &mutate(&mut rng, INLINE), inline_text);
    }
}

#[test]
fn mutated_and_random_yaml_never_panics() {
    let (n, seed) = cases();
    let mut rng = Rng(seed ^ 0xa5a5);
    assert!(yaml_text(YAML).is_ok(), "the base model compiles");
    for _ in 0..n {
        check("yaml", &mutate(&mut rng, YAML), yaml_text);
        let bytes: String = (0..rng.below(200))
            .map(|_| char::from_u32(rng.below(0x3000) as u32).unwrap_or('?'))
            .collect();
        check("yaml", &bytes, yaml_text);
    }
}

/// The reproducers of the issue: 2000 nested parentheses (which crashed
/// rustc with SIGSEGV) and constants that fold to non-finite values are
/// errors, not crashes.
#[test]
fn deep_nesting_and_non_finite_constants_are_errors() {
    let deep = format!("{}y{}", "(".repeat(2000), ")".repeat(2000));
    let text =
        format!("name: Deep\ncoordinates:\n  - y: vy\nkinetic: 0.5 * vy^2\npotential: {deep}\n");
    let err = yaml_text(&text).unwrap_err();
    assert!(err.contains("nested more than 256 levels"), "{err}");
    for potential in ["x / 0", "(1/0)*x", "sqrt(-1)*x", "ln(0)*x", "2^1024*x"] {
        let text = format!(
            "pub struct C; coordinates {{ x: vx }} kinetic = 0.5 * vx^2; potential = {potential};"
        );
        let err = inline_text(&text).unwrap_err();
        assert!(
            err.contains("not a finite number") || err.contains("division by zero"),
            "{potential}: {err}"
        );
    }
}
