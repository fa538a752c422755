//! Measured parts: the files interferometers, profilometers and stylus
//! profilers write, read into one model with their units (millimetres
//! here, as everywhere in lensc) and their invalid points; the
//! measurement registered to the job's design surface (piston, tilt,
//! decentre and clocking); and the figures the error map gives: PV and
//! RMS along the surface normal, texture after form removal (ISO 25178-2),
//! and a turned part's set-up errors.
//!
//! No language and no file system here: readers take bytes, the caller
//! (lensc-build) opens the file under lensc's sandbox rules and turns
//! these errors into coded diagnostics.

pub mod correct;
pub mod error;
pub mod map;
pub mod read;
pub mod register;
pub mod texture;
pub mod turned;
pub mod write;

pub use error::ReadError;
pub use map::{HeightMap, Measured, Measurement, PointCloud, Profile2d};

/// The MD5 of a file's bytes, as lowercase hex: which measurement a
/// report (and a later compensation) was made from.
pub fn md5_hex(bytes: &[u8]) -> String {
    use md5::{Digest, Md5};
    Md5::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}
