//! Firmware parameter blocks on the host (`eha-sim params-block`): a rig file
//! reduced to the firmware's model constants and written as
//! `firmware-params.bin` (format: `eha_guard::params_block`), and the same
//! checks the firmware runs at boot, with a readable report.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use eha_guard::model::{consts, ConfigError, Model};
use eha_guard::params::ReducedParams;
use eha_guard::params_block::{self, BlockError, BLOCK_LEN};

pub use crate::reduce::rediscretise;
use crate::reduce::reduce;
use crate::rig::Rig;

/// `eha-sim params-block`.
#[derive(Args, Debug)]
pub struct ParamsBlockArgs {
    #[command(subcommand)]
    cmd: BlockCmd,
}

#[derive(Subcommand, Debug)]
enum BlockCmd {
    /// Reduce a rig file to the firmware's model constants and write the
    /// parameter block (2488 bytes) to flash at the PARAMS region
    /// (STM32F411: 0x0802_0000; QEMU mps2: 0x0003_F000).
    Write {
        /// Rig file (TOML, as `host-tests/rig/liu2024.toml`).
        #[arg(long)]
        rig: PathBuf,
        /// Output file.
        #[arg(long, default_value = "firmware-params.bin")]
        out: PathBuf,
        /// Rig id stored in the block (16 ASCII bytes; default: the rig file's stem).
        #[arg(long)]
        id: Option<String>,
    },
    /// Run the firmware's boot checks on a block file: header, CRC, value
    /// ranges, and the stability of the discretised model. Exit code 1 if the
    /// firmware would refuse it (CONFIG fault).
    Check {
        /// The block file.
        file: PathBuf,
    },
}

/// Runs `eha-sim params-block`.
pub fn run(a: &ParamsBlockArgs) -> Result<()> {
    match &a.cmd {
        BlockCmd::Write { rig, out, id } => {
            let r = Rig::from_toml_file(rig).map_err(|e| anyhow::anyhow!("{e}"))?;
            if let Some(why) = crate::reduce::unsupported_structure(&r) {
                anyhow::bail!("{}: cannot be reduced to a parameter block: {why}", rig.display());
            }
            let p = reduce(&r).context("the reduced parameters are rejected by the firmware model")?;
            let id = id.clone().unwrap_or_else(|| rig.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default());
            let block = block_for(&p, &id)?;
            std::fs::write(out, block).with_context(|| format!("writing {}", out.display()))?;
            println!("{}", check_bytes(&block)?);
            println!("wrote {} ({BLOCK_LEN} bytes)", out.display());
            Ok(())
        }
        BlockCmd::Check { file } => {
            let bytes = read_block(file)?;
            println!("{}", check_bytes(&bytes).with_context(|| format!("{}: the firmware would refuse this block (CONFIG fault)", file.display()))?);
            Ok(())
        }
    }
}

/// The block of SI parameters `p` (checked as the firmware will).
pub fn block_for(p: &ReducedParams, id: &str) -> Result<[u8; BLOCK_LEN]> {
    let c = consts::derive(p).map_err(|e| anyhow::anyhow!("model constants rejected: {e:?}"))?.to_f32();
    let block = params_block::encode(&c, id);
    check_bytes(&block)?;
    Ok(block)
}

/// Reads a block file: exactly [`BLOCK_LEN`] bytes.
pub fn read_block(path: &Path) -> Result<[u8; BLOCK_LEN]> {
    let v = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    v.as_slice()
        .try_into()
        .map_err(|_| anyhow::anyhow!("{}: {} bytes, expected a parameter block of {BLOCK_LEN} bytes", path.display(), v.len()))
}

