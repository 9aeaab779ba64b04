moreau::model!(file = "tests/ui/yaml/syntax_error.yaml");

fn main() {}
