//! Runs inputs where a panic or a hang cannot take the fuzzer down: in a
//! worker thread (a large stack, as `lensc` gives its own), each input
//! under `catch_unwind` with a panic hook that records the message and
//! where it was raised, and the answer awaited with a timeout. A worker
//! that does not answer in time is abandoned and a new one started.
//!
//! Workers are named after the inputs they run (`fuzz seed S inputs
//! A..B`), so that a stack overflow, which aborts the process, names the
//! range to `--replay`.

use std::cell::RefCell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, channel};
use std::time::Duration;

use crate::harness::{Depth, Fault, MemFs, Reached};

/// Inputs one worker thread runs before the next takes over.
const BATCH: u64 = 1000;
const WORKER_PREFIX: &str = "fuzz seed ";

/// What became of one input.
pub enum Outcome {
    Done(Result<Reached, Fault>),
    Panicked(String),
    Hung,
}

/// What a worker does with an input: `targets::run`, or a stand-in in
/// the tests.
pub type Runner = fn(&MemFs, &[u8], Depth, &std::path::Path) -> Result<Reached, Fault>;

struct Job {
    bytes: Vec<u8>,
    depth: Depth,
}

struct Worker {
    jobs: Sender<Job>,
    answers: Receiver<Outcome>,
    /// The first input index past this worker's batch.
    until: u64,
}

pub struct Supervisor {
    seed: u64,
    fs: Arc<MemFs>,
    out_dir: PathBuf,
    timeout: Duration,
    worker: Option<Worker>,
    runner: Runner,
}

thread_local! {
    static PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Records panics in workers (message and location) instead of printing
/// them; any other thread's panic is reported as usual.
pub fn install_panic_hook() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let in_worker = std::thread::current()
            .name()
            .is_some_and(|n| n.starts_with(WORKER_PREFIX));
        if !in_worker {
            return default(info);
        }
        let payload = info.payload();
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "(a panic without a message)".into());
        let at = info
            .location()
            .map(|l| format!("{}:{}:{}", l.file(), l.line(), l.column()))
            .unwrap_or_default();
        PANIC.with(|p| *p.borrow_mut() = Some(format!("{message} at {at}")));
    }));
}

impl Supervisor {
    pub fn new(seed: u64, fs: Arc<MemFs>, out_dir: PathBuf, timeout: Duration) -> Supervisor {
        Supervisor {
            seed,
            fs,
            out_dir,
            timeout,
            worker: None,
            runner: crate::targets::run,
        }
    }

    /// Runs input `index` and waits for it at most the timeout.
    pub fn run(&mut self, index: u64, bytes: Vec<u8>, depth: Depth) -> Outcome {
        if self.worker.as_ref().is_none_or(|w| index >= w.until) {
            self.worker = Some(self.spawn(index));
        }
        let Some(w) = &self.worker else {
            unreachable!("a worker was just started")
        };
        if w.jobs.send(Job { bytes, depth }).is_err() {
            self.worker = None;
            return Outcome::Panicked("the worker thread died".into());
        }
        match w.answers.recv_timeout(self.timeout) {
            Ok(outcome) => outcome,
            Err(RecvTimeoutError::Timeout) => {
                // The stuck thread is left to finish on its own.
                self.worker = None;
                Outcome::Hung
            }
            Err(RecvTimeoutError::Disconnected) => {
                self.worker = None;
                Outcome::Panicked("the worker thread died".into())
            }
        }
    }

    fn spawn(&self, from: u64) -> Worker {
        let until = (from / BATCH + 1) * BATCH;
        let (jobs, job_rx) = channel::<Job>();
        let (answer_tx, answers) = channel();
        let fs = Arc::clone(&self.fs);
        let dir = self.out_dir.clone();
        let runner = self.runner;
        std::thread::Builder::new()
            .name(format!(
                "{WORKER_PREFIX}{} inputs {from}..{until}",
                self.seed
            ))
            .stack_size(256 << 20)
            .spawn(move || {
                for job in job_rx {
                    let result = catch_unwind(AssertUnwindSafe(|| {
                        runner(&fs, &job.bytes, job.depth, &dir)
                    }));
                    let outcome = match result {
                        Ok(r) => Outcome::Done(r),
                        Err(_) => Outcome::Panicked(
                            PANIC
                                .with(|p| p.borrow_mut().take())
                                .unwrap_or_else(|| "(no message recorded)".into()),
                        ),
                    };
                    if answer_tx.send(outcome).is_err() {
                        return;
                    }
                }
            })
            .expect("a worker thread starts");
        Worker {
            jobs,
            answers,
            until,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn supervisor(runner: Runner, timeout: Duration) -> Supervisor {
        install_panic_hook();
        let mut s = Supervisor::new(1, Arc::new(MemFs::new(&[])), std::env::temp_dir(), timeout);
        s.runner = runner;
        s
    }

    fn boom(_: &MemFs, bytes: &[u8], _: Depth, _: &std::path::Path) -> Result<Reached, Fault> {
        if bytes == b"boom" {
            panic!("boom went the checker");
        }
        Ok(Reached::default())
    }

    fn stuck(_: &MemFs, bytes: &[u8], _: Depth, _: &std::path::Path) -> Result<Reached, Fault> {
        if bytes == b"stuck" {
            std::thread::sleep(Duration::from_secs(5));
        }
        Ok(Reached::default())
    }

    #[test]
    fn a_panic_is_caught_with_its_message_and_the_next_input_runs() {
        let mut s = supervisor(boom, Duration::from_secs(10));
        match s.run(0, b"boom".to_vec(), Depth::Check) {
            Outcome::Panicked(m) => {
                assert!(
                    m.contains("boom went the checker") && m.contains("supervise.rs"),
                    "{m}"
                )
            }
            _ => panic!("the panic was not caught"),
        }
        assert!(matches!(
            s.run(1, b"fine".to_vec(), Depth::Check),
            Outcome::Done(Ok(_))
        ));
    }

    #[test]
    fn an_input_over_the_timeout_is_a_hang_and_a_new_worker_takes_over() {
        let mut s = supervisor(stuck, Duration::from_millis(200));
        assert!(matches!(
            s.run(0, b"stuck".to_vec(), Depth::Check),
            Outcome::Hung
        ));
        assert!(matches!(
            s.run(1, b"fine".to_vec(), Depth::Check),
            Outcome::Done(Ok(_))
        ));
    }
}
