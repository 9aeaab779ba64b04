//! The YAML front end's reading of a kinematic tree: `bodies` (a URDF,
//! `urdf`, `locked`, `limits`, is read by `front/urdf_keys.rs`).

use super::*;
use crate::front::follows;

impl Walker<'_> {
    /// `[x, y, z]`: three expressions.
    pub(super) fn vector(&self, node: &YNode, what: &str) -> Option<[Expr; 3]> {
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
    pub(super) fn bodies(&self, spec: &mut ModelSpec, node: &YNode) {
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

    pub(super) fn body(&self, spec: &mut ModelSpec, item: &YNode) -> Option<Body> {
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
    pub(super) fn inertia(&self, node: &YNode) -> Option<[Expr; 6]> {
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
    pub(super) fn joint(&self, spec: &mut ModelSpec, node: &YNode) -> Option<Joint> {
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
        let (mut mimic, mut multiplier, mut offset) = (None, None, None);
        let mut ok = true;
        for (key, value) in entries {
            let Some(k) = self.key(key) else { continue };
            match k.text.as_str() {
                keys::TYPE => {
                    kind = self.joint_kind(value);
                    ok &= kind.is_some();
                }
                keys::NAME => name = self.name(value, "the joint's coordinate"),
                keys::VELOCITY => velocity = self.name(value, "the joint's velocity"),
                keys::MIMIC => mimic = self.name(value, "the coordinate this joint follows"),
                keys::MULTIPLIER => multiplier = self.number(value, "`multiplier`"),
                keys::OFFSET => offset = self.number(value, "`offset`"),
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
        let mimic = follows(self.cx, kind, mimic, (multiplier, offset), here);
        let coordinate = match &mimic {
            Some(_) => {
                for n in name.iter().chain(&velocity) {
                    self.cx.error(
                        n.loc,
                        "a joint that mimics another has no coordinate or velocity of its own",
                    );
                }
                None
            }
            None => self.joint_coordinate(spec, kind, name, velocity, here)?,
        };
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
            mimic,
            axis,
            xyz: xyz.unwrap_or_else(|| [zero(), zero(), zero()]),
            rpy: rpy.unwrap_or_else(|| [zero(), zero(), zero()]),
        })
    }

    /// A joint's `type`.
    fn joint_kind(&self, value: &YNode) -> Option<JointKind> {
        match value.scalar_text().as_deref() {
            Some("revolute") => Some(JointKind::Revolute),
            Some("prismatic") => Some(JointKind::Prismatic),
            Some("fixed") => Some(JointKind::Fixed),
            _ => {
                self.expected(
                    value,
                    &format!("a joint type ({})", keys::JOINT_TYPES.join(", ")),
                );
                None
            }
        }
    }

    /// Declares the coordinate (and velocity) of a moving joint: its index,
    /// `Some(None)` for a fixed joint, `None` after reporting a problem
    /// that leaves the joint unusable.
    fn joint_coordinate(
        &self,
        spec: &mut ModelSpec,
        kind: JointKind,
        name: Option<Name>,
        velocity: Option<Name>,
        here: Loc,
    ) -> Option<Option<usize>> {
        if let (JointKind::Fixed, Some(v)) = (kind, &velocity) {
            self.cx
                .error(v.loc, "a fixed joint has no velocity to name");
        }
        match (kind, name) {
            (JointKind::Fixed, Some(n)) => {
                self.cx
                    .error(n.loc, "a fixed joint has no coordinate to name");
                Some(None)
            }
            (JointKind::Fixed, None) => Some(None),
            (_, None) => {
                self.cx
                    .error(here, "missing `name` in this joint: its coordinate's name");
                None
            }
            (_, Some(q)) => {
                let v = velocity.unwrap_or_else(|| Name {
                    text: format!("d{}", q.text),
                    loc: q.loc,
                });
                spec.coordinates.push(Coordinate { q, v, joint: None });
                Some(Some(spec.coordinates.len() - 1))
            }
        }
    }

    /// A joint's axis: three numbers, not all zero.
    pub(super) fn axis(&self, node: &YNode) -> Option<[Number; 3]> {
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
}
