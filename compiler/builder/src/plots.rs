//! The plots of `lensc report`: what a job's program will cut, drawn as
//! SVG with plotters from the series the build's simulations keep — a
//! profile's design, nose-centre path and simulated cut with the form
//! error beneath, a height map's form error as a colour map with its
//! scale, a fast tool servo's following error along the radius.

use lensc_runtime::verify::follow::RadialBins;
use lensc_runtime::verify::heightmap::ErrorRaster;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// Radii sampled by a profile's cut simulation.
pub const PROFILE_SAMPLES: usize = 20_001;

/// A profile's simulated cut as the series of its plot: the design and
/// the error at every simulated radius, the tool centre's path as printed
/// (the cutting moves of `stream`), the seams' radii. `tool` names the
/// tool ("nose", "wheel") and gives its radius (mm).
pub fn profile_series(
    cut: &lensc_runtime::verify::simulate::ProfileCut,
    design: &dyn Fn(f64) -> f64,
    stream: &[lensc_runtime::moves::Move],
    tool: (&'static str, f64),
    resolution: f64,
    seams: Vec<f64>,
) -> ProfileSeries {
    ProfileSeries {
        tool: tool.0,
        tool_radius: tool.1,
        samples: cut
            .samples
            .iter()
            .map(|&(x, e)| (x, design(x), e))
            .collect(),
        centre_path: lensc_runtime::verify::simulate::centre_path(stream, resolution),
        seams,
        pv: cut.pv,
        rms: cut.rms,
    }
}

/// The series behind a job's plots, kept by its build (each bounded in
/// size whatever the job: see the constants below).
#[derive(Clone, Debug, Default)]
pub struct PlotSeries {
    pub profile: Option<ProfileSeries>,
    pub form_error: Option<FormErrorSeries>,
    pub following: Option<FollowingSeries>,
}

/// A profile job's simulated cut against its design.
#[derive(Clone, Debug)]
pub struct ProfileSeries {
    /// "nose" or "wheel", and its radius (mm).
    pub tool: &'static str,
    pub tool_radius: f64,
    /// Per simulated radius (mm): the design's height and the error, cut
    /// minus design (mm; positive where material is left).
    pub samples: Vec<(f64, f64, f64)>,
    /// The tool centre's path as printed, one polyline of (X, Z) per run
    /// of cutting moves (mm).
    pub centre_path: Vec<Vec<(f64, f64)>>,
    /// Radii (mm) of the concave corners the tool cannot reach into.
    pub seams: Vec<f64>,
    /// PV and RMS of the error (mm), as the report gives them.
    pub pv: f64,
    pub rms: f64,
}

/// A height-map job's form error over its simulation window.
#[derive(Clone, Debug)]
pub struct FormErrorSeries {
    pub raster: ErrorRaster,
    /// The window (mm) and the simulation grid's spacing (mm).
    pub window: ((f64, f64), (f64, f64)),
    pub spacing: f64,
    /// The axes' titles (with their units).
    pub x_axis: &'static str,
    pub y_axis: &'static str,
}

/// A fast-tool-servo job's following error.
#[derive(Clone, Debug)]
pub struct FollowingSeries {
    pub by_radius: RadialBins,
    pub samples: usize,
    pub data_rate_hz: f64,
    /// Largest |error| (mm) and where (radius, mm).
    pub max_error: (f64, f64),
}

/// Samples of a profile's simulation drawn as at most this many points
/// per curve (each consecutive run of samples by its least and largest).
pub const PROFILE_POINTS: usize = 2000;
/// Bins of radius for a fast tool servo's following error.
pub const FOLLOWING_BINS: usize = 1000;
/// The most blocks along either side of a form-error map.
pub const RASTER_SIDE: usize = 300;
/// Colour levels of a form-error map (and steps of its scale).
pub const COLOUR_LEVELS: usize = 64;

/// Keeps at most `max_points` of a series (in order), honestly: the
/// points are taken in consecutive runs of equal length and each run is
/// drawn by its lowest and its highest point (its first and last when it
/// is level), so every peak and valley survives. Returns the points and
/// the run length (1 when nothing was dropped).
pub fn decimate(points: &[(f64, f64)], max_points: usize) -> (Vec<(f64, f64)>, usize) {
    let pairs = (max_points / 2).max(1);
    if points.len() <= max_points.max(2) {
        return (points.to_vec(), 1);
    }
    let run = points.len().div_ceil(pairs);
    let mut out = Vec::with_capacity(2 * pairs);
    for chunk in points.chunks(run) {
        let (mut lo, mut hi) = (0, 0);
        for (i, p) in chunk.iter().enumerate() {
            if p.1 < chunk[lo].1 {
                lo = i;
            }
            if p.1 > chunk[hi].1 {
                hi = i;
            }
        }
        if lo == hi {
            (lo, hi) = (0, chunk.len() - 1);
        }
        if lo == hi {
            out.push(chunk[lo]);
        } else {
            out.push(chunk[lo.min(hi)]);
            out.push(chunk[lo.max(hi)]);
        }
    }
    (out, run)
}

/// The SVG files of a job's plots: name and text.
pub fn render(job: &str, series: &PlotSeries) -> Result<Vec<(String, String)>, String> {
    let mut out = Vec::new();
    if let Some(p) = &series.profile {
        out.push((format!("{job}.profile.svg"), profile_svg(job, p)?));
    }
    if let Some(f) = &series.form_error {
        out.push((format!("{job}.form_error.svg"), form_error_svg(job, f)?));
    }
    if let Some(f) = &series.following {
        out.push((format!("{job}.following.svg"), following_svg(job, f)?));
    }
    Ok(out)
}

const FONT: &str = "sans-serif";
const WIDTH: u32 = 1000;
/// Pixels of caption text per character, for wrapping (14 px type).
const CAPTION_CHAR: f64 = 7.0;

fn err<E: std::fmt::Display>(e: E) -> String {
    format!("cannot draw the plot: {e}")
}

/// A number with `d` decimals and no minus sign on zero.
fn num(v: f64, d: usize) -> String {
    let s = format!("{v:.d$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

/// Decimals enough to show `v` to about three significant figures.
fn decimals(v: f64) -> usize {
    let v = v.abs();
    if v.is_nan() || v == 0.0 || v >= 100.0 {
        0
    } else {
        (2.0 - v.log10().floor()).clamp(0.0, 6.0) as usize
    }
}

/// Tick labels for an axis over `lo..hi`: as many decimals as a tenth
/// of the range needs.
fn ticks(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let step = ((hi - lo) / 10.0).abs();
    let d = if step > 0.0 && step.is_finite() {
        (-step.log10().floor()).clamp(0.0, 6.0) as usize
    } else {
        0
    };
    move |v: &f64| num(*v, d)
}

/// Splits `text` into lines of at most `width` pixels of caption type.
fn wrap(text: &str, width: f64) -> Vec<String> {
    let per_line = (width / CAPTION_CHAR).max(20.0) as usize;
    let mut lines = Vec::new();
    for para in text.split('\n') {
        let mut line = String::new();
        for word in para.split_whitespace() {
            if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > per_line {
                lines.push(std::mem::take(&mut line));
            }
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(word);
        }
        lines.push(line);
    }
    lines
}

/// Writes the caption lines at the top of `area`.
fn caption<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    lines: &[String],
) -> Result<(), String> {
    let style = TextStyle::from((FONT, 14).into_font()).color(&BLACK);
    for (k, line) in lines.iter().enumerate() {
        area.draw_text(line, &style, (20, 6 + 18 * k as i32))
            .map_err(err)?;
    }
    Ok(())
}

/// A region of an SVG page.
type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// Splits a page into the title strip, the plot and the caption strip
/// (sized for `caption_lines`).
fn page<'a>(
    root: &Area<'a>,
    title: &str,
    caption_lines: usize,
) -> Result<(Area<'a>, Area<'a>), String> {
    root.fill(&WHITE).map_err(err)?;
    let body = root
        .titled(title, (FONT, 22).into_font().style(FontStyle::Bold))
        .map_err(err)?;
    let (_, h) = body.dim_in_pixel();
    let cap = 14 + 18 * caption_lines as u32;
    let (plot, below) = body.split_vertically(h.saturating_sub(cap));
    Ok((plot, below))
}

/// A range padded by 5 % below and `top` (a share of the range) above,
/// room for the legend (and widened if empty).
fn padded(lo: f64, hi: f64, top: f64) -> (f64, f64) {
    let (lo, hi) = if hi > lo {
        (lo, hi)
    } else {
        let w = lo.abs().max(1e-6) * 0.5;
        (lo - w, hi + w)
    };
    let pad = hi - lo;
    (lo - 0.05 * pad, hi + top * pad)
}

fn range_of(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
}

const DESIGN: RGBColor = RGBColor(0, 0, 0);
const CUT: RGBColor = RGBColor(214, 39, 40);
const CENTRE: RGBColor = RGBColor(31, 119, 180);
const SEAM: RGBColor = RGBColor(255, 127, 14);
const ERROR: RGBColor = RGBColor(44, 160, 44);

fn legend_line(c: RGBColor) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(2))
}

