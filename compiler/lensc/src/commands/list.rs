//! `lensc list [CATEGORY] [NAME]`: the kinds a file can construct and the
//! standard library's items, each with its documentation, parameters
//! (dimension, unit, range, default) and values (a machine's travel,
//! feed, spindle, resolution and dialects), for people or as JSON. Read
//! from the checker's own schema (`lensc_lang::schema`), the standard
//! library's text and doc comments (`lensc_lang::stdlib`) and the values
//! the checker gives its items: nothing here is a second copy.

use std::fmt::Write as _;

use lensc::cli::Listed;
use lensc_lang::loader::RealFs;
use lensc_lang::schema::{self, Category, Kind, Param, Ty};
use lensc_lang::value::{Field, Value};
use serde::Serialize;

/// One category: its kinds and its standard-library items. The JSON shape
/// of `lensc list --format json` is `{"categories": [Section…]}`.
#[derive(Serialize)]
pub struct Section {
    pub category: &'static str,
    pub kinds: Vec<KindDoc>,
    pub items: Vec<ItemDoc>,
}

/// A built-in kind (`round_nose`, `lathe`).
#[derive(Serialize)]
pub struct KindDoc {
    pub name: &'static str,
    /// What it makes: `a tool`, `an aperture`.
    pub makes: &'static str,
    pub doc: &'static str,
    pub params: Vec<ParamDoc>,
    /// Coefficients named by a pattern (`A4`, `Z11`), if any.
    pub coefficients: Option<&'static str>,
    /// Groups of parameters of which at most one may be given.
    pub exclusive: Vec<Vec<&'static str>>,
}

#[derive(Serialize)]
pub struct ParamDoc {
    pub name: &'static str,
    pub required: bool,
    /// What the value is, in words: `a length`, `one of convex, concave`.
    pub takes: String,
    /// The unit values are shown in (`mm`, `deg`, `mm/min`), for quantities.
    pub unit: Option<String>,
    /// The allowed values, in `unit`: `> 0`, `0 ≤ v < 90`.
    pub range: Option<String>,
    /// The default its documentation gives, when optional.
    pub default: Option<String>,
    pub doc: &'static str,
    /// The parameters of a nested block.
    pub params: Vec<ParamDoc>,
}

/// A standard-library item (`linuxcnc_lathe`).
#[derive(Serialize)]
pub struct ItemDoc {
    pub name: String,
    pub kind: &'static str,
    /// The line that brings it into a file; `None` for the dialects, which
    /// every file sees without one.
    #[serde(rename = "use")]
    pub use_line: Option<String>,
    pub doc: String,
    pub values: Vec<ValueDoc>,
}

/// One value an item sets, as its file writes it.
#[derive(Clone, Serialize)]
pub struct ValueDoc {
    pub name: String,
    pub value: String,
}

/// Runs the subcommand; returns the exit code.
pub fn run(category: Option<Listed>, name: Option<&str>, json: bool) -> u8 {
    let mut sections = catalogue(category);
    if let Some(name) = name {
        for s in &mut sections {
            s.kinds.retain(|k| k.name == name);
            s.items.retain(|i| i.name == name);
        }
        sections.retain(|s| !s.kinds.is_empty() || !s.items.is_empty());
        if sections.is_empty() {
            let known: Vec<String> = catalogue(category)
                .into_iter()
                .flat_map(|s| {
                    let kinds = s.kinds.into_iter().map(|k| k.name.to_string());
                    kinds.chain(s.items.into_iter().map(|i| i.name))
                })
                .collect();
            let hint = lensc_grammar::suggest::did_you_mean(name, known.iter().map(String::as_str))
                .map_or(String::new(), |s| format!(": did you mean `{s}`?"));
            eprintln!(
                "error: `lensc list` knows nothing called `{name}`{hint} (`lensc list{}` shows them all)",
                category.map_or(String::new(), |c| format!(" {}", c.name()))
            );
            return 2;
        }
    }
    let text = if json {
        let v = serde_json::json!({ "categories": sections });
        format!("{v:#}\n")
    } else {
        let detail = match (category, name) {
            (_, Some(_)) => Detail::One,
            (Some(_), None) => Detail::Full,
            (None, None) => Detail::Summary,
        };
        human(&sections, detail)
    };
    print!("{text}");
    0
}

