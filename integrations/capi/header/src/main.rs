//! Writes `integrations/capi/include/eha_guard.h` from the C API crate with
//! cbindgen; `--check` regenerates it in memory and fails (exit 1, the first
//! differing line shown) when the committed header is stale.

use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let check = match std::env::args().nth(1).as_deref() {
        None => false,
        Some("--check") => true,
        Some(other) => {
            eprintln!("usage: eha-capi-header [--check] (unknown argument {other:?})");
            return ExitCode::from(2);
        }
    };
    let krate = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let header = krate.join("include/eha_guard.h");
    let config = match cbindgen::Config::from_file(krate.join("cbindgen.toml")) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("{}: {e}", krate.join("cbindgen.toml").display());
            return ExitCode::FAILURE;
        }
    };
    let bindings = match cbindgen::Builder::new().with_crate(&krate).with_config(config).generate() {
        Ok(b) => b,
        Err(e) => {
            eprintln!("cbindgen on {}: {e}", krate.display());
            return ExitCode::FAILURE;
        }
    };
    let mut fresh = Vec::new();
    bindings.write(&mut fresh);
    if !check {
        if let Err(e) = std::fs::write(&header, &fresh) {
            eprintln!("writing {}: {e}", header.display());
            return ExitCode::FAILURE;
        }
        println!("wrote {} ({} bytes)", header.display(), fresh.len());
        return ExitCode::SUCCESS;
    }
    let old = std::fs::read(&header).unwrap_or_default();
    if old == fresh {
        println!("{} is up to date ({} bytes)", header.display(), fresh.len());
        return ExitCode::SUCCESS;
    }
    let (old, fresh) = (String::from_utf8_lossy(&old), String::from_utf8_lossy(&fresh));
    let mut lines = old.lines().zip(fresh.lines()).enumerate();
    let at = lines.find(|(_, (a, b))| a != b).map_or(old.lines().count().min(fresh.lines().count()), |(k, _)| k);
    eprintln!(
        "{} is stale: line {} is {:?}, the code gives {:?}. Regenerate: cargo run -p eha-capi-header",
        header.display(),
        at + 1,
        old.lines().nth(at).unwrap_or("<end of file>"),
        fresh.lines().nth(at).unwrap_or("<end of file>")
    );
    ExitCode::FAILURE
}
