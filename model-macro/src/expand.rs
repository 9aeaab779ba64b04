//! The expansion as a chain of stages: front end → checks → lowering →
//! emission. On error, the model's struct and a stub `impl Model` are still
//! emitted beside the errors, so users see their mistakes rather than a
//! cascade of "cannot find type".

use proc_macro2::{TokenStream, TokenTree};

use crate::ctxt::Ctxt;
use crate::front::{inline, yaml};
use crate::lower::Lowered;
use crate::resolve::Resolved;
use crate::scope::Scope;
use crate::spec::ModelSpec;
use crate::{check, emit, lower, resolve};

/// Expands one `model!` invocation.
///
/// With the environment variable `MOREAU_TIMINGS` set, the expansion time
/// of each model is printed to stderr (see it with `cargo build -vv`; touch
/// the model file, or the source of an inline model, to expand it again).
pub(crate) fn model(input: TokenStream) -> TokenStream {
    let start = std::time::Instant::now();
    let output = try_expand(input).unwrap_or_else(syn::Error::into_compile_error);
    if std::env::var_os("MOREAU_TIMINGS").is_some() {
        let name = output
            .clone()
            .into_iter()
            .skip_while(|t| !matches!(t, TokenTree::Ident(i) if i == "struct"))
            .nth(1)
            .map_or_else(|| "?".to_string(), |t| t.to_string());
        eprintln!(
            "moreau::model! {name}: expanded in {:.2} ms",
            start.elapsed().as_secs_f64() * 1e3
        );
    }
    output
}

fn try_expand(input: TokenStream) -> syn::Result<TokenStream> {
    if is_file_form(&input) {
        let args: yaml::FileArgs = syn::parse2(input)?;
        let span = args.path.span();
        let (source, path) = yaml::read(&args)?;
        let root = yaml::parse_tree(&source, span)?;
        let text = source.text.clone();
        let cx = Ctxt::with_locator(source);
        let spec = yaml::build(&cx, &root, span, &path, text);
        finish(cx, spec)
    } else {
        let cx = Ctxt::new();
        let spec = inline::build(&cx, input);
        finish(cx, spec)
    }
}

/// `file = "..."` selects the YAML front end.
fn is_file_form(input: &TokenStream) -> bool {
    let mut trees = input.clone().into_iter();
    matches!(
        (trees.next(), trees.next()),
        (Some(TokenTree::Ident(k)), Some(TokenTree::Punct(p))) if k == "file" && p.as_char() == '='
    )
}

/// The stages after the front end: checks, resolution into typed symbols,
/// lowering. `None` when any of them recorded an error (or, for
/// resolution, met a name the checks should have reported: the caller
/// reports that as an internal error).
pub(crate) fn compile<'a>(cx: &Ctxt, spec: &'a ModelSpec) -> Option<(Resolved<'a>, Lowered)> {
    let scope = Scope::new(spec);
    check::check(cx, spec, &scope);
    if cx.has_errors() {
        return None;
    }
    let model = resolve::resolve(spec, &scope)?;
    let lowered = lower::lower(cx, &model)?;
    Some((model, lowered))
}

fn finish(cx: Ctxt, spec: Option<ModelSpec>) -> syn::Result<TokenStream> {
    let internal = || {
        syn::Error::new(
            proc_macro2::Span::call_site(),
            "moreau::model!: a stage failed without saying why (a bug in the macro; please report it)",
        )
    };
    let Some(spec) = spec else {
        // The front ends give up only after recording why.
        cx.check()?;
        return Err(internal());
    };
    let compiled = compile(&cx, &spec);
    match (cx.check(), compiled) {
        (Ok(()), Some((model, lowered))) => Ok(emit::emit(&model, &lowered)),
        (Ok(()), None) => Err(internal()),
        (Err(errors), _) => {
            let mut out = errors.into_compile_error();
            out.extend(emit::fallback(&spec));
            Ok(out)
        }
    }
}
