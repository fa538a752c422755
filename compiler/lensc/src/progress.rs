//! How far `build` and `report` have got, as people and tools see it: a
//! bar per job on stderr when it is a terminal (indicatif), shown once the
//! build has run about a second (a quick build draws nothing); one JSON
//! object per line on stdout with `--message-format json`, beside the
//! diagnostics; nothing when stderr is no terminal or with `--quiet`.
//! The build (lensc-build) counts and calls `Progress::event`; this module
//! renders, and tells of the writing phase, which the commands do.

use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use indicatif::{HumanBytes, ProgressBar, ProgressDrawTarget, ProgressStyle};
use lensc_build::progress::{Event, Observer, Phase, Progress};
use serde_json::json;

use crate::MessageFormat;
use crate::output::Output;

/// How long a build runs before its bar is drawn: a second, or
/// `LENSC_PROGRESS_AFTER_MS` milliseconds (the tests draw it at once, on
/// machines fast enough to build their jobs within the second).
fn show_after() -> Duration {
    std::env::var("LENSC_PROGRESS_AFTER_MS")
        .ok()
        .and_then(|v| v.parse().ok())
        .map_or(Duration::from_secs(1), Duration::from_millis)
}

/// Follows one `build` or `report` run.
pub struct Reporter {
    kind: Kind,
    totals: Mutex<Totals>,
}

enum Kind {
    Nothing,
    Json,
    Bar(Arc<Bars>),
}

/// What the run has built and written, for the closing event.
#[derive(Default)]
struct Totals {
    jobs: usize,
    built: usize,
    points: u64,
    bytes_written: u64,
    files_written: usize,
}

impl Reporter {
    /// The reporter `out` and `--quiet` ask for, for a run over `file`
    /// building `jobs` jobs (its `start` event is told here).
    pub fn new(out: &Output, quiet: bool, file: &str, jobs: usize) -> Reporter {
        let kind = if quiet {
            Kind::Nothing
        } else if out.format == MessageFormat::Json {
            Kind::Json
        } else if std::io::stderr().is_terminal() {
            Kind::Bar(Bars::start())
        } else {
            Kind::Nothing
        };
        let r = Reporter {
            kind,
            totals: Mutex::new(Totals {
                jobs,
                ..Totals::default()
            }),
        };
        r.json(|| json!({"event": "start", "file": file, "jobs": jobs}));
        r
    }

    /// The observer to hand the build.
    pub fn observer(&self) -> Observer<'_> {
        Observer(match self.kind {
            Kind::Nothing => None,
            _ => Some(self),
        })
    }

    fn json(&self, event: impl FnOnce() -> serde_json::Value) {
        if let Kind::Json = self.kind {
            let mut out = std::io::stdout().lock();
            // A closed pipe is no reason to fail the build.
            let _ = writeln!(out, "{}", event()).and_then(|()| out.flush());
        }
    }

    fn totals(&self) -> MutexGuard<'_, Totals> {
        self.totals.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// `job`'s writing phase begins: `bytes` to write in all.
    pub fn writing(&self, job: &str, bytes: u64) {
        self.json(|| json!({"event": "phase", "job": job, "phase": Phase::Writing.as_str(), "total_bytes": bytes}));
        if let Kind::Bar(bars) = &self.kind {
            bars.replace(
                job,
                bytes.max(1),
                "{prefix} writing {bytes}/{total_bytes} {elapsed} [{wide_bar}]",
            );
        }
    }

    /// One of `job`'s files is on disk: `bytes` of it, `so_far` of the job's.
    pub fn wrote(&self, job: &str, bytes: u64, so_far: u64) {
        {
            let mut t = self.totals();
            t.bytes_written += bytes;
            t.files_written += 1;
        }
        self.json(|| json!({"event": "progress", "job": job, "phase": Phase::Writing.as_str(), "bytes": so_far}));
        if let Kind::Bar(bars) = &self.kind {
            bars.with(|b| b.set_position(so_far));
        }
    }

    /// `job`'s files are all on disk (its bar is cleared for the summary
    /// line that follows).
    pub fn written(&self, job: &str, files: usize, bytes: u64) {
        self.json(|| json!({"event": "written", "job": job, "files": files, "bytes": bytes}));
        if let Kind::Bar(bars) = &self.kind {
            bars.clear();
        }
    }

    /// The run is over: its `done` event, with the totals.
    pub fn done(self, ok: bool) {
        let t = self.totals();
        self.json(|| {
            json!({"event": "done", "ok": ok, "jobs": t.jobs, "built": t.built, "points": t.points,
                "files": t.files_written, "bytes": t.bytes_written})
        });
    }
}

impl Progress for Reporter {
    fn event(&self, e: Event<'_>) {
        if let Event::JobDone { built, points, .. } = e
            && built
        {
            let mut t = self.totals();
            t.built += 1;
            t.points += points;
        }
        match &self.kind {
            Kind::Nothing => {}
            Kind::Json => self.json(|| event_json(e)),
            Kind::Bar(bars) => bars.event(e),
        }
    }
}

