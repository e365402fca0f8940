//! Flash and RAM of a firmware image, from its ELF section headers.

use object::{Object, ObjectSection, SectionFlags};

/// Start of RAM on mps2-an386 and on microbit (memory-*.x); allocated sections below it are in flash.
pub const RAM_ORIGIN: u64 = 0x2000_0000;

/// `SHF_ALLOC`: the section occupies memory on the target.
const SHF_ALLOC: u64 = 0x2;

/// Memory an image occupies on the target, in bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sizes {
    /// Flash: code, read-only data, the vector table and `.data`'s initial values.
    pub flash: u64,
    /// Static RAM: `.data`, `.bss` and `.uninit` (the stack comes on top).
    pub ram: u64,
    /// Of `flash`, `.text`.
    pub text: u64,
    /// Of `flash`, `.rodata`.
    pub rodata: u64,
}

/// Sums an image's allocated sections by where they live.
pub fn sizes(elf: &[u8]) -> Result<Sizes, String> {
    let file = object::File::parse(elf).map_err(|e| format!("not an ELF image: {e}"))?;
    let mut s = Sizes::default();
    for section in file.sections() {
        let SectionFlags::Elf { sh_flags } = section.flags() else {
            continue;
        };
        if sh_flags & SHF_ALLOC == 0 {
            continue;
        }
        let size = section.size();
        // `.bss` and `.uninit` (SHT_NOBITS) have no bytes in the image.
        let nobits = matches!(
            section.kind(),
            object::SectionKind::UninitializedData | object::SectionKind::UninitializedTls
        );
        if section.address() >= RAM_ORIGIN {
            s.ram += size;
            if !nobits {
                // `.data`: its initial values are copied from flash at reset.
                s.flash += size;
            }
        } else {
            s.flash += size;
        }
        match section.name().unwrap_or_default() {
            ".text" => s.text += size,
            ".rodata" => s.rodata += size,
            _ => {}
        }
    }
    Ok(s)
}
