// A path that exists but cannot be read as a model file (a directory).
moreau::model!(file = "tests/ui/yaml");

fn main() {}
