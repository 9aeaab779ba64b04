moreau::model!(file = "tests/ui/yaml/bodies_positions.yaml");

fn main() {}
