//! Whether this process was started by an MPI launcher, read from the environment the
//! launchers set (before MPI is initialised, and without MPI at all).

/// A process's place in a job started by `mpirun` (OpenMPI), `mpiexec` (MPICH, Intel MPI) or
/// MVAPICH.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Launch {
    /// This process's rank, 0-based.
    pub rank: usize,
    /// Processes in the job.
    pub size: usize,
    /// Processes of the job on this machine (for the threads each one starts).
    pub local_size: usize,
}

/// Environment variables of the size, rank and local size, per launcher.
const VARS: [[&str; 3]; 3] = [
    [
        "OMPI_COMM_WORLD_SIZE",
        "OMPI_COMM_WORLD_RANK",
        "OMPI_COMM_WORLD_LOCAL_SIZE",
    ],
    ["PMI_SIZE", "PMI_RANK", "MPI_LOCALNRANKS"],
    [
        "MV2_COMM_WORLD_SIZE",
        "MV2_COMM_WORLD_RANK",
        "MV2_COMM_WORLD_LOCAL_SIZE",
    ],
];

impl Launch {
    /// The launch this process is part of, from its environment (`None`: not launched by an
    /// MPI launcher).
    pub fn from_env() -> Option<Launch> {
        Launch::from_vars(|k| std::env::var(k).ok())
    }

    /// As [`Launch::from_env`] with the variables given by `var`.
    pub fn from_vars(var: impl Fn(&str) -> Option<String>) -> Option<Launch> {
        let num = |k: &str| var(k).and_then(|v| v.trim().parse::<usize>().ok());
        VARS.iter().find_map(|[size, rank, local]| {
            let size = num(size).filter(|&n| n > 0)?;
            Some(Launch {
                rank: num(rank).unwrap_or(0),
                size,
                local_size: num(local).filter(|&n| n > 0).unwrap_or(1),
            })
        })
    }

    /// Threads each process of this machine should start by default: the cores shared out.
    pub fn threads_per_process(&self, cores: usize) -> usize {
        (cores / self.local_size.max(1)).max(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn launches_are_read_from_each_launchers_variables() {
        fn env<'a>(pairs: &'a [(&str, &str)]) -> impl Fn(&str) -> Option<String> + 'a {
            move |k| pairs.iter().find(|p| p.0 == k).map(|p| p.1.to_string())
        }
        assert_eq!(Launch::from_vars(env(&[])), None);
        let ompi = [
            ("OMPI_COMM_WORLD_SIZE", "4"),
            ("OMPI_COMM_WORLD_RANK", "3"),
            ("OMPI_COMM_WORLD_LOCAL_SIZE", "2"),
        ];
        let l = Launch::from_vars(env(&ompi)).unwrap();
        assert_eq!((l.rank, l.size, l.local_size), (3, 4, 2));
        assert_eq!(l.threads_per_process(8), 4);
        assert_eq!(l.threads_per_process(1), 1);
        let mpich = Launch::from_vars(env(&[("PMI_SIZE", "2"), ("PMI_RANK", "1")])).unwrap();
        assert_eq!((mpich.rank, mpich.size, mpich.local_size), (1, 2, 1));
        assert_eq!(Launch::from_vars(env(&[("PMI_SIZE", "zero")])), None);
    }
}