/// Draws a chart's legend box, the same on every plot: upper right, on a
/// translucent white ground with a black border.
fn legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 14))
        .draw()
        .map_err(err)
}

/// Draws a chart's mesh and axes, the same on every plot: each axis's
/// description and its ticks over the range shown.
fn draw_axes(
    chart: &mut ChartContext<'_, SVGBackend<'_>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    (x_desc, (x0, x1)): (&str, (f64, f64)),
    (y_desc, (y0, y1)): (&str, (f64, f64)),
) -> Result<(), String> {
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&ticks(x0, x1))
        .y_label_formatter(&ticks(y0, y1))
        .axis_desc_style((FONT, 16))
        .label_style((FONT, 13))
        .draw()
        .map_err(err)
}

/// A profile's series thinned for drawing, with the ranges of its axes.
struct ProfileView {
    design: Vec<(f64, f64)>,
    cut: Vec<(f64, f64)>,
    error_nm: Vec<(f64, f64)>,
    /// How many consecutive samples each drawn error point stands for.
    run: usize,
    path: Vec<Vec<(f64, f64)>>,
    /// Radius, height, the centre path's height (right axis) and error.
    r: (f64, f64),
    z: (f64, f64),
    centre_z: (f64, f64),
    e: (f64, f64),
}

