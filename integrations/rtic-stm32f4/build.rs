//! The STM32F411 memory map of the product image (`boards/stm32f411/memory.x`:
//! firmware, parameter block, thermal-record sectors) as this example's
//! `memory.x`.
use std::{env, fs, path::PathBuf};

fn main() {
    let map = "../../boards/stm32f411/memory.x";
    println!("cargo:rerun-if-changed={map}");
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy(map, out.join("memory.x")).expect("copying the STM32F411 memory map");
    println!("cargo:rustc-link-search={}", out.display());
}
