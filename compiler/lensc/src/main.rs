//! The `lensc` command line: `check`, `build`, `report`, `analyse` and
//! `sample`. Exit codes: 0 success (warnings allowed), 1 errors in the
//! input, 2 usage errors, 101 an internal error.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use lensc::render;
use lensc_build::driver::{self, Checked};
use lensc_lang::loader::{RealFs, plain_io_error};

#[derive(Parser)]
#[command(
    name = "lensc",
    version,
    about = "Compile lens-machining jobs (.lens files) into machine programs"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// How diagnostics are printed: for people, or one JSON object per line on stdout.
    #[arg(long, global = true, value_enum, default_value_t = MessageFormat::Human)]
    message_format: MessageFormat,
    /// Colour in human diagnostics.
    #[arg(long, global = true, value_enum, default_value_t = ColorChoice::Auto)]
    color: ColorChoice,
}

#[derive(Subcommand)]
enum Command {
    /// Check files for errors without building anything.
    Check {
        /// The .lens files to check.
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Check a file and write a program for each of its jobs.
    Build {
        /// The .lens file to build.
        file: PathBuf,
        /// Build only this job.
        #[arg(long)]
        job: Option<String>,
        /// Write the program in this dialect, one the machine offers (its
        /// `dialect` or one of its `other_dialects`).
        #[arg(long)]
        dialect: Option<String>,
        /// Directory for the programs.
        #[arg(long, default_value = "out")]
        out: PathBuf,
    },
    /// Plan and simulate a file's jobs as `build` does and write SVG plots
    /// of what each program will cut: `JOB.profile.svg` (profile jobs: the
    /// design, the tool-centre path and the simulated cut, with the form
    /// error in nm beneath), `JOB.form_error.svg` (raster, spiral and
    /// roller jobs: the form error over the simulation window as a colour
    /// map) and `JOB.following.svg` (fast-tool-servo jobs: the servo's
    /// following error against radius). Writes no program or report (use
    /// `build`); nothing is written if any job fails.
    Report {
        /// The .lens file to plot.
        file: PathBuf,
        /// Plot only this job.
        #[arg(long)]
        job: Option<String>,
        /// Directory for the plots.
        #[arg(long, default_value = "out")]
        out: PathBuf,
    },
    /// Analyse a surface over its aperture: sag range, slopes and radii of
    /// curvature with where they occur, as JSON on stdout.
    Analyse {
        /// The .lens file that declares the surface.
        file: PathBuf,
        /// The surface's name.
        #[arg(long)]
        surface: String,
        /// Grid points per side before refinement.
        #[arg(long, default_value_t = 201, value_name = "N")]
        grid: usize,
    },
    /// Evaluate a surface: CSV on stdout with the header
    /// x,y,z,dzdx,dzdy,curvature_x,curvature_y (mm and 1/mm).
    #[command(group(clap::ArgGroup::new("at").required(true).args(["grid", "radial", "points"])))]
    Sample {
        /// The .lens file that declares the surface.
        file: PathBuf,
        /// The surface's name.
        #[arg(long)]
        surface: String,
        /// N × N points over the aperture.
        #[arg(long, value_name = "N")]
        grid: Option<usize>,
        /// N points from the centre to the edge along x.
        #[arg(long, value_name = "N")]
        radial: Option<usize>,
        /// Points from a CSV file of x,y in mm (a header line is skipped).
        #[arg(long, value_name = "FILE.csv")]
        points: Option<PathBuf>,
    },
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum MessageFormat {
    Human,
    Json,
}

#[derive(Clone, Copy, ValueEnum)]
enum ColorChoice {
    Auto,
    Always,
    Never,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Deep but valid input is bounded by the parser's nesting limit; a large
    // stack keeps the recursive checker far from the edge all the same.
    let worker = std::thread::Builder::new()
        .stack_size(256 << 20)
        .spawn(move || run(cli));
    match worker.map(|h| h.join()) {
        Ok(Ok(code)) => ExitCode::from(code),
        _ => ExitCode::from(101),
    }
}

fn run(cli: Cli) -> u8 {
    let color = match cli.color {
        ColorChoice::Always => true,
        ColorChoice::Never => false,
        ColorChoice::Auto => {
            std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none()
        }
    };
    let out = Output {
        format: cli.message_format,
        color,
    };
    match cli.command {
        Command::Check { files } => {
            let mut code = 0;
            for f in &files {
                let Some(c) = load(&out, f) else {
                    code = 1;
                    continue;
                };
                // Everything knowable without planning: each job lowered
                // as `build` lowers it (in its machine's own dialect), once
                // the file checks.
                let mut diags = c.diags().to_vec();
                if !c.has_errors() {
                    diags.extend(
                        c.checked
                            .jobs
                            .iter()
                            .filter_map(|j| lensc_build::pipeline::lower(j, None).err())
                            .flatten(),
                    );
                }
                out.diagnostics(&c, &diags);
                if diags.iter().any(|d| d.is_error()) {
                    code = 1;
                }
            }
            code
        }
        Command::Analyse {
            file,
            surface,
            grid,
        } => {
            let Some(c) = load(&out, &file) else { return 1 };
            out.diagnostics(&c, c.diags());
            if c.has_errors() {
                return 1;
            }
            match driver::declared_surface(&c, &surface) {
                Ok(l) => {
                    let kind = c
                        .checked
                        .declarations
                        .get(&surface)
                        .map_or("", |o| o.kind.name);
                    let v = driver::analysis_json(&surface, kind, &l, grid.max(2));
                    // A closed pipe (`| head`) is not an error.
                    let _ = writeln!(
                        std::io::stdout().lock(),
                        "{}",
                        serde_json::to_string_pretty(&v).unwrap_or_default()
                    );
                    0
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    2
                }
            }
        }
        Command::Sample {
            file,
            surface,
            grid,
            radial,
            points,
        } => {
            let Some(c) = load(&out, &file) else { return 1 };
            out.diagnostics(&c, c.diags());
            if c.has_errors() {
                return 1;
            }
            let at = match (grid, radial, points) {
                (Some(n), _, _) => driver::SamplePoints::Grid(n),
                (_, Some(n), _) => driver::SamplePoints::Radial(n),
                (_, _, Some(p)) => match read_points(&p) {
                    Ok(p) => driver::SamplePoints::Points(p),
                    Err(e) => {
                        eprintln!("error: {e}");
                        return 2;
                    }
                },
                _ => unreachable!("clap requires one of them"),
            };
            match driver::sample(&c, &surface, &at) {
                Ok(rows) => {
                    let mut text = String::from("x,y,z,dzdx,dzdy,curvature_x,curvature_y\n");
                    for r in rows {
                        let cells: Vec<String> = r.iter().map(|v| format!("{v}")).collect();
                        text.push_str(&cells.join(","));
                        text.push('\n');
                    }
                    let _ = std::io::stdout().lock().write_all(text.as_bytes());
                    0
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    2
                }
            }
        }
        Command::Report {
            file,
            job,
            out: dir,
        } => {
            let c = match load_jobs(&out, &file, job.as_deref()) {
                Ok(c) => c,
                Err(code) => return code,
            };
            // The programs are built as `build` builds them (spooled into
            // the output directory and dropped: only the plots are kept).
            let (built, diags) = driver::plan_and_emit(
                &c,
                driver::Request {
                    job: job.as_deref(),
                    dialect: None,
                },
                &file.display().to_string(),
                Some(&dir),
            );
            out.diagnostics(&c, &diags);
            if diags.iter().any(|d| d.is_error()) {
                return 1;
            }
            // Every plot is drawn before any is written.
            let mut plots = Vec::new();
            for b in built {
                let name = b.report["job"].as_str().unwrap_or_default().to_string();
                match lensc_build::plots::render(&name, &b.plots) {
                    Ok(files) if files.is_empty() => eprintln!(
                        "note: job `{name}` has nothing to plot: its simulation was skipped ({})",
                        b.report["simulation"]["skipped"]
                            .as_str()
                            .unwrap_or("no simulation")
                    ),
                    Ok(files) => plots.extend(files),
                    Err(e) => {
                        eprintln!("error: job `{name}`: {e}");
                        return 101;
                    }
                }
            }
            for (name, svg) in plots {
                let path = dir.join(&name);
                if let Err(e) = driver::write_atomic(&path, &svg) {
                    eprintln!(
                        "error[{}]: cannot write {}: {}",
                        lensc_lang::codes::CANNOT_WRITE,
                        path.display(),
                        plain_io_error(&e)
                    );
                    return 1;
                }
                eprintln!("wrote {} ({} bytes)", path.display(), svg.len());
            }
            0
        }
        Command::Build {
            file,
            job,
            dialect,
            out: dir,
        } => {
            let c = match load_jobs(&out, &file, job.as_deref()) {
                Ok(c) => c,
                Err(code) => return code,
            };
            let (programs, diags) = driver::plan_and_emit(
                &c,
                driver::Request {
                    job: job.as_deref(),
                    dialect: dialect.as_deref(),
                },
                &file.display().to_string(),
                Some(&dir),
            );
            out.diagnostics(&c, &diags);
            if diags.iter().any(|d| d.is_error()) {
                return 1;
            }
            for built in programs {
                let target = dir.join(&built.program_name);
                let report_path = dir.join(&built.report_name);
                let report = serde_json::to_string_pretty(&built.report).unwrap_or_default() + "\n";
                let lines = built.program.lines();
                let beside: Vec<String> = built
                    .beside
                    .iter()
                    .map(|(name, text)| {
                        format!(", {} ({} lines)", dir.join(name).display(), text.lines())
                    })
                    .collect();
                // The report is written first: a program on disk always has
                // its report beside it.
                let mut written = driver::write_atomic(&report_path, &report)
                    .map_err(|e| (report_path.clone(), e));
                // Then what the program reads, then the program.
                for (name, text) in built.beside {
                    let path = dir.join(&name);
                    written = written.and_then(|()| text.write_to(&path).map_err(|e| (path, e)));
                }
                let written = written.and_then(|()| {
                    built
                        .program
                        .write_to(&target)
                        .map_err(|e| (target.clone(), e))
                });
                if let Err((path, e)) = written {
                    eprintln!(
                        "error[{}]: cannot write {}: {}",
                        lensc_lang::codes::CANNOT_WRITE,
                        path.display(),
                        plain_io_error(&e)
                    );
                    return 1;
                }
                eprintln!(
                    "wrote {} ({} lines, {} cut points, estimated cutting time {:.1} s){} and {}",
                    target.display(),
                    lines,
                    built.cut_points,
                    built.cutting_time,
                    beside.concat(),
                    report_path.display()
                );
            }
            0
        }
    }
}

struct Output {
    format: MessageFormat,
    color: bool,
}

impl Output {
    fn diagnostics(&self, c: &Checked, diags: &[lensc_grammar::Diagnostic]) {
        let result = match self.format {
            MessageFormat::Human => render::human(
                diags,
                &c.loaded.sources,
                self.color,
                &mut std::io::stderr().lock(),
            ),
            MessageFormat::Json => {
                render::json_lines(diags, &c.loaded.sources, &mut std::io::stdout().lock())
            }
        };
        // A closed pipe is no reason to fail the build.
        let _ = result;
        let _ = std::io::stdout().flush();
    }
}

/// Whether the checked file has the job asked for (exit 2 if not) and any
/// job at all (exit 1, E-code NO_JOB, if not).
/// Loads and checks `file` for `build` and `report`, printing its
/// diagnostics: the checked file if it has the job(s) asked for, or the
/// exit code (1 for errors in the input, 2 for a `--job` naming no job).
fn load_jobs(out: &Output, file: &Path, job: Option<&str>) -> Result<Checked, u8> {
    let Some(c) = load(out, file) else {
        return Err(1);
    };
    out.diagnostics(&c, c.diags());
    if c.has_errors() {
        return Err(1);
    }
    has_jobs(out, &c, file, job)?;
    Ok(c)
}

fn has_jobs(out: &Output, c: &Checked, file: &Path, job: Option<&str>) -> Result<(), u8> {
    if let Some(name) = job
        && !c.checked.jobs.iter().any(|j| j.name.name == name)
    {
        let names: Vec<&str> = c
            .checked
            .jobs
            .iter()
            .map(|j| j.name.name.as_str())
            .collect();
        eprintln!(
            "error: {} has no job `{name}` (its jobs: {})",
            file.display(),
            if names.is_empty() {
                "none".into()
            } else {
                names.join(", ")
            }
        );
        return Err(2);
    }
    if c.checked.jobs.is_empty() {
        let d = lensc_grammar::Diagnostic::error(
            lensc_lang::codes::NO_JOB,
            "this file has no job to build",
            lensc_grammar::FileId(0),
            lensc_grammar::Span::new(0, 0),
        )
        .with_help("add `job NAME { surface: …, tool: …, machine: …, strategy: … }`");
        out.diagnostics(c, &[d]);
        return Err(1);
    }
    Ok(())
}

/// Loads and checks a root file; reports an unreadable file itself.
fn load(out: &Output, path: &Path) -> Option<Checked> {
    match driver::check_path(&RealFs, path) {
        Ok(c) => Some(c),
        Err(e) => {
            let msg = format!("cannot read {}: {}", path.display(), plain_io_error(&e));
            match out.format {
                MessageFormat::Human => {
                    eprintln!("error[{}]: {msg}", lensc_lang::codes::CANNOT_READ)
                }
                MessageFormat::Json => drop(writeln!(
                    std::io::stdout().lock(),
                    "{}",
                    serde_json::json!({"severity": "error", "code": lensc_lang::codes::CANNOT_READ, "message": msg,
                        "file": path.display().to_string(), "line": 0, "column": 0,
                        "span": {"start": 0, "end": 0}, "labels": [], "help": null})
                )),
            }
            None
        }
    }
}

/// Reads x,y pairs (mm) from a CSV file; a first line that is not two
/// numbers is taken as a header.
fn read_points(path: &Path) -> Result<Vec<(f64, f64)>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {}", path.display(), plain_io_error(&e)))?;
    let mut pts = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let mut cells = line.split(',').map(str::trim);
        let parsed = (
            cells.next().and_then(|c| c.parse::<f64>().ok()),
            cells.next().and_then(|c| c.parse::<f64>().ok()),
        );
        match parsed {
            (Some(x), Some(y)) if x.is_finite() && y.is_finite() => pts.push((x, y)),
            _ if i == 0 => {}
            _ => {
                return Err(format!(
                    "{}:{}: expected two numbers `x,y` in mm",
                    path.display(),
                    i + 1
                ));
            }
        }
    }
    Ok(pts)
}
