//! The two front ends. Each builds a [`ModelSpec`](crate::spec::ModelSpec);
//! neither checks more than the shape of what it reads.

pub(crate) mod inline;
pub(crate) mod yaml;
pub(crate) mod yaml_tree;

/// The keys of the model language, shared by both front ends, the messages
/// and `models/README.md`.
pub(crate) mod keys {
    pub const NAME: &str = "name";
    pub const DOC: &str = "doc";
    pub const COORDINATES: &str = "coordinates";
    pub const PARAMETERS: &str = "parameters";
    pub const INPUTS: &str = "inputs";
    pub const DEFINITIONS: &str = "definitions";
    pub const KINETIC: &str = "kinetic";
    pub const POTENTIAL: &str = "potential";
    pub const FORCES: &str = "forces";
    pub const CONSTRAINTS: &str = "constraints";
    pub const RESTITUTION: &str = "restitution";
    pub const INITIAL: &str = "initial";
    /// Keys of one constraint entry (YAML).
    pub const H: &str = "h";

    /// Every top-level YAML key, in the order the documentation lists them.
    pub const TOP_LEVEL: [&str; 12] = [
        NAME,
        DOC,
        COORDINATES,
        PARAMETERS,
        INPUTS,
        DEFINITIONS,
        KINETIC,
        POTENTIAL,
        FORCES,
        CONSTRAINTS,
        RESTITUTION,
        INITIAL,
    ];
}
