//! Reads a Zemax OpticStudio `.zmx` lens file: the sequential surfaces
//! (`SURF n` blocks) with their `TYPE`, `CURV` (curvature), `CONI`,
//! `PARM n` (the type's parameters), `XDAT n` (extra data), `DIAM`
//! (semi-diameter), `GLAS` and `COMM`, in the lens units of `UNIT`.
//!
//! Types and their parameters (OpticStudio's manual, "Surface types"):
//! STANDARD (conic); EVENASPH, PARM i the coefficient of r^(2i), i = 1…8;
//! ODDASPHE, PARM i of r^i, i = 1…8; BICONICX, PARM 1 the x radius (0 is
//! flat) and PARM 2 the x conic, `CURV`/`CONI` the y–z section's;
//! TOROIDAL, PARM 1 the radius of rotation (0 is a cylinder), PARM 2…8
//! the coefficients α1 … α7 of y², y⁴ … y¹⁴ of the y–z profile and PARM 0
//! its extrapolation flag (no part of the shape). COORDBRK moves
//! the surfaces after it and is not a surface. XPOLYNOM and SZERNSAG keep
//! their terms in extra data (`extra_data_shape`). Every other type, every
//! parameter a type does not use and all extra data are named in a
//! warning, never dropped silently.

use std::collections::BTreeMap;

use lensc_grammar::{Diagnostic, FileId, Span};

use super::{Found, Prescription, Role, Shape, decide, keep_terms};
use crate::codes;

/// One `SURF` block as written, in lens units.
#[derive(Default)]
struct Raw {
    number: usize,
    /// The `SURF` line.
    span: Span,
    type_name: Option<String>,
    curv: f64,
    conic: f64,
    parms: BTreeMap<u32, (f64, Span)>,
    xdat: BTreeMap<u32, (f64, Span)>,
    semi_diameter: Option<f64>,
    glass: Option<String>,
    comment: String,
}

