//! Building the firmware ELF with a nested `cargo build` (the same commands
//! as the `cargo fw-build` / `cargo fw-build-m3` aliases). The images are
//! the binaries of the board crates: [`MPS2`] (QEMU: `eha-fw`, `eha-bench`,
//! `eha-mps2`) and [`STM32F4`] (`eha-stm32f4`).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use anyhow::{bail, Context, Result};

/// The two numeric builds of the firmware.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Build {
    /// f32 with libm, Cortex-M4F, QEMU `mps2-an386`.
    F32,
    /// Fixed point (`fixed` crate), Cortex-M3 without FPU, QEMU `mps2-an385`.
    Fixed,
}

impl Build {
    /// Rust target triple of the build.
    pub fn target(self) -> &'static str {
        match self {
            Build::F32 => "thumbv7em-none-eabihf",
            Build::Fixed => "thumbv7m-none-eabi",
        }
    }
    /// QEMU machine that emulates the build's board.
    pub fn machine(self) -> &'static str {
        match self {
            Build::F32 => "mps2-an386",
            Build::Fixed => "mps2-an385",
        }
    }
    /// QEMU CPU of that machine.
    pub fn cpu(self) -> &'static str {
        match self {
            Build::F32 => "cortex-m4",
            Build::Fixed => "cortex-m3",
        }
    }
    /// Name of the build in reports.
    pub fn name(self) -> &'static str {
        match self {
            Build::F32 => "f32",
            Build::Fixed => "fixed-point",
        }
    }
}

impl std::str::FromStr for Build {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "f32" => Ok(Build::F32),
            "fixed" | "fixed-point" => Ok(Build::Fixed),
            _ => bail!("unknown firmware build {s:?} (expected f32 or fixed)"),
        }
    }
}

/// The board crate of the QEMU mps2 images (`boards/mps2`).
pub const MPS2: &str = "eha-mps2";
/// The board crate of the flashed STM32F411 image (`boards/stm32f411`).
pub const STM32F4: &str = "eha-stm32f4";

/// The workspace root (the firmware crate's directory).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().map(Path::to_path_buf).unwrap_or_else(|| PathBuf::from(".."))
}

/// Build the firmware (release) and return the ELF path. Uses the `cargo`
/// that runs us (`$CARGO`) when there is one; output goes to the same target
/// directory as the host build (`$CARGO_TARGET_DIR` or `<workspace>/target`).
/// When the image was built beforehand (`.ci/run` builds every image before
/// the tests), this is cargo's up-to-date check, about a second.
pub fn build_firmware(build: Build) -> Result<PathBuf> {
    build_bin(build, MPS2, "eha-fw", &[])
}

/// Build firmware binary `bin` of the board crate `package` for `build`
/// (release profile, LTO, the flashed configuration) with the extra cargo
/// `features` of that crate (e.g. `fault-inject`), and return the ELF path.
pub fn build_bin(build: Build, package: &str, bin: &str, features: &[&str]) -> Result<PathBuf> {
    ensure_target(build)?;
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let root = workspace_root();
    let mut feats: Vec<&str> = features.to_vec();
    if build == Build::Fixed {
        feats.push("fixed-point");
    }
    let feat_args: Vec<String> = if feats.is_empty() { vec![] } else { vec!["--features".into(), feats.join(",")] };
    let mut cmd = Command::new(&cargo);
    cmd.current_dir(&root)
        .args(["build", "--release", "-p", package, "--bin", bin, "--target", build.target()])
        .args(&feat_args)
        .args(["--message-format", "json-render-diagnostics"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit());
    // Flags meant for the host build must not leak into the firmware build.
    cmd.env_remove("RUSTFLAGS").env_remove("CARGO_ENCODED_RUSTFLAGS");
    let out = cmd.output().with_context(|| format!("running {cargo:?} to build the firmware in {}", root.display()))?;
    if !out.status.success() {
        bail!(
            "firmware build failed ({}): cargo build --release -p {package} --bin {bin} --target {} {} (see the compiler output above)",
            out.status,
            build.target(),
            feat_args.join(" ")
        );
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    for line in stdout.lines().rev() {
        let Ok(v) = serde_json::from_str::<serde_json::Value>(line) else { continue };
        if v["reason"] == "compiler-artifact" && v["target"]["name"] == bin {
            if let Some(exe) = v["executable"].as_str() {
                return Ok(PathBuf::from(exe));
            }
        }
    }
    bail!("firmware build succeeded but cargo reported no {bin} executable")
}

/// Make sure the Rust target of `build` is installed (rustup does not add the
/// targets of `rust-toolchain.toml` by itself when auto-install is off): runs
/// `rustup target add` when it is missing. Without rustup, the build's own
/// error says what is missing.
pub fn ensure_target(build: Build) -> Result<()> {
    let root = workspace_root();
    let Ok(out) = Command::new("rustup").current_dir(&root).args(["target", "list", "--installed"]).stdin(Stdio::null()).output() else {
        return Ok(()); // no rustup: let cargo report a missing target
    };
    if String::from_utf8_lossy(&out.stdout).lines().any(|l| l.trim() == build.target()) {
        return Ok(());
    }
    eprintln!("installing the Rust target {} (rustup target add) ...", build.target());
    let st = Command::new("rustup").current_dir(&root).args(["target", "add", build.target()]).stdin(Stdio::null()).status()
        .context("running rustup target add")?;
    if !st.success() {
        bail!("`rustup target add {}` failed ({st})", build.target());
    }
    Ok(())
}
