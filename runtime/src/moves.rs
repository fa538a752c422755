//! The dialect-independent move stream: what every planner hands the
//! post-processors. A move says where the axes go (machine coordinates of
//! the tool's reference point, mm; C in radians), how fast (a feed in one
//! of the controller's feed modes), and the spindle's state; it knows
//! nothing of words, letters or decimals. Planners that run to millions
//! of points produce it in chunks, so a program streams in bounded memory.

/// Where a move takes the axes; NaN leaves an axis where it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Position {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    /// Spindle (C axis) angle in radians, counted on (not wrapped).
    pub c: f64,
}

impl Position {
    /// No axis moves.
    pub const KEEP: Position = Position {
        x: f64::NAN,
        y: f64::NAN,
        z: f64::NAN,
        c: f64::NAN,
    };

    /// X and Z of a lathe.
    pub fn xz(x: f64, z: f64) -> Position {
        Position { x, z, ..Self::KEEP }
    }
    pub fn xyz(x: f64, y: f64, z: f64) -> Position {
        Position {
            x,
            y,
            z,
            c: f64::NAN,
        }
    }
    pub fn xzc(x: f64, z: f64, c: f64) -> Position {
        Position {
            x,
            z,
            c,
            y: f64::NAN,
        }
    }
    /// X, Z and C of a lathe whose fast tool servo is programmed as an
    /// axis of its own: a lathe has no Y, so the servo's position goes in
    /// Y's place (`ProgramWriter::servo_in_y` prints it with its letter).
    pub fn xzc_servo(x: f64, z: f64, c: f64, servo: f64) -> Position {
        Position { x, y: servo, z, c }
    }
    /// The axes in the order X, Y, Z, C.
    pub fn axes(&self) -> [f64; 4] {
        [self.x, self.y, self.z, self.c]
    }
}

/// How fast a cutting move goes, in the feed mode it is given in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Feed {
    /// Path speed (mm/s).
    PerTime(f64),
    /// mm per radian of spindle rotation.
    PerRevolution(f64),
    /// The time (s) the move takes: for moves that mix rotary and linear
    /// axes, where no path speed means anything.
    InverseTime(f64),
}

/// A plane of circular interpolation. Its two axes are named in the
/// right-handed order that defines counter-clockwise, seen from the
/// positive end of the third axis: G17 (X, Y), G18 (Z, X), G19 (Y, Z).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plane {
    Xy,
    Zx,
    Yz,
}

impl Plane {
    /// Every plane, G17's, G18's and G19's.
    pub const ALL: [Plane; 3] = [Plane::Xy, Plane::Zx, Plane::Yz];

    /// The plane named `name` in the language and dialect files; `None`
    /// for any other word.
    pub fn from_name(name: &str) -> Option<Plane> {
        Plane::ALL.into_iter().find(|p| p.name() == name)
    }

    /// Indices into `Position::axes()` of the plane's first and second axis.
    pub fn axes(self) -> (usize, usize) {
        match self {
            Plane::Xy => (0, 1),
            Plane::Zx => (2, 0),
            Plane::Yz => (1, 2),
        }
    }
    /// The plane's name in the language and dialect files.
    pub fn name(self) -> &'static str {
        match self {
            Plane::Xy => "xy",
            Plane::Zx => "zx",
            Plane::Yz => "yz",
        }
    }
}

/// One step of a program.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Move {
    /// Positioning at rapid rate, out of the material.
    Rapid(Position),
    /// A straight cutting move; `feed: None` keeps the feed in force.
    Linear {
        to: Position,
        feed: Option<Feed>,
    },
    /// A circular cutting move in `plane` from where the axes are to `to`
    /// about `centre` (absolute; only the plane's two axes are read),
    /// counter-clockwise in the plane's order if `ccw`; less than a half
    /// turn, and the axes off the plane do not move.
    Arc {
        to: Position,
        centre: Position,
        plane: Plane,
        ccw: bool,
        feed: Option<Feed>,
    },
    /// Spindle on at a constant speed (rad/s), turning the job's way.
    SpindleOn(f64),
    /// Spindle stopped at a fixed angle and held there: for a tool that
    /// cuts with the spindle still (a shaping knife).
    SpindleHeld,
    /// Spindle on at constant surface speed (mm/s at the tool's radius),
    /// turning no faster than `cap` (rad/s).
    SpindleSurfaceSpeed {
        surface_speed: f64,
        cap: f64,
    },
    SpindleOff,
}

