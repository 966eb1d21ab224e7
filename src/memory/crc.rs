//! CRC-32 (IEEE 802.3, as zlib's `crc32`) of the thermal records, the
//! parameter block and the wire's confirmations.

/// Nibble table of the reflected CRC-32 (IEEE, polynomial 0xEDB88320).
/// Built at compile time (an out-of-range index would be a compile error).
/// Not the `crc` crate: it offers a bitwise CRC-32 (the A/B record's CRC in
/// every product tick then took the loop from ~5 000 to ~10 600
/// instructions per tick, measured) or a 1 KiB table (960 B more, past the
/// product image's 32 KiB flash); this 64-byte table does two lookups per byte.
#[allow(clippy::indexing_slicing)]
const CRC_NIBBLE: [u32; 16] = {
    let mut t = [0u32; 16];
    let mut i = 0;
    while i < 16 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 4 {
            c = if c & 1 != 0 {
                (c >> 1) ^ 0xEDB8_8320
            } else {
                c >> 1
            };
            k += 1;
        }
        t[i] = c;
        i += 1;
    }
    t
};

/// CRC-32 (IEEE 802.3, as zlib's `crc32`) update over `data`.
#[inline(never)]
pub fn crc32_update(mut crc: u32, data: &[u8]) -> u32 {
    for b in data {
        crc ^= *b as u32;
        for _ in 0..2 {
            let idx = (crc & 0xf) as usize;
            crc = (crc >> 4) ^ CRC_NIBBLE.get(idx).copied().unwrap_or(0);
        }
    }
    crc
}

/// [`crc32_update`] over the little-endian bytes of `words`: the whole word
/// is XORed in and shifted through eight nibble steps (the same register
/// as four bytes of two steps each, the CRC being linear).
#[inline(never)]
pub(super) fn crc32_words(mut crc: u32, words: &[u32]) -> u32 {
    for w in words {
        crc ^= *w;
        for _ in 0..8 {
            let idx = (crc & 0xf) as usize;
            crc = (crc >> 4) ^ CRC_NIBBLE.get(idx).copied().unwrap_or(0);
        }
    }
    crc
}

/// CRC-32 of `data` (init and final xor 0xFFFFFFFF).
pub fn crc32(data: &[u8]) -> u32 {
    !crc32_update(0xFFFF_FFFF, data)
}
