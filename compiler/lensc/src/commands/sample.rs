//! `lensc sample`: evaluate a surface at points, as CSV on stdout.

use std::io::Write;
use std::path::Path;

use lensc_build::driver;
use lensc_lang::loader::plain_io_error;

use crate::output::{Output, load};

/// Runs the subcommand; returns the exit code.
pub fn run(
    out: &Output,
    file: &Path,
    surface: &str,
    grid: Option<usize>,
    radial: Option<usize>,
    points: Option<std::path::PathBuf>,
) -> u8 {
    let Some(c) = load(out, file) else { return 1 };
    // A surface with no value over part of its aperture is a warning
    // here (W0022; `check` and `build` refuse it): its points are NaN.
    let mut diags = c.diags().to_vec();
    if !c.has_errors() {
        diags.extend(lensc_build::evaluate::undefined_surfaces(
            &c,
            lensc_grammar::Severity::Warning,
            Some(surface),
        ));
    }
    out.diagnostics(&c, &diags);
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
    match driver::sample(&c, surface, &at) {
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
