//! Reads an optiland JSON export (`optiland.fileio.save_optiland_file`,
//! the `Optic.to_dict()` of HarrisonKramer/optiland): the surfaces of
//! `surface_group.surfaces`, each with its `geometry` (`type`, `radius`,
//! `conic`, `coefficients`, `cs`), `material_pre`/`material_post`,
//! `aperture` (a `RadialAperture`'s `r_max` is the semi-diameter) and
//! `comment`. Lengths are in mm.
//!
//! Geometries: `Plane`; `StandardGeometry` (conic); `EvenAsphere`,
//! coefficient i (from 0) of r^(2i+2); `OddAsphere`, coefficient i of
//! r^(i+1); `BiconicGeometry` (`radius_x`, `radius_y`, `conic_x`,
//! `conic_y`). Python's `json` writes an infinite radius as `Infinity`,
//! which is read as flat. Any other geometry is named in a warning.

use lensc_grammar::{Diagnostic, FileId, Span};
use serde_json::Value;

use super::{Found, Prescription, Role, Shape, decide, keep_terms};
use crate::codes;

/// Reads an optiland JSON file's text; `None` (with errors in `diags`) if
/// it cannot.
pub fn read(name: &str, text: &str, diags: &mut Vec<Diagnostic>) -> Option<Prescription> {
    let value: Value = match serde_json::from_str(&finite_json(text)) {
        Ok(v) => v,
        Err(e) => {
            let at = line_offset(text, e.line(), e.column());
            diags.push(unreadable(
                Span::new(at, at),
                format!("{name} is not JSON: {e}"),
            ));
            return None;
        }
    };
    let Some(surfaces) = value
        .pointer("/surface_group/surfaces")
        .and_then(Value::as_array)
    else {
        diags.push(unreadable(
            Span::new(0, 0),
            format!("{name} has no `surface_group.surfaces`: it is not an optiland lens file"),
        ));
        return None;
    };
    let spans = geometry_spans(text);
    let last = surfaces.len().saturating_sub(1);
    let mut entries = Vec::new();
    for (i, s) in surfaces.iter().enumerate() {
        let span = spans.get(i).copied().unwrap_or(Span::new(0, 0));
        let g = &s["geometry"];
        let type_name = g["type"].as_str().unwrap_or("?").to_string();
        let mut dropped = Vec::new();
        let shape = shape(g, &type_name, span, &mut dropped);
        let role = match i {
            0 => Role::Object,
            i if i == last => Role::Image,
            _ => Role::Optical,
        };
        if role == Role::Optical {
            position(g, i, span, diags);
        }
        let (semi_diameter, inner) = aperture(&s["aperture"]);
        if inner != 0.0 {
            dropped.push((
                span,
                format!("the aperture's inner radius r_min = {inner} mm"),
            ));
        }
        let before = material(&s["material_pre"]);
        let after = material(&s["material_post"]);
        let mirror =
            s["is_reflective"].as_bool() == Some(true) || after.as_deref() == Some("mirror");
        let found = Found {
            number: i,
            type_name,
            comment: s["comment"].as_str().unwrap_or("").to_string(),
            span,
            role,
            shape,
            semi_diameter,
            rear_of: if !mirror && after.is_none() {
                before
            } else {
                None
            },
            dropped,
        };
        entries.push(decide(found, diags));
    }
    Some(Prescription {
        source: name.to_string(),
        format: "optiland JSON, lengths in mm",
        entries,
    })
}

/// The shape of a geometry lensc imports, or why not.
fn shape(
    g: &Value,
    type_name: &str,
    span: Span,
    dropped: &mut Vec<(Span, String)>,
) -> Result<Shape, String> {
    let curvature = match number(&g["radius"]) {
        Some(r) if r.is_finite() && r != 0.0 => 1.0 / r,
        _ => 0.0,
    };
    let conic = number(&g["conic"]).unwrap_or(0.0);
    let coefficients: Vec<f64> = g["coefficients"]
        .as_array()
        .map(|a| a.iter().map(|v| number(v).unwrap_or(f64::NAN)).collect())
        .unwrap_or_default();
    if coefficients.iter().any(|c| !c.is_finite()) {
        return Err("a coefficient is not a finite number".into());
    }
    let terms = |power: fn(u32) -> u32, dropped: &mut Vec<(Span, String)>| {
        let t = coefficients
            .iter()
            .enumerate()
            .map(|(i, a)| (power(i as u32), *a, span));
        keep_terms(t, dropped)
    };
    match type_name {
        "Plane" | "StandardGeometry" => Ok(Shape::Rotational {
            curvature,
            conic,
            terms: vec![],
        }),
        "EvenAsphere" => Ok(Shape::Rotational {
            curvature,
            conic,
            terms: terms(|i| 2 * i + 2, dropped),
        }),
        "OddAsphere" => Ok(Shape::Rotational {
            curvature,
            conic,
            terms: terms(|i| i + 1, dropped),
        }),
        "BiconicGeometry" => {
            let c = |key: &str| match number(&g[key]) {
                Some(r) if r.is_finite() && r != 0.0 => 1.0 / r,
                _ => 0.0,
            };
            Ok(Shape::Biconic {
                cx: c("radius_x"),
                cy: c("radius_y"),
                kx: number(&g["conic_x"]).unwrap_or(0.0),
                ky: number(&g["conic_y"]).unwrap_or(0.0),
            })
        }
        other => Err(format!("lensc does not import optiland {other} geometries")),
    }
}

