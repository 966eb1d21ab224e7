//! The STM32F411 memory map of the product image (`boards/stm32f411/memory.x`:
//! firmware, parameter block, thermal-record sectors) as this example's map:
//! copied to `OUT_DIR` as `board-memory.x`, which the workspace's top-level
//! `memory.x` INCLUDEs (the linker runs in the workspace root and finds that
//! one first).
use std::{env, fs, path::PathBuf};

fn main() {
    let map = "../../boards/stm32f411/memory.x";
    println!("cargo:rerun-if-changed={map}");
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy(map, out.join("board-memory.x")).expect("copying the STM32F411 memory map");
    println!("cargo:rustc-link-search={}", out.display());
}
