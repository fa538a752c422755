//! What a program is read back against (`lensc verify` and the build's
//! read-back, `lensc_runtime::reader`): a machine's limits and a dialect,
//! found by name among a file's declarations or taken from a job.

use std::rc::Rc;

use lensc_runtime::post::Dialect;
use lensc_runtime::reader::MachineLimits;

use crate::check::CheckedJob;
use crate::schema::{OfferedDialect, offered_dialects};
use crate::value::{self, Object};

/// A checked machine's limits as the reader takes them (feeds in mm/min,
/// spindle speeds in rpm).
pub fn machine_limits(machine: &Object) -> MachineLimits {
    let m = &machine.fields;
    let travel = value::block(m, "travel");
    let rpm = |w: f64| w * 60.0 / std::f64::consts::TAU;
    MachineLimits {
        lathe: !machine.kind.name.starts_with("mill"),
        travel: ["x", "y", "z", "c"].map(|a| travel.and_then(|t| value::range(t, a))),
        max_feed: value::num(m, "max_feed").map(|f| f * 60.0),
        max_spindle_rpm: value::block(m, "spindle")
            .and_then(|s| value::num(s, "max_speed"))
            .map(rpm),
    }
}

/// The limits of a job's machine.
pub fn job_machine(job: &CheckedJob) -> MachineLimits {
    machine_limits(value::object(&job.fields, "machine").expect("checked job part"))
}

/// A declared machine: its limits and the names of the dialects it
/// offers, its own first.
pub fn machine_named(
    declarations: &std::collections::HashMap<String, Rc<Object>>,
    name: &str,
) -> Option<(MachineLimits, Vec<String>)> {
    let o = declarations.get(name)?;
    if !o.kind.name.contains("lathe")
        && !o.kind.name.contains("mill")
        && !o.kind.name.contains("grinder")
    {
        return None;
    }
    let offered = offered_dialects(o)
        .iter()
        .map(OfferedDialect::name)
        .collect();
    Some((machine_limits(o), offered))
}

/// A declared dialect by name: among the declarations, or among the
/// dialects the declared machines offer.
pub fn dialect_named(
    declarations: &std::collections::HashMap<String, Rc<Object>>,
    name: &str,
) -> Option<Dialect> {
    let mut found = declarations
        .get(name)
        .filter(|o| o.kind.name == "gcode")
        .cloned();
    if found.is_none() {
        for o in declarations.values() {
            if let Some(d) = offered_dialects(o).into_iter().find(|d| d.name() == name) {
                found = Some(d.dialect.clone());
                break;
            }
        }
    }
    found.map(|o| crate::lower::dialect_of(&o, name.to_string()))
}

/// A finding of the reader as a diagnostic over the program's text
/// (`file`), labelled with what the line breaks.
pub fn finding_diagnostic(
    f: &lensc_runtime::reader::Finding,
    file: lensc_grammar::FileId,
) -> lensc_grammar::Diagnostic {
    let d = lensc_grammar::Diagnostic::error(
        crate::codes::program_rule(f.rule),
        f.message.clone(),
        file,
        lensc_grammar::Span::new(f.span.0, f.span.1),
    )
    .with_label("this block");
    match &f.hint {
        Some(h) => d.with_help(h.clone()),
        None => d,
    }
}