impl ProfileView {
    fn of(p: &ProfileSeries) -> Result<ProfileView, String> {
        let design: Vec<(f64, f64)> = p.samples.iter().map(|s| (s.0, s.1)).collect();
        let cut: Vec<(f64, f64)> = p.samples.iter().map(|s| (s.0, s.1 + s.2)).collect();
        let error_nm: Vec<(f64, f64)> = p.samples.iter().map(|s| (s.0, s.2 * 1e6)).collect();
        let (design, _) = decimate(&design, PROFILE_POINTS);
        let (cut, _) = decimate(&cut, PROFILE_POINTS);
        let (error_nm, run) = decimate(&error_nm, PROFILE_POINTS);
        let path: Vec<Vec<(f64, f64)>> = p
            .centre_path
            .iter()
            .map(|r| {
                let abs: Vec<(f64, f64)> = r.iter().map(|q| (q.0.abs(), q.1)).collect();
                decimate(&abs, PROFILE_POINTS).0
            })
            .collect();
        let (r0, r1) = range_of(p.samples.iter().map(|s| s.0));
        let (z0, z1) = range_of(p.samples.iter().flat_map(|s| [s.1, s.1 + s.2]));
        // The path's own scale (right axis): where it runs over the simulated
        // radii, up to the tool radius above the design's top (an approach or
        // retract from higher leaves the top of the plot).
        let ceiling = z1 + 1.05 * p.tool_radius;
        let (c0, c1) = range_of(
            path.iter()
                .flatten()
                .filter(|q| q.0 >= r0 && q.0 <= r1 && q.1 <= ceiling)
                .map(|q| q.1),
        );
        let centre_z = if c1 >= c0 {
            padded(c0, c1, 0.3)
        } else {
            padded(z0, z1, 0.3)
        };
        let (e0, e1) = range_of(error_nm.iter().map(|e| e.1));
        if !(r1 >= r0 && z1 >= z0 && e1 >= e0) {
            return Err("the profile's simulation has no samples to plot".into());
        }
        Ok(ProfileView {
            design,
            cut,
            error_nm,
            run,
            path,
            r: (r0, r1),
            z: padded(z0, z1, 0.3),
            centre_z,
            e: padded(e0.min(0.0), e1.max(0.0), 0.25),
        })
    }
}

