//! Dimensions and units. Every quantity carries its dimension as integer
//! powers of length, angle and time; internally one base unit per dimension
//! (mm, rad, s). Angle is a dimension of its own so that `sin(1 mm)` and
//! `1 mm + 1 deg` are type errors and a feed per revolution (length/angle)
//! is told apart from a length.

use std::f64::consts::PI;
use std::fmt;

/// Powers of (length, angle, time).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Dim {
    pub length: i8,
    pub angle: i8,
    pub time: i8,
}

impl Dim {
    pub const NONE: Dim = Dim::new(0, 0, 0);
    pub const LENGTH: Dim = Dim::new(1, 0, 0);
    pub const ANGLE: Dim = Dim::new(0, 1, 0);
    pub const TIME: Dim = Dim::new(0, 0, 1);
    pub const SPEED: Dim = Dim::new(1, 0, -1);
    pub const FEED_PER_REV: Dim = Dim::new(1, -1, 0);
    pub const ROTATIONAL_SPEED: Dim = Dim::new(0, 1, -1);
    pub const FREQUENCY: Dim = Dim::new(0, 0, -1);
    pub const ACCELERATION: Dim = Dim::new(1, 0, -2);
    pub const AREA: Dim = Dim::new(2, 0, 0);

    pub const fn new(length: i8, angle: i8, time: i8) -> Dim {
        Dim {
            length,
            angle,
            time,
        }
    }
    /// `self^p`, or `None` if a power leaves the i8 range.
    pub fn pow(self, p: i32) -> Option<Dim> {
        let f = |e: i8| i8::try_from(i32::from(e) * p).ok();
        Some(Dim::new(f(self.length)?, f(self.angle)?, f(self.time)?))
    }
    /// Square root, if every power is even.
    pub fn sqrt(self) -> Option<Dim> {
        let f = |e: i8| (e % 2 == 0).then_some(e / 2);
        Some(Dim::new(f(self.length)?, f(self.angle)?, f(self.time)?))
    }
    pub fn is_none(self) -> bool {
        self == Dim::NONE
    }
    /// The unit a value of this dimension is shown in, and its factor from
    /// base units: a length in mm, a speed in mm/min, an angle in deg.
    pub fn display_unit(self) -> (String, f64) {
        match self {
            Dim::NONE => (String::new(), 1.0),
            Dim::ANGLE => ("deg".into(), 180.0 / PI),
            Dim::SPEED => ("mm/min".into(), 60.0),
            Dim::FEED_PER_REV => ("mm/rev".into(), 2.0 * PI),
            Dim::ROTATIONAL_SPEED => ("rpm".into(), 60.0 / (2.0 * PI)),
            Dim::FREQUENCY => ("Hz".into(), 1.0),
            _ => (self.base_units(), 1.0),
        }
    }
}

impl Dim {
    /// The base units of this dimension written out: `mm`, `mm/s^2`, `1/mm^3`.
    pub fn base_units(self) -> String {
        let mut num = Vec::new();
        let mut den = Vec::new();
        for (sym, e) in [("mm", self.length), ("rad", self.angle), ("s", self.time)] {
            let part = |p: i8| {
                if p == 1 {
                    sym.to_string()
                } else {
                    format!("{sym}^{p}")
                }
            };
            if e > 0 {
                num.push(part(e));
            } else if e < 0 {
                den.push(part(-e));
            }
        }
        let n = if num.is_empty() {
            "1".to_string()
        } else {
            num.join("·")
        };
        if den.is_empty() {
            n
        } else {
            format!("{n}/{}", den.join("·"))
        }
    }
}

impl fmt::Display for Dim {
    /// Plain words for the common dimensions, base units otherwise.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match *self {
            Dim::NONE => "a plain number",
            Dim::LENGTH => "a length",
            Dim::ANGLE => "an angle",
            Dim::TIME => "a time",
            Dim::SPEED => "a speed",
            Dim::FEED_PER_REV => "a feed per revolution",
            Dim::ROTATIONAL_SPEED => "a rotational speed",
            Dim::FREQUENCY => "a frequency",
            Dim::ACCELERATION => "an acceleration",
            _ => return write!(f, "a quantity in {}", self.base_units()),
        };
        f.write_str(name)
    }
}

impl std::ops::Mul for Dim {
    type Output = Dim;
    fn mul(self, o: Dim) -> Dim {
        Dim::new(
            self.length + o.length,
            self.angle + o.angle,
            self.time + o.time,
        )
    }
}

impl std::ops::Div for Dim {
    type Output = Dim;
    fn div(self, o: Dim) -> Dim {
        Dim::new(
            self.length - o.length,
            self.angle - o.angle,
            self.time - o.time,
        )
    }
}

/// A named unit: its dimension and its size in base units.
#[derive(Clone, Copy, Debug)]
pub struct UnitDef {
    pub name: &'static str,
    pub dim: Dim,
    pub factor: f64,
}

