//! The book's language reference (`docs/reference/`), generated as Markdown
//! from the schema, the standard library's text and doc comments, the
//! units and functions the checker knows and the codes' explanations, so
//! it cannot drift from them; also how one parameter reads in words
//! (`describe`), which `lensc list` and the language server print too.
//! A test (`tests/it/docs.rs`) fails when the committed pages are stale.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use lensc_grammar::FileId;
use lensc_grammar::ast::ItemKind;

use crate::check::{FUNCTIONS, trim_num};
use crate::explain;
use crate::loader::{PRELUDE, STDLIB};
use crate::schema::{self, ACCEPT_PARAMS, Category, Check, JOB_PARAMS, Kind, Param, Ty};
use crate::stdlib::{self, StdItem};
use crate::units::{Dim, UNITS};

/// How one parameter reads in words, from its schema entry.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamText {
    /// What the value is: `a length`, `one of convex, concave`.
    pub takes: String,
    /// The unit values are shown in (`mm`, `deg`, `mm/min`), for quantities.
    pub unit: Option<String>,
    /// The allowed values, in `unit`: `> 0`, `0 ≤ v < 90`.
    pub range: Option<String>,
    /// The default its documentation gives, when optional.
    pub default: Option<String>,
    /// The documentation without the default it states.
    pub doc: &'static str,
}

/// `p` in words: what it takes, its unit, range and default.
pub fn describe(p: &Param) -> ParamText {
    let (doc, default) = split_default(p.doc);
    let (takes, unit, range) = match p.ty {
        Ty::Quantity(dims) => {
            let (unit, factor) = dims[0].display_unit();
            let takes = dims.iter().map(|d| d.to_string()).collect::<Vec<_>>();
            let unit = (!unit.is_empty()).then_some(unit);
            // A range is shown in the first dimension's unit: only
            // single-dimension parameters carry one.
            (takes.join(" or "), unit, range_text(p.check, factor))
        }
        Ty::Word(words) => (format!("one of {}", words.join(", ")), None, None),
        Ty::Object(c) => (c.noun().to_string(), None, None),
        Ty::Objects(c) => (format!("a list, each {}", c.noun()), None, None),
        Ty::Text => ("a string".into(), None, None),
        Ty::Texts => ("a list of strings".into(), None, None),
        Ty::Block(_) => ("a block { … }".into(), None, None),
        Ty::BlockOr(_, words) => (
            format!("a block {{ … }} or one of {}", words.join(", ")),
            None,
            None,
        ),
        Ty::Range(d) => (
            format!("a range lo .. hi, each {d}"),
            Some(d.display_unit().0),
            None,
        ),
        Ty::Formula { coords, result } => (
            format!("a formula z({}) giving {result}", coords.join(", ")),
            None,
            None,
        ),
    };
    ParamText {
        takes,
        unit,
        range,
        default: default.filter(|_| !p.required),
        doc,
    }
}

/// The parameter's documentation and the default it states: `…; default
/// 20 kHz`, or a word marked `` `x` (default)``.
pub fn split_default(doc: &'static str) -> (&'static str, Option<String>) {
    if let Some(at) = doc.rfind("; default ") {
        return (&doc[..at], Some(doc[at + 10..].trim().to_string()));
    }
    if let Some(at) = doc.find("` (default)") {
        let word = doc[..at].rsplit('`').next().unwrap_or("");
        return (doc, Some(word.to_string()));
    }
    (doc, None)
}

/// The allowed values in the display unit (`factor` from base units).
fn range_text(check: Check, factor: f64) -> Option<String> {
    let n = |v: f64| trim_num(v * factor);
    Some(match check {
        Check::Any => return None,
        Check::Positive => "> 0".into(),
        Check::NonNegative => "≥ 0".into(),
        Check::HalfOpen(lo, hi) => format!("{} ≤ v < {}", n(lo), n(hi)),
        Check::Open(lo, hi) => format!("{} < v < {}", n(lo), n(hi)),
        Check::Count => "a whole number, 1 to 100000".into(),
    })
}

/// The command that rewrites the generated pages.
pub const BLESS: &str = "LENSC_BLESS=1 cargo test --test it -- docs::";

