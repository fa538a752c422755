//! Where a checked surface is defined: its aperture (or a freeform's
//! domain) as the runtime's `Domain`, and the radii of circular and
//! annular apertures. Shared by the checker's rules and by lowering.

use lensc_runtime::surface::analysis::Domain;

use crate::value::{self, Object};

/// The outer radius of a circular or annular aperture.
pub fn aperture_radius(ap: &Object) -> Option<f64> {
    match ap.kind.name {
        "circle" => value::num(&ap.fields, "radius")
            .or_else(|| value::num(&ap.fields, "diameter").map(|d| d / 2.0)),
        "annulus" => value::num(&ap.fields, "outer"),
        _ => None,
    }
}

/// The inner radius of an annular aperture (0 for a circle).
pub fn aperture_inner_radius(ap: &Object) -> f64 {
    if ap.kind.name == "annulus" {
        value::num(&ap.fields, "inner").unwrap_or(0.0)
    } else {
        0.0
    }
}

/// The region a surface is defined on: its aperture, or its domain.
pub fn region(o: &Object) -> Option<&Object> {
    value::object(&o.fields, "aperture")
        .or_else(|| value::object(&o.fields, "domain"))
        .map(|r| &**r)
}

/// The domain a checked surface is evaluated over, if it can be lowered.
pub fn surface_domain(o: &Object) -> Option<Domain> {
    match region(o) {
        Some(r) => domain_of(r).ok(),
        None if matches!(o.kind.name, "grid" | "hex_grid" | "linear_array") => array_domain(o),
        None => value::object(&o.fields, "surface").and_then(|s| surface_domain(s)),
    }
}

/// The domain of aperture `ap`, or the kind of aperture that lacks a size.
pub fn domain_of(ap: &Object) -> Result<Domain, &'static str> {
    match ap.kind.name {
        "circle" => aperture_radius(ap)
            .map(|radius| Domain::Circle { radius })
            .ok_or("circle"),
        "annulus" => match (
            value::num(&ap.fields, "inner"),
            value::num(&ap.fields, "outer"),
        ) {
            (Some(inner), Some(outer)) => Ok(Domain::Annulus { inner, outer }),
            _ => Err("annulus"),
        },
        "rect" => match (value::range(&ap.fields, "x"), value::range(&ap.fields, "y")) {
            (Some(x), Some(y)) => Ok(Domain::Rect { x, y }),
            _ => Err("rect"),
        },
        _ => Err("unknown aperture"),
    }
}

/// The rectangle of every cell of an array (count × pitch), centred on
/// the origin: a wrapped array closes on itself when its cells do.
fn array_domain(o: &Object) -> Option<Domain> {
    let f = &o.fields;
    let lenslet = value::object(f, "lenslet")?;
    let ap = domain_of(region(lenslet)?).ok()?;
    let (hx, hy) = half_extent(&ap);
    let num = |name: &str| value::num(f, name).unwrap_or(1.0);
    let (ex, ey) = match o.kind.name {
        "grid" => (
            num("count_x") * num("pitch_x") / 2.0,
            num("count_y") * num("pitch_y") / 2.0,
        ),
        "hex_grid" => (
            num("count_x") * num("pitch") / 2.0 + num("pitch") / 4.0,
            num("count_y") * num("pitch") * 3f64.sqrt() / 4.0,
        ),
        _ if value::word(f, "axis") == Some("y") => (hx, num("count") * num("pitch") / 2.0),
        _ => (num("count") * num("pitch") / 2.0, hy),
    };
    Some(Domain::Rect {
        x: (-ex, ex),
        y: (-ey, ey),
    })
}

/// Half the extent of a lenslet's aperture along x and y.
pub fn half_extent(d: &Domain) -> (f64, f64) {
    match *d {
        Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => (radius, radius),
        Domain::Rect { x, y } => (x.0.abs().max(x.1.abs()), y.0.abs().max(y.1.abs())),
    }
}
