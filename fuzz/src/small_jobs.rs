//! Small whole jobs for the build tier: one job per file, each strategy
//! with the machine and tool it needs, a random surface of the kinds it
//! cuts, and random values kept where a build stays small (apertures of
//! at most half a millimetre, rollers of at most 0.8 mm, coarse feeds,
//! steps and tolerances) so that one build takes milliseconds: the
//! build's time goes to simulating the cut over the part, which grows with
//! its area over the feed; one job in `LARGE` is drawn from ranges ten
//! times wider. Most jobs are ones a build can make (a tolerance the
//! machine's resolution holds, a tool that fits the surface's concave
//! curvature, a surface the strategy cuts, acceptance criteria loose enough
//! for coarse steps), so that most build inputs reach planning, the
//! simulation, the acceptance gate and the writer; a share of each is
//! drawn outside on purpose (`ASTRAY`), for the refusals. The machine is
//! now and then a derived one, in a dialect it offers or one derived from
//! it with line and number limits, and with a `delivery` (memory, file
//! limit, link and its rate) that may split the program or refuse it. The
//! size limits themselves are also exercised by the numbers made extreme
//! (`extreme_somewhere`) and by the program sizes the build target draws.
//! Values that do not change the size of the cut (conic constants,
//! coefficients, senses, angles) range freely, extremes included.

use std::fmt::Write;

use crate::rng::Rng;

/// The share of a job's choices drawn where a build refuses them (a
/// tolerance finer than the machine holds, a tool too large for the
/// surface, a surface the strategy cannot cut).
const ASTRAY: f64 = 0.05;

/// One job in this many is large: its aperture, roller and steps drawn
/// from ranges wider than a small job's.
const LARGE: usize = 20;

/// A standard-library machine a small job runs on: its resolution (mm),
/// the axes a program moves, and the dialects it offers (its own first).
pub struct Machine {
    pub name: &'static str,
    resolution: f64,
    axes: f64,
    pub dialects: &'static [&'static str],
}

const LINUXCNC_LATHE: Machine = Machine {
    name: "linuxcnc_lathe",
    resolution: 1e-4,
    axes: 2.0,
    dialects: &["linuxcnc", "fanuc_0i_lathe", "siemens_840d_lathe"],
};
const ULTRA_PRECISION_LATHE: Machine = Machine {
    name: "ultra_precision_lathe",
    resolution: 1e-6,
    axes: 2.0,
    dialects: &[
        "linuxcnc",
        "ultra_precision_lathe_gcode",
        "siemens_840d_lathe",
    ],
};
const NANOFORM_FTS: Machine = Machine {
    name: "nanoform_x_fts5000",
    resolution: 1e-6,
    axes: 3.0,
    dialects: &["linuxcnc", "ultra_precision_lathe_gcode"],
};
const MILL: Machine = Machine {
    name: "generic_3axis_mill",
    resolution: 1e-4,
    axes: 3.0,
    dialects: &[
        "linuxcnc",
        "fanuc_0i_mill",
        "siemens_840d_mill",
        "heidenhain_iso",
        "heidenhain_tnc_klartext",
    ],
};
const GRINDER: Machine = Machine {
    name: "nano_grinder",
    resolution: 1e-5,
    axes: 2.0,
    dialects: &["linuxcnc", "siemens_840d_lathe"],
};
const MOORE: Machine = Machine {
    name: "moore_nanotech_450fg",
    resolution: 1e-6,
    axes: 3.0,
    dialects: &["linuxcnc", "ultra_precision_lathe_gcode"],
};

/// A small job: its file and the dialects its machine offers (what
/// `--dialect` may ask for).
pub struct SmallJob {
    pub text: String,
    pub dialects: &'static [&'static str],
}

/// One file with one small job.
pub fn file(rng: &mut Rng) -> String {
    job(rng).text
}