/// One page of the reference.
struct Page {
    file: &'static str,
    title: &'static str,
    /// One line for the index.
    about: &'static str,
    render: fn(&mut String),
}

const PAGES: &[Page] = &[
    Page {
        file: "surfaces.md",
        title: "Surfaces",
        about: "every surface kind: formulas, composites (arrays, wraps, tilts) and their coefficients",
        render: surfaces,
    },
    Page {
        file: "apertures.md",
        title: "Apertures and rollers",
        about: "the region of a surface to machine, and the roller a design is wrapped onto",
        render: apertures,
    },
    Page {
        file: "tools.md",
        title: "Tools",
        about: "tool kinds and the standard library's tools",
        render: tools,
    },
    Page {
        file: "machines.md",
        title: "Machines",
        about: "machine kinds and the standard library's machines with their limits",
        render: machines,
    },
    Page {
        file: "strategies.md",
        title: "Strategies",
        about: "how a path is planned: each strategy's parameters, and the standard library's presets",
        render: strategies,
    },
    Page {
        file: "dialects.md",
        title: "Dialects",
        about: "the `gcode` dialect kind and every shipped dialect as the standard library writes it",
        render: dialects,
    },
    Page {
        file: "jobs.md",
        title: "Jobs",
        about: "the `job` block and its `accept` criteria",
        render: jobs,
    },
    Page {
        file: "units.md",
        title: "Units and functions",
        about: "every unit a file may write and the built-in functions",
        render: units,
    },
    Page {
        file: "codes.md",
        title: "Diagnostic codes",
        about: "every code lensc reports, with its title; `lensc explain CODE` prints the whole explanation",
        render: codes,
    },
];

/// Every page of `docs/reference/`: `(file name, Markdown)`, the index
/// (`README.md`) first.
pub fn reference_pages() -> Vec<(String, String)> {
    let mut pages = vec![("README.md".to_string(), index())];
    for p in PAGES {
        let mut out = head(p.title);
        (p.render)(&mut out);
        pages.push((p.file.to_string(), tidy(out)));
    }
    pages
}

/// The title and the note that the page is generated.
fn head(title: &str) -> String {
    format!(
        "<!-- Generated by lensc_lang::reference from the schema, the standard library and the\n     code explanations: do not edit. `{BLESS}` rewrites it. -->\n\n# {title}\n\n"
    )
}

/// One blank line between blocks, one newline at the end.
fn tidy(text: String) -> String {
    let mut out = String::with_capacity(text.len());
    let mut blank = 0;
    for line in text.lines() {
        let line = line.trim_end();
        if line.is_empty() {
            blank += 1;
            continue;
        }
        if blank > 0 && !out.is_empty() {
            out.push('\n');
        }
        blank = 0;
        out.push_str(line);
        out.push('\n');
    }
    out
}

fn index() -> String {
    let mut out = head("Language reference");
    out.push_str(
        "Everything a `.lens` file can name, generated from the checker's own tables: \
         the kinds of each category with every parameter (what it takes, its unit, \
         whether it is required or its default, its allowed range), the standard \
         library's items as their files write them, the units and functions, and \
         every diagnostic code. `lensc list` prints the same for a terminal, and \
         `lensc explain CODE` a code's explanation.\n\n\
         How to read a parameter table: **takes** is the value's type (a quantity's \
         dimension, a word, a block, another kind's value); **unit** is the unit \
         values are shown in, though any unit of the same dimension may be written \
         (`85 um` or `0.085 mm`); **allowed** is the range the checker holds the \
         value to (E0123 outside it); a nested block's parameters are written \
         `block.name`.\n\n",
    );
    out.push_str("| page | what it holds |\n|---|---|\n");
    for p in PAGES {
        let _ = writeln!(out, "| [{}]({}) | {} |", p.title, p.file, p.about);
    }
    tidy(out)
}

fn kinds_of(categories: &[Category]) -> impl Iterator<Item = &'static Kind> + '_ {
    schema::KINDS
        .iter()
        .filter(move |k| categories.contains(&k.category))
}

