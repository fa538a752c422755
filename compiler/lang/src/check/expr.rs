//! Expressions: numbers with units, names, arithmetic with
//! dimensional analysis, the built-in functions, calls and blocks that
//! construct kinds, and surface formulas.

use std::collections::HashMap;
use std::rc::Rc;

use lensc_grammar::ast::{Arg, BinaryOp, Block, Entry, Expr, ExprKind, Span, UnaryOp, Unit};
use lensc_grammar::suggest::did_you_mean;
use lensc_grammar::{Diagnostic, FileId};

use super::{COORDINATES, Checker, FUNCTIONS, param_list};
use crate::codes;
use crate::schema::{self, Kind};
use crate::units::{self, Dim};
use crate::value::{Field, Formula, Value};

impl<'a> Checker<'a> {
    /// The value of `e`. A number that is not finite (an overflow such as
    /// `1e308 * 1e308`, `inf - inf`) is an error where it first appears,
    /// and no value; in a formula a coordinate is NaN, so only an infinity
    /// is reported there (a formula is sampled over its aperture later).
    pub(super) fn eval(&mut self, file: FileId, e: &Expr, coords: &[String]) -> Value {
        let v = self.eval_inner(file, e, coords);
        match v {
            Value::Num(x, _) if x.is_infinite() || (x.is_nan() && coords.is_empty()) => {
                self.err(
                    Diagnostic::error(
                        codes::NOT_FINITE,
                        format!(
                            "this number is {}",
                            if x.is_nan() {
                                "not a number (NaN)"
                            } else {
                                "infinite: larger than about 1.8e308"
                            }
                        ),
                        file,
                        e.span,
                    )
                    .with_label("no finite value")
                    .with_help("every quantity must be a finite number: check the exponents and the operations here"),
                );
                Value::Error
            }
            v => v,
        }
    }

    fn eval_inner(&mut self, file: FileId, e: &Expr, coords: &[String]) -> Value {
        match &e.kind {
            ExprKind::Invalid => Value::Error,
            ExprKind::Quantity { value, unit } => {
                self.quantity(file, *value, unit.as_ref(), coords)
            }
            ExprKind::Str(s) => Value::Str(s.clone()),
            ExprKind::Name(n) => self.name_value(file, n, coords),
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
            ExprKind::Call { callee, args } => self.call(file, e.span, callee, args, coords),
            ExprKind::WithBlock { base, block } => self.with_block(file, base, block, coords),
            ExprKind::Block(block) => Value::Block(Rc::new(self.block_fields(file, block, coords))),
            ExprKind::List(items) => Value::List(
                items
                    .iter()
                    .map(|i| (self.eval(file, i, coords), i.span))
                    .collect(),
            ),
        }
    }

