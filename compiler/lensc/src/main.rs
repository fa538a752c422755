//! The `lensc` command line: `check`, `build`, `report`, `analyse`,
//! `sample`, `fmt`, `list`, `explain`, `import` and `lsp` (a language server). Exit codes: 0 success (warnings allowed), 1 errors in the
//! input, 2 usage errors, 101 an internal error, 130 and 143 a `build` or
//! `report` stopped by SIGINT or SIGTERM.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

mod commands;
mod interrupt;
mod lsp;
mod output;
mod progress;

use lensc_build::driver;
use output::Output;

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
    /// The project root: no file outside it is read on a job's behalf (a
    /// `use` that resolves there is an error). Default: the directory of
    /// the file given.
    #[arg(long, global = true, value_name = "DIR")]
    root: Option<PathBuf>,
    /// Print every diagnostic: without it, after 100 of one code the rest
    /// are counted in one summary line per code.
    #[arg(long, global = true)]
    all_diagnostics: bool,
}

#[derive(Subcommand)]
enum Command {
    /// Check files for errors without building anything.
    Check {
        /// The .lens files to check.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// The largest program to write, in bytes or with a unit (`500MB`,
        /// `4GB`, `2GiB`): a job whose program is estimated larger is
        /// refused before it is planned.
        #[arg(long, value_name = "SIZE", default_value = "4GB", value_parser = parse_size)]
        max_program_size: u64,
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
        /// The largest program to write, in bytes or with a unit (`500MB`,
        /// `4GB`, `2GiB`): a job whose program is estimated larger is
        /// refused before it is planned.
        #[arg(long, value_name = "SIZE", default_value = "4GB", value_parser = parse_size)]
        max_program_size: u64,
        /// What a job whose simulated part misses its acceptance criteria
        /// (its `accept` block, or the defaults) is: `error` (no program
        /// is written, exit 1) or `warn` (the program is written, for
        /// exploration).
        #[arg(long, value_enum, default_value_t = AcceptChoice::Error)]
        accept: AcceptChoice,
        /// No progress: neither the bar a terminal shows nor the JSON
        /// progress events of `--message-format json`.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Read a program back from its text as its controller would: modal
    /// state block by block, and every rule it breaks (feed moves with the
    /// spindle stopped or before a tool call, moves outside the travel or
    /// over the machine's feed, rapids into the part, arcs the controller
    /// refuses, number formats, comments, line lengths). Machine and
    /// dialect default to those the program's header names.
    Verify {
        /// The program to read.
        program: PathBuf,
        /// The machine to read it for (default: the header's).
        #[arg(long)]
        machine: Option<String>,
        /// The dialect to read it in (default: the header's).
        #[arg(long)]
        dialect: Option<String>,
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
        /// The largest program to write, in bytes or with a unit (`500MB`,
        /// `4GB`, `2GiB`): a job whose program is estimated larger is
        /// refused before it is planned.
        #[arg(long, value_name = "SIZE", default_value = "4GB", value_parser = parse_size)]
        max_program_size: u64,
        /// No progress: neither the bar a terminal shows nor the JSON
        /// progress events of `--message-format json`.
        #[arg(long, short)]
        quiet: bool,
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
    /// Put .lens files in the one canonical layout (comments kept where
    /// they were, meaning unchanged), rewriting each file that changes.
    Fmt {
        /// The .lens files to format.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Write nothing: list the files that would change and exit 1 if any would.
        #[arg(long)]
        check: bool,
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

    /// List the kinds a file can build and the standard library's machines,
    /// tools, dialects and strategies: documentation, parameters with their
    /// dimension, range and default, and each item's values (a machine's
    /// travel, feed, spindle, resolution and dialects).
    List {
        /// Only this category.
        #[arg(value_enum)]
        category: Option<commands::list::Listed>,
        /// Only this kind or item, in full.
        name: Option<String>,
        /// For people, or JSON (`{"categories": [...]}`, README "lensc list --format json").
        #[arg(long, value_enum, default_value_t = Format::Human)]
        format: Format,
    },
    /// Import a lens designer's prescription (a Zemax OpticStudio `.zmx` or
    /// an optiland JSON export) as a `.lens` file: one `surface` per optical
    /// surface, the designer's signs kept with `convention: optical`, each
    /// aperture from the semi-diameter. What is not imported is named in a
    /// warning and a comment.
    Import {
        /// The `.zmx` or optiland `.json` file.
        file: PathBuf,
        /// Write the `.lens` file here (default: stdout).
        #[arg(short = 'o', long = "output", value_name = "OUT.lens")]
        output: Option<PathBuf>,
    },
    /// Explain a diagnostic code (`E0147`), with an example that causes it
    /// and its fix.
    Explain {
        /// The code, as printed (`E0147`; `e147` and `147` work too).
        code: Option<String>,
        /// Every code with its title.
        #[arg(long)]
        list: bool,
        /// For people (Markdown), or JSON.
        #[arg(long, value_enum, default_value_t = Format::Human)]
        format: Format,
    },
    /// Run a language server on stdin and stdout for an editor: diagnostics
    /// as you type, hover, completion, go to definition and formatting
    /// (editors/README.md says how to set one up).
    Lsp,
}

/// How `list` and `explain` print.
#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum Format {
    Human,
    Json,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum MessageFormat {
    Human,
    Json,
}

#[derive(Clone, Copy, ValueEnum)]
enum AcceptChoice {
    Error,
    Warn,
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
    if let Some(root) = &cli.root
        && !root.is_dir()
    {
        eprintln!("error: --root {}: no such directory", root.display());
        return 2;
    }
    let out = Output {
        format: cli.message_format,
        color,
        root: cli.root,
        all_diagnostics: cli.all_diagnostics,
    };
    match cli.command {
        Command::Lsp => lsp::run(),
        Command::List {
            category,
            name,
            format,
        } => commands::list::run(category, name.as_deref(), format == Format::Json),
        Command::Explain { code, list, format } => {
            commands::explain::run(code.as_deref(), list, format == Format::Json)
        }
        Command::Check {
            files,
            max_program_size,
        } => commands::check::run(&out, &files, max_program_size),
        Command::Verify {
            program,
            machine,
            dialect,
        } => commands::verify::run(&out, &program, machine.as_deref(), dialect.as_deref()),
        Command::Fmt { files, check } => commands::fmt::run(&out, &files, check),
        Command::Import { file, output } => commands::import::run(&out, &file, output.as_deref()),
        Command::Analyse {
            file,
            surface,
            grid,
        } => commands::analyse::run(&out, &file, &surface, grid),
        Command::Sample {
            file,
            surface,
            grid,
            radial,
            points,
        } => commands::sample::run(&out, &file, &surface, grid, radial, points),
        Command::Report {
            file,
            job,
            out: dir,
            max_program_size,
            quiet,
        } => commands::report::run(&out, &file, job.as_deref(), &dir, max_program_size, quiet),
        Command::Build {
            file,
            job,
            dialect,
            out: dir,
            max_program_size,
            accept,
            quiet,
        } => commands::build::run(
            &out,
            &file,
            driver::Request {
                job: job.as_deref(),
                dialect: dialect.as_deref(),
                max_program_size: Some(max_program_size),
                accept: match accept {
                    AcceptChoice::Error => lensc_build::accept::Mode::Gate,
                    AcceptChoice::Warn => lensc_build::accept::Mode::Warn,
                },
                progress: lensc_build::progress::Observer::default(),
            },
            &dir,
            quiet,
        ),
    }
}

/// A size in bytes: a whole number, optionally with a decimal (`kB`, `MB`,
/// `GB`, `TB`) or binary (`KiB`, `MiB`, `GiB`, `TiB`) unit.
fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let factor: f64 = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "kb" | "k" => 1e3,
        "mb" | "m" => 1e6,
        "gb" | "g" => 1e9,
        "tb" | "t" => 1e12,
        "kib" => 1024.0,
        "mib" => 1024.0 * 1024.0,
        "gib" => 1024.0 * 1024.0 * 1024.0,
        "tib" => 1024.0 * 1024.0 * 1024.0 * 1024.0,
        other => {
            return Err(format!(
                "unknown unit `{other}`: use B, kB, MB, GB, TB, KiB, MiB, GiB or TiB"
            ));
        }
    };
    let n: f64 = number.parse().map_err(|_| {
        format!(
            "`{text}` is not a size: write a number of bytes, or one with a unit (`500MB`, `4GB`)"
        )
    })?;
    let bytes = n * factor;
    if (1.0..1.8e19).contains(&bytes) {
        Ok(bytes as u64)
    } else {
        Err(format!("`{text}` is not a size lensc can hold to"))
    }
}
