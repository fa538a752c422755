//! Temporary files of `build` and `report` in their output directory: those
//! a lensc that no longer runs left behind are removed at the start, and
//! this run's own on SIGINT (exit 130) or SIGTERM (exit 143) before it exits.

use std::path::Path;

/// Removes the stale temporary files in `dir` and, from now on, answers
/// SIGINT and SIGTERM by removing this run's temporary files and exiting
/// with 128 + the signal's number, as a shell reports a killed command.
pub fn clean_temporaries(dir: &Path) {
    on_signal_remove_temporaries();
    let removed = lensc_build::temps::remove_stale(dir);
    if removed > 0 {
        eprintln!(
            "note: removed {removed} temporary file{} left in {} by a lensc that is no longer running",
            if removed == 1 { "" } else { "s" },
            dir.display()
        );
    }
}

#[cfg(unix)]
fn on_signal_remove_temporaries() {
    use signal_hook::consts::{SIGINT, SIGTERM};
    // A signal this process was started ignoring (a shell's background
    // job ignores SIGINT) stays ignored, as a shell's user meant it.
    let caught: Vec<libc::c_int> = [SIGINT, SIGTERM]
        .into_iter()
        .filter(|&s| !ignored(s))
        .collect();
    // Without the handler the signal still stops the build, only leaving
    // its temporary files for the next build's sweep.
    // Noted in the signal handler itself, so a run whose work ends before
    // the handler's thread is scheduled still exits as stopped.
    for &signal in &caught {
        let _ = signal_hook::flag::register_usize(signal, caught_flag(), signal as usize);
    }
    let Ok(mut signals) = signal_hook::iterator::Signals::new(caught) else {
        return;
    };
    let _ = std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                // Held until the exit: no temporary file is made meanwhile.
                let _held = lensc_build::temps::remove_all_and_hold();
                std::process::exit(128 + signal);
            }
        });
}

/// The signal caught so far (0: none), set in the signal handler.
#[cfg(unix)]
fn caught_flag() -> std::sync::Arc<std::sync::atomic::AtomicUsize> {
    static CAUGHT: std::sync::OnceLock<std::sync::Arc<std::sync::atomic::AtomicUsize>> =
        std::sync::OnceLock::new();
    CAUGHT.get_or_init(Default::default).clone()
}

/// The exit status of a run that SIGINT or SIGTERM asked to stop (128 +
/// the signal's number), whether or not its work had ended: a caller that
/// sent the signal is told the run was stopped, never 0. `None` if no
/// signal came.
pub fn stopped_status() -> Option<u8> {
    #[cfg(unix)]
    {
        let signal = caught_flag().load(std::sync::atomic::Ordering::SeqCst);
        if signal != 0 {
            // Once the temporaries are gone (the handler holds the
            // registry until it exits, so none is made meanwhile).
            let _held = lensc_build::temps::remove_all_and_hold();
            return Some((128 + signal).min(255) as u8);
        }
    }
    None
}

/// Whether `signal` is ignored (its disposition inherited from the parent).
#[cfg(unix)]
fn ignored(signal: libc::c_int) -> bool {
    // SAFETY: sigaction with no new action only reads the current one into
    // `current`, a plain C struct for which all-zeroes is a valid value.
    unsafe {
        let mut current: libc::sigaction = std::mem::zeroed();
        libc::sigaction(signal, std::ptr::null(), &mut current) == 0
            && current.sa_sigaction == libc::SIG_IGN
    }
}

#[cfg(not(unix))]
fn on_signal_remove_temporaries() {}
