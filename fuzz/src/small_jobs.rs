//! Small whole jobs for the build tier: one job per file, each strategy
//! with the machine and tool it needs, a random surface of the kinds it
//! cuts, and random values kept where a build stays small (apertures of
//! at most half a millimetre, rollers of at most 1.5 mm, coarse feeds,
//! steps and tolerances) so that one build takes well under a second: the
//! build's time goes to simulating the cut over the part, which grows with
//! its area over the feed. The size limits themselves are exercised by
//! the numbers made extreme (`extreme_somewhere`) and by the program sizes
//! the build target draws. Values that do not change the size of the
//! cut (conic constants, coefficients, senses, angles) range freely,
//! extremes included.

use std::fmt::Write;

use crate::rng::Rng;

/// One file with one small job.
pub fn file(rng: &mut Rng) -> String {
    let mut out = String::new();
    match rng.below(7) {
        0 | 1 => turning(rng, &mut out),
        2 => grinding(rng, &mut out),
        3 => raster(rng, &mut out),
        4 => spiral(rng, &mut out),
        5 => fts(rng, &mut out),
        _ => roller(rng, &mut out),
    }
    // Now and then one number of the file, whatever it sizes, becomes an
    // extreme: the build must refuse it with a coded diagnostic or finish.
    if rng.chance(0.03) {
        out = extreme_somewhere(rng, &out);
    }
    out
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

/// A rotationally symmetric surface `s` of aperture radius `r` mm.
fn rotational(rng: &mut Rng, out: &mut String, r: f64) {
    let radius = random_length(rng, r.max(0.01) * 1.05, 500.0);
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
    let _ = match rng.below(6) {
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

fn turning(rng: &mut Rng, out: &mut String) {
    let r = rng.log_uniform(0.03, 0.5);
    rotational(rng, out, r);
    let machine = rng.pick(&["linuxcnc_lathe", "ultra_precision_lathe"]);
    let _ = writeln!(out, "use std::machines::{machine}");
    let _ = writeln!(
        out,
        "tool t = round_nose {{ nose_radius: {}, clearance: {} deg }}",
        random_length(rng, 0.005, 3.0),
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
        random_length(rng, 5e-6, 1e-3)
    );
    let _ = writeln!(
        out,
        "job j {{ surface: s, tool: t, machine: {machine}, strategy: st }}"
    );
}

fn grinding(rng: &mut Rng, out: &mut String) {
    let r = rng.log_uniform(0.03, 0.5);
    rotational(rng, out, r);
    let _ = writeln!(out, "use std::machines::nano_grinder");
    let _ = writeln!(
        out,
        "tool t = spherical_wheel {{ diameter: {} }}",
        random_length(rng, 0.5, 8.0)
    );
    let _ = writeln!(
        out,
        "strategy st = profile_grinding {{ interval: {} um, feed: {} um/s, smoothness: {}, spindle_speed: 1000 rpm }}",
        rng.log_uniform(2.0, 40.0),
        rng.log_uniform(1.0, 100.0),
        free_number(rng, 0.01, 0.99)
    );
    let _ = writeln!(
        out,
        "job j {{ surface: s, tool: t, machine: nano_grinder, strategy: st }}"
    );
}

fn raster(rng: &mut Rng, out: &mut String) {
    let r = rng.log_uniform(0.02, 0.25);
    if rng.chance(0.5) {
        rotational(rng, out, r);
    } else {
        any_shape(rng, out, r);
    }
    let _ = writeln!(out, "use std::machines::generic_3axis_mill");
    let _ = writeln!(
        out,
        "tool t = microshaper {{ nose_radius: {} }}",
        random_length(rng, 0.01, 0.2)
    );
    let _ = writeln!(
        out,
        "strategy st = raster {{ along: {}, direction: {}, stepover: {} um, feed: {} mm/min, chord_tolerance: {} }}",
        rng.pick(&["x", "y"]),
        rng.pick(&["one_way", "zigzag"]),
        rng.log_uniform(10.0, 120.0),
        rng.log_uniform(1.0, 1000.0),
        random_length(rng, 2e-5, 1e-3)
    );
    let _ = writeln!(
        out,
        "job j {{ surface: s, tool: t, machine: generic_3axis_mill, strategy: st }}"
    );
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

fn spiral(rng: &mut Rng, out: &mut String) {
    let r = rng.log_uniform(0.03, 0.3);
    if rng.chance(0.4) {
        rotational(rng, out, r);
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
    let _ = writeln!(out, "use std::machines::moore_nanotech_450fg");
    let _ = writeln!(out, "use std::tools::diamond_r500um");
    let _ = writeln!(
        out,
        "strategy st = spiral_turning {{ feed: {} um/rev, spindle_speed: {} rpm, chord_tolerance: {} }}",
        rng.log_uniform(10.0, 60.0),
        10 + rng.below(200),
        random_length(rng, 5e-5, 2e-3)
    );
    let _ = writeln!(
        out,
        "job j {{ surface: s, tool: diamond_r500um, machine: moore_nanotech_450fg, strategy: st }}"
    );
}

fn fts(rng: &mut Rng, out: &mut String) {
    let lenslet_r = rng.log_uniform(0.02, 0.1);
    let _ = writeln!(
        out,
        "surface lenslet = sphere {{ radius: {}, sense: {}, aperture: circle(radius: {}) }}",
        random_length(rng, lenslet_r * 1.5, 50.0),
        sense(rng),
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
    let _ = writeln!(out, "use std::machines::nanoform_x_fts5000");
    let _ = writeln!(out, "use std::tools::diamond_r496um");
    let _ = writeln!(
        out,
        "strategy st = fts_spiral {{ feed: {} um/rev, spindle_speed: {} rpm, chord_tolerance: {}, settle: {} }}",
        rng.log_uniform(10.0, 50.0),
        20 + rng.below(200),
        random_length(rng, 1e-4, 2e-3),
        rng.pick(&["auto", "none"])
    );
    let _ = writeln!(
        out,
        "job j {{ surface: s, tool: diamond_r496um, machine: nanoform_x_fts5000, strategy: st }}"
    );
}

fn roller(rng: &mut Rng, out: &mut String) {
    let radius = rng.log_uniform(0.3, 1.5);
    let width = rng.log_uniform(0.1, 0.4);
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
    let _ = writeln!(out, "use std::machines::moore_nanotech_450fg");
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
    let _ = writeln!(
        out,
        "strategy st = roller_helix {{ {rough}finish: {{ c_step: {} deg, pitch: {} }}, spindle_speed: 60 rpm }}",
        rng.log_uniform(3.0, 12.0),
        random_length(rng, 0.08, 0.3)
    );
    let _ = writeln!(
        out,
        "job j {{ surface: s, tool: t, machine: moore_nanotech_450fg, strategy: st }}"
    );
}
