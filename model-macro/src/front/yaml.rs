//! The YAML front end: `model!(file = "models/parabola.yaml")`.
//!
//! The file is resolved against the calling crate's manifest directory and
//! must lie inside it. Its tree is walked key by key; an unknown or
//! malformed entry is recorded and skipped, so that every mistake in the file
//! is reported at once, each with `path:line:column`.

use std::path::{Path, PathBuf};

use proc_macro2::Span;
use quote::quote;

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
    read_file(&args.path.value(), args.path.span(), "model file")
}

/// Reads the file at `relative` (to the crate's directory, and inside it);
/// `what` names it in messages.
fn read_file(relative: &str, span: Span, what: &str) -> syn::Result<(YamlSource, PathBuf)> {
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
    let mut spec = ModelSpec {
        name: Name {
            text: String::new(),
            loc: w.loc(root),
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
            reads: Vec::new(),
        },
        unreadable: Vec::new(),
    };
    let mut seen: Vec<&str> = Vec::new();
    let (mut urdf, mut locked): (Option<(Name, &YNode)>, Vec<Name>) = (None, Vec::new());
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
                if let Some(path) = w.name(value, "the URDF file's path") {
                    urdf = Some((path, value));
                }
                seen.push(keys::URDF);
            }
            keys::LOCKED | keys::LIMITS => {
                let names = match &value.kind {
                    YKind::Seq(items) => items
                        .iter()
                        .filter_map(|i| w.name(i, "a joint of the URDF"))
                        .collect(),
                    _ => {
                        w.expected(value, "a list of joint names, like `[joint1, joint2]`");
                        Vec::new()
                    }
                };
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
    if let Some((urdf, node)) = urdf {
        w.import_urdf(&mut spec, &urdf, node, &locked, &limits);
    } else if let Some(first) = locked.first().or(limits.first()) {
        cx.error(
            first.loc,
            "`locked` and `limits` name joints of a URDF, but this model has no `urdf`",
        );
    }
    let has_bodies = seen.contains(&keys::BODIES) || seen.contains(&keys::URDF);
    for (key, what) in [
        (keys::NAME, "its name"),
        (keys::COORDINATES, "its coordinates (or `bodies`)"),
        (keys::KINETIC, "its kinetic energy (or `bodies`)"),
    ] {
        if !seen.contains(&key) && (key == keys::NAME || !has_bodies) {
            cx.error(
                w.loc(root),
                format!("missing `{key}`: a model needs {what}"),
            );
        }
    }
    Some(spec)
}

/// Walks the tree, recording problems in the context.
struct Walker<'a> {
    cx: &'a Ctxt,
    span: Span,
}

