moreau::model!(path = "tests/ui/yaml/shapes.yaml");

moreau::model!(file = "tests/ui/yaml/shapes.yaml", extra);

fn main() {}