fn surfaces(out: &mut String) {
    out.push_str(
        "A surface is declared `surface NAME = KIND { … }`. Its height z is along the \
         part's +Z axis, which points out of the material towards the tool; `sense` or \
         `convention: optical` says which side is material (see the language guide's \
         [sign rule](../language/sign-rule.md)). Composite kinds take other surfaces, \
         by name or written in place.\n\n",
    );
    for k in kinds_of(&[Category::Surface]) {
        kind_section(out, k, "surface");
    }
}

fn apertures(out: &mut String) {
    out.push_str(
        "Apertures are written as calls with named arguments \
         (`aperture: circle(diameter: 1.6 mm)`); a roller is what `wrap` takes \
         (`onto: roller(radius: 3 mm)`).\n\n",
    );
    for k in kinds_of(&[Category::Aperture, Category::Roller]) {
        kind_section(out, k, "");
    }
}

fn tools(out: &mut String) {
    category_page(out, Category::Tool, "tool");
}

fn machines(out: &mut String) {
    category_page(out, Category::Machine, "machine");
}

fn strategies(out: &mut String) {
    category_page(out, Category::Strategy, "strategy");
}

fn dialects(out: &mut String) {
    out.push_str(
        "A dialect is data: `dialect NAME = gcode { … }` gives a controller's words, \
         number formats and the lines around the moves. Every file sees the shipped \
         dialects without a `use`; a shop adapts one by copying it into its own file. \
         The [controller pages](../controllers/README.md) say what each family's \
         programs look like and what the dialects assume.\n\n",
    );
    category_page(out, Category::Dialect, "dialect");
}

/// A category's kinds, then its standard-library items.
fn category_page(out: &mut String, c: Category, keyword: &str) {
    for k in kinds_of(&[c]) {
        kind_section(out, k, keyword);
    }
    let items: Vec<&StdItem> = stdlib::items()
        .iter()
        .filter(|i| Category::of(i.kind) == c)
        .collect();
    if items.is_empty() {
        return;
    }
    let module = items[0].module;
    out.push_str("## Standard library\n\n");
    if module == PRELUDE {
        out.push_str("Every file sees these without a `use`. ");
    } else {
        let _ = write!(out, "`use std::{module}::NAME` brings one into a file. ");
    }
    let _ = writeln!(
        out,
        "Copy one and change what differs: `{keyword} mine = NAME {{ … }}`. Each is shown as \
         [`stdlib/{module}.lens`](../../stdlib/{module}.lens) writes it.\n"
    );
    let text = STDLIB
        .iter()
        .find(|(m, _)| *m == module)
        .map_or("", |(_, t)| t);
    let written = declarations(text);
    for i in items {
        let kind = stdlib::kind_of(i).unwrap_or("?");
        let _ = writeln!(out, "### `{}`\n", i.name);
        let _ = writeln!(out, "{} of kind [`{kind}`](#{kind}).\n", capital(noun(c)));
        for para in i.doc.split("\n\n") {
            let _ = writeln!(out, "{para}\n");
        }
        if i.module != PRELUDE {
            let _ = writeln!(out, "`{}`\n", i.use_line());
        }
        if let Some(src) = written.get(&i.name) {
            let _ = writeln!(out, "```lens\n{src}\n```\n");
        }
    }
}

/// Each declaration of a standard-library file as written, by name.
fn declarations(text: &str) -> BTreeMap<String, &str> {
    let (file, _) = lensc_grammar::parse(text, FileId(0));
    let mut out = BTreeMap::new();
    for item in &file.items {
        if let ItemKind::Decl { name, .. } = &item.kind
            && let Some(src) = text.get(item.span.start as usize..item.span.end as usize)
        {
            out.insert(name.name.clone(), without_trailing_comments(src));
        }
    }
    out
}

/// A declaration's text without the comments after it (the next item's
/// documentation, which its span takes in).
fn without_trailing_comments(src: &str) -> &str {
    let mut s = src.trim_end();
    while let Some(at) = s.rfind('\n') {
        let last = s[at + 1..].trim();
        if last.starts_with("//") || last.is_empty() {
            s = s[..at].trim_end();
        } else {
            break;
        }
    }
    s
}

