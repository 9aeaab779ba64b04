//! The model text in the YAML model language, for
//! `ModelInfo::source`: a YAML model keeps its file's text verbatim; an inline
//! model is printed here, in canonical form, so that any model can be fed to
//! the CasADi reference script.

use std::fmt::Write;

use crate::expr::fmt_number;
use crate::keys;
use crate::spec::{Body, JointKind, ModelSpec, Origin};

/// The model's text in the YAML language.
pub(crate) fn source(spec: &ModelSpec) -> String {
    match &spec.origin {
        Origin::Yaml { text, .. } => text.clone(),
        Origin::Inline => canonical(spec),
    }
}

/// Prints an inline model as YAML. Expressions are double-quoted (they never
/// contain `"` or `\`), so no YAML indicator can be misread.
fn canonical(spec: &ModelSpec) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{}: {}", keys::NAME, spec.name.text);
    if !spec.doc.is_empty() {
        let doc = spec
            .doc
            .join(" ")
            .replace('\\', "\\\\")
            .replace('"', "\\\"");
        let _ = writeln!(s, "{}: \"{doc}\"", keys::DOC);
    }
    // Joint coordinates are declared by their bodies.
    let joints: Vec<usize> = spec
        .bodies
        .iter()
        .filter_map(|b| b.joint.coordinate)
        .collect();
    let written: Vec<_> = (0..spec.coordinates.len())
        .filter(|i| !joints.contains(i))
        .map(|i| &spec.coordinates[i])
        .collect();
    if !written.is_empty() || spec.bodies.is_empty() {
        let _ = writeln!(s, "{}:", keys::COORDINATES);
    }
    for c in written {
        let _ = writeln!(s, "  - {}: {}", c.q.text, c.v.text);
    }
    if !spec.parameters.is_empty() {
        let _ = writeln!(s, "{}:", keys::PARAMETERS);
        for p in &spec.parameters {
            let _ = writeln!(s, "  {}: {}", p.name.text, fmt_number(p.default.value));
        }
    }
    if !spec.inputs.is_empty() {
        let names: Vec<&str> = spec.inputs.iter().map(|i| i.text.as_str()).collect();
        let _ = writeln!(s, "{}: [{}]", keys::INPUTS, names.join(", "));
    }
    if !spec.definitions.is_empty() {
        let _ = writeln!(s, "{}:", keys::DEFINITIONS);
        for d in &spec.definitions {
            let _ = writeln!(s, "  {}: \"{}\"", d.name.text, d.expr);
        }
    }
    if let Some(g) = &spec.gravity {
        let _ = writeln!(s, "{}: {}", keys::GRAVITY, list(g));
    }
    if !spec.bodies.is_empty() {
        let _ = writeln!(s, "{}:", keys::BODIES);
    }
    for b in &spec.bodies {
        body(&mut s, spec, b);
    }
    if let Some(k) = &spec.kinetic {
        let _ = writeln!(s, "{}: \"{k}\"", keys::KINETIC);
    }
    if let Some(p) = &spec.potential {
        let _ = writeln!(s, "{}: \"{p}\"", keys::POTENTIAL);
    }
    if !spec.applied.is_empty() {
        let _ = writeln!(s, "{}:", keys::APPLIED);
        for f in &spec.applied {
            let _ = writeln!(s, "  {}: \"{}\"", f.coordinate.text, f.expr);
        }
    }
    if !spec.constraints.is_empty() {
        let _ = writeln!(s, "{}:", keys::CONSTRAINTS);
        for c in &spec.constraints {
            let _ = writeln!(s, "  - {}: {}", keys::NAME, c.name.text);
            let _ = writeln!(s, "    {}: \"{}\"", keys::H, c.h);
            if let Some(e) = c.restitution {
                let _ = writeln!(s, "    {}: {}", keys::RESTITUTION, fmt_number(e.value));
            }
        }
    }
    if let Some(e) = spec.restitution {
        let _ = writeln!(s, "{}: {}", keys::RESTITUTION, fmt_number(e.value));
    }
    if !spec.initial.is_empty() {
        let _ = writeln!(s, "{}:", keys::INITIAL);
        for (name, x) in &spec.initial {
            let _ = writeln!(s, "  {}: {}", name.text, fmt_number(x.value));
        }
    }
    s
}

/// `["e1", "e2", …]`: expressions as a YAML flow list.
fn list(items: &[crate::expr::Expr]) -> String {
    let quoted: Vec<String> = items.iter().map(|e| format!("\"{e}\"")).collect();
    format!("[{}]", quoted.join(", "))
}