/// One small job.
pub fn job(rng: &mut Rng) -> SmallJob {
    let mut out = String::new();
    let large = rng.below(LARGE) == 0;
    let machine = match rng.below(7) {
        0 | 1 => turning(rng, &mut out, large),
        2 => grinding(rng, &mut out, large),
        3 => raster(rng, &mut out, large),
        4 => spiral(rng, &mut out, large),
        5 => fts(rng, &mut out, large),
        _ => roller(rng, &mut out, large),
    };
    // Now and then one number of the file, whatever it sizes, becomes an
    // extreme: the build must refuse it with a coded diagnostic or finish.
    if rng.chance(0.03) {
        out = extreme_somewhere(rng, &out);
    }
    SmallJob {
        text: out,
        dialects: machine.dialects,
    }
}

/// `use`s machine `m` and, one time in three, declares `m2` derived from
/// it: in another dialect it offers (or one derived from that with line
/// and number limits), with a `delivery` that may split the program or
/// refuse it. Returns the name the job names.
fn machine(rng: &mut Rng, out: &mut String, m: &Machine) -> &'static str {
    let _ = writeln!(out, "use std::machines::{}", m.name);
    if !rng.chance(1.0 / 3.0) {
        return m.name;
    }
    let mut fields = Vec::new();
    if rng.chance(0.5) {
        let base = rng.pick(m.dialects);
        if rng.chance(0.5) {
            let mut limits = Vec::new();
            if rng.chance(0.7) {
                limits.push(format!("max_line_length: {}", 12 + rng.below(300)));
            }
            if rng.chance(0.3) {
                limits.push(format!("line_numbers: {}", 1 + rng.below(10)));
                limits.push(format!("max_line_number: {}", 10 + rng.below(99_990)));
            }
            if rng.chance(0.2) {
                limits.push(format!("max_digits: {}", 4 + rng.below(8)));
            }
            let _ = writeln!(out, "dialect d2 = {base} {{ {} }}", limits.join(", "));
            fields.push("dialect: d2".to_string());
        } else {
            fields.push(format!("dialect: {base}"));
        }
    }
    if rng.chance(0.7) {
        let link = *rng.pick(&["memory", "disk", "dnc", "data_server"]);
        let mut d = vec![format!("link: {link}")];
        if rng.chance(0.6) {
            d.push(format!("memory: {}", rng.log_uniform(2e3, 1e8) as u64));
        }
        if rng.chance(0.6) {
            d.push(format!("file_limit: {}", rng.log_uniform(2e3, 1e8) as u64));
        }
        if link == "dnc" && rng.chance(0.8) {
            d.push(format!(
                "baud: {}",
                rng.pick(&[1200, 9600, 19_200, 115_200])
            ));
        }
        if rng.chance(0.3) {
            d.push(format!("rate: {}", rng.log_uniform(100.0, 1e7) as u64));
        }
        if rng.chance(0.2) {
            d.push(format!("buffer: {}", rng.log_uniform(64.0, 1e6) as u64));
        }
        fields.push(format!("delivery: {{ {} }}", d.join(", ")));
    }
    let _ = writeln!(out, "machine m2 = {} {{ {} }}", m.name, fields.join(", "));
    "m2"
}

/// A path tolerance (mm, written with a unit) between `lo` and `hi` mm
/// that machine `m` holds; now and then one finer than it holds.
fn tolerance(rng: &mut Rng, m: &Machine, lo: f64, hi: f64) -> String {
    // Rounding each axis to the resolution moves a point up to
    // sqrt(axes) q / 2, which must stay within half the tolerance.
    let holds = 1.5 * m.axes.sqrt() * m.resolution;
    let lo = if rng.chance(ASTRAY) {
        holds / 20.0
    } else {
        lo.max(holds)
    };
    random_length(rng, lo, hi.max(2.0 * lo))
}

/// The job's line: its acceptance criteria (half of them stated loose
/// enough for the coarse steps a small job is cut with, a few `none`, the
/// rest the defaults, which a coarse job may miss).
fn job_line(rng: &mut Rng, out: &mut String, tool: &str, machine: &str) {
    let accept = match rng.below(20) {
        0..=9 => format!(
            ", accept: {{ form_pv: {}, form_rms: {}, max_gouge: {}, max_residual: {}, uncut_area: {} }}",
            random_length(rng, 0.02, 1.0),
            random_length(rng, 0.005, 0.3),
            random_length(rng, 0.02, 1.0),
            random_length(rng, 0.02, 1.0),
            rng.pick(&["0.5", "0.1", "1", "0.01 mm^2"])
        ),
        10 | 11 => ", accept: none".to_string(),
        _ => String::new(),
    };
    let _ = writeln!(
        out,
        "job j {{ surface: s, tool: {tool}, machine: {machine}, strategy: st{accept} }}"
    );
}

