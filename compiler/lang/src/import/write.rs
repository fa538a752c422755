//! Writes an imported prescription as `.lens` text: a header comment, then
//! for each source surface a comment naming the file, the surface's number,
//! type and comment, and either its `surface` block (the simplest kind
//! that says it exactly, the designer's sign kept with `convention:
//! optical`, the aperture from the semi-diameter) or why it was skipped.
//! The caller puts the text in the canonical layout.

use std::fmt::Write as _;

use super::{Entry, Prescription, Shape, Surface, What};

/// The `.lens` text of a prescription (not yet in canonical layout).
pub(super) fn lens_text(p: &Prescription) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// Imported by `lensc import` from {} ({}).\n\
         // Each surface keeps the lens designer's signs with `convention: optical`\n\
         // (light along +z into the material, R > 0 convex to the tool); a lens's\n\
         // rear surface is written as the tool meets it, with the part turned over.\n\
         // Apertures are the surfaces' semi-diameters; lengths are in mm.",
        clean(&p.source),
        p.format
    );
    for e in &p.entries {
        out.push('\n');
        let _ = write!(
            out,
            "// {} surface {} ({})",
            clean(&p.source),
            e.number,
            clean(&e.type_name)
        );
        if !e.comment.trim().is_empty() {
            let _ = write!(out, " \"{}\"", clean(e.comment.trim()));
        }
        match &e.what {
            What::Skipped(why) => {
                let _ = writeln!(out, ": not imported, {why}.");
            }
            What::Surface(s) => {
                out.push_str(".\n");
                surface(&mut out, e, s);
            }
        }
    }
    out
}

/// One surface's comments and block.
fn surface(out: &mut String, e: &Entry, s: &Surface) {
    for d in &s.dropped {
        let _ = writeln!(out, "// Not imported: {}.", clean(d));
    }
    let shape = match &s.rear_of {
        Some(glass) => {
            let _ = writeln!(
                out,
                "// A rear surface ({} before it): the tool meets it with the part turned\n\
                 // over about y, so this is the designer's sag reversed in sign (and in x).",
                clean(glass)
            );
            s.shape.turned_over()
        }
        None => s.shape.clone(),
    };
    let name = format!("surface_{}", e.number);
    let aperture = format!("circle(radius: {} mm)", num(s.semi_diameter));
    let mut fields: Vec<String> = Vec::new();
    let kind = match &shape {
        Shape::Rotational {
            curvature,
            conic,
            terms,
        } if *curvature != 0.0 => {
            fields.push(format!("radius: {} mm", num(1.0 / curvature)));
            let kind = if !terms.is_empty() {
                "asphere"
            } else if *conic != 0.0 {
                "conic"
            } else {
                "sphere"
            };
            if kind != "sphere" {
                fields.push(format!("conic: {}", num(*conic)));
            }
            optical(&mut fields, &aperture);
            fields.extend(coefficients(terms));
            kind
        }
        Shape::Rotational { terms, .. } => {
            return formula(out, &name, &aperture, &rotational_formula(terms));
        }
        Shape::Biconic { cx, cy, kx, ky } if *cx != 0.0 && *cy != 0.0 => {
            fields.push(format!("radius_x: {} mm", num(1.0 / cx)));
            fields.push(format!("radius_y: {} mm", num(1.0 / cy)));
            fields.push(format!("conic_x: {}", num(*kx)));
            fields.push(format!("conic_y: {}", num(*ky)));
            optical(&mut fields, &aperture);
            "biconic"
        }
        Shape::Biconic { cx, cy, kx, ky } => {
            // One section flat: a profile across the other, extruded.
            let (c, k, axis) = if *cx == 0.0 {
                (cy, ky, "x")
            } else {
                (cx, kx, "y")
            };
            extruded(&mut fields, *c, *k, axis, &[], &aperture)
        }
        Shape::Toroid {
            cy,
            conic,
            rotation_radius: None,
            terms,
        } if *cy != 0.0 => extruded(&mut fields, *cy, *conic, "x", terms, &aperture),
        Shape::Toroid {
            rotation_radius: None,
            terms,
            ..
        } => {
            return formula(out, &name, &aperture, &profile_formula(terms));
        }
        Shape::Toroid {
            cy,
            conic,
            rotation_radius: Some(r),
            terms,
        } => {
            fields.push(format!("radius: {} mm", num(1.0 / cy)));
            fields.push(format!("conic: {}", num(*conic)));
            fields.push(format!("rotation_radius: {} mm", num(r.abs())));
            optical(&mut fields, &aperture);
            fields.extend(coefficients(terms));
            "toroid"
        }
        Shape::XyPolynomial {
            curvature,
            conic,
            terms,
        } => {
            base(&mut fields, *curvature, *conic);
            optical(&mut fields, &aperture);
            fields.extend(
                terms
                    .iter()
                    .map(|(i, j, c)| format!("X{i}Y{j}: {}", coefficient(i + j, *c))),
            );
            "xy_polynomial"
        }
        Shape::Zernike {
            curvature,
            conic,
            norm_radius,
            terms,
        } => {
            base(&mut fields, *curvature, *conic);
            optical(&mut fields, &aperture);
            fields.push(format!("norm_radius: {} mm", num(*norm_radius)));
            fields.push("ordering: ansi".into());
            fields.extend(terms.iter().map(|(j, a)| format!("Z{j}: {} mm", num(*a))));
            "zernike"
        }
    };
    let _ = writeln!(out, "surface {name} = {kind} {{");
    for f in fields {
        let _ = writeln!(out, "    {f}");
    }
    out.push_str("}\n");
}

