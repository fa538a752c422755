//! How far a build has got, told to whoever asked (`Request::progress`):
//! each job's phases, the points planned and the program's bytes formatted
//! so far. The build only counts; the caller renders (the `lensc` binary
//! draws a bar on a terminal or prints JSON lines). Reports are coarse:
//! the planners' callbacks add to a counter (a revolution or a pass at a
//! time, never a point at a time), and the observer hears of it once a
//! step: the job's estimated points over `STEPS`, at least `MIN_STEP`.

use std::fmt;

/// Reports per job the planning phase is cut into, at most.
pub const STEPS: u64 = 200;

/// Fewest points between two reports, however small the estimate.
pub const MIN_STEP: u64 = 10_000;

/// A phase of one job's build.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// The job lowered to its typed spec, checked and estimated.
    Lowering,
    /// The path planned, the program formatted, the cut simulated.
    Planning,
    /// The program read back by the controller's rules.
    ReadingBack,
    /// The report, the files beside the program and the program put on
    /// disk (told by the caller, which writes them).
    Writing,
}

impl Phase {
    /// The phase's name in the JSON events.
    pub fn as_str(self) -> &'static str {
        match self {
            Phase::Lowering => "lowering",
            Phase::Planning => "planning",
            Phase::ReadingBack => "reading-back",
            Phase::Writing => "writing",
        }
    }
}

/// What a build tells its observer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event<'a> {
    /// A job begins: its index among the jobs built and their count.
    Job {
        job: &'a str,
        index: usize,
        jobs: usize,
    },
    /// A job enters a phase. Planning comes with the estimate's points and
    /// program bytes (0 before lowering has made one).
    Phase {
        job: &'a str,
        phase: Phase,
        estimated_points: u64,
        estimated_bytes: u64,
    },
    /// Points planned and program bytes formatted so far in the planning
    /// phase (each count only grows; the last equals the job's total).
    Planned {
        job: &'a str,
        points: u64,
        bytes: u64,
    },
    /// A job is over: built (its cut points and program bytes) or refused.
    JobDone {
        job: &'a str,
        built: bool,
        points: u64,
        bytes: u64,
    },
}

/// Whoever follows a build. Called from the build's threads (the
/// planners' consumer among them), hence `Sync`.
pub trait Progress: Sync {
    fn event(&self, event: Event<'_>);
}

/// The observer a request carries, if any.
#[derive(Clone, Copy, Default)]
pub struct Observer<'a>(pub Option<&'a dyn Progress>);

impl fmt::Debug for Observer<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0.is_some() {
            "Observer(Some)"
        } else {
            "Observer(None)"
        })
    }
}

impl<'a> Observer<'a> {
    pub fn event(&self, event: Event<'_>) {
        if let Some(p) = self.0 {
            p.event(event);
        }
    }

    /// A meter for `job`'s planning phase, reporting every
    /// `estimated_points / STEPS` points (at least `MIN_STEP`).
    pub fn meter(&self, job: &'a str, estimated_points: u64) -> Meter<'a> {
        Meter {
            observer: *self,
            job,
            step: (estimated_points / STEPS).max(MIN_STEP),
            points: 0,
            bytes: 0,
            told: 0,
        }
    }
}

/// Counts one job's planned points and formatted bytes, and tells the
/// observer once a step.
#[derive(Clone, Copy, Debug)]
pub struct Meter<'a> {
    observer: Observer<'a>,
    job: &'a str,
    step: u64,
    points: u64,
    bytes: u64,
    /// Points when the observer was last told.
    told: u64,
}

impl Meter<'_> {
    /// A meter that tells no one.
    pub fn silent() -> Meter<'static> {
        Observer::default().meter("", 0)
    }

    /// `n` more points planned (after their text: `bytes`), told once a
    /// step.
    pub fn points(&mut self, n: usize) {
        self.points += n as u64;
        if self.points - self.told >= self.step {
            self.tell();
        }
    }

    /// `n` more bytes of program formatted.
    pub fn bytes(&mut self, n: usize) {
        self.bytes += n as u64;
    }

    /// Tells the observer the counts now.
    fn tell(&mut self) {
        self.told = self.points;
        self.observer.event(Event::Planned {
            job: self.job,
            points: self.points,
            bytes: self.bytes,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    struct Seen(Mutex<Vec<(u64, u64)>>);
    impl Progress for Seen {
        fn event(&self, e: Event<'_>) {
            if let Event::Planned { points, bytes, .. } = e {
                self.0.lock().unwrap().push((points, bytes));
            }
        }
    }

    #[test]
    fn a_meter_tells_once_a_step_not_once_a_point() {
        let seen = Seen(Mutex::new(Vec::new()));
        let observer = Observer(Some(&seen));
        // 4 million points estimated: a step of 20,000.
        let mut m = observer.meter("j", 4_000_000);
        // As the builders count: a revolution's text, then its points.
        for _ in 0..4_000 {
            m.bytes(30_000);
            m.points(1_000);
        }
        let seen = seen.0.into_inner().unwrap();
        assert_eq!(seen.len(), 200);
        assert_eq!(seen[0], (20_000, 600_000));
        assert_eq!(*seen.last().unwrap(), (4_000_000, 120_000_000));
        assert!(seen.windows(2).all(|w| w[0].0 < w[1].0 && w[0].1 < w[1].1));
    }

    #[test]
    fn a_small_job_is_not_told_while_it_plans() {
        let seen = Seen(Mutex::new(Vec::new()));
        let mut m = Observer(Some(&seen)).meter("j", 500);
        m.points(500);
        // Under a step: the pipeline tells the job's counts at its end.
        assert!(seen.0.into_inner().unwrap().is_empty());
    }
}
