//! The C API's error paths, exercised from C: `tests/c/error_paths.c`
//! compiled with the host's gcc against the host build of the static
//! library and the generated header, run on a valid parameter block written
//! here. The C program checks every return code and output it gets (NULL
//! pointers, storage size and alignment, refused blocks, an uninitialised
//! guard, commands without arm or key, damaged records) and exits with the
//! number of failed checks.

mod common;

use std::process::Command;

use eha_guard::model::DEFAULT_CONSTS;
use eha_guard::params_block;

/// Native libraries a Rust `std` static library needs on Linux
/// (`rustc --print native-static-libs`).
const NATIVE_LIBS: [&str; 6] = ["-lgcc_s", "-lutil", "-lrt", "-lpthread", "-lm", "-ldl"];

#[test]
fn c_error_paths_return_their_status_codes() {
    let lib = common::staticlib(None);
    let dir = common::scratch("error_paths");
    let block = dir.join("capi-test-rig.bin");
    std::fs::write(&block, params_block::encode(&DEFAULT_CONSTS, "capi-test-rig")).unwrap_or_else(|e| panic!("{}: {e}", block.display()));
    let exe = dir.join("error_paths");
    let src = common::crate_dir().join("tests/c/error_paths.c");
    let include = common::crate_dir().join("include");
    common::run(
        Command::new("gcc").args(["-std=c11", "-O1", "-g", "-Wall", "-Wextra", "-Werror", "-I"]).arg(&include).arg(&src).arg(&lib).args(NATIVE_LIBS).arg("-o").arg(&exe),
        "compiling tests/c/error_paths.c with gcc",
    );
    let out = Command::new(&exe).arg(&block).output().unwrap_or_else(|e| panic!("running {}: {e}", exe.display()));
    let text = String::from_utf8_lossy(&out.stdout);
    eprintln!("{text}");
    assert_eq!(out.status.code(), Some(0), "failed C checks (exit code = their number):\n{text}");
    let passed: usize = text.lines().last().and_then(|l| l.split_whitespace().next()).and_then(|n| n.parse().ok()).unwrap_or(0);
    // Every check ran (a program that stopped early would pass fewer).
    assert!(passed >= 150, "only {passed} checks ran:\n{text}");
}
