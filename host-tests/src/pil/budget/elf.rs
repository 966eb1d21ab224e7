//! Flash and static RAM of a firmware image, read from its ELF sections.

use std::path::Path;

use anyhow::{Context, Result};
use object::{Object, ObjectSection, SectionFlags};

/// Flash (`.text` + `.rodata`) and static RAM of an ELF, bytes.
pub fn elf_sizes(elf: &Path) -> Result<(u64, u64)> {
    let data = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let file = object::File::parse(&*data).with_context(|| format!("parsing ELF {}", elf.display()))?;
    let (mut flash, mut ram) = (0u64, 0u64);
    for s in file.sections() {
        let name = s.name().unwrap_or("");
        let SectionFlags::Elf { sh_flags } = s.flags() else { continue };
        let alloc = sh_flags & u64::from(object::elf::SHF_ALLOC) != 0;
        let write = sh_flags & u64::from(object::elf::SHF_WRITE) != 0;
        if name == ".text" || name == ".rodata" {
            flash += s.size();
        } else if alloc && write {
            ram += s.size();
        }
    }
    Ok((flash, ram))
}

/// Flash of the whole load image: every allocated section with file contents
/// (vector table, code, constants, `.data`'s initial values), bytes.
pub fn elf_load_size(elf: &Path) -> Result<u64> {
    let data = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let file = object::File::parse(&*data).with_context(|| format!("parsing ELF {}", elf.display()))?;
    let mut total = 0u64;
    for s in file.sections() {
        let SectionFlags::Elf { sh_flags } = s.flags() else { continue };
        let alloc = sh_flags & u64::from(object::elf::SHF_ALLOC) != 0;
        // (.bss and no-init RAM have no file contents: SHT_NOBITS)
        if alloc && s.file_range().is_some() && s.address() < 0x2000_0000 || alloc && s.name().unwrap_or("") == ".data" {
            total += s.size();
        }
    }
    Ok(total)
}