/// Every category asked for, from the schema and the standard library.
pub fn catalogue(only: Option<Listed>) -> Vec<Section> {
    let values = stdlib_values();
    Listed::ALL
        .into_iter()
        .filter(|c| only.is_none_or(|o| o == *c))
        .map(|c| Section {
            category: c.name(),
            kinds: schema::KINDS
                .iter()
                .filter(|k| c.holds(k.category))
                .map(kind_doc)
                .collect(),
            items: lensc_lang::stdlib::items()
                .iter()
                .filter(|i| c.holds(Category::of(i.kind)))
                .map(|i| {
                    let checked = values.iter().find(|(n, ..)| *n == i.name);
                    ItemDoc {
                        name: i.name.clone(),
                        kind: checked.map_or("", |(_, kind, _)| kind),
                        use_line: (i.module != lensc_lang::loader::PRELUDE).then(|| i.use_line()),
                        doc: i.doc.clone(),
                        values: checked.map_or_else(Vec::new, |(.., v)| v.clone()),
                    }
                })
                .collect(),
        })
        .collect()
}

/// The standard library's items as the checker evaluates them: each
/// item's kind and its values as its file writes them (`25 G`, `1 nm`).
fn stdlib_values() -> Vec<(String, &'static str, Vec<ValueDoc>)> {
    let uses: String = lensc_lang::loader::STDLIB
        .iter()
        .map(|(m, _)| format!("use std::{m}\n"))
        .collect();
    let c = lensc_lang::check_text(&RealFs, "<stdlib>", uses.as_bytes());
    c.checked
        .declarations
        .iter()
        .map(|(name, o)| {
            let values = o
                .fields
                .iter()
                .map(|f| ValueDoc {
                    name: f.name.clone(),
                    value: as_written(&c.loaded.sources.get(f.file).text, f),
                })
                .collect();
            (name.clone(), o.kind.name, values)
        })
        .collect()
}

/// A field's value as its file writes it, on one line; as the checker
/// holds it when the span does not cover it.
fn as_written(text: &str, f: &Field) -> String {
    match text.get(f.span.start as usize..f.span.end as usize) {
        Some(t) if !t.trim().is_empty() => t.split_whitespace().collect::<Vec<_>>().join(" "),
        _ => value_text(&f.value),
    }
}

pub(crate) fn kind_doc(k: &'static Kind) -> KindDoc {
    KindDoc {
        name: k.name,
        makes: k.category.noun(),
        doc: k.doc,
        params: k.params.iter().map(param_doc).collect(),
        coefficients: k.family.map(|f| f.describe),
        exclusive: k.exclusive.iter().map(|(g, _)| g.to_vec()).collect(),
    }
}

pub(crate) fn param_doc(p: &Param) -> ParamDoc {
    let t = lensc_lang::reference::describe(p);
    ParamDoc {
        name: p.name,
        required: p.required,
        takes: t.takes,
        unit: t.unit,
        range: t.range,
        default: t.default,
        doc: t.doc,
        params: match p.ty {
            Ty::Block(sub) | Ty::BlockOr(sub, _) => sub.iter().map(param_doc).collect(),
            _ => Vec::new(),
        },
    }
}

pub(crate) fn value_text(v: &Value) -> String {
    let n = lensc_lang::check::trim_num;
    match v {
        Value::Num(x, d) => {
            let (unit, factor) = d.display_unit();
            format!("{} {unit}", n(x * factor)).trim_end().to_string()
        }
        Value::Range(a, b, d) => {
            let (unit, factor) = d.display_unit();
            format!("{} .. {} {unit}", n(a * factor), n(b * factor))
        }
        Value::Str(s) => format!("{s:?}"),
        Value::Word(w) => w.clone(),
        Value::Object(o) => o.name.clone().unwrap_or_else(|| o.kind.name.to_string()),
        Value::Block(fs) => {
            let inner: Vec<String> = fs
                .iter()
                .map(|f| format!("{}: {}", f.name, value_text(&f.value)))
                .collect();
            format!("{{ {} }}", inner.join(", "))
        }
        Value::List(items) => {
            let inner: Vec<String> = items.iter().map(|(v, _)| value_text(v)).collect();
            format!("[{}]", inner.join(", "))
        }
        other => other.describe(),
    }
}

/// The listing for a terminal. `Summary`: one line per kind and item of
/// every category; `Full`: each kind with its parameters and each item
/// with its documentation and values; `One`: the same for one NAME.
#[derive(Clone, Copy, PartialEq)]
enum Detail {
    Summary,
    Full,
    One,
}

fn human(sections: &[Section], detail: Detail) -> String {
    let mut out = String::new();
    for s in sections {
        if detail != Detail::One {
            let _ = writeln!(out, "{}\n", s.category.to_uppercase());
        }
        if !s.kinds.is_empty() && detail != Detail::One {
            let _ = writeln!(out, "Kinds (`NAME = KIND {{ … }}` builds one):\n");
        }
        for k in &s.kinds {
            if detail == Detail::Summary {
                let _ = writeln!(out, "    {:<27} {}", k.name, k.doc);
            } else {
                kind_detail(&mut out, k);
            }
        }
        if !s.items.is_empty() && detail != Detail::One {
            let how = if s.category == lensc_lang::loader::PRELUDE {
                "every file sees these without a `use`".to_string()
            } else {
                format!("`use std::{}::NAME`", s.category)
            };
            let _ = writeln!(
                out,
                "\nStandard library ({how}; copy one and change what differs: `NEW = NAME {{ … }}`):\n"
            );
        }
        for i in &s.items {
            item_text(&mut out, i, detail != Detail::Summary);
        }
        if detail == Detail::Summary {
            let _ = writeln!(out);
        }
    }
    if detail == Detail::Summary {
        out.push_str(
            "`lensc list CATEGORY` shows each in full; `lensc list CATEGORY NAME` one of them.\n",
        );
    }
    out
}

