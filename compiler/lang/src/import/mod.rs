//! Prescription import (`lensc import`): a lens designer's file — a Zemax
//! OpticStudio `.zmx` (`zemax`) or an optiland JSON export (`optiland`) —
//! read into one model of its surfaces (here), then written as a `.lens`
//! file with one `surface` per optical surface (`write`).
//!
//! The readers only read: each surface becomes an [`Entry`], a shape in
//! millimetres with the designer's signs, or the reason it is skipped.
//! What the file holds that lensc cannot carry over is a coded warning
//! with the line it is on, and a comment in the output, never dropped
//! silently. The writer decides how a shape is spelled in the language.

pub mod optiland;
mod write;
pub mod zemax;

use lensc_grammar::{Diagnostic, FileId, Span};

use crate::codes;

/// A prescription read from a file, ready to write.
#[derive(Debug)]
pub struct Prescription {
    /// The file's name as the output's comments give it.
    pub source: String,
    /// What kind of file it was, for the header comment.
    pub format: &'static str,
    /// Every surface of the file, in order, imported or skipped.
    pub entries: Vec<Entry>,
}

/// One surface of the source file.
#[derive(Debug)]
pub struct Entry {
    /// The surface's number in the source (Zemax `SURF n`, optiland's index).
    pub number: usize,
    /// The source's type name (`EVENASPH`, `EvenAsphere`).
    pub type_name: String,
    /// The designer's comment on the surface (may be empty).
    pub comment: String,
    pub what: What,
}

/// What becomes of a surface.
#[derive(Debug)]
pub enum What {
    /// Written as a `surface`.
    Surface(Surface),
    /// Not written; the reason, for the output's comment.
    Skipped(String),
}

/// An optical surface to write.
#[derive(Debug, Clone)]
pub struct Surface {
    pub shape: Shape,
    /// The clear semi-diameter, in mm.
    pub semi_diameter: f64,
    /// `Some(glass)` when only the medium before the surface is glass: a
    /// lens's rear surface, which the tool meets with the part turned over.
    pub rear_of: Option<String>,
    /// What the source holds for this surface that is not carried over
    /// (each also a warning), for the output's comment.
    pub dropped: Vec<String>,
}

/// A surface's shape in the designer's frame (light along +z), in mm:
/// curvatures in 1/mm (0 = flat), coefficients as (power j, value in
/// mm^(1−j)).
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// z = c r²/(1 + sqrt(1 − (1+k) c² r²)) + Σ a_j r^j.
    Rotational {
        curvature: f64,
        conic: f64,
        terms: Vec<(u32, f64)>,
    },
    /// z = (cx x² + cy y²)/(1 + sqrt(1 − (1+kx) cx² x² − (1+ky) cy² y²)).
    Biconic { cx: f64, cy: f64, kx: f64, ky: f64 },
    /// A y–z profile (conic + Σ a_j y^j) swept about an axis parallel to y
    /// at `rotation_radius` from the vertex (`None`: a cylinder, never swept).
    Toroid {
        cy: f64,
        conic: f64,
        rotation_radius: Option<f64>,
        terms: Vec<(u32, f64)>,
    },
    /// A conic of revolution plus Σ c_ij x^i y^j, each (i, j, c_ij) in
    /// mm^(1−i−j).
    XyPolynomial {
        curvature: f64,
        conic: f64,
        terms: Vec<(u32, u32, f64)>,
    },
    /// A conic of revolution plus Σ a_j Z_j(ρ, θ), ρ = r / `norm_radius`,
    /// the Z_j normalised and numbered as ANSI Z80.28 (j from 0), a_j in mm.
    Zernike {
        curvature: f64,
        conic: f64,
        norm_radius: f64,
        terms: Vec<(u32, f64)>,
    },
}