const fn u(name: &'static str, dim: Dim, factor: f64) -> UnitDef {
    UnitDef { name, dim, factor }
}

/// Standard gravity, mm/s².
pub const STANDARD_GRAVITY: f64 = 9806.65;

/// Every unit a `.lens` file may write. Compound units are formed with `/`
/// and `^` from these (`mm/min`, `m/s^2`, `rad/mm`).
pub const UNITS: &[UnitDef] = &[
    u("nm", Dim::LENGTH, 1e-6),
    u("um", Dim::LENGTH, 1e-3),
    u("µm", Dim::LENGTH, 1e-3),
    u("μm", Dim::LENGTH, 1e-3),
    u("mm", Dim::LENGTH, 1.0),
    u("cm", Dim::LENGTH, 10.0),
    u("m", Dim::LENGTH, 1000.0),
    u("in", Dim::LENGTH, 25.4),
    u("deg", Dim::ANGLE, PI / 180.0),
    u("°", Dim::ANGLE, PI / 180.0),
    u("rad", Dim::ANGLE, 1.0),
    u("mrad", Dim::ANGLE, 1e-3),
    u("urad", Dim::ANGLE, 1e-6),
    u("µrad", Dim::ANGLE, 1e-6),
    u("μrad", Dim::ANGLE, 1e-6),
    u("rev", Dim::ANGLE, 2.0 * PI),
    u("s", Dim::TIME, 1.0),
    u("ms", Dim::TIME, 1e-3),
    u("us", Dim::TIME, 1e-6),
    u("µs", Dim::TIME, 1e-6),
    u("μs", Dim::TIME, 1e-6),
    u("min", Dim::TIME, 60.0),
    u("h", Dim::TIME, 3600.0),
    u("rpm", Dim::ROTATIONAL_SPEED, 2.0 * PI / 60.0),
    u("Hz", Dim::FREQUENCY, 1.0),
    u("kHz", Dim::FREQUENCY, 1e3),
    u("g", Dim::ACCELERATION, STANDARD_GRAVITY),
    u("G", Dim::ACCELERATION, STANDARD_GRAVITY),
];

pub fn lookup(name: &str) -> Option<&'static UnitDef> {
    UNITS.iter().find(|u| u.name == name)
}

/// How many base units one `unit` is, computed as the checker computes a
/// `.lens` quantity's unit (`mm/min`: 1 × 60⁻¹, each part's size to its
/// power, in the order written): what a header figure in this unit is
/// multiplied by when read back. `mm/s^2` and `mm·rad` read as written, a
/// leading `1` (`1/mm^3`) as nothing; `None` if a part is no unit.
pub fn size_of(unit: &str) -> Option<f64> {
    let mut size = 1.0_f64;
    for (k, quotient) in unit.split('/').enumerate() {
        for part in quotient.split('·').filter(|p| k > 0 || *p != "1") {
            let (name, power) = match part.split_once('^') {
                Some((n, p)) => (n, p.parse::<i32>().ok()?),
                None => (part, 1),
            };
            let power = if k > 0 { -power } else { power };
            size *= lookup(name)?.factor.powi(power);
        }
    }
    Some(size)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base_units_and_conversions() {
        assert_eq!(lookup("um").expect("um").factor, 1e-3);
        assert_eq!(lookup("µm").expect("µm").dim, Dim::LENGTH);
        let rpm = lookup("rpm").expect("rpm");
        assert!((1000.0 * rpm.factor - 104.719_755_119_659_77).abs() < 1e-12);
        assert_eq!(lookup("g").expect("g").factor, 9806.65);
        assert_eq!(Dim::LENGTH / Dim::ANGLE, Dim::FEED_PER_REV);
        assert_eq!(Dim::ANGLE / Dim::LENGTH * Dim::LENGTH, Dim::ANGLE);
        assert_eq!(Dim::new(2, 0, -2).sqrt(), Some(Dim::SPEED));
        assert_eq!(Dim::LENGTH.sqrt(), None);
    }

    #[test]
    fn a_units_size_is_the_checkers() {
        assert_eq!(size_of("mm/min"), Some(1.0 / 60.0));
        assert_eq!(size_of("rpm"), Some(2.0 * PI / 60.0));
        assert_eq!(size_of("1/mm^3"), Some(1.0));
        assert_eq!(size_of("mm/s^2"), Some(1.0));
        assert_eq!(size_of("um"), Some(1e-3));
        assert_eq!(size_of("furlong"), None);
    }

    #[test]
    fn dimensions_read_as_words() {
        assert_eq!(Dim::FEED_PER_REV.to_string(), "a feed per revolution");
        assert_eq!(Dim::new(-3, 0, 0).to_string(), "a quantity in 1/mm^3");
        assert_eq!(Dim::new(1, 0, -2).base_units(), "mm/s^2");
    }
}
