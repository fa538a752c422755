//! `lensc view`'s page: one self-contained HTML file per job that opens
//! offline — the program's backplot in 3-D (`backplot`: the moves the
//! controller reads from the program as written, thinned for drawing and
//! saying so), the simulated form error over the whole part drawn on the
//! design surface, the acceptance figures and the set-up, every number
//! taken from the build's report and set-up sheet. The page's script and
//! style are ours (`page.js`, `page.css`), inlined: a canvas renderer with
//! no library and no network.

pub mod backplot;

use serde::Serialize;
use serde_json::{Value, json};

use crate::output::{Built, ProgramText};
use crate::plots::{FormErrorSeries, ProfileSeries};
use lensc_runtime::surface::ir::SurfaceFn;

pub use backplot::Backplot;

/// The file name of a job's page.
pub fn file_name(job: &str) -> String {
    format!("{job}.view.html")
}

/// Radii a profile's error is drawn on, revolved.
pub const PROFILE_RINGS: usize = 200;

const SCRIPT: &str = include_str!("page.js");
const STYLE: &str = include_str!("page.css");

/// The page of `built` with its backplot; `design` evaluates the design
/// surface (the heights the error map is drawn on), if it can be.
pub fn page(built: &Built, path: &Backplot, design: Option<&dyn SurfaceFn>) -> String {
    let data = json!({
        "job": built.report.job,
        "source": built.report.source,
        "program": {
            "file": built.report.program.file,
            "dialect": built.report.program.dialect,
            "lines": built.report.program.lines,
        },
        "figures": figures(built),
        "setup": setup_rows(built),
        "path": path_data(path, lathe(built)),
        "map": map_data(built, design),
    });
    // `</` inside a script element would end it: JSON may carry any text.
    let data = data.to_string().replace("</", "<\\/");
    let title = escape(&format!(
        "{}: toolpath and simulated part",
        built.report.job
    ));
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{title}</title>\n<style>\n{STYLE}</style>\n</head>\n<body>\n{BODY}\n<script type=\"application/json\" id=\"lensc-data\">{data}</script>\n<script>\n{SCRIPT}</script>\n</body>\n</html>\n"
    )
}

const BODY: &str = r#"<header><h1 id="title"></h1><p id="subtitle"></p></header>
<main>
<section id="scene">
<canvas id="view" width="900" height="640" aria-label="3-D view of the toolpath and the simulated part"></canvas>
<div id="controls">
<label>pass <input type="range" id="pass" min="0" value="0"> <span id="pass-label"></span></label>
<label>moves shown <input type="range" id="upto" min="0" value="0"> <span id="upto-label"></span></label>
<label>Z scale <input type="range" id="zscale" min="0" max="20" value="0"> <span id="zscale-label"></span></label>
<label><input type="checkbox" id="show-path" checked> toolpath</label>
<label><input type="checkbox" id="show-map" checked> error map</label>
<button id="reset" type="button">reset view</button>
</div>
<p class="hint">Drag to turn, shift-drag (or right-drag) to pan, wheel to zoom.</p>
<div id="legend"></div>
<p id="thinning"></p>
</section>
<aside>
<h2>Acceptance</h2>
<p id="verdict"></p>
<table id="criteria"><thead><tr><th>criterion</th><th>measured</th><th>limit</th><th></th></tr></thead><tbody></tbody></table>
<p id="judged"></p>
<h2>Set-up</h2>
<table id="setup"><tbody></tbody></table>
<h2>Error map</h2>
<canvas id="scale" width="300" height="54"></canvas>
<p id="map-note"></p>
</aside>
</main>
<pre id="lensc-status" hidden></pre>"#;

fn lathe(built: &Built) -> bool {
    built.read_back.as_ref().is_some_and(|r| r.machine.lathe)
}

/// The acceptance figures as the report gives them, with the cutting time.
fn figures(built: &Built) -> Value {
    let a = &built.report.acceptance;
    let report = built.report.to_json();
    json!({
        "mode": report["acceptance"]["mode"],
        "passed": a.passed,
        "judged": a.judged.words,
        "judged_area": report["acceptance"]["judged"]["area"],
        "criteria": report["acceptance"]["criteria"],
        "cutting_time_s": report["toolpath"]["cutting_time_s"],
    })
}

/// The set-up sheet's rows a machinist sets the machine up by (label,
/// text), as the build wrote them beside the program.
fn setup_rows(built: &Built) -> Vec<(String, String)> {
    const WANTED: [&str; 8] = [
        "machine",
        "work offset",
        "tool",
        "control point",
        "offsets to",
        "from centre",
        "spindle",
        "cycle time",
    ];
    let sheet = built.beside.iter().find_map(|(name, text)| match text {
        ProgramText::Memory(t) if name.ends_with(crate::setup_sheet::EXTENSION) => Some(t),
        _ => None,
    });
    let Some(sheet) = sheet else {
        return Vec::new();
    };
    // Rows are `label` padded to 15 columns, then the text; a row's text
    // may go on over indented lines.
    let mut rows: Vec<(String, String)> = Vec::new();
    let mut current: Option<usize> = None;
    for line in sheet.lines() {
        if line.trim().is_empty() {
            current = None;
            continue;
        }
        let (label, text) = match line.char_indices().nth(15) {
            Some((i, _)) => (line[..i].trim(), line[i..].trim()),
            None => (line.trim(), ""),
        };
        if label.is_empty() {
            if let Some(k) = current {
                rows[k].1.push(' ');
                rows[k].1.push_str(text);
            }
            continue;
        }
        current = None;
        if WANTED.contains(&label) {
            rows.push((label.to_string(), text.to_string()));
            current = Some(rows.len() - 1);
        }
    }
    rows
}

