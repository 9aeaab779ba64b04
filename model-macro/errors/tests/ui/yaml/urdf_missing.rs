moreau::model!(file = "tests/ui/yaml/urdf_missing.yaml");

fn main() {}
