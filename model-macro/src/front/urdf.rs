//! URDF import: a model's `urdf` key (`urdf: path` in YAML, `urdf =
//! "path";` inline; read by `urdf_keys.rs`) names a URDF whose links and
//! joints become the model's `bodies` (see `models/README.md`).
//!
//! The XML is read with `roxmltree`. The mapping, for a fixed base:
//!
//! - the root link (the one that is no joint's child) is the world: the
//!   bodies attached to it have the parent `world`, and it has no body (its
//!   mass would only add a constant to `V`);
//! - every other link is a body named as the link, attached by the joint
//!   whose child it is: `revolute` and `continuous` become revolute joints,
//!   `prismatic` prismatic, `fixed` fixed; the joint's `<origin>` is the
//!   body's `xyz` and `rpy`, its `<axis>` (default `1 0 0`) the axis, its
//!   name the coordinate's (the velocity is `d<name>`), the coordinates in
//!   the depth-first order of the tree, a link's children in the order of
//!   the file (Pinocchio, through urdfdom, sorts them by joint name);
//! - the link's `<inertial>`: `mass`, `origin xyz` as the centre of mass and
//!   the inertia rotated by `origin rpy` into the link's frame
//!   (`R I Rᵀ`), computed here in `f64`;
//! - joints listed in the model's `limits` get the constraints
//!   `q − lower ≥ 0` and `upper − q ≥ 0` from their `<limit>`;
//! - joints listed in the model's `locked` are held at zero: they become
//!   fixed joints (Pinocchio's `buildReducedModel` at the zero
//!   configuration).
//!
//! - a URDF name that is not an identifier of the model's language
//!   (Allegro's joint `joint_8.0`, Romeo's link `LFoot/FSR/CenterFront_sensor`)
//!   becomes one ([`identifier`]): every character other than an ASCII
//!   letter, digit or `_` becomes `_`, a leading digit gets a `_` before
//!   it, and a Rust keyword or prelude value (`type`, `None`) a `_` after
//!   it; two names of one kind (links, or joints) that become the same are
//!   an error naming both. `locked` and `limits` take a joint by either
//!   name. A link may share a joint's name: bodies are a namespace of their
//!   own (`scope.rs`).
//!
//! - a joint with `<mimic joint multiplier offset>` follows the joint it
//!   names: no coordinate of its own, its angle `multiplier · q + offset`
//!   of that joint's coordinate `q` (a [`Mimic`]), as Pinocchio's
//!   `buildModelFromUrdf(…, mimic=True)` reads it. Locked, it is fixed at
//!   zero as any locked joint; the joint it follows must be a moving joint
//!   of the file, neither locked nor itself mimicking one.
//!
//! `floating` (a quaternion base, out of scope) and `planar` joints are
//! refused with an error that says why; every problem in the file is
//! reported at once, each with the URDF's `path:line:column`.

use std::collections::HashMap;

use crate::expr::{Expr, ExprKind};
use crate::loc::Loc;
use crate::spec::{
    Body, Coordinate, Joint, JointKind, Mimic, Name, Number, PRELUDE_VALUES, RUST_KEYWORDS,
};

/// A joint or link of the URDF, as read.
struct UrdfJoint<'a> {
    name: &'a str,
    kind: JointKind,
    parent: &'a str,
    child: &'a str,
    xyz: [f64; 3],
    rpy: [f64; 3],
    axis: [f64; 3],
    /// `lower` and `upper` of `<limit>`, when both are given.
    limit: Option<(f64, f64)>,
    /// `<mimic>`, on a moving joint that is not locked.
    mimic: Option<UrdfMimic<'a>>,
}

/// A joint's `<mimic joint multiplier offset>`, as read.
struct UrdfMimic<'a> {
    /// The joint followed.
    joint: &'a str,
    multiplier: f64,
    offset: f64,
    /// Where it is written (`path:line:column`).
    at: String,
}

#[derive(Default, Clone, Copy)]
struct Inertial {
    mass: f64,
    com: [f64; 3],
    /// `ixx, ixy, ixz, iyy, iyz, izz` in the link's frame.
    inertia: [f64; 6],
}

/// What the URDF gives the model: its bodies (parents before children, in
/// the depth-first order of the tree, children in the order of the file)
/// and one coordinate per moving joint, in the same order.
pub(crate) struct Imported {
    pub bodies: Vec<Body>,
    pub coordinates: Vec<Coordinate>,
    /// The `<limit lower upper>` of every moving joint that has both.
    pub limits: Vec<Limit>,
}

