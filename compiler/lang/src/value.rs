//! Values the checker computes from expressions: quantities with their
//! dimension, words, constructed objects, blocks, lists, ranges, formulas.

use std::rc::Rc;

use lensc_grammar::FileId;
use lensc_grammar::ast::{Expr, Span};

use crate::schema::kind::Kind;
use crate::units::Dim;

#[derive(Clone, Debug)]
pub enum Value {
    /// A quantity in base units. The value is NaN when it is only known at
    /// run time (a coordinate inside a surface formula).
    Num(f64, Dim),
    Str(String),
    /// A bare name that is not bound: an enumerated word such as `convex`,
    /// or an unknown name (reported by whoever needed a value).
    Word(String),
    Object(Rc<Object>),
    Block(Rc<Vec<Field>>),
    List(Vec<(Value, Span)>),
    Range(f64, f64, Dim),
    Formula(Rc<Formula>),
    /// A built-in math function, only callable.
    Function(&'static str),
    /// A built-in kind, used as a constructor.
    Kind(&'static Kind),
    /// An error was already reported for this value.
    Error,
}

impl Value {
    /// What this is, in plain words, for messages.
    pub fn describe(&self) -> String {
        match self {
            Value::Num(_, d) => d.to_string(),
            Value::Str(_) => "a string".into(),
            Value::Word(w) => format!("the name `{w}`"),
            Value::Object(o) => format!("{} (`{}`)", o.kind.category.noun(), o.kind.name),
            Value::Block(_) => "a block".into(),
            Value::List(_) => "a list".into(),
            Value::Range(..) => "a range".into(),
            Value::Formula(_) => "a formula".into(),
            Value::Function(f) => format!("the function `{f}`"),
            Value::Kind(k) => format!("the kind `{}`", k.name),
            Value::Error => "an invalid value".into(),
        }
    }
}

/// One `name: value` of a block or object, with where it was written.
#[derive(Clone, Debug)]
pub struct Field {
    pub name: String,
    pub name_span: Span,
    pub value: Value,
    pub span: Span,
    pub file: FileId,
}

/// A value built by a kind: `conic { … }`, `circle(diameter: 2 mm)`.
#[derive(Clone, Debug)]
pub struct Object {
    pub kind: &'static Kind,
    pub fields: Vec<Field>,
    /// Where the kind's name was written (or the copied declaration's).
    pub head: Span,
    pub file: FileId,
    /// The name it was declared under (`dialect fanuc_0i_lathe = …`), if any.
    pub name: Option<String>,
}

#[derive(Debug)]
pub struct Formula {
    pub params: Vec<String>,
    pub result: Dim,
    pub body: Expr,
    pub file: FileId,
    /// Every `let` or other constant the body names, in base units.
    pub constants: std::collections::HashMap<String, f64>,
}

pub fn field<'a>(fields: &'a [Field], name: &str) -> Option<&'a Field> {
    fields.iter().find(|f| f.name == name)
}

pub fn num(fields: &[Field], name: &str) -> Option<f64> {
    match field(fields, name)?.value {
        Value::Num(v, _) => Some(v),
        _ => None,
    }
}

pub fn word<'a>(fields: &'a [Field], name: &str) -> Option<&'a str> {
    match &field(fields, name)?.value {
        Value::Word(w) => Some(w),
        _ => None,
    }
}

pub fn object<'a>(fields: &'a [Field], name: &str) -> Option<&'a Rc<Object>> {
    match &field(fields, name)?.value {
        Value::Object(o) => Some(o),
        _ => None,
    }
}

pub fn block<'a>(fields: &'a [Field], name: &str) -> Option<&'a [Field]> {
    match &field(fields, name)?.value {
        Value::Block(b) => Some(b),
        _ => None,
    }
}

pub fn range(fields: &[Field], name: &str) -> Option<(f64, f64)> {
    match field(fields, name)?.value {
        Value::Range(a, b, _) => Some((a, b)),
        _ => None,
    }
}

/// A parameter's value and where the file states it (for a message that
/// points at it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stated<T> {
    pub value: T,
    pub site: (FileId, Span),
}

impl<T> Stated<T> {
    fn at(value: T, f: &Field) -> Stated<T> {
        Stated {
            value,
            site: (f.file, f.span),
        }
    }
}