impl Shape {
    /// No optical power and no aspheric terms: nothing to machine.
    pub fn is_flat(&self) -> bool {
        match self {
            Shape::Rotational {
                curvature, terms, ..
            } => *curvature == 0.0 && terms.iter().all(|(_, a)| *a == 0.0),
            Shape::Biconic { cx, cy, .. } => *cx == 0.0 && *cy == 0.0,
            Shape::Toroid {
                cy,
                rotation_radius,
                terms,
                ..
            } => *cy == 0.0 && rotation_radius.is_none() && terms.iter().all(|(_, a)| *a == 0.0),
            Shape::XyPolynomial {
                curvature, terms, ..
            } => *curvature == 0.0 && terms.iter().all(|(_, _, a)| *a == 0.0),
            Shape::Zernike {
                curvature, terms, ..
            } => *curvature == 0.0 && terms.iter().all(|(_, a)| *a == 0.0),
        }
    }

    /// The designer's sag z(x, y), in mm: the formulas above, for tests
    /// and for checks that the written file says the same.
    pub fn sag(&self, x: f64, y: f64) -> f64 {
        fn conic(c: f64, k: f64, s: f64) -> f64 {
            c * s / (1.0 + (1.0 - (1.0 + k) * c * c * s).sqrt())
        }
        fn series(terms: &[(u32, f64)], r: f64) -> f64 {
            terms.iter().map(|(j, a)| a * r.abs().powi(*j as i32)).sum()
        }
        match self {
            Shape::Rotational {
                curvature,
                conic: k,
                terms,
            } => {
                let s = x * x + y * y;
                conic(*curvature, *k, s) + series(terms, s.sqrt())
            }
            Shape::Biconic { cx, cy, kx, ky } => {
                let (x2, y2) = (x * x, y * y);
                (cx * x2 + cy * y2)
                    / (1.0 + (1.0 - (1.0 + kx) * cx * cx * x2 - (1.0 + ky) * cy * cy * y2).sqrt())
            }
            Shape::Toroid {
                cy,
                conic: k,
                rotation_radius,
                terms,
            } => {
                let zy = conic(*cy, *k, y * y) + series(terms, y);
                match rotation_radius {
                    None => zy,
                    Some(r) => r - r.signum() * ((r - zy).powi(2) - x * x).sqrt(),
                }
            }
            Shape::XyPolynomial {
                curvature,
                conic: k,
                terms,
            } => {
                conic(*curvature, *k, x * x + y * y)
                    + terms
                        .iter()
                        .map(|(i, j, c)| c * x.powi(*i as i32) * y.powi(*j as i32))
                        .sum::<f64>()
            }
            Shape::Zernike {
                curvature,
                conic: k,
                norm_radius,
                terms,
            } => {
                let (rho, theta) = ((x * x + y * y).sqrt() / norm_radius, y.atan2(x));
                conic(*curvature, *k, x * x + y * y)
                    + terms
                        .iter()
                        .map(|(j, a)| a * zernike_ansi_value(*j, rho, theta))
                        .sum::<f64>()
            }
        }
    }

    /// The same surface seen from the other side (the part turned over
    /// about the y axis): every curvature and coefficient negated.
    pub fn turned_over(&self) -> Shape {
        let neg = |t: &[(u32, f64)]| t.iter().map(|(j, a)| (*j, -a)).collect();
        match self {
            Shape::Rotational {
                curvature,
                conic,
                terms,
            } => Shape::Rotational {
                curvature: -curvature,
                conic: *conic,
                terms: neg(terms),
            },
            Shape::Biconic { cx, cy, kx, ky } => Shape::Biconic {
                cx: -cx,
                cy: -cy,
                kx: *kx,
                ky: *ky,
            },
            Shape::Toroid {
                cy,
                conic,
                rotation_radius,
                terms,
            } => Shape::Toroid {
                cy: -cy,
                conic: *conic,
                rotation_radius: rotation_radius.map(|r| -r),
                terms: neg(terms),
            },
            // Turned over about y, x becomes −x: a term odd in x keeps its
            // sign when the sag's is reversed.
            Shape::XyPolynomial {
                curvature,
                conic,
                terms,
            } => Shape::XyPolynomial {
                curvature: -curvature,
                conic: *conic,
                terms: terms
                    .iter()
                    .map(|(i, j, c)| (*i, *j, if i % 2 == 1 { *c } else { -c }))
                    .collect(),
            },
            // θ becomes π − θ: cos mθ changes sign with m odd, sin mθ with m even.
            Shape::Zernike {
                curvature,
                conic,
                norm_radius,
                terms,
            } => Shape::Zernike {
                curvature: -curvature,
                conic: *conic,
                norm_radius: *norm_radius,
                terms: terms
                    .iter()
                    .map(|(j, a)| {
                        let (_, m) = ansi_nm(*j);
                        let odd_in_x = if m >= 0 { m % 2 == 1 } else { m % 2 == 0 };
                        (*j, if odd_in_x { *a } else { -a })
                    })
                    .collect(),
            },
        }
    }
}