fn kind_detail(out: &mut String, k: &KindDoc) {
    let _ = writeln!(
        out,
        "{} — {}, built-in kind\n\n  {}\n",
        k.name, k.makes, k.doc
    );
    let _ = writeln!(out, "  Parameters:");
    params_text(out, &k.params, 4);
    if let Some(c) = k.coefficients {
        let _ = writeln!(out, "    and {c}");
    }
    for g in &k.exclusive {
        let _ = writeln!(out, "  Give at most one of: {}", g.join(", "));
    }
    let _ = writeln!(out);
}

fn params_text(out: &mut String, params: &[ParamDoc], indent: usize) {
    for p in params {
        let mut line = format!(
            "{:indent$}{:<18} {:<9} {}",
            "",
            p.name,
            if p.required { "required" } else { "optional" },
            p.takes
        );
        if let Some(u) = &p.unit {
            let _ = write!(line, ", in {u}");
        }
        if let Some(r) = &p.range {
            let _ = write!(line, ", {r}");
        }
        if let Some(d) = &p.default {
            let _ = write!(line, ", default {d}");
        }
        let _ = writeln!(out, "{line}\n{:indent$}    {}", "", p.doc);
        params_text(out, &p.params, indent + 4);
    }
}

fn item_text(out: &mut String, i: &ItemDoc, detailed: bool) {
    if !detailed {
        let _ = writeln!(
            out,
            "    {:<27} {} ({})",
            i.name,
            first_sentence(&i.doc),
            i.kind
        );
        return;
    }
    let _ = writeln!(
        out,
        "{} — {} of the standard library (kind `{}`)\n",
        i.name,
        category_noun(i.kind),
        i.kind
    );
    for para in i.doc.split("\n\n") {
        let _ = writeln!(out, "  {}\n", wrap(para, 74).join("\n  "));
    }
    match &i.use_line {
        Some(u) => {
            let _ = writeln!(out, "  {u}\n");
        }
        None => out.push_str("  Every file sees it without a `use`.\n\n"),
    }
    let _ = writeln!(out, "  Values:");
    for v in &i.values {
        let _ = writeln!(out, "    {:<18} {}", v.name, v.value);
    }
    let _ = writeln!(
        out,
        "\n  `lensc list {} {}` shows every parameter it can change.\n",
        category_of_kind(i.kind),
        i.kind
    );
}

/// The documentation's first sentence (ending at a `.` before a capital
/// letter, not at `et al. 2021`), at most about 90 characters.
fn first_sentence(doc: &str) -> String {
    let end = doc
        .match_indices(". ")
        .find(|(at, _)| doc[at + 2..].chars().next().is_some_and(char::is_uppercase))
        .map_or(doc.len(), |(at, _)| at);
    let s = doc[..end].trim_end_matches('.');
    match wrap(s, 90).as_slice() {
        [one] => one.clone(),
        [first, ..] => format!("{first} …"),
        [] => String::new(),
    }
}

fn category_noun(kind: &str) -> &'static str {
    schema::kind(kind).map_or("an item", |k| k.category.noun())
}

fn category_of_kind(kind: &str) -> &'static str {
    schema::kind(kind)
        .and_then(|k| Listed::ALL.into_iter().find(|c| c.holds(k.category)))
        .map_or("", Listed::name)
}

/// Words of `text` in lines of at most `width` characters.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for w in text.split_whitespace() {
        let last = lines.last_mut().expect("one line");
        if !last.is_empty() && last.chars().count() + 1 + w.chars().count() > width {
            lines.push(w.to_string());
        } else {
            if !last.is_empty() {
                last.push(' ');
            }
            last.push_str(w);
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_and_stdlib_item_is_listed_once() {
        let all = catalogue(None);
        let kinds: usize = all.iter().map(|s| s.kinds.len()).sum();
        let items: usize = all.iter().map(|s| s.items.len()).sum();
        assert_eq!(kinds, schema::KINDS.len());
        assert_eq!(items, lensc_lang::stdlib::items().len());
        // Every stdlib item checked, so it has its kind and values.
        for s in &all {
            for i in &s.items {
                assert!(!i.kind.is_empty() && !i.values.is_empty(), "{}", i.name);
            }
        }
    }
}
