//! Compiles CasADi's generated C for every shipped model and every chain
//! (written by `tests/casadi_reference.py` into `casadi/` and
//! `casadi/chains/`) at `-O3`, the anchor of the model-evaluation benchmark.
//!
//! Both sides are built for the same target CPU: `cc` gets no `-march`
//! and the workspace sets no `-C target-cpu`, so both compile for the
//! target's baseline (x86-64 here), the C at `-O3` and the Rust at the
//! bench profile's `opt-level = 3`.

fn main() {
    let mut build = cc::Build::new();
    build.opt_level(3).warnings(false);
    for dir in ["casadi", "casadi/chains"] {
        println!("cargo:rerun-if-changed={dir}");
        for entry in std::fs::read_dir(dir).expect("benches/casadi") {
            let path = entry.expect("a directory entry").path();
            if path.extension().is_some_and(|e| e == "c") {
                println!("cargo:rerun-if-changed={}", path.display());
                build.file(path);
            }
        }
    }
    build.compile("casadi_models");
}
