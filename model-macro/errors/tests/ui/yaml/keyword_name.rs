moreau::model!(file = "tests/ui/yaml/keyword_name.yaml");

fn main() {}
