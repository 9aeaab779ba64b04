//! The keys of the model language, shared by both front ends, the checks,
//! the messages and `models/README.md`: one module, so that parser, message
//! and documentation agree.

pub(crate) const NAME: &str = "name";
pub(crate) const DOC: &str = "doc";
pub(crate) const COORDINATES: &str = "coordinates";
pub(crate) const PARAMETERS: &str = "parameters";
pub(crate) const INPUTS: &str = "inputs";
pub(crate) const DEFINITIONS: &str = "definitions";
pub(crate) const KINETIC: &str = "kinetic";
pub(crate) const POTENTIAL: &str = "potential";
/// The extra generalized forces `Q` (the total force is
/// `F = C v + G − Q`).
pub(crate) const APPLIED: &str = "applied";
/// The old name of [`APPLIED`], answered with an error that names the
/// new key.
pub(crate) const FORCES_RENAMED: &str = "forces";
pub(crate) const CONSTRAINTS: &str = "constraints";
pub(crate) const RESTITUTION: &str = "restitution";
pub(crate) const INITIAL: &str = "initial";
/// The kinematic tree: a list of bodies.
pub(crate) const BODIES: &str = "bodies";
/// A URDF file whose links and joints become `bodies`.
pub(crate) const URDF: &str = "urdf";
/// The URDF's joints to hold at zero (made fixed).
pub(crate) const LOCKED: &str = "locked";
/// The URDF's joints whose `<limit>`s become constraints.
pub(crate) const LIMITS: &str = "limits";
/// The gravity vector of the tree (default `[0, 0, -9.81]`).
pub(crate) const GRAVITY: &str = "gravity";
/// Keys of one body (YAML).
pub(crate) const PARENT: &str = "parent";
pub(crate) const JOINT: &str = "joint";
pub(crate) const MASS: &str = "mass";
pub(crate) const COM: &str = "com";
pub(crate) const INERTIA: &str = "inertia";
pub(crate) const BODY_KEYS: [&str; 6] = [NAME, PARENT, JOINT, MASS, COM, INERTIA];
/// Keys of a body's joint (YAML).
pub(crate) const TYPE: &str = "type";
pub(crate) const AXIS: &str = "axis";
pub(crate) const XYZ: &str = "xyz";
pub(crate) const RPY: &str = "rpy";
pub(crate) const VELOCITY: &str = "velocity";
/// A joint that follows another's coordinate (URDF's `<mimic>`), by a
/// multiplier (default 1) and an offset (default 0).
pub(crate) const MIMIC: &str = "mimic";
pub(crate) const MULTIPLIER: &str = "multiplier";
pub(crate) const OFFSET: &str = "offset";
pub(crate) const JOINT_KEYS: [&str; 9] = [
    TYPE, NAME, VELOCITY, MIMIC, MULTIPLIER, OFFSET, AXIS, XYZ, RPY,
];
/// The joint types of `bodies`.
pub(crate) const JOINT_TYPES: [&str; 3] = ["revolute", "prismatic", "fixed"];
/// The name of the fixed base as a parent.
pub(crate) const WORLD: &str = "world";
/// Keys of one constraint entry (YAML).
pub(crate) const H: &str = "h";

/// Every top-level YAML key, in the order the documentation lists them.
pub(crate) const TOP_LEVEL: [&str; 17] = [
    NAME,
    DOC,
    COORDINATES,
    PARAMETERS,
    INPUTS,
    DEFINITIONS,
    URDF,
    LOCKED,
    LIMITS,
    BODIES,
    GRAVITY,
    KINETIC,
    POTENTIAL,
    APPLIED,
    CONSTRAINTS,
    RESTITUTION,
    INITIAL,
];

/// The message for the old key `forces`.
pub(crate) fn forces_renamed() -> String {
    format!(
        "`{}` is now `{}`: the extra generalized forces Q (\"forces\" in `Model::forces` is the total force F = C v + G − Q)",
        FORCES_RENAMED, APPLIED
    )
}