/// A joint's position limits, as the URDF gives them.
pub(crate) struct Limit {
    /// The joint's name in the URDF.
    pub joint: String,
    /// Its coordinate's name ([`identifier`] of `joint`).
    pub coordinate: String,
    pub lower: f64,
    pub upper: f64,
}

/// The identifier a URDF name becomes in the model (see the module docs):
/// `joint_8.0` → `joint_8_0`, `iris__/imu_link` → `iris___imu_link`, `3d`
/// → `_3d`, `type` → `type_`; an identifier is itself. A name with no
/// ASCII letter or digit becomes `_`, which the checks refuse.
pub(crate) fn identifier(name: &str) -> String {
    let mut id: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if id.is_empty() || id.starts_with(|c: char| c.is_ascii_digit()) {
        id.insert(0, '_');
    }
    if RUST_KEYWORDS.contains(&id.as_str()) || PRELUDE_VALUES.contains(&id.as_str()) {
        id.push('_');
    }
    id
}

/// Whether the model's `written` names the URDF joint `joint`: by its URDF
/// name or by its coordinate's.
pub(crate) fn names_joint(written: &str, joint: &str) -> bool {
    written == joint || written == identifier(joint)
}

/// Two names of one `kind` of the URDF that become the same identifier;
/// `names` are the names with where each is written (`path:line:column`).
fn clashes(kind: &str, names: &[(&str, String)], errors: &mut Vec<String>) {
    let mut first: HashMap<String, &str> = HashMap::new();
    for (name, at) in names {
        let id = identifier(name);
        match first.get(&id) {
            Some(other) if other != name => errors.push(format!(
                "{at}: the {kind}s `{other}` and `{name}` both become `{id}` (a name of the model is letters, digits and `_`): rename one in the URDF"
            )),
            Some(_) => {}
            None => {
                first.insert(id, name);
            }
        }
    }
}

/// Reads the URDF `text` (shown in messages as `display`). `loc` is where
/// the model names the file, and every imported name and number points
/// there. Every problem is returned with where to report it: a problem of
/// the file at `loc`, its message starting with `display:line:column`; a
/// joint of `locked` (the joints to hold at zero) that the file does not
/// have at that name.
pub(crate) fn import(
    display: &str,
    text: &str,
    loc: Loc,
    locked: &[Name],
) -> Result<Imported, Vec<(Loc, String)>> {
    let at_file = |messages: Vec<String>| messages.into_iter().map(|m| (loc, m)).collect();
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let pos = e.pos();
        at_file(vec![format!(
            "{display}:{}:{}: malformed URDF: {e}",
            pos.row, pos.col
        )])
    })?;
    let mut errors = Vec::new();
    let at = |node: roxmltree::Node<'_, '_>| {
        let pos = doc.text_pos_at(node.range().start);
        format!("{display}:{}:{}", pos.row, pos.col)
    };
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(at_file(vec![format!(
            "{}: a URDF's root element is <robot>, found <{}>",
            at(root),
            root.tag_name().name()
        )]));
    }
    let mut links: Vec<(&str, Inertial)> = Vec::new();
    let mut joints: Vec<UrdfJoint<'_>> = Vec::new();
    // the names, with where each is written
    let (mut link_names, mut joint_names) = (Vec::new(), Vec::new());
    for node in root.children().filter(|n| n.is_element()) {
        match node.tag_name().name() {
            "link" => {
                let Some(name) = attribute(node, "name", &at, &mut errors) else {
                    continue;
                };
                let inertial = inertial(node, &at, &mut errors);
                links.push((name, inertial));
                link_names.push((name, at(node)));
            }
            "joint" => {
                if let Some(j) = joint(node, locked, &at, &mut errors) {
                    joint_names.push((j.name, at(node)));
                    joints.push(j);
                }
            }
            _ => {}
        }
    }
    clashes("link", &link_names, &mut errors);
    clashes("joint", &joint_names, &mut errors);
    check_mimics(&joints, locked, &mut errors);
    let root = check_tree(display, &links, &joints, &mut errors);
    let mut problems: Vec<(Loc, String)> = at_file(errors);
    for l in locked {
        if !joints.iter().any(|j| names_joint(&l.text, j.name)) {
            problems.push((
                l.loc,
                format!(
                    "`{}` is not a joint of {display}: it cannot be locked",
                    l.text
                ),
            ));
        }
    }
    match root {
        Some(root) if problems.is_empty() => {
            walk(display, &links, &joints, root, loc).map_err(at_file)
        }
        _ => Err(problems),
    }
}

