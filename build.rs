//! Selects the linker memory map: copies the board's map to `OUT_DIR` as
//! `board-memory.x` and puts `OUT_DIR` on the linker search path; the root
//! `memory.x` (which cortex-m-rt's `link.x` INCLUDEs, found first in the linker's
//! working directory, the package root) INCLUDEs it. Default (QEMU
//! mps2-an385/an386, 256 KiB flash at 0, 64 KiB RAM): `boards/mps2/memory.x`.
//! With feature `board-stm32f4`: `boards/stm32f411/memory.x`.
use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=boards/mps2/memory.x");
    println!("cargo:rerun-if-changed=boards/stm32f411/memory.x");
    let Some(out) = env::var_os("OUT_DIR").map(PathBuf::from) else {
        return;
    };
    let src = if env::var_os("CARGO_FEATURE_BOARD_STM32F4").is_some() {
        "boards/stm32f411/memory.x"
    } else {
        "boards/mps2/memory.x"
    };
    // cortex-m-rt's `device` feature INCLUDEs `device.x` (PROVIDEs of the
    // device's handler names). The STM32 PAC ships one; the mps2 vectors
    // (`src/vectors.rs`) name only `DefaultHandler`, so theirs is empty.
    if env::var_os("CARGO_FEATURE_BOARD_STM32F4").is_none() {
        let _ = fs::write(out.join("device.x"), "/* mps2: every IRQ vector is DefaultHandler (src/vectors.rs) */\n");
    }
    if let Ok(bytes) = fs::read(src) {
        if fs::write(out.join("board-memory.x"), bytes).is_ok() {
            println!("cargo:rustc-link-search={}", out.display());
        }
    }
}