/// The caption under a profile plot: what each curve is, and the figures.
fn profile_caption(p: &ProfileSeries, run: usize) -> String {
    let thinned = if run > 1 {
        format!(
            "The {} samples are drawn in runs of {run} consecutive ones, each by its least and largest value, so every peak is kept.",
            p.samples.len()
        )
    } else {
        format!("All {} samples are drawn.", p.samples.len())
    };
    let seams = if p.seams.is_empty() {
        String::new()
    } else {
        format!(
            " Dashed: the {} concave corner{} the {} cannot reach into (seams).",
            p.seams.len(),
            if p.seams.len() == 1 { "" } else { "s" },
            p.tool
        )
    };
    format!(
        "Upper: the design profile and the cut the program leaves (left axis): the exact envelope of the {tool} ({tool} radius {rho} mm) swept along the printed moves, simulated on {n} radii; it lies on the design wherever the form error below is too small to see at this scale. The {tool} centre's path as the program prints it, on its own scale (right axis). \
         Lower: the form error, cut − design, in nm (positive where material is left, negative a gouge): PV {pv} nm, RMS {rms} nm.{seams}\n{thinned}",
        tool = p.tool,
        rho = num(p.tool_radius, decimals(p.tool_radius)),
        n = p.samples.len(),
        pv = num(p.pv * 1e6, decimals(p.pv * 1e6)),
        rms = num(p.rms * 1e6, decimals(p.rms * 1e6)),
    )
}

fn profile_svg(job: &str, p: &ProfileSeries) -> Result<String, String> {
    let view = ProfileView::of(p)?;
    let lines = wrap(&profile_caption(p, view.run), f64::from(WIDTH) - 40.0);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, 900)).into_drawing_area();
        let (plot, below) = page(
            &root,
            &format!("{job}: profile, tool path and simulated cut"),
            lines.len(),
        )?;
        let (_, h) = plot.dim_in_pixel();
        let (upper, lower) = plot.split_vertically(h * 11 / 20);
        draw_profile_and_path(&upper, p, &view)?;
        draw_profile_error(&lower, p, &view)?;
        caption(&below, &lines)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// The upper half of a profile plot: design and cut (left axis), the
/// tool centre's path on its own scale (right axis).
fn draw_profile_and_path(area: &Area, p: &ProfileSeries, v: &ProfileView) -> Result<(), String> {
    let ((r0, r1), (z0, z1), (c0, c1)) = (v.r, v.z, v.centre_z);
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(45)
        .y_label_area_size(90)
        .right_y_label_area_size(90)
        .build_cartesian_2d(r0..r1, z0..z1)
        .map_err(err)?
        .set_secondary_coord(r0..r1, c0..c1);
    draw_axes(
        &mut chart,
        ("radius r (mm)", (r0, r1)),
        ("height z (mm)", (z0, z1)),
    )?;
    chart
        .configure_secondary_axes()
        .y_desc(format!("{} centre Z (mm)", p.tool))
        .y_label_formatter(&ticks(c0, c1))
        .axis_desc_style((FONT, 16).into_font().color(&CENTRE))
        .label_style((FONT, 13))
        .draw()
        .map_err(err)?;
    for (k, run) in v.path.iter().enumerate() {
        let drawn = chart
            .draw_secondary_series(LineSeries::new(run.iter().copied(), CENTRE.stroke_width(2)))
            .map_err(err)?;
        if k == 0 {
            drawn
                .label(format!("{} centre path, as printed (right axis)", p.tool))
                .legend(legend_line(CENTRE));
        }
    }
    chart
        .draw_series(LineSeries::new(
            v.design.iter().copied(),
            DESIGN.stroke_width(2),
        ))
        .map_err(err)?
        .label("design")
        .legend(legend_line(DESIGN));
    chart
        .draw_series(LineSeries::new(v.cut.iter().copied(), CUT.stroke_width(1)))
        .map_err(err)?
        .label("simulated cut")
        .legend(legend_line(CUT));
    legend(&mut chart)
}

