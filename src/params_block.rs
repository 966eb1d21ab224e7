//! The firmware parameter block (`firmware-params.bin`): the model constants of
//! one commissioned EHA ([`ModelConsts`], `f32` words in model units, the exact-ZOH
//! matrix included), with a header and a CRC, flashed into its own region (the
//! `PARAMS` region of the board's `memory.x`) and read at boot.
//!
//! Layout (little-endian, [`BLOCK_LEN`] = 2488 bytes):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 4 | magic [`MAGIC`] (`"EHAP"`) |
//! | 4 | 2 | format version [`VERSION`] |
//! | 6 | 2 | number of words ([`N_WORDS`]) |
//! | 8 | 16 | rig id, ASCII, zero-padded |
//! | 24 | 4 × N_WORDS | the words of [`ModelConsts`] in field order |
//! | 2484 | 4 | CRC-32 (IEEE) of bytes 0..2484 |
//!
//! Erased flash (`0xFF…`) or empty memory (`0x00…`, QEMU) at the magic means
//! *absent*: the firmware runs the compiled-in [`crate::model::DEFAULT_CONSTS`]
//! (the paper rig) and reports NOT_COMMISSIONED. Anything else that fails a
//! check is *invalid*: CONFIG fault, valve open. The values and the stability
//! of the discretisation are checked when the model is built from the block
//! ([`crate::model::Model::init_in`]).

use crate::memory::crc32;
use crate::model::consts::N_WORDS;
use crate::model::ModelConsts;

/// Block size, bytes.
pub const BLOCK_LEN: usize = WORDS_AT + 4 * N_WORDS + 4;
/// `"EHAP"` little-endian.
pub const MAGIC: u32 = u32::from_le_bytes(*b"EHAP");
/// Format version of this firmware. 7: the commissioning margin on the
/// drain estimate (`drain_margin_k`, K, 0..10, added by the guard to the
/// model's case oil for its decisions and reports; 615 words, 2488 bytes).
/// 6: both of the following (614 words,
/// 2484 bytes). 5 (oil): the oil over temperature (613 words,
/// 2480 bytes): the tables over the case-oil temperature (`leak_ratio`,
/// `visc_ratio`, `tc_speed`: each 1 at 40 degC and monotonic, checked in
/// [`ModelConsts::check_values`]), the ducts' transitional films (`re_q`,
/// `g_wall`, `g_trans` at Re = 2300, 1e4, 3e4, 1e5), `rc2`, and `Phi` over the three fast states (pump
/// housing, case oil, loop oil; the blocks and actuator by explicit Euler, their
/// step bounded in the same check); `k_mu`, `t_mu` gone. 5 (safety): the
/// motor's pole pairs (the speed check's electrical frequency); the bounds
/// table of `crate::model::bounds` checks every word. 4: the pump's no-load and viscous
/// friction and the oil's expansion coefficient (`k_m0`, `k_mv`, `alpha`,
/// `alpha_t0`, `g_case_slope`; 264 words, 1084 bytes). 3: without `irc0`/`irc1` (the oil
/// capacity's inverse is exact; 259 words, 1064 bytes). 2: the rest-cooling
/// words (`rest_rate`, `rest_mode`). Older blocks are refused.
pub const VERSION: u16 = 7;
/// Offset of the rig id.
const ID_AT: usize = 8;
/// Length of the rig id, bytes.
pub const ID_LEN: usize = 16;
/// Offset of the first word.
const WORDS_AT: usize = ID_AT + ID_LEN;
/// Offset of the CRC.
const CRC_AT: usize = BLOCK_LEN - 4;
const _: () = assert!(WORDS_AT + 4 * N_WORDS == CRC_AT);

/// Why a block is refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BlockError {
    /// Not erased and not [`MAGIC`].
    Magic,
    /// Another format version.
    Version,
    /// Another word count (another model structure).
    Words,
    /// CRC mismatch (torn or corrupted write).
    Crc,
    /// The block is not 4-byte aligned in memory (cannot be read in place).
    Alignment,
}

/// Where the model constants of this boot come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ParamSource {
    /// No block: the compiled-in paper rig (NOT_COMMISSIONED).
    Default,
    /// A valid block (its values are checked when the model is built).
    Block,
    /// A block that fails its checks: CONFIG fault, fail-safe.
    Invalid(BlockError),
}

impl ParamSource {
    /// Wire code: 0 default, 1 block, 2.. invalid (2 + the error's index).
    pub fn code(&self) -> u8 {
        match self {
            ParamSource::Default => 0,
            ParamSource::Block => 1,
            ParamSource::Invalid(e) => 2 + *e as u8,
        }
    }
}

fn u32_at(b: &[u8; BLOCK_LEN], at: usize) -> u32 {
    let mut w = [0u8; 4];
    if let Some(s) = b.get(at..at + 4) {
        w.copy_from_slice(s);
    }
    u32::from_le_bytes(w)
}

/// Checks the header and CRC. `Ok(false)`: absent (erased or empty memory).
pub fn check_header(b: &[u8; BLOCK_LEN]) -> Result<bool, BlockError> {
    let magic = u32_at(b, 0);
    if magic == 0xFFFF_FFFF || magic == 0 {
        return Ok(false);
    }
    if magic != MAGIC {
        return Err(BlockError::Magic);
    }
    let vw = u32_at(b, 4);
    if (vw & 0xFFFF) as u16 != VERSION {
        return Err(BlockError::Version);
    }
    if (vw >> 16) as usize != N_WORDS {
        return Err(BlockError::Words);
    }
    let body = b.get(..CRC_AT).unwrap_or(&[]);
    if crc32(body) != u32_at(b, CRC_AT) {
        return Err(BlockError::Crc);
    }
    Ok(true)
}

