//! `Ranks` of a build without the `mpi` feature: there are none. A launch by mpirun with
//! several processes is refused with the way to build with MPI.

use std::convert::Infallible;
use std::path::Path;

use render::SceneFrame;

use crate::{ClusterError, ClusterFrame, Launch};

/// The processes of an MPI job; none exist in a build without the `mpi` feature.
pub struct Ranks(Infallible);

impl Ranks {
    /// `None` when this process is alone (not launched by mpirun, or one rank); the error
    /// [`ClusterError::NotBuiltWithMpi`] when launched as several.
    pub fn from_launch() -> Result<Option<Ranks>, ClusterError> {
        match Launch::from_env() {
            Some(l) if l.size > 1 => Err(ClusterError::NotBuiltWithMpi { ranks: l.size }),
            _ => Ok(None),
        }
    }

    /// This process's rank.
    pub fn rank(&self) -> usize {
        match self.0 {}
    }

    /// Processes in the job.
    pub fn size(&self) -> usize {
        match self.0 {}
    }

    /// Threads this process should start when not told (the machine's cores shared out).
    pub fn default_threads(&self) -> usize {
        match self.0 {}
    }

    /// Ends the job's agreement on `result` (see the `mpi` build).
    pub fn settle(&self, _result: Result<(), String>) -> Result<(), String> {
        match self.0 {}
    }

    /// Ends this rank's part in the job (see the `mpi` build).
    pub fn conclude(self, _result: Result<(), String>, _report: impl FnOnce(&str)) -> bool {
        match self.0 {}
    }

    /// Renders a frame over the ranks (see the `mpi` build).
    pub fn render_scene_to_file(
        &self,
        _job: &SceneFrame,
        _on_rows: Option<&mut dyn FnMut(u32, u32)>,
        _path: &Path,
    ) -> Result<ClusterFrame, ClusterError> {
        match self.0 {}
    }
}
