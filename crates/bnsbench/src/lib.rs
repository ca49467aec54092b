//! The benchmark of bnsview (`bnsview bench`): reproduces the paper's results (Knoll, Wald et
//! al., UltraVis 2013, §5, Tables 1-3 and Figure 4) on this machine.
//!
//! Per scene: preprocess once (generate, bonds, BVH, density volume at the paper's
//! resolution), then for every mode × view × size × thread count × ISA of the [`plan()`] render
//! a warm-up frame and N timed frames ([`measure`]). [`report`] prints markdown tables with the
//! paper's figures ([`paper`]) beside ours (whole machine and per core); [`json`] writes every
//! measurement as JSON and reads earlier runs back.
//!
//! Scenes are built by the `scene` crate and frames rendered by the `render` crate's one
//! driver with [`BenchMode::settings`], the settings `bnsview render` uses for the same
//! picture (the CLI's tests check the two agree flag for flag).
#![warn(missing_docs)]

pub mod error;
mod figure4;
pub mod json;
pub mod measure;
pub mod mode;
pub mod paper;
pub mod plan;
pub mod probe;
pub mod record;
pub mod report;
pub mod run;

pub use error::BenchError;
pub use mode::{expand_modes, BenchMode, ModeSel, TableSel, ViewSel};
pub use plan::{plan, Key, PlanSpec, Tables};
pub use record::{Measurement, Preprocess};
pub use run::{run, run_report, Config};
