//! Where the work runs: this process's threads, or — built with the `mpi`
//! feature and launched by `mpirun -n N` — N processes that split the
//! ranges of steps of a certification, or the b values of a b-study, and
//! gather them on rank 0, which alone writes and prints. The report is the
//! same bytes either way: ranges and their order are the schedule's.

use reconfcheck::certify::jobs::{self, Done};
use reconfcheck::certify::{RangeRunner, Threads};
#[cfg(feature = "mpi")]
use reconfcheck::certify::{Ranges, StepOutcome};
use reconfcheck::error::{Error, InputError};
use serde::{Serialize, de::DeserializeOwned};
use std::sync::OnceLock;
#[cfg(feature = "mpi")]
use std::sync::atomic::AtomicUsize;

/// This process's rank and the number of processes (0 of 1 without MPI).
static PLACE: OnceLock<(usize, usize)> = OnceLock::new();

/// Whether an MPI launcher started this process as one of several
/// (Open MPI's and MPICH's environment).
fn launched_by_mpi() -> Option<usize> {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"]
        .iter()
        .find_map(|v| std::env::var(v).ok())
        .and_then(|n| n.parse().ok())
}

/// Whether this process writes the outputs (rank 0, or the only process).
pub fn is_root() -> bool {
    PLACE.get().is_none_or(|&(rank, _)| rank == 0)
}

/// Splits `n` independent jobs over the processes: the indices this one
/// runs. Refused when a process would get none (it could not contribute,
/// and the split would hide a mistake in the launch).
#[cfg(feature = "mpi")]
fn my_share(n: usize, what: &str) -> Result<Vec<usize>, InputError> {
    let (rank, size) = PLACE.get().copied().unwrap_or((0, 1));
    if n < size {
        return Err(InputError::new(format!(
            "{size} processes for {n} {what}: each process needs at least one; run with at most {n}"
        )));
    }
    Ok((rank..n).step_by(size).collect())
}

/// The runner of certification's ranges in this process's setting.
pub fn runner() -> Box<dyn RangeRunner> {
    #[cfg(feature = "mpi")]
    if let Some(m) = mpi_session::world() {
        return Box::new(m);
    }
    Box::new(Threads)
}

/// Runs jobs (handed out in `order`) on this process's threads, or under
/// MPI on every process's, and returns every job's result on rank 0;
/// `None` on the other ranks. `what` names the jobs when there are fewer
/// than processes (refused: a process without work hides a mistake).
pub fn run_jobs<T: Serialize + DeserializeOwned + Send>(
    order: &[usize],
    job: &(dyn Fn(usize) -> Result<T, InputError> + Sync),
    what: &str,
) -> Result<Option<Done<T>>, InputError> {
    #[cfg(feature = "mpi")]
    if let Some(m) = mpi_session::world() {
        return m.run_jobs(order, job, what);
    }
    let _ = what;
    Ok(Some(jobs::on_threads(order, job)))
}

/// Runs `command` on every process and returns the exit code all of them
/// end with: rank 0's, broadcast, so that `mpirun` reports one verdict.
pub fn run(command: impl FnOnce() -> Result<u8, Error>) -> Result<u8, Error> {
    match launched_by_mpi() {
        Some(n) if n > 1 => {}
        _ => {
            let _ = PLACE.set((0, 1));
            return command();
        }
    }
    #[cfg(feature = "mpi")]
    {
        mpi_session::run(command)
    }
    #[cfg(not(feature = "mpi"))]
    {
        Err(InputError::new(
            "started by an MPI launcher with several processes, but this reconfcheck was built \
             without the `mpi` feature: every process would do all the work; rebuild with \
             `cargo build --release --features mpi`, or run without mpirun",
        )
        .into())
    }
}

#[cfg(feature = "mpi")]
mod mpi_session {
    use super::*;
    use mpi::point_to_point::MatchedReceiveVec;
    use mpi::topology::SimpleCommunicator;
    use mpi::traits::*;

    /// Set once MPI is initialised (the communicator itself is not
    /// `Sync`, so it is fetched where needed); holds whether MPI granted
    /// calls from several threads at once, which the dispatcher needs.
    static ON: OnceLock<bool> = OnceLock::new();

    /// A thread asks rank 0 for a range (empty message).
    const ASK: mpi::Tag = 11;
    /// Rank 0's answer: a range index, or −1 for "none left".
    const GIVE: mpi::Tag = 12;
    /// A rank's findings, sent once to rank 0.
    const PART: mpi::Tag = 13;