/// A checked object's (or block's) fields read by name into a typed
/// struct, once. Each kind's `read`, declared beside its schema entry, is
/// the only place a parameter is looked up by its name; nothing after
/// lowering does. A parameter the schema requires that is missing anyway
/// (the checker rejects that, so only a checker bug gets here) is
/// recorded rather than unwrapped, and `finish` turns it into E0121: bad
/// input never panics.
pub struct Reader<'a> {
    fields: &'a [Field],
    missing: Vec<String>,
}

impl<'a> Reader<'a> {
    pub fn new(fields: &'a [Field]) -> Reader<'a> {
        Reader {
            fields,
            missing: Vec::new(),
        }
    }
    /// The field itself, with where it was written.
    pub fn field(&self, name: &str) -> Option<&'a Field> {
        field(self.fields, name)
    }
    /// Whether the file states this parameter.
    pub fn has(&self, name: &str) -> bool {
        self.field(name).is_some()
    }
    pub fn num(&self, name: &str) -> Option<f64> {
        num(self.fields, name)
    }
    /// A quantity with its dimension (a feed per revolution or per minute).
    pub fn quantity(&self, name: &str) -> Option<(f64, Dim)> {
        match self.field(name)?.value {
            Value::Num(v, d) => Some((v, d)),
            _ => None,
        }
    }
    /// A quantity with where it was written (for a message about it).
    pub fn stated_num(&self, name: &str) -> Option<Stated<f64>> {
        let f = self.field(name)?;
        let v = self.num(name)?;
        Some(Stated::at(v, f))
    }
    /// A word with where it was written.
    pub fn stated_word(&self, name: &str) -> Option<Stated<&'a str>> {
        let f = self.field(name)?;
        let w = self.word(name)?;
        Some(Stated::at(w, f))
    }
    /// Where a parameter was written, if it was.
    pub fn site(&self, name: &str) -> Option<(FileId, Span)> {
        self.field(name).map(|f| (f.file, f.span))
    }
    /// A required quantity (NaN, recorded as missing, if it is not there).
    pub fn required_num(&mut self, name: &str) -> f64 {
        self.num(name).unwrap_or_else(|| {
            self.missing.push(name.to_string());
            f64::NAN
        })
    }
    pub fn word(&self, name: &str) -> Option<&'a str> {
        word(self.fields, name)
    }
    pub fn object(&self, name: &str) -> Option<&'a Rc<Object>> {
        object(self.fields, name)
    }
    pub fn range(&self, name: &str) -> Option<(f64, f64)> {
        range(self.fields, name)
    }
    /// A nested block read by `read`, if the file states it.
    pub fn block<T>(&mut self, name: &str, read: impl FnOnce(&mut Reader<'a>) -> T) -> Option<T> {
        let fields = block(self.fields, name)?;
        let mut inner = Reader::new(fields);
        let value = read(&mut inner);
        self.missing
            .extend(inner.missing.into_iter().map(|m| format!("{name}.{m}")));
        Some(value)
    }
    /// A required nested block read by `read` (read from no fields, and
    /// recorded as missing, if it is not there).
    pub fn required_block<T>(&mut self, name: &str, read: impl FnOnce(&mut Reader<'a>) -> T) -> T {
        if !self.has(name) || block(self.fields, name).is_none() {
            self.missing.push(name.to_string());
        }
        let fields = block(self.fields, name).unwrap_or(&[]);
        let mut inner = Reader::new(fields);
        let value = read(&mut inner);
        self.missing
            .extend(inner.missing.into_iter().map(|m| format!("{name}.{m}")));
        value
    }
    /// E0121 at `site` (the object's kind, `what`) for every required
    /// parameter that was missing.
    pub fn finish(
        self,
        what: &str,
        (file, span): (FileId, Span),
    ) -> Result<(), lensc_grammar::Diagnostic> {
        if self.missing.is_empty() {
            return Ok(());
        }
        Err(lensc_grammar::Diagnostic::error(
            crate::codes::MISSING_PARAMETER,
            format!(
                "`{what}` is missing {}",
                self.missing
                    .iter()
                    .map(|m| format!("`{m}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            file,
            span,
        )
        .with_label("here"))
    }
}
