//! Rotationally symmetric optical surfaces: conic of revolution plus a
//! polynomial in |r| whose every term is named by its power, with exact
//! first and second derivatives in closed form.
//!
//! Sign rule (documented in README): the part's +z axis points out of the
//! material, towards the tool. A `concave` surface is a bowl (z rises with
//! r), a `convex` one a dome (z falls with r). The sag formula gives the
//! magnitude; the sense gives the sign: z(r) = s · sag(r), s = +1 concave,
//! s = −1 convex — the same s as Lin 2022 (seed 000) eq 7.

pub mod analysis;
pub mod conformance;
pub mod fdlibm;
pub mod forbes;
pub mod ir;
#[cfg(feature = "jit")]
pub mod jit;

/// Which side of the surface the material is on, as seen by the tool.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sense {
    /// A dome: material under the bump.
    Convex,
    /// A bowl.
    Concave,
}

impl Sense {
    /// Lin's s: +1 concave, −1 convex.
    pub fn sign(self) -> f64 {
        match self {
            Sense::Convex => -1.0,
            Sense::Concave => 1.0,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Sense::Convex => "convex",
            Sense::Concave => "concave",
        }
    }
}

/// A conic of revolution with optional polynomial terms Σ A_j |r|^j.
#[derive(Clone, Debug, PartialEq)]
pub struct RotationalSurface {
    /// Vertex radius of curvature R (mm), positive.
    pub radius: f64,
    /// Conic constant k (0 sphere, −1 paraboloid, < −1 hyperboloid).
    pub conic: f64,
    pub sense: Sense,
    /// `(j, A_j)` with A_j in mm^(1−j); any powers 1..=20, each at most once.
    pub terms: Vec<(u32, f64)>,
    /// Radius of the circular aperture (mm).
    pub aperture_radius: f64,
}

/// Sag and its exact derivatives at one radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfilePoint {
    pub z: f64,
    pub dz: f64,
    pub d2z: f64,
}

/// A section z(r) of a rotationally symmetric surface with its exact
/// first and second derivatives: what profile turning follows.
pub trait Profile {
    fn point(&self, r: f64) -> ProfilePoint;
}

impl Profile for RotationalSurface {
    fn point(&self, r: f64) -> ProfilePoint {
        self.eval(r)
    }
}

/// Any evaluated surface read along +x at y = 0 (for a surface of
/// revolution, its profile): z, ∂z/∂x and ∂²z/∂x².
pub struct SectionAlongX<'a>(pub &'a dyn crate::surface::ir::SurfaceFn);

impl Profile for SectionAlongX<'_> {
    fn point(&self, r: f64) -> ProfilePoint {
        let o = self.0.eval(r, 0.0);
        ProfilePoint {
            z: o[0],
            dz: o[1],
            d2z: o[3],
        }
    }
}

/// What a program header says about the surface it makes.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceInfo {
    /// Kind and parameters in words, with the material side.
    pub description: String,
    /// Outer radius of the aperture (mm).
    pub aperture_radius: f64,
}

impl RotationalSurface {
    /// The largest radius where the conic is defined, if it is bounded
    /// (1 − (1+k) r²/R² ≥ 0).
    pub fn conic_limit(radius: f64, conic: f64) -> Option<f64> {
        (conic > -1.0).then(|| radius / (1.0 + conic).sqrt())
    }

    /// z(r), dz/dr and d²z/dr² in the part frame (sense applied).
    pub fn eval(&self, r: f64) -> ProfilePoint {
        let c = 1.0 / self.radius;
        let u = 1.0 - (1.0 + self.conic) * c * c * r * r;
        let root = u.sqrt();
        let mut z = c * r * r / (1.0 + root);
        let mut dz = c * r / root;
        let mut d2z = c / (u * root);
        let a = r.abs();
        let sgn = if r < 0.0 { -1.0 } else { 1.0 };
        for &(j, aj) in &self.terms {
            let jf = f64::from(j);
            z += aj * a.powi(j as i32);
            dz += sgn * jf * aj * a.powi(j as i32 - 1);
            if j >= 2 {
                d2z += jf * (jf - 1.0) * aj * a.powi(j as i32 - 2);
            }
        }
        let s = self.sense.sign();
        ProfilePoint {
            z: s * z,
            dz: s * dz,
            d2z: s * d2z,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn surf(k: f64, sense: Sense, terms: Vec<(u32, f64)>) -> RotationalSurface {
        RotationalSurface {
            radius: 4.0,
            conic: k,
            sense,
            terms,
            aperture_radius: 1.5,
        }
    }

    #[test]
    fn sphere_sag_matches_closed_form() {
        // A sphere of radius R: sag = R − sqrt(R² − r²).
        let s = surf(0.0, Sense::Concave, vec![]);
        for r in [0.0, 0.3, 1.0, 1.5] {
            let want = 4.0 - (16.0f64 - r * r).sqrt();
            assert!((s.eval(r).z - want).abs() < 1e-15, "r={r}");
        }
        assert!(
            (surf(0.0, Sense::Convex, vec![]).eval(1.0).z + (4.0 - 15f64.sqrt())).abs() < 1e-15
        );
    }

    #[test]
    fn paraboloid_is_r2_over_2r() {
        let s = surf(-1.0, Sense::Concave, vec![]);
        assert!((s.eval(1.2).z - 1.44 / 8.0).abs() < 1e-15);
    }

    #[test]
    fn derivatives_agree_with_finite_differences() {
        for sense in [Sense::Convex, Sense::Concave] {
            let s = surf(-0.5, sense, vec![(3, 1e-3), (4, -2e-4), (6, 3e-6)]);
            for r in [0.1, 0.7, 1.4] {
                let h = 1e-5;
                let p = s.eval(r);
                let fd1 = (s.eval(r + h).z - s.eval(r - h).z) / (2.0 * h);
                let fd2 = (s.eval(r + h).z - 2.0 * p.z + s.eval(r - h).z) / (h * h);
                assert!((p.dz - fd1).abs() < 1e-9, "dz {} vs {fd1}", p.dz);
                assert!((p.d2z - fd2).abs() < 1e-5, "d2z {} vs {fd2}", p.d2z);
            }
        }
    }

    #[test]
    fn conic_limit_is_where_the_root_vanishes() {
        let lim = RotationalSurface::conic_limit(3.0, 10.0).unwrap();
        assert!((lim - 3.0 / 11f64.sqrt()).abs() < 1e-15);
        assert!(RotationalSurface::conic_limit(1.0, -20.0).is_none());
    }
}