/// The constants of a block in place (the words are little-endian `f32` at a
/// 4-byte aligned offset; Cortex-M and the host are little-endian). `Ok(None)`:
/// absent.
pub fn view(b: &[u8; BLOCK_LEN]) -> Result<Option<&ModelConsts<f32>>, BlockError> {
    if !check_header(b)? {
        return Ok(None);
    }
    let words = b.get(WORDS_AT..CRC_AT).unwrap_or(&[]);
    let p = words.as_ptr();
    if words.len() != core::mem::size_of::<ModelConsts<f32>>() || p.align_offset(core::mem::align_of::<ModelConsts<f32>>()) != 0 {
        return Err(BlockError::Alignment);
    }
    #[cfg(target_endian = "big")]
    compile_error!("the parameter block is read in place as little-endian f32 words");
    // SAFETY: `ModelConsts<f32>` is `repr(C)` of `f32` fields only (no padding,
    // checked in `model::consts`), every bit pattern is a valid `f32`, the
    // pointer is aligned (checked above) and the bytes live as long as `b`.
    Ok(Some(unsafe { &*p.cast::<ModelConsts<f32>>() }))
}

/// The rig id of a block (up to the first zero byte; non-ASCII bytes end it).
pub fn rig_id(b: &[u8; BLOCK_LEN]) -> &str {
    core::str::from_utf8(rig_id_bytes(b)).unwrap_or("")
}

/// [`rig_id`] as bytes, all ASCII (the firmware's command key: no UTF-8
/// validation, which took 0.5 KB of the product image's flash).
pub fn rig_id_bytes(b: &[u8; BLOCK_LEN]) -> &[u8] {
    let id = b.get(ID_AT..ID_AT + ID_LEN).unwrap_or(&[]);
    let n = id.iter().position(|c| *c == 0 || !c.is_ascii()).unwrap_or(id.len());
    id.get(..n).unwrap_or(&[])
}

/// The `PARAMS` region of the flash (the symbol `__eha_params` of the board's
/// `memory.x`): what the boards hand to [`crate::product::Board::param_block`].
#[cfg(target_os = "none")]
pub fn flash_region() -> &'static [u8; BLOCK_LEN] {
    unsafe extern "C" {
        static __eha_params: [u8; BLOCK_LEN];
    }
    // SAFETY: the board's memory.x defines `__eha_params` at the start of its
    // PARAMS region (at least 4 KiB of flash that the linker leaves empty and
    // this firmware never writes), 4-byte aligned.
    unsafe { &*core::ptr::addr_of!(__eha_params) }
}

/// Encodes a block (host tools; the rig id is cut to [`ID_LEN`] ASCII bytes).
pub fn encode(c: &ModelConsts<f32>, rig_id: &str) -> [u8; BLOCK_LEN] {
    let mut b = [0u8; BLOCK_LEN];
    let mut put = |at: usize, bytes: &[u8]| {
        if let Some(s) = b.get_mut(at..at + bytes.len()) {
            s.copy_from_slice(bytes);
        }
    };
    put(0, &MAGIC.to_le_bytes());
    put(4, &VERSION.to_le_bytes());
    put(6, &(N_WORDS as u16).to_le_bytes());
    let id: heapless::Vec<u8, ID_LEN> = rig_id.bytes().filter(u8::is_ascii).take(ID_LEN).collect();
    put(ID_AT, &id);
    let mut at = WORDS_AT;
    c.for_each(|x| {
        put(at, &x.to_le_bytes());
        at += 4;
    });
    let crc = crc32(b.get(..CRC_AT).unwrap_or(&[]));
    if let Some(s) = b.get_mut(CRC_AT..) {
        s.copy_from_slice(&crc.to_le_bytes());
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::DEFAULT_CONSTS;

    /// 4-byte aligned block storage (as the linker places the region).
    #[repr(C, align(4))]
    struct Aligned([u8; BLOCK_LEN]);

    #[test]
    fn round_trip_in_place() {
        let b = Aligned(encode(&DEFAULT_CONSTS, "liu2024-paper"));
        assert_eq!(view(&b.0), Ok(Some(&DEFAULT_CONSTS)));
        assert_eq!(rig_id(&b.0), "liu2024-paper");
    }

    #[test]
    fn erased_and_empty_are_absent() {
        assert_eq!(view(&[0xFF; BLOCK_LEN]), Ok(None));
        assert_eq!(view(&[0; BLOCK_LEN]), Ok(None));
    }

    /// Every single-bit flip in the block is refused (magic, version, count or
    /// CRC), never read as constants.
    #[test]
    fn every_bit_flip_is_refused() {
        let good = encode(&DEFAULT_CONSTS, "x");
        for byte in 0..BLOCK_LEN {
            for bit in 0..8 {
                let mut b = Aligned(good);
                b.0[byte] ^= 1 << bit;
                assert!(view(&b.0).is_err(), "flip at byte {byte} bit {bit} accepted");
            }
        }
    }

    #[test]
    fn version_and_words_are_checked_before_the_crc() {
        let mut b = Aligned(encode(&DEFAULT_CONSTS, "x"));
        b.0[4] = 2; // a version-2 block (with irc0/irc1)
        assert_eq!(view(&b.0), Err(BlockError::Version));
        let mut b = Aligned(encode(&DEFAULT_CONSTS, "x"));
        b.0[6] ^= 1;
        assert_eq!(view(&b.0), Err(BlockError::Words));
        let mut b = Aligned(encode(&DEFAULT_CONSTS, "x"));
        b.0[0] = b'X';
        assert_eq!(view(&b.0), Err(BlockError::Magic));
    }
}
