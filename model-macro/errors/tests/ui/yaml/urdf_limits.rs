moreau::model!(file = "tests/ui/yaml/urdf_limits.yaml");

fn main() {}