/// (n, m) of ANSI Z80.28 index j (from 0): m < 0 is a sine term.
pub fn ansi_nm(j: u32) -> (u32, i32) {
    let mut n = 0;
    while (n + 1) * (n + 2) / 2 <= j {
        n += 1;
    }
    (n, 2 * j as i32 - (n * (n + 2)) as i32)
}

/// (n, m) of Noll's index j (from 1, Zemax's "Zernike Standard" order):
/// m < 0 is a sine term, odd j the sines.
pub fn noll_nm(j: u32) -> (u32, i32) {
    let mut n = 0;
    while (n + 1) * (n + 2) / 2 < j {
        n += 1;
    }
    let k = j - n * (n + 1) / 2;
    let m = if n % 2 == 0 {
        2 * (k / 2)
    } else {
        2 * ((k - 1) / 2) + 1
    } as i32;
    (n, if m != 0 && j % 2 == 1 { -m } else { m })
}

/// The ANSI index of (n, m).
pub fn ansi_index(n: u32, m: i32) -> u32 {
    ((n * (n + 2)) as i32 + m) as u32 / 2
}

/// Z_j(ρ, θ), ANSI-numbered and normalised: sqrt(2(n+1)/(1+δ_m0))
/// R_n^|m|(ρ) cos mθ (m ≥ 0) or sin |m|θ (m < 0).
fn zernike_ansi_value(j: u32, rho: f64, theta: f64) -> f64 {
    let (n, m) = ansi_nm(j);
    let ma = m.unsigned_abs();
    let fact = |k: u32| (1..=k).map(f64::from).product::<f64>();
    let radial: f64 = (0..=(n - ma) / 2)
        .map(|s| {
            let sign = if s % 2 == 0 { 1.0 } else { -1.0 };
            sign * fact(n - s) / (fact(s) * fact((n + ma) / 2 - s) * fact((n - ma) / 2 - s))
                * rho.powi((n - 2 * s) as i32)
        })
        .sum();
    let norm = (2.0 * f64::from(n + 1) / if m == 0 { 2.0 } else { 1.0 }).sqrt();
    let angular = if m >= 0 {
        (f64::from(ma) * theta).cos()
    } else {
        (f64::from(ma) * theta).sin()
    };
    norm * radial * angular
}

/// Which reader a file is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Zemax,
    Optiland,
}

impl Format {
    /// By the file's extension (`.zmx`, `.json`), else by its first
    /// non-blank character (`{` is JSON).
    pub fn of(name: &str, text: &str) -> Format {
        let lower = name.to_ascii_lowercase();
        if lower.ends_with(".zmx") {
            Format::Zemax
        } else if lower.ends_with(".json") || text.trim_start().starts_with('{') {
            Format::Optiland
        } else {
            Format::Zemax
        }
    }
}

/// The outcome of an import: the decoded source text (what diagnostic
/// spans point into, as `FileId(0)`), the `.lens` text if there is one,
/// and every diagnostic.
pub struct Imported {
    pub source_text: String,
    pub lens: Option<String>,
    pub diags: Vec<Diagnostic>,
}

