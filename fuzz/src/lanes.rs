//! Lanes as child processes (fork mode): each lane is the fuzz binary run
//! again with `--worker LANE --worker-from I`, taking the inputs I, I + J,
//! I + 2J, … of the seed (J lanes) and printing a `Record` line for each
//! one it finishes. The parent counts the records; when a worker dies
//! (an abort: a failed allocation, a stack overflow), stops answering, or
//! gives up after a hang, the input it was on is the one after the last
//! it reported: the parent reports it (`Lost`) and starts the lane again
//! past it, so no input is lost silently and the figures add up over
//! restarts.

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc::{RecvTimeoutError, Sender, channel};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::record::Record;

/// The exit code of a worker that stops after a hang (its stuck thread
/// still running): the parent starts a fresh one past the input.
pub const EXIT_AFTER_HANG: i32 = 3;

/// The exit code of a worker that cannot start (a bad flag, no corpus):
/// the lane is not started again.
pub const EXIT_SETUP: i32 = 2;

/// What the parent tells about an input no record came for.
#[derive(Debug, PartialEq, Eq)]
pub struct Lost {
    pub lane: u64,
    pub index: u64,
    /// `abort` (the worker died) or `hang` (it stopped answering).
    pub what: &'static str,
    pub message: String,
}

/// How the lanes are run.
pub struct Plan {
    /// The command that starts a worker, before its `--worker` flags
    /// (the fuzz binary and the run's flags).
    pub command: Vec<String>,
    pub lanes: u64,
    /// The inputs of the seed: 0..end.
    pub end: u64,
    pub deadline: Instant,
    /// A worker that reports nothing for this long is killed.
    pub silence: Duration,
    /// Where each worker gets a directory of its own to build into.
    pub scratch: PathBuf,
}

enum Event {
    Line(u64, u64, String),
    Exited(u64, u64, ExitStatus),
}

struct Lane {
    /// The worker, shared with the thread that reads it and reaps it.
    child: Option<Arc<Mutex<Child>>>,
    /// Which start of the lane this is (events of older ones are stale).
    generation: u64,
    /// The next input this lane's worker has not reported.
    next: u64,
    heard: Instant,
    restarts: u64,
}

/// Most restarts of one lane before it is given up (a worker that cannot
/// get past its first input would otherwise start again forever).
const MAX_RESTARTS: u64 = 10_000;

/// Runs the lanes to the deadline (or the end of the inputs, or until
/// `tick`, called every 200 ms or so, says it is enough), handing every record to `on_record` and every input
/// that was lost with its worker to `on_lost`, in the order they come.
/// Returns the number of restarts.
pub fn run(
    plan: &Plan,
    mut on_record: impl FnMut(Record),
    mut on_lost: impl FnMut(Lost),
    mut tick: impl FnMut() -> bool,
) -> u64 {
    let (tx, rx) = channel();
    let mut lanes: Vec<Lane> = (0..plan.lanes)
        .map(|lane| Lane {
            child: None,
            generation: 0,
            next: lane,
            heard: Instant::now(),
            restarts: 0,
        })
        .collect();
    for lane in 0..plan.lanes {
        start(plan, &mut lanes[lane as usize], lane, &tx);
    }
    let mut restarts = 0;
    let mut stopping = false;
    while lanes.iter().any(|l| l.child.is_some()) {
        if !stopping && (tick() || Instant::now() > plan.deadline + plan.silence) {
            stopping = true;
            for l in &mut lanes {
                if let Some(c) = &l.child {
                    kill(c);
                }
            }
        }
        let event = match rx.recv_timeout(Duration::from_millis(200)) {
            Ok(e) => Some(e),
            Err(RecvTimeoutError::Timeout) => None,
            Err(RecvTimeoutError::Disconnected) => break,
        };
        match event {
            Some(Event::Line(lane, generation, text)) => {
                let l = &mut lanes[lane as usize];
                if generation != l.generation {
                    continue;
                }
                l.heard = Instant::now();
                if let Some(r) = Record::parse(&text) {
                    l.next = r.index + plan.lanes;
                    on_record(r);
                } else {
                    // Not a record: something the worker printed on stdout.
                    eprintln!("fuzz: lane {lane}: {text}");
                }
            }
            Some(Event::Exited(lane, generation, status)) => {
                let l = &mut lanes[lane as usize];
                // Stale: a worker already killed and replaced, or given up.
                if generation != l.generation || l.child.is_none() {
                    continue;
                }
                l.child = None;
                if stopping || status.success() {
                    continue;
                }
                if status.code() == Some(EXIT_SETUP) {
                    eprintln!("fuzz: lane {lane}'s worker could not start ({status})");
                    continue;
                }
                if status.code() != Some(EXIT_AFTER_HANG) {
                    on_lost(Lost {
                        lane,
                        index: l.next,
                        what: "abort",
                        message: format!("the worker died ({})", describe(status)),
                    });
                }
                // Past the input that was lost (a hang's was reported).
                if status.code() != Some(EXIT_AFTER_HANG) {
                    l.next += plan.lanes;
                }
                if restart(plan, l, lane, &tx) {
                    restarts += 1;
                }
            }
            None => {}
        }
        // A worker that stopped answering: killed, its input a hang.
        for (lane, l) in lanes.iter_mut().enumerate() {
            let lane = lane as u64;
            if stopping || l.heard.elapsed() < plan.silence {
                continue;
            }
            let Some(c) = l.child.take() else {
                continue;
            };
            kill(&c);
            on_lost(Lost {
                lane,
                index: l.next,
                what: "hang",
                message: format!(
                    "the worker reported nothing for {} s",
                    plan.silence.as_secs()
                ),
            });
            l.next += plan.lanes;
            if restart(plan, l, lane, &tx) {
                restarts += 1;
            }
        }
    }
    restarts
}

