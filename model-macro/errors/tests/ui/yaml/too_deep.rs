moreau::model!(file = "tests/ui/yaml/too_deep.yaml");

fn main() {}
