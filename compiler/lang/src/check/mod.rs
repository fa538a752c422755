//! The checker: name resolution across files, evaluation of every
//! expression with dimensional analysis, and validation of every block
//! against its kind's parameters. It reports every error it finds and
//! hands back the checked jobs of the root file.
//!
//! This file holds the checker's state, the entry `check` and the jobs of
//! the root file; by concern: `scope` (declarations, names, imports,
//! cycles), `expr` (expressions, units, functions, formulas), `params`
//! (blocks of parameters against the schema) and `rules` (the rules that
//! tie a kind's parameters together, one function per rule).

use std::collections::HashMap;
use std::rc::Rc;

use lensc_grammar::ast::{DeclKind, Entry, Expr, ExprKind, Ident, ItemKind, Span};
use lensc_grammar::{Diagnostic, FileId};

use crate::codes;
use crate::loader::Loaded;
use crate::schema::{self, Param, Ty};
use crate::units::Dim;
use crate::value::{Field, Object, Value};

mod expr;
mod params;
mod rules;
mod scope;

pub use crate::domain::{aperture_inner_radius, aperture_radius};

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
    /// The file the job is written in (`None` for text given directly)
    /// and the project root it was read beneath: a file the job names
    /// (`compensate { measurement: … }`) is found beside the one and
    /// read beneath the other.
    pub path: Option<std::path::PathBuf>,
    pub root: Option<std::sync::Arc<crate::sandbox::Root>>,
}

pub struct Checked {
    pub jobs: Vec<CheckedJob>,
    pub diags: Vec<Diagnostic>,
    /// Every surface, tool, machine and strategy the root file can name
    /// (its own and those it uses) that checked, by name.
    pub declarations: HashMap<String, Rc<Object>>,
    /// Every `let` of every loaded file that evaluated: its file, where its
    /// name is written, and its value (what an editor's hover shows).
    pub lets: Vec<(FileId, Span, Value)>,
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
    /// While a declaration's value is evaluated: the category it declares
    /// and where its value starts, so that an unknown kind there is matched
    /// against that category's kinds (`surface s = even_asphere { … }`).
    declaring: Option<(schema::Category, u32)>,
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
        declaring: None,
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
    let lets = c
        .decls
        .iter()
        .zip(&c.state)
        .filter_map(|(d, s)| match (d.kind, s) {
            (None, State::Done(v)) if !matches!(v, Value::Error) => {
                Some((d.file, d.name.span, v.clone()))
            }
            _ => None,
        })
        .collect();
    let mut diags = loaded.diags.clone();
    diags.append(&mut c.diags);
    Checked {
        jobs,
        diags,
        declarations,
        lets,
    }
}

impl<'a> Checker<'a> {
    fn err(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    fn error_count(&self) -> usize {
        self.diags.iter().filter(|d| d.is_error()).count()
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
                    path: self.loaded.sources.get(root.id).path.clone(),
                    root: self.loaded.root.clone(),
                });
            }
        }
        jobs
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
        Ty::BlockOr(_, words) => format!("a block `{{ … }}` or {}", one_of(words)),
        Ty::Range(d) => format!("a range `from .. to` of {d}"),
        Ty::Formula { coords, .. } => format!("a formula of {}", quoted(coords)),
    }
}

fn example_unit(d: Dim) -> String {
    match d {
        Dim::LENGTH => "`85 um` or `1.5 mm`".into(),
        Dim::ANGLE => "`7 deg`".into(),
        Dim::SPEED => "`100 mm/min`".into(),
        Dim::FEED_PER_REV => "`2 um/rev`".into(),
        Dim::ROTATIONAL_SPEED => "`1000 rpm`".into(),
        Dim::TIME => "`1 ms`".into(),
        Dim::FREQUENCY => "`20 kHz`".into(),
        Dim::ACCELERATION => "`25 g`".into(),
        Dim::AREA => "`0.01 mm^2`".into(),
        // A power of a length (an asphere's A6 is mm^-5): that power.
        Dim {
            length,
            angle: 0,
            time: 0,
        } => format!("`1 mm^{length}`"),
        // Anything else: the unit in the dimension's own words.
        other => format!("a number with a unit in {other}"),
    }
}

/// A figure for a message: up to 6 significant decimals, no trailing zeros.
pub fn trim_num(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}
