//! lensc-grammar: the first step of the pipeline (text → syntax tree →
//! checked values → typed jobs → toolpath → move stream → program → report).
//! The `.lens` language's syntax: a pest grammar, a syntax tree whose every
//! node carries a byte span, and diagnostics as plain data. It knows nothing
//! about machining; `lensc-lang` checks what it parses.

// pest is built without its `std` feature (whose per-rule stack probe cost a
// third of parse time; `parser::scan` bounds nesting instead), and its
// derive then names `alloc` directly.
extern crate alloc;

pub mod ast;
mod descent;
pub mod diagnostic;
pub mod parser;
pub mod suggest;

pub use ast::Span;
pub use diagnostic::{Diagnostic, FileId, Label, Severity};
pub use parser::{parse, parse_reference};

#[cfg(test)]
mod tests;
