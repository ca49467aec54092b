//! The benchmark of bnsview (`bnsview bench`): reproduces the paper's results (Knoll, Wald et
//! al., UltraVis 2013, §5, Tables 1-3 and Figure 4) on this machine.
//!
//! Per scene: preprocess once (generate, bonds, BVH, density volume at the paper's
//! resolution), then for every mode × view × size × thread count × ISA of the [`plan`] render
//! a warm-up frame and N timed frames ([`measure`]). [`report`] prints markdown tables with the
//! paper's figures ([`paper`]) beside ours (whole machine and per core); [`json`] writes every
//! measurement as JSON and reads earlier runs back.
//!
//! The application supplies scene building and render settings through the [`Pipeline`]
//! trait, so that this crate does not depend on how the CLI spells its flags.
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

pub use error::{BenchError, PipelineError};
pub use measure::{FrameSetup, Loaded, Pipeline};
pub use mode::{expand_modes, BenchMode, ModeSel, TableSel};
pub use plan::{plan, Key, PlanSpec, Tables};
pub use record::{Measurement, Preprocess};
pub use run::{run, run_report, Config};
