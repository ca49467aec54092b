//! What a scene build reports while it runs: the [`Stage`] it starts, the units it finishes
//! ([`Progress`], which also carries the caller's cancel test) and the wall time of each
//! stage ([`Timings`]).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use crate::SceneError;

/// A stage of [`crate::Scene::build`], reported to the progress callback when it starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Bond detection.
    Bonds,
    /// Model geometry and BVH (and the wide BVH when used).
    Model,
    /// Density volume.
    Volume,
    /// Macrocells and transfer-function classification.
    Macrocells,
    /// Light volume.
    LightVolume,
    /// Generating a built-in scene ([`crate::Input::load`]; 1 unit).
    Generate,
    /// Reading a frame of a file (bytes decoded; 0 units when the size is not known up
    /// front, as for a gzip file).
    Read,
    /// Scanning the whole file for its number of frames (bytes decoded; 0 when unknown).
    CountFrames,
}

impl std::fmt::Display for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Stage::Bonds => "bonds",
            Stage::Model => "BVH",
            Stage::Volume => "density volume",
            Stage::Macrocells => "macrocells",
            Stage::LightVolume => "light volume",
            Stage::Generate => "generating",
            Stage::Read => "reading",
            Stage::CountFrames => "counting the frames",
        })
    }
}

/// Where [`crate::Scene::build_with`] reports progress: `stage` is called as each stage starts, with
/// the units of work the stage counts (atoms searched for bonds, primitives placed in the BVH,
/// slab passes of the density, z-planes of the light volume, 1 for macrocells); the stage adds
/// the units it finishes to `done`, which is set to 0 after `stage` returns (so `stage` still
/// reads the last stage's count) and before the work starts, so another thread can draw a
/// bar from the two. [`crate::Input::load`] reports through it too.
pub struct Progress<'a> {
    /// Called as each stage starts with its total units.
    pub stage: &'a dyn Fn(Stage, u64),
    /// Units finished in the running stage (shared: a file reader counts into it).
    pub done: Arc<AtomicU64>,
    /// Asked at each stage's start and before each of the density's slab passes; once it
    /// returns true the build stops with [`SceneError::Cancelled`] (a viewer's loader stops
    /// building a time step the user has moved past).
    pub cancelled: &'a (dyn Fn() -> bool + Sync),
}

impl Progress<'_> {
    /// Progress reported nowhere, never cancelled.
    pub fn none() -> Progress<'static> {
        Progress {
            stage: &|_, _| {},
            done: Arc::new(AtomicU64::new(0)),
            cancelled: &|| false,
        }
    }

    /// Progress reported to `stage` and `done`, never cancelled.
    pub fn new<'a>(stage: &'a dyn Fn(Stage, u64), done: Arc<AtomicU64>) -> Progress<'a> {
        Progress {
            stage,
            done,
            cancelled: &|| false,
        }
    }

    /// Announces `stage` of `total` units and resets `done`; [`SceneError::Cancelled`]
    /// instead when the build is no longer wanted.
    pub(crate) fn start(&self, stage: Stage, total: u64) -> Result<(), SceneError> {
        if (self.cancelled)() {
            return Err(SceneError::Cancelled);
        }
        (self.stage)(stage, total);
        self.done.store(0, Ordering::Relaxed);
        Ok(())
    }
}

/// Wall time of each stage (seconds; 0 for stages not run).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Bond detection.
    pub bonds: f64,
    /// Model geometry and BVH (the BVH alone: `model.bvh.stats.build_time`).
    pub model: f64,
    /// Density volume.
    pub volume: f64,
    /// Macrocells and transfer-function classification.
    pub macrocells: f64,
    /// Light volume.
    pub light_volume: f64,
}
