//! The servo's view of a spiral: its points as the program prints them
//! (what the servo is driven by: the path itself where the controller
//! leads the servo, the path led by its inverse model where the program
//! must, `machine::lead`) and the fast axis's following simulated along
//! it. Used by the build and by the speed advice's trials, so neither
//! needs the other.

use super::SpiralSpec;

/// `points` as the program prints them (X and W rounded to the machine's
/// `resolution`, mm), into `printed`: what the servo is driven by.
pub(super) fn as_printed(
    points: &[lensc_runtime::plan::spiral::SpiralPoint],
    resolution: f64,
    printed: &mut Vec<lensc_runtime::plan::spiral::SpiralPoint>,
) {
    let printed_at = lensc_runtime::verify::simulate::Printed::new(resolution);
    let round = |v: f64| printed_at.round(v);
    printed.clear();
    printed.extend(
        points
            .iter()
            .map(|q| lensc_runtime::plan::spiral::SpiralPoint {
                x: round(q.x),
                w: round(q.w),
                ..*q
            }),
    );
}

/// Whether the program leads the fast axis's servo itself: a fast tool
/// servo with a model whose controller feeds nothing forward
/// (`feed_forward: none`).
pub(super) fn program_leads(spec: &SpiralSpec) -> bool {
    !spec.slow && spec.servo.is_some() && !spec.controller_leads
}

/// Whether the program writes the axis that carries the surface as its
/// own moves, each held to the machine's `max_feed` by the controller
/// (LinuxCNC programs the fast axis on Z), rather than into a servo table
/// beside it.
pub(super) fn writes_moves(spec: &SpiralSpec) -> bool {
    spec.slow || spec.head.dialect.fts_table.is_none()
}

/// The letter the program writes a fast tool servo's motion on where it
/// writes the fast axis as moves (`writes_moves`) and the machine gives
/// the servo an axis of its own (`fast_axis { letter, max_velocity }`):
/// the slide's Z then holds still and the tool tip is Z plus the servo.
/// `None`: the fast axis is written on Z (or into a servo table).
pub(super) fn servo_letter(spec: &SpiralSpec) -> Option<char> {
    spec.servo_axis
        .filter(|_| !spec.slow && writes_moves(spec))
        .map(|(letter, _)| letter)
}

/// The commands a spiral's points are printed as, batch by batch: the
/// planned path, or where the program leads the servo
/// (`program_leads`), the path led by the servo's inverse model, a point
/// behind (each point is led once the next is known).
pub(super) struct Commands {
    lead: Option<lensc_runtime::machine::lead::ProgramLead>,
    /// The batch: the commands and the path's points they lead to.
    pub commands: Vec<lensc_runtime::plan::spiral::SpiralPoint>,
    pub path: Vec<lensc_runtime::plan::spiral::SpiralPoint>,
    /// As printed (`as_printed`), and the printed path's W.
    printed: Vec<lensc_runtime::plan::spiral::SpiralPoint>,
    aims: Vec<f64>,
    /// The lowest and highest command (mm) led so far.
    pub range: (f64, f64),
    /// The fastest move between two commands as printed so far: its
    /// slides' feed (mm/s: its X and Z travel over its planned time, as
    /// the controller reads an inverse-time move; Z carrying the fast axis
    /// unless the servo has a letter of its own, `own_axis`) and radius
    /// (mm).
    pub fastest: Option<(f64, f64)>,
    /// Where the servo is written on its own letter: the fastest it is
    /// driven, its travel over the move's planned time (mm/s), and the
    /// radius (mm).
    pub fastest_servo: Option<(f64, f64)>,
    own_axis: bool,
    /// The last command as printed, the start of the next move.
    last: Option<lensc_runtime::plan::spiral::SpiralPoint>,
    resolution: f64,
    /// The commands made so far: the points the program cuts, the lead's
    /// added points beside bends included.
    pub written: usize,
}

impl Commands {
    pub fn of(spec: &SpiralSpec, data_rate: f64) -> Commands {
        let resolution = spec.head.resolution;
        Commands {
            lead: spec
                .servo
                .as_ref()
                .filter(|_| program_leads(spec))
                .map(|s| lensc_runtime::machine::lead::ProgramLead::new(s, data_rate, resolution)),
            commands: Vec::new(),
            path: Vec::new(),
            printed: Vec::new(),
            aims: Vec::new(),
            range: (f64::INFINITY, f64::NEG_INFINITY),
            fastest: None,
            fastest_servo: None,
            own_axis: servo_letter(spec).is_some(),
            last: None,
            resolution,
            written: 0,
        }
    }

    /// The next planned points: the batch's commands and path.
    pub fn next(&mut self, points: &[lensc_runtime::plan::spiral::SpiralPoint]) {
        self.path.clear();
        let Some(lead) = self.lead.as_mut() else {
            self.path.extend_from_slice(points);
            self.commands.clone_from(&self.path);
            return self.account();
        };
        lead.extend(points, &mut self.commands, &mut self.path);
        self.account();
    }