/// The lower half of a profile plot: the form error in nm, seams dashed.
fn draw_profile_error(area: &Area, p: &ProfileSeries, v: &ProfileView) -> Result<(), String> {
    let ((r0, r1), (e0, e1)) = (v.r, v.e);
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .margin_right(100)
        .x_label_area_size(45)
        .y_label_area_size(90)
        .build_cartesian_2d(r0..r1, e0..e1)
        .map_err(err)?;
    draw_axes(
        &mut chart,
        ("radius r (mm)", (r0, r1)),
        ("form error, cut − design (nm)", (e0, e1)),
    )?;
    for (k, &r) in p.seams.iter().enumerate() {
        let drawn = chart
            .draw_series(DashedLineSeries::new(
                [(r, e0), (r, e1)],
                6,
                4,
                SEAM.stroke_width(1),
            ))
            .map_err(err)?;
        if k == 0 {
            drawn.label("seam").legend(legend_line(SEAM));
        }
    }
    chart
        .draw_series(LineSeries::new(
            v.error_nm.iter().copied(),
            ERROR.stroke_width(1),
        ))
        .map_err(err)?
        .label("form error")
        .legend(legend_line(ERROR));
    legend(&mut chart)
}

/// The colour of level `k` of `COLOUR_LEVELS` (viridis, low to high).
fn level_colour(k: usize) -> RGBColor {
    let t = (k as f64 + 0.5) / COLOUR_LEVELS as f64;
    ViridisRGB.get_color(t as f32)
}

/// The level of error `e` on the scale `lo..hi`.
fn level(e: f64, lo: f64, hi: f64) -> usize {
    let t = (e - lo) / (hi - lo) * COLOUR_LEVELS as f64;
    (t.floor().max(0.0) as usize).min(COLOUR_LEVELS - 1)
}

/// The caption under a form-error map: what it shows and its scale.
fn form_error_caption(f: &FormErrorSeries, lo: f64, hi: f64) -> String {
    let r = &f.raster;
    let cut_blocks = r.cells.iter().filter(|e| !e.is_nan()).count();
    let uncut_blocks = r.uncut.iter().filter(|u| **u).count();
    let uncut = if uncut_blocks == 0 {
        "Nothing of the part is left uncut.".to_string()
    } else {
        format!(
            "Grey: the {uncut_blocks} block{} holding a cell of the part the program leaves uncut (drawn as uncut whatever else they hold).",
            if uncut_blocks == 1 { "" } else { "s" }
        )
    };
    format!(
        "The form error of the simulated cut, cut − design, in nm (positive where material is left, negative a gouge) over the simulation window x {wx0} .. {wx1} mm, y {wy0} .. {wy1} mm (grid spacing {sp} µm). \
         Shown on {nx} × {ny} blocks {b} µm square; each block holds the error of largest magnitude (sign kept) among the grid cells in it, so every peak is kept. \
         White: no cell of the part (outside the window, the surface or its lenslets); {cut_blocks} blocks hold cut cells. {uncut} Colours in {levels} steps from {lo} to {hi} nm, the least and largest block values.",
        wx0 = num(f.window.0.0, 4),
        wx1 = num(f.window.0.1, 4),
        wy0 = num(f.window.1.0, 4),
        wy1 = num(f.window.1.1, 4),
        sp = num(f.spacing * 1000.0, decimals(f.spacing * 1000.0)),
        nx = r.nx,
        ny = r.ny,
        b = num(r.block * 1000.0, decimals(r.block * 1000.0)),
        levels = COLOUR_LEVELS,
        lo = num(lo * 1e6, decimals(lo * 1e6).max(1)),
        hi = num(hi * 1e6, decimals(hi * 1e6).max(1)),
    )
}

