//! Values the checker computes from expressions: quantities with their
//! dimension, words, constructed objects, blocks, lists, ranges, formulas.

use std::rc::Rc;

use lensc_grammar::FileId;
use lensc_grammar::ast::{Expr, Span};

use crate::schema::Kind;
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
