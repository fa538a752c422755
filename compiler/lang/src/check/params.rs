//! Blocks of parameters against the schema: unknown, missing and
//! conflicting parameters, and each value's type, dimension and range.

use std::rc::Rc;

use lensc_grammar::ast::Span;
use lensc_grammar::suggest::did_you_mean;
use lensc_grammar::{Diagnostic, FileId};

use super::{Checker, example_unit, one_of, param_list, quoted, trim_num, ty_words};
use crate::codes;
use crate::schema::{self, Check, Kind, Param, Ty};
use crate::units::Dim;
use crate::value::{self, Field, Formula, Object, Value};

impl<'a> Checker<'a> {
    pub(super) fn construct(
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
    pub(super) fn validate(
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
    pub(super) fn validate_with(
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
                let named_elsewhere = named_as_elsewhere(params, f);
                let near = did_you_mean(&f.name, params.iter().map(|p| p.name));
                d = d.with_help(match (named_elsewhere, near) {
                    (Some(h), _) => h,
                    (None, Some(s)) => format!("did you mean `{s}`?"),
                    (None, None) => match family {
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

    pub(super) fn check_param(&mut self, p: &Param, f: &Field, owner: &str) {
        let (file, span) = (f.file, f.span);
        match (&p.ty, &f.value) {
            (_, Value::Error) => {}
            (Ty::Quantity(dims), Value::Num(v, d)) => self.check_quantity(p, f, dims, *v, *d),
            (Ty::Word(words), Value::Word(w)) => self.check_word(p, f, words, w),
            (Ty::Object(cat), Value::Object(o)) if o.kind.category == *cat => {}
            (Ty::Object(cat), v @ Value::Word(_)) => {
                self.expect_category(file, span, v.clone(), *cat, None);
            }
            (Ty::Text, Value::Str(_)) => {}
            (Ty::Texts, Value::List(items)) => self.check_texts(p, f, items),
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
            (Ty::BlockOr(_, words), Value::Word(w)) => self.check_word(p, f, words, w),
            (Ty::Block(sub) | Ty::BlockOr(sub, _), Value::Block(fields)) => {
                let owner = format!("`{}` of {owner}", f.name);
                self.validate(sub, fields, &owner, f.name_span, file, &[]);
            }
            (Ty::Range(dim), Value::Range(lo, hi, d)) => self.check_range(f, *dim, (*lo, *hi, *d)),
            (Ty::Formula { coords, result }, Value::Formula(fm)) => {
                self.check_formula(f, coords, *result, fm)
            }
            (_, v) => self.wrong_value(p, f, v),
        }
    }

    /// A quantity: of one of the parameter's dimensions and in its range.
    fn check_quantity(&mut self, p: &Param, f: &Field, dims: &[Dim], v: f64, d: Dim) {
        let (file, span) = (f.file, f.span);
        if !dims.contains(&d) {
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
            let examples = dims
                .iter()
                .map(|d| example_unit(*d))
                .collect::<Vec<_>>()
                .join(" or ");
            diag = diag.with_help(if d.is_none() {
                format!("write a unit after the number, for example {examples}")
            } else if dims == [Dim::NONE] {
                format!(
                    "write `{}` as a plain number, with no unit ({})",
                    f.name, p.doc
                )
            } else {
                format!("write `{}` as, for example, {examples} ({})", f.name, p.doc)
            });
            self.err(diag);
            return;
        }
        let ok = match p.check {
            Check::Any => true,
            Check::Positive => v > 0.0,
            Check::NonNegative => v >= 0.0,
            Check::HalfOpen(lo, hi) => v >= lo && v < hi,
            Check::Open(lo, hi) => v > lo && v < hi,
            Check::Count => v.fract() == 0.0 && (1.0..=100_000.0).contains(&v),
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

    /// A word: one of those the parameter takes.
    fn check_word(&mut self, p: &Param, f: &Field, words: &[&str], w: &str) {
        let (file, span) = (f.file, f.span);
        if !words.contains(&w) {
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

    /// A list of strings.
    fn check_texts(&mut self, p: &Param, f: &Field, items: &[(Value, Span)]) {
        let file = f.file;
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

    /// A range `lo .. hi`: of the parameter's dimension, and not empty.
    fn check_range(&mut self, f: &Field, dim: Dim, (lo, hi, d): (f64, f64, Dim)) {
        let (file, span) = (f.file, f.span);
        if d != dim {
            self.err(
                Diagnostic::error(
                    codes::PARAMETER_DIMENSION,
                    format!("the ends of `{}` must be {dim}, but they are {d}", f.name),
                    file,
                    span,
                )
                .with_label(format!("this is {d}"))
                .with_help(format!(
                    "write both ends as {dim}, for example {}",
                    example_unit(dim)
                )),
            );
        } else if lo >= hi {
            self.err(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    format!("the range of `{}` is empty or reversed", f.name),
                    file,
                    span,
                )
                .with_label("the start must be below the end")
                .with_help({
                    let (unit, factor) = d.display_unit();
                    if lo == hi {
                        "its ends are equal: give the range a length".to_string()
                    } else {
                        format!(
                            "write the lower end first: `{} {unit} .. {} {unit}`",
                            trim_num(hi * factor),
                            trim_num(lo * factor)
                        )
                    }
                }),
            );
        }
    }

    /// A formula: in the parameter's coordinates, giving its dimension.
    fn check_formula(&mut self, f: &Field, coords: &[&str], result: Dim, fm: &Formula) {
        let (file, span) = (f.file, f.span);
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
        if fm.result != result {
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

    /// A value of the wrong kind for the parameter.
    fn wrong_value(&mut self, p: &Param, f: &Field, v: &Value) {
        let (file, span) = (f.file, f.span);
        let v = v.clone();
        if let Value::Word(w) = &v
            && matches!(p.ty, Ty::Quantity(_) | Ty::Range(_))
        {
            self.unknown_name(file, span, w, None);
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

/// Help for a parameter named as other tools and drawings name it, where
/// the kind takes the same thing under another name and form: a ball's or
/// a circle's `radius` where lensc takes its `diameter` (a spelling guess
/// would not say the value doubles), a rectangle's `width` and `height`
/// where lensc takes the ranges `x` and `y`, a job's `dialect`, which
/// `lensc build --dialect` chooses. `None` where the kind takes
/// no such parameter.
fn named_as_elsewhere(params: &[Param], f: &Field) -> Option<String> {
    let takes = |name: &str| params.iter().any(|p| p.name == name);
    let length = match f.value {
        Value::Num(v, Dim::LENGTH) if v.is_finite() && v > 0.0 => Some(v),
        _ => None,
    };
    match f.name.as_str() {
        "radius" if takes("diameter") => Some(match length {
            Some(r) => format!(
                "this is sized by its `diameter`, twice the radius: `diameter: {} mm`",
                trim_num(2.0 * r)
            ),
            None => "this is sized by its `diameter`, twice the radius".into(),
        }),
        "width" | "height" if takes("x") && takes("y") => {
            let (axis, other) = if f.name == "width" {
                ("x", "y")
            } else {
                ("y", "x")
            };
            Some(match length {
                Some(w) => format!(
                    "a rectangle is given by its ranges `x` and `y`: `{axis}: {} mm .. {} mm` is a {} of {} mm centred on the axis (and `{other}: …` likewise)",
                    trim_num(-w / 2.0),
                    trim_num(w / 2.0),
                    f.name,
                    trim_num(w)
                ),
                None => format!(
                    "a rectangle is given by its ranges `x` and `y`: the {} is `{axis}: lo .. hi`",
                    f.name
                ),
            })
        }
        "dialect" if takes("machine") && takes("strategy") => Some(match match &f.value {
            Value::Word(w) => Some(w),
            Value::Object(o) => o.name.as_ref(),
            _ => None,
        } {
            Some(w) => format!(
                "a job's program is written in its machine's dialect; another the machine offers (its `other_dialects`) is chosen when building: `lensc build FILE --dialect {w}`"
            ),
            _ => "a job's program is written in its machine's dialect; another the machine offers (its `other_dialects`) is chosen when building: `lensc build FILE --dialect NAME`".into(),
        }),
        _ => None,
    }
}
