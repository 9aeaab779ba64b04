moreau::model!(file = "tests/ui/yaml/not_a_mapping.yaml");

fn main() {}