/// The map's blocks as rectangles: runs of equal level along each row of
/// blocks, one rectangle each.
fn level_runs(r: &ErrorRaster, lo_nm: f64, hi_nm: f64) -> Vec<Rectangle<(f64, f64)>> {
    let (x0, y0) = (r.x.0, r.y.0);
    let mut rects = Vec::new();
    for by in 0..r.ny {
        let row = &r.cells[by * r.nx..(by + 1) * r.nx];
        let mut bx = 0;
        while bx < r.nx {
            let uncut = &r.uncut[by * r.nx..(by + 1) * r.nx];
            let e = row[bx];
            // An uncut block is drawn as uncut (`uncut_runs`), whatever
            // else it holds.
            if e.is_nan() || uncut[bx] {
                bx += 1;
                continue;
            }
            let k = level(e * 1e6, lo_nm, hi_nm);
            let mut end = bx + 1;
            while end < r.nx
                && !row[end].is_nan()
                && !uncut[end]
                && level(row[end] * 1e6, lo_nm, hi_nm) == k
            {
                end += 1;
            }
            let yb = y0 + by as f64 * r.block;
            rects.push(Rectangle::new(
                [
                    (x0 + bx as f64 * r.block, yb),
                    (x0 + end as f64 * r.block, yb + r.block),
                ],
                level_colour(k).filled(),
            ));
            bx = end;
        }
    }
    rects
}

/// The colour of a block the program leaves uncut: a grey no level of
/// the viridis scale comes near.
const UNCUT: RGBColor = RGBColor(150, 150, 150);

/// The blocks holding an uncut cell of the part as rectangles, runs along
/// each row of blocks.
fn uncut_runs(r: &ErrorRaster) -> Vec<Rectangle<(f64, f64)>> {
    let mut rects = Vec::new();
    for by in 0..r.ny {
        let row = &r.uncut[by * r.nx..(by + 1) * r.nx];
        let mut bx = 0;
        while bx < r.nx {
            if !row[bx] {
                bx += 1;
                continue;
            }
            let mut end = bx + 1;
            while end < r.nx && row[end] {
                end += 1;
            }
            let yb = r.y.0 + by as f64 * r.block;
            rects.push(Rectangle::new(
                [
                    (r.x.0 + bx as f64 * r.block, yb),
                    (r.x.0 + end as f64 * r.block, yb + r.block),
                ],
                UNCUT.filled(),
            ));
            bx = end;
        }
    }
    rects
}

/// The colour scale beside a form-error map: every level, in nm.
fn draw_colour_scale(
    area: &Area,
    (lo_nm, hi_nm): (f64, f64),
    (margin, bottom): (u32, u32),
    desc: &str,
) -> Result<(), String> {
    let mut bar = ChartBuilder::on(area)
        .margin(margin)
        .margin_left(0)
        .x_label_area_size(bottom)
        .y_label_area_size(90)
        .build_cartesian_2d(0.0..1.0, lo_nm..hi_nm)
        .map_err(err)?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(desc)
        .y_label_formatter(&ticks(lo_nm, hi_nm))
        .axis_desc_style((FONT, 16))
        .label_style((FONT, 13))
        .y_labels(8)
        .draw()
        .map_err(err)?;
    let step = (hi_nm - lo_nm) / COLOUR_LEVELS as f64;
    bar.draw_series((0..COLOUR_LEVELS).map(|k| {
        Rectangle::new(
            [
                (0.0, lo_nm + k as f64 * step),
                (1.0, lo_nm + (k + 1) as f64 * step),
            ],
            level_colour(k).filled(),
        )
    }))
    .map_err(err)?;
    Ok(())
}

fn form_error_svg(job: &str, f: &FormErrorSeries) -> Result<String, String> {
    let r = &f.raster;
    let Some((lo, hi)) = r.range() else {
        return Err("the height map has no cut cell in its window".into());
    };
    let text = form_error_caption(f, lo, hi);
    error_map_svg(
        &format!("{job}: form error over the simulation window"),
        &text,
        r,
        (f.x_axis, f.y_axis),
        "form error, cut − design (nm)",
    )
}

/// A measured part's error map (`lensc measure`): the blocks of the
/// raster in colour, with `caption` under it.
pub fn measured_error_svg(title: &str, caption: &str, r: &ErrorRaster) -> Result<String, String> {
    error_map_svg(
        title,
        caption,
        r,
        ("x (mm)", "y (mm)"),
        "error along the normal, measured − design (nm)",
    )
}

