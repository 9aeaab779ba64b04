//! Compiles CasADi's generated C for every shipped model and every chain
//! (written by `tests/casadi_reference.py` into `casadi/` and
//! `casadi/chains/`) at `-O3`, the anchor of the model-evaluation benchmark.
//!
//! Both sides are built for the same target CPU: `cc` gets no `-march`
//! and the workspace sets no `-C target-cpu`, so both compile for the
//! target's baseline (x86-64 here), the C at `-O3` and the Rust at the
//! bench profile's `opt-level = 3`.
//!
//! When asked for with `MOREAU_PINOCCHIO_VENV` (a venv holding Pinocchio's
//! wheel, such as the `.venv-pinocchio` that `.ci/run` makes at the
//! repository's root; only on request, since the shim takes about 100 s to
//! compile per build profile), also compiles `pinocchio/shim.cpp` against its headers at `-O3` (Eigen's
//! headers from `/usr/include/eigen3`, Debian's `libeigen3-dev`), saves the
//! benchmark's robots as Pinocchio archives into `OUT_DIR` with the venv's
//! Python, and sets `cfg(pinocchio)` for the benchmark beside Pinocchio.

use std::path::{Path, PathBuf};
use std::process::Command;

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
    println!("cargo::rustc-check-cfg=cfg(pinocchio)");
    if let Some(venv) = pinocchio_venv() {
        pinocchio(&venv);
    }
}

/// The venv holding the `pin` wheel, if any.
fn pinocchio_venv() -> Option<PathBuf> {
    println!("cargo:rerun-if-env-changed=MOREAU_PINOCCHIO_VENV");
    let venv = PathBuf::from(std::env::var_os("MOREAU_PINOCCHIO_VENV")?);
    if prefix(&venv).is_none() {
        println!(
            "cargo:warning=MOREAU_PINOCCHIO_VENV={} holds no Pinocchio wheel \
             (pip install -r tests/requirements-pinocchio.txt): the benchmark beside Pinocchio is left out",
            venv.display()
        );
        return None;
    }
    Some(venv)
}

/// The wheel's install prefix (`cmeel.prefix`) in `venv`.
fn prefix(venv: &Path) -> Option<PathBuf> {
    let lib = std::fs::read_dir(venv.join("lib")).ok()?;
    lib.filter_map(Result::ok)
        .map(|e| e.path().join("site-packages/cmeel.prefix"))
        .find(|p| p.join("include/pinocchio").is_dir())
}

fn pinocchio(venv: &Path) {
    let prefix = prefix(venv).expect("checked by pinocchio_venv");
    let eigen = Path::new("/usr/include/eigen3");
    if !eigen.join("Eigen").is_dir() {
        println!(
            "cargo:warning=Pinocchio found in {} but not Eigen's headers (/usr/include/eigen3, \
             Debian's libeigen3-dev): the benchmark beside Pinocchio is left out",
            venv.display()
        );
        return;
    }
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    for f in ["pinocchio/shim.cpp", "pinocchio/save_models.py", "robots"] {
        println!("cargo:rerun-if-changed={f}");
    }
    let saved = Command::new(venv.join("bin/python"))
        .arg("pinocchio/save_models.py")
        .arg(&out)
        .status()
        .expect("the venv's python runs");
    assert!(saved.success(), "pinocchio/save_models.py failed");
    // Pinocchio's own compile definitions (its CMake targets' interface).
    cc::Build::new()
        .cpp(true)
        .std("c++17")
        .opt_level(3)
        .warnings(false)
        .define("NDEBUG", None)
        .define("BOOST_MPL_LIMIT_LIST_SIZE", "30")
        .define("BOOST_MPL_LIMIT_VECTOR_SIZE", "30")
        .define("BOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", None)
        .define("BOOST_FUSION_INVOKE_MAX_ARITY", "12")
        .include(prefix.join("include"))
        .include(eigen)
        .file("pinocchio/shim.cpp")
        .compile("moreau_pinocchio_shim");
    let lib = prefix.join("lib");
    println!("cargo:rustc-link-search=native={}", lib.display());
    println!("cargo:rustc-link-lib=dylib=boost_serialization");
    println!("cargo:rustc-link-arg=-Wl,-rpath,{}", lib.display());
    println!("cargo:rustc-cfg=pinocchio");
}
