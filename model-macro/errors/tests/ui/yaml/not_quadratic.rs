moreau::model!(file = "tests/ui/yaml/not_quadratic.yaml");

fn main() {}