fn noun(c: Category) -> &'static str {
    c.noun()
}

fn capital(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().chain(c).collect())
        .unwrap_or_default()
}

/// One kind: its documentation, how it is written and its parameters.
fn kind_section(out: &mut String, k: &Kind, keyword: &str) {
    let _ = writeln!(out, "## `{}`\n", k.name);
    let _ = writeln!(out, "{}.\n", capital(k.doc.trim_end_matches('.')));
    if !keyword.is_empty() {
        let _ = writeln!(out, "`{keyword} NAME = {} {{ … }}`\n", k.name);
    }
    if !k.positional.is_empty() {
        let names: Vec<String> = k.positional.iter().map(|p| format!("`{p}`")).collect();
        let _ = writeln!(
            out,
            "Arguments without a name fill, in order: {}.\n",
            names.join(", ")
        );
    }
    if k.params.is_empty() {
        out.push_str("No parameters.\n\n");
    } else {
        param_table(out, k.params);
    }
    if let Some(f) = k.family {
        let _ = writeln!(out, "And {}.\n", f.describe);
    }
    for (group, exactly_one) in k.exclusive {
        let names: Vec<String> = group.iter().map(|p| format!("`{p}`")).collect();
        let _ = writeln!(
            out,
            "Give {} of {}.\n",
            if *exactly_one {
                "exactly one"
            } else {
                "at most one"
            },
            names.join(", ")
        );
    }
}

fn param_table(out: &mut String, params: &[Param]) {
    out.push_str("| parameter | takes | unit | required or default | allowed | what it is |\n");
    out.push_str("|---|---|---|---|---|---|\n");
    param_rows(out, params, "");
    out.push('\n');
}

fn param_rows(out: &mut String, params: &[Param], prefix: &str) {
    for p in params {
        let t = describe(p);
        let need = if p.required {
            "required".to_string()
        } else {
            match (&t.default, p.ty) {
                (Some(d), Ty::Word(w)) if w.contains(&d.as_str()) => format!("default `{d}`"),
                (Some(d), _) => format!("default {d}"),
                (None, _) => "optional".to_string(),
            }
        };
        let _ = writeln!(
            out,
            "| `{prefix}{}` | {} | {} | {} | {} | {} |",
            p.name,
            cell(&takes_md(p, &t)),
            t.unit.as_deref().map_or(String::new(), cell),
            cell(&need),
            t.range.as_deref().map_or(String::new(), cell),
            cell(t.doc)
        );
        if let Ty::Block(sub) | Ty::BlockOr(sub, _) = p.ty {
            param_rows(out, sub, &format!("{prefix}{}.", p.name));
        }
    }
}

