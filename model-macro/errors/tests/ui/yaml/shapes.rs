moreau::model!(file = "tests/ui/yaml/shapes.yaml");

fn main() {}