/// An error raster drawn to scale with its colour scale and caption.
fn error_map_svg(
    title: &str,
    text: &str,
    r: &ErrorRaster,
    (x_axis, y_axis): (&str, &str),
    scale: &str,
) -> Result<String, String> {
    let Some((lo, hi)) = r.range() else {
        return Err("the map has no cell to draw".into());
    };
    let (lo_nm, hi_nm) = if hi > lo {
        (lo * 1e6, hi * 1e6)
    } else {
        (lo * 1e6 - 0.5, hi * 1e6 + 0.5)
    };
    let (w, h) = (r.nx as f64 * r.block, r.ny as f64 * r.block);
    let (x0, y0) = (r.x.0, r.y.0);
    let lines = wrap(text, f64::from(WIDTH) - 40.0);
    // The map's plotting area keeps the window's aspect (axes to scale).
    let side = 600.0;
    let (pw, ph) = if w >= h {
        (side, (side * h / w).max(60.0))
    } else {
        ((side * w / h).max(60.0), side)
    };
    let (left, bottom, margin) = (90u32, 50u32, 15u32);
    let map_w = left + 2 * margin + pw.round() as u32;
    let map_h = bottom + 2 * margin + ph.round() as u32;
    let height = 45 + map_h + 20 + 14 + 18 * lines.len() as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, height)).into_drawing_area();
        let (plot, below) = page(&root, title, lines.len())?;
        let map_area = plot.clone().shrink((0, 0), (map_w, map_h));
        let mut chart = ChartBuilder::on(&map_area)
            .margin(margin)
            .x_label_area_size(bottom)
            .y_label_area_size(left)
            .build_cartesian_2d(x0..x0 + w, y0..y0 + h)
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(x_axis)
            .y_desc(y_axis)
            .x_label_formatter(&ticks(x0, x0 + w))
            .y_label_formatter(&ticks(y0, y0 + h))
            .axis_desc_style((FONT, 16))
            .label_style((FONT, 13))
            .x_labels(6)
            .y_labels(6)
            .draw()
            .map_err(err)?;
        chart
            .draw_series(level_runs(r, lo_nm, hi_nm))
            .map_err(err)?;
        let uncut = uncut_runs(r);
        if !uncut.is_empty() {
            chart
                .draw_series(uncut)
                .map_err(err)?
                .label("uncut: a cell of the part the program does not cut")
                .legend(|(x, y)| Rectangle::new([(x, y - 6), (x + 24, y + 6)], UNCUT.filled()));
            legend(&mut chart)?;
        }
        // The scale: every level, labelled in nm.
        let bar_area = plot.clone().shrink((map_w + 10, 0), (170u32, map_h));
        draw_colour_scale(&bar_area, (lo_nm, hi_nm), (margin, bottom), scale)?;
        caption(&below, &lines)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