/// One body of the tree, as a YAML list entry.
fn body(s: &mut String, spec: &ModelSpec, b: &Body) {
    let j = &b.joint;
    let _ = writeln!(s, "  - {}: {}", keys::NAME, b.name.text);
    if let Some(p) = &b.parent {
        let _ = writeln!(s, "    {}: {}", keys::PARENT, p.text);
    }
    let kind = match j.kind {
        JointKind::Revolute => "revolute",
        JointKind::Prismatic => "prismatic",
        JointKind::Fixed => "fixed",
    };
    let _ = write!(s, "    {}: {{{}: {kind}", keys::JOINT, keys::TYPE);
    if let Some(m) = &j.mimic {
        let _ = write!(
            s,
            ", {}: {}, {}: {}, {}: {}",
            keys::MIMIC,
            m.coordinate.text,
            keys::MULTIPLIER,
            fmt_number(m.multiplier.value),
            keys::OFFSET,
            fmt_number(m.offset.value),
        );
    }
    if let Some(i) = j.coordinate {
        let c = &spec.coordinates[i];
        let _ = write!(
            s,
            ", {}: {}, {}: {}",
            keys::NAME,
            c.q.text,
            keys::VELOCITY,
            c.v.text,
        );
    }
    if j.kind != JointKind::Fixed {
        let axis: Vec<String> = j.axis.iter().map(|n| fmt_number(n.value)).collect();
        let _ = write!(s, ", {}: [{}]", keys::AXIS, axis.join(", "));
    }
    let _ = writeln!(
        s,
        ", {}: {}, {}: {}}}",
        keys::XYZ,
        list(&j.xyz),
        keys::RPY,
        list(&j.rpy)
    );
    let _ = writeln!(s, "    {}: \"{}\"", keys::MASS, b.mass);
    let _ = writeln!(s, "    {}: {}", keys::COM, list(&b.com));
    let _ = writeln!(s, "    {}: {}", keys::INERTIA, list(&b.inertia));
}

#[cfg(test)]
mod tests {
    use crate::ctxt::Ctxt;
    use crate::front::{inline, yaml, yaml_tree::YamlSource};

    /// An inline model printed as YAML reads back, through the YAML front
    /// end, as the same model printed the same way.
    #[test]
    fn canonical_text_round_trips_through_the_yaml_front_end() {
        let tokens: proc_macro2::TokenStream = r#"
            /// A ball "in" a bowl.
            pub struct Bowl;
            coordinates { x: vx, y: vy }
            parameters { m: 1.0, g: 9.81, k: -0.5 }
            inputs { u }
            let r2 = x^2 + y^2;
            kinetic = 0.5 * m * (vx^2 + vy^2);
            potential = m * g * y;
            applied { x: u - 0.1 * vx }
            constraints { #[restitution = 0.5] bowl: y >= r2 - 1, lid: y <= 2 }
            restitution = 0.9;
            initial { x: 0.5, vy: -1e-3 }
        "#
        .parse()
        .unwrap();
        let cx = Ctxt::new();
        let spec = inline::build(&cx, tokens).unwrap();
        cx.check().unwrap();
        let text = super::source(&spec);

        let source = YamlSource {
            display: "bowl.yaml".into(),
            text: text.clone(),
        };
        let root = source.parse().unwrap();
        let cx = Ctxt::with_locator(source);
        let again = yaml::build(
            &cx,
            &root,
            proc_macro2::Span::call_site(),
            std::path::Path::new("bowl.yaml"),
            text.clone(),
        )
        .unwrap();
        cx.check().unwrap();
        let again = super::canonical(&again);
        assert_eq!(again, text);
        assert!(text.contains("h: \"y - (r2 - 1)\""), "{text}");
        assert!(text.contains("h: \"2 - y\""), "{text}");
    }

    /// An inline model with bodies prints as YAML that reads back as the
    /// same model (the joint coordinates declared by their bodies, after
    /// the written ones).
    #[test]
    fn bodies_round_trip_through_the_yaml_front_end() {
        let tokens: proc_macro2::TokenStream = r#"
            pub struct Arm;
            bodies {
                upper: { joint: revolute(a1: w1), axis: [0, -1, 0], xyz: [0, 0, 0.3], mass: m, com: [0, 0, -l / 2], inertia: [1, 0, 0, 1, 0, 2] },
                tip: { parent: upper, joint: fixed, xyz: [0, 0, -l], rpy: [0.1, 0, 0], mass: 0.25 },
                slider: { parent: upper, joint: prismatic(s), axis: [1, 0, 0], mass: 1 },
                twin: { parent: upper, joint: prismatic, mimic: s, multiplier: -1, offset: 0.02, axis: [1, 0, 0], mass: 1 },
            }
            coordinates { x: vx }
            parameters { m: 1.5, l: 0.9, g: 9.81 }
            gravity = [0, 0, -g];
            kinetic = 0.5 * vx^2;
            constraints { floor: position_z(tip) + 1 >= 0 }
            restitution = 0.5;
        "#
        .parse()
        .unwrap();
        let cx = Ctxt::new();
        let spec = inline::build(&cx, tokens).unwrap();
        cx.check().unwrap();
        let names: Vec<&str> = spec.coordinates.iter().map(|c| c.q.text.as_str()).collect();
        assert_eq!(names, ["x", "a1", "s"]);
        assert_eq!(spec.coordinates[2].v.text, "ds");
        let text = super::source(&spec);
        let source = YamlSource {
            display: "arm.yaml".into(),
            text: text.clone(),
        };
        let root = source.parse().unwrap();
        let cx = Ctxt::with_locator(source);
        let again = yaml::build(
            &cx,
            &root,
            proc_macro2::Span::call_site(),
            std::path::Path::new("arm.yaml"),
            text.clone(),
        )
        .unwrap();
        cx.check().unwrap();
        assert_eq!(super::canonical(&again), text);
        assert!(
            text.contains("h: \"position_z(tip, 0, 0, 0) + 1\""),
            "{text}"
        );
        assert!(
            text.contains(
                "joint: {type: prismatic, mimic: s, multiplier: -1, offset: 0.02, axis: [1, 0, 0]"
            ),
            "{text}"
        );
    }
}
