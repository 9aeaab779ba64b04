moreau::model!(file = "tests/ui/yaml/no_such_model.yaml");

fn main() {}
