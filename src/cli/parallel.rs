//! Where the work runs: this process's threads, or — built with the `mpi`
//! feature and launched by `mpirun -n N` — N processes that split the
//! ranges of steps of a certification, or the b values of a b-study, and
//! gather them on rank 0, which alone writes and prints. The report is the
//! same bytes either way: ranges and their order are the schedule's.

use reconfcheck::certify::{RangeRunner, Threads};
#[cfg(feature = "mpi")]
use reconfcheck::certify::{Ranges, StepOutcome};
use reconfcheck::error::{Error, InputError};
use std::sync::OnceLock;

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
pub fn my_share(n: usize, what: &str) -> Result<Vec<usize>, InputError> {
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

/// The threads' runner for a subset of ranges: what each process uses for
/// its own share.
#[cfg(feature = "mpi")]
fn run_ranges(
    ranges: &Ranges<'_>,
    share: &[usize],
) -> Result<Vec<(usize, StepOutcome)>, InputError> {
    use rayon::prelude::*;
    let parts: Vec<Vec<(usize, StepOutcome)>> = share
        .par_iter()
        .map(|&i| ranges.run(i))
        .collect::<Result<_, InputError>>()?;
    Ok(parts.into_iter().flatten().collect())
}

#[cfg(feature = "mpi")]
mod mpi_session {
    use super::*;
    use mpi::topology::SimpleCommunicator;
    use mpi::traits::*;

    /// Set once MPI is initialised (the communicator itself is not
    /// `Sync`, so it is fetched where needed).
    static ON: OnceLock<()> = OnceLock::new();

    pub fn world() -> Option<Mpi> {
        ON.get().map(|_| Mpi)
    }

    fn comm() -> SimpleCommunicator {
        SimpleCommunicator::world()
    }

    /// Initialises MPI, runs `command`, broadcasts rank 0's exit code.
    pub fn run(command: impl FnOnce() -> Result<u8, Error>) -> Result<u8, Error> {
        let universe = mpi::initialize().ok_or_else(|| {
            InputError::new("MPI could not be initialised (was it initialised twice?)")
        })?;
        let world = universe.world();
        let place = (world.rank() as usize, world.size() as usize);
        let _ = PLACE.set(place);
        let _ = ON.set(());
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

    /// Runs each process's share of the ranges and gathers them on rank 0.
    pub struct Mpi;

    type Part = Result<Vec<(usize, StepOutcome)>, String>;

    impl RangeRunner for Mpi {
        fn run(&self, ranges: &Ranges<'_>) -> Result<Vec<(usize, StepOutcome)>, InputError> {
            let share = my_share(ranges.count(), "ranges of steps")?;
            let mine: Part = run_ranges(ranges, &share).map_err(|e| e.to_string());
            gather(mine)
        }
    }

    /// Sends every rank's part to rank 0, which returns them all; other
    /// ranks return nothing. Every rank sends, errors included, so that
    /// rank 0 never waits for a message that will not come.
    pub fn gather<T: serde::Serialize + serde::de::DeserializeOwned>(
        mine: Result<Vec<T>, String>,
    ) -> Result<Vec<T>, InputError> {
        let world = comm();
        let bytes = rmp_serde::to_vec(&mine).expect("parts serialise");
        if world.rank() != 0 {
            world.process_at_rank(0).send(&bytes[..]);
            return mine.map(|_| Vec::new()).map_err(InputError::new);
        }
        let mut all = mine.map_err(InputError::new)?;
        for r in 1..world.size() {
            let (msg, _) = world.process_at_rank(r).receive_vec::<u8>();
            let part: Result<Vec<T>, String> = rmp_serde::from_slice(&msg)
                .map_err(|e| InputError::new(format!("rank {r} sent an unreadable part: {e}")))?;
            all.extend(part.map_err(|e| InputError::new(format!("rank {r}: {e}")))?);
        }
        Ok(all)
    }
}

/// Gathers the parts of a job split with [`my_share`] on rank 0 (all of
/// them without MPI).
pub fn gather<T: serde::Serialize + serde::de::DeserializeOwned>(
    mine: Result<Vec<T>, InputError>,
) -> Result<Vec<T>, InputError> {
    #[cfg(feature = "mpi")]
    if mpi_session::world().is_some() {
        return mpi_session::gather(mine.map_err(|e| e.to_string()));
    }
    mine
}
