//! Names: declarations and `let`s of every file, `use` imports,
//! evaluation of each declaration once (reporting cycles), unknown
//! names with a suggestion, and unused definitions.

use std::collections::HashMap;

use lensc_grammar::ast::{DeclKind, Ident, ItemKind, Span};
use lensc_grammar::suggest::{completions, did_you_mean, meant};
use lensc_grammar::{Diagnostic, FileId};

use super::{COORDINATES, Checker, Decl, FUNCTIONS, State};
use crate::codes;
use crate::loader::{Import, ParsedFile};
use crate::schema::{self, Category};
use crate::stdlib;
use crate::units;
use crate::value::Value;

impl<'a> Checker<'a> {
    /// Builds every file's scope: its own items first, then its imports.
    pub(super) fn build_scopes(&mut self) {
        let loaded = self.loaded;
        let locals: Vec<HashMap<&'a str, usize>> = loaded
            .files
            .iter()
            .map(|pf| self.declare_items(pf))
            .collect();
        for pf in &loaded.files {
            let scope = self.resolve_imports(pf, &locals);
            self.scopes.push(scope);
        }
    }

    /// A file's own `let`s and declarations, by name.
    fn declare_items(&mut self, pf: &'a ParsedFile) -> HashMap<&'a str, usize> {
        let mut scope: HashMap<&'a str, usize> = HashMap::with_capacity(pf.ast.items.len());
        for item in &pf.ast.items {
            let (name, kind, value) = match &item.kind {
                ItemKind::Let { name, value } => (name, None, value),
                ItemKind::Decl { kind, name, value } => (name, Some(*kind), value),
                _ => continue,
            };
            if !self.name_is_free(pf.id, &scope, name) {
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
        scope
    }

    /// Whether `name` may be defined in a file: not twice, and not a word,
    /// function, kind or coordinate lensc already gives a meaning.
    fn name_is_free(
        &mut self,
        file: FileId,
        scope: &HashMap<&'a str, usize>,
        name: &Ident,
    ) -> bool {
        if let Some(&prev) = scope.get(name.name.as_str()) {
            let first = self.decls[prev].name.span;
            self.err(
                Diagnostic::error(
                    codes::DUPLICATE_NAME,
                    format!("`{}` is defined twice", name.name),
                    file,
                    name.span,
                )
                .with_label("second definition")
                .with_note(file, first, "first defined here")
                .with_help("rename one of them"),
            );
            return false;
        }
        if schema::is_word(&name.name) {
            self.err(
                Diagnostic::error(
                    codes::DUPLICATE_NAME,
                    format!("`{}` is a word lensc uses as a value", name.name),
                    file,
                    name.span,
                )
                .with_label("this name would hide the word")
                .with_help(format!(
                    "`{}` is the value of a parameter (as in `sense: convex`); choose another name",
                    name.name
                )),
            );
            return false;
        }
        let n = name.name.as_str();
        let builtin = if FUNCTIONS.contains(&n) {
            Some("a built-in function")
        } else if schema::kind(n).is_some() {
            Some("a built-in kind")
        } else if COORDINATES.contains(&n) {
            Some("a coordinate of surface formulas (x, y, r)")
        } else {
            None
        };
        if let Some(what) = builtin {
            self.err(
                Diagnostic::error(
                    codes::DUPLICATE_NAME,
                    format!("`{n}` is {what} and cannot be given another meaning"),
                    file,
                    name.span,
                )
                .with_label("this would hide the built-in")
                .with_help(format!(
                    "choose another name, such as `{n}_1`, and use that name where this one is used"
                )),
            );
            return false;
        }
        true
    }

    /// A file's scope: its own items and those it imports.
    fn resolve_imports(
        &mut self,
        pf: &'a ParsedFile,
        locals: &[HashMap<&'a str, usize>],
    ) -> HashMap<&'a str, usize> {
        let mut scope = locals[pf.id.0 as usize].clone();
        for imp in &pf.imports {
            match imp {
                Import::One { file, name } => {
                    self.import_one(pf.id, &mut scope, &locals[file.0 as usize], *file, name)
                }
                Import::All { file, .. } => {
                    for (&n, &i) in &locals[file.0 as usize] {
                        scope.entry(n).or_insert(i);
                    }
                }
            }
        }
        scope
    }

    /// `use module::name`: the item joins the scope unless the name is taken.
    fn import_one(
        &mut self,
        here: FileId,
        scope: &mut HashMap<&'a str, usize>,
        source: &HashMap<&'a str, usize>,
        file: FileId,
        name: &'a Ident,
    ) {
        match source.get(name.name.as_str()) {
            Some(&i) => {
                if let Some(&prev) = scope.get(name.name.as_str()) {
                    let prev_span = self.decls[prev].name.span;
                    let prev_file = self.decls[prev].file;
                    self.err(
                        Diagnostic::error(
                            codes::DUPLICATE_NAME,
                            format!("`{}` is already defined", name.name),
                            here,
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
                let module = self.loaded.sources.get(file).name.clone();
                let mut d = Diagnostic::error(
                    codes::NOT_IN_MODULE,
                    format!("`{module}` has no item `{}`", name.name),
                    here,
                    name.span,
                )
                .with_label("not found");
                let names: Vec<&str> = source.keys().copied().collect();
                let mut sorted = names.clone();
                sorted.sort_unstable();
                d = d.with_help(match meant(&name.name, names.iter().copied()) {
                    Some(s) => format!("did you mean {s}?"),
                    None => format!("it has: {}", sorted.join(", ")),
                });
                self.err(d);
            }
        }
    }

    pub(super) fn decl_value(&mut self, i: usize) -> Value {
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
        let outer = self.declaring.take();
        self.declaring = kind.map(|k| (Category::of(k), expr.span.start));
        let mut v = self.eval(file, expr, &[]);
        self.declaring = outer;
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
    pub(super) fn expect_category(
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
                self.unknown_name(file, span, w, Some(cat));
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

    pub(super) fn lookup(&mut self, file: FileId, name: &str) -> Option<usize> {
        let i = *self.scopes[file.0 as usize].get(name)?;
        self.used[i] = true;
        Some(i)
    }

    /// Whether `file` declares `name` but its declaration was refused (a
    /// built-in name, a word, a second definition): uses of it are not
    /// reported again.
    fn refused_here(&self, file: FileId, name: &str) -> bool {
        self.loaded
            .file(file)
            .ast
            .items
            .iter()
            .any(|i| match &i.kind {
                ItemKind::Let { name: n, .. } | ItemKind::Decl { name: n, .. } => n.name == name,
                _ => false,
            })
    }

    /// E0100 for `name`, with a hint; `category`, where the slot takes
    /// one, narrows the names suggested to that category's.
    pub(super) fn unknown_name(
        &mut self,
        file: FileId,
        span: Span,
        name: &str,
        category: Option<Category>,
    ) {
        let scope = &self.scopes[file.0 as usize];
        let decls = &self.decls;
        let mut candidates: Vec<&str> = scope
            .iter()
            .filter(|&(_, &i)| category.is_none_or(|c| decls[i].kind.map(Category::of) == Some(c)))
            .map(|(&n, _)| n)
            .collect();
        if category.is_none() {
            candidates.extend(FUNCTIONS);
        }
        candidates.extend(
            schema::KINDS
                .iter()
                .filter(|k| category.is_none_or(|c| k.category == c))
                .map(|k| k.name),
        );
        let mut d = Diagnostic::error(
            codes::UNKNOWN_NAME,
            format!("unknown name `{name}`"),
            file,
            span,
        )
        .with_label("not defined");
        if self.refused_here(file, name) {
            // Its declaration was refused, with its own error.
            return;
        }
        if let Some(line) = unread_declaration(&self.loaded.sources.get(file).text, name) {
            // Declared, but the parser could not read the declaration (its
            // syntax error is reported): not a unit, not a misspelling.
            d = d.with_help(format!(
                "`{name}` is declared on line {line}, but that declaration could not be read: mend the syntax error there first"
            ));
        } else if COORDINATES.contains(&name) {
            d = d.with_help(
                "coordinates can only be used inside a surface formula such as `z(x, y) = …`",
            );
        } else if let Some(help) = known_elsewhere(scope, name, candidates, category) {
            d = d.with_help(help);
        } else if units::lookup(name).is_some() {
            let text = &self.loaded.sources.get(file).text;
            let before = text[..span.start as usize].trim_end();
            d = d.with_help(if before.ends_with('/') {
                // `1e-5 /mm^3`: a reciprocal unit written as a division.
                format!(
                    "`{name}` is a unit: write it right after the number, a unit per length with a negative power, as in `1e-5 {name}^-3`"
                )
            } else {
                format!("`{name}` is a unit: write it right after a number, as in `1 {name}`")
            });
        }
        self.err(d);
    }

    /// Unused definitions are worth a warning in a job file; a file with no
    /// job (a library of surfaces or tools) is all definitions by design.
    pub(super) fn warn_unused(&mut self) {
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

/// The line (from 1) of a declaration of `name` in `text` that the parser
/// did not read (`surface s = …`, `let s = …`, a job): a line that starts
/// with the keyword and the name, then `=` or `{`.
fn unread_declaration(text: &str, name: &str) -> Option<usize> {
    const KEYWORDS: [&str; 7] = [
        "surface", "tool", "machine", "strategy", "dialect", "let", "job",
    ];
    text.lines()
        .position(|line| {
            let mut words = line.trim_start().splitn(2, char::is_whitespace);
            let (Some(keyword), Some(rest)) = (words.next(), words.next()) else {
                return false;
            };
            let rest = rest.trim_start();
            KEYWORDS.contains(&keyword)
                && rest.strip_prefix(name).is_some_and(|after| {
                    let after = after.trim_start();
                    after.starts_with('=') || after.starts_with('{')
                })
        })
        .map(|i| i + 1)
}

/// Help for a name not in `scope`: the `use` that brings it in when the
/// standard library declares it, else the nearest of `candidates` or of the
/// standard library's names ("did you mean `s`?", with its `use` when the
/// file has not imported it).
pub(super) fn known_elsewhere<'c>(
    scope: &HashMap<&str, usize>,
    name: &str,
    candidates: impl IntoIterator<Item = &'c str>,
    category: Option<Category>,
) -> Option<String> {
    let use_it = |item: &stdlib::StdItem| {
        format!(
            "{} of the standard library: add `{}` at the top of the file",
            Category::of(item.kind).noun(),
            item.use_line()
        )
    };
    if let Some(item) = stdlib::find(name) {
        return Some(format!("`{name}` is {}", use_it(item)));
    }
    // Where the slot takes one category, only the standard library's items
    // of that category are meant.
    let stdlib_names = stdlib::items()
        .iter()
        .filter(|i| category.is_none_or(|c| Category::of(i.kind) == c))
        .map(|i| i.name.as_str());
    let candidates: Vec<&str> = candidates.into_iter().chain(stdlib_names).collect();
    let Some(s) = did_you_mean(name, candidates.iter().copied()) else {
        // A name cut short: every name it begins, with the `use` of each
        // the file lacks.
        let all = completions(name, candidates.iter().copied());
        let meant = meant(name, all.iter().copied())?;
        let uses: Vec<String> = all
            .iter()
            .filter(|c| !scope.contains_key(*c))
            .filter_map(|c| stdlib::find(c))
            .map(|item| format!("`{}`", item.use_line()))
            .collect();
        return Some(if uses.is_empty() {
            format!("did you mean {meant}?")
        } else {
            format!(
                "did you mean {meant}? From the standard library: {}",
                uses.join(", ")
            )
        });
    };
    Some(match stdlib::find(s) {
        Some(item) if !scope.contains_key(s) => {
            format!("did you mean `{s}`? It is {}", use_it(item))
        }
        _ => format!("did you mean `{s}`?"),
    })
}
