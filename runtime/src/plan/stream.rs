//! Planning and consuming at once: the parallel planners compute batches
//! of revolutions on rayon's threads while one consumer thread takes the
//! finished ones in order (the accounting, the program text, the
//! simulation), the two joined by a bounded channel so memory stays flat
//! however long the path. Items are made from their index alone and taken
//! in index order: the result is the same for any thread count.

use std::ops::ControlFlow;
use std::sync::mpsc::sync_channel;

use rayon::prelude::*;

/// Batches that may wait, made, for the consumer: enough to keep the
/// planner busy while the consumer catches up, and no more.
const DEPTH: usize = 2;

/// Makes items `0..count` with `make`, `batch` at a time in parallel on
/// the calling thread's rayon pool, and hands each to `take` in index
/// order on a thread of its own, while the next batches are made. `take`
/// may stop the run early (`ControlFlow::Break`): no further batch is
/// made after the one in hand. At most `DEPTH + 2` batches exist at once.
pub fn in_order<T: Send>(
    count: usize,
    batch: usize,
    make: impl Fn(usize) -> T + Sync,
    mut take: impl FnMut(T) -> ControlFlow<()> + Send,
) {
    let batch = batch.max(1);
    let (tx, rx) = sync_channel::<Vec<T>>(DEPTH);
    std::thread::scope(|s| {
        s.spawn(move || {
            for items in rx {
                for item in items {
                    if take(item).is_break() {
                        // Dropping the receiver stops the planner at its
                        // next batch.
                        return;
                    }
                }
            }
        });
        let mut first = 0;
        while first < count {
            let end = (first + batch).min(count);
            let items: Vec<T> = (first..end).into_par_iter().map(&make).collect();
            if tx.send(items).is_err() {
                break;
            }
            first = end;
        }
        drop(tx);
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn items_arrive_in_order_whatever_the_batch() {
        for batch in [1, 3, 64, 1000] {
            let mut seen = Vec::new();
            in_order(
                257,
                batch,
                |i| i * i,
                |v| {
                    seen.push(v);
                    ControlFlow::Continue(())
                },
            );
            assert_eq!(seen, (0..257).map(|i| i * i).collect::<Vec<_>>());
        }
    }

    #[test]
    fn a_stop_makes_no_further_batch() {
        let made = std::sync::atomic::AtomicUsize::new(0);
        let mut taken = 0;
        in_order(
            10_000,
            10,
            |i| {
                made.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                i
            },
            |i| {
                taken += 1;
                if i == 25 {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            },
        );
        assert_eq!(taken, 26);
        // The batch in hand, those waiting in the channel and the one
        // being made when the stop came: a few batches, not all 1,000.
        assert!(made.into_inner() <= 10 * (DEPTH + 3));
    }

    #[test]
    fn nothing_to_make_takes_nothing() {
        in_order(0, 4, |i| i, |_| panic!("no item"));
    }
}
