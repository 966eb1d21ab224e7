//! Links the mps2 images with this folder's memory map: copies `memory.x` to
//! `OUT_DIR` as `board-memory.x`, which the workspace's top-level `memory.x`
//! INCLUDEs (the linker runs in the workspace root and finds that one
//! first), and writes the empty `device.x` that cortex-m-rt's `device`
//! feature INCLUDEs (every IRQ vector is `DefaultHandler`, src/vectors.rs).
use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy("memory.x", out.join("board-memory.x")).expect("copying boards/mps2/memory.x");
    fs::write(out.join("device.x"), "/* mps2: every IRQ vector is DefaultHandler (src/vectors.rs) */\n").expect("writing device.x");
    println!("cargo:rustc-link-search={}", out.display());
}