/// `text` with one of its numbers replaced by an extreme.
fn extreme_somewhere(rng: &mut Rng, text: &str) -> String {
    let starts: Vec<usize> = text
        .char_indices()
        .filter(|&(i, c)| {
            c.is_ascii_digit()
                && !text[..i].ends_with(|p: char| p.is_ascii_alphanumeric() || p == '.')
        })
        .map(|(i, _)| i)
        .collect();
    if starts.is_empty() {
        return text.to_string();
    }
    let at = *rng.pick(&starts);
    let end = text[at..]
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == '-'))
        .map_or(text.len(), |n| at + n);
    let new = rng.pick(&[
        "0", "1e-300", "1e300", "5e-324", "1e-9", "100000", "0.000001",
    ]);
    format!("{}{new}{}", &text[..at], &text[end..])
}

/// A length in mm written with a random unit.
fn length(rng: &mut Rng, mm: f64) -> String {
    match rng.below(3) {
        0 => format!("{mm} mm"),
        1 => format!("{} um", mm * 1e3),
        _ => format!("{:e} mm", mm),
    }
}

/// A length between `lo` and `hi` mm (log-uniform), with a random unit.
fn random_length(rng: &mut Rng, lo: f64, hi: f64) -> String {
    let mm = rng.log_uniform(lo, hi);
    length(rng, mm)
}

/// A number that does not change the size of a build: mostly ordinary,
/// sometimes an extreme.
fn free_number(rng: &mut Rng, lo: f64, hi: f64) -> String {
    if rng.chance(0.1) {
        return rng
            .pick(&[
                "0", "-0", "1e308", "-1e308", "1e-300", "5e-324", "(0/0)", "1e999", "-1",
            ])
            .to_string();
    }
    format!("{}", lo + rng.unit() * (hi - lo))
}

fn sense(rng: &mut Rng) -> &'static str {
    ["convex", "concave"][rng.below(2)]
}

/// A rotationally symmetric surface `s` of aperture radius `r` mm whose
/// vertex radius is at least `min_radius` mm (a tool's radius: a concave
/// surface tighter than the tool gouges), but for a share drawn astray.
/// `profile` asks for a surface a profile strategy cuts (not a plane or a
/// formula, but for a share astray).
fn rotational(rng: &mut Rng, out: &mut String, r: f64, min_radius: f64, profile: bool) {
    let floor = if rng.chance(ASTRAY) {
        r * 1.05
    } else {
        (r * 1.05).max(min_radius * 1.25)
    };
    let radius = random_length(rng, floor.max(0.01), 500.0_f64.max(2.0 * floor));
    let sense = sense(rng);
    let aperture = if rng.chance(0.85) {
        format!("circle(radius: {})", length(rng, r))
    } else {
        let inner = r * rng.unit();
        format!(
            "annulus(inner: {}, outer: {})",
            length(rng, inner),
            length(rng, r)
        )
    };
    let kinds = if profile && !rng.chance(ASTRAY) { 3 } else { 6 };
    let kind = match rng.below(kinds) {
        // A profile strategy's kinds: sphere, conic, asphere, Q.
        0 => 0,
        1 => 1,
        2 => [2, 4][rng.below(2)],
        n => [3, 5, 4][n - 3],
    };
    let _ = match kind {
        0 => writeln!(
            out,
            "surface s = sphere {{ radius: {radius}, sense: {sense}, aperture: {aperture} }}"
        ),
        1 => writeln!(
            out,
            "surface s = conic {{ radius: {radius}, conic: {}, sense: {sense}, aperture: {aperture} }}",
            free_number(rng, -5.0, 5.0)
        ),
        2 => {
            let mut coeffs = String::new();
            for j in [4, 6, 8, 10] {
                if rng.chance(0.6) {
                    let _ = write!(
                        coeffs,
                        "A{j}: {} mm^{}, ",
                        free_number(rng, -1e-3, 1e-3),
                        1 - j
                    );
                }
            }
            writeln!(
                out,
                "surface s = asphere {{ radius: {radius}, conic: {}, {coeffs}sense: {sense}, aperture: {aperture} }}",
                free_number(rng, -3.0, 1.0)
            )
        }
        3 => writeln!(out, "surface s = plane {{ aperture: {aperture} }}"),
        4 => {
            let norm = r * (1.0 + rng.unit());
            let mut coeffs = String::new();
            for m in 0..rng.below(4) {
                let _ = write!(coeffs, "Q{m}: {} um, ", free_number(rng, -5.0, 5.0));
            }
            let kind = rng.pick(&["qbfs", "qcon"]);
            writeln!(
                out,
                "surface s = {kind} {{ radius: {radius}, norm_radius: {}, {coeffs}sense: {sense}, aperture: {aperture} }}",
                length(rng, norm)
            )
        }
        _ => writeln!(
            out,
            "surface s = freeform {{ z(x, y) = {} * (x^2 + y^2) / 1 mm, domain: {aperture} }}",
            free_number(rng, -0.05, 0.05)
        ),
    };
}

