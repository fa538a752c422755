//! The syntax tree of a `.lens` file. Every node carries a small `Copy` byte
//! span into its source; nothing here knows what the names mean.

/// A byte range `start..end` in one source file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Span {
    pub start: u32,
    pub end: u32,
}

impl Span {
    pub fn new(start: usize, end: usize) -> Span {
        Span {
            start: start as u32,
            end: end as u32,
        }
    }
    /// The smallest span covering both.
    pub fn to(self, other: Span) -> Span {
        Span {
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }
    pub fn range(self) -> std::ops::Range<usize> {
        self.start as usize..self.end as usize
    }
}

/// A name as written, with where it was written.
#[derive(Clone, Debug, PartialEq)]
pub struct Ident {
    pub name: String,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Default)]
pub struct File {
    pub items: Vec<Item>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Item {
    pub kind: ItemKind,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ItemKind {
    /// `use std::tools::round_nose` or `use "common.lens"`.
    Use(UseTarget),
    /// `let name = expr`
    Let { name: Ident, value: Expr },
    /// `surface name = expr` (and tool, machine, strategy)
    Decl {
        kind: DeclKind,
        name: Ident,
        value: Expr,
    },
    /// `job name { ... }`
    Job { name: Ident, body: Block },
}

#[derive(Clone, Debug, PartialEq)]
pub enum UseTarget {
    /// `std::machines::nanoform_x`: the segments, in order.
    Std(Vec<Ident>),
    /// `"relative/path.lens"`: the path as written, and the span of the string.
    File { path: String, span: Span },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DeclKind {
    Surface,
    Tool,
    Machine,
    Strategy,
    Dialect,
}

impl DeclKind {
    /// Every kind of declaration, in the grammar's order.
    pub const ALL: [DeclKind; 5] = [
        DeclKind::Surface,
        DeclKind::Tool,
        DeclKind::Machine,
        DeclKind::Strategy,
        DeclKind::Dialect,
    ];

    /// The kind `keyword` declares; `None` for any other word.
    pub fn from_keyword(keyword: &str) -> Option<DeclKind> {
        DeclKind::ALL.into_iter().find(|k| k.keyword() == keyword)
    }

    pub fn keyword(self) -> &'static str {
        match self {
            DeclKind::Surface => "surface",
            DeclKind::Tool => "tool",
            DeclKind::Machine => "machine",
            DeclKind::Strategy => "strategy",
            DeclKind::Dialect => "dialect",
        }
    }
}

/// Deepest expression tree accepted (operators, calls, brackets together):
/// both parsers give up on, or report, a deeper one.
pub const MAX_EXPR_DEPTH: u32 = 200;

#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// A number with the unit written after it, if any: `85 um`.
    Quantity {
        value: f64,
        unit: Option<Unit>,
    },
    Str(String),
    Name(String),
    Unary {
        op: UnaryOp,
        operand: Box<Expr>,
    },
    Binary {
        op: BinaryOp,
        lhs: Box<Expr>,
        rhs: Box<Expr>,
    },
    Call {
        callee: Box<Expr>,
        args: Vec<Arg>,
    },
    /// `base { entries }`: a constructor or a copy of `base` with entries replaced.
    WithBlock {
        base: Box<Expr>,
        block: Block,
    },
    Block(Block),
    List(Vec<Expr>),
    /// Stands where the parser refused a node (e.g. nesting too deep); an
    /// error has already been reported.
    Invalid,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnaryOp {
    Neg,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinaryOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Range,
}

impl BinaryOp {
    pub fn symbol(self) -> &'static str {
        match self {
            BinaryOp::Add => "+",
            BinaryOp::Sub => "-",
            BinaryOp::Mul => "*",
            BinaryOp::Div => "/",
            BinaryOp::Pow => "^",
            BinaryOp::Range => "..",
        }
    }
}

/// A unit as written: `rad/mm` is `[rad^1, mm^-1]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Unit {
    pub parts: Vec<UnitPart>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct UnitPart {
    pub name: String,
    pub power: i32,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    pub entries: Vec<Entry>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Entry {
    /// `name: expr`
    Param { name: Ident, value: Expr },
    /// `z(x, y) = expr`
    Formula {
        name: Ident,
        params: Vec<Ident>,
        body: Expr,
    },
}

impl Entry {
    pub fn name(&self) -> &Ident {
        match self {
            Entry::Param { name, .. } | Entry::Formula { name, .. } => name,
        }
    }
    pub fn span(&self) -> Span {
        match self {
            Entry::Param { name, value } => name.span.to(value.span),
            Entry::Formula { name, body, .. } => name.span.to(body.span),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Arg {
    pub name: Option<Ident>,
    pub value: Expr,
}