/// The backplot as the page reads it: points quantised to 16 bits per
/// axis over their bounds, what reaches each, the passes, the counts.
fn path_data(p: &Backplot, lathe: bool) -> Value {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for q in &p.points {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let mut bytes = Vec::with_capacity(p.points.len() * 6);
    for q in &p.points {
        for k in 0..3 {
            let span = hi[k] - lo[k];
            let t = if span > 0.0 {
                (q[k] - lo[k]) / span
            } else {
                0.0
            };
            let v = (t * 65535.0).round().clamp(0.0, 65535.0) as u16;
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    let reached: Vec<u8> = p.reached.iter().map(|r| *r as u8).collect();
    if p.points.is_empty() {
        (lo, hi) = ([0.0; 3], [0.0; 3]);
    }
    json!({
        "lathe": lathe,
        "lo": lo,
        "hi": hi,
        "points": base64(&bytes),
        "reached": base64(&reached),
        "passes": p.passes,
        "rapids": p.rapids,
        "feeds": p.feeds,
        "step_mm": p.step,
        "revolution_stride": p.revolution_stride,
        "truncated": p.truncated,
        "segments": p.segments(),
    })
}

/// The error map the page draws on the design surface.
#[derive(Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
enum Map {
    /// A profile's error revolved about the spindle: per ring, its
    /// radius, the design's height and the error of largest magnitude
    /// (nm) among the samples it stands for.
    Revolved {
        radii: Vec<f64>,
        design: Vec<f64>,
        error_nm: Vec<f64>,
        samples: usize,
    },
    /// A height map's blocks: the error (nm, null where no cut cell
    /// falls), the design's height at each block's centre.
    Blocks {
        x0: f64,
        y0: f64,
        block: f64,
        nx: usize,
        ny: usize,
        /// Base64 of little-endian f32s, NaN where there is none.
        error_nm: String,
        design: String,
        /// Base64 of one byte per block: 1 where it holds a cell of the
        /// part the program leaves uncut (drawn as uncut).
        uncut: String,
        uncut_blocks: usize,
        x_axis: &'static str,
        y_axis: &'static str,
        flat: bool,
    },
    None {
        why: &'static str,
    },
}

fn map_data(built: &Built, design: Option<&dyn SurfaceFn>) -> Map {
    let roller = matches!(
        built.report.toolpath,
        crate::report::Toolpath::RollerHelix(_)
    );
    if let Some(p) = &built.plots.profile {
        return revolved(p);
    }
    if let Some(f) = &built.plots.form_error {
        return blocks(f, if roller { None } else { design });
    }
    Map::None {
        why: "the simulation kept no error map for this job",
    }
}

fn revolved(p: &ProfileSeries) -> Map {
    let n = p.samples.len();
    let run = n.div_ceil(PROFILE_RINGS).max(1);
    let mut radii = Vec::new();
    let mut design = Vec::new();
    let mut error_nm = Vec::new();
    for chunk in p.samples.chunks(run) {
        let worst =
            chunk
                .iter()
                .filter(|s| s.2.is_finite())
                .map(|s| s.2)
                .fold(f64::NAN, |w: f64, e| {
                    if w.is_nan() || e.abs() > w.abs() {
                        e
                    } else {
                        w
                    }
                });
        let mid = chunk[chunk.len() / 2];
        radii.push(mid.0.abs());
        design.push(mid.1);
        error_nm.push(worst * 1e6);
    }
    Map::Revolved {
        radii,
        design,
        error_nm: error_nm
            .into_iter()
            .map(|e| if e.is_finite() { e } else { 0.0 })
            .collect(),
        samples: n,
    }
}

fn blocks(f: &FormErrorSeries, design: Option<&dyn SurfaceFn>) -> Map {
    let r = &f.raster;
    let centre = |i: usize| {
        let (bx, by) = (i % r.nx, i / r.nx);
        (
            r.x.0 + (bx as f64 + 0.5) * r.block,
            r.y.0 + (by as f64 + 0.5) * r.block,
        )
    };
    let heights: Vec<f32> = match design {
        Some(d) => {
            let (xs, ys): (Vec<f64>, Vec<f64>) = (0..r.cells.len()).map(centre).unzip();
            let mut out = vec![0.0; 6 * xs.len()];
            d.eval_batch(&xs, &ys, &mut out);
            (0..xs.len())
                .map(|i| {
                    let z = out[6 * i];
                    if z.is_finite() && (!r.cells[i].is_nan() || r.uncut[i]) {
                        z as f32
                    } else {
                        f32::NAN
                    }
                })
                .collect()
        }
        None => vec![f32::NAN; r.cells.len()],
    };
    let errors: Vec<f32> = r.cells.iter().map(|e| (e * 1e6) as f32).collect();
    Map::Blocks {
        x0: r.x.0,
        y0: r.y.0,
        block: r.block,
        nx: r.nx,
        ny: r.ny,
        error_nm: f32s(&errors),
        design: f32s(&heights),
        uncut: base64(&r.uncut.iter().map(|&u| u8::from(u)).collect::<Vec<u8>>()),
        uncut_blocks: r.uncut.iter().filter(|u| **u).count(),
        x_axis: f.x_axis,
        y_axis: f.y_axis,
        flat: design.is_none(),
    }
}

/// Base64 of `values` as little-endian f32s.
fn f32s(values: &[f32]) -> String {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    base64(&bytes)
}

/// Standard base64 (RFC 4648, with padding).
pub fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                s.push(ABC[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// `text` safe in HTML text and attributes.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_is_rfc_4648() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
        assert_eq!(base64(&[0xff, 0xfe]), "//4=");
    }
}