/// The conic base of a polynomial or Zernike surface (none when flat).
fn base(fields: &mut Vec<String>, curvature: f64, conic: f64) {
    if curvature != 0.0 {
        fields.push(format!("radius: {} mm", num(1.0 / curvature)));
        fields.push(format!("conic: {}", num(conic)));
    }
}

/// `convention: optical` and the aperture.
fn optical(fields: &mut Vec<String>, aperture: &str) {
    fields.push("convention: optical".into());
    fields.push(format!("aperture: {aperture}"));
}

/// A profile of curvature `c` across `axis`'s other direction, extruded
/// along `axis`: a cylinder, or an acylinder with a conic or terms.
fn extruded(
    fields: &mut Vec<String>,
    c: f64,
    k: f64,
    axis: &str,
    terms: &[(u32, f64)],
    aperture: &str,
) -> &'static str {
    fields.push(format!("radius: {} mm", num(1.0 / c)));
    let plain = k == 0.0 && terms.is_empty();
    if !plain {
        fields.push(format!("conic: {}", num(k)));
    }
    fields.push(format!("axis: {axis}"));
    optical(fields, aperture);
    fields.extend(coefficients(terms));
    if plain { "cylinder" } else { "acylinder" }
}

/// A flat base with terms, which no kind with a radius can say: a
/// freeform formula, the sign written out (z is the height the tool sees,
/// the designer's sag negated).
fn formula(out: &mut String, name: &str, aperture: &str, sum: &str) {
    out.push_str(
        "// A flat base with aspheric terms: written as a formula, the designer's\n\
         // sag with its sign reversed (z is the height towards the tool).\n",
    );
    let _ = writeln!(out, "surface {name} = freeform {{");
    let _ = writeln!(out, "    z(x, y) = -({sum})");
    let _ = writeln!(out, "    domain: {aperture}");
    out.push_str("}\n");
}

/// Σ a_j r^j as a formula of x and y.
fn rotational_formula(terms: &[(u32, f64)]) -> String {
    terms
        .iter()
        .map(|(j, a)| match j {
            1 => format!("{} * sqrt(x^2 + y^2)", coefficient(*j, *a)),
            _ => format!("{} * sqrt(x^2 + y^2)^{j}", coefficient(*j, *a)),
        })
        .collect::<Vec<_>>()
        .join(" + ")
}

/// Σ a_j |y|^j as a formula of y.
fn profile_formula(terms: &[(u32, f64)]) -> String {
    terms
        .iter()
        .map(|(j, a)| match j {
            1 => format!("{} * abs(y)", coefficient(*j, *a)),
            _ => format!("{} * abs(y)^{j}", coefficient(*j, *a)),
        })
        .collect::<Vec<_>>()
        .join(" + ")
}

/// `A4: 2.1e-4 mm^-3` for each term.
fn coefficients(terms: &[(u32, f64)]) -> Vec<String> {
    terms
        .iter()
        .map(|(j, a)| format!("A{j}: {}", coefficient(*j, *a)))
        .collect()
}

/// A coefficient of r^j with its unit, mm^(1−j).
fn coefficient(j: u32, a: f64) -> String {
    match j {
        0 => format!("{} mm", num(a)),
        1 => num(a),
        _ => format!("{} mm^-{}", num(a), j - 1),
    }
}

/// A number as short as it can be written and still read back within two
/// units in the last place (so a unit conversion's last-digit noise,
/// 31.749999999999993, is written 31.75): plain where that is short, in
/// exponent form for the very small and very large.
pub(super) fn num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return "0".into();
    }
    let ulp = f64::from_bits(v.abs().to_bits() + 1) - v.abs();
    let close = (0..17)
        .map(|p| format!("{v:.p$e}"))
        .filter_map(|s| s.parse::<f64>().ok())
        .find(|r| (r - v).abs() <= 2.0 * ulp)
        .unwrap_or(v);
    if (1e-4..1e7).contains(&close.abs()) {
        format!("{close}")
    } else {
        format!("{close:e}")
    }
}

/// Text safe inside a line comment: no line breaks or control characters.
fn clean(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}