/// Checks that the joints make one tree over the links (every link named
/// exists, each link the child of at most one joint, one root); the root
/// link, or `None` with `errors`.
fn check_tree<'a>(
    display: &str,
    links: &[(&'a str, Inertial)],
    joints: &[UrdfJoint<'a>],
    errors: &mut Vec<String>,
) -> Option<&'a str> {
    let inertials: HashMap<&str, Inertial> = links.iter().copied().collect();
    let mut child_of: HashMap<&str, usize> = HashMap::new();
    for (i, j) in joints.iter().enumerate() {
        for link in [j.parent, j.child] {
            if !inertials.contains_key(link) {
                errors.push(format!(
                    "{display}: joint `{}` names the link `{link}`, which this URDF does not have",
                    j.name
                ));
            }
        }
        if child_of.insert(j.child, i).is_some() {
            errors.push(format!(
                "{display}: link `{}` is the child of two joints: a URDF is a tree",
                j.child
            ));
        }
    }
    let roots: Vec<&str> = links
        .iter()
        .map(|(name, _)| *name)
        .filter(|name| !child_of.contains_key(name))
        .collect();
    if roots.len() != 1 && errors.is_empty() {
        errors.push(if links.is_empty() {
            format!("{display}: the URDF has no `<link>`: there is no robot to read")
        } else if roots.is_empty() {
            format!(
                "{display}: a URDF has one root link (a link that is no joint's child), found none: the joints form a cycle"
            )
        } else {
            format!(
                "{display}: a URDF has one root link (a link that is no joint's child), found {}: {}",
                roots.len(),
                roots.join(", ")
            )
        });
    }
    (roots.len() == 1).then(|| roots[0])
}

/// Reads the tree depth-first from `root`, children in the order of the
/// file, into bodies, coordinates and limits.
fn walk(
    display: &str,
    links: &[(&str, Inertial)],
    joints: &[UrdfJoint<'_>],
    root: &str,
    loc: Loc,
) -> Result<Imported, Vec<String>> {
    let inertials: HashMap<&str, Inertial> = links.iter().copied().collect();
    // Depth-first from the root, children in the order of the file.
    let mut imported = Imported {
        bodies: Vec::new(),
        coordinates: Vec::new(),
        limits: Vec::new(),
    };
    let mut stack: Vec<(usize, Option<&str>)> = joints
        .iter()
        .enumerate()
        .rev()
        .filter(|(_, j)| j.parent == root)
        .map(|(i, _)| (i, None))
        .collect();
    let number = |value: f64| Expr {
        kind: ExprKind::Num(value),
        loc,
    };
    let three = |v: [f64; 3]| v.map(number);
    let name = |text: &str| Name {
        text: identifier(text),
        loc,
    };
    while let Some((i, parent)) = stack.pop() {
        let j = &joints[i];
        let moving = j.kind != JointKind::Fixed;
        if let (Some((lower, upper)), true, None) = (j.limit, moving, &j.mimic) {
            imported.limits.push(Limit {
                joint: j.name.to_string(),
                coordinate: identifier(j.name),
                lower,
                upper,
            });
        }
        // only a moving joint that is not locked has its `<mimic>` read
        let mimic = j.mimic.as_ref().map(|m| Mimic {
            coordinate: name(m.joint),
            multiplier: Number {
                value: m.multiplier,
                loc,
            },
            offset: Number {
                value: m.offset,
                loc,
            },
        });
        let coordinate = (moving && mimic.is_none()).then(|| {
            imported.coordinates.push(Coordinate {
                q: name(j.name),
                v: name(&format!("d{}", identifier(j.name))),
                joint: Some(j.name.to_string()),
            });
            imported.coordinates.len() - 1
        });
        let inertial = inertials[j.child];
        imported.bodies.push(Body {
            name: name(j.child),
            parent: parent.map(name),
            joint: Joint {
                kind: j.kind,
                coordinate,
                mimic,
                axis: j.axis.map(|value| Number { value, loc }),
                xyz: three(j.xyz),
                rpy: three(j.rpy),
            },
            mass: number(inertial.mass),
            com: three(inertial.com),
            inertia: inertial.inertia.map(number),
        });
        stack.extend(
            joints
                .iter()
                .enumerate()
                .rev()
                .filter(|(_, c)| c.parent == j.child)
                .map(|(c, _)| (c, Some(j.child))),
        );
        if stack.len() > joints.len() {
            // Only a cycle can push more joints than there are.
            return Err(vec![format!(
                "{display}: the joints form a cycle through link `{}`: a URDF is a tree",
                j.child
            )]);
        }
    }
    Ok(imported)
}

fn attribute<'a>(
    node: roxmltree::Node<'a, '_>,
    key: &str,
    at: &dyn Fn(roxmltree::Node<'_, '_>) -> String,
    errors: &mut Vec<String>,
) -> Option<&'a str> {
    let value = node.attribute(key);
    if value.is_none() {
        errors.push(format!(
            "{}: <{}> has no `{key}` attribute",
            at(node),
            node.tag_name().name()
        ));
    }
    value
}

