//! Diagnostics as plain data: a code, a message, labelled byte spans and a
//! hint. Rendering (ariadne, JSON) happens at the edge, in the compiler.

use crate::ast::Span;

/// Which loaded source a span points into.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FileId(pub u32);

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    Error,
    Warning,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    pub file: FileId,
    pub span: Span,
    pub message: String,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    pub severity: Severity,
    /// Stable code, `E0001`…; never reused for another meaning.
    pub code: &'static str,
    pub message: String,
    /// The first label is the primary one: where the problem is.
    pub labels: Vec<Label>,
    pub help: Option<String>,
}

impl Diagnostic {
    pub fn error(code: &'static str, message: impl Into<String>, file: FileId, span: Span) -> Self {
        Diagnostic {
            severity: Severity::Error,
            code,
            message: message.into(),
            labels: vec![Label {
                file,
                span,
                message: String::new(),
            }],
            help: None,
        }
    }
    pub fn warning(
        code: &'static str,
        message: impl Into<String>,
        file: FileId,
        span: Span,
    ) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            ..Diagnostic::error(code, message, file, span)
        }
    }
    /// Sets the primary label's text.
    pub fn with_label(mut self, text: impl Into<String>) -> Self {
        self.labels[0].message = text.into();
        self
    }
    /// Adds a secondary label.
    pub fn with_note(mut self, file: FileId, span: Span, text: impl Into<String>) -> Self {
        self.labels.push(Label {
            file,
            span,
            message: text.into(),
        });
        self
    }
    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }
    pub fn primary(&self) -> &Label {
        &self.labels[0]
    }
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

/// Syntax-level codes (the compiler owns the rest, from E0100 on).
pub mod codes {
    /// The text does not follow the grammar.
    pub const SYNTAX: &str = "E0001";
    /// Brackets nested deeper than the parser allows.
    pub const TOO_DEEP: &str = "E0002";
    /// A number that does not fit in an f64 (or is not finite).
    pub const BAD_NUMBER: &str = "E0003";
    /// A string escape other than `\"` `\\` `\n` `\t`.
    pub const BAD_ESCAPE: &str = "E0004";
    /// The file is not valid UTF-8.
    pub const NOT_UTF8: &str = "E0005";
    /// A unit power of zero, or a file too large to address with 32-bit spans.
    pub const BAD_UNIT_POWER: &str = "E0006";
    pub const TOO_LARGE: &str = "E0007";

    /// Every syntax code, for `lensc explain` and its test.
    pub const ALL: &[&str] = &[
        SYNTAX,
        TOO_DEEP,
        BAD_NUMBER,
        BAD_ESCAPE,
        NOT_UTF8,
        BAD_UNIT_POWER,
        TOO_LARGE,
    ];
}