/// The JSON line of one build event (the shape docs/usage/build.md documents).
fn event_json(e: Event<'_>) -> serde_json::Value {
    match e {
        Event::Job { job, index, jobs } => {
            json!({"event": "job", "job": job, "index": index, "jobs": jobs})
        }
        Event::Phase {
            job,
            phase,
            estimated_points,
            estimated_bytes,
        } => {
            let mut v = json!({"event": "phase", "job": job, "phase": phase.as_str()});
            if phase == Phase::Planning {
                v["estimated_points"] = estimated_points.into();
                v["estimated_bytes"] = estimated_bytes.into();
            }
            v
        }
        Event::Planned { job, points, bytes } => {
            json!({"event": "progress", "job": job, "phase": "planning", "points": points, "bytes": bytes})
        }
        Event::JobDone {
            job,
            built,
            points,
            bytes,
        } => {
            json!({"event": "job-done", "job": job, "built": built, "points": points, "bytes": bytes})
        }
    }
}

/// The bar of the job in hand, drawn on stderr once the run has lasted
/// `show_after()` (a thread of its own turns it on then and redraws it).
struct Bars {
    start: Instant,
    shown: AtomicBool,
    bar: Mutex<Option<ProgressBar>>,
    /// `i/n name` (the name alone when it is the only job), the bar's
    /// prefix.
    label: Mutex<String>,
}

impl Bars {
    fn start() -> Arc<Bars> {
        let bars = Arc::new(Bars {
            start: Instant::now(),
            shown: AtomicBool::new(false),
            bar: Mutex::new(None),
            label: Mutex::new(String::new()),
        });
        let weak = Arc::downgrade(&bars);
        let after = show_after();
        // Ends with the run: the bars dropped, nothing left to draw.
        let _ = std::thread::Builder::new()
            .name("progress".into())
            .spawn(move || {
                while let Some(bars) = weak.upgrade() {
                    if !bars.shown.load(Ordering::Relaxed) && bars.start.elapsed() >= after {
                        bars.shown.store(true, Ordering::Relaxed);
                        bars.with(|b| b.set_draw_target(ProgressDrawTarget::stderr()));
                    }
                    bars.with(ProgressBar::tick);
                    drop(bars);
                    std::thread::sleep(Duration::from_millis(100));
                }
            });
        bars
    }

    fn with(&self, f: impl FnOnce(&ProgressBar)) {
        if let Some(b) = self.bar.lock().unwrap_or_else(|e| e.into_inner()).as_ref() {
            f(b);
        }
    }

    /// A new bar of `len` in `template` in place of the last.
    fn replace(&self, job: &str, len: u64, template: &str) {
        let target = if self.shown.load(Ordering::Relaxed) {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let style = ProgressStyle::with_template(template)
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        let label = self.label.lock().unwrap_or_else(|e| e.into_inner());
        let prefix = if label.is_empty() { job } else { &label };
        let bar = ProgressBar::with_draw_target(Some(len), target)
            .with_style(style)
            .with_prefix(prefix.to_string());
        if let Some(old) = self
            .bar
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .replace(bar)
        {
            old.finish_and_clear();
        }
    }

    fn clear(&self) {
        if let Some(old) = self.bar.lock().unwrap_or_else(|e| e.into_inner()).take() {
            old.finish_and_clear();
        }
    }

    fn event(&self, e: Event<'_>) {
        match e {
            Event::Job { job, index, jobs } => {
                *self.label.lock().unwrap_or_else(|e| e.into_inner()) = if jobs == 1 {
                    job.to_string()
                } else {
                    format!("{}/{jobs} {job}", index + 1)
                };
            }
            Event::Phase {
                job,
                phase: Phase::Planning,
                estimated_points,
                ..
            } => self.replace(
                job,
                estimated_points.max(1),
                "{prefix} planning {human_pos}/{human_len} points, {msg} {elapsed} [{wide_bar}]",
            ),
            Event::Phase { job, phase, .. } => {
                self.replace(job, 1, "{prefix} {msg} {elapsed}");
                let msg = match phase {
                    Phase::Lowering => "lowering and estimating",
                    Phase::ReadingBack => "reading the program back",
                    _ => "",
                };
                self.with(|b| b.set_message(msg));
            }
            Event::Planned { points, bytes, .. } => self.with(|b| {
                if points > b.length().unwrap_or(0) {
                    b.set_length(points);
                }
                b.set_position(points);
                b.set_message(format!("{} formatted", HumanBytes(bytes)));
            }),
            Event::JobDone { .. } => self.clear(),
        }
    }
}

impl Drop for Bars {
    fn drop(&mut self) {
        self.clear();
    }
}
