moreau::model!(file = "/etc/passwd");

fn main() {}
