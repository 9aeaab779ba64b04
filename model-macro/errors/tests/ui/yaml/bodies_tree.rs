moreau::model!(file = "tests/ui/yaml/bodies_tree.yaml");

fn main() {}
