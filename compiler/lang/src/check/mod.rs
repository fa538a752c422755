//! The checker: name resolution across files, evaluation of every
//! expression with dimensional analysis, and validation of every block
//! against its kind's parameters. It reports every error it finds and
//! hands back the checked jobs of the root file.

use std::collections::HashMap;
use std::rc::Rc;

use lensc_grammar::ast::{
    BinaryOp, Block, DeclKind, Entry, Expr, ExprKind, Ident, ItemKind, Span, UnaryOp,
};
use lensc_grammar::{Diagnostic, FileId};

use crate::codes;
use crate::loader::{Import, Loaded};
use crate::schema::{self, Category, Check, Kind, Param, Ty};
use crate::units::{self, Dim};
use crate::value::{self, Field, Formula, Object, Value};
use lensc_grammar::suggest::did_you_mean;

/// Built-in math functions.
pub const FUNCTIONS: &[&str] = &[
    "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sqrt", "abs", "exp", "ln", "min", "max",
];

/// Coordinates a surface formula may use.
const COORDINATES: &[&str] = &["x", "y", "r"];

/// A job of the root file whose parameters all checked.
#[derive(Debug)]
pub struct CheckedJob {
    pub name: Ident,
    pub file: FileId,
    pub fields: Vec<Field>,
    /// The declared names of the job's parts, for the program header.
    pub part_names: HashMap<String, String>,
}

pub struct Checked {
    pub jobs: Vec<CheckedJob>,
    pub diags: Vec<Diagnostic>,
    /// Every surface, tool, machine and strategy the root file can name
    /// (its own and those it uses) that checked, by name.
    pub declarations: HashMap<String, Rc<Object>>,
}

impl Checked {
    pub fn has_errors(&self) -> bool {
        self.diags.iter().any(Diagnostic::is_error)
    }
}

struct Decl<'a> {
    file: FileId,
    name: &'a Ident,
    /// `None` for `let`.
    kind: Option<DeclKind>,
    value: &'a Expr,
}

enum State {
    Todo,
    Busy,
    Done(Value),
}

struct Checker<'a> {
    loaded: &'a Loaded,
    diags: Vec<Diagnostic>,
    decls: Vec<Decl<'a>>,
    /// Per file: name → declaration index (local items and imports).
    scopes: Vec<HashMap<&'a str, usize>>,
    state: Vec<State>,
    used: Vec<bool>,
    /// While a formula body is evaluated: the constants it names, so that
    /// lowering can build its IR without the scopes.
    formula_constants: Option<HashMap<String, f64>>,
}

/// Checks a loaded file set. Diagnostics from loading come first.
pub fn check(loaded: &Loaded) -> Checked {
    let mut c = Checker {
        loaded,
        diags: Vec::new(),
        decls: Vec::new(),
        scopes: Vec::new(),
        state: Vec::new(),
        used: Vec::new(),
        formula_constants: None,
    };
    c.build_scopes();
    for i in 0..c.decls.len() {
        c.decl_value(i);
    }
    let jobs = c.check_jobs();
    c.warn_unused();
    let root = &loaded.files[0];
    if root.ast.items.is_empty() && loaded.diags.is_empty() {
        c.diags.push(
            Diagnostic::error(
                codes::EMPTY_FILE,
                "this file declares nothing",
                root.id,
                Span::new(0, 0),
            )
            .with_help("a job file declares a surface, a tool, a machine, a strategy and a job"),
        );
    }
    let mut declarations = HashMap::new();
    if let Some(scope) = c.scopes.first() {
        for (&name, &i) in scope {
            if let (Some(_), State::Done(Value::Object(o))) = (c.decls[i].kind, &c.state[i]) {
                declarations.insert(name.to_string(), o.clone());
            }
        }
    }
    let mut diags = loaded.diags.clone();
    diags.append(&mut c.diags);
    Checked {
        jobs,
        diags,
        declarations,
    }
}

