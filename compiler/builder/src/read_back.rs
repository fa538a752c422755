//! Every program a build makes is read back from its text before it is
//! put in place, by the rules of `lensc verify` (`lensc_runtime::reader`):
//! a program the reader refuses is never written, and its job fails with
//! the reader's findings, at the job, each naming the program's line. A
//! spooled program (millions of lines) is read on a thread of its own as
//! its text is spooled (`read_along`), from the pieces in memory: it is
//! not read from the disk again, and it is read while the next pieces are
//! planned; the spool file is still renamed into place only once the
//! reader has passed it.

use std::io::BufReader;

use crate::job::JobHead;
use lensc_grammar::Diagnostic;
use lensc_lang::check::CheckedJob;
use lensc_lang::lower::read_back::job_machine;
use lensc_runtime::reader;

use crate::output::ProgramText;
use crate::read_along::ReadAlong;

/// Whether builds read their programs back before writing them (on since
/// every program is complete: issue 14, item 1). `LENSC_READ_BACK=1`
/// turns it on where this is off.
pub const READ_BACK_BY_DEFAULT: bool = true;

/// Whether this run reads its programs back.
pub fn enabled() -> bool {
    READ_BACK_BY_DEFAULT || std::env::var_os("LENSC_READ_BACK").is_some_and(|v| v == "1")
}

pub use crate::reading::ReadBack;

/// The reader's findings in `program` as errors at the job; none if it
/// reads clean. A program read as it was spooled is not read again: its
/// reader's findings are taken once it has read the whole text; nor one
/// in memory whose builder read its text for the simulation by the
/// read-back's rules (`read`, its findings: `context::read_program`).
pub(crate) fn findings(
    job: &CheckedJob,
    head: &JobHead,
    program: &mut ProgramText,
    read: Option<Vec<reader::Finding>>,
) -> Vec<Diagnostic> {
    let machine = job_machine(job);
    let found = match (program, read) {
        (ProgramText::Memory(_), Some(found)) => Ok(found),
        (ProgramText::Memory(text), None) => Ok(reader::read(text, &head.dialect, &machine)),
        (
            ProgramText::Spooled {
                read: read @ Some(_),
                ..
            },
            _,
        ) => Ok(read.take().map(ReadAlong::finish).unwrap_or_default()),
        (ProgramText::Spooled { file, .. }, _) => std::fs::File::open(file.path())
            .and_then(|f| reader::read_from(BufReader::new(f), &head.dialect, &machine)),
    };
    diagnostics(head, found)
}

/// The reader's findings (or why the text could not be read) as errors at
/// the job.
fn diagnostics(head: &JobHead, found: std::io::Result<Vec<reader::Finding>>) -> Vec<Diagnostic> {
    let name = head.program_name();
    match found {
        Ok(found) => found
            .iter()
            .map(|f| {
                let d = head.error(
                    lensc_lang::codes::program_rule(f.rule),
                    match f.rule.policy() {
                        Some(_) => format!(
                            "{name}, line {}, read back, breaks lensc's {}",
                            f.line,
                            lensc_lang::lower::read_back::policy_message(f)
                        ),
                        None => format!(
                            "{name}, line {}, read back as the controller reads it: {}",
                            f.line, f.message
                        ),
                    },
                );
                let help =
                    "no program was written; `lensc verify` reads a program by the same rules";
                d.with_help(match &f.hint {
                    Some(h) => format!("{h}; {help}"),
                    None => help.to_string(),
                })
            })
            .collect(),
        Err(e) => vec![head.error(
            lensc_lang::codes::CANNOT_WRITE,
            format!("{name} could not be read back before writing: {e}"),
        )],
    }
}
