//! Where a checked surface is defined: its aperture (or a freeform's
//! domain) as the runtime's `Domain`, and the radii of circular and
//! annular apertures. Shared by the checker's rules and by lowering; the
//! parameters come read once (`schema::Aperture`, `schema::Surface`).

use lensc_runtime::surface::analysis::Domain;

use crate::schema::{Aperture, Array, Axis, Layout, Surface};
use crate::value::Object;

/// The outer radius of a circular or annular aperture.
pub fn aperture_radius(ap: &Object) -> Option<f64> {
    Aperture::read(ap).ok()?.radius()
}

/// The inner radius of an annular aperture (0 for a circle).
pub fn aperture_inner_radius(ap: &Object) -> f64 {
    Aperture::read(ap).map_or(0.0, |a| a.inner_radius())
}

/// An aperture as the runtime's domain.
pub fn aperture_domain(ap: &Aperture) -> Domain {
    match *ap {
        Aperture::Circle { radius } => Domain::Circle { radius },
        Aperture::Annulus { inner, outer } => Domain::Annulus { inner, outer },
        Aperture::Rect { x, y } => Domain::Rect { x, y },
    }
}

/// The domain a checked surface is evaluated over, if it can be lowered.
pub fn surface_domain(o: &Object) -> Option<Domain> {
    domain(&Surface::read(o).ok()?)
}

/// The domain a surface is evaluated over: its aperture or domain; an
/// array's cells where it states no aperture; a wrapped design's.
pub fn domain(s: &Surface) -> Option<Domain> {
    match (s.region(), s) {
        (Some(ap), _) => Some(aperture_domain(ap)),
        (None, Surface::Array(a)) => array_domain(a),
        (None, Surface::Wrap(w)) => domain(&w.surface),
        (None, _) => None,
    }
}

/// The rectangle of every cell of an array (count × pitch), centred on
/// the origin: a wrapped array closes on itself when its cells do.
fn array_domain(a: &Array) -> Option<Domain> {
    let ap = aperture_domain(a.lenslet.region()?);
    let (hx, hy) = half_extent(&ap);
    let (ex, ey) = match a.layout {
        Layout::Grid {
            pitch_x,
            pitch_y,
            count_x,
            count_y,
        } => (count_x * pitch_x / 2.0, count_y * pitch_y / 2.0),
        Layout::Hex {
            pitch,
            count_x,
            count_y,
        } => (
            count_x * pitch / 2.0 + pitch / 4.0,
            count_y * pitch * 3f64.sqrt() / 4.0,
        ),
        Layout::Linear {
            pitch,
            count,
            axis: Axis::Y,
        } => (hx, count * pitch / 2.0),
        Layout::Linear {
            pitch,
            count,
            axis: Axis::X,
        } => (count * pitch / 2.0, hy),
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
