//! The processes of an MPI job (rsmpi): started once, they agree on whether every rank is
//! ready before working together, so that one rank's error ends the job with its message
//! instead of leaving the others waiting.

use std::cell::Cell;

use mpi::environment::Universe;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

use crate::{ClusterError, Launch};

/// The ranks of an MPI job, as seen from one of them. Dropping it finalises MPI.
pub struct Ranks {
    pub(crate) world: SimpleCommunicator,
    launch: Launch,
    /// Whether this rank has taken part in the agreement ([`Ranks::agree`]).
    agreed: Cell<bool>,
    // Dropped last: MPI_Finalize.
    _universe: Universe,
}

impl Ranks {
    /// Initialises MPI when this process was launched by mpirun as one of several ranks
    /// (`None` when it is alone: then it renders as one process, without MPI). Installs a
    /// panic hook that aborts the whole job (`MPI_Abort`) after printing the panic, so a rank
    /// that dies never leaves the others waiting.
    pub fn from_launch() -> Result<Option<Ranks>, ClusterError> {
        let Some(launch) = Launch::from_env().filter(|l| l.size > 1) else {
            return Ok(None);
        };
        // Only the main thread calls MPI; rayon's workers never do.
        let (universe, _) =
            mpi::initialize_with_threading(mpi::Threading::Funneled).ok_or(ClusterError::Init)?;
        let world = universe.world();
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            default(info);
            SimpleCommunicator::world().abort(101)
        }));
        let launch = Launch {
            rank: world.rank() as usize,
            size: world.size() as usize,
            ..launch
        };
        Ok(Some(Ranks {
            world,
            launch,
            agreed: Cell::new(false),
            _universe: universe,
        }))
    }

    /// This process's rank (0 writes the image and reports).
    pub fn rank(&self) -> usize {
        self.launch.rank
    }

    /// Processes in the job.
    pub fn size(&self) -> usize {
        self.launch.size
    }

    /// Threads this process should start when not told: this machine's cores shared out
    /// among the job's processes on it.
    pub fn default_threads(&self) -> usize {
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        self.launch.threads_per_process(cores)
    }

    /// Every rank's `result` made one (collective): `Ok` when all are ready, else on every
    /// rank [`ClusterError::Failed`] with the lowest failing rank's message.
    pub(crate) fn agree<T>(&self, result: Result<T, String>) -> Result<T, ClusterError> {
        self.agreed.set(true);
        // Each rank's message length, or -1 when it is ready.
        let mine: i64 = result.as_ref().map_or_else(|m| m.len() as i64, |_| -1);
        let mut all = vec![0i64; self.size()];
        self.world.all_gather_into(&mine, &mut all[..]);
        let Some(failed) = all.iter().position(|&n| n >= 0) else {
            return Ok(result.unwrap_or_else(|_| unreachable!("this rank's length was -1")));
        };
        let mut message = match &result {
            Err(m) if failed == self.rank() => m.clone().into_bytes(),
            _ => vec![0u8; all[failed] as usize],
        };
        let from = self.world.process_at_rank(failed as i32);
        from.broadcast_into(&mut message[..]);
        Err(ClusterError::Failed {
            rank: failed,
            ranks: self.size(),
            message: String::from_utf8_lossy(&message).into_owned(),
        })
    }

    /// This rank's outcome at the end of its command: if it failed before the ranks agreed to
    /// render, the others are still waiting at the agreement, so it takes part with its error
    /// and every rank ends with the first failing rank's message ([`ClusterError::Failed`]).
    /// After the agreement, the outcome is returned as it is (the others have stopped).
    pub fn settle(&self, result: Result<(), String>) -> Result<(), String> {
        if self.agreed.get() {
            return result;
        }
        self.agree(result).map_err(|e| e.to_string())
    }

    /// Ends this rank's part in the job with its command's `result`: [`Ranks::settle`]s it,
    /// lets rank 0 `report` the job's error, then waits for every rank (a barrier) before MPI
    /// is finalised, because mpirun kills the job as soon as one rank exits with an error
    /// and rank 0 could be killed before it has said why. Returns whether the job succeeded.
    pub fn conclude(self, result: Result<(), String>, report: impl FnOnce(&str)) -> bool {
        let result = self.settle(result);
        if let (Err(e), 0) = (&result, self.rank()) {
            report(e);
        }
        self.world.barrier();
        result.is_ok()
    }
}
