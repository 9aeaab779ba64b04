//! The YAML front end: `model!(file = "models/parabola.yaml")`.
//!
//! The file is resolved against the calling crate's manifest directory and
//! must lie inside it. Its tree is walked key by key; an unknown or
//! malformed entry is recorded and skipped, so that every mistake in the file
//! is reported at once, each with `path:line:column`. The kinematic tree
//! (`bodies`) is read in `bodies.rs`, a URDF (`urdf`, `locked`, `limits`)
//! by `front/urdf_keys.rs`, which the inline front end shares.

mod bodies;

use std::path::{Path, PathBuf};

use proc_macro2::Span;
use quote::quote;

use super::urdf_keys::{import_urdf, read_crate_file};
use super::yaml_tree::{YKind, YNode, YamlSource};
use crate::ctxt::{Ctxt, Locate};
use crate::expr::{self, Expr};
use crate::keys;
use crate::loc::Loc;
use crate::loc::YamlPos;
use crate::spec::{
    Applied, Body, Constraint, Coordinate, Definition, Joint, JointKind, ModelSpec, Name, Number,
    Origin, Parameter,
};

/// The arguments of the file form: `file = "path"`.
pub(crate) struct FileArgs {
    pub path: syn::LitStr,
}

impl syn::parse::Parse for FileArgs {
    fn parse(input: syn::parse::ParseStream<'_>) -> syn::Result<Self> {
        let key: syn::Ident = input.parse()?;
        if key != "file" {
            return Err(syn::Error::new(
                key.span(),
                format!("expected `file = \"models/...yaml\"` or an inline model, found `{key}`"),
            ));
        }
        input.parse::<syn::Token![=]>()?;
        let path: syn::LitStr = input.parse()?;
        input.parse::<Option<syn::Token![,]>>()?;
        if !input.is_empty() {
            return Err(input.error("unexpected tokens after the file path"));
        }
        Ok(FileArgs { path })
    }
}

/// Finds and reads the model file. Errors (missing, unreadable, outside the
/// crate) point at the path literal.
pub(crate) fn read(args: &FileArgs) -> syn::Result<(YamlSource, PathBuf)> {
    read_crate_file(&args.path.value(), args.path.span(), "model file")
}

/// Parses the YAML text; a syntax error is reported with its position.
pub(crate) fn parse_tree(source: &YamlSource, span: Span) -> syn::Result<YNode> {
    source.parse().map_err(|e| {
        let at = e
            .location()
            .map(|l| format!("{}:{}:{}", source.display, l.line(), l.column()))
            .unwrap_or_else(|| source.display.clone());
        syn::Error::new(span, format!("{at}: invalid YAML: {e}"))
    })
}

/// Builds the model from the document tree. Returns `None` only when the
/// document is not a mapping at all.
pub(crate) fn build(
    cx: &Ctxt,
    root: &YNode,
    span: Span,
    path: &Path,
    text: String,
) -> Option<ModelSpec> {
    let w = Walker { cx, span };
    let YKind::Map(entries) = &root.kind else {
        cx.error(
            w.loc(root),
            format!(
                "a model file is a mapping of keys ({}), found {}",
                keys::TOP_LEVEL.join(", "),
                root.shape()
            ),
        );
        return None;
    };
    let mut spec = empty_spec(w.loc(root), path, text);
    let mut seen: Vec<&str> = Vec::new();
    let (mut urdf, mut locked): (Option<Name>, Vec<Name>) = (None, Vec::new());
    let mut limits: Vec<Name> = Vec::new();
    for (key, value) in entries {
        let Some(k) = w.key(key) else { continue };
        if let Some(first) = seen.iter().find(|s| **s == k.text) {
            cx.error(k.loc, format!("duplicate key `{first}`"));
            continue;
        }
        match k.text.as_str() {
            // Read after the other keys, whatever their order.
            keys::URDF => {
                urdf = w.name(value, "the URDF file's path");
                seen.push(keys::URDF);
            }
            keys::LOCKED | keys::LIMITS => {
                let names = w.joint_names(value);
                if k.text == keys::LOCKED {
                    locked = names;
                    seen.push(keys::LOCKED);
                } else {
                    limits = names;
                    seen.push(keys::LIMITS);
                }
            }
            _ => {
                if let Some(known) = w.top_level(&mut spec, &k, value) {
                    seen.push(known);
                }
            }
        }
    }
    if let Some(urdf) = urdf {
        import_urdf(cx, &mut spec, &urdf, &locked, &limits);
    } else if seen.contains(&keys::URDF) {
        // A malformed `urdf` value has been reported.
    } else if let Some(first) = locked.first().or(limits.first()) {
        cx.error(
            first.loc,
            "`locked` and `limits` name joints of a URDF, but this model has no `urdf`",
        );
    }
    check_required(&w, root, &seen);
    Some(spec)
}