    pub fn world() -> Option<Mpi> {
        ON.get().map(|&dispatch| Mpi { dispatch })
    }

    fn comm() -> SimpleCommunicator {
        SimpleCommunicator::world()
    }

    /// Initialises MPI, runs `command`, broadcasts rank 0's exit code.
    pub fn run(command: impl FnOnce() -> Result<u8, Error>) -> Result<u8, Error> {
        let (universe, granted) = mpi::initialize_with_threading(mpi::Threading::Multiple)
            .ok_or_else(|| {
                InputError::new("MPI could not be initialised (was it initialised twice?)")
            })?;
        let world = universe.world();
        let place = (world.rank() as usize, world.size() as usize);
        let _ = PLACE.set(place);
        let _ = ON.set(granted == mpi::Threading::Multiple);
        let result = command();
        // Rank 0's verdict is everyone's; an error on rank 0 is code 2 or 3.
        let mut code: u8 = match &result {
            Ok(c) => *c,
            Err(e) => e.exit_code(),
        };
        // Rank 0 says why before the broadcast releases the others: once
        // one process exits non-zero, mpirun aborts the rest, and rank 0's
        // message would be lost if it came later.
        if place.0 == 0
            && let Err(e) = &result
        {
            eprintln!("error: {e}");
        }
        comm().process_at_rank(0).broadcast_into(&mut code);
        Ok(code)
    }

    /// Runs jobs over the processes and gathers their results on rank 0.
    ///
    /// With MPI's full thread support, jobs are handed out one at a time,
    /// in the caller's order (costliest first), by a dispatcher thread on
    /// rank 0 (a range's cost varies tenfold over a schedule, so a fixed
    /// split leaves most processes idle behind the one with the late
    /// ranges). Without it, rank r runs the jobs at positions r, r + N, …
    /// of the order. Either way the results carry their job index, so what
    /// the caller makes of them does not depend on who ran what.
    pub struct Mpi {
        dispatch: bool,
    }

    impl Mpi {
        pub fn run_jobs<T: Serialize + DeserializeOwned + Send>(
            &self,
            order: &[usize],
            job: &(dyn Fn(usize) -> Result<T, InputError> + Sync),
            what: &str,
        ) -> Result<Option<Done<T>>, InputError> {
            // Every process must get work, whichever way it is handed out.
            let share = my_share(order.len(), what)?;
            if !self.dispatch {
                let mine: Vec<usize> = share.iter().map(|&k| order[k]).collect();
                return gather(jobs::on_threads(&mine, job));
            }
            if comm().rank() != 0 {
                return gather(jobs::pull(&|| ask_rank_0(&comm()), job));
            }
            // Rank 0's own threads take jobs from the counter; the
            // dispatcher alone talks to the other ranks (answers and
            // parts), so MPI is never called from two threads at once here.
            let handed = AtomicUsize::new(0);
            let next = || jobs::next_in(order, &handed);
            std::thread::scope(|s| {
                let dispatcher = s.spawn(|| serve(&next));
                let mine = jobs::pull(&next, job);
                let parts = dispatcher.join().expect("the dispatcher does not panic");
                combine(mine, parts).map(Some)
            })
        }
    }

    impl RangeRunner for Mpi {
        fn run(&self, ranges: &Ranges<'_>) -> Result<Vec<(usize, StepOutcome)>, InputError> {
            match self.run_jobs(&ranges.order(), &|i| ranges.run(i), "ranges of steps")? {
                Some(done) => ranges.findings(done),
                None => Ok(Vec::new()),
            }
        }
    }

    /// One thread's request for its next job. Answers may cross between
    /// a process's threads; each ask gets one answer, so they balance.
    fn ask_rank_0(world: &SimpleCommunicator) -> Option<usize> {
        let root = world.process_at_rank(0);
        root.send_with_tag(&0u8, ASK);
        let (i, _) = root.receive_with_tag::<i64>(GIVE);
        usize::try_from(i).ok()
    }

