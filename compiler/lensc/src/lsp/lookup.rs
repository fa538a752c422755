//! What a name stands for, from the tables the checker itself uses: the
//! kind a block is built with (a built-in kind, or the kind of the
//! declaration or standard-library item it copies), the parameters that
//! block takes, and the documentation `lensc list` prints for each.

use lensc_lang::schema::{self, Kind, Param, Ty};
use lensc_lang::stdlib;

use super::analysis::Analysis;
use super::context::{Frame, Owner};
use crate::commands::list::{ParamDoc, kind_doc, param_doc};

/// The kind `name` builds with: a built-in kind, a declaration the
/// document can name (its checked kind), or a standard-library item.
pub fn kind_named(a: Option<&Analysis>, name: &str) -> Option<&'static Kind> {
    if let Some(k) = schema::kind(name) {
        return Some(k);
    }
    if let Some(o) = a.and_then(|a| a.checked.checked.declarations.get(name)) {
        return Some(o.kind);
    }
    stdlib::find(name)
        .and_then(stdlib::kind_of)
        .and_then(schema::kind)
}

/// The parameters of the block or call open at `frames`' innermost
/// bracket, with the kind when it is a kind's own.
pub fn params_at(
    a: Option<&Analysis>,
    frames: &[Frame],
) -> Option<(&'static [Param], Option<&'static Kind>)> {
    let (last, outer) = frames.split_last()?;
    match &last.owner {
        Owner::Job => Some((schema::JOB_PARAMS, None)),
        Owner::Name(n) => kind_named(a, n).map(|k| (k.params, Some(k))),
        Owner::Param(p) => {
            let (params, kind) = params_at(a, outer)?;
            match param_in(params, kind, p)?.ty {
                // `accept { … }` takes a block or a word (`accept: none`).
                Ty::Block(sub) | Ty::BlockOr(sub, _) => Some((sub, None)),
                _ => None,
            }
        }
        Owner::Other => None,
    }
}

/// The parameter `name` of a parameter list, or of the kind's family of
/// coefficients (`A4`, `Z11`).
pub fn param_in(params: &[Param], kind: Option<&Kind>, name: &str) -> Option<Param> {
    params
        .iter()
        .find(|p| p.name == name)
        .copied()
        .or_else(|| kind.and_then(|k| k.family).and_then(|f| (f.param)(name)))
}

/// A parameter in one line: `a length, in mm, > 0, default 20 um`.
pub fn param_summary(p: &ParamDoc) -> String {
    let mut s = p.takes.clone();
    if let Some(u) = &p.unit {
        s.push_str(&format!(", in {u}"));
    }
    if let Some(r) = &p.range {
        s.push_str(&format!(", {r}"));
    }
    s.push_str(if p.required {
        ", required"
    } else {
        ", optional"
    });
    if let Some(d) = &p.default {
        s.push_str(&format!(", default {d}"));
    }
    s
}

/// A parameter's documentation as Markdown.
pub fn param_markdown(p: Param) -> String {
    let doc = param_doc(&p);
    format!("**{}**: {}\n\n{}", doc.name, param_summary(&doc), doc.doc)
}

/// A kind's documentation as Markdown: what it makes and its parameters.
pub fn kind_markdown(k: &'static Kind) -> String {
    let doc = kind_doc(k);
    let mut s = format!(
        "**{}** — {}, built-in kind\n\n{}\n",
        doc.name, doc.makes, doc.doc
    );
    if !doc.params.is_empty() {
        s.push_str("\nParameters:\n");
        for p in &doc.params {
            s.push_str(&format!("- `{}`: {}\n", p.name, param_summary(p)));
        }
    }
    if let Some(c) = doc.coefficients {
        s.push_str(&format!("- and {c}\n"));
    }
    s
}

/// A standard-library item's documentation as Markdown.
pub fn stdlib_markdown(item: &stdlib::StdItem) -> String {
    let made = stdlib::kind_of(item).map_or(String::new(), |k| format!(" (`{k}`)"));
    let mut s = format!(
        "**{}** — {}{made} of the standard library\n\n{}",
        item.name,
        item.kind.keyword(),
        item.doc
    );
    if item.module != lensc_lang::loader::PRELUDE {
        s.push_str(&format!("\n\n`{}`", item.use_line()));
    }
    // The declaration itself: a machine's travel, limits and resolution,
    // a tool's geometry, as the standard library states them.
    if !item.source.is_empty() {
        s.push_str(&format!("\n\n```lens\n{}\n```", item.source));
    }
    s
}