impl Walker<'_> {
    /// Reads the URDF named by `urdf:` and appends its bodies and joint
    /// coordinates to `spec`; its problems are reported at the `urdf:`
    /// value, each message starting with the URDF's `path:line:column`.
    fn import_urdf(
        &self,
        spec: &mut ModelSpec,
        path: &Name,
        node: &YNode,
        locked: &[Name],
        limits: &[Name],
    ) {
        let loc = self.loc(node);
        let (source, absolute) = match read_file(&path.text, self.span, "URDF file") {
            Ok(read) => read,
            Err(e) => {
                self.cx.error(loc, e.to_string());
                return;
            }
        };
        if let Origin::Yaml { reads, .. } = &mut spec.origin {
            reads.push(absolute.display().to_string());
        }
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
                self.limit_constraints(spec, &imported.limits, limits, &source.display);
            }
            Err(messages) => {
                for m in messages {
                    self.cx.error(loc, m);
                }
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
            keys::APPLIED => {
                spec.applied = w
                    .entries(value, keys::APPLIED)
                    .into_iter()
                    .filter_map(|(coordinate, v)| {
                        Some(Applied {
                            coordinate,
                            expr: w.expr(v)?,
                        })
                    })
                    .collect();
            }
            keys::CONSTRAINTS => spec.constraints = w.constraints(value),
            keys::RESTITUTION => spec.restitution = w.number(value, "`restitution`"),
            keys::INITIAL => {
                spec.initial = w
                    .entries(value, keys::INITIAL)
                    .into_iter()
                    .filter_map(|(name, v)| {
                        let x = w.number(v, &format!("the initial value of `{}`", name.text))?;
                        Some((name, x))
                    })
                    .collect();
            }
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
                    })
                }
                _ => {
                    self.expected(item, "one `position: velocity` entry, like `- x: vx`");
                    None
                }
            })
            .collect()
    }

    /// The constraints `q − lower ≥ 0` (`<joint>_lower`) and `upper − q ≥ 0`
    /// (`<joint>_upper`) of each joint named in `limits:`, from the URDF's
    /// `<limit>`; they take the model's restitution.
    fn limit_constraints(
        &self,
        spec: &mut ModelSpec,
        found: &[super::urdf::Limit],
        wanted: &[Name],
        display: &str,
    ) {
        for name in wanted {
            let Some(limit) = found.iter().find(|l| l.joint == name.text) else {
                self.cx.error(
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
            let q = || node(crate::expr::ExprKind::Name(name.text.clone()));
            let x = |v| node(crate::expr::ExprKind::Num(v));
            use crate::expr::BinOp::Sub;
            for (suffix, h) in [
                (
                    "lower",
                    crate::expr::ExprKind::Binary(Sub, q(), x(limit.lower)),
                ),
                (
                    "upper",
                    crate::expr::ExprKind::Binary(Sub, x(limit.upper), q()),
                ),
            ] {
                spec.constraints.push(Constraint {
                    name: Name {
                        text: format!("{}_{suffix}", name.text),
                        loc,
                    },
                    h: Expr { kind: h, loc },
                    restitution: None,
                    doc: vec![format!(
                        "The {suffix} limit of joint `{}` (from the URDF).",
                        name.text
                    )],
                });
            }
        }
    }

    /// `[x, y, z]`: three expressions.
    fn vector(&self, node: &YNode, what: &str) -> Option<[Expr; 3]> {
        match &node.kind {
            YKind::Seq(items) if items.len() == 3 => {
                let (x, y, z) = (
                    self.expr(&items[0]),
                    self.expr(&items[1]),
                    self.expr(&items[2]),
                );
                Some([x?, y?, z?])
            }
            _ => {
                self.expected(
                    node,
                    &format!("three numbers or expressions `[x, y, z]` for {what}"),
                );
                None
            }
        }
    }

    /// `bodies:`, a list of bodies; each moving joint appends its
    /// coordinate to `spec.coordinates`.
    fn bodies(&self, spec: &mut ModelSpec, node: &YNode) {
        let YKind::Seq(items) = &node.kind else {
            self.expected(
                node,
                "a list of bodies (`- name: ..., parent: ..., joint: ...`)",
            );
            return;
        };
        for item in items {
            if let Some(body) = self.body(spec, item) {
                spec.bodies.push(body);
            }
        }
    }

    fn body(&self, spec: &mut ModelSpec, item: &YNode) -> Option<Body> {
        let YKind::Map(entries) = &item.kind else {
            self.expected(
                item,
                "a body with `name`, `joint`, `mass`, `com` and `inertia`",
            );
            return None;
        };
        let zero = |loc| Expr {
            kind: crate::expr::ExprKind::Num(0.0),
            loc,
        };
        let here = self.loc(item);
        let (mut name, mut parent, mut joint, mut mass) = (None, None, None, None);
        let (mut com, mut inertia) = (None, None);
        let mut ok = true;
        for (key, value) in entries {
            let Some(k) = self.key(key) else { continue };
            match k.text.as_str() {
                keys::NAME => name = self.name(value, "the body"),
                keys::PARENT => {
                    parent = self.name(value, "the parent body (or `world`)");
                    ok &= parent.is_some();
                }
                keys::JOINT => {
                    joint = self.joint(spec, value);
                    ok &= joint.is_some();
                }
                keys::MASS => {
                    mass = self.expr(value);
                    ok &= mass.is_some();
                }
                keys::COM => {
                    com = self.vector(value, "`com`");
                    ok &= com.is_some();
                }
                keys::INERTIA => {
                    inertia = self.inertia(value);
                    ok &= inertia.is_some();
                }
                other => self.cx.error(
                    k.loc,
                    format!(
                        "unknown key `{other}` in a body; a body has {}",
                        keys::BODY_KEYS.join(", ")
                    ),
                ),
            }
        }
        for (missing, key) in [
            (name.is_none(), keys::NAME),
            (joint.is_none() && ok, keys::JOINT),
            (mass.is_none() && ok, keys::MASS),
        ] {
            if missing {
                self.cx.error(here, format!("missing `{key}` in this body"));
            }
        }
        Some(Body {
            name: name?,
            parent: parent.filter(|p| p.text != keys::WORLD),
            joint: joint?,
            mass: mass?,
            com: com.unwrap_or_else(|| [zero(here), zero(here), zero(here)]),
            inertia: inertia.unwrap_or_else(|| std::array::from_fn(|_| zero(here))),
        })
    }

    /// `inertia: [ixx, ixy, ixz, iyy, iyz, izz]`.
    fn inertia(&self, node: &YNode) -> Option<[Expr; 6]> {
        match &node.kind {
            YKind::Seq(items) if items.len() == 6 => {
                let all: Vec<Option<Expr>> = items.iter().map(|i| self.expr(i)).collect();
                let all: Vec<Expr> = all.into_iter().collect::<Option<_>>()?;
                <[Expr; 6]>::try_from(all).ok()
            }
            _ => {
                self.expected(
                    node,
                    "six numbers or expressions `[ixx, ixy, ixz, iyy, iyz, izz]` for `inertia`",
                );
                None
            }
        }
    }

    /// A body's `joint:` mapping; a moving joint declares its coordinate.
    fn joint(&self, spec: &mut ModelSpec, node: &YNode) -> Option<Joint> {
        let YKind::Map(entries) = &node.kind else {
            self.expected(
                node,
                "a joint (`{type: revolute, name: q1, axis: [0, 0, 1]}`)",
            );
            return None;
        };
        let here = self.loc(node);
        let zero = || Expr {
            kind: crate::expr::ExprKind::Num(0.0),
            loc: here,
        };
        let (mut kind, mut name, mut velocity, mut axis) = (None, None, None, None);
        let (mut xyz, mut rpy) = (None, None);
        let mut ok = true;
        for (key, value) in entries {
            let Some(k) = self.key(key) else { continue };
            match k.text.as_str() {
                keys::TYPE => {
                    kind = match value.scalar_text().as_deref() {
                        Some("revolute") => Some(JointKind::Revolute),
                        Some("prismatic") => Some(JointKind::Prismatic),
                        Some("fixed") => Some(JointKind::Fixed),
                        _ => {
                            self.expected(
                                value,
                                &format!("a joint type ({})", keys::JOINT_TYPES.join(", ")),
                            );
                            ok = false;
                            None
                        }
                    }
                }
                keys::NAME => name = self.name(value, "the joint's coordinate"),
                keys::VELOCITY => velocity = self.name(value, "the joint's velocity"),
                keys::AXIS => {
                    axis = self.axis(value);
                    ok &= axis.is_some();
                }
                keys::XYZ => {
                    xyz = self.vector(value, "`xyz`");
                    ok &= xyz.is_some();
                }
                keys::RPY => {
                    rpy = self.vector(value, "`rpy`");
                    ok &= rpy.is_some();
                }
                other => self.cx.error(
                    k.loc,
                    format!(
                        "unknown key `{other}` in a joint; a joint has {}",
                        keys::JOINT_KEYS.join(", ")
                    ),
                ),
            }
        }
        if kind.is_none() && ok {
            self.cx.error(
                here,
                format!(
                    "missing `type` in this joint ({})",
                    keys::JOINT_TYPES.join(", ")
                ),
            );
        }
        let kind = kind?;
        let coordinate = match (kind, name) {
            (JointKind::Fixed, Some(n)) => {
                self.cx
                    .error(n.loc, "a fixed joint has no coordinate to name");
                None
            }
            (JointKind::Fixed, None) => None,
            (_, None) => {
                self.cx
                    .error(here, "missing `name` in this joint: its coordinate's name");
                return None;
            }
            (_, Some(q)) => {
                let v = velocity.clone().unwrap_or_else(|| Name {
                    text: format!("d{}", q.text),
                    loc: q.loc,
                });
                spec.coordinates.push(Coordinate { q, v });
                Some(spec.coordinates.len() - 1)
            }
        };
        if let (JointKind::Fixed, Some(v)) = (kind, &velocity) {
            self.cx
                .error(v.loc, "a fixed joint has no velocity to name");
        }
        let unit = |value| Number { value, loc: here };
        let axis = match (kind, axis) {
            (JointKind::Fixed, _) => [unit(0.0), unit(0.0), unit(1.0)],
            (_, Some(a)) => a,
            (_, None) => {
                if ok {
                    self.cx.error(here, "missing `axis` in this joint");
                }
                return None;
            }
        };
        Some(Joint {
            kind,
            coordinate,
            axis,
            xyz: xyz.unwrap_or_else(|| [zero(), zero(), zero()]),
            rpy: rpy.unwrap_or_else(|| [zero(), zero(), zero()]),
        })
    }

    /// A joint's axis: three numbers, not all zero.
    fn axis(&self, node: &YNode) -> Option<[Number; 3]> {
        let numbers = match &node.kind {
            YKind::Seq(items) if items.len() == 3 => {
                let all: Vec<Option<Number>> = items
                    .iter()
                    .map(|i| self.number(i, "an axis component"))
                    .collect();
                all.into_iter().collect::<Option<Vec<_>>>()?
            }
            _ => {
                self.expected(node, "three numbers `[x, y, z]` for `axis`");
                return None;
            }
        };
        let norm = numbers
            .iter()
            .map(|n| n.value * n.value)
            .sum::<f64>()
            .sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            self.cx.error(
                self.loc(node),
                "a joint's axis must be a finite, non-zero vector",
            );
            return None;
        }
        <[Number; 3]>::try_from(numbers).ok()
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