fn turning(rng: &mut Rng, out: &mut String, large: bool) -> &'static Machine {
    let r = rng.log_uniform(0.03, if large { 5.0 } else { 0.5 });
    let nose = rng.log_uniform(0.005, 3.0);
    rotational(rng, out, r, nose, true);
    let m = *rng.pick(&[&LINUXCNC_LATHE, &ULTRA_PRECISION_LATHE]);
    let name = machine(rng, out, m);
    let _ = writeln!(
        out,
        "tool t = round_nose {{ nose_radius: {}, clearance: {} deg }}",
        length(rng, nose),
        free_number(rng, 0.5, 30.0)
    );
    let speed = if rng.chance(0.7) {
        format!("spindle_speed: {} rpm", 100 + rng.below(3000))
    } else {
        format!(
            "surface_speed: {} m/min, spindle_cap: 3000 rpm",
            1 + rng.below(60)
        )
    };
    let _ = writeln!(
        out,
        "strategy st = profile_turning {{ feed: {} um/rev, {speed}, chord_tolerance: {} }}",
        rng.log_uniform(2.0, 60.0),
        tolerance(rng, m, 5e-6, 1e-3)
    );
    job_line(rng, out, "t", name);
    m
}

fn grinding(rng: &mut Rng, out: &mut String, large: bool) -> &'static Machine {
    let r = rng.log_uniform(0.03, if large { 5.0 } else { 0.5 });
    let diameter = rng.log_uniform(0.5, 8.0);
    rotational(rng, out, r, diameter / 2.0, true);
    let name = machine(rng, out, &GRINDER);
    let _ = writeln!(
        out,
        "tool t = spherical_wheel {{ diameter: {} }}",
        length(rng, diameter)
    );
    let _ = writeln!(
        out,
        "strategy st = profile_grinding {{ interval: {} um, feed: {} um/s, smoothness: {}, spindle_speed: 1000 rpm }}",
        rng.log_uniform(2.0, 40.0),
        rng.log_uniform(1.0, 100.0),
        free_number(rng, 0.01, 0.99)
    );
    job_line(rng, out, "t", name);
    &GRINDER
}