/// What a parameter takes, its words as code: "one of `convex`, `concave`".
fn takes_md(p: &Param, t: &ParamText) -> String {
    let words = |w: &[&str]| {
        w.iter()
            .map(|w| format!("`{w}`"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match p.ty {
        Ty::Word(w) => format!("one of {}", words(w)),
        Ty::BlockOr(_, w) => format!("a block {{ … }} or one of {}", words(w)),
        _ => t.takes.clone(),
    }
}

/// Text for one table cell: `|` escaped, on one line.
fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace('\n', " ")
}

fn jobs(out: &mut String) {
    out.push_str(
        "A job names what to make and how: `job NAME { surface: …, tool: …, machine: …, \
         strategy: … }`, each a declared name or a value written in place. `lensc build` \
         writes one program (and its report) per job, named after it.\n\n\
         ## `job`\n\n",
    );
    param_table(out, JOB_PARAMS);
    out.push_str(
        "## `accept`\n\n\
         The criteria of a job's `accept` block, each a limit on a figure of the simulated \
         part; the language guide's [acceptance](../language/acceptance.md) page says how \
         each is measured and how its default is derived. `accept: none` opts out.\n\n",
    );
    param_table(out, ACCEPT_PARAMS);
}

fn units(out: &mut String) {
    out.push_str(
        "A unit follows its number (`85 um`, `10°`); compound units join these with `/` \
         and `^` and no spaces (`mm/min`, `um/rev`, `m/s^2`, `1.2e-5 mm^-3`). Inside \
         lensc every quantity is held in one base unit per dimension: mm, rad, s.\n\n\
         | unit | dimension | in base units |\n|---|---|---|\n",
    );
    for u in UNITS {
        let _ = writeln!(
            out,
            "| `{}` | {} | {} {} |",
            u.name,
            u.dim,
            shortest(u.factor),
            if u.dim == Dim::NONE {
                String::new()
            } else {
                u.dim.base_units()
            }
        );
    }
    out.push_str(
        "\n## Functions\n\n\
         Calls of these take their arguments in order; `sin`, `cos` and `tan` take an \
         angle (or a plain number, as radians), `atan2` two quantities of one dimension, \
         `sqrt` a quantity whose powers are even, `min` and `max` quantities of one \
         dimension.\n\n",
    );
    let names: Vec<String> = FUNCTIONS.iter().map(|f| format!("`{f}`")).collect();
    let _ = writeln!(out, "{}\n", names.join(" "));
}

/// The shortest text that reads back as `v`.
fn shortest(v: f64) -> String {
    let s = format!("{v}");
    if s.len() > 12 { format!("{v:e}") } else { s }
}

/// Code ranges and their headings, in order.
const CODE_GROUPS: &[(&str, &str, &str)] = &[
    ("E0000", "E0099", "Syntax"),
    ("E0100", "E0109", "Names and files"),
    ("E0110", "E0119", "Expressions and units"),
    ("E0120", "E0139", "Parameters and kinds"),
    ("E0140", "E0199", "Planning, output, limits and acceptance"),
    (
        "E0300",
        "E0349",
        "Reading a program back (`lensc verify`, and every build)",
    ),
    (
        "E0350",
        "E0399",
        "Importing a prescription (`lensc import`)",
    ),
    ("W0000", "W9999", "Warnings"),
];

fn codes(out: &mut String) {
    out.push_str(
        "Every diagnostic lensc reports has one of these codes. `lensc explain CODE` \
         prints the whole explanation (what it means, what to write instead, and an \
         example with its fix); each is a file in \
         [`compiler/lang/explain/`](../../compiler/lang/explain/).\n\n",
    );
    let all = explain::all();
    let mut shown = 0;
    for (lo, hi, heading) in CODE_GROUPS {
        let in_group: Vec<_> = all.iter().filter(|(c, _)| *c >= *lo && *c <= *hi).collect();
        if in_group.is_empty() {
            continue;
        }
        let _ = writeln!(out, "## {heading}\n\n| code | what it means |\n|---|---|");
        for (code, text) in in_group {
            let _ = writeln!(
                out,
                "| [{code}](../../compiler/lang/explain/{code}.md) | {} |",
                cell(explain::title(text))
            );
            shown += 1;
        }
        out.push('\n');
    }
    // A code outside every group still appears.
    if shown < all.len() {
        out.push_str("## Others\n\n| code | what it means |\n|---|---|\n");
        for (code, text) in all {
            if !CODE_GROUPS
                .iter()
                .any(|(lo, hi, _)| *code >= *lo && *code <= *hi)
            {
                let _ = writeln!(
                    out,
                    "| [{code}](../../compiler/lang/explain/{code}.md) | {} |",
                    cell(explain::title(text))
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_read_from_the_documentation() {
        assert_eq!(
            split_default("rake angle; default 0°"),
            ("rake angle", Some("0°".to_string()))
        );
        assert_eq!(
            split_default("`x` (default) or `y`").1.as_deref(),
            Some("x")
        );
        assert_eq!(split_default("radius of the nose").1, None);
    }

    #[test]
    fn every_kind_stdlib_item_and_code_has_its_place() {
        let pages = reference_pages();
        let all: String = pages.iter().map(|(_, t)| t.as_str()).collect();
        for k in schema::KINDS {
            assert!(all.contains(&format!("## `{}`\n", k.name)), "{}", k.name);
        }
        for i in stdlib::items() {
            assert!(all.contains(&format!("### `{}`\n", i.name)), "{}", i.name);
        }
        for (code, _) in explain::all() {
            assert!(all.contains(&format!("[{code}]")), "{code}");
        }
    }
}