/// Reads a `.zmx` file's text; `None` (with errors in `diags`) if it cannot.
pub fn read(name: &str, text: &str, diags: &mut Vec<Diagnostic>) -> Option<Prescription> {
    let errors_before = diags.iter().filter(|d| d.is_error()).count();
    let mut scale = 1.0;
    let mut unit = "MM".to_string();
    let mut surfaces: Vec<Raw> = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let start = offset;
        offset += line.len();
        let content = line.trim_end_matches(['\r', '\n']);
        let lead = content.len() - content.trim_start().len();
        let mut words = content.split_whitespace();
        let Some(key) = words.next() else { continue };
        let rest: Vec<&str> = words.collect();
        let span = Span::new(start + lead, start + content.len());
        let mut number = |i: usize| -> Option<f64> {
            let w = rest.get(i).copied().unwrap_or("");
            match w.parse::<f64>() {
                Ok(v) if v.is_finite() => Some(v),
                Ok(_)
                    if !w.to_ascii_lowercase().contains("inf")
                        && !w.to_ascii_lowercase().contains("nan") =>
                {
                    diags.push(
                        Diagnostic::error(
                            codes::IMPORT_NOT_FINITE,
                            format!("`{key}` {w} is beyond the largest number lensc reads (about 1.8e308)"),
                            FileId(0),
                            span,
                        )
                        .with_help("a number this large is a damaged file or a value no design holds: write the value the design means"),
                    );
                    None
                }
                _ => {
                    diags.push(unreadable(
                        span,
                        format!("`{key}` needs a number here, not `{w}`"),
                    ));
                    None
                }
            }
        };
        match key {
            "MODE" if rest.first().is_some_and(|m| !m.eq_ignore_ascii_case("SEQ")) => {
                diags.push(
                    Diagnostic::error(
                        codes::IMPORT_NON_SEQUENTIAL,
                        format!("{name} is a non-sequential ({}) design", rest[0]),
                        FileId(0),
                        span,
                    )
                    .with_label("lensc imports sequential surfaces only")
                    .with_help("export the sequential part of the design (OpticStudio: Sequential mode) and import that"),
                );
                return None;
            }
            "UNIT" => {
                let u = rest.first().copied().unwrap_or("MM").to_ascii_uppercase();
                scale = match u.as_str() {
                    "MM" => 1.0,
                    "CM" => 10.0,
                    "IN" => 25.4,
                    "METER" | "M" => 1000.0,
                    _ => {
                        diags.push(unreadable(
                            span,
                            format!("lens unit `{u}` is not one of MM, CM, IN, METER"),
                        ));
                        1.0
                    }
                };
                unit = u;
            }
            "SURF" => {
                let n = number(0).unwrap_or(surfaces.len() as f64);
                surfaces.push(Raw {
                    number: n as usize,
                    span,
                    ..Raw::default()
                });
            }
            _ => {
                let Some(s) = surfaces.last_mut() else {
                    continue;
                };
                match key {
                    "TYPE" => s.type_name = rest.first().map(|t| t.to_string()),
                    "CURV" => s.curv = number(0).unwrap_or(0.0),
                    "CONI" => s.conic = number(0).unwrap_or(0.0),
                    "DIAM" => s.semi_diameter = number(0),
                    "GLAS" => s.glass = rest.first().map(|g| g.to_string()),
                    "COMM" => s.comment = content.trim_start()[4..].trim().to_string(),
                    "PARM" | "XDAT" => {
                        if let (Some(i), Some(v)) = (number(0), number(1)) {
                            let map = if key == "PARM" {
                                &mut s.parms
                            } else {
                                &mut s.xdat
                            };
                            map.insert(i as u32, (v, span));
                        }
                    }
                    _ => {}
                }
            }
        }
    }
    if diags.iter().filter(|d| d.is_error()).count() > errors_before {
        return None;
    }
    if surfaces.is_empty() {
        diags.push(unreadable(
            Span::new(0, 0),
            format!("{name} has no `SURF` lines: it is not a Zemax lens file"),
        ));
        return None;
    }
    let entries = surfaces_to_entries(&surfaces, scale, diags);
    Some(Prescription {
        source: name.to_string(),
        format: if unit == "MM" {
            "Zemax OpticStudio, lens units mm"
        } else {
            "Zemax OpticStudio, lens units converted to mm"
        },
        entries,
    })
}

/// The entries of the surfaces, with each one's medium before and after
/// it (a mirror keeps the medium it reflects back into).
fn surfaces_to_entries(
    surfaces: &[Raw],
    scale: f64,
    diags: &mut Vec<Diagnostic>,
) -> Vec<super::Entry> {
    let mut entries = Vec::new();
    let mut medium = surfaces[0].glass.clone().filter(|g| !is_air(g));
    let last = surfaces.len() - 1;
    for (i, s) in surfaces.iter().enumerate() {
        let type_name = s.type_name.clone().unwrap_or_else(|| "STANDARD".into());
        let before = medium.clone();
        let mirror = s
            .glass
            .as_deref()
            .is_some_and(|g| g.eq_ignore_ascii_case("MIRROR"));
        // A coordinate break moves the axes, not the light out of its medium.
        if i > 0 && !mirror && type_name != "COORDBRK" {
            medium = s.glass.clone().filter(|g| !is_air(g));
        }
        if type_name == "COORDBRK" {
            entries.push(coordinate_break(s, diags));
            continue;
        }
        let mut dropped = Vec::new();
        let shape = shape(s, &type_name, scale, &mut dropped);
        let found = Found {
            number: s.number,
            type_name,
            comment: s.comment.clone(),
            span: s.span,
            role: match i {
                0 => Role::Object,
                i if i == last => Role::Image,
                _ => Role::Optical,
            },
            shape,
            semi_diameter: s.semi_diameter.map(|d| d * scale),
            rear_of: if !mirror && medium.is_none() {
                before
            } else {
                None
            },
            dropped,
        };
        entries.push(decide(found, diags));
    }
    entries
}