fn raster(rng: &mut Rng, out: &mut String, large: bool) -> &'static Machine {
    let r = rng.log_uniform(0.02, if large { 2.5 } else { 0.25 });
    let nose = rng.log_uniform(0.01, 0.2);
    if rng.chance(0.5) {
        rotational(rng, out, r, nose, false);
    } else {
        any_shape(rng, out, r);
    }
    let name = machine(rng, out, &MILL);
    let _ = writeln!(
        out,
        "tool t = microshaper {{ nose_radius: {} }}",
        length(rng, nose)
    );
    let _ = writeln!(
        out,
        "strategy st = raster {{ along: {}, direction: {}, stepover: {} um, feed: {} mm/min, chord_tolerance: {} }}",
        rng.pick(&["x", "y"]),
        rng.pick(&["one_way", "zigzag"]),
        rng.log_uniform(10.0, 120.0),
        rng.log_uniform(1.0, 1000.0),
        tolerance(rng, &MILL, 2e-5, 1e-3)
    );
    job_line(rng, out, "t", name);
    &MILL
}

/// A surface of any shape `s` over a circle of radius `r` mm.
fn any_shape(rng: &mut Rng, out: &mut String, r: f64) {
    let aperture = format!("circle(radius: {})", length(rng, r));
    let _ = match rng.below(5) {
        0 => writeln!(
            out,
            "surface s = toroid {{ radius: {}, rotation_radius: {}, sense: {}, aperture: {aperture} }}",
            random_length(rng, 2.0, 100.0),
            random_length(rng, 2.0, 100.0),
            sense(rng)
        ),
        1 => writeln!(
            out,
            "surface s = xy_polynomial {{ sense: concave, X2Y0: {} mm^-1, X0Y2: {} mm^-1, X1Y1: {} mm^-1, aperture: {aperture} }}",
            free_number(rng, -0.05, 0.05),
            free_number(rng, -0.05, 0.05),
            free_number(rng, -0.05, 0.05)
        ),
        2 => writeln!(
            out,
            "surface s = zernike {{ sense: concave, ordering: {}, norm_radius: {}, Z4: {} um, Z5: {} um, Z11: {} um, aperture: {aperture} }}",
            ["fringe", "ansi"][rng.below(2)],
            length(rng, r),
            free_number(rng, -2.0, 2.0),
            free_number(rng, -2.0, 2.0),
            free_number(rng, -2.0, 2.0)
        ),
        3 => {
            let _ = writeln!(
                out,
                "surface parent = conic {{ radius: {}, conic: -1, sense: concave, aperture: circle(radius: {}) }}",
                random_length(rng, 20.0, 200.0),
                length(rng, 4.0 * r + 1.0)
            );
            let x = 2.0 * r * rng.unit();
            writeln!(
                out,
                "surface s = off_axis(parent, x: {}, y: 0 mm, aperture: {aperture})",
                length(rng, x)
            )
        }
        _ => {
            let _ = writeln!(
                out,
                "surface flat = sphere {{ radius: {}, sense: convex, aperture: circle(radius: {}) }}",
                random_length(rng, 5.0, 100.0),
                length(rng, 2.0 * r)
            );
            writeln!(
                out,
                "surface s = tilt(flat, about: {}, angle: {} deg, aperture: {aperture})",
                ["x", "y"][rng.below(2)],
                free_number(rng, -10.0, 10.0)
            )
        }
    };
}

fn spiral(rng: &mut Rng, out: &mut String, large: bool) -> &'static Machine {
    let r = rng.log_uniform(0.03, if large { 3.0 } else { 0.3 });
    if rng.chance(0.4) {
        rotational(rng, out, r, 0.5, false);
    } else if rng.chance(0.6) {
        any_shape(rng, out, r);
    } else {
        let _ = writeln!(
            out,
            "surface s = biconic {{ radius_x: {}, radius_y: {}, sense: {}, aperture: circle(radius: {}) }}",
            random_length(rng, 2.0, 100.0),
            random_length(rng, 2.0, 100.0),
            sense(rng),
            length(rng, r)
        );
    }
    let name = machine(rng, out, &MOORE);
    let _ = writeln!(out, "use std::tools::diamond_r500um");
    let _ = writeln!(
        out,
        "strategy st = spiral_turning {{ feed: {} um/rev, spindle_speed: {} rpm, chord_tolerance: {} }}",
        rng.log_uniform(10.0, 60.0),
        10 + rng.below(200),
        tolerance(rng, &MOORE, 5e-5, 2e-3)
    );
    job_line(rng, out, "diamond_r500um", name);
    &MOORE
}

