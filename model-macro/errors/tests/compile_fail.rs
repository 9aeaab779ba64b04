//! Malformed models are compile errors that name the problem and point at
//! it: the token's span inline, `file:line:column` for YAML. One case per
//! rule under `tests/ui/<class>/`, and cases with several mistakes to show
//! they are reported together. Refresh the expected `.stderr` files with
//! `TRYBUILD=overwrite cargo test --release -p moreau-macro-errors`, then
//! read the diff.

use std::path::PathBuf;

#[test]
fn malformed_models_are_spanned_compile_errors() {
    // trybuild compiles each case inside its own crate, under
    // `target/tests/trybuild/moreau-macro-errors`; a model file must lie
    // inside the calling crate, so the YAML cases' files (and the URDFs
    // they name) are copied there first.
    let target = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .expect("the target directory")
        .to_path_buf();
    // trybuild names its project after this crate
    let project_yaml = target
        .join("tests/trybuild")
        .join(env!("CARGO_PKG_NAME"))
        .join("tests/ui/yaml");
    std::fs::create_dir_all(&project_yaml).expect("create the trybuild crate's model folder");
    let source = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/ui/yaml");
    for entry in std::fs::read_dir(&source).expect("tests/ui/yaml") {
        let path = entry.expect("a directory entry").path();
        if path.extension().is_some_and(|e| e == "yaml" || e == "urdf") {
            std::fs::copy(
                &path,
                project_yaml.join(path.file_name().expect("a file name")),
            )
            .expect("copy a model file");
        }
    }
    let cases = trybuild::TestCases::new();
    cases.compile_fail("tests/ui/*/*.rs");
}
