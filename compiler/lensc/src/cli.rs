//! The command line as clap defines it: every subcommand, argument and
//! help text, in the library so that the book's CLI page (`cli_page`) is
//! rendered from this very definition. `main.rs` parses with it and runs.

use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};
use lensc_build::measure::LensletPick;
use lensc_lang::schema::Category;

#[derive(Parser)]
#[command(
    name = "lensc",
    version,
    about = "Compile lens-machining jobs (.lens files) into machine programs"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// How diagnostics are printed: for people, or one JSON object per line on stdout.
    #[arg(long, global = true, value_enum, default_value_t = MessageFormat::Human)]
    pub message_format: MessageFormat,
    /// Colour in human diagnostics.
    #[arg(long, global = true, value_enum, default_value_t = ColorChoice::Auto)]
    pub color: ColorChoice,
    /// The project root: no file outside it is read on a job's behalf (a
    /// `use` that resolves there is an error). Default: the directory of
    /// the file given.
    #[arg(long, global = true, value_name = "DIR")]
    pub root: Option<PathBuf>,
    /// Print every diagnostic: without it, after 100 of one code the rest
    /// are counted in one summary line per code.
    #[arg(long, global = true)]
    pub all_diagnostics: bool,
}

#[derive(Subcommand)]
pub enum Command {
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
        /// Write the jobs that pass even when others fail (the exit code is
        /// still 1). Without it a build is all or nothing: the files of
        /// every job are written together, as one unit, only if every job
        /// passes.
        #[arg(long)]
        keep_going: bool,
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
        /// What a finding of lensc's own policy (a rule the controller
        /// would run, such as `rapid-into-material`) does: `fail` (exit 1,
        /// as the controller's rules) or `warn` (printed as a warning;
        /// exit 0 if nothing else is found).
        #[arg(long, value_enum, default_value = "fail")]
        policy: PolicyChoice,
        /// The `.lens` file the program was built from, to check the hash
        /// its header carries against (default: the path the header
        /// names, from the current directory, else beside the program).
        #[arg(long)]
        source: Option<PathBuf>,
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
        /// Plot the program as `build --dialect` writes it in this
        /// dialect, one the machine offers (its `dialect` or one of its
        /// `other_dialects`): its moves are what is simulated.
        #[arg(long)]
        dialect: Option<String>,
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
    /// Build a file's jobs as `build` does and write one self-contained
    /// HTML page per job (`JOB.view.html`, opens offline): the program's
    /// backplot in 3-D as the controller reads it (rapids and cutting
    /// moves apart, passes selectable; a long program thinned for drawing,
    /// and the page says how), the simulated form error over the whole
    /// part on the design surface, the acceptance figures and the set-up,
    /// from the build's report. Writes no program (use `build`); a part
    /// that misses its criteria is viewed all the same, with its verdict;
    /// nothing is written if any job fails to build.
    View {
        /// The .lens file to view.
        file: PathBuf,
        /// View only this job.
        #[arg(long)]
        job: Option<String>,
        /// View the program as `build --dialect` writes it in this
        /// dialect, one the machine offers (its `dialect` or one of its
        /// `other_dialects`): its moves are what is simulated.
        #[arg(long)]
        dialect: Option<String>,
        /// Directory for the pages.
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
        category: Option<Listed>,
        /// Only this kind or item, in full.
        name: Option<String>,
        /// For people, or JSON (`{"categories": [...]}`, its shape in the book's
        /// docs/usage/list-and-explain.md).
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
    /// Hold a measured part to its job's design: read the measurement (an
    /// X3P, SDF or MetroPro file, its ASCII export, x y z points or an x z
    /// profile), register it to the job's surface (piston, tilt, decentre
    /// and, off a surface of revolution, clocking), and write
    /// `JOB.measure.json` (the error along the normal with its PV and RMS,
    /// the registration, the texture after form removal, a turned part's
    /// centre-height error and X offset with their corrections) and
    /// `JOB.error_map.svg`. Nothing is written if the file cannot be read
    /// or does not fit the surface.
    Measure {
        /// The .lens file with the job.
        file: PathBuf,
        /// The measurement file (under the project root, as job files).
        part: PathBuf,
        /// The job the part was cut by (needed when the file has several).
        #[arg(long)]
        job: Option<String>,
        /// Directory for the report and the picture.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// What a plain-text file's numbers are (X3P, SDF and MetroPro
        /// files state their own units).
        #[arg(long, value_enum, default_value_t = TextUnit::Mm)]
        units: TextUnit,
        /// The least share (percent) of the measured aperture whose points
        /// must be valid.
        #[arg(long, value_name = "PERCENT", default_value = "50", value_parser = parse_percent)]
        min_valid: f64,
        /// The nesting index λc of the texture's Gaussian filter, with its
        /// unit (`0.08mm`, `250um`).
        #[arg(long, value_name = "LENGTH", default_value = "0.08mm", value_parser = parse_length)]
        cutoff: f64,
        /// Use the file's own x and y instead of centring the measurement
        /// on its middle.
        #[arg(long)]
        keep_origin: bool,
        /// Also register each lenslet of the job's array on its own (a
        /// map of an array): each lenslet's piston, tilt and decentre,
        /// its error PV and RMS and its texture, in the report's
        /// `lenslets`; a lenslet the mask leaves too little of is a
        /// finding (W0036), not an error.
        #[arg(long, conflicts_with = "lenslet")]
        per_lenslet: bool,
        /// The map is one lenslet's field (an instrument's field of view):
        /// hold it to that lenslet's design alone. LENSLET is its index in
        /// the array as the reports number them (`23`: from 0, row by row
        /// from the least y, along each row from the least x), or its row
        /// and column (`2,3`: each from 0, in that order). The map's middle pixel (the file's
        /// origin with --keep-origin) is taken to lie on the lenslet's
        /// centre unless --at says where it lay.
        #[arg(long, value_name = "LENSLET", value_parser = parse_lenslet)]
        lenslet: Option<LensletPick>,
        /// With --lenslet: where the map's middle pixel (the file's origin
        /// with --keep-origin) lay on the part, in the job's x and y, each
        /// with its unit (`1.75mm,-1.75mm`); the registration finds the
        /// field's place from there.
        #[arg(long, value_name = "X,Y", requires = "lenslet", allow_hyphen_values = true, value_parser = parse_point)]
        at: Option<(f64, f64)>,
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
    /// as you type (and what lowering the jobs finds, after a pause),
    /// hover, completion, go to definition, references, rename, the
    /// outline, quick fixes and formatting (editors/README.md says how to
    /// set one up).
    Lsp,
}

/// How `list` and `explain` print.
#[derive(Clone, Copy, ValueEnum, PartialEq)]
pub enum Format {
    Human,
    Json,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
pub enum MessageFormat {
    Human,
    Json,
}

/// What `verify` does with a finding of lensc's own policy.
#[derive(Clone, Copy, ValueEnum, PartialEq)]
pub enum PolicyChoice {
    Fail,
    Warn,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum AcceptChoice {
    Error,
    Warn,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum ColorChoice {
    Auto,
    Always,
    Never,
}

/// The categories `lensc list` knows, with the kinds each holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Listed {
    Machines,
    Tools,
    Dialects,
    Strategies,
    /// Surfaces, with the apertures and rollers they are made with.
    Surfaces,
}

impl Listed {
    pub const ALL: [Listed; 5] = [
        Listed::Machines,
        Listed::Tools,
        Listed::Dialects,
        Listed::Strategies,
        Listed::Surfaces,
    ];
    pub fn name(self) -> &'static str {
        match self {
            Listed::Machines => "machines",
            Listed::Tools => "tools",
            Listed::Dialects => "dialects",
            Listed::Strategies => "strategies",
            Listed::Surfaces => "surfaces",
        }
    }
    pub fn holds(self, c: Category) -> bool {
        match self {
            Listed::Machines => c == Category::Machine,
            Listed::Tools => c == Category::Tool,
            Listed::Dialects => c == Category::Dialect,
            Listed::Strategies => c == Category::Strategy,
            Listed::Surfaces => {
                matches!(c, Category::Surface | Category::Aperture | Category::Roller)
            }
        }
    }
}

/// A size in bytes: a whole number, optionally with a decimal (`kB`, `MB`,
/// `GB`, `TB`) or binary (`KiB`, `MiB`, `GiB`, `TiB`) unit.
/// The units of a plain-text measurement's numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TextUnit {
    M,
    Mm,
    Um,
    Nm,
}

impl TextUnit {
    /// Millimetres per unit.
    pub fn mm(self) -> f64 {
        match self {
            TextUnit::M => 1000.0,
            TextUnit::Mm => 1.0,
            TextUnit::Um => 1e-3,
            TextUnit::Nm => 1e-6,
        }
    }
}

/// A share in percent, 0 to 100.
pub fn parse_percent(text: &str) -> Result<f64, String> {
    match text.trim().trim_end_matches('%').parse::<f64>() {
        Ok(v) if (0.0..=100.0).contains(&v) => Ok(v),
        _ => Err(format!("`{text}` is not a percentage from 0 to 100")),
    }
}

/// A lenslet of an array: `7` (its index) or `3,5` (its row and column),
/// each from 0.
pub fn parse_lenslet(text: &str) -> Result<LensletPick, String> {
    let whole = |t: &str| t.trim().parse::<usize>().ok();
    let bad = || {
        format!(
            "`{text}` is not a lenslet: write its index (`7`) or its row and column (`3,5`), each from 0"
        )
    };
    match text.split_once(',') {
        None => whole(text).map(LensletPick::Index).ok_or_else(bad),
        Some((r, c)) => match (whole(r), whole(c)) {
            (Some(r), Some(c)) => Ok(LensletPick::RowColumn(r, c)),
            _ => Err(bad()),
        },
    }
}

/// A point on the part: two lengths with their units, `X,Y`, in mm.
pub fn parse_point(text: &str) -> Result<(f64, f64), String> {
    let Some((x, y)) = text.split_once(',') else {
        return Err(format!(
            "`{text}` is not a point: write its x and y with their units (`1.75mm,-1.75mm`)"
        ));
    };
    Ok((signed_length(x)?, signed_length(y)?))
}

/// A length with its unit (`0.08mm`, `80um`, `80 µm`), in mm.
pub fn parse_length(text: &str) -> Result<f64, String> {
    let mm = signed_length(text)?;
    if mm > 0.0 {
        Ok(mm)
    } else {
        Err(format!("`{text}` is not a positive length"))
    }
}

/// A finite length of either sign with its unit, in mm.
fn signed_length(text: &str) -> Result<f64, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == '-' || c == '+'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let v: f64 = number
        .parse()
        .map_err(|_| format!("`{text}` is not a length (write `0.08mm` or `80um`)"))?;
    let scale = match unit.trim() {
        "mm" => 1.0,
        "um" | "µm" => 1e-3,
        "nm" => 1e-6,
        "m" => 1000.0,
        "" => {
            return Err(format!(
                "`{text}` has no unit: write `{text}mm` or `{text}um`"
            ));
        }
        u => return Err(format!("`{u}` is not a unit of length (mm, um, nm, m)")),
    };
    let mm = v * scale;
    if mm.is_finite() {
        Ok(mm)
    } else {
        Err(format!("`{text}` is not a finite length"))
    }
}

pub fn parse_size(text: &str) -> Result<u64, String> {
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
