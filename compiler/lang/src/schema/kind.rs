//! The types of the schema's tables: what a kind makes, the type and
//! allowed range of each parameter, and the kind itself. A leaf: it names
//! no kind, so checked values (`value::Object`) can point at theirs.

use lensc_grammar::ast::DeclKind;

use crate::units::Dim;

/// What a kind makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Category {
    Surface,
    Tool,
    Machine,
    Strategy,
    Aperture,
    Roller,
    Dialect,
}

impl Category {
    pub fn of(kind: DeclKind) -> Category {
        match kind {
            DeclKind::Surface => Category::Surface,
            DeclKind::Tool => Category::Tool,
            DeclKind::Machine => Category::Machine,
            DeclKind::Strategy => Category::Strategy,
            DeclKind::Dialect => Category::Dialect,
        }
    }
    pub fn noun(self) -> &'static str {
        match self {
            Category::Surface => "a surface",
            Category::Tool => "a tool",
            Category::Machine => "a machine",
            Category::Strategy => "a strategy",
            Category::Aperture => "an aperture",
            Category::Roller => "a roller",
            Category::Dialect => "a dialect",
        }
    }
}

/// The type a parameter's value must have.
#[derive(Clone, Copy, Debug)]
pub enum Ty {
    /// A quantity of one of these dimensions.
    Quantity(&'static [Dim]),
    /// One of these words.
    Word(&'static [&'static str]),
    /// A value constructed by a kind of this category.
    Object(Category),
    /// A list `[a, b]` of values of this category.
    Objects(Category),
    /// A string `"…"`.
    Text,
    /// A list of strings `["…", "…"]`.
    Texts,
    /// A nested block with its own parameters.
    Block(&'static [Param]),
    /// A nested block with its own parameters, or one of these words
    /// instead (`accept: none`).
    BlockOr(&'static [Param], &'static [&'static str]),
    /// `lo .. hi`, both of this dimension.
    Range(Dim),
    /// `name(coords) = expr` giving this dimension, over these coordinates.
    Formula {
        coords: &'static [&'static str],
        result: Dim,
    },
}

/// Allowed values of a quantity, in base units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Check {
    Any,
    Positive,
    NonNegative,
    /// lo ≤ v < hi
    HalfOpen(f64, f64),
    /// lo < v < hi
    Open(f64, f64),
    /// A whole number from 1 to 100 000.
    Count,
}

#[derive(Clone, Copy, Debug)]
pub struct Param {
    pub name: &'static str,
    pub ty: Ty,
    pub required: bool,
    pub check: Check,
    pub doc: &'static str,
}

pub(super) const fn req(name: &'static str, ty: Ty, check: Check, doc: &'static str) -> Param {
    Param {
        name,
        ty,
        required: true,
        check,
        doc,
    }
}
pub(super) const fn opt(name: &'static str, ty: Ty, check: Check, doc: &'static str) -> Param {
    Param {
        name,
        ty,
        required: false,
        check,
        doc,
    }
}

pub const LENGTH: Ty = Ty::Quantity(&[Dim::LENGTH]);
pub const NUMBER: Ty = Ty::Quantity(&[Dim::NONE]);
pub const ANGLE: Ty = Ty::Quantity(&[Dim::ANGLE]);
pub(super) const DEG90: f64 = std::f64::consts::FRAC_PI_2;

/// A family of parameters named by a pattern (`X2Y1`, `Z11`): a
/// description for messages, and the parameter a name stands for.
pub struct Family {
    pub describe: &'static str,
    pub param: fn(&str) -> Option<Param>,
}

impl std::fmt::Debug for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.describe)
    }
}

#[derive(Clone, Copy, Debug)]
pub struct Kind {
    pub name: &'static str,
    pub category: Category,
    pub params: &'static [Param],
    /// Coefficients named by a pattern, beyond `params`.
    pub family: Option<&'static Family>,
    /// Parameter names that positional arguments fill, in order.
    pub positional: &'static [&'static str],
    /// At most one of each group may be given; `exactly_one` groups need one.
    pub exclusive: &'static [(&'static [&'static str], bool)],
    pub doc: &'static str,
}

impl Kind {
    pub fn param(&self, name: &str) -> Option<&'static Param> {
        self.params.iter().find(|p| p.name == name)
    }
}