fn following_svg(job: &str, f: &FollowingSeries) -> Result<String, String> {
    let b = &f.by_radius;
    let mut points = Vec::new();
    for (i, bin) in b.bins.iter().enumerate() {
        if bin.samples == 0 {
            continue;
        }
        let (a, c) = b.span(i);
        let mid = 0.5 * (a + c);
        points.push((mid, bin.min * 1e6));
        points.push((mid, bin.max * 1e6));
    }
    if points.is_empty() {
        return Err("the servo simulation has no samples to plot".into());
    }
    let used = points.len() / 2;
    let (e0, e1) = range_of(points.iter().map(|p| p.1));
    let (e0, e1) = padded(e0.min(0.0), e1.max(0.0), 0.15);
    let width_um = (b.to - b.from) / b.bins.len() as f64 * 1000.0;
    let text = format!(
        "The fast axis's following error, actual − commanded position, in nm: the machine's servo model driven at its data rate ({rate} kHz) by the commanded positions as printed. \
         Its {n} samples are gathered in {bins} bins of radius {bw} µm wide ({used} hold samples); each bin is drawn as a vertical stroke from its least to its largest error, so every peak is kept. \
         Largest |error| {max} nm at r = {at} mm.",
        rate = num(f.data_rate_hz / 1000.0, decimals(f.data_rate_hz / 1000.0)),
        n = f.samples,
        bins = b.bins.len(),
        bw = num(width_um, decimals(width_um)),
        max = num(f.max_error.0 * 1e6, decimals(f.max_error.0 * 1e6)),
        at = num(f.max_error.1, 3),
    );
    let lines = wrap(&text, f64::from(WIDTH) - 40.0);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, 640)).into_drawing_area();
        let (plot, below) = page(
            &root,
            &format!("{job}: fast-tool-servo following error"),
            lines.len(),
        )?;
        let mut chart = ChartBuilder::on(&plot)
            .margin(10)
            .margin_right(30)
            .x_label_area_size(45)
            .y_label_area_size(90)
            .build_cartesian_2d(b.from..b.to, e0..e1)
            .map_err(err)?;
        draw_axes(
            &mut chart,
            ("radius r (mm)", (b.from, b.to)),
            ("following error (nm)", (e0, e1)),
        )?;
        chart
            .draw_series(LineSeries::new(points, CENTRE.stroke_width(1)))
            .map_err(err)?
            .label("least and largest error per bin")
            .legend(legend_line(CENTRE));
        legend(&mut chart)?;
        caption(&below, &lines)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimation_keeps_every_runs_extremes_in_order() {
        let pts: Vec<(f64, f64)> = (0..1001)
            .map(|i| (i as f64, ((i * 7919) % 101) as f64))
            .collect();
        let (kept, run) = decimate(&pts, 100);
        assert_eq!(run, 21);
        assert_eq!(kept.len(), 2 * 1001usize.div_ceil(21));
        assert!(kept.windows(2).all(|w| w[0].0 < w[1].0), "in order");
        for (k, chunk) in pts.chunks(run).enumerate() {
            let lo = chunk.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
            let hi = chunk.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
            let got = [kept[2 * k].1, kept[2 * k + 1].1];
            assert!(got.contains(&lo) && got.contains(&hi), "{k}: {got:?}");
        }
        // A level run keeps its ends; a short series is kept whole.
        let flat: Vec<(f64, f64)> = (0..10).map(|i| (i as f64, 1.0)).collect();
        assert_eq!(decimate(&flat, 2).0, vec![(0.0, 1.0), (9.0, 1.0)]);
        assert_eq!(decimate(&flat, 10), (flat.clone(), 1));
    }

    /// A 4 × 4 map with every block cut, the one at (1, 1) holding an
    /// uncut cell as well when `uncut`.
    fn small_map(uncut: bool) -> FormErrorSeries {
        let mut r = ErrorRaster {
            x: (0.0, 0.4),
            y: (0.0, 0.4),
            block: 0.1,
            nx: 4,
            ny: 4,
            cells: (0..16).map(|k| 1e-6 * k as f64).collect(),
            uncut: vec![false; 16],
        };
        r.uncut[5] = uncut;
        FormErrorSeries {
            raster: r,
            window: ((0.0, 0.4), (0.0, 0.4)),
            spacing: 0.01,
            x_axis: "x (mm)",
            y_axis: "y (mm)",
        }
    }

    #[test]
    fn uncut_area_is_drawn_as_uncut_with_its_legend() {
        let grey = "#969696";
        let with = form_error_svg("j", &small_map(true)).expect("svg");
        assert!(with.contains("uncut: a cell of the part"), "no legend");
        assert!(with.contains(&format!("fill=\"{grey}\"")), "no grey block");
        assert!(with.contains("Grey: the 1 block holding"), "caption");
        let without = form_error_svg("j", &small_map(false)).expect("svg");
        assert!(!without.contains("uncut: a cell"));
        assert!(!without.contains(&format!("fill=\"{grey}\"")));
        assert!(without.contains("Nothing of the part is left uncut."));
    }

    #[test]
    fn numbers_print_without_negative_zero() {
        assert_eq!(num(-0.0001, 2), "0.00");
        assert_eq!(num(-1.5, 1), "-1.5");
        assert_eq!(decimals(0.0123), 4);
        assert_eq!(decimals(250.0), 0);
    }
}
