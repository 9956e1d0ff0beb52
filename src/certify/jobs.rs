//! Independent jobs — certification's ranges of steps, the b-study's
//! ranges of every branch length — handed out one at a time, in an order
//! the caller chooses (costliest first balances the workers), to this
//! process's threads or, through the binary's MPI runner, to processes.
//!
//! Every job runs, even after another failed, and results are put back in
//! job order by [`in_order`]: what a run returns, its first error
//! included, does not depend on the number of threads or processes.

use crate::error::InputError;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Each job run, with its index: `(job, result)`, in any order.
pub type Done<T> = Vec<(usize, Result<T, InputError>)>;

/// The job a worker's `k`-th ask gets from `order`, `k` counted by
/// `handed` (shared by whoever hands jobs out); `None` once all are out.
pub fn next_in(order: &[usize], handed: &AtomicUsize) -> Option<usize> {
    order.get(handed.fetch_add(1, Ordering::Relaxed)).copied()
}

/// Runs jobs on this process's threads, each thread taking the next job
/// from `next` until it returns `None` (a shared counter in one process, a
/// dispatcher across processes).
pub fn pull<T: Send>(
    next: &(dyn Fn() -> Option<usize> + Sync),
    job: &(dyn Fn(usize) -> Result<T, InputError> + Sync),
) -> Done<T> {
    let threads = rayon::current_num_threads().max(1);
    (0..threads)
        .into_par_iter()
        .with_max_len(1)
        .flat_map_iter(|_| std::iter::from_fn(|| next().map(|i| (i, job(i)))).collect::<Vec<_>>())
        .collect()
}

/// Runs every job of `order` on this process's threads.
pub fn on_threads<T: Send>(
    order: &[usize],
    job: &(dyn Fn(usize) -> Result<T, InputError> + Sync),
) -> Done<T> {
    let handed = AtomicUsize::new(0);
    pull(&|| next_in(order, &handed), job)
}

/// The results of jobs `0..n` in job order, or the error of the first job
/// (in job order) that failed; an error too if some job's result is
/// missing or came twice (a runner that lost one), never a short list.
pub fn in_order<T>(mut done: Done<T>, n: usize) -> Result<Vec<T>, InputError> {
    done.sort_by_key(|(i, _)| *i);
    if done.len() != n || done.iter().enumerate().any(|(k, (i, _))| k != *i) {
        let got: Vec<usize> = done.iter().map(|(i, _)| *i).collect();
        return Err(InputError::new(format!(
            "internal: {n} jobs were handed out, results came back for {got:?}"
        )));
    }
    done.into_iter().map(|(_, r)| r).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_job_runs_once_and_the_first_error_is_the_first_in_job_order() {
        let order: Vec<usize> = (0..40).rev().collect();
        let job = |i: usize| {
            if i % 7 == 3 {
                Err(InputError::new(format!("job {i}")))
            } else {
                Ok(i * i)
            }
        };
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let done = pool.install(|| on_threads(&order, &job));
            let mut ran: Vec<usize> = done.iter().map(|(i, _)| *i).collect();
            ran.sort_unstable();
            assert_eq!(ran, (0..40).collect::<Vec<_>>(), "{threads} threads");
            // Handed out last first, yet job 3's error is the one returned.
            assert_eq!(in_order(done, 40).unwrap_err().message, "job 3");
        }
        let fine = on_threads(&order, &|i| Ok::<usize, InputError>(i));
        assert_eq!(
            in_order(fine.clone(), 40).unwrap(),
            (0..40).collect::<Vec<_>>()
        );
        // A lost or doubled result is an error.
        let lost: Done<usize> = fine.iter().filter(|(i, _)| *i != 17).cloned().collect();
        assert!(in_order(lost, 40).is_err());
        let mut twice = fine.clone();
        twice[0].0 = twice[1].0;
        assert!(in_order(twice, 40).is_err());
    }
}
