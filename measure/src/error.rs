//! Why a measurement file was not read: errors as data, each with the
//! byte offset in the file (or in the archive's entry) where it was found.

/// Why a measurement file could not be read.
#[derive(Clone, Debug, PartialEq)]
pub enum ReadError {
    /// The bytes are not the format they claim (a bad magic number, a
    /// header field that cannot be, a number that does not parse).
    Malformed { what: String, at: Option<usize> },
    /// The file ends before the data its header promises.
    Truncated {
        expected: usize,
        found: usize,
        what: String,
    },
    /// A checksum the file carries does not match its data.
    Checksum {
        part: String,
        stated: String,
        computed: String,
    },
    /// A variant of the format lensc does not read (named).
    Unsupported { what: String },
    /// The file's name and first bytes match no format lensc reads.
    UnknownFormat,
}

impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReadError::Malformed { what, at: Some(at) } => write!(f, "{what} (at byte {at})"),
            ReadError::Malformed { what, at: None } => f.write_str(what),
            ReadError::Truncated {
                expected,
                found,
                what,
            } => write!(
                f,
                "{what}: {expected} bytes expected, the file holds {found}: it is truncated"
            ),
            ReadError::Checksum {
                part,
                stated,
                computed,
            } => write!(
                f,
                "the MD5 checksum of {part} is {computed}, but the file states {stated}: the data was changed or damaged"
            ),
            ReadError::Unsupported { what } => write!(f, "{what} is not read by lensc"),
            ReadError::UnknownFormat => f.write_str(
                "not a measurement format lensc reads (X3P, SDF, MetroPro .dat or its ASCII export, XYZ/CSV points, x z profile)",
            ),
        }
    }
}

impl std::error::Error for ReadError {}

/// A malformed-file error at a byte offset.
pub fn malformed(what: impl Into<String>, at: Option<usize>) -> ReadError {
    ReadError::Malformed {
        what: what.into(),
        at,
    }
}