/// Reads `bytes` (the file `name`) and writes its surfaces as a `.lens`
/// file in the canonical layout. `lens` is `None` when an error was found.
pub fn import(name: &str, bytes: &[u8]) -> Imported {
    import_within(name, bytes, crate::sandbox::MAX_FILE_BYTES)
}

/// `import`, refusing (E0354) a `.lens` text over `limit` bytes.
pub fn import_within(name: &str, bytes: &[u8], limit: u64) -> Imported {
    let text = decode(bytes);
    let mut diags = Vec::new();
    let read = match Format::of(name, &text) {
        Format::Zemax => zemax::read(name, &text, &mut diags),
        Format::Optiland => optiland::read(name, &text, &mut diags),
    };
    let lens = read.and_then(|p| {
        if diags.iter().any(Diagnostic::is_error) {
            return None;
        }
        if !p.entries.iter().any(|e| matches!(e.what, What::Surface(_))) {
            diags.push(
                Diagnostic::error(
                    codes::IMPORT_NOTHING,
                    format!("{name} has no surface to import"),
                    FileId(0),
                    Span::new(0, 0),
                )
                .with_help(format!(
                    "every surface is skipped: {}",
                    p.entries
                        .iter()
                        .map(|e| match &e.what {
                            What::Skipped(why) => format!("surface {} ({why})", e.number),
                            _ => format!("surface {}", e.number),
                        })
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
            );
            return None;
        }
        match crate::format::format_source(&write::lens_text(&p)) {
            Ok(formatted) if formatted.len() as u64 > limit => {
                diags.push(
                    Diagnostic::error(
                        codes::IMPORT_TOO_LARGE,
                        format!(
                            "the .lens text imported from {name} would be {} bytes, over the {} lensc reads; nothing is written",
                            formatted.len(),
                            if limit >= 1 << 20 {
                                format!("{} MiB", limit >> 20)
                            } else {
                                format!("{limit} bytes")
                            }
                        ),
                        FileId(0),
                        Span::new(0, 0),
                    )
                    .with_help("import a copy of the design with only the surfaces the part needs"),
                );
                None
            }
            Ok(formatted) => Some(formatted),
            Err(d) => {
                diags.extend(d);
                None
            }
        }
    });
    Imported {
        source_text: text,
        lens,
        diags,
    }
}

/// The file's text: UTF-16 (little- or big-endian, with its byte-order
/// mark, as OpticStudio writes `.zmx` files, or little-endian without one),
/// UTF-8, or else Latin-1 (older Zemax files are ANSI).
pub fn decode(bytes: &[u8]) -> String {
    let utf16 = |b: &[u8], le: bool| -> String {
        let units = b.chunks_exact(2).map(|p| {
            if le {
                u16::from_le_bytes([p[0], p[1]])
            } else {
                u16::from_be_bytes([p[0], p[1]])
            }
        });
        char::decode_utf16(units)
            .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
            .collect()
    };
    match bytes {
        [0xFF, 0xFE, rest @ ..] => utf16(rest, true),
        [0xFE, 0xFF, rest @ ..] => utf16(rest, false),
        [0xEF, 0xBB, 0xBF, rest @ ..] => String::from_utf8_lossy(rest).into_owned(),
        [a, 0, b, 0, ..] if *a != 0 && *b != 0 => utf16(bytes, true),
        _ => match std::str::from_utf8(bytes) {
            Ok(s) => s.to_string(),
            Err(_) => bytes.iter().map(|&b| b as char).collect(),
        },
    }
}

/// Where a surface sits in the source's sequence.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Role {
    Object,
    Image,
    Optical,
}

/// What a reader found for one surface, before the decisions both readers
/// share (what is skipped, what is warned about).
pub(crate) struct Found {
    pub number: usize,
    pub type_name: String,
    pub comment: String,
    /// Where the surface is in the source, for warnings.
    pub span: Span,
    pub role: Role,
    /// The shape, or why the type cannot be imported.
    pub shape: Result<Shape, String>,
    pub semi_diameter: Option<f64>,
    pub rear_of: Option<String>,
    /// What is not carried over, with where it is.
    pub dropped: Vec<(Span, String)>,
}

/// The highest power a coefficient can have (`A20`).
pub(crate) const TOP_POWER: u32 = 20;

/// Splits (power, value) terms into those lensc carries (nonzero, power
/// 1 … 20) and warnings for the rest.
pub(crate) fn keep_terms(
    terms: impl IntoIterator<Item = (u32, f64, Span)>,
    dropped: &mut Vec<(Span, String)>,
) -> Vec<(u32, f64)> {
    let mut kept = Vec::new();
    for (j, a, span) in terms {
        if a == 0.0 {
            continue;
        }
        if (1..=TOP_POWER).contains(&j) {
            kept.push((j, a));
        } else {
            dropped.push((
                span,
                format!("the r^{j} coefficient {a:e} (lensc names A1 … A20)"),
            ));
        }
    }
    kept
}

/// The entry for a found surface: the shared rules for what is skipped
/// (object and image, flat surfaces, unsupported shapes, no semi-diameter,
/// a surface that does not reach its rim), each warned about but the
/// object, image and flat ones.
pub(crate) fn decide(f: Found, diags: &mut Vec<Diagnostic>) -> Entry {
    let entry = |what| Entry {
        number: f.number,
        type_name: f.type_name.clone(),
        comment: f.comment.clone(),
        what,
    };
    match f.role {
        Role::Object => return entry(What::Skipped("the object surface".into())),
        Role::Image => {
            // The last surface is the image plane by the format's rule; a
            // curved one may be a lens surface of a file cut short.
            if f.shape.as_ref().is_ok_and(|s| !s.is_flat()) {
                diags.push(
                    Diagnostic::warning(
                        codes::IMPORT_IMAGE_CURVED,
                        format!(
                            "surface {}, the last, is taken as the image surface and not imported, but it is curved",
                            f.number
                        ),
                        FileId(0),
                        f.span,
                    )
                    .with_label("the last surface of a design is its image surface")
                    .with_help("if this is a lens surface (a file cut short after it), add the image surface after it, as OpticStudio writes one, and import again"),
                );
            }
            return entry(What::Skipped("the image surface".into()));
        }
        Role::Optical => {}
    }
    for (span, what) in &f.dropped {
        diags.push(dropped(*span, f.number, what));
    }
    let shape = match f.shape {
        Ok(s) => s,
        Err(why) => {
            diags.push(unsupported(f.span, f.number, &f.type_name, &why));
            return entry(What::Skipped(why));
        }
    };
    if shape.is_flat() {
        return entry(What::Skipped(
            "flat, with no optical power and no aspheric terms".into(),
        ));
    }
    if let Err(why) = finite(&shape) {
        diags.push(
            Diagnostic::error(
                codes::IMPORT_NOT_FINITE,
                format!("surface {} ({}): {why}", f.number, f.type_name),
                FileId(0),
                f.span,
            )
            .with_help("a curvature this close to 0 is a flat surface: write 0 in the design, or the radius it means"),
        );
        return entry(What::Skipped(why));
    }
    if let Err(why) = representable(&shape) {
        diags.push(unsupported(f.span, f.number, &f.type_name, &why));
        return entry(What::Skipped(why));
    }
    let Some(sd) = f.semi_diameter.filter(|d| d.is_finite() && *d > 0.0) else {
        diags.push(
            Diagnostic::warning(
                codes::IMPORT_NO_SEMI_DIAMETER,
                format!("surface {} has no semi-diameter, so no aperture to machine", f.number),
                FileId(0),
                f.span,
            )
            .with_help("give the surface a semi-diameter in the design (Zemax DIAM, an optiland RadialAperture) and import it again"),
        );
        return entry(What::Skipped(
            "no semi-diameter to make its aperture from".into(),
        ));
    };
    let h = sd / std::f64::consts::SQRT_2;
    if [(sd, 0.0), (0.0, sd), (h, h), (-sd, 0.0), (0.0, -sd)]
        .iter()
        .any(|&(x, y)| !shape.sag(x, y).is_finite())
    {
        let why = format!(
            "its sag is not defined out to its semi-diameter {sd} mm (the conic closes before it)"
        );
        diags.push(unsupported(f.span, f.number, &f.type_name, &why));
        return entry(What::Skipped(why));
    }
    entry(What::Surface(Surface {
        shape,
        semi_diameter: sd,
        rear_of: f.rear_of.clone(),
        dropped: f.dropped.iter().map(|(_, w)| w.clone()).collect(),
    }))
}

/// Whether a kind of the language says this shape exactly.
/// Every number the shape is written with is finite: its values, and the
/// radius 1/c of each curvature that is not 0 (a curvature under about
/// 5.6e-309 1/mm has none).
fn finite(shape: &Shape) -> Result<(), String> {
    let (curvatures, values): (Vec<f64>, Vec<f64>) = match shape {
        Shape::Rotational {
            curvature,
            conic,
            terms,
        } => (
            vec![*curvature],
            std::iter::once(*conic)
                .chain(terms.iter().map(|t| t.1))
                .collect(),
        ),
        Shape::Biconic { cx, cy, kx, ky } => (vec![*cx, *cy], vec![*kx, *ky]),
        Shape::Toroid {
            cy,
            conic,
            rotation_radius,
            terms,
        } => (
            vec![*cy],
            [*conic]
                .into_iter()
                .chain(*rotation_radius)
                .chain(terms.iter().map(|t| t.1))
                .collect(),
        ),
        Shape::XyPolynomial {
            curvature,
            conic,
            terms,
        } => (
            vec![*curvature],
            std::iter::once(*conic)
                .chain(terms.iter().map(|t| t.2))
                .collect(),
        ),
        Shape::Zernike {
            curvature,
            conic,
            norm_radius,
            terms,
        } => (
            vec![*curvature],
            [*conic, *norm_radius]
                .into_iter()
                .chain(terms.iter().map(|t| t.1))
                .collect(),
        ),
    };
    for c in curvatures {
        if !c.is_finite() || (c != 0.0 && !(1.0 / c).is_finite()) {
            return Err(format!(
                "its curvature {c:e} 1/mm has no finite radius (1/c overflows)"
            ));
        }
    }
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(format!("it has a value that is not finite ({v})")),
        None => Ok(()),
    }
}