    /// Rank 0's dispatcher: answers every ask with the next job of `next`
    /// (or −1) and collects the other ranks' parts, until it has them all.
    /// It polls, sleeping between empty polls, so that it does not take a
    /// core from the jobs.
    fn serve(next: &(dyn Fn() -> Option<usize> + Sync)) -> Vec<(i32, Vec<u8>)> {
        let world = comm();
        let mut parts = Vec::new();
        while parts.len() + 1 < world.size() as usize {
            let Some((msg, status)) = world.any_process().immediate_matched_probe() else {
                std::thread::sleep(std::time::Duration::from_micros(200));
                continue;
            };
            if status.tag() == PART {
                parts.push((
                    status.source_rank(),
                    (msg, status).matched_receive_vec::<u8>().0,
                ));
                continue;
            }
            let _: (u8, _) = msg.matched_receive();
            let answer = next().map_or(-1, |i| i as i64);
            world
                .process_at_rank(status.source_rank())
                .send_with_tag(&answer, GIVE);
        }
        parts
    }

    /// Sends every rank's results to rank 0, which returns them all
    /// (`None` on the other ranks). Rank 0 receives every part before it
    /// reports anything, so that no rank is left blocked in its send.
    fn gather<T: Serialize + DeserializeOwned>(
        mine: Done<T>,
    ) -> Result<Option<Done<T>>, InputError> {
        let world = comm();
        if world.rank() != 0 {
            world
                .process_at_rank(0)
                .send_with_tag(&encode(&mine)[..], PART);
            return Ok(None);
        }
        let parts = (1..world.size())
            .map(|r| {
                (
                    r,
                    world.process_at_rank(r).receive_vec_with_tag::<u8>(PART).0,
                )
            })
            .collect();
        combine(mine, parts).map(Some)
    }

    /// Rank 0's results and the other ranks' encoded parts, together. A
    /// job's error travels as its message and reads as on one process.
    fn combine<T: DeserializeOwned>(
        mut all: Done<T>,
        parts: Vec<(i32, Vec<u8>)>,
    ) -> Result<Done<T>, InputError> {
        for (r, msg) in parts {
            let part = decode::<T>(&msg)
                .map_err(|e| InputError::new(format!("rank {r} sent an unreadable part: {e}")))?;
            all.extend(
                part.into_iter()
                    .map(|(i, res)| (i, res.map_err(InputError::new))),
            );
        }
        Ok(all)
    }
}

/// A rank's part as MessagePack, with field names: the report's types skip
/// fields at their default (a violation's `severity`, empty maps), which a
/// positional encoding cannot tell apart from the next field.
#[cfg(feature = "mpi")]
fn encode<T: Serialize>(done: &Done<T>) -> Vec<u8> {
    let wire: Vec<(usize, Result<&T, String>)> = done
        .iter()
        .map(|(i, r)| (*i, r.as_ref().map_err(|e| e.to_string())))
        .collect();
    rmp_serde::to_vec_named(&wire).expect("parts serialise")
}

/// A part as [`encode`] wrote it: each job's result, an error as its
/// message.
#[cfg(feature = "mpi")]
type Wire<T> = Vec<(usize, Result<T, String>)>;

#[cfg(feature = "mpi")]
fn decode<T: DeserializeOwned>(bytes: &[u8]) -> Result<Wire<T>, rmp_serde::decode::Error> {
    rmp_serde::from_slice(bytes)
}

#[cfg(all(test, feature = "mpi"))]
mod tests {
    use super::*;
    use reconfcheck::algorithms::scaffold::{ShapeSpec, scaffold_schedule};
    use reconfcheck::certify::{Options, certify};

    #[test]
    fn a_part_with_violations_and_skipped_fields_comes_back_whole() {
        // The 2-pyramid at b = 9 is overloaded from step 84 on: its
        // violations skip `severity` (an error) in the encoding.
        let s = scaffold_schedule(&ShapeSpec::Pyramid { h: 2 }, 9).unwrap();
        let models = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
        let opts = Options {
            model: Some(models.join("catom-3.6mm.toml")),
            ..Default::default()
        };
        let report = certify(&s, &opts).unwrap();
        assert!(!report.violations.is_empty());
        let part: Done<Vec<_>> = vec![
            (3, Ok(report.violations.clone())),
            (5, Err(InputError::new("step 7: clash"))),
        ];
        let back: Wire<Vec<reconfcheck::certify::Violation>> = decode(&encode(&part)).unwrap();
        assert_eq!(back[0].0, 3);
        assert_eq!(
            serde_json::to_string(back[0].1.as_ref().unwrap()).unwrap(),
            serde_json::to_string(&report.violations).unwrap()
        );
        // An error comes back as its message.
        assert_eq!(back[1].0, 5);
        assert_eq!(back[1].1.as_ref().unwrap_err(), "step 7: clash");
    }
}
