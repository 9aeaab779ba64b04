moreau::model!(file = "tests/ui/yaml/urdf_malformed.yaml");

fn main() {}