/// Warns when a surface's coordinate system is decentred or tilted.
fn position(g: &Value, i: usize, span: Span, diags: &mut Vec<Diagnostic>) {
    let moved: Vec<&str> = ["x", "y", "rx", "ry", "rz"]
        .into_iter()
        .filter(|k| number(&g["cs"][*k]).is_some_and(|v| v != 0.0))
        .collect();
    if !moved.is_empty() {
        diags.push(
            Diagnostic::warning(
                codes::IMPORT_POSITION_IGNORED,
                format!(
                    "surface {i} is decentred or tilted ({}); it is imported about its own vertex",
                    moved.join(", ")
                ),
                FileId(0),
                span,
            )
            .with_help("an off-axis part is cut about its own vertex: write the section with `off_axis(...)` or `tilt(...)` by hand"),
        );
    }
}

/// The semi-diameter (a `RadialAperture`'s `r_max`) and inner radius.
fn aperture(a: &Value) -> (Option<f64>, f64) {
    if a["type"].as_str() != Some("RadialAperture") {
        return (None, 0.0);
    }
    (number(&a["r_max"]), number(&a["r_min"]).unwrap_or(0.0))
}

/// A material's name, `None` for air (an ideal material of index 1),
/// `mirror` for a mirror.
fn material(m: &Value) -> Option<String> {
    match m["type"].as_str() {
        None => None,
        Some("Mirror") => Some("mirror".into()),
        Some("IdealMaterial") if number(&m["index"]) == Some(1.0) => None,
        Some(t) => Some(
            m["name"]
                .as_str()
                .map(str::to_string)
                .or_else(|| number(&m["index"]).map(|n| format!("a material of index {n}")))
                .unwrap_or_else(|| t.to_string()),
        ),
    }
}

/// A number, a one-element list of one (optiland writes arrays), or the
/// infinities `finite_json` turned into strings.
fn number(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => n.as_f64(),
        Value::Array(a) if a.len() == 1 => number(&a[0]),
        Value::String(s) if s == "Infinity" => Some(f64::INFINITY),
        Value::String(s) if s == "-Infinity" => Some(f64::NEG_INFINITY),
        _ => None,
    }
}

/// Python's `json` writes `Infinity`, `-Infinity` and `NaN`, which JSON
/// has not: outside strings they become the strings `"Infinity"`,
/// `"-Infinity"` and `"NaN"`, so the file parses and `number` reads them.
fn finite_json(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut in_string = false;
    let mut escaped = false;
    let mut rest = text;
    while let Some(c) = rest.chars().next() {
        if in_string {
            in_string = escaped || c != '"';
            escaped = !escaped && c == '\\';
        } else if c == '"' {
            in_string = true;
        } else if let Some(word) = ["-Infinity", "Infinity", "NaN"]
            .into_iter()
            .find(|w| rest.starts_with(w))
        {
            out.push('"');
            out.push_str(word);
            out.push('"');
            rest = &rest[word.len()..];
            continue;
        }
        out.push(c);
        rest = &rest[c.len_utf8()..];
    }
    out
}

/// Where each surface's `"geometry"` key is: the span its warnings point at.
fn geometry_spans(text: &str) -> Vec<Span> {
    text.match_indices("\"geometry\"")
        .map(|(i, m)| Span::new(i, i + m.len()))
        .collect()
}

/// The byte offset of a 1-based line and column.
fn line_offset(text: &str, line: usize, column: usize) -> usize {
    let start: usize = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    let mut at = (start + column.saturating_sub(1)).min(text.len());
    // A column that falls inside a character (serde counts bytes of the
    // text it was given, which `finite_json` and a `�` read in place of
    // a byte that is not UTF-8 lengthen) is moved back to its start.
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    at
}

fn unreadable(span: Span, msg: String) -> Diagnostic {
    Diagnostic::error(codes::IMPORT_UNREADABLE, msg, FileId(0), span)
}
