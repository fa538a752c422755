//! Reading a measurement file's bytes: the format found from its first
//! bytes (and, for the plain-text formats, its name), then that format's
//! reader. Every reader gives millimetres and keeps the invalid points as
//! a mask.

pub mod metropro;
pub mod sdf;
pub mod text;
pub mod x3p;

use crate::error::ReadError;
use crate::map::{Format, Measurement};

/// The units of a plain-text file's numbers, which the file cannot state
/// (`--units`): millimetres per unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextUnits(pub f64);

impl TextUnits {
    pub const MM: TextUnits = TextUnits(1.0);
}

/// The format of a file from its first bytes, else from its name's
/// extension (`.xyz`, `.csv` points; `.txt`, `.prf` profiles).
pub fn detect(name: &str, bytes: &[u8]) -> Option<Format> {
    if bytes.starts_with(b"PK\x03\x04") {
        return Some(Format::X3p);
    }
    if bytes.len() >= 4 && bytes[..3] == [0x88, 0x1b, 0x03] && (0x6f..=0x71).contains(&bytes[3]) {
        return Some(Format::MetroProDat);
    }
    for magic in [&b"aISO-"[..], b"aBCR-", b"bISO-", b"bBCR-"] {
        if bytes.starts_with(magic) {
            return Some(Format::Sdf);
        }
    }
    if bytes.starts_with(b"Zygo ASCII Data File") {
        return Some(Format::MetroProAscii);
    }
    let ext = name.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("xyz" | "csv") => Some(Format::Xyz),
        Some("txt" | "prf" | "profile") => Some(Format::Profile),
        _ => None,
    }
}

/// Reads a measurement file given its name (for its extension) and bytes.
pub fn read(name: &str, bytes: &[u8], units: TextUnits) -> Result<Measurement, ReadError> {
    match detect(name, bytes).ok_or(ReadError::UnknownFormat)? {
        Format::X3p => x3p::read(bytes),
        Format::MetroProDat => metropro::read_dat(bytes),
        Format::MetroProAscii => metropro::read_ascii(bytes),
        Format::Sdf => sdf::read(bytes),
        Format::Xyz => text::read_points(bytes, units),
        Format::Profile => text::read_profile(bytes, units),
    }
}

/// Text from bytes, or a malformed-file error at the first bad byte.
pub(crate) fn utf8(bytes: &[u8]) -> Result<&str, ReadError> {
    std::str::from_utf8(bytes)
        .map_err(|e| crate::error::malformed("the text is not UTF-8", Some(e.valid_up_to())))
}

#[cfg(test)]
mod tests;
