//! The four parts of a checked job (surface, tool, machine, strategy) as
//! every job builder reads them: their declared names, where a job's errors
//! point, the provenance lines every program header starts with, and the
//! report every program has beside it.

use crate::diagnostics::RuntimeError;
use crate::driver::{ProgramText, surface_analysis};
use crate::report;
use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_lang::check::CheckedJob;
use lensc_lang::codes;
use lensc_lang::value::{self, Object};
use lensc_runtime::post::Dialect;
use lensc_runtime::post::ProgramError;
use lensc_runtime::post::Provenance;

/// The four parts of a checked job, their names, and where errors point.
pub(crate) struct Parts<'a> {
    pub job: &'a CheckedJob,
    pub surface: &'a Object,
    pub tool: &'a Object,
    pub machine: &'a Object,
    pub strategy: &'a Object,
    /// The dialect the program is written in.
    pub dialect: &'a Dialect,
}

impl<'a> Parts<'a> {
    pub(crate) fn of(job: &'a CheckedJob, dialect: &'a Dialect) -> Parts<'a> {
        let part = |name: &str| -> &'a Object {
            value::object(&job.fields, name).expect("checked job part")
        };
        Parts {
            job,
            surface: part("surface"),
            tool: part("tool"),
            machine: part("machine"),
            strategy: part("strategy"),
            dialect,
        }
    }
    pub(crate) fn name(&self, part: &str, o: &Object) -> String {
        self.job
            .part_names
            .get(part)
            .cloned()
            .unwrap_or_else(|| o.kind.name.to_string())
    }
    pub(crate) fn site(&self) -> (FileId, Span) {
        (self.job.file, self.job.name.span)
    }
    pub(crate) fn error(&self, code: &'static str, msg: String) -> Diagnostic {
        let (file, span) = self.site();
        Diagnostic::error(code, msg, file, span).with_label("this job")
    }
    /// The program's file name: the job's name and the dialect's extension.
    pub(crate) fn program_name(&self) -> String {
        format!("{}.{}", self.job.name.name, self.dialect.extension)
    }
    /// The header words for the feed in inverse time.
    pub(crate) fn inverse_time_words(&self) -> String {
        format!(
            "feed in inverse time [{}, F = 1/min per move]",
            self.dialect.inverse_time.as_deref().unwrap_or("none")
        )
    }
    /// The lines every header starts with.
    pub(crate) fn header(&self, prov: &Provenance, units: &str) -> Vec<String> {
        vec![
            format!("lensc {}: job {}", prov.lensc_version, self.job.name.name),
            format!("source {} fnv1a64 {:016x}", prov.source, prov.source_hash),
            units.to_string(),
            format!(
                "surface {}: {}",
                self.name("surface", self.surface),
                lensc_lang::lower::describe(self.surface)
            ),
        ]
    }
    /// The report of the job's program, its toolpath and simulation, with
    /// the analysis of the surface.
    pub(crate) fn report(
        &self,
        prov: &Provenance,
        program_name: &str,
        program: &ProgramText,
        toolpath: report::Toolpath,
        simulation: report::Simulation,
        lowered: &lensc_lang::lower::surface::LoweredSurface,
    ) -> report::Report {
        report::Report {
            job: self.job.name.name.to_string(),
            lensc_version: prov.lensc_version.clone(),
            source: prov.source.clone(),
            source_fnv1a64: format!("{:016x}", prov.source_hash),
            program: report::Program {
                file: program_name.to_string(),
                dialect: self.dialect.name.clone(),
                lines: program.lines(),
                bytes: program.bytes(),
                fts_table: None,
            },
            toolpath,
            simulation,
            surface: surface_analysis(
                &self.name("surface", self.surface),
                self.surface.kind.name,
                lowered,
                201,
            ),
        }
    }
    /// E0141 if a move of the stream leaves the machine's `travel` block.
    pub(crate) fn travel_error(&self, moves: &[lensc_runtime::moves::Move]) -> Option<Diagnostic> {
        let travel = value::block(&self.machine.fields, "travel")?;
        let limits = ["x", "y", "z", "c"].map(|a| value::range(travel, a));
        let (axis, v, (lo, hi)) = lensc_runtime::moves::outside_travel(moves, limits)?;
        Some(self.error(
            codes::OUT_OF_TRAVEL,
            format!(
                "the path moves {axis} to {} mm, outside the machine's travel {} .. {} mm",
                lensc_lang::check::trim_num(v),
                lensc_lang::check::trim_num(lo),
                lensc_lang::check::trim_num(hi)
            ),
        ))
    }

    /// A runtime error of this job as its diagnostic.
    pub(crate) fn failed(&self, e: RuntimeError) -> Diagnostic {
        let (file, span) = self.site();
        e.at(file, span)
    }
    pub(crate) fn not_printable(&self, e: ProgramError) -> Diagnostic {
        self.failed(RuntimeError::Program(e))
    }
    pub(crate) fn lowered(
        &self,
    ) -> Result<lensc_lang::lower::surface::LoweredSurface, Vec<Diagnostic>> {
        lensc_lang::lower::surface::lower_surface(self.surface)
            .map_err(|e| vec![self.failed(RuntimeError::Surface(e))])
    }
    pub(crate) fn needs(
        &self,
        part: &str,
        o: &Object,
        kinds: &[&str],
        what: &str,
    ) -> Option<Diagnostic> {
        (!kinds.contains(&o.kind.name)).then(|| {
            self.error(
                codes::UNSUPPORTED_COMBINATION,
                format!(
                    "{what} needs {}; this {part} is a `{}`",
                    kinds
                        .iter()
                        .map(|k| format!("`{k}`"))
                        .collect::<Vec<_>>()
                        .join(" or "),
                    o.kind.name
                ),
            )
        })
    }
}