/// A model with nothing read yet, located at the document's root.
fn empty_spec(loc: Loc, path: &Path, text: String) -> ModelSpec {
    ModelSpec {
        name: Name {
            text: String::new(),
            loc,
        },
        vis: quote!(pub),
        doc: Vec::new(),
        coordinates: Vec::new(),
        parameters: Vec::new(),
        inputs: Vec::new(),
        definitions: Vec::new(),
        kinetic: None,
        potential: None,
        applied: Vec::new(),
        constraints: Vec::new(),
        restitution: None,
        initial: Vec::new(),
        bodies: Vec::new(),
        gravity: None,
        bodies_loc: None,
        origin: Origin::Yaml {
            path: path.display().to_string(),
            text,
        },
        reads: Vec::new(),
        unreadable: Vec::new(),
    }
}

/// The keys every model needs: a name, and coordinates and a kinetic
/// energy unless a kinematic tree (`bodies` or `urdf`) gives them.
fn check_required(w: &Walker<'_>, root: &YNode, seen: &[&str]) {
    let has_bodies = seen.contains(&keys::BODIES) || seen.contains(&keys::URDF);
    for (key, what) in [
        (keys::NAME, "its name"),
        (keys::COORDINATES, "its coordinates (or `bodies`)"),
        (keys::KINETIC, "its kinetic energy (or `bodies`)"),
    ] {
        if !seen.contains(&key) && (key == keys::NAME || !has_bodies) {
            w.cx.error(
                w.loc(root),
                format!("missing `{key}`: a model needs {what}"),
            );
        }
    }
}

/// Walks the tree, recording problems in the context.
struct Walker<'a> {
    cx: &'a Ctxt,
    span: Span,
}

