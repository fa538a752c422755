//! Seed 004's profile, for the envelope's tests and the tool-location
//! bench (each includes this file with `#[path]`; its parent module brings
//! `Profile` and `ProfilePoint` into scope).

use super::{Profile, ProfilePoint};

/// Convex circular arcs of radius R, width w, separated by flat seams
/// of width s at z = 0 (Lei et al. 2021's cylinder array profile).
pub struct Arcs {
    pub r: f64,
    pub w: f64,
    pub s: f64,
}

impl Profile for Arcs {
    fn point(&self, u: f64) -> ProfilePoint {
        let p = self.w + self.s;
        let c = (u / p).floor() * p + 0.5 * p;
        let d = u - c;
        if d.abs() > 0.5 * self.w {
            return ProfilePoint {
                z: 0.0,
                dz: 0.0,
                d2z: 0.0,
            };
        }
        let rim = (self.r * self.r - 0.25 * self.w * self.w).sqrt();
        let q = (self.r * self.r - d * d).sqrt();
        ProfilePoint {
            z: q - rim,
            dz: -d / q,
            d2z: -self.r * self.r / (q * q * q),
        }
    }
}

/// Lei et al. 2021: R = 0.788 mm, width 0.534 mm, 20 µm seams.
pub fn lei() -> Arcs {
    Arcs {
        r: 0.788,
        w: 0.534,
        s: 0.02,
    }
}
