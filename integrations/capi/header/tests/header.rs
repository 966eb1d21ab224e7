//! The committed C header (`integrations/capi/include/eha_guard.h`) is what
//! cbindgen generates from the C API crate now: a change to the API that
//! was not regenerated (`cargo run -p eha-capi-header`) fails here.

use std::process::Command;

#[test]
fn committed_header_is_not_stale() {
    let out = Command::new(env!("CARGO_BIN_EXE_eha-capi-header")).arg("--check").output().expect("running eha-capi-header --check");
    assert!(out.status.success(), "{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
}
