moreau::model!(file = "tests/ui/yaml/missing_keys.yaml");

fn main() {}
