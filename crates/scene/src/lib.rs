//! Scene assembly (paper §4.1): from a molecule frame and typed [`SceneSettings`] to what the
//! renderer traces — bonds, the ball-and-stick [`Model`] (geometry, BVH, per-slot colours),
//! the density volume with macrocells and the light volume ([`Scene::build`]) — with one
//! [`MemoryEstimate`] checked before allocation, and camera fitting ([`bounding_sphere`],
//! [`Camera::fit`]) with the paper's far/close views (Table 3).
//!
//! Units: positions and radii in Ångström (Å); field of view and orbit angles in degrees.
#![warn(missing_docs)]

mod build;
mod camera;
mod camera_spec;
mod colormap;
mod describe;
mod error;
mod fit;
mod frame_bands;
mod input;
mod memory;
mod model;
mod periodic;
mod progress;
mod report;
mod settings;
pub mod text;

pub use build::{Density, DensityVolume, Prepared, Scene, SharedModel, UnwrapReport};
pub use camera::{Camera, Projection, View};
pub use camera_spec::CameraSpecError;
pub use colormap::{viridis, Colormap};
pub use describe::{Description, EstimateFor};
pub use error::SceneError;
pub use fit::{
    ball_sphere, bounding_sphere, CameraChoice, Orbit, Sphere, ViewPreset, ATOM_SPHERE_PAD,
};
pub use frame_bands::{
    band_rows, held_frame_bytes, is_streamed, BAND_BYTES, BAND_ROW_MULTIPLE, STREAM_ABOVE_BYTES,
};
pub use input::{Input, LoadedFrame};
pub use memory::{
    retained_bytes, MemoryEstimate, Peak, PeakPhase, BASELINE_BYTES, BVH_NODES_PER_PRIM,
    WIDE_NODES_PER_PRIM,
};
pub use model::{Coloring, Model, ModelOptions, Style, CELL_COLOR};
pub use periodic::{add_cell_edges, split_periodic_sticks};
pub use progress::{Progress, Stage, Timings};
pub use settings::{
    BondSettings, BondSource, ColorBy, DensitySource, LightVolumeSettings, ModelSettings,
    RadiusKind, SceneSettings, VolumeSettings, LIGHT_VOLUME_STRIDE,
};

/// Packs an RGBA8 colour as the framebuffer stores it (`r | g << 8 | b << 16 | a << 24`).
pub const fn rgba(r: u8, g: u8, b: u8, a: u8) -> u32 {
    r as u32 | (g as u32) << 8 | (b as u32) << 16 | (a as u32) << 24
}