    /// The last batch: the path's last point led (none where the
    /// controller leads).
    pub fn finish(&mut self) {
        self.path.clear();
        self.commands.clear();
        if let Some(lead) = self.lead.as_mut() {
            lead.finish(&mut self.commands, &mut self.path);
        }
        self.account();
    }

    fn account(&mut self) {
        self.written += self.commands.len();
        for c in &self.commands {
            self.range = (self.range.0.min(c.w), self.range.1.max(c.w));
        }
        // Each move's feed from the positions as printed (rounded to the
        // resolution, as the controller reads them) over its planned time:
        // the program never prints a move faster than planned
        // (`inverse_time_not_faster`), so the controller's feed is at most
        // this.
        as_printed(&self.commands, self.resolution, &mut self.printed);
        for q in &self.printed {
            if let Some(p) = self.last
                && q.t > p.t
            {
                let dt = q.t - p.t;
                // The Z slide carries W, or (the servo on its own letter)
                // holds still.
                let slide_z = if self.own_axis { 0.0 } else { q.w - p.w };
                let feed = (q.x - p.x).hypot(slide_z) / dt;
                if self.fastest.is_none_or(|(f, _)| feed > f) {
                    self.fastest = Some((feed, q.x.abs()));
                }
                let servo = (q.w - p.w).abs() / dt;
                if self.own_axis && self.fastest_servo.is_none_or(|(v, _)| servo > v) {
                    self.fastest_servo = Some((servo, q.x.abs()));
                }
            }
            self.last = Some(*q);
        }
    }

    /// The fastest move's feed (mm/s) and radius where it is above the
    /// machine's `max_feed` and the program writes the surface's axis as
    /// moves (`writes_moves`).
    pub fn over_max_feed(&self, spec: &SpiralSpec) -> Option<(f64, f64)> {
        self.fastest
            .filter(|&(feed, _)| writes_moves(spec) && feed > spec.max_feed)
    }

    /// The servo's fastest move (mm/s) and radius where the servo is
    /// written on its own letter (`servo_letter`) and that move drives it
    /// faster than its `max_velocity`.
    pub fn over_servo_velocity(&self, spec: &SpiralSpec) -> Option<(f64, f64)> {
        let (_, most) = spec.servo_axis?;
        self.fastest_servo.filter(|&(v, _)| v > most)
    }

    /// Runs `sim` on the batch's commands as printed (at `resolution`,
    /// mm), toward the path as printed.
    pub fn drive(
        &mut self,
        sim: &mut lensc_runtime::verify::follow::FollowingSimulation,
        resolution: f64,
    ) {
        if self.lead.is_none() {
            as_printed(&self.commands, resolution, &mut self.printed);
            return sim.extend(&self.printed);
        }
        as_printed(&self.path, resolution, &mut self.printed);
        self.aims.clear();
        self.aims.extend(self.printed.iter().map(|p| p.w));
        as_printed(&self.commands, resolution, &mut self.printed);
        sim.extend_toward(&self.printed, &self.aims);
    }
}

/// The fast axis's servo following along `spiral` (the job's, or at a
/// trial speed, with the `bounds` its trajectory has there), simulated
/// over radial bins, where it has a servo model: where its controller
/// leads it (`feed_forward: inverse_model`), led by its inverse model
/// (velocity and acceleration feed-forward of the commanded path,
/// `FollowingSimulation::led`); where it does not, unled, on the commands
/// the program leads it by (`Commands::drive`).
pub(super) fn following(
    spec: &SpiralSpec,
    spiral: &lensc_runtime::plan::spiral::FtsSpiral,
    bounds: &lensc_runtime::plan::spiral::TrajectoryBounds,
    data_rate: f64,
) -> Option<lensc_runtime::verify::follow::FollowingSimulation> {
    use lensc_runtime::verify::follow::{FollowingSimulation, RadialBins};
    let servo = spec.servo.as_ref().filter(|_| !spec.slow)?;
    let (r0, r1) = (spiral.start_radius.abs(), spiral.end_radius.abs());
    FollowingSimulation::new(
        servo,
        data_rate,
        bounds.features.as_deref().unwrap_or_default(),
        // From the axis where the spiral reaches or passes it.
        RadialBins::new(
            if spiral.end_radius <= 0.0 {
                0.0
            } else {
                r0.min(r1)
            },
            r0.max(r1),
            crate::plots::FOLLOWING_BINS,
        ),
    )
    .map(|sim| {
        // Only where the nose cuts: above the part's top (the settling
        // plateau and the lenslets' continuations) it cuts air.
        let sim = if spec.controller_leads {
            sim.led(servo)
        } else {
            sim
        };
        sim.cutting_below(bounds.part_top + spec.nose_radius + 1e-9)
    })
}
