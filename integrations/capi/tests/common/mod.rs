//! Builds for the C API tests: the static library (host or Cortex-M4F, by a
//! nested `cargo build`, as the firmware tests build their images) and the
//! C programs that link it.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The C API crate's directory.
pub fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The cargo profile this test binary was built with (its directory under
/// `target/`), so the nested build reuses it.
fn profile() -> String {
    let exe = std::env::current_exe().expect("the test's own path");
    let dir = exe.parent().and_then(Path::parent).and_then(Path::file_name).and_then(|s| s.to_str()).unwrap_or("debug");
    match dir {
        "debug" => "dev".into(),
        other => other.into(),
    }
}

/// Builds `libeha_guard_capi.a`: for `target` with the release profile (the
/// firmware's: LTO, opt-level 2), or for the host with this test's profile.
pub fn staticlib(target: Option<&str>) -> PathBuf {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = Command::new(&cargo);
    cmd.current_dir(crate_dir()).args(["build", "-p", "eha-guard-capi", "--lib", "--message-format", "json-render-diagnostics"]);
    match target {
        Some(t) => cmd.args(["--release", "--target", t]),
        None => cmd.args(["--profile", &profile()]),
    };
    // Flags meant for the host build must not leak into the firmware build.
    cmd.env_remove("RUSTFLAGS").env_remove("CARGO_ENCODED_RUSTFLAGS").stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::inherit());
    let out = cmd.output().unwrap_or_else(|e| panic!("running {cargo:?}: {e}"));
    assert!(out.status.success(), "cargo build -p eha-guard-capi ({target:?}) failed: see above");
    for line in String::from_utf8_lossy(&out.stdout).lines() {
        if !line.contains("\"compiler-artifact\"") || !line.contains("eha_guard_capi") {
            continue;
        }
        if let Some(a) = line.split('"').find(|s| s.ends_with("libeha_guard_capi.a")) {
            return PathBuf::from(a);
        }
    }
    panic!("cargo built eha-guard-capi but reported no libeha_guard_capi.a")
}

/// A scratch directory for this test's outputs.
pub fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::create_dir_all(&d).unwrap_or_else(|e| panic!("creating {}: {e}", d.display()));
    d
}

/// Runs a command to completion; panics with its output when it fails.
pub fn run(cmd: &mut Command, what: &str) -> String {
    let out = cmd.output().unwrap_or_else(|e| panic!("{what}: cannot start {cmd:?}: {e}"));
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{what} failed ({}):\n{text}", out.status);
    text
}
