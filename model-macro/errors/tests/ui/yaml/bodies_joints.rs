moreau::model!(file = "tests/ui/yaml/bodies_joints.yaml");

fn main() {}
