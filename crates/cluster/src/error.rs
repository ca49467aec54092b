//! What can stop a job of several ranks.

/// An error of a job over MPI.
#[derive(Debug, thiserror::Error)]
pub enum ClusterError {
    /// Launched by mpirun with several ranks, but built without the `mpi` feature.
    #[error(
        "launched as {ranks} processes (mpirun), but this bnsview is built without MPI: each \
         would render the whole frame into the same file. Build it with `cargo build --release \
         --features mpi` (README, \"On a cluster\"), or run it as one process"
    )]
    NotBuiltWithMpi {
        /// Processes launched.
        ranks: usize,
    },
    /// MPI could not be initialised.
    #[error("MPI could not be initialised (already initialised in this process?)")]
    Init,
    /// A rank failed; every rank stops with its message.
    #[error("rank {rank} of {ranks}: {message}")]
    Failed {
        /// The first rank that failed.
        rank: usize,
        /// Ranks in the job.
        ranks: usize,
        /// What it said.
        message: String,
    },
    /// Rank 0 failed while writing the frame (it reports why); this rank stopped.
    #[error("stopped: rank 0 failed writing the frame")]
    Stopped,
}
