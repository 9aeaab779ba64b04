// Limits asked of a continuous joint (no <limit>), of a fixed joint and of
// a joint the URDF does not have: each reported at its name.
moreau::model! {
    pub struct BadLimits;
    urdf = "tests/ui/yaml/two_joints.urdf";
    limits { spin, weld, knee }
    restitution = 0.5;
}

fn main() {}
