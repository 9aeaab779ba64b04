moreau::model!(file = "tests/ui/yaml/forces_renamed.yaml");

fn main() {}
