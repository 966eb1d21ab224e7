//! Links the STM32F411 image with this folder's memory map: copies
//! `memory.x` to `OUT_DIR` as `board-memory.x`, which the workspace's
//! top-level `memory.x` INCLUDEs (the linker runs in the workspace root and
//! finds that one first). The vector table's `device.x` comes with the PAC.
use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy("memory.x", out.join("board-memory.x")).expect("copying boards/stm32f411/memory.x");
    println!("cargo:rustc-link-search={}", out.display());
}
