//! Settings shared by the scene crate's tests.

use scene::{LightVolumeSettings, VolumeSettings};
use volume::{Light, VolumeFormat};

/// A coarse density (2 voxels/Å) in `format` with a light volume (directional light, every
/// second plane): small enough for tests, and every volume build stage runs.
pub fn lit_volume(format: VolumeFormat) -> VolumeSettings {
    VolumeSettings {
        voxels_per_angstrom: 2.0,
        format,
        light_volume: Some(LightVolumeSettings {
            light: Light::Directional([1.0, 2.0, 1.5]),
            step_voxels: 2.0,
            stride: 2,
        }),
        ..VolumeSettings::default()
    }
}
