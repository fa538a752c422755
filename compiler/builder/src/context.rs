//! The build context: what every strategy's builder is given (provenance,
//! where its program goes, who counts its progress, the reader that reads
//! it back as it is spooled) and the steps every builder shares: the
//! provenance lines every program header starts with, the feed words, the
//! sink a program is written into, the report every program has beside
//! it, the program's own moves read back as the controller reads them,
//! and the errors that point at the job.

use crate::job::JobHead;
use lensc_grammar::Diagnostic;
use lensc_runtime::post::ProgramError;
use lensc_runtime::post::Provenance;

use crate::diagnostics::RuntimeError;
use crate::output::Destination;
use crate::output::{Built, ProgramText};
use crate::plots::PlotSeries;
use crate::progress::Meter;
use crate::read_back::ReadBack;
use crate::report;
use crate::report::surface_analysis;
use crate::spool::ProgramSink;
use lensc_lang::codes;

/// What a strategy's builder is given, whatever the strategy: every
/// builder builds through `Strategy::build(&self, &BuildContext)`.
#[derive(Clone, Copy)]
pub struct BuildContext<'a> {
    /// Where the program's header says it came from.
    pub prov: &'a Provenance,
    /// Where a streamed program goes: memory, a spool file or nowhere.
    pub to: Destination<'a>,
    /// Counts the points planned and bytes formatted, for progress.
    pub meter: Meter<'a>,
    /// The reader that reads a spooled program back as it is written.
    pub read: Option<&'a ReadBack>,
}

impl<'a> BuildContext<'a> {
    /// The sink a streamed program (a spiral's, a roller's) is written
    /// into as it is planned: spooled, counted and read back as it goes.
    pub(crate) fn sink(&self, head: &JobHead) -> Result<ProgramSink<'a>, Vec<Diagnostic>> {
        ProgramSink::new(self.to, head.site, self.meter, self.read)
    }
}

/// The header words for the feed in inverse time.
pub(crate) fn inverse_time_words(head: &JobHead) -> String {
    format!(
        "feed in inverse time [{}, F = 1/min per move]",
        head.dialect.inverse_time.as_deref().unwrap_or("none")
    )
}

/// The lines every header starts with: provenance, units, the control
/// point, the surface.
pub(crate) fn header(head: &JobHead, prov: &Provenance, units: &str) -> Vec<String> {
    let mut lines = vec![
        format!("lensc {}: job {}", prov.lensc_version, head.name),
        format!("source {} fnv1a64 {:016x}", prov.source, prov.source_hash),
        units.to_string(),
        head.control.header_line(head.start.control),
        format!("surface {}: {}", head.names.surface, head.surface.words),
    ];
    if let Some(c) = &head.surface.compensation {
        lines.push(crate::compensate::header_words(c));
    }
    lines
}

/// The lines of a servo lathe's header: provenance, units, the control
/// point, the feed, surface, and the round-nose tool.
pub(crate) fn nose_centre_header(
    head: &JobHead,
    prov: &Provenance,
    units: &str,
    nose_radius: f64,
) -> Vec<String> {
    let mut lines = header(head, prov, units);
    // The feed's words stand between the control point and the surface.
    lines.insert(4, inverse_time_words(head));
    lines.push(format!(
        "tool {}: round nose, nose radius {} mm",
        head.names.tool,
        lensc_lang::lower::exact_in(nose_radius, "mm")
    ));
    lines
}

/// A built job: its program, the report beside it (from the toolpath's
/// section and the simulation), the plots, and the points and time (s) of
/// the cut; nothing beside the program and no warnings, until its builder
/// adds them.
pub(crate) fn built(
    head: &JobHead,
    prov: &Provenance,
    program: ProgramText,
    toolpath: report::Toolpath,
    simulation: report::Simulation,
    plots: PlotSeries,
    (cut_points, cutting_time): (usize, f64),
) -> Built {
    let program_name = head.program_name();
    let report = report(head, prov, &program_name, &program, toolpath, simulation);
    Built {
        report_name: format!("{}.report.json", head.name),
        program_name,
        program,
        report,
        beside: Vec::new(),
        cut_points,
        cutting_time,
        plots,
        warnings: Vec::new(),
        read_back: None,
        read_findings: None,
    }
}

/// The report beside a program: provenance, the program, the toolpath's
/// own section, the simulation and the surface's analysis.
fn report(
    head: &JobHead,
    prov: &Provenance,
    program_name: &str,
    program: &ProgramText,
    toolpath: report::Toolpath,
    simulation: report::Simulation,
) -> report::Report {
    report::Report {
        job: head.name.to_string(),
        lensc_version: prov.lensc_version.clone(),
        source: prov.source.clone(),
        source_fnv1a64: format!("{:016x}", prov.source_hash),
        program: report::Program {
            file: program_name.to_string(),
            dialect: head.dialect.name.clone(),
            lines: program.lines(),
            bytes: program.bytes(),
            fts_table: None,
            delivery: None,
        },
        toolpath,
        // Filled in by the pipeline, which made the estimate.
        estimate: report::Estimate::default(),
        simulation,
        // Filled in by the pipeline's acceptance gate.
        acceptance: report::Acceptance::pending(),
        surface: surface_analysis(
            &head.names.surface,
            head.surface.kind,
            &head.surface.lowered,
            201,
        ),
        compensation: head.surface.compensation.clone(),
    }
}

