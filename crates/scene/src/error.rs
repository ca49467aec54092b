//! Why a scene could not be built.

/// Errors of [`crate::Scene::build`] and [`crate::Input::load`].
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A setting is out of range.
    #[error("{name} must be {expected}, got {value}")]
    BadSetting {
        /// Setting (CLI flag name without dashes, e.g. `radius-scale`).
        name: &'static str,
        /// What it must be.
        expected: &'static str,
        /// The value given.
        value: f32,
    },
    /// Two settings that do not go together (the message says which and the way out).
    #[error("{0}")]
    Unsupported(&'static str),
    /// Colouring by a per-atom column the input does not have.
    #[error("--color {name}: the input has no such per-atom column (it has: element{})",
        available.iter().map(|a| format!(", {a}")).collect::<String>())]
    NoSuchColumn {
        /// Requested column.
        name: String,
        /// Columns the input has.
        available: Vec<String>,
    },
    /// A colour range that is empty, reversed or not finite.
    #[error("--color-range {lo}:{hi}: expected two finite values LO:HI with LO < HI")]
    BadColorRange {
        /// Low end given.
        lo: f32,
        /// High end given.
        hi: f32,
    },
    /// Drawing the cell of an input that has none.
    #[error("--cell: the input has no simulation cell (box) to draw")]
    NoCell,
    /// [`crate::BondSource::File`] but the input lists no bonds.
    #[error("--bonds file: the input lists no bonds (LAMMPS data Bonds / PDB CONECT)")]
    NoFileBonds,
    /// The bond search refused the atoms (extent or bond count; see [`molecule::bonds::BondError`]).
    #[error(transparent)]
    Bonds(#[from] molecule::bonds::BondError),
    /// Unwrapping failed (no cell, bad image flags; see [`molecule::unwrap::UnwrapError`]).
    #[error("--unwrap: {0}")]
    Unwrap(#[from] molecule::unwrap::UnwrapError),
    /// No atoms.
    #[error("no atoms to build a scene of")]
    NoAtoms,
    /// The density grid is zero at every lattice point: its spacing is coarser than the
    /// atoms' support (each atom's density reaches √2·r from its centre), so the transfer
    /// function would have no range and the volume nothing to show.
    #[error(
        "the density is zero at every lattice point at {voxels_per_angstrom} voxels/Å: \
        the lattice is coarser than the atoms (each reaches √2 times its radius, a few Å); \
        use a finer --voxels-per-angstrom (1 to 4 are typical)"
    )]
    EmptyDensity {
        /// The resolution asked for.
        voxels_per_angstrom: f32,
    },
    /// The estimate exceeds the memory budget (checked before anything large is allocated).
    #[error("the scene would need about {} MB ({}), over the memory budget of {} MB; \
        fewer atoms, --style spheres (no sticks) or a coarser --voxels-per-angstrom need \
        less, and --memory-budget MB allows more (the default is 75 % of the memory \
        available)",
        needed / 1_000_000, breakdown, budget / 1_000_000)]
    TooLarge {
        /// Estimated bytes still to allocate: [`crate::MemoryEstimate::peak_bytes`] less the
        /// baseline, the frame and the bonds already resident.
        needed: u64,
        /// Allowed bytes.
        budget: u64,
        /// The largest components, human readable.
        breakdown: String,
    },
    /// Reading the input file failed (file, line, what was expected).
    #[error(transparent)]
    Read(Box<molecule::read::ReadError>),
    /// A built-in scene could not be generated (too many atoms for the limit or the memory).
    #[error(transparent)]
    Generate(#[from] molecule::scenes::SceneError),
    /// A frame other than 0 of a built-in scene.
    #[error("--frame {frame}: built-in scenes have a single frame")]
    OneFrame {
        /// The frame asked for.
        frame: i64,
    },
    /// The build was stopped by its [`crate::Progress::cancelled`] test before it finished
    /// (e.g. a viewer whose user moved on to another time step); nothing was kept.
    #[error("the scene's build was cancelled")]
    Cancelled,
    /// The density volume failed (bad input, resolution or over its own budget); its
    /// message names the volume (shown once, also in an error chain).
    #[error(transparent)]
    Volume(#[from] volume::VolumeError),
}
