//! The approach to a lathe cut: how the tool comes down from the retract
//! height to the cut's first point without cutting air at a finishing
//! feed for a minute, and without a rapid below the part's top.
//!
//! Three legs at the cut's first X:
//!
//! 1. a rapid down from the retract height to `APPROACH_CLEARANCE` above
//!    the highest point any cut reaches (never lower: a rapid below the
//!    part's top is a plunge by the reader's rule, which knows no stock);
//! 2. a feed at the air feed (`AIR_FEED`, or the machine's maximum if
//!    lower) down to `APPROACH_CLEARANCE` above the material over the
//!    first point: on a convex part the first point, at the rim, lies a
//!    sag below the top, all of it air;
//! 3. the last `APPROACH_CLEARANCE` (and whatever material lies over the
//!    first point) at the cutting feed.
//!
//! A leg of no length is left out; where the cutting feed is as fast as
//! the air feed, legs 2 and 3 are one feed move.

use crate::moves::{Feed, Move, Position};

/// The safe distance (mm) above the material at which an approach slows
/// from a rapid, or from the air feed, to the cutting feed: 0.1 mm. An
/// assumption, not a controller's rule: a finishing pass on a
/// diamond-turned or ground blank takes µm to tens of µm, and 0.1 mm
/// clears that with the machine's positioning to spare. Capped at the
/// strategy's `retract`, which is the clearance for rapids.
pub const APPROACH_CLEARANCE: f64 = 0.1;

/// The feed (mm/s) of the approach through air over the part: 100 mm/min,
/// or the machine's maximum feed where that is lower. An assumption: fast
/// enough that a few mm of air take a few seconds, slow enough that the
/// axes settle before the cutting feed takes over.
pub const AIR_FEED: f64 = 100.0 / 60.0;

/// Where an approach runs, in the nose (or wheel) centre's X and Z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Approach {
    /// The X of the cut's first point.
    pub x: f64,
    /// The retract height the tool rapids across at.
    pub safe_z: f64,
    /// The highest point any cut reaches (or the stock's top): rapids stay
    /// at or above it.
    pub top: f64,
    /// How high the material over the first point reaches, as a centre
    /// height (the tool touches it with its centre there).
    pub material: f64,
    /// The cut's first point's Z.
    pub start_z: f64,
    /// The cutting feed's speed (mm/s) at the first point.
    pub cutting_speed: f64,
    /// The machine's maximum feed (mm/s).
    pub max_feed: f64,
    /// The strategy's retract (mm).
    pub retract: f64,
}

/// One leg of an approach.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Leg {
    /// A rapid down to this Z.
    Rapid(f64),
    /// A feed through air down to this Z at this speed (mm/s).
    Air(f64, f64),
    /// The cutting feed down to this Z (the first point's).
    Cutting(f64),
}

impl Approach {
    /// The legs after the rapid to (x, safe_z), in order.
    pub fn legs(&self) -> Vec<Leg> {
        let clearance = APPROACH_CLEARANCE.min(self.retract);
        let material = self.material.max(self.start_z);
        let rapid_to = (self.top.max(material) + clearance).min(self.safe_z);
        let air = AIR_FEED.min(self.max_feed);
        let slow_from = (material + clearance).min(rapid_to);
        let mut legs = Vec::with_capacity(3);
        if rapid_to < self.safe_z {
            legs.push(Leg::Rapid(rapid_to));
        }
        if self.cutting_speed < air && slow_from < rapid_to {
            legs.push(Leg::Air(slow_from, air));
        }
        legs.push(Leg::Cutting(self.start_z));
        legs
    }

