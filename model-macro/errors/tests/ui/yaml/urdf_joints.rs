moreau::model!(file = "tests/ui/yaml/urdf_joints.yaml");

fn main() {}
