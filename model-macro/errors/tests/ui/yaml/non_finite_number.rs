moreau::model!(file = "tests/ui/yaml/non_finite_number.yaml");

fn main() {}
