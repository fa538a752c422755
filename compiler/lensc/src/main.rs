//! The `lensc` command line: `check`, `build`, `report`, `analyse`,
//! `sample`, `fmt`, `list`, `explain`, `import` and `lsp` (a language server). Exit codes: 0 success (warnings allowed), 1 errors in the
//! input, 2 usage errors, 101 an internal error, 130 and 143 a `build` or
//! `report` stopped by SIGINT or SIGTERM. The arguments are defined in the
//! library (`lensc::cli`), so the book's CLI page is rendered from them.

use std::io::IsTerminal;
use std::process::ExitCode;

use clap::Parser;
use lensc::cli::{AcceptChoice, Cli, ColorChoice, Command, Format, MessageFormat};

mod commands;
mod interrupt;
mod lsp;
mod output;
mod progress;

use lensc_build::driver;
use output::Output;

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Deep but valid input is bounded by the parser's nesting limit; a large
    // stack keeps the recursive checker far from the edge all the same.
    let worker = std::thread::Builder::new()
        .stack_size(256 << 20)
        .spawn(move || run(cli));
    match worker.map(|h| h.join()) {
        Ok(Ok(code)) => ExitCode::from(interrupt::stopped_status().unwrap_or(code)),
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
            policy,
            source,
        } => commands::verify::run(
            &out,
            &program,
            commands::verify::Asked {
                machine: machine.as_deref(),
                dialect: dialect.as_deref(),
                policy_fails: policy == lensc::cli::PolicyChoice::Fail,
                source: source.as_deref(),
            },
        ),
        Command::Fmt { files, check } => commands::fmt::run(&out, &files, check),
        Command::Import { file, output } => commands::import::run(&out, &file, output.as_deref()),
        Command::Measure {
            file,
            part,
            job,
            out: dir,
            units,
            min_valid,
            cutoff,
            keep_origin,
            per_lenslet,
            lenslet,
            at,
        } => commands::measure::run(
            &out,
            (&file, &part),
            job.as_deref(),
            &dir,
            lensc_build::measure::Options {
                units: lensc_measure::read::TextUnits(units.mm()),
                min_valid: min_valid / 100.0,
                cutoff,
                keep_origin,
                from_job: false,
                per_lenslet,
                lenslet,
                at,
            },
        ),

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
            dialect,
            out: dir,
            max_program_size,
            quiet,
        } => commands::report::run(
            &out,
            &file,
            (job.as_deref(), dialect.as_deref()),
            &dir,
            max_program_size,
            quiet,
        ),
        Command::View {
            file,
            job,
            dialect,
            out: dir,
            max_program_size,
            quiet,
        } => commands::view::run(
            &out,
            &file,
            (job.as_deref(), dialect.as_deref()),
            &dir,
            max_program_size,
            quiet,
        ),
        Command::Build {
            file,
            job,
            dialect,
            out: dir,
            max_program_size,
            accept,
            keep_going,
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
            keep_going,
        ),
    }
}