fn representable(shape: &Shape) -> Result<(), String> {
    match shape {
        Shape::Toroid {
            cy,
            rotation_radius: Some(r),
            ..
        } if *cy == 0.0 || r.signum() != cy.signum() => Err(format!(
            "a toroid whose axis of rotation ({} mm) is not on the side of its y–z profile's centre of curvature ({}); lensc's `toroid` sweeps towards the profile's centre",
            r,
            if *cy == 0.0 {
                "flat".to_string()
            } else {
                format!("{} mm", 1.0 / cy)
            }
        )),
        _ => Ok(()),
    }
}

/// A warning that `what` on a surface is not carried over.
pub(crate) fn dropped(span: Span, surface: usize, what: &str) -> Diagnostic {
    Diagnostic::warning(
        codes::IMPORT_PARAMETER_DROPPED,
        format!("surface {surface}: {what} is not imported"),
        FileId(0),
        span,
    )
    .with_help(
        "the output names it in a comment above the surface; add it by hand if the part needs it",
    )
}

/// A warning that surface `surface` (of type `type_name`) is skipped.
pub(crate) fn unsupported(span: Span, surface: usize, type_name: &str, why: &str) -> Diagnostic {
    Diagnostic::warning(
        codes::IMPORT_UNSUPPORTED_SURFACE,
        format!("surface {surface} ({type_name}) is not imported: {why}"),
        FileId(0),
        span,
    )
    .with_help("the output names it in a comment; write it by hand with a kind `lensc list surfaces` shows")
}

#[cfg(test)]
mod tests;