impl Walker<'_> {
    /// A list of joint names of the URDF (`locked`, `limits`).
    fn joint_names(&self, value: &YNode) -> Vec<Name> {
        match &value.kind {
            YKind::Seq(items) => items
                .iter()
                .filter_map(|i| self.name(i, "a joint of the URDF"))
                .collect(),
            _ => {
                self.expected(value, "a list of joint names, like `[joint1, joint2]`");
                Vec::new()
            }
        }
    }

    /// `parameters:`, a mapping of names to default values.
    fn parameters(&self, value: &YNode) -> Vec<Parameter> {
        let w = self;
        w.entries(value, keys::PARAMETERS)
            .into_iter()
            .filter_map(|(name, v)| {
                let default = w.number(v, &format!("parameter `{}`", name.text))?;
                Some(Parameter {
                    name,
                    default,
                    doc: Vec::new(),
                })
            })
            .collect()
    }

    /// `applied:`, a mapping of coordinates to expressions.
    fn applied(&self, value: &YNode) -> Vec<Applied> {
        self.entries(value, keys::APPLIED)
            .into_iter()
            .filter_map(|(coordinate, v)| {
                Some(Applied {
                    coordinate,
                    expr: self.expr(v)?,
                })
            })
            .collect()
    }

    /// `initial:`, a mapping of coordinates and velocities to numbers.
    fn initial(&self, value: &YNode) -> Vec<(Name, Number)> {
        self.entries(value, keys::INITIAL)
            .into_iter()
            .filter_map(|(name, v)| {
                let x = self.number(v, &format!("the initial value of `{}`", name.text))?;
                Some((name, x))
            })
            .collect()
    }

    /// Reads one top-level entry into `spec`; the key's constant, or `None`
    /// (after recording why) when the key is unknown.
    fn top_level(&self, spec: &mut ModelSpec, k: &Name, value: &YNode) -> Option<&'static str> {
        let (w, cx) = (self, self.cx);
        match k.text.as_str() {
            keys::NAME => {
                if let Some(name) = w.name(value, "the model's name") {
                    spec.name = name;
                }
            }
            keys::DOC => match value.scalar_text() {
                Some(doc) => spec.doc = doc.lines().map(str::to_string).collect(),
                None => w.expected(value, "a text for `doc`"),
            },
            keys::COORDINATES => {
                // Joint coordinates (when `bodies` came first) go after
                // the written ones.
                let mut written = w.coordinates(value);
                let shift = written.len();
                for b in &mut spec.bodies {
                    if let Some(c) = &mut b.joint.coordinate {
                        *c += shift;
                    }
                }
                written.append(&mut spec.coordinates);
                spec.coordinates = written;
            }
            keys::BODIES => {
                spec.bodies_loc = Some(w.loc(value));
                w.bodies(spec, value);
            }
            keys::GRAVITY => spec.gravity = w.vector(value, "`gravity`"),
            keys::PARAMETERS => spec.parameters = w.parameters(value),
            keys::INPUTS => match &value.kind {
                YKind::Seq(items) => {
                    spec.inputs = items.iter().filter_map(|i| w.name(i, "an input")).collect();
                }
                YKind::Null => {}
                _ => w.expected(value, "a list of input names, like `[u1, u2]`"),
            },
            keys::DEFINITIONS => {
                for (name, v) in w.entries(value, keys::DEFINITIONS) {
                    match w.expr(v) {
                        Some(expr) => spec.definitions.push(Definition { name, expr }),
                        None => spec.unreadable.push(name),
                    }
                }
            }
            keys::KINETIC => spec.kinetic = w.expr(value),
            keys::POTENTIAL => spec.potential = w.expr(value),
            keys::APPLIED => spec.applied = w.applied(value),
            keys::CONSTRAINTS => spec.constraints = w.constraints(value),
            keys::RESTITUTION => spec.restitution = w.number(value, "`restitution`"),
            keys::INITIAL => spec.initial = w.initial(value),
            keys::FORCES_RENAMED => {
                cx.error(k.loc, keys::forces_renamed());
                return None;
            }
            other => {
                cx.error(
                    k.loc,
                    format!(
                        "unknown key `{other}`; a model has {}",
                        keys::TOP_LEVEL.join(", ")
                    ),
                );
                return None;
            }
        }
        keys::TOP_LEVEL.iter().find(|t| **t == k.text).copied()
    }

    fn loc(&self, node: &YNode) -> Loc {
        Loc {
            span: self.span,
            node: Some(node.pos()),
        }
    }

    fn expected(&self, node: &YNode, what: &str) {
        self.cx.error(
            self.loc(node),
            format!("expected {what}, found {}", node.shape()),
        );
    }

    fn key(&self, node: &YNode) -> Option<Name> {
        match &node.kind {
            YKind::Str(s) => Some(Name {
                text: s.clone(),
                loc: self.loc(node),
            }),
            _ => {
                self.expected(node, "a key");
                None
            }
        }
    }

    fn name(&self, node: &YNode, what: &str) -> Option<Name> {
        match &node.kind {
            YKind::Str(s) => Some(Name {
                text: s.clone(),
                loc: self.loc(node),
            }),
            _ => {
                self.expected(node, &format!("a name for {what}"));
                None
            }
        }
    }

    fn number(&self, node: &YNode, what: &str) -> Option<Number> {
        match node.kind {
            YKind::Num(value) => Some(Number {
                value,
                loc: self.loc(node),
            }),
            _ => {
                self.expected(node, &format!("a number for {what}"));
                None
            }
        }
    }

    fn expr(&self, node: &YNode) -> Option<Expr> {
        let Some(text) = node.scalar_text() else {
            self.expected(node, "an expression");
            return None;
        };
        let loc = self.loc(node);
        let toks = expr::tokenize_str(self.cx, &text, loc)?;
        expr::parse(self.cx, &toks, loc)
    }

    /// The entries of a `name: value` mapping, in order.
    fn entries<'n>(&self, node: &'n YNode, section: &str) -> Vec<(Name, &'n YNode)> {
        match &node.kind {
            YKind::Map(entries) => entries
                .iter()
                .filter_map(|(k, v)| Some((self.name(k, &format!("an entry of `{section}`"))?, v)))
                .collect(),
            YKind::Null => Vec::new(),
            _ => {
                self.expected(
                    node,
                    &format!("a mapping of `name: value` entries for `{section}`"),
                );
                Vec::new()
            }
        }
    }

    fn coordinates(&self, node: &YNode) -> Vec<Coordinate> {
        let YKind::Seq(items) = &node.kind else {
            self.expected(
                node,
                "a list of `position: velocity` entries for `coordinates`",
            );
            return Vec::new();
        };
        items
            .iter()
            .filter_map(|item| match &item.kind {
                YKind::Map(entries) if entries.len() == 1 => {
                    let (q, v) = &entries[0];
                    Some(Coordinate {
                        q: self.name(q, "a coordinate")?,
                        v: self.name(v, "a velocity")?,
                        joint: None,
                    })
                }
                _ => {
                    self.expected(item, "one `position: velocity` entry, like `- x: vx`");
                    None
                }
            })
            .collect()
    }

    fn constraints(&self, node: &YNode) -> Vec<Constraint> {
        let YKind::Seq(items) = &node.kind else {
            self.expected(node, "a list of constraints (`- name: ..., h: ...`)");
            return Vec::new();
        };
        items
            .iter()
            .filter_map(|item| self.constraint(item))
            .collect()
    }

    fn constraint(&self, item: &YNode) -> Option<Constraint> {
        let YKind::Map(entries) = &item.kind else {
            self.expected(item, "a constraint with `name` and `h`");
            return None;
        };
        let (mut name, mut h, mut restitution, mut complete) = (None, None, None, true);
        for (key, value) in entries {
            let Some(k) = self.key(key) else { continue };
            match k.text.as_str() {
                keys::NAME => name = self.name(value, "the constraint"),
                keys::H => {
                    h = self.expr(value);
                    complete &= h.is_some();
                }
                keys::RESTITUTION => restitution = self.number(value, "`restitution`"),
                other => self.cx.error(
                    k.loc,
                    format!("unknown key `{other}` in a constraint; a constraint has name, h, restitution"),
                ),
            }
        }
        if name.is_none() {
            self.cx
                .error(self.loc(item), "missing `name` in this constraint");
        }
        if h.is_none() && complete {
            self.cx.error(
                self.loc(item),
                "missing `h` (the gap, `h >= 0`) in this constraint",
            );
        }
        Some(Constraint {
            name: name?,
            h: h?,
            restitution,
            doc: Vec::new(),
        })
    }
}

/// The error context locates YAML errors through the source, handed to it
/// as a value (`Ctxt::with_locator`).
impl Locate for YamlSource {
    fn describe(&self, pos: YamlPos) -> String {
        YamlSource::describe(self, pos)
    }

    fn display(&self) -> &str {
        &self.display
    }
}