impl<'a> Checker<'a> {
    fn err(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    fn build_scopes(&mut self) {
        let loaded = self.loaded;
        // Pass 1: every file's own items.
        let mut locals: Vec<HashMap<&'a str, usize>> = Vec::new();
        for pf in &loaded.files {
            let mut scope: HashMap<&'a str, usize> = HashMap::new();
            for item in &pf.ast.items {
                let (name, kind, value) = match &item.kind {
                    ItemKind::Let { name, value } => (name, None, value),
                    ItemKind::Decl { kind, name, value } => (name, Some(*kind), value),
                    _ => continue,
                };
                if let Some(&prev) = scope.get(name.name.as_str()) {
                    let first = self.decls[prev].name.span;
                    self.err(
                        Diagnostic::error(
                            codes::DUPLICATE_NAME,
                            format!("`{}` is defined twice", name.name),
                            pf.id,
                            name.span,
                        )
                        .with_label("second definition")
                        .with_note(pf.id, first, "first defined here")
                        .with_help("rename one of them"),
                    );
                    continue;
                }
                if schema::is_word(&name.name) {
                    self.err(
                        Diagnostic::error(codes::DUPLICATE_NAME, format!("`{}` is a word lensc uses as a value", name.name), pf.id, name.span)
                            .with_label("this name would hide the word")
                            .with_help(format!("`{}` is the value of a parameter (as in `sense: convex`); choose another name", name.name)),
                    );
                    continue;
                }
                if FUNCTIONS.contains(&name.name.as_str())
                    || schema::kind(&name.name).is_some()
                    || COORDINATES.contains(&name.name.as_str())
                {
                    self.err(
                        Diagnostic::error(
                            codes::DUPLICATE_NAME,
                            format!("`{}` is a built-in name", name.name),
                            pf.id,
                            name.span,
                        )
                        .with_label("this would hide the built-in")
                        .with_help("choose another name"),
                    );
                    continue;
                }
                scope.insert(name.name.as_str(), self.decls.len());
                self.decls.push(Decl {
                    file: pf.id,
                    name,
                    kind,
                    value,
                });
                self.state.push(State::Todo);
                self.used.push(false);
            }
            locals.push(scope);
        }
        // Pass 2: imports.
        for pf in &loaded.files {
            let mut scope = locals[pf.id.0 as usize].clone();
            for imp in &pf.imports {
                match imp {
                    Import::One { file, name } => {
                        let source = &locals[file.0 as usize];
                        match source.get(name.name.as_str()) {
                            Some(&i) => {
                                if let Some(&prev) = scope.get(name.name.as_str()) {
                                    let prev_span = self.decls[prev].name.span;
                                    let prev_file = self.decls[prev].file;
                                    self.err(
                                        Diagnostic::error(
                                            codes::DUPLICATE_NAME,
                                            format!("`{}` is already defined", name.name),
                                            pf.id,
                                            name.span,
                                        )
                                        .with_label("imported here")
                                        .with_note(prev_file, prev_span, "also defined here")
                                        .with_help("rename the local definition"),
                                    );
                                } else {
                                    scope.insert(name.name.as_str(), i);
                                    self.used[i] = true;
                                }
                            }
                            None => {
                                let module = loaded.sources.get(*file).name.clone();
                                let mut d = Diagnostic::error(
                                    codes::NOT_IN_MODULE,
                                    format!("`{module}` has no item `{}`", name.name),
                                    pf.id,
                                    name.span,
                                )
                                .with_label("not found");
                                let names: Vec<&str> = source.keys().copied().collect();
                                let mut sorted = names.clone();
                                sorted.sort_unstable();
                                d = d.with_help(match did_you_mean(&name.name, names) {
                                    Some(s) => format!("did you mean `{s}`?"),
                                    None => format!("it has: {}", sorted.join(", ")),
                                });
                                self.err(d);
                            }
                        }
                    }
                    Import::All { file, .. } => {
                        for (&n, &i) in &locals[file.0 as usize] {
                            scope.entry(n).or_insert(i);
                        }
                    }
                }
            }
            self.scopes.push(scope);
        }
    }

    fn decl_value(&mut self, i: usize) -> Value {
        match &self.state[i] {
            State::Done(v) => return v.clone(),
            State::Busy => {
                let d = &self.decls[i];
                let (file, span, name) = (d.file, d.name.span, d.name.name.clone());
                self.err(
                    Diagnostic::error(
                        codes::SELF_REFERENCE,
                        format!("`{name}` is defined in terms of itself"),
                        file,
                        span,
                    )
                    .with_label("this definition needs its own value")
                    .with_help("break the cycle by giving one of the values directly"),
                );
                self.state[i] = State::Done(Value::Error);
                return Value::Error;
            }
            State::Todo => {}
        }
        self.state[i] = State::Busy;
        let (file, expr, kind, name) = (
            self.decls[i].file,
            self.decls[i].value,
            self.decls[i].kind,
            self.decls[i].name,
        );
        let mut v = self.eval(file, expr, &[]);
        if let Some(kind) = kind {
            v = self.expect_category(file, expr.span, v, Category::of(kind), Some((kind, name)));
            // A declared object is known by its name (a dialect is chosen by it).
            if let Value::Object(o) = &v
                && o.name.is_none()
            {
                let mut named = (**o).clone();
                named.name = Some(name.name.clone());
                v = Value::Object(std::rc::Rc::new(named));
            }
        }
        if let State::Done(prev) = &self.state[i] {
            // A cycle was reported while evaluating; keep the error value.
            return prev.clone();
        }
        self.state[i] = State::Done(v.clone());
        v
    }

    /// Checks that a declaration's value was made by a kind of the category.
    fn expect_category(
        &mut self,
        file: FileId,
        span: Span,
        v: Value,
        cat: Category,
        decl: Option<(DeclKind, &Ident)>,
    ) -> Value {
        match &v {
            Value::Object(o) if o.kind.category == cat => v,
            Value::Error => v,
            Value::Kind(k) if k.category == cat => {
                self.err(
                    Diagnostic::error(
                        codes::WRONG_VALUE,
                        format!("`{}` needs its parameters", k.name),
                        file,
                        span,
                    )
                    .with_label("a kind, not a value")
                    .with_help(format!("write `{} {{ … }}` with its parameters", k.name)),
                );
                Value::Error
            }
            Value::Word(w) => {
                self.unknown_name(file, span, w);
                Value::Error
            }
            other => {
                let what = other.describe();
                let msg = match decl {
                    Some((k, name)) => format!(
                        "`{}` is declared as {} but its value is {what}",
                        name.name,
                        Category::of(k).noun()
                    ),
                    None => format!("expected {} but found {what}", cat.noun()),
                };
                let mut d = Diagnostic::error(codes::DECLARATION_KIND, msg, file, span)
                    .with_label(format!("this is {what}"));
                let kinds: Vec<&str> = schema::KINDS
                    .iter()
                    .filter(|k| k.category == cat)
                    .map(|k| k.name)
                    .collect();
                d = d.with_help(format!(
                    "{} is made by one of: {}",
                    cat.noun(),
                    kinds.join(", ")
                ));
                self.err(d);
                Value::Error
            }
        }
    }

    fn lookup(&mut self, file: FileId, name: &str) -> Option<usize> {
        let i = *self.scopes[file.0 as usize].get(name)?;
        self.used[i] = true;
        Some(i)
    }

    fn unknown_name(&mut self, file: FileId, span: Span, name: &str) {
        let scope = &self.scopes[file.0 as usize];
        let mut candidates: Vec<&str> = scope.keys().copied().collect();
        candidates.extend(FUNCTIONS);
        candidates.extend(schema::KINDS.iter().map(|k| k.name));
        let mut d = Diagnostic::error(
            codes::UNKNOWN_NAME,
            format!("unknown name `{name}`"),
            file,
            span,
        )
        .with_label("not defined");
        if COORDINATES.contains(&name) {
            d = d.with_help(
                "coordinates can only be used inside a surface formula such as `z(x, y) = …`",
            );
        } else if let Some(s) = did_you_mean(name, candidates) {
            d = d.with_help(format!("did you mean `{s}`?"));
        } else if units::lookup(name).is_some() {
            d = d.with_help(format!(
                "`{name}` is a unit: write it right after a number, as in `1 {name}`"
            ));
        }
        self.err(d);
    }

    // ---- expressions -------------------------------------------------------

    fn eval(&mut self, file: FileId, e: &Expr, coords: &[String]) -> Value {
        match &e.kind {
            ExprKind::Invalid => Value::Error,
            ExprKind::Quantity { value, unit } => {
                let Some(unit) = unit else {
                    return Value::Num(*value, Dim::NONE);
                };
                let mut factor = 1.0;
                let mut dim = Dim::NONE;
                let mut ok = true;
                for part in &unit.parts {
                    match units::lookup(&part.name) {
                        Some(u) => {
                            factor *= u.factor.powi(part.power);
                            match u.dim.pow(part.power) {
                                Some(d) => dim = dim * d,
                                None => ok = false,
                            }
                        }
                        None => {
                            ok = false;
                            let mut d = Diagnostic::error(
                                codes::UNKNOWN_UNIT,
                                format!("unknown unit `{}`", part.name),
                                file,
                                part.span,
                            )
                            .with_label("not a unit lensc knows");
                            d = d.with_help(match did_you_mean(&part.name, units::UNITS.iter().map(|u| u.name)) {
                                Some(s) => format!("did you mean `{s}`?"),
                                None if part.name.len() == 1 || self.scopes[file.0 as usize].contains_key(part.name.as_str()) || coords.contains(&part.name) =>
                                    format!("to multiply by `{}`, write `* {}`", part.name, part.name),
                                None => "units are nm um mm cm m in, deg rad mrad urad rev, s ms us min, rpm Hz kHz, g, and their quotients like mm/min".into(),
                            });
                            self.err(d);
                        }
                    }
                }
                if ok {
                    Value::Num(value * factor, dim)
                } else {
                    Value::Error
                }
            }
            ExprKind::Str(s) => Value::Str(s.clone()),
            ExprKind::Name(n) => {
                if coords.iter().any(|c| c == n) {
                    return Value::Num(f64::NAN, Dim::LENGTH);
                }
                if let Some(i) = self.lookup(file, n) {
                    let v = self.decl_value(i);
                    if let (Some(consts), Value::Num(x, _)) = (&mut self.formula_constants, &v) {
                        consts.insert(n.clone(), *x);
                    }
                    return v;
                }
                if FUNCTIONS.contains(&n.as_str()) {
                    let f = FUNCTIONS.iter().find(|f| **f == n).expect("function");
                    return Value::Function(f);
                }
                if let Some(k) = schema::kind(n) {
                    return Value::Kind(k);
                }
                Value::Word(n.clone())
            }
            ExprKind::Unary {
                op: UnaryOp::Neg,
                operand,
            } => {
                let v = self.eval(file, operand, coords);
                match v {
                    Value::Num(x, d) => Value::Num(-x, d),
                    other => {
                        self.expect_number(file, operand.span, &other, "negate");
                        Value::Error
                    }
                }
            }
            ExprKind::Binary { op, lhs, rhs } => {
                let a = self.eval(file, lhs, coords);
                let b = self.eval(file, rhs, coords);
                self.binary(file, *op, e.span, (a, lhs.span), (b, rhs.span))
            }
            ExprKind::Call { callee, args } => {
                let f = self.eval(file, callee, coords);
                match f {
                    Value::Function(name) => {
                        self.call_function(file, name, e.span, callee.span, args, coords)
                    }
                    Value::Kind(k) => {
                        let mut fields = Vec::new();
                        let mut positional = 0;
                        for a in args {
                            let v = self.eval(file, &a.value, coords);
                            let (name, name_span) = match &a.name {
                                Some(n) => (n.name.clone(), n.span),
                                None => {
                                    let Some(p) = k.positional.get(positional) else {
                                        self.err(
                                            Diagnostic::error(
                                                codes::ARGUMENT_COUNT,
                                                format!("`{}` takes only named arguments", k.name),
                                                file,
                                                a.value.span,
                                            )
                                            .with_label("unnamed argument")
                                            .with_help(format!(
                                                "write `name: value`; `{}` has: {}",
                                                k.name,
                                                param_list(k.params)
                                            )),
                                        );
                                        continue;
                                    };
                                    positional += 1;
                                    (p.to_string(), a.value.span)
                                }
                            };
                            self.push_field(
                                &mut fields,
                                Field {
                                    name,
                                    name_span,
                                    value: v,
                                    span: a.value.span,
                                    file,
                                },
                            );
                        }
                        self.construct(k, fields, callee.span, file)
                    }
                    Value::Error => {
                        for a in args {
                            self.eval(file, &a.value, coords);
                        }
                        Value::Error
                    }
                    Value::Word(w) => {
                        let mut d = Diagnostic::error(
                            codes::UNKNOWN_NAME,
                            format!("unknown function `{w}`"),
                            file,
                            callee.span,
                        )
                        .with_label("not defined");
                        let cands = FUNCTIONS
                            .iter()
                            .copied()
                            .chain(schema::KINDS.iter().map(|k| k.name));
                        d = d.with_help(match did_you_mean(&w, cands) {
                            Some(s) => format!("did you mean `{s}`?"),
                            None => format!("the functions are: {}", FUNCTIONS.join(", ")),
                        });
                        self.err(d);
                        Value::Error
                    }
                    other => {
                        self.err(
                            Diagnostic::error(
                                codes::NOT_CALLABLE,
                                format!("{} cannot be called", other.describe()),
                                file,
                                callee.span,
                            )
                            .with_label("not a function"),
                        );
                        Value::Error
                    }
                }
            }
            ExprKind::WithBlock { base, block } => {
                let b = self.eval(file, base, coords);
                match b {
                    Value::Kind(k) => {
                        let fields = self.block_fields(file, block, coords);
                        self.construct(k, fields, base.span, file)
                    }
                    Value::Object(o) => {
                        let fields = self.block_fields(file, block, coords);
                        let merged = merge(&o.fields, fields);
                        self.construct(o.kind, merged, base.span, file)
                    }
                    Value::Error => {
                        self.block_fields(file, block, coords);
                        Value::Error
                    }
                    Value::Word(w) => {
                        let mut d = Diagnostic::error(
                            codes::UNKNOWN_NAME,
                            format!("unknown kind `{w}`"),
                            file,
                            base.span,
                        )
                        .with_label("not a kind or declaration");
                        let mut cands: Vec<&str> = schema::KINDS.iter().map(|k| k.name).collect();
                        cands.extend(self.scopes[file.0 as usize].keys().copied());
                        d = d.with_help(match did_you_mean(&w, cands) {
                            Some(s) => format!("did you mean `{s}`?"),
                            None => format!(
                                "the kinds are: {}",
                                schema::KINDS
                                    .iter()
                                    .map(|k| k.name)
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        });
                        self.err(d);
                        self.block_fields(file, block, coords);
                        Value::Error
                    }
                    other => {
                        self.err(
                            Diagnostic::error(codes::WRONG_VALUE, format!("{} cannot take a block of parameters", other.describe()), file, base.span)
                                .with_label("a block follows this")
                                .with_help("a block follows a kind (`conic { … }`) or a declaration to copy and change"),
                        );
                        Value::Error
                    }
                }
            }
            ExprKind::Block(block) => Value::Block(Rc::new(self.block_fields(file, block, coords))),
            ExprKind::List(items) => Value::List(
                items
                    .iter()
                    .map(|i| (self.eval(file, i, coords), i.span))
                    .collect(),
            ),
        }
    }

    fn push_field(&mut self, fields: &mut Vec<Field>, f: Field) {
        if let Some(prev) = fields.iter().find(|p| p.name == f.name) {
            let first = prev.name_span;
            self.err(
                Diagnostic::error(
                    codes::DUPLICATE_PARAMETER,
                    format!("`{}` is given twice", f.name),
                    f.file,
                    f.name_span,
                )
                .with_label("given again here")
                .with_note(f.file, first, "first given here")
                .with_help("remove one of them"),
            );
            return;
        }
        fields.push(f);
    }

    fn block_fields(&mut self, file: FileId, block: &Block, coords: &[String]) -> Vec<Field> {
        let mut fields = Vec::new();
        for entry in &block.entries {
            let f = match entry {
                Entry::Param { name, value } => {
                    let v = self.eval(file, value, coords);
                    Field {
                        name: name.name.clone(),
                        name_span: name.span,
                        value: v,
                        span: value.span,
                        file,
                    }
                }
                Entry::Formula { name, params, body } => {
                    let mut ok = true;
                    for p in params {
                        if !COORDINATES.contains(&p.name.as_str()) {
                            ok = false;
                            self.err(
                                Diagnostic::error(codes::UNKNOWN_COORDINATE, format!("`{}` is not a coordinate", p.name), file, p.span)
                                    .with_label("unknown coordinate")
                                    .with_help("a surface formula is written in x and y (or r for a radial profile)"),
                            );
                        }
                    }
                    let names: Vec<String> = params.iter().map(|p| p.name.clone()).collect();
                    let outer = self.formula_constants.replace(HashMap::new());
                    let v = self.eval(file, body, &names);
                    let constants =
                        std::mem::replace(&mut self.formula_constants, outer).unwrap_or_default();
                    let value = match v {
                        Value::Num(_, dim) if ok => Value::Formula(Rc::new(Formula {
                            params: names,
                            result: dim,
                            body: body.clone(),
                            file,
                            constants,
                        })),
                        Value::Num(..) | Value::Error => Value::Error,
                        other => {
                            self.expect_number(file, body.span, &other, "use as a formula");
                            Value::Error
                        }
                    };
                    Field {
                        name: name.name.clone(),
                        name_span: name.span,
                        value,
                        span: body.span,
                        file,
                    }
                }
            };
            self.push_field(&mut fields, f);
        }
        fields
    }

    /// Reports a value that should have been a number.
    fn expect_number(&mut self, file: FileId, span: Span, v: &Value, action: &str) {
        match v {
            Value::Error => {}
            Value::Word(w) => {
                let w = w.clone();
                self.unknown_name(file, span, &w);
            }
            other => self.err(
                Diagnostic::error(
                    codes::WRONG_VALUE,
                    format!("cannot {action} {}", other.describe()),
                    file,
                    span,
                )
                .with_label("expected a number or quantity"),
            ),
        }
    }

    fn binary(
        &mut self,
        file: FileId,
        op: BinaryOp,
        span: Span,
        (a, sa): (Value, Span),
        (b, sb): (Value, Span),
    ) -> Value {
        let (x, da, y, db) = match (&a, &b) {
            (Value::Num(x, da), Value::Num(y, db)) => (*x, *da, *y, *db),
            _ => {
                let verb = match op {
                    BinaryOp::Range => "make a range of",
                    _ => "do arithmetic on",
                };
                for (v, s) in [(&a, sa), (&b, sb)] {
                    if !matches!(v, Value::Num(..)) {
                        self.expect_number(file, s, v, verb);
                    }
                }
                return Value::Error;
            }
        };
        match op {
            BinaryOp::Add | BinaryOp::Sub | BinaryOp::Range => {
                if da != db {
                    let what = match op {
                        BinaryOp::Add => "add",
                        BinaryOp::Sub => "subtract",
                        _ => "make a range from",
                    };
                    let mut d = Diagnostic::error(
                        codes::DIMENSION_MISMATCH,
                        format!("cannot {what} {da} and {db}"),
                        file,
                        span,
                    )
                    .with_label(format!(
                        "`{}` needs both sides of one dimension",
                        op.symbol()
                    ))
                    .with_note(file, sa, format!("this is {da}"))
                    .with_note(file, sb, format!("this is {db}"));
                    if da.is_none() || db.is_none() {
                        d = d.with_help(
                            "a plain number has no unit: write the unit after it, as in `3 um`",
                        );
                    }
                    self.err(d);
                    return Value::Error;
                }
                match op {
                    BinaryOp::Add => Value::Num(x + y, da),
                    BinaryOp::Sub => Value::Num(x - y, da),
                    _ => {
                        if x.is_nan() || y.is_nan() {
                            self.err(
                                Diagnostic::error(
                                    codes::WRONG_VALUE,
                                    "a range's ends must be constants",
                                    file,
                                    span,
                                )
                                .with_label("depends on a coordinate"),
                            );
                            return Value::Error;
                        }
                        Value::Range(x, y, da)
                    }
                }
            }
            BinaryOp::Mul => Value::Num(x * y, da * db),
            BinaryOp::Div => {
                if y == 0.0 {
                    self.err(
                        Diagnostic::error(codes::MATH_DOMAIN, "division by zero", file, sb)
                            .with_label("this is zero"),
                    );
                    return Value::Error;
                }
                Value::Num(x / y, da / db)
            }
            BinaryOp::Pow => {
                if !db.is_none() {
                    self.err(
                        Diagnostic::error(
                            codes::BAD_EXPONENT,
                            format!("an exponent must be a plain number, not {db}"),
                            file,
                            sb,
                        )
                        .with_label("has a unit"),
                    );
                    return Value::Error;
                }
                if da.is_none() {
                    return Value::Num(x.powf(y), Dim::NONE);
                }
                if y.is_nan() || y.fract() != 0.0 || y.abs() > 12.0 {
                    self.err(
                        Diagnostic::error(
                            codes::BAD_EXPONENT,
                            format!("{da} can only be raised to a whole-number constant power"),
                            file,
                            sb,
                        )
                        .with_label("not a small whole number")
                        .with_help(
                            "use sqrt for square roots; other powers of a unit have no meaning",
                        ),
                    );
                    return Value::Error;
                }
                match da.pow(y as i32) {
                    Some(d) => Value::Num(x.powi(y as i32), d),
                    None => {
                        self.err(Diagnostic::error(
                            codes::BAD_EXPONENT,
                            "the power of the unit is too large",
                            file,
                            span,
                        ));
                        Value::Error
                    }
                }
            }
        }
    }

    fn call_function(
        &mut self,
        file: FileId,
        name: &'static str,
        span: Span,
        callee: Span,
        args: &[lensc_grammar::ast::Arg],
        coords: &[String],
    ) -> Value {
        let mut vals = Vec::new();
        let mut bad = false;
        for a in args {
            if let Some(n) = &a.name {
                self.err(
                    Diagnostic::error(
                        codes::ARGUMENT_COUNT,
                        format!("`{name}` takes no named arguments"),
                        file,
                        n.span,
                    )
                    .with_label("remove this name"),
                );
                bad = true;
            }
            let v = self.eval(file, &a.value, coords);
            match v {
                Value::Num(x, d) => vals.push((x, d, a.value.span)),
                other => {
                    self.expect_number(file, a.value.span, &other, &format!("pass to `{name}`"));
                    bad = true;
                }
            }
        }
        if bad {
            return Value::Error;
        }
        let arity_ok = match name {
            "atan2" => vals.len() == 2,
            "min" | "max" => vals.len() >= 2,
            _ => vals.len() == 1,
        };
        if !arity_ok {
            let want = match name {
                "atan2" => "2 arguments",
                "min" | "max" => "at least 2 arguments",
                _ => "1 argument",
            };
            self.err(
                Diagnostic::error(
                    codes::ARGUMENT_COUNT,
                    format!("`{name}` takes {want}, not {}", vals.len()),
                    file,
                    span,
                )
                .with_label("wrong number of arguments")
                .with_note(file, callee, "this function"),
            );
            return Value::Error;
        }
        let (x, d, s) = vals[0];
        let need = |me: &mut Self, ok: bool, wanted: &str, d: Dim, s: Span| {
            if !ok {
                me.err(
                    Diagnostic::error(codes::BAD_ARGUMENT_DIMENSION, format!("`{name}` needs {wanted}, but this is {d}"), file, s)
                        .with_label(format!("this is {d}"))
                        .with_help(match name {
                            "sin" | "cos" | "tan" => "multiply a length by an angle per length first, as in `sin(5 rad/mm * x)`",
                            _ => "check the units of the argument",
                        }),
                );
            }
            ok
        };
        let domain = |me: &mut Self, ok: bool, what: &str| {
            if !ok && !x.is_nan() {
                me.err(
                    Diagnostic::error(codes::MATH_DOMAIN, format!("`{name}` of {what}"), file, s)
                        .with_label("outside the function's domain"),
                );
                return false;
            }
            true
        };
        match name {
            "sin" | "cos" | "tan" => {
                if !need(self, d == Dim::ANGLE || d.is_none(), "an angle", d, s) {
                    return Value::Error;
                }
                let v = match name {
                    "sin" => x.sin(),
                    "cos" => x.cos(),
                    _ => x.tan(),
                };
                Value::Num(v, Dim::NONE)
            }
            "asin" | "acos" | "atan" => {
                if !need(self, d.is_none(), "a plain number", d, s) {
                    return Value::Error;
                }
                if name != "atan"
                    && !domain(self, (-1.0..=1.0).contains(&x), "a number outside -1 ..= 1")
                {
                    return Value::Error;
                }
                let v = match name {
                    "asin" => x.asin(),
                    "acos" => x.acos(),
                    _ => x.atan(),
                };
                Value::Num(v, Dim::ANGLE)
            }
            "atan2" => {
                let (x2, d2, s2) = vals[1];
                if d != d2 {
                    self.err(
                        Diagnostic::error(
                            codes::BAD_ARGUMENT_DIMENSION,
                            format!(
                                "`atan2` needs two arguments of one dimension, not {d} and {d2}"
                            ),
                            file,
                            span,
                        )
                        .with_note(file, s, format!("this is {d}"))
                        .with_note(file, s2, format!("this is {d2}")),
                    );
                    return Value::Error;
                }
                Value::Num(x.atan2(x2), Dim::ANGLE)
            }
            "sqrt" => match d.sqrt() {
                Some(h) => {
                    if !domain(self, x >= 0.0, "a negative number") {
                        return Value::Error;
                    }
                    Value::Num(x.sqrt(), h)
                }
                None => {
                    need(
                        self,
                        false,
                        "a quantity with even powers of its units (like an area)",
                        d,
                        s,
                    );
                    Value::Error
                }
            },
            "abs" => Value::Num(x.abs(), d),
            "exp" | "ln" => {
                if !need(self, d.is_none(), "a plain number", d, s) {
                    return Value::Error;
                }
                if name == "ln" {
                    if !domain(self, x > 0.0, "a number that is not positive") {
                        return Value::Error;
                    }
                    Value::Num(x.ln(), Dim::NONE)
                } else {
                    Value::Num(x.exp(), Dim::NONE)
                }
            }
            _ => {
                // min, max
                let mut acc = x;
                for &(y, dy, sy) in &vals[1..] {
                    if dy != d {
                        self.err(
                            Diagnostic::error(
                                codes::BAD_ARGUMENT_DIMENSION,
                                format!(
                                    "`{name}` needs arguments of one dimension, not {d} and {dy}"
                                ),
                                file,
                                sy,
                            )
                            .with_label(format!("this is {dy}"))
                            .with_note(file, s, format!("this is {d}")),
                        );
                        return Value::Error;
                    }
                    acc = if name == "min" {
                        acc.min(y)
                    } else {
                        acc.max(y)
                    };
                }
                Value::Num(acc, d)
            }
        }
    }

    // ---- kinds and parameters ---------------------------------------------

    fn construct(
        &mut self,
        kind: &'static Kind,
        fields: Vec<Field>,
        head: Span,
        file: FileId,
    ) -> Value {
        let ok = self.validate_with(
            kind.params,
            kind.family,
            &fields,
            &format!("`{}`", kind.name),
            head,
            file,
            kind.exclusive,
        );
        let obj = Object {
            kind,
            fields,
            head,
            file,
            name: None,
        };
        // The sign rule reads only fields it checks itself, so it runs even
        // when another parameter is wrong: every error is reported.
        let signs_ok = kind.param("convention").is_none() || self.sign_rule(&obj);
        if !ok || !signs_ok || !self.kind_rules(&obj) {
            return Value::Error;
        }
        Value::Object(Rc::new(obj))
    }

    /// Validates fields against parameters; true if all is well.
    fn validate(
        &mut self,
        params: &'static [Param],
        fields: &[Field],
        owner: &str,
        head: Span,
        file: FileId,
        exclusive: &[(&[&str], bool)],
    ) -> bool {
        self.validate_with(params, None, fields, owner, head, file, exclusive)
    }

    /// Validates fields against parameters and a family of coefficient
    /// names (`X2Y1`, `Z4`…); true if all is well.
    #[allow(clippy::too_many_arguments)]
    fn validate_with(
        &mut self,
        params: &'static [Param],
        family: Option<&schema::Family>,
        fields: &[Field],
        owner: &str,
        head: Span,
        file: FileId,
        exclusive: &[(&[&str], bool)],
    ) -> bool {
        let before = self.error_count();
        for f in fields {
            if let Some(p) = family.and_then(|fam| (fam.param)(&f.name)) {
                self.check_param(&p, f, owner);
                continue;
            }
            let Some(p) = params.iter().find(|p| p.name == f.name) else {
                let mut d = Diagnostic::error(
                    codes::UNKNOWN_PARAMETER,
                    format!("{owner} has no parameter `{}`", f.name),
                    f.file,
                    f.name_span,
                )
                .with_label("unknown parameter");
                d = d.with_help(match did_you_mean(&f.name, params.iter().map(|p| p.name)) {
                    Some(s) => format!("did you mean `{s}`?"),
                    None => match family {
                        Some(fam) => format!(
                            "{owner} takes: {}, and {}",
                            param_list(params),
                            fam.describe
                        ),
                        None => format!("{owner} takes: {}", param_list(params)),
                    },
                });
                self.err(d);
                continue;
            };
            self.check_param(p, f, owner);
        }
        for p in params.iter().filter(|p| p.required) {
            if value::field(fields, p.name).is_none() {
                self.err(
                    Diagnostic::error(
                        codes::MISSING_PARAMETER,
                        format!("{owner} is missing `{}`", p.name),
                        file,
                        head,
                    )
                    .with_label(format!("needs `{}`", p.name))
                    .with_help(
                        format!("add `{}: …`, {}", p.name, ty_words(&p.ty))
                            + &format!(" ({})", p.doc),
                    ),
                );
            }
        }
        for (group, exactly_one) in exclusive {
            let given: Vec<&Field> = group
                .iter()
                .filter_map(|n| value::field(fields, n))
                .collect();
            if given.len() > 1 {
                self.err(
                    Diagnostic::error(
                        codes::CONFLICTING_PARAMETERS,
                        format!("{owner} takes only one of {}", quoted(group)),
                        given[1].file,
                        given[1].name_span,
                    )
                    .with_label("second of them")
                    .with_note(given[0].file, given[0].name_span, "first of them")
                    .with_help("keep one"),
                );
            } else if given.is_empty() && *exactly_one {
                self.err(
                    Diagnostic::error(
                        codes::MISSING_PARAMETER,
                        format!("{owner} needs one of {}", quoted(group)),
                        file,
                        head,
                    )
                    .with_label("give one of them"),
                );
            }
        }
        self.error_count() == before
    }

    fn error_count(&self) -> usize {
        self.diags.iter().filter(|d| d.is_error()).count()
    }

    fn check_param(&mut self, p: &Param, f: &Field, owner: &str) {
        let (file, span) = (f.file, f.span);
        match (&p.ty, &f.value) {
            (_, Value::Error) => {}
            (Ty::Quantity(dims), Value::Num(v, d)) => {
                if !dims.contains(d) {
                    let want = dims
                        .iter()
                        .map(|d| d.to_string())
                        .collect::<Vec<_>>()
                        .join(" or ");
                    let mut diag = Diagnostic::error(
                        codes::PARAMETER_DIMENSION,
                        format!("`{}` must be {want}, but this is {d}", f.name),
                        file,
                        span,
                    )
                    .with_label(format!("this is {d}"));
                    diag = diag.with_help(if d.is_none() {
                        format!(
                            "write a unit after the number, for example {}",
                            example_unit(dims[0])
                        )
                    } else {
                        format!("`{}` is {}: {}", f.name, want, p.doc)
                    });
                    self.err(diag);
                    return;
                }
                let ok = match p.check {
                    Check::Any => true,
                    Check::Positive => *v > 0.0,
                    Check::NonNegative => *v >= 0.0,
                    Check::HalfOpen(lo, hi) => *v >= lo && *v < hi,
                    Check::Open(lo, hi) => *v > lo && *v < hi,
                    Check::Count => v.fract() == 0.0 && (1.0..=100_000.0).contains(v),
                };
                if !ok {
                    let (unit, factor) = d.display_unit();
                    let shown = format!("{} {unit}", trim_num(v * factor));
                    let rule = match p.check {
                        Check::Positive => "must be greater than zero".to_string(),
                        Check::NonNegative => "cannot be negative".to_string(),
                        Check::HalfOpen(lo, hi) => format!(
                            "must be at least {} and less than {} {unit}",
                            trim_num(lo * factor),
                            trim_num(hi * factor)
                        )
                        .trim_end()
                        .to_string(),
                        Check::Open(lo, hi) => format!(
                            "must be greater than {} and less than {} {unit}",
                            trim_num(lo * factor),
                            trim_num(hi * factor)
                        )
                        .trim_end()
                        .to_string(),
                        Check::Count => "must be a whole number from 1 to 100000".to_string(),
                        Check::Any => unreachable!(),
                    };
                    self.err(
                        Diagnostic::error(
                            codes::OUT_OF_RANGE,
                            format!("`{}` {rule}, but it is {}", f.name, shown.trim_end()),
                            file,
                            span,
                        )
                        .with_label("out of range")
                        .with_help(format!("`{}`: {}", f.name, p.doc)),
                    );
                }
            }
            (Ty::Word(words), Value::Word(w)) => {
                if !words.contains(&w.as_str()) {
                    let mut d = Diagnostic::error(
                        codes::UNKNOWN_WORD,
                        format!("`{}` cannot be `{w}`", f.name),
                        file,
                        span,
                    )
                    .with_label(format!("expected {}", one_of(words)));
                    if let Some(s) = did_you_mean(w, words.iter().copied()) {
                        d = d.with_help(format!("did you mean `{s}`?"));
                    } else {
                        d = d.with_help(format!("`{}`: {}", f.name, p.doc));
                    }
                    self.err(d);
                }
            }
            (Ty::Object(cat), Value::Object(o)) if o.kind.category == *cat => {}
            (Ty::Object(cat), v @ Value::Word(_)) => {
                self.expect_category(file, span, v.clone(), *cat, None);
            }
            (Ty::Text, Value::Str(_)) => {}
            (Ty::Texts, Value::List(items)) => {
                for (v, s) in items {
                    if !matches!(v, Value::Str(_) | Value::Error) {
                        self.err(
                            Diagnostic::error(
                                codes::WRONG_VALUE,
                                format!(
                                    "`{}` is a list of strings, but this is {}",
                                    f.name,
                                    v.describe()
                                ),
                                file,
                                *s,
                            )
                            .with_label("expected a string `\"…\"`")
                            .with_help(format!("`{}`: {}", f.name, p.doc)),
                        );
                    }
                }
            }
            (Ty::Objects(cat), Value::List(items)) => {
                for (v, s) in items {
                    match v {
                        Value::Object(o) if o.kind.category == *cat => {}
                        Value::Error => {}
                        v => {
                            self.expect_category(file, *s, v.clone(), *cat, None);
                        }
                    }
                }
            }
            (Ty::Block(sub), Value::Block(fields)) => {
                let owner = format!("`{}` of {owner}", f.name);
                self.validate(sub, fields, &owner, f.name_span, file, &[]);
            }
            (Ty::Range(dim), Value::Range(lo, hi, d)) => {
                if d != dim {
                    self.err(
                        Diagnostic::error(
                            codes::PARAMETER_DIMENSION,
                            format!("the ends of `{}` must be {dim}, but they are {d}", f.name),
                            file,
                            span,
                        )
                        .with_label(format!("this is {d}")),
                    );
                } else if lo >= hi {
                    self.err(
                        Diagnostic::error(
                            codes::OUT_OF_RANGE,
                            format!("the range of `{}` is empty or reversed", f.name),
                            file,
                            span,
                        )
                        .with_label("the start must be below the end"),
                    );
                }
            }
            (Ty::Formula { coords, result }, Value::Formula(fm)) => {
                if let Some(bad) = fm.params.iter().find(|c| !coords.contains(&c.as_str())) {
                    self.err(
                        Diagnostic::error(
                            codes::UNKNOWN_COORDINATE,
                            format!("`{}` is written in {}, not `{bad}`", f.name, quoted(coords)),
                            file,
                            f.name_span,
                        )
                        .with_label("wrong coordinates"),
                    );
                }
                if fm.result != *result {
                    self.err(
                        Diagnostic::error(
                            codes::FORMULA_DIMENSION,
                            format!(
                                "the formula for `{}` must give {result}, but it gives {}",
                                f.name, fm.result
                            ),
                            file,
                            span,
                        )
                        .with_label(format!("this is {}", fm.result))
                        .with_help(if fm.result.is_none() {
                            "multiply by a length, as in `0.02 mm * sin(…)`"
                        } else {
                            "check the units of each term"
                        }),
                    );
                }
            }
            (_, v) => {
                let v = v.clone();
                if let Value::Word(w) = &v
                    && matches!(p.ty, Ty::Quantity(_) | Ty::Range(_))
                {
                    self.unknown_name(file, span, w);
                    return;
                }
                self.err(
                    Diagnostic::error(
                        codes::WRONG_VALUE,
                        format!(
                            "`{}` must be {}, but this is {}",
                            f.name,
                            ty_words(&p.ty),
                            v.describe()
                        ),
                        file,
                        span,
                    )
                    .with_label("wrong kind of value")
                    .with_help(format!("`{}`: {}", f.name, p.doc)),
                );
            }
        }
    }

    /// Rules that tie several parameters of one kind together.
    fn kind_rules(&mut self, o: &Object) -> bool {
        match o.kind.name {
            "conic" | "sphere" | "asphere" | "cylinder" | "acylinder" | "toroid" | "qbfs"
            | "qcon" => {
                let (Some(r), Some(ap)) = (
                    value::num(&o.fields, "radius").map(f64::abs),
                    value::object(&o.fields, "aperture"),
                ) else {
                    return true;
                };
                let k = value::num(&o.fields, "conic").unwrap_or(0.0);
                let Some(ar) = aperture_radius(ap) else {
                    return true;
                };
                let Some(limit) = lensc_runtime::surface::RotationalSurface::conic_limit(r, k)
                else {
                    return true;
                };
                if ar >= limit {
                    let ap_field = value::field(&o.fields, "aperture").expect("aperture");
                    self.err(
                        Diagnostic::error(
                            codes::CONIC_DOMAIN,
                            format!("the aperture (radius {} mm) reaches beyond the edge of this conic, which ends at r = {} mm", trim_num(ar), trim_num(limit)),
                            ap_field.file,
                            ap_field.span,
                        )
                        .with_label(format!("the conic is only defined for r < {} mm", trim_num(limit)))
                        .with_note(o.file, o.head, "R/sqrt(1 + k) bounds this conic")
                        .with_help("reduce the aperture, or check the sign of the conic constant"),
                    );
                    return false;
                }
                true
            }
            "annulus" => {
                let (Some(inner), Some(outer)) = (
                    value::num(&o.fields, "inner"),
                    value::num(&o.fields, "outer"),
                ) else {
                    return true;
                };
                if inner >= outer {
                    let f = value::field(&o.fields, "inner").expect("inner");
                    self.err(
                        Diagnostic::error(codes::OUT_OF_RANGE, format!("the annulus's inner radius ({} mm) is not inside its outer radius ({} mm)", trim_num(inner), trim_num(outer)), f.file, f.span)
                            .with_label("not below `outer`"),
                    );
                    return false;
                }
                true
            }
            "wrap" => {
                let f = &o.fields;
                let (Some(design), Some(roller)) =
                    (value::object(f, "surface"), value::object(f, "onto"))
                else {
                    return true;
                };
                let Some(radius) = value::num(&roller.fields, "radius") else {
                    return true;
                };
                let length = crate::lower::surface::surface_domain(design).map(|d| match d {
                    lensc_runtime::surface::analysis::Domain::Rect { y, .. } => y.1 - y.0,
                    lensc_runtime::surface::analysis::Domain::Circle { radius }
                    | lensc_runtime::surface::analysis::Domain::Annulus { outer: radius, .. } => {
                        2.0 * radius
                    }
                });
                let Some(length) = length else { return true };
                let at = value::field(f, "onto").expect("onto");
                // The rule and its 1 µm tolerance live with the planner's
                // precondition, so the two cannot disagree.
                use lensc_runtime::plan::roller::{RollerError, check_wrap};
                match check_wrap(radius, length) {
                    Err(RollerError::Overlap { circumference, .. }) => {
                        self.err(
                            Diagnostic::error(
                                codes::WRAP_OVERLAP,
                                format!("the design is {} mm long around the roller, more than its circumference 2π·{} = {} mm: it would overlap itself", trim_num(length), trim_num(radius), trim_num(circumference)),
                                at.file,
                                at.span,
                            )
                            .with_label("this roller is too small for the design")
                            .with_help(format!("a roller for this design has radius L/2π = {} mm", trim_num(length / (2.0 * std::f64::consts::PI)))),
                        );
                        return false;
                    }
                    Ok(fit) if fit.gap > 0.0 => {
                        self.diags.push(
                            Diagnostic::warning(
                                codes::WRAP_GAP,
                                format!("the design is {} mm long around the roller, shorter than its circumference {} mm: a {} mm gap is left", trim_num(length), trim_num(fit.circumference), trim_num(fit.gap)),
                                at.file,
                                at.span,
                            )
                            .with_label("the design does not close around this roller"),
                        );
                    }
                    // Other errors (a length or radius not positive) are
                    // the range checks' to report.
                    _ => {}
                }
                true
            }
            "zernike" => {
                if value::word(&o.fields, "ordering") != Some("fringe") {
                    return true;
                }
                let mut ok = true;
                for f in &o.fields {
                    if let Some(j) = f.name.strip_prefix('Z').and_then(|j| j.parse::<u32>().ok())
                        && !(1..=37).contains(&j)
                    {
                        self.err(
                            Diagnostic::error(
                                codes::UNKNOWN_PARAMETER,
                                format!("fringe Zernike terms are `Z1` … `Z37`, not `{}`", f.name),
                                f.file,
                                f.name_span,
                            )
                            .with_label("no such fringe term")
                            .with_help("use `ordering: ansi` for more terms (numbered from `Z0`)"),
                        );
                        ok = false;
                    }
                }
                ok
            }
            "ellipsoid" => {
                let f = &o.fields;
                let (Some(a), Some(b), Some(ap)) = (
                    value::num(f, "a"),
                    value::num(f, "b"),
                    value::object(f, "aperture"),
                ) else {
                    return true;
                };
                // The cap is defined inside x²/a² + y²/b² < 1.
                let reach = match ap.kind.name {
                    "circle" => aperture_radius(ap).map(|r| r / a.min(b)),
                    _ => value::range(&ap.fields, "x")
                        .zip(value::range(&ap.fields, "y"))
                        .map(|((x0, x1), (y0, y1))| {
                            let (x, y) = (x0.abs().max(x1.abs()), y0.abs().max(y1.abs()));
                            (x * x / (a * a) + y * y / (b * b)).sqrt()
                        }),
                };
                if reach.is_some_and(|q| q >= 1.0) {
                    let ap_field = value::field(f, "aperture").expect("aperture");
                    self.err(
                        Diagnostic::error(
                            codes::CONIC_DOMAIN,
                            "the aperture reaches beyond the ellipsoid's rim (x²/a² + y²/b² = 1)",
                            ap_field.file,
                            ap_field.span,
                        )
                        .with_label(format!(
                            "reaches {} of the way to the rim",
                            trim_num(reach.unwrap_or(0.0))
                        ))
                        .with_help("keep the aperture inside the semi-axes a and b"),
                    );
                    return false;
                }
                true
            }
            "profile_turning" => {
                let f = &o.fields;
                let stock = value::field(f, "stock_top").or(value::field(f, "stock_allowance"));
                if let Some(at) = stock
                    && value::num(f, "depth_of_cut").is_none()
                {
                    self.err(
                        Diagnostic::error(
                            codes::MISSING_PARAMETER,
                            format!("`{}` gives the stock, but no `depth_of_cut` says how much each roughing pass removes", at.name),
                            at.file,
                            at.span,
                        )
                        .with_label("the stock")
                        .with_help("add `depth_of_cut: …`, a length"),
                    );
                    return false;
                }
                if let (Some(from), Some(to)) =
                    (value::num(&o.fields, "from"), value::num(&o.fields, "to"))
                    && from <= to
                {
                    let f = value::field(&o.fields, "from").expect("from");
                    self.err(
                        Diagnostic::error(
                            codes::OUT_OF_RANGE,
                            "the cut must start at a larger radius than it ends",
                            f.file,
                            f.span,
                        )
                        .with_label("`from` is not above `to`"),
                    );
                    return false;
                }
                true
            }
            _ => true,
        }
    }

    /// The material side is given either by a positive radius and `sense`,
    /// or by a signed radius with `convention: optical`, never both.
    fn sign_rule(&mut self, o: &Object) -> bool {
        let f = &o.fields;
        let optical = value::word(f, "convention") == Some("optical");
        let radii: Vec<&Field> = ["radius", "radius_x", "radius_y"]
            .iter()
            .filter_map(|n| value::field(f, n))
            .collect();
        let mut ok = true;
        if optical {
            if let Some(sense) = value::field(f, "sense") {
                let conv = value::field(f, "convention").expect("convention");
                self.err(
                    Diagnostic::error(codes::CONFLICTING_PARAMETERS, "`sense` and `convention: optical` both say which side is material", sense.file, sense.name_span)
                        .with_label("remove this")
                        .with_note(conv.file, conv.span, "the radius's sign says it here")
                        .with_help("with `convention: optical` the sign of the radius gives the side: R > 0 convex, R < 0 concave"),
                );
                ok = false;
            }
            for r in radii {
                if matches!(r.value, Value::Num(v, _) if v == 0.0) {
                    self.err(
                        Diagnostic::error(
                            codes::OUT_OF_RANGE,
                            format!("`{}` cannot be zero", r.name),
                            r.file,
                            r.span,
                        )
                        .with_label("zero radius")
                        .with_help("a flat surface is a `plane`"),
                    );
                    ok = false;
                }
            }
            return ok;
        }
        if value::field(f, "sense").is_none()
            && (!radii.is_empty()
                || o.kind
                    .params
                    .iter()
                    .any(|p| p.name == "radius" && p.required))
        {
            self.err(
                Diagnostic::error(codes::MISSING_PARAMETER, format!("`{}` is missing `sense`", o.kind.name), o.file, o.head)
                    .with_label("needs `sense`")
                    .with_help("add `sense: convex` (a dome) or `sense: concave` (a bowl), or give a signed radius with `convention: optical`"),
            );
            ok = false;
        }
        for r in radii {
            if let Value::Num(v, _) = r.value
                && v <= 0.0
            {
                self.err(
                    Diagnostic::error(codes::OUT_OF_RANGE, format!("`{}` must be greater than zero, but it is {} mm", r.name, trim_num(v)), r.file, r.span)
                        .with_label("out of range")
                        .with_help("with `sense`, the radius is a magnitude; a signed radius as in lens design needs `convention: optical` (R < 0 concave)"),
                );
                ok = false;
            }
        }
        ok
    }

    // ---- jobs -----------------------------------------------------------------

    fn check_jobs(&mut self) -> Vec<CheckedJob> {
        let loaded = self.loaded;
        let root = &loaded.files[0];
        let mut jobs: Vec<CheckedJob> = Vec::new();
        let mut seen: HashMap<&str, Span> = HashMap::new();
        for item in &root.ast.items {
            let ItemKind::Job { name, body } = &item.kind else {
                continue;
            };
            if let Some(first) = seen.get(name.name.as_str()) {
                self.err(
                    Diagnostic::error(
                        codes::DUPLICATE_NAME,
                        format!("job `{}` is defined twice", name.name),
                        root.id,
                        name.span,
                    )
                    .with_label("second definition")
                    .with_note(root.id, *first, "first defined here"),
                );
                continue;
            }
            seen.insert(&name.name, name.span);
            let fields = self.block_fields(root.id, body, &[]);
            let mut part_names = HashMap::new();
            for entry in &body.entries {
                if let Entry::Param { name: p, value } = entry
                    && let ExprKind::Name(n) = &value.kind
                {
                    part_names.insert(p.name.clone(), n.clone());
                }
            }
            if self.validate(
                schema::JOB_PARAMS,
                &fields,
                &format!("job `{}`", name.name),
                name.span,
                root.id,
                &[],
            ) {
                jobs.push(CheckedJob {
                    name: name.clone(),
                    file: root.id,
                    fields,
                    part_names,
                });
            }
        }
        jobs
    }

    /// Unused definitions are worth a warning in a job file; a file with no
    /// job (a library of surfaces or tools) is all definitions by design.
    fn warn_unused(&mut self) {
        let has_jobs = self.loaded.files[0]
            .ast
            .items
            .iter()
            .any(|i| matches!(i.kind, ItemKind::Job { .. }));
        for (i, d) in self.decls.iter().enumerate() {
            if !has_jobs && d.kind.is_some() {
                continue;
            }
            if d.file == FileId(0) && !self.used[i] {
                self.diags.push(
                    Diagnostic::warning(
                        codes::UNUSED,
                        format!("`{}` is never used", d.name.name),
                        d.file,
                        d.name.span,
                    )
                    .with_label("defined here")
                    .with_help("remove it, or use it in a job"),
                );
            }
        }
    }
}

/// Copies `base` with `over` replacing fields of the same name; nested
/// blocks are merged field by field.
fn merge(base: &[Field], over: Vec<Field>) -> Vec<Field> {
    let mut out: Vec<Field> = base.to_vec();
    for f in over {
        match out.iter_mut().find(|b| b.name == f.name) {
            Some(slot) => {
                if let (Value::Block(a), Value::Block(b)) = (&slot.value, &f.value) {
                    let merged = merge(a, b.as_ref().clone());
                    *slot = Field {
                        value: Value::Block(Rc::new(merged)),
                        ..f
                    };
                } else {
                    *slot = f;
                }
            }
            None => out.push(f),
        }
    }
    out
}

/// The radius of a circular aperture, if it is one.
/// The outer radius of a circular or annular aperture.
pub fn aperture_radius(ap: &Object) -> Option<f64> {
    match ap.kind.name {
        "circle" => value::num(&ap.fields, "radius")
            .or_else(|| value::num(&ap.fields, "diameter").map(|d| d / 2.0)),
        "annulus" => value::num(&ap.fields, "outer"),
        _ => None,
    }
}

/// The inner radius of an annular aperture (0 for a circle).
pub fn aperture_inner_radius(ap: &Object) -> f64 {
    if ap.kind.name == "annulus" {
        value::num(&ap.fields, "inner").unwrap_or(0.0)
    } else {
        0.0
    }
}

fn param_list(params: &[Param]) -> String {
    params.iter().map(|p| p.name).collect::<Vec<_>>().join(", ")
}

fn quoted(names: &[&str]) -> String {
    let q: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    q.join(", ")
}

fn one_of(words: &[&str]) -> String {
    match words {
        [one] => format!("`{one}`"),
        _ => format!("one of {}", quoted(words)),
    }
}

fn ty_words(ty: &Ty) -> String {
    match ty {
        Ty::Quantity(dims) => dims
            .iter()
            .map(|d| d.to_string())
            .collect::<Vec<_>>()
            .join(" or "),
        Ty::Word(words) => one_of(words),
        Ty::Object(c) => c.noun().to_string(),
        Ty::Objects(c) => format!(
            "a list of {}s",
            c.noun().trim_start_matches("a ").trim_start_matches("an ")
        ),
        Ty::Text => "a string `\"…\"`".into(),
        Ty::Texts => "a list of strings `[\"…\"]`".into(),
        Ty::Block(_) => "a block `{ … }`".into(),
        Ty::Range(d) => format!("a range `from .. to` of {d}"),
        Ty::Formula { coords, .. } => format!("a formula of {}", quoted(coords)),
    }
}

fn example_unit(d: Dim) -> &'static str {
    match d {
        Dim::LENGTH => "`85 um` or `1.5 mm`",
        Dim::ANGLE => "`7 deg`",
        Dim::SPEED => "`100 mm/min`",
        Dim::FEED_PER_REV => "`2 um/rev`",
        Dim::ROTATIONAL_SPEED => "`1000 rpm`",
        Dim::TIME => "`1 ms`",
        Dim::FREQUENCY => "`20 kHz`",
        Dim::ACCELERATION => "`25 g`",
        _ => "`1 mm^-3`",
    }
}

/// A figure for a message: up to 6 significant decimals, no trailing zeros.
pub fn trim_num(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}
