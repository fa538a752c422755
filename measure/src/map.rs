//! The one model every reader produces: a height map on a regular grid,
//! a cloud of points, or a profile, in millimetres, each point valid or
//! not (the instrument's invalid-pixel mask, kept as a mask: an invalid
//! point's height is never a number anyone reads).

/// Heights on a regular grid: point (i, j) at x = x0 + i·dx, y = y0 + j·dy
/// (mm), row-major with x fastest.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightMap {
    pub nx: usize,
    pub ny: usize,
    /// Pixel spacing along x and y (mm), positive.
    pub dx: f64,
    pub dy: f64,
    /// The first point's position (mm).
    pub x0: f64,
    pub y0: f64,
    /// Heights (mm), `nx · ny`; 0 where `valid` is false.
    pub z: Vec<f64>,
    /// Whether each point was measured.
    pub valid: Vec<bool>,
}

impl HeightMap {
    /// A map from heights in which a non-finite value marks an invalid point.
    pub fn from_heights(nx: usize, ny: usize, (dx, dy): (f64, f64), z: Vec<f64>) -> HeightMap {
        let valid: Vec<bool> = z.iter().map(|v| v.is_finite()).collect();
        let z = z
            .into_iter()
            .map(|v| if v.is_finite() { v } else { 0.0 })
            .collect();
        HeightMap {
            nx,
            ny,
            dx,
            dy,
            x0: 0.0,
            y0: 0.0,
            z,
            valid,
        }
    }

    pub fn x(&self, i: usize) -> f64 {
        self.x0 + i as f64 * self.dx
    }

    pub fn y(&self, j: usize) -> f64 {
        self.y0 + j as f64 * self.dy
    }

    /// How many points are valid.
    pub fn valid_count(&self) -> usize {
        self.valid.iter().filter(|v| **v).count()
    }

    /// The valid points as (x, y, z), mm.
    pub fn points(&self) -> Vec<[f64; 3]> {
        let mut out = Vec::with_capacity(self.valid_count());
        for j in 0..self.ny {
            for i in 0..self.nx {
                let k = j * self.nx + i;
                if self.valid[k] {
                    out.push([self.x(i), self.y(j), self.z[k]]);
                }
            }
        }
        out
    }

    /// The map moved so its centre pixel sits at x = y = 0 (an
    /// interferometer's map is centred on the part; the file's origin is
    /// its corner).
    pub fn centred(mut self) -> HeightMap {
        self.x0 = -(self.nx as f64 - 1.0) * self.dx / 2.0;
        self.y0 = -(self.ny as f64 - 1.0) * self.dy / 2.0;
        self
    }

    /// Root mean square of the valid heights about their mean (mm).
    pub fn rms_about_mean(&self) -> f64 {
        let n = self.valid_count() as f64;
        let mean = self.valid_heights().sum::<f64>() / n;
        (self
            .valid_heights()
            .map(|z| (z - mean).powi(2))
            .sum::<f64>()
            / n)
            .sqrt()
    }

    fn valid_heights(&self) -> impl Iterator<Item = f64> + '_ {
        self.z
            .iter()
            .zip(&self.valid)
            .filter(|(_, v)| **v)
            .map(|(z, _)| *z)
    }
}

/// Points measured anywhere (x, y, z), mm.
#[derive(Clone, Debug, PartialEq)]
pub struct PointCloud {
    pub points: Vec<[f64; 3]>,
}

/// A stylus profile along x: heights z at positions x (mm), in order.
#[derive(Clone, Debug, PartialEq)]
pub struct Profile2d {
    pub x: Vec<f64>,
    pub z: Vec<f64>,
}

/// What a file holds.
#[derive(Clone, Debug, PartialEq)]
pub enum Measured {
    Map(HeightMap),
    Cloud(PointCloud),
    Profile(Profile2d),
}

/// The formats lensc reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// ISO 25178-72 (ISO 5436-2) XML 3D surface profile: a zip archive.
    X3p,
    /// ISO 25178-71 surface data file, text (`aISO-1.0`, `aBCR-1.0`).
    Sdf,
    /// Zygo MetroPro's binary `.dat`.
    MetroProDat,
    /// Zygo MetroPro's ASCII export (`Zygo ASCII Data File - Format 2`).
    MetroProAscii,
    /// x y z per line, separated by spaces, tabs, commas or semicolons.
    Xyz,
    /// x z per line: a stylus profile.
    Profile,
}

impl Format {
    pub fn name(self) -> &'static str {
        match self {
            Format::X3p => "x3p",
            Format::Sdf => "sdf",
            Format::MetroProDat => "metropro_dat",
            Format::MetroProAscii => "metropro_ascii",
            Format::Xyz => "xyz",
            Format::Profile => "profile",
        }
    }
}

/// A file read: what it holds, in which format, and what it says of itself.
#[derive(Clone, Debug, PartialEq)]
pub struct Measurement {
    pub format: Format,
    pub data: Measured,
    /// The instrument or software that wrote it, if the file says.
    pub instrument: Option<String>,
}
