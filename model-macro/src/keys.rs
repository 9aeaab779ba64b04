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
/// Keys of one constraint entry (YAML).
pub(crate) const H: &str = "h";

/// Every top-level YAML key, in the order the documentation lists them.
pub(crate) const TOP_LEVEL: [&str; 12] = [
    NAME,
    DOC,
    COORDINATES,
    PARAMETERS,
    INPUTS,
    DEFINITIONS,
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
