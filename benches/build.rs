//! Compiles CasADi's generated C for every shipped model (written by
//! `tests/casadi_reference.py` into `casadi/`) at `-O3`, the anchor of the
//! model-evaluation benchmark.

fn main() {
    let mut build = cc::Build::new();
    build.opt_level(3).warnings(false);
    for entry in std::fs::read_dir("casadi").expect("benches/casadi") {
        let path = entry.expect("a directory entry").path();
        if path.extension().is_some_and(|e| e == "c") {
            println!("cargo:rerun-if-changed={}", path.display());
            build.file(path);
        }
    }
    build.compile("casadi_models");
}