/// Starts the lane again past its lost input, if inputs and time are left.
fn restart(plan: &Plan, l: &mut Lane, lane: u64, tx: &Sender<Event>) -> bool {
    if l.next >= plan.end || Instant::now() >= plan.deadline || l.restarts >= MAX_RESTARTS {
        return false;
    }
    l.restarts += 1;
    l.generation += 1;
    start(plan, l, lane, tx);
    l.child.is_some()
}

/// Starts lane `lane`'s worker from its next input, with threads that
/// pass its lines and its exit on to the parent.
fn start(plan: &Plan, l: &mut Lane, lane: u64, tx: &Sender<Event>) {
    let seconds = plan
        .deadline
        .saturating_duration_since(Instant::now())
        .as_secs()
        .max(1);
    let dir = plan
        .scratch
        .join(format!("lane-{lane}-start-{}", l.generation));
    let Some((program, args)) = plan.command.split_first() else {
        return;
    };
    let child = Command::new(program)
        .args(args)
        .arg("--seconds")
        .arg(seconds.to_string())
        .arg("--worker")
        .arg(lane.to_string())
        .arg("--worker-from")
        .arg(l.next.to_string())
        .arg("--worker-dir")
        .arg(&dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn();
    let mut child = match child {
        Ok(c) => c,
        Err(e) => {
            eprintln!("fuzz: cannot start lane {lane}'s worker: {e}");
            return;
        }
    };
    l.heard = Instant::now();
    let generation = l.generation;
    let out = child.stdout.take();
    let child = Arc::new(Mutex::new(child));
    let owner = Arc::clone(&child);
    let tx = tx.clone();
    std::thread::spawn(move || {
        if let Some(out) = out {
            for line in BufReader::new(out).lines() {
                let Ok(line) = line else { break };
                if tx.send(Event::Line(lane, generation, line)).is_err() {
                    return;
                }
            }
        }
        // Its output closed: the worker has ended (nothing it starts
        // inherits its standard output).
        let status = owner.lock().ok().and_then(|mut c| c.wait().ok());
        if let Some(status) = status {
            let _ = tx.send(Event::Exited(lane, generation, status));
        }
    });
    l.child = Some(child);
}

/// Kills a worker (it may have ended already).
fn kill(child: &Arc<Mutex<Child>>) {
    if let Ok(mut c) = child.lock() {
        let _ = c.kill();
    }
}

/// An exit status as a person reads it: the signal by name where known.
fn describe(status: ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match (status.code(), status.signal()) {
        (Some(c), _) => format!("exit code {c}"),
        (None, Some(6)) => {
            "SIGABRT: an allocation that failed, a stack overflow or an abort".into()
        }
        (None, Some(9)) => "SIGKILL: the out-of-memory killer, or killed".into(),
        (None, Some(11)) => "SIGSEGV".into(),
        (None, Some(s)) => format!("signal {s}"),
        (None, None) => format!("{status}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stand-in worker: prints a record for each of its lane's inputs
    /// below 12 (every second one, from `--worker-from`), and on input 4
    /// does `on_four` (dies by SIGABRT, or goes silent).
    fn lanes_with(on_four: &str, silence: Duration) -> (Vec<u64>, Vec<Lost>, u64) {
        let script = format!(
            "from=0; while [ $# -gt 0 ]; do [ \"$1\" = --worker-from ] && from=$2; shift; done\n\
             i=$from\n\
             while [ $i -lt 12 ]; do\n\
               [ $i -eq 4 ] && {on_four}\n\
               printf 'rec\\t%s\\t0\\t0\\tother\\td\\t1\\t1\\t0\\t0\\t0\\t0\\t0\\t0,0,0,0,0,0\\t-\\n' $i\n\
               i=$((i+2))\n\
             done\n"
        );
        let scratch = tempfile::tempdir().expect("temp dir");
        let plan = Plan {
            command: vec!["sh".into(), "-c".into(), script, "sh".into()],
            lanes: 2,
            end: 12,
            deadline: Instant::now() + Duration::from_secs(60),
            silence,
            scratch: scratch.path().to_path_buf(),
        };
        let (mut seen, mut lost) = (Vec::new(), Vec::new());
        let restarts = run(&plan, |r| seen.push(r.index), |l| lost.push(l), || false);
        seen.sort();
        (seen, lost, restarts)
    }

    #[test]
    fn a_worker_that_aborts_loses_one_input_which_is_reported_and_the_lane_goes_on() {
        let (seen, lost, restarts) = lanes_with("kill -ABRT $$", Duration::from_secs(30));
        assert_eq!(seen, [0, 1, 2, 3, 5, 6, 7, 8, 9, 10, 11]);
        assert_eq!(lost.len(), 1, "{lost:?}");
        assert_eq!((lost[0].lane, lost[0].index, lost[0].what), (0, 4, "abort"));
        assert!(lost[0].message.contains("SIGABRT"), "{}", lost[0].message);
        assert_eq!(restarts, 1);
    }

    #[test]
    fn a_worker_that_goes_silent_is_killed_its_input_a_hang_and_the_lane_goes_on() {
        let (seen, lost, restarts) = lanes_with("sleep 5", Duration::from_secs(1));
        assert_eq!(seen, [0, 1, 2, 3, 5, 6, 7, 8, 9, 10, 11]);
        assert_eq!(lost.len(), 1, "{lost:?}");
        assert_eq!((lost[0].lane, lost[0].index, lost[0].what), (0, 4, "hang"));
        assert_eq!(restarts, 1);
    }
}