    /// A number with its unit, in base units.
    fn quantity(
        &mut self,
        file: FileId,
        value: f64,
        unit: Option<&Unit>,
        coords: &[String],
    ) -> Value {
        let Some(unit) = unit else {
            return Value::Num(value, Dim::NONE);
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

    /// A name: a coordinate, a declaration, a function or a kind; else a
    /// word for the parameter to judge.
    fn name_value(&mut self, file: FileId, n: &str, coords: &[String]) -> Value {
        if coords.iter().any(|c| c == n) {
            return Value::Num(f64::NAN, Dim::LENGTH);
        }
        if let Some(i) = self.lookup(file, n) {
            let v = self.decl_value(i);
            if let (Some(consts), Value::Num(x, _)) = (&mut self.formula_constants, &v) {
                consts.insert(n.to_string(), *x);
            }
            return v;
        }
        if FUNCTIONS.contains(&n) {
            let f = FUNCTIONS.iter().find(|f| **f == n).expect("function");
            return Value::Function(f);
        }
        if let Some(k) = schema::kind(n) {
            return Value::Kind(k);
        }
        Value::Word(n.to_string())
    }

    /// A call: of a built-in function, or of a kind with its arguments.
    fn call(
        &mut self,
        file: FileId,
        span: Span,
        callee: &Expr,
        args: &[Arg],
        coords: &[String],
    ) -> Value {
        let f = self.eval(file, callee, coords);
        match f {
            Value::Function(name) => {
                self.call_function(file, name, span, callee.span, args, coords)
            }
            Value::Kind(k) => self.construct_from_args(file, k, callee.span, args, coords),
            Value::Error => {
                for a in args {
                    self.eval(file, &a.value, coords);
                }
                Value::Error
            }
            Value::Word(w) => self.unknown_function(file, &w, callee.span),
            other => {
                self.err(
                    Diagnostic::error(
                        codes::NOT_CALLABLE,
                        format!("{} cannot be called", other.describe()),
                        file,
                        callee.span,
                    )
                    .with_label("not a function")
                    .with_help("only functions (`sin(…)`) and kinds (`circle(…)`) take arguments in brackets; to multiply, write `*` between the factors"),
                );
                Value::Error
            }
        }
    }

    /// A kind called with arguments, named or in its positional order.
    fn construct_from_args(
        &mut self,
        file: FileId,
        k: &'static Kind,
        head: Span,
        args: &[Arg],
        coords: &[String],
    ) -> Value {
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
        self.construct(k, fields, head, file)
    }

    fn unknown_function(&mut self, file: FileId, w: &str, span: Span) -> Value {
        let mut d = Diagnostic::error(
            codes::UNKNOWN_NAME,
            format!("unknown function `{w}`"),
            file,
            span,
        )
        .with_label("not defined");
        let cands = FUNCTIONS
            .iter()
            .copied()
            .chain(schema::KINDS.iter().map(|k| k.name));
        d = d.with_help(match did_you_mean(w, cands) {
            Some(s) => format!("did you mean `{s}`?"),
            None => format!("the functions are: {}", FUNCTIONS.join(", ")),
        });
        self.err(d);
        Value::Error
    }

    /// A block after a kind (`conic { … }`) or after a declaration to copy
    /// and change.
    fn with_block(&mut self, file: FileId, base: &Expr, block: &Block, coords: &[String]) -> Value {
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
            Value::Word(w) => self.unknown_kind(file, &w, base.span, block, coords),
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

    fn unknown_kind(
        &mut self,
        file: FileId,
        w: &str,
        span: Span,
        block: &Block,
        coords: &[String],
    ) -> Value {
        let mut d = Diagnostic::error(
            codes::UNKNOWN_NAME,
            format!("unknown kind `{w}`"),
            file,
            span,
        )
        .with_label("not a kind or declaration");
        let scope = &self.scopes[file.0 as usize];
        // As the value of a declaration (`surface s = …`), only the kinds
        // of that category are meant; elsewhere any kind may be.
        let category = self
            .declaring
            .filter(|&(_, start)| start == span.start)
            .map(|(c, _)| c);
        let kinds: Vec<&str> = schema::KINDS
            .iter()
            .filter(|k| category.is_none_or(|c| k.category == c))
            .map(|k| k.name)
            .collect();
        let mut cands = kinds.clone();
        cands.extend(scope.keys().copied());
        let listed = match category {
            Some(c) => format!("{} is made by one of: {}", c.noun(), kinds.join(", ")),
            None => format!("the kinds are: {}", kinds.join(", ")),
        };
        d = d.with_help(
            match super::scope::known_elsewhere(scope, w, cands, category) {
                Some(help) => help,
                None => match kind_within(w, &kinds) {
                    Some(k) => format!("did you mean `{k}`? {listed}"),
                    None => listed,
                },
            },
        );
        self.err(d);
        self.block_fields(file, block, coords);
        Value::Error
    }

    pub(super) fn push_field(&mut self, fields: &mut Vec<Field>, f: Field) {
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

    pub(super) fn block_fields(
        &mut self,
        file: FileId,
        block: &Block,
        coords: &[String],
    ) -> Vec<Field> {
        let mut fields = Vec::new();
        // The names given so far: a name given once is pushed at once, and
        // only a repeated one is looked for among the fields (to report
        // where it was first given), so a block of n entries checks in
        // O(n), not O(n²).
        let mut seen: std::collections::HashSet<String> = std::collections::HashSet::new();
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
            if seen.insert(f.name.clone()) {
                fields.push(f);
            } else {
                self.push_field(&mut fields, f);
            }
        }
        fields
    }

    /// Reports a value that should have been a number.
    pub(super) fn expect_number(&mut self, file: FileId, span: Span, v: &Value, action: &str) {
        match v {
            Value::Error => {}
            Value::Word(w) => {
                let w = w.clone();
                self.unknown_name(file, span, &w, None);
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

    /// `5 mm / min`: a unit written with spaces around `/` (or `*`) reads
    /// as a division by the function `min` or the name `s`; say how a unit
    /// is written instead.
    fn spaced_unit(
        &self,
        file: FileId,
        op: BinaryOp,
        (a, sa): (&Value, Span),
        (b, sb): (&Value, Span),
    ) -> Option<Diagnostic> {
        let (BinaryOp::Div | BinaryOp::Mul) = op else {
            return None;
        };
        let (name, read_as): (&str, String) = match (a, b) {
            (Value::Num(..), Value::Function(f)) => (f, format!("the function `{f}`")),
            (Value::Num(..), Value::Word(w)) => (w, format!("an unknown name `{w}`")),
            _ => return None,
        };
        units::lookup(name)?;
        let text = &self.loaded.sources.get(file).text;
        let left = text.get(sa.start as usize..sa.end as usize)?;
        let sign = if op == BinaryOp::Div { "/" } else { "*" };
        Some(
            Diagnostic::error(
                codes::WRONG_VALUE,
                format!(
                    "a unit is written without spaces around `{sign}`: here `{name}` is read as {read_as}, not as the unit"
                ),
                file,
                sb,
            )
            .with_label(format!("a unit after `{sign}` is written without spaces"))
            .with_help(format!(
                "write the unit without spaces around `{sign}`: `{left}{sign}{name}`"
            )),
        )
    }

    pub(super) fn binary(
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
                if let Some(d) = self.spaced_unit(file, op, (&a, sa), (&b, sb)) {
                    self.err(d);
                    return Value::Error;
                }
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
                self.additive(file, op, span, (x, da, sa), (y, db, sb))
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
            BinaryOp::Pow => self.power(file, span, (x, da), (y, db, sb)),
        }
    }

    /// `a + b`, `a - b` and the range `a .. b`: both sides of one dimension.
    fn additive(
        &mut self,
        file: FileId,
        op: BinaryOp,
        span: Span,
        (x, da, sa): (f64, Dim, Span),
        (y, db, sb): (f64, Dim, Span),
    ) -> Value {
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
                d = d
                    .with_help("a plain number has no unit: write the unit after it, as in `3 um`");
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

    /// `a ^ b`: a plain exponent; a quantity with units only to a small
    /// whole-number constant power.
    fn power(
        &mut self,
        file: FileId,
        span: Span,
        (x, da): (f64, Dim),
        (y, db, sb): (f64, Dim, Span),
    ) -> Value {
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
                .with_help("use sqrt for square roots; other powers of a unit have no meaning"),
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

    pub(super) fn call_function(
        &mut self,
        file: FileId,
        name: &'static str,
        span: Span,
        callee: Span,
        args: &[lensc_grammar::ast::Arg],
        coords: &[String],
    ) -> Value {
        let Some(vals) = self.function_args(file, name, args, coords) else {
            return Value::Error;
        };
        if !self.arity_ok(file, name, span, callee, vals.len()) {
            return Value::Error;
        }
        self.apply_function(file, name, span, &vals)
    }

    /// The arguments of a built-in function: plain numbers or quantities,
    /// never named.
    fn function_args(
        &mut self,
        file: FileId,
        name: &'static str,
        args: &[lensc_grammar::ast::Arg],
        coords: &[String],
    ) -> Option<Vec<(f64, Dim, Span)>> {
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
        (!bad).then_some(vals)
    }

    /// Whether a built-in function has the number of arguments it takes.
    fn arity_ok(
        &mut self,
        file: FileId,
        name: &str,
        span: Span,
        callee: Span,
        count: usize,
    ) -> bool {
        let arity_ok = match name {
            "atan2" => count == 2,
            "min" | "max" => count >= 2,
            _ => count == 1,
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
                    format!("`{name}` takes {want}, not {count}"),
                    file,
                    span,
                )
                .with_label("wrong number of arguments")
                .with_note(file, callee, "this function"),
            );
            return false;
        }
        true
    }

    /// A built-in function of checked arguments: each argument's dimension
    /// and domain, and the value.
    fn apply_function(
        &mut self,
        file: FileId,
        name: &'static str,
        span: Span,
        vals: &[(f64, Dim, Span)],
    ) -> Value {
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
            "atan2" => self.atan2(file, span, vals),
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
            _ => self.min_max(file, name, vals),
        }
    }

    /// `atan2(y, x)`: two arguments of one dimension, giving an angle.
    fn atan2(&mut self, file: FileId, span: Span, vals: &[(f64, Dim, Span)]) -> Value {
        let ((x, d, s), (x2, d2, s2)) = (vals[0], vals[1]);
        if d != d2 {
            self.err(
                Diagnostic::error(
                    codes::BAD_ARGUMENT_DIMENSION,
                    format!("`atan2` needs two arguments of one dimension, not {d} and {d2}"),
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

    /// `min` and `max`: arguments of one dimension.
    fn min_max(&mut self, file: FileId, name: &str, vals: &[(f64, Dim, Span)]) -> Value {
        let (x, d, s) = vals[0];
        let mut acc = x;
        for &(y, dy, sy) in &vals[1..] {
            if dy != d {
                self.err(
                    Diagnostic::error(
                        codes::BAD_ARGUMENT_DIMENSION,
                        format!("`{name}` needs arguments of one dimension, not {d} and {dy}"),
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

/// The longest kind name that a misspelt kind contains, or that contains
/// it (`even_asphere` → `asphere`): names a user qualified or cut short,
/// beyond the reach of an edit distance.
fn kind_within<'k>(word: &str, kinds: &[&'k str]) -> Option<&'k str> {
    let word = word.to_ascii_lowercase();
    kinds
        .iter()
        .copied()
        .filter(|k| {
            k.len() >= 4 && word.len() >= 4 && (word.contains(k) || k.contains(word.as_str()))
        })
        .max_by_key(|k| k.len())
}