    /// The legs as moves; the cutting leg's feed is `cutting` (`None`: the
    /// job's, as the emitter gives it), the air leg's `air(speed)` (a feed
    /// per revolution where the cutting feed is one: under constant
    /// surface speed some dialects cannot switch to a feed per minute).
    pub fn moves(&self, cutting: Option<Feed>, air: impl Fn(f64) -> Feed) -> Vec<Move> {
        self.legs()
            .into_iter()
            .map(|leg| match leg {
                Leg::Rapid(z) => Move::Rapid(Position::xz(self.x, z)),
                Leg::Air(z, v) => Move::Linear {
                    to: Position::xz(self.x, z),
                    feed: Some(air(v)),
                },
                Leg::Cutting(z) => Move::Linear {
                    to: Position::xz(self.x, z),
                    feed: cutting,
                },
            })
            .collect()
    }

    /// The time (s) of the feed legs, and their length (mm).
    pub fn feed_time_and_length(&self) -> (f64, f64) {
        let mut z = self.safe_z;
        let (mut time, mut length) = (0.0, 0.0);
        for leg in self.legs() {
            match leg {
                Leg::Rapid(to) => z = to,
                Leg::Air(to, v) => {
                    time += (z - to).abs() / v;
                    length += (z - to).abs();
                    z = to;
                }
                Leg::Cutting(to) => {
                    time += (z - to).abs() / self.cutting_speed;
                    length += (z - to).abs();
                    z = to;
                }
            }
        }
        (time, length)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn convex() -> Approach {
        // A convex part: its rim, where the cut starts, 1.5 mm below its
        // top; a finishing feed of 1.5 mm/min.
        Approach {
            x: 6.0,
            safe_z: 1.0,
            top: 0.0,
            material: -1.5,
            start_z: -1.5,
            cutting_speed: 1.5 / 60.0,
            max_feed: 1000.0 / 60.0,
            retract: 1.0,
        }
    }

    #[test]
    fn a_convex_rim_is_reached_by_rapid_to_the_top_and_air_feed_down() {
        let a = convex();
        assert_eq!(
            a.legs(),
            vec![
                Leg::Rapid(APPROACH_CLEARANCE),
                Leg::Air(-1.5 + APPROACH_CLEARANCE, AIR_FEED),
                Leg::Cutting(-1.5)
            ]
        );
        let (time, length) = a.feed_time_and_length();
        assert!((length - 1.6).abs() < 1e-12, "{length}");
        // 1.5 mm at 100 mm/min, 0.1 mm at 1.5 mm/min: 0.9 s + 4 s.
        assert!((time - (0.9 + 4.0)).abs() < 1e-9, "{time}");
    }

    #[test]
    fn material_over_the_first_point_is_cut_at_the_cutting_feed() {
        // What a roughing pass left 0.2 mm over the first point.
        let a = Approach {
            material: -1.3,
            ..convex()
        };
        assert_eq!(
            a.legs(),
            vec![
                Leg::Rapid(APPROACH_CLEARANCE),
                Leg::Air(-1.3 + APPROACH_CLEARANCE, AIR_FEED),
                Leg::Cutting(-1.5)
            ]
        );
    }

    #[test]
    fn no_rapid_ends_below_the_top_nor_above_the_retract() {
        // Stock above the cuts' top keeps the rapid over the stock.
        let a = Approach {
            top: 0.95,
            ..convex()
        };
        assert_eq!(a.legs()[0], Leg::Air(-1.4, AIR_FEED));
        // A retract under the clearance: the clearance is the retract.
        let a = Approach {
            safe_z: 0.05,
            retract: 0.05,
            ..convex()
        };
        assert_eq!(
            a.legs(),
            vec![Leg::Air(-1.45, AIR_FEED), Leg::Cutting(-1.5)]
        );
    }

    #[test]
    fn a_fast_cutting_feed_takes_the_whole_approach() {
        let a = Approach {
            cutting_speed: 200.0 / 60.0,
            ..convex()
        };
        assert_eq!(
            a.legs(),
            vec![Leg::Rapid(APPROACH_CLEARANCE), Leg::Cutting(-1.5)]
        );
        // And a machine slower than the air feed sets the air feed.
        let a = Approach {
            max_feed: 50.0 / 60.0,
            ..convex()
        };
        assert_eq!(a.legs()[1], Leg::Air(-1.4, 50.0 / 60.0));
    }
}