/// The firmware's boot checks on `bytes`: a one-paragraph report, or why the
/// firmware would refuse the block.
pub fn check_bytes(bytes: &[u8; BLOCK_LEN]) -> Result<String> {
    // (an owned, aligned copy: the firmware reads the block in place)
    #[repr(C, align(8))]
    struct Aligned([u8; BLOCK_LEN]);
    let a = Box::new(Aligned(*bytes));
    let c = match params_block::view(&a.0) {
        Ok(Some(c)) => *c,
        Ok(None) => bail!("no block: erased or empty (the firmware runs its compiled-in default and reports NOT_COMMISSIONED)"),
        Err(e) => bail!("{}", block_error_text(e)),
    };
    let model = Model::<f32>::from_consts(&c).map_err(|e| anyhow::anyhow!("{}", config_error_text(e, &c)))?;
    let j = model.nominal_jacobian_f32();
    let mismatch = eha_guard::model::stability::phi_mismatch_s(&c.phi, &j);
    let gain = eha_guard::model::stability::step_gain(&c.phi, &j);
    Ok(format!(
        "block ok: rig id \"{}\", format v{}, {} words; drain margin {} K (added to the drain estimate); Phi mismatch {mismatch:.2e} s (limit {:.0e} s); step gain |M^1024| {gain:.5} (limit 1.001)",
        params_block::rig_id(bytes),
        params_block::VERSION,
        consts::N_WORDS,
        c.drain_margin_k,
        eha_guard::model::stability::PHI_TOL_S,
    ))
}

fn block_error_text(e: BlockError) -> String {
    match e {
        BlockError::Magic => "bytes 0..4: not the parameter-block magic \"EHAP\" (and not erased)".into(),
        BlockError::Version => format!("bytes 4..6: format version is not {} (this firmware's)", params_block::VERSION),
        BlockError::Words => format!("bytes 6..8: word count is not {} (another model structure)", consts::N_WORDS),
        BlockError::Crc => format!("bytes {}..{BLOCK_LEN}: CRC-32 mismatch (torn or corrupted block)", BLOCK_LEN - 4),
        BlockError::Alignment => "block not 4-byte aligned".into(),
    }
}

fn config_error_text(e: ConfigError, c: &eha_guard::model::ModelConsts<f32>) -> String {
    match e {
        ConfigError::Implausible => "a constant is out of its physical range (negative conductance, capacity or share > 1)".into(),
        ConfigError::CoefficientRange => "a row of Phi exceeds the coefficient format".into(),
        ConfigError::ConstantRange => "a constant is not finite or exceeds 250 in model units".into(),
        ConfigError::Unstable => "the discretisation does not belong to the constants or amplifies (Phi mismatch or step gain)".into(),
        ConfigError::OutOfBounds(w) => {
            let w = usize::from(w);
            let value = c.as_words().get(w).copied().unwrap_or(f32::NAN);
            match eha_guard::model::bounds::word_bound(w) {
                Some((field, k, b, why)) => format!(
                    "word {w} ({field}[{k}]) = {value:e} is outside its range [{:e}, {:e}]: {why} (src/model/bounds.rs)",
                    b.lo, b.hi
                ),
                None => format!("word {w} = {value:e} is outside its range"),
            }
        }
        ConfigError::Inconsistent => "a derived word differs from its derivation (k_lf_half = k_lf / 2, k_lp = 10 k_lf, k_hyd = 10 k_q, alpha_t0 = 273.15 alpha)".into(),
        ConfigError::NoHeating => format!(
            "the block's model does not heat its drain oil at {} K/s under the reference load (60 bar, 500 rpm, 20 degC): are its loss coefficients filled in? (src/model/physics_checks.rs)",
            eha_guard::model::physics_checks::MIN_HEATING_K_PER_S
        ),
        ConfigError::RestBound => "the block's cooling bound at rest (rest_rate, rest_mode) claims faster cooling than its own model (src/model/physics_checks.rs)".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper rig's block passes; a block for another EHA (masses, films and
    /// friction changed, Phi recomputed) passes; a flipped bit and a Phi kept from
    /// the paper rig are refused with their reasons.
    #[test]
    fn blocks_are_checked_as_the_firmware_does() {
        let paper = block_for(&eha_guard::params::DEFAULT, "liu2024").unwrap();
        assert!(check_bytes(&paper).unwrap().contains("liu2024"));
        let mut other = eha_guard::params::DEFAULT;
        other.eta_m *= 1.3;
        other.pump_j_per_k *= 0.7;
        for g in other.g_case_w_per_k.iter_mut() {
            *g *= 1.3;
        }
        let stale_phi = other;
        let other = rediscretise(&other).unwrap();
        assert!(block_for(&other, "other").is_ok());
        let e = block_for(&stale_phi, "stale").unwrap_err().to_string();
        assert!(e.contains("discretisation"), "{e}");
        let mut torn = paper;
        torn[300] ^= 1;
        assert!(check_bytes(&torn).unwrap_err().to_string().contains("CRC"));
    }
}