/// The first position in `moves` outside the machine's travel, given per
/// axis X, Y, Z, C as (min, max) where limited: the axis letter, the
/// value, and its travel.
pub fn outside_travel(
    moves: &[Move],
    travel: [Option<(f64, f64)>; 4],
) -> Option<(char, f64, (f64, f64))> {
    moves.iter().find_map(|m| {
        let (Move::Rapid(to) | Move::Linear { to, .. } | Move::Arc { to, .. }) = m else {
            return None;
        };
        to.axes()
            .into_iter()
            .zip(travel)
            .zip(['X', 'Y', 'Z', 'C'])
            .find_map(|((v, range), letter)| {
                let (lo, hi) = range?;
                (!v.is_nan() && (v < lo || v > hi)).then_some((letter, v, (lo, hi)))
            })
    })
}

/// Which way the spindle turns, seen as the controller's M3 (clockwise)
/// and M4 (counter-clockwise) name it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Rotation {
    #[default]
    Clockwise,
    CounterClockwise,
}

/// Coolant for the whole program.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Coolant {
    #[default]
    Off,
    Flood,
    Mist,
}

/// What a program states before its first move, whatever its strategy:
/// the tool it calls (its number and offset register), which way the
/// spindle turns when it turns, the coolant, and the point of the tool
/// its coordinates are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Start {
    pub tool: u32,
    pub offset: u32,
    pub rotation: Rotation,
    pub coolant: Coolant,
    pub control: ControlOffset,
    /// The workpiece blank, where the program states one (Klartext's
    /// `BLK FORM`, for the control's graphic test run).
    pub blank: Option<Blank>,
}

/// A workpiece blank as a box in work coordinates (mm): its least and
/// greatest X, Y and Z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blank {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

/// Where the tool's control point (the point its length and X offsets
/// are measured to, which the controller moves to the programmed
/// coordinates) lies from the tool's centre (the ball's, the nose's, the
/// wheel's: the point every planner's move stream gives), in mm along X,
/// Y and Z: zero for a tool set to its centre; `Z = -r` for a ball-end
/// mill measured to its tip; `X = -r, Z = -r` for a lathe tool's
/// imaginary tip. The writer adds it to every position it prints and the
/// read-back subtracts it again.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ControlOffset {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl ControlOffset {
    /// The tool's centre: no offset.
    pub const CENTRE: ControlOffset = ControlOffset {
        x: 0.0,
        y: 0.0,
        z: 0.0,
    };

    /// Whether it moves anything.
    pub fn is_zero(&self) -> bool {
        self.x == 0.0 && self.y == 0.0 && self.z == 0.0
    }

    /// `p` moved by the offset (an axis left where it is stays so).
    pub fn apply(&self, p: Position) -> Position {
        Position {
            x: p.x + self.x,
            y: p.y + self.y,
            z: p.z + self.z,
            c: p.c,
        }
    }

    /// `m` with its positions and arc centre moved by the offset.
    pub fn apply_to(&self, m: &Move) -> Move {
        match *m {
            Move::Rapid(to) => Move::Rapid(self.apply(to)),
            Move::Linear { to, feed } => Move::Linear {
                to: self.apply(to),
                feed,
            },
            Move::Arc {
                to,
                centre,
                plane,
                ccw,
                feed,
            } => Move::Arc {
                to: self.apply(to),
                centre: self.apply(centre),
                plane,
                ccw,
                feed,
            },
            other => other,
        }
    }
}

impl Default for Start {
    /// Tool 1 with offset 1, clockwise, no coolant, programmed at the
    /// tool's centre.
    fn default() -> Start {
        Start {
            tool: 1,
            offset: 1,
            rotation: Rotation::Clockwise,
            coolant: Coolant::Off,
            control: ControlOffset::CENTRE,
            blank: None,
        }
    }
}

/// A curve the controller interpolates itself: a clamped, non-rational
/// B-spline of `order` (degree + 1) through X, Y and Z, as Fanuc's G06.2
/// takes one. It starts at its first control point, which must be where
/// the axes are, and ends at its last; `knots` holds as many values as
/// control points plus the order, its first `order` equal and its last
/// `order` equal. Positions are the tool centre's, like every move's.
#[derive(Clone, Debug, PartialEq)]
pub struct Spline {
    pub order: usize,
    pub points: Vec<[f64; 3]>,
    pub knots: Vec<f64>,
    /// The feed along it; `None` keeps the feed in force.
    pub feed: Option<Feed>,
}

/// One step of a program written with splines: a move of the stream, or
/// a spline that stands for a run of its straight moves.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    Move(Move),
    Spline(Spline),
}
