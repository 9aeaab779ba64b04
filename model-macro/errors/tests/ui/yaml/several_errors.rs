// Every mistake in a YAML model is reported at once, with file:line:column.
moreau::model!(file = "tests/ui/yaml/several_errors.yaml");

fn main() {}
