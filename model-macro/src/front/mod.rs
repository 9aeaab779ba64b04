//! The two front ends. Each builds a [`ModelSpec`](crate::spec::ModelSpec);
//! neither checks more than the shape of what it reads.

pub(crate) mod inline;
pub(crate) mod urdf;
pub(crate) mod urdf_keys;
pub(crate) mod yaml;
pub(crate) mod yaml_tree;
