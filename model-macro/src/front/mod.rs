//! The two front ends. Each builds a [`ModelSpec`](crate::spec::ModelSpec);
//! neither checks more than the shape of what it reads.

pub(crate) mod inline;
pub(crate) mod urdf;
pub(crate) mod urdf_keys;
pub(crate) mod yaml;
pub(crate) mod yaml_tree;

use crate::ctxt::Ctxt;
use crate::loc::Loc;
use crate::spec::{JointKind, Mimic, Name, Number};

/// A joint's `mimic` with its `multiplier` and `offset` (both fronts): the
/// [`Mimic`], defaults filled in (1 and 0), or `None` without `mimic`,
/// reporting a fixed joint that mimics and a `multiplier` or `offset`
/// without `mimic` (at `here`, the joint).
pub(crate) fn follows(
    cx: &Ctxt,
    kind: JointKind,
    mimic: Option<Name>,
    (multiplier, offset): (Option<Number>, Option<Number>),
    here: Loc,
) -> Option<Mimic> {
    let Some(coordinate) = mimic else {
        for n in multiplier.iter().chain(&offset) {
            cx.error(
                n.loc,
                "`multiplier` and `offset` belong to a joint that mimics another (`mimic`)",
            );
        }
        return None;
    };
    if kind == JointKind::Fixed {
        cx.error(
            coordinate.loc,
            "a fixed joint does not move: it cannot mimic",
        );
        return None;
    }
    let number = |n: Option<Number>, value| n.unwrap_or(Number { value, loc: here });
    Some(Mimic {
        coordinate,
        multiplier: number(multiplier, 1.0),
        offset: number(offset, 0.0),
    })
}
