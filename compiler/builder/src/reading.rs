//! What reading a job's program back takes beside its text (its dialect
//! and its machine, as data): kept with a built program, so the build's
//! read-back, the spool's reader and `lensc view` read it alike.

use crate::job::JobHead;
use lensc_lang::check::CheckedJob;
use lensc_lang::lower::read_back::job_machine;
use lensc_runtime::dialect::Dialect;
use lensc_runtime::reader::MachineLimits;

/// What reading a job's program back takes beside its text: the dialect
/// it is written in and the job's machine, as data.
#[derive(Clone, Debug)]
pub struct ReadBack {
    pub dialect: Dialect,
    pub machine: MachineLimits,
}

impl ReadBack {
    /// The read-back of `job`'s program (lowered with `head`).
    pub fn of(job: &CheckedJob, head: &JobHead) -> ReadBack {
        ReadBack {
            dialect: head.dialect.clone(),
            machine: job_machine(job),
        }
    }
}