/// A coordinate break: skipped, and a warning if it moves anything.
fn coordinate_break(s: &Raw, diags: &mut Vec<Diagnostic>) -> super::Entry {
    let moves = s.parms.values().any(|(v, _)| *v != 0.0);
    if moves {
        diags.push(
            Diagnostic::warning(
                codes::IMPORT_POSITION_IGNORED,
                format!("surface {} is a coordinate break (a decentre or tilt); the surfaces after it are imported about their own vertex", s.number),
                FileId(0),
                s.span,
            )
            .with_help("an off-axis part is cut about its own vertex: write the section with `off_axis(...)` or `tilt(...)` by hand"),
        );
    }
    super::Entry {
        number: s.number,
        type_name: "COORDBRK".into(),
        comment: s.comment.clone(),
        what: super::What::Skipped(if moves {
            "a coordinate break (a decentre or tilt), which the surfaces after it do not carry"
                .into()
        } else {
            "a coordinate break that moves nothing".into()
        }),
    }
}

/// The shape of a surface of a type lensc imports, in mm, or why not;
/// the parameters its type does not use go to `dropped`.
fn shape(
    s: &Raw,
    type_name: &str,
    scale: f64,
    dropped: &mut Vec<(Span, String)>,
) -> Result<Shape, String> {
    // A coefficient of (lens unit)^(1−j) in mm^(1−j).
    let coeff = |j: u32, a: f64| a * scale.powi(1 - j as i32);
    let parm = |i: u32| s.parms.get(&i).map_or(0.0, |(v, _)| *v);
    let curvature = s.curv / scale;
    let used: &[u32] = match type_name {
        "STANDARD" => &[],
        "EVENASPH" | "ODDASPHE" | "ODDASPH" => &[1, 2, 3, 4, 5, 6, 7, 8],
        "BICONICX" => &[1, 2],
        "TOROIDAL" => &[0, 1, 2, 3, 4, 5, 6, 7, 8],
        "XPOLYNOM" => &[],
        "SZERNSAG" => &[0],
        other => return Err(format!("lensc does not import Zemax {other} surfaces")),
    };
    if matches!(type_name, "XPOLYNOM" | "SZERNSAG") {
        for (i, (v, span)) in &s.parms {
            if *v != 0.0 && !used.contains(i) {
                let what = if type_name == "SZERNSAG" && (1..=8).contains(i) {
                    format!(
                        "the r^{} term α{i} = {v} (lensc's `zernike` has no power terms)",
                        2 * i
                    )
                } else {
                    format!("parameter {i} = {v} of a {type_name} surface")
                };
                dropped.push((*span, what));
            }
        }
        return extra_data_shape(s, type_name, scale, dropped);
    }
    for (i, (v, span)) in &s.parms {
        if *v != 0.0 && !used.contains(i) {
            dropped.push((
                *span,
                format!("parameter {i} = {v} of a {type_name} surface"),
            ));
        }
    }
    for (i, (v, span)) in &s.xdat {
        if *v != 0.0 {
            dropped.push((*span, format!("extra data {i} = {v}")));
        }
    }
    // The parameters `first`, `first + 1` … `last` are the coefficients
    // of r^power(1), r^power(2) …
    let terms =
        |power: &dyn Fn(u32) -> u32, first: u32, last: u32, dropped: &mut Vec<(Span, String)>| {
            let t = (first..=last).filter_map(|i| {
                let (v, span) = s.parms.get(&i)?;
                let j = power(i - first + 1);
                Some((j, coeff(j, *v), *span))
            });
            keep_terms(t, dropped)
        };
    Ok(match type_name {
        "STANDARD" => Shape::Rotational {
            curvature,
            conic: s.conic,
            terms: vec![],
        },
        "EVENASPH" => Shape::Rotational {
            curvature,
            conic: s.conic,
            terms: terms(&|i| 2 * i, 1, 8, dropped),
        },
        "ODDASPHE" | "ODDASPH" => Shape::Rotational {
            curvature,
            conic: s.conic,
            terms: terms(&|i| i, 1, 8, dropped),
        },
        "BICONICX" => Shape::Biconic {
            cx: if parm(1) == 0.0 {
                0.0
            } else {
                1.0 / (parm(1) * scale)
            },
            cy: curvature,
            kx: parm(2),
            ky: s.conic,
        },
        _ => Shape::Toroid {
            cy: curvature,
            conic: s.conic,
            rotation_radius: (parm(1) != 0.0).then(|| parm(1) * scale),
            terms: terms(&|i| 2 * i, 2, 8, dropped),
        },
    })
}

