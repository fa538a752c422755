//! What a program is read back against (`lensc verify` and the build's
//! read-back, `lensc_runtime::reader`): a machine's limits and a dialect,
//! found by name among a file's declarations or taken from a job.

use std::rc::Rc;

use lensc_runtime::post::Dialect;
use lensc_runtime::reader::MachineLimits;

use crate::check::CheckedJob;
use crate::schema::machines::{FastAxisParams, MachineParams};
use crate::schema::{OfferedDialect, offered_dialects};
use crate::value::{Object, Reader};

/// A checked machine's limits as the reader takes them (feeds in mm/min,
/// spindle speeds in rpm); none but its kind's for a machine that did not
/// check.
pub fn machine_limits(machine: &Object) -> MachineLimits {
    let lathe = !machine.kind.name.starts_with("mill");
    let rpm = |w: f64| w * 60.0 / std::f64::consts::TAU;
    match MachineParams::read(machine) {
        Ok(m) => MachineLimits {
            lathe,
            travel: m.travel,
            max_feed: Some(m.max_feed * 60.0),
            max_spindle_rpm: m.max_spindle_speed.map(rpm),
            servo: m.fast_axis.as_ref().and_then(servo_axis),
        },
        Err(_) => MachineLimits {
            lathe,
            travel: [None; 4],
            max_feed: None,
            max_spindle_rpm: None,
            servo: None,
        },
    }
}

/// The limits of a job's machine (none, on a lathe, if it has none that
/// checked).
pub fn job_machine(job: &CheckedJob) -> MachineLimits {
    match Reader::new(&job.fields).object("machine") {
        Some(m) => machine_limits(m),
        None => MachineLimits {
            lathe: true,
            travel: [None; 4],
            max_feed: None,
            max_spindle_rpm: None,
            servo: None,
        },
    }
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
    let span = lensc_grammar::Span::new(f.span.0, f.span.1);
    let code = crate::codes::program_rule(f.rule);
    let Some(policy) = f.rule.policy() else {
        let d = lensc_grammar::Diagnostic::error(code, f.message.clone(), file, span)
            .with_label("this block");
        return match &f.hint {
            Some(h) => d.with_help(h.clone()),
            None => d,
        };
    };
    let help = format!(
        "lensc's policy, not the controller's: {}{}",
        policy.reason,
        f.hint
            .as_ref()
            .map(|h| format!("; {h}"))
            .unwrap_or_default()
    );
    lensc_grammar::Diagnostic::error(code, policy_message(f), file, span)
        .with_label("this block")
        .with_help(help)
}

/// A finding's message, named by its policy where it is one of lensc's
/// own rules (`policy rapid-into-material: …`), so text and JSON both
/// say which class it is.
pub fn policy_message(f: &lensc_runtime::reader::Finding) -> String {
    match f.rule.policy() {
        Some(p) => format!("policy {}: {}", p.name, f.message),
        None => f.message.clone(),
    }
}

/// A fast tool servo the control programs on its own letter, as the
/// reader holds it (its velocity in mm/min, its stroke); `None` where
/// the program writes the servo otherwise (a table, or Z).
pub fn servo_axis(f: &FastAxisParams) -> Option<lensc_runtime::reader::ServoAxis> {
    f.own_axis
        .map(|(letter, v)| lensc_runtime::reader::ServoAxis {
            letter,
            max_velocity: v * 60.0,
            stroke: f.stroke,
        })
}