/// The first child element called `tag`.
fn child<'a, 'i>(node: roxmltree::Node<'a, 'i>, tag: &str) -> Option<roxmltree::Node<'a, 'i>> {
    node.children()
        .find(|c| c.is_element() && c.tag_name().name() == tag)
}

/// The numbers of attribute `key` of `node` (`xyz="0 0 0.1"`), `default`
/// when the node or attribute is absent.
fn numbers<const K: usize>(
    node: Option<roxmltree::Node<'_, '_>>,
    key: &str,
    default: [f64; K],
    at: &dyn Fn(roxmltree::Node<'_, '_>) -> String,
    errors: &mut Vec<String>,
) -> [f64; K] {
    let Some(node) = node else { return default };
    let Some(text) = node.attribute(key) else {
        return default;
    };
    let parsed: Result<Vec<f64>, _> = text.split_whitespace().map(str::parse::<f64>).collect();
    match parsed {
        Ok(v) if v.len() == K && v.iter().all(|x| x.is_finite()) => {
            <[f64; K]>::try_from(v).unwrap_or(default)
        }
        _ => {
            errors.push(format!(
                "{}: `{key}=\"{text}\"` is not {K} finite number{}",
                at(node),
                if K == 1 { "" } else { "s" }
            ));
            default
        }
    }
}

fn inertial(
    link: roxmltree::Node<'_, '_>,
    at: &dyn Fn(roxmltree::Node<'_, '_>) -> String,
    errors: &mut Vec<String>,
) -> Inertial {
    let Some(node) = child(link, "inertial") else {
        return Inertial::default();
    };
    let origin = child(node, "origin");
    let com = numbers(origin, "xyz", [0.0; 3], at, errors);
    let rpy = numbers(origin, "rpy", [0.0; 3], at, errors);
    let [mass] = numbers(child(node, "mass"), "value", [0.0], at, errors);
    let inertia = child(node, "inertia");
    let mut i = [0.0; 6];
    for (slot, key) in i.iter_mut().zip(["ixx", "ixy", "ixz", "iyy", "iyz", "izz"]) {
        [*slot] = numbers(inertia, key, [0.0], at, errors);
    }
    if mass < 0.0 {
        errors.push(format!("{}: a link's mass cannot be negative", at(node)));
    }
    Inertial {
        mass,
        com,
        inertia: rotate_inertia(i, rpy),
    }
}

/// `R I Rᵀ` with `R = Rz(yaw) Ry(pitch) Rx(roll)`.
fn rotate_inertia([xx, xy, xz, yy, yz, zz]: [f64; 6], [r, p, y]: [f64; 3]) -> [f64; 6] {
    let (sr, cr) = r.sin_cos();
    let (sp, cp) = p.sin_cos();
    let (sy, cy) = y.sin_cos();
    let rot = [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ];
    let i = [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]];
    let mut out = [[0.0; 3]; 3];
    for (a, row) in out.iter_mut().enumerate() {
        for (b, cell) in row.iter_mut().enumerate() {
            for k in 0..3 {
                for l in 0..3 {
                    *cell += rot[a][k] * i[k][l] * rot[b][l];
                }
            }
        }
    }
    [
        out[0][0], out[0][1], out[0][2], out[1][1], out[1][2], out[2][2],
    ]
}