/// E0141 if a move of the stream leaves the machine's travel.
pub(crate) fn travel_error(
    head: &JobHead,
    moves: &[lensc_runtime::moves::Move],
) -> Option<Diagnostic> {
    let (axis, v, (lo, hi)) = lensc_runtime::moves::outside_travel(moves, head.travel)?;
    Some(head.error(
        codes::OUT_OF_TRAVEL,
        format!(
            "the path moves {axis} to {} mm, outside the machine's travel {} .. {} mm",
            lensc_lang::check::trim_num(v),
            lensc_lang::check::trim_num(lo),
            lensc_lang::check::trim_num(hi)
        ),
    )
    .with_help("check the machine's `travel`, the part's size and where it sits, and the strategy's retract height; or use a machine with more travel"))
}

/// E0150: the program cannot be written in the job's dialect.
pub(crate) fn not_printable(head: &JobHead, e: ProgramError) -> Diagnostic {
    failed(head, RuntimeError::Program(e))
}

/// A runtime error of the job as its diagnostic, at the job's name.
pub(crate) fn failed(head: &JobHead, e: RuntimeError) -> Diagnostic {
    e.at(head.site)
}

/// The moves the controller makes reading `text` (`reader::read_moves`)
/// on a lathe or a mill: only the moves are taken here, the read-back
/// judges the rules.
pub(crate) fn executed_moves(
    head: &JobHead,
    text: &str,
    lathe: bool,
) -> Vec<lensc_runtime::reader::Executed> {
    read_program(head, text, lathe, None).1
}

/// `text` read once as the controller reads it, for the simulation and
/// the read-back both: the moves it makes (as `executed_moves`) and, when
/// the build reads its program back (`read`: the job's dialect and
/// machine), the reader's findings by the read-back's rules, which the
/// read-back takes instead of reading the text a second time. The reader
/// reads the text alone, whoever asks (the fitter's splines are read from
/// their printed blocks).
pub(crate) fn read_program(
    head: &JobHead,
    text: &str,
    lathe: bool,
    read: Option<&ReadBack>,
) -> (
    Option<Vec<lensc_runtime::reader::Finding>>,
    Vec<lensc_runtime::reader::Executed>,
) {
    let relaxed = lensc_runtime::reader::MachineLimits {
        lathe,
        travel: [None; 4],
        max_feed: None,
        max_spindle_rpm: None,
        servo: head.servo,
    };
    // The machine's travel, feed and speed only add findings: the moves
    // are the same read by either. A read-back of another kind of machine
    // than `lathe` says is not shared (the text is read as `lathe` says,
    // and the read-back reads it again).
    let by = read.filter(|r| r.machine.lathe == lathe);
    let machine = by.map_or(&relaxed, |r| &r.machine);
    let (found, mut moves) = lensc_runtime::reader::read_moves(text, &head.dialect, machine);
    // As `lensc verify` would: the control point the program's header
    // states, taken off again, so the cut is the tool centre's.
    if let Some(offset) = lensc_runtime::reader::header_control_offset(text) {
        lensc_runtime::reader::to_tool_centre(&mut moves, offset);
    }
    (by.map(|_| found), moves)
}

/// What a lathe or grinder program cuts, read from its text as the
/// controller reads it (`reader::read_moves`, arcs blended as the
/// controller blends them) with a round edge of radius `rho` along it,
/// against `design` over `range` (`simulate::program_cut`). Only the moves
/// are taken here: the read-back judges the rules.
pub(crate) fn program_cut(
    head: &JobHead,
    text: &str,
    rho: f64,
    design: &dyn Fn(f64) -> f64,
    range: (f64, f64),
) -> lensc_runtime::verify::simulate::ProfileCut {
    program_cut_by(
        head,
        text,
        &lensc_runtime::machine::edge::Nose::circle(rho),
        design,
        range,
    )
}

/// `program_cut` by a round nose whose edge may be measured.
pub(crate) fn program_cut_by(
    head: &JobHead,
    text: &str,
    nose: &lensc_runtime::machine::edge::Nose,
    design: &dyn Fn(f64) -> f64,
    range: (f64, f64),
) -> lensc_runtime::verify::simulate::ProfileCut {
    lensc_runtime::verify::simulate::program_cut_by(
        &executed_moves(head, text, true),
        nose,
        design,
        range,
        crate::plots::PROFILE_SAMPLES,
    )
}
