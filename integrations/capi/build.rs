//! Empty: the package's `[build-dependencies]` exist only to unify `syn`'s
//! features with the board images' graph (see Cargo.toml).
fn main() {}
