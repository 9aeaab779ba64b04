//! The keys `urdf`, `locked` and `limits`, read alike by both front ends
//! (YAML `urdf: path`, inline `urdf = "path";`): the URDF is found like a
//! model file (relative to the crate's directory and inside it), recorded
//! in [`ModelSpec::reads`] so that editing it rebuilds the model, imported
//! by [`super::urdf::import`], and appended to the model: its bodies after
//! the written ones, its joint coordinates after the written coordinates,
//! the constraints of its `limits` after the written constraints.

use std::path::{Path, PathBuf};

use proc_macro2::Span;

use super::yaml_tree::YamlSource;
use crate::ctxt::Ctxt;
use crate::expr::{BinOp, Expr, ExprKind};
use crate::spec::{Constraint, ModelSpec, Name};

/// Reads the file at `relative` (to the crate's directory, and inside it);
/// `what` names it in messages, which point at `span`.
pub(crate) fn read_crate_file(
    relative: &str,
    span: Span,
    what: &str,
) -> syn::Result<(YamlSource, PathBuf)> {
    let relative = relative.to_string();
    let manifest = std::env::var("CARGO_MANIFEST_DIR")
        .map_err(|_| syn::Error::new(span, "CARGO_MANIFEST_DIR is not set; build with cargo"))?;
    let root = Path::new(&manifest).canonicalize().map_err(|e| {
        syn::Error::new(
            span,
            format!("cannot resolve the crate directory `{manifest}`: {e}"),
        )
    })?;
    let path = root.join(&relative).canonicalize().map_err(|e| {
        syn::Error::new(
            span,
            format!(
                "cannot read {what} `{relative}` (paths are relative to the crate's directory): {e}"
            ),
        )
    })?;
    if !path.starts_with(&root) {
        return Err(syn::Error::new(
            span,
            format!(
                "{what} `{relative}` is outside this crate; keep model files inside the crate's directory"
            ),
        ));
    }
    let text = std::fs::read_to_string(&path)
        .map_err(|e| syn::Error::new(span, format!("cannot read {what} `{relative}`: {e}")))?;
    Ok((
        YamlSource {
            display: relative,
            text,
        },
        path,
    ))
}

/// Reads the URDF named `path` and appends its bodies and joint coordinates
/// to `spec`, with the constraints of the joints named in `limits`;
/// `locked` names the joints held at zero. Every problem is reported at
/// `path` (each message of the URDF's starting with its
/// `path:line:column`), except a joint name of `locked` or `limits` the
/// URDF does not have, reported at that name.
pub(crate) fn import_urdf(
    cx: &Ctxt,
    spec: &mut ModelSpec,
    path: &Name,
    locked: &[Name],
    limits: &[Name],
) {
    let loc = path.loc;
    let (source, absolute) = match read_crate_file(&path.text, loc.span, "URDF file") {
        Ok(read) => read,
        Err(e) => {
            cx.error(loc, e.to_string());
            return;
        }
    };
    spec.reads.push(absolute.display().to_string());
    match super::urdf::import(&source.display, &source.text, loc, locked) {
        Ok(imported) => {
            let shift = spec.coordinates.len();
            spec.coordinates.extend(imported.coordinates);
            for mut b in imported.bodies {
                if let Some(c) = &mut b.joint.coordinate {
                    *c += shift;
                }
                spec.bodies.push(b);
            }
            spec.bodies_loc.get_or_insert(loc);
            limit_constraints(cx, spec, &imported.limits, limits, &source.display);
        }
        Err(problems) => {
            for (at, message) in problems {
                cx.error(at, message);
            }
        }
    }
}

/// The constraints `q − lower ≥ 0` (`<joint>_lower`) and `upper − q ≥ 0`
/// (`<joint>_upper`) of each joint named in `limits`, from the URDF's
/// `<limit>`; they take the model's restitution.
fn limit_constraints(
    cx: &Ctxt,
    spec: &mut ModelSpec,
    found: &[super::urdf::Limit],
    wanted: &[Name],
    display: &str,
) {
    for name in wanted {
        let Some(limit) = found
            .iter()
            .find(|l| super::urdf::names_joint(&name.text, &l.joint))
        else {
            cx.error(
                name.loc,
                format!(
                    "`{}` is not a moving joint of {display} with a `<limit lower=… upper=…>`",
                    name.text
                ),
            );
            continue;
        };
        let loc = name.loc;
        let node = |kind| Box::new(Expr { kind, loc });
        let q = || node(ExprKind::Name(limit.coordinate.clone()));
        let x = |v| node(ExprKind::Num(v));
        for (suffix, h) in [
            ("lower", ExprKind::Binary(BinOp::Sub, q(), x(limit.lower))),
            ("upper", ExprKind::Binary(BinOp::Sub, x(limit.upper), q())),
        ] {
            spec.constraints.push(Constraint {
                name: Name {
                    text: format!("{}_{suffix}", limit.coordinate),
                    loc,
                },
                h: Expr { kind: h, loc },
                restitution: None,
                doc: vec![format!(
                    "The {suffix} limit of joint `{}` (from the URDF).",
                    limit.joint
                )],
            });
        }
    }
}