/// The shapes held in extra data: XDAT 1 the number of terms N, XDAT 2
/// the normalisation radius R, XDAT 3 … N+2 the terms' coefficients (lens
/// units). XPOLYNOM (extended polynomial): term t of x, y, x², xy, y², x³ …
/// over (x/R, y/R). SZERNSAG (Zernike standard sag): Noll's Z1 … ZN over
/// r/R, normalised, written in lensc's ANSI numbering.
fn extra_data_shape(
    s: &Raw,
    type_name: &str,
    scale: f64,
    dropped: &mut Vec<(Span, String)>,
) -> Result<Shape, String> {
    let xdat = |i: u32| s.xdat.get(&i).map_or(0.0, |(v, _)| *v);
    let count = xdat(1).max(0.0) as u32;
    let norm = xdat(2) * scale;
    if norm <= 0.0 {
        return Err("its normalisation radius (extra data 2) is not positive".into());
    }
    let mut terms = Vec::new();
    for (i, (v, span)) in &s.xdat {
        let t = i.wrapping_sub(2);
        if *i < 3 || *v == 0.0 {
            continue;
        }
        if t > count {
            dropped.push((
                *span,
                format!("extra data {i} = {v} (past the {count} terms extra data 1 counts)"),
            ));
            continue;
        }
        terms.push((t, v * scale, *span));
    }
    let (curvature, conic) = (s.curv / scale, s.conic);
    if type_name == "XPOLYNOM" {
        let mut kept = Vec::new();
        for (t, a, span) in terms {
            let (i, j) = xy_term(t);
            if i + j > super::TOP_POWER {
                dropped.push((
                    span,
                    format!("the x^{i} y^{j} term (lensc names powers up to 20)"),
                ));
            } else {
                kept.push((i, j, a / norm.powi((i + j) as i32)));
            }
        }
        return Ok(Shape::XyPolynomial {
            curvature,
            conic,
            terms: kept,
        });
    }
    let mut kept = Vec::new();
    for (t, a, span) in terms {
        let (n, m) = super::noll_nm(t);
        if n > super::TOP_POWER {
            dropped.push((
                span,
                format!("Zernike term {t} (radial order {n}; lensc goes to 20)"),
            ));
        } else {
            kept.push((super::ansi_index(n, m), a));
        }
    }
    kept.sort_by_key(|t| t.0);
    Ok(Shape::Zernike {
        curvature,
        conic,
        norm_radius: norm,
        terms: kept,
    })
}

/// (i, j) of the extended polynomial's term t (from 1): x, y, x², xy, y², x³ …
fn xy_term(t: u32) -> (u32, u32) {
    let mut degree = 1;
    let mut first = 1;
    while t > first + degree {
        first += degree + 1;
        degree += 1;
    }
    let j = t - first;
    (degree - j, j)
}

/// No glass: air (or a blank `GLAS`).
fn is_air(glass: &str) -> bool {
    glass.is_empty() || glass.eq_ignore_ascii_case("AIR")
}

fn unreadable(span: Span, msg: String) -> Diagnostic {
    Diagnostic::error(codes::IMPORT_UNREADABLE, msg, FileId(0), span)
}
