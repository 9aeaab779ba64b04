moreau::model!(file = "tests/ui/yaml/parens.yaml");

fn main() {}