fn fts(rng: &mut Rng, out: &mut String, large: bool) -> &'static Machine {
    let lenslet_r = rng.log_uniform(0.02, if large { 0.5 } else { 0.1 });
    // The tool's nose (0.496 mm) fits a concave lenslet of a larger
    // radius; `settle: auto` needs concave lenslets.
    let sense = sense(rng);
    let floor = if rng.chance(ASTRAY) {
        lenslet_r * 1.5
    } else {
        (lenslet_r * 1.5).max(0.62)
    };
    let _ = writeln!(
        out,
        "surface lenslet = sphere {{ radius: {}, sense: {sense}, aperture: circle(radius: {}) }}",
        random_length(rng, floor, 50.0),
        length(rng, lenslet_r)
    );
    let pitch = lenslet_r * (2.0 + rng.unit());
    let n = 1 + rng.below(3);
    let _ = if rng.chance(0.5) {
        writeln!(
            out,
            "surface s = grid(lenslet, pitch_x: {}, pitch_y: {}, count_x: {n}, count_y: {n})",
            length(rng, pitch),
            length(rng, pitch)
        )
    } else {
        writeln!(
            out,
            "surface s = hex_grid(lenslet, pitch: {}, count_x: {n}, count_y: {n})",
            length(rng, pitch)
        )
    };
    let name = machine(rng, out, &NANOFORM_FTS);
    let _ = writeln!(out, "use std::tools::diamond_r496um");
    let settle = if sense == "concave" || rng.chance(ASTRAY) {
        *rng.pick(&["auto", "none"])
    } else {
        "none"
    };
    let _ = writeln!(
        out,
        "strategy st = fts_spiral {{ feed: {} um/rev, spindle_speed: {} rpm, chord_tolerance: {}, settle: {settle} }}",
        rng.log_uniform(10.0, 50.0),
        20 + rng.below(200),
        tolerance(rng, &NANOFORM_FTS, 1e-4, 2e-3)
    );
    job_line(rng, out, "diamond_r496um", name);
    &NANOFORM_FTS
}

fn roller(rng: &mut Rng, out: &mut String, large: bool) -> &'static Machine {
    let (radius, width) = if large {
        (rng.log_uniform(0.3, 1.5), rng.log_uniform(0.1, 0.4))
    } else {
        (rng.log_uniform(0.2, 0.8), rng.log_uniform(0.05, 0.25))
    };
    let _ = writeln!(
        out,
        "surface pattern = freeform {{ z(x, y) = {} * sin(5 rad/mm * x) - 0.04 mm, domain: rect(x: 0 mm .. {}, y: 0 mm .. {}) }}",
        ["0.02 mm", "0.01 mm", "1 um", "0 mm"][rng.below(4)],
        length(rng, width),
        length(rng, std::f64::consts::TAU * radius)
    );
    let _ = writeln!(
        out,
        "surface s = wrap(pattern, onto: roller(radius: {}))",
        length(rng, radius)
    );
    let name = machine(rng, out, &MOORE);
    let _ = writeln!(
        out,
        "tool t = round_nose {{ nose_radius: {}, clearance: 12.5 deg, included_angle: {} deg }}",
        random_length(rng, 0.05, 2.0),
        free_number(rng, 40.0, 120.0)
    );
    let rough = if rng.chance(0.5) {
        format!(
            "rough: {{ c_step: {} deg, pitch: {}, finish_allowance: {} }}, ",
            rng.log_uniform(1.0, 5.0),
            random_length(rng, 0.1, 0.5),
            random_length(rng, 0.001, 0.02)
        )
    } else {
        String::new()
    };
    let (c_lo, pitch_lo) = if large { (3.0, 0.08) } else { (6.0, 0.12) };
    let _ = writeln!(
        out,
        "strategy st = roller_helix {{ {rough}finish: {{ c_step: {} deg, pitch: {} }}, spindle_speed: 60 rpm }}",
        rng.log_uniform(c_lo, 12.0),
        random_length(rng, pitch_lo, 0.3)
    );
    job_line(rng, out, "t", name);
    &MOORE
}
