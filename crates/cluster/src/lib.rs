//! Beyond one machine (the paper's display-wall renders): the image-parallel, data-replicated
//! scheme of its MPI renderer. Every rank reads the file and builds the whole scene; the rows
//! of tiles of each band are dealt to the ranks round robin (for load balance; whole rows, so
//! that a rank's share is contiguous and needs no packing) and rendered with the rank's
//! threads; rank 0 receives each row of tiles in place, into the frame or into the band of a
//! giant frame's streamed PNG, and writes the file.
//!
//! The MPI parts need the `mpi` feature (rsmpi over OpenMPI or MPICH). Without it the crate
//! still detects a launch by `mpirun` ([`Launch`]) so that N copies of a process built without
//! MPI refuse to run instead of each rendering the whole frame into the same file.

#![warn(missing_docs)]

mod error;
mod launch;
mod tiles;

#[cfg(feature = "mpi")]
mod frame;
#[cfg(feature = "mpi")]
mod ranks;
#[cfg(not(feature = "mpi"))]
#[path = "ranks_off.rs"]
mod ranks;
mod report;

pub use error::ClusterError;
pub use launch::Launch;
pub use ranks::Ranks;
pub use report::{ClusterFrame, RankStats};
pub use tiles::{owned_tiles, row_owner, tile_rows};

/// Whether this build can run over MPI (the `mpi` feature).
pub const WITH_MPI: bool = cfg!(feature = "mpi");
