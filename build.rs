//! No build step: the build-dependency on `syn` 3 only aligns its host features with the
//! Python package's build (see Cargo.toml).
fn main() {
    println!("cargo::rerun-if-changed=build.rs");
}
