//! No build step: the build-dependency on `syn` only aligns its host features with the
//! workspace (see Cargo.toml).
fn main() {}
