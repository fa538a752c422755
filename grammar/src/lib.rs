//! The `.lens` language's syntax: a pest grammar, a syntax tree whose every
//! node carries a byte span, and diagnostics as plain data. It knows nothing
//! about machining.

pub mod ast;
pub mod diagnostic;
pub mod parser;
pub mod suggest;

pub use ast::Span;
pub use diagnostic::{Diagnostic, FileId, Label, Severity};
pub use parser::parse;
