//! Errors of the benchmark.

use std::path::PathBuf;

use crate::mode::TableSel;

/// Why a benchmark run or report failed.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// No backend was given.
    #[error("no ISA to benchmark")]
    NoIsa,
    /// The JSON output exists and overwriting was not asked for.
    #[error("{} exists; pass --force to overwrite it", .0.display())]
    Exists(PathBuf),
    /// The JSON output's directory does not exist.
    #[error("cannot write {}: directory {} does not exist", .file.display(), .dir.display())]
    NoDirectory {
        /// The JSON file.
        file: PathBuf,
        /// Its missing directory.
        dir: PathBuf,
    },
    /// Zero timed frames were asked for.
    #[error("--frames must be at least 1")]
    NoFrames,
    /// The plan is empty.
    #[error("nothing to measure: --table {0:?} with these --scenes selects no measurement")]
    NothingToMeasure(TableSel),
    /// A frame buffer of the plan cannot be allocated.
    #[error("a {0}x{1} frame")]
    Frame(u32, u32, #[source] render::RenderError),
    /// A rayon thread pool could not be built.
    #[error("building a thread pool")]
    ThreadPool(#[source] rayon::ThreadPoolBuildError),
    /// A mode's render settings were refused for what the scene holds.
    #[error("render settings")]
    Settings(#[source] render::SettingsError),
    /// Generating the atoms was refused (too many for this machine).
    #[error("generating the scene")]
    Generate(#[source] molecule::scenes::SceneError),
    /// Building the bonds, model or volume failed.
    #[error("building the scene")]
    Scene(#[source] scene::SceneError),
    /// Reading a file failed.
    #[error("reading {}", .0.display())]
    Read(PathBuf, #[source] std::io::Error),
    /// Writing a file failed.
    #[error("writing {}", .0.display())]
    Write(PathBuf, #[source] std::io::Error),
    /// Serialising the JSON document failed.
    #[error("serialising the JSON document")]
    Serialise(#[source] serde_json::Error),
    /// A report file is not JSON.
    #[error("{}: not JSON", .0.display())]
    NotJson(PathBuf, #[source] serde_json::Error),
    /// A report file's record lacks a field.
    #[error("{}: record without a valid {what}", .file.display())]
    BadRecord {
        /// The report file.
        file: PathBuf,
        /// The missing or invalid field.
        what: &'static str,
    },
    /// Some scenes failed; the others were measured and reported.
    #[error("{count} scene(s) failed: {list}")]
    ScenesFailed {
        /// Number of failed scenes.
        count: usize,
        /// `scene: error` per failure, `; ` separated.
        list: String,
    },
}

/// `e` and its sources, `: ` separated (as anyhow's `{:#}`).
pub fn chain(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut src = e.source();
    while let Some(c) = src {
        s.push_str(": ");
        s.push_str(&c.to_string());
        src = c.source();
    }
    s
}
