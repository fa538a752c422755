//! The post-processor: the dialect-independent move stream (`crate::moves`)
//! to program text in a dialect given as data. Every number goes through
//! the one formatter (`format.rs`: rounded to integer units, printed from
//! them); a program with a value that cannot be written is refused whole.
//! It knows nothing of planners: each strategy's adapter lives in `emit/`.

pub mod format;
pub mod header;
pub mod split;
pub mod writer;

pub use crate::dialect::{CommentStyle, Dialect};
pub use header::Provenance;
pub use writer::{ProgramWriter, Setup, check_dialect, check_numbers};

/// A program could not be written.
#[derive(Clone, Debug, PartialEq)]
pub enum ProgramError {
    /// A coordinate or feed is NaN, infinite or too large to print.
    NotPrintable { word: char, value: f64 },
    /// The dialect cannot express this move.
    Unsupported(String),
}

impl ProgramError {
    /// What is wrong, in plain words.
    pub fn message(&self) -> String {
        match self {
            ProgramError::NotPrintable { word, value } => {
                format!("the program would contain {word}{value}, which no controller accepts")
            }
            ProgramError::Unsupported(what) => {
                format!("the machine's dialect cannot express {what}")
            }
        }
    }
}