fn joint<'a>(
    node: roxmltree::Node<'a, '_>,
    locked: &[Name],
    at: &dyn Fn(roxmltree::Node<'_, '_>) -> String,
    errors: &mut Vec<String>,
) -> Option<UrdfJoint<'a>> {
    let name = attribute(node, "name", at, errors);
    let kind = attribute(node, "type", at, errors);
    let parent = child(node, "parent")
        .ok_or(())
        .map_err(|()| errors.push(format!("{}: <joint> has no <parent>", at(node))))
        .ok()
        .and_then(|p| attribute(p, "link", at, errors));
    let child_link = child(node, "child")
        .ok_or(())
        .map_err(|()| errors.push(format!("{}: <joint> has no <child>", at(node))))
        .ok()
        .and_then(|c| attribute(c, "link", at, errors));
    let origin = child(node, "origin");
    let xyz = numbers(origin, "xyz", [0.0; 3], at, errors);
    let rpy = numbers(origin, "rpy", [0.0; 3], at, errors);
    let axis = numbers(child(node, "axis"), "xyz", [1.0, 0.0, 0.0], at, errors);
    let limit_node = child(node, "limit");
    let limit = match limit_node.map(|l| (l.attribute("lower"), l.attribute("upper"))) {
        Some((Some(_), Some(_))) => {
            let [lower] = numbers(limit_node, "lower", [0.0], at, errors);
            let [upper] = numbers(limit_node, "upper", [0.0], at, errors);
            Some((lower, upper))
        }
        _ => None,
    };
    let (name, kind) = (name?, kind?);
    let is_locked = locked.iter().any(|l| names_joint(&l.text, name));
    let kind = match kind {
        _ if is_locked => JointKind::Fixed,
        "revolute" | "continuous" => JointKind::Revolute,
        "prismatic" => JointKind::Prismatic,
        "fixed" => JointKind::Fixed,
        "floating" | "planar" => {
            let why = if kind == "floating" {
                "a floating base, whose orientation is a quaternion, is out of scope"
            } else {
                "a planar joint is not supported"
            };
            errors.push(format!(
                "{}: joint `{name}` is {kind}: {why}; the base is fixed (write a planar or spatial base as explicit prismatic and revolute joints in `bodies`, or list the joint in `locked` to hold it at zero)",
                at(node)
            ));
            return None;
        }
        other => {
            errors.push(format!(
                "{}: joint `{name}` has the unknown type `{other}` (revolute, continuous, prismatic, fixed)",
                at(node)
            ));
            return None;
        }
    };
    // a fixed joint's `<mimic>` moves nothing (Talos's reduced grippers)
    let mimic = match child(node, "mimic") {
        Some(m) if !is_locked && kind != JointKind::Fixed => {
            let joint = attribute(m, "joint", at, errors)?;
            let [multiplier] = numbers(Some(m), "multiplier", [1.0], at, errors);
            let [offset] = numbers(Some(m), "offset", [0.0], at, errors);
            Some(UrdfMimic {
                joint,
                multiplier,
                offset,
                at: at(m),
            })
        }
        _ => None,
    };
    if kind != JointKind::Fixed && axis.iter().all(|a| *a == 0.0) {
        errors.push(format!("{}: joint `{name}` has a zero axis", at(node)));
        return None;
    }
    Some(UrdfJoint {
        name,
        kind,
        parent: parent?,
        child: child_link?,
        xyz,
        rpy,
        axis,
        limit,
        mimic,
    })
}

/// Each `<mimic>` names a moving joint of the file that is neither locked
/// nor mimicking one itself.
fn check_mimics(joints: &[UrdfJoint<'_>], locked: &[Name], errors: &mut Vec<String>) {
    for j in joints {
        let Some(UrdfMimic {
            joint: followed,
            at,
            ..
        }) = &j.mimic
        else {
            continue;
        };
        let name = j.name;
        let why = match joints.iter().find(|f| f.name == *followed) {
            None => "which is not a joint this URDF has (or could read)",
            Some(_) if locked.iter().any(|l| names_joint(&l.text, followed)) => {
                "which is locked: lock this joint too"
            }
            Some(f) if f.kind == JointKind::Fixed => {
                "which is fixed: it has no coordinate to follow"
            }
            Some(f) if f.mimic.is_some() => "which mimics another itself: follow that one instead",
            Some(_) => continue,
        };
        errors.push(format!("{at}: joint `{name}` mimics `{followed}`, {why}"));
    }
}

#[cfg(test)]
mod tests {
    use super::{identifier, names_joint};
    use crate::spec::is_identifier;

    #[test]
    fn a_urdf_name_becomes_an_identifier() {
        for (urdf, model) in [
            ("shoulder_pan_joint", "shoulder_pan_joint"),
            ("joint_8.0", "joint_8_0"),
            ("iris__/imu_link", "iris___imu_link"),
            (
                "LFoot/FSR/CenterFront_sensor",
                "LFoot_FSR_CenterFront_sensor",
            ),
            ("left wheel", "left_wheel"),
            ("3d_camera", "_3d_camera"),
            ("type", "type_"),
            ("None", "None_"),
            ("", "_"),
            ("-", "_"),
            ("ø", "_"),
        ] {
            assert_eq!(identifier(urdf), model, "{urdf:?}");
        }
        // a name with nothing to keep is refused by the checks
        assert!(!is_identifier(&identifier("ø")));
        assert!(is_identifier(&identifier("joint_8.0")));
        assert!(names_joint("joint_8.0", "joint_8.0"));
        assert!(names_joint("joint_8_0", "joint_8.0"));
        assert!(!names_joint("joint_8", "joint_8.0"));
    }
}
