// An inline model naming a URDF with a floating joint (a quaternion base,
// out of scope), a planar joint, an unknown joint type, a joint mimicking it,
// malformed numbers and a joint to a missing link, and locking a joint the
// URDF does not have: every problem at once, those of the file at the path
// with the URDF's file:line:column, the unknown joint at its name.
moreau::model! {
    pub struct BadUrdf;
    urdf = "tests/ui/yaml/bad_joints.urdf";
    locked { elbow }
}

fn main() {}
