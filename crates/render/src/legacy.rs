//! The option types and entry points of the two former drivers, kept as thin adapters onto
//! the one driver ([`crate::render_frame`], [`crate::accumulate`]) until their last callers
//! (`src/bench.rs`, examples, tests) move to [`RenderSettings`].

use scene::{Camera, Model};
use spmd::Isa;
use volume::{Light, VolumeScene};

use crate::accum::Accum;
use crate::driver::{accumulate, render_frame, FrameInputs, RenderStats};
use crate::framebuffer::{Framebuffer, RenderError};
use crate::settings::{Modality, RenderSettings, SecondaryTraversal, DIRECT_AMBIENT};

/// Shading options of the headlight modes (use [`RenderSettings`] in new code).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Background colour, packed RGBA8 (see [`crate::rgba`]; alpha is ignored: 255).
    pub background: u32,
    /// Ambient term of the headlight shading: colour × (ambient + (1 − ambient)·|n·v|).
    pub ambient: f32,
    /// SIMD registers per ray packet (1, 2 or 4; 0 = the measured default per ISA).
    pub packet_registers: usize,
}

impl Default for RenderOptions {
    fn default() -> Self {
        let d = RenderSettings::default();
        RenderOptions {
            background: d.background_packed(),
            ambient: d.ambient,
            packet_registers: d.packet_registers,
        }
    }
}

impl RenderOptions {
    /// The same as [`RenderSettings`].
    pub fn settings(&self) -> RenderSettings {
        let b = self.background.to_le_bytes();
        RenderSettings {
            ambient: self.ambient,
            packet_registers: self.packet_registers,
            ..RenderSettings::headlight([b[0], b[1], b[2]])
        }
    }
}

/// Options of the ray-traced modalities (use [`RenderSettings`] in new code).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceOptions {
    /// What to compute.
    pub modality: Modality,
    /// The light of `Direct` shading and of the path tracer's next-event estimation.
    pub light: Light,
    /// Light intensity (Direct: factor of `max(0, n·l)`; Path: irradiance / π).
    pub light_intensity: f32,
    /// Ambient term of `Direct`.
    pub ambient: f32,
    /// Background colour, RGB in [0, 1] (rounded to 8 bits).
    pub background: [f32; 3],
    /// Seed of the random numbers.
    pub seed: u32,
    /// Shadow rays are attenuated by the volume when one is given.
    pub volume_shadows: bool,
    /// Step of shadow rays through the volume, voxels.
    pub shadow_step_voxels: f32,
    /// Path tracing: radiance multiplier before clamp and gamma.
    pub exposure: f32,
    /// Traversal of shadow and AO rays (and the path tracer's light samples).
    pub secondary: SecondaryTraversal,
    /// Traversal of the path tracer's bounced rays.
    pub bounces: SecondaryTraversal,
}

impl Default for TraceOptions {
    fn default() -> Self {
        let d = RenderSettings::default();
        TraceOptions {
            modality: Modality::Direct { shadows: true },
            light: d.light,
            light_intensity: d.light_intensity,
            ambient: DIRECT_AMBIENT,
            background: [1.0, 1.0, 1.0],
            seed: d.seed,
            volume_shadows: d.volume_shadows,
            shadow_step_voxels: d.shadow_step_voxels,
            exposure: d.exposure,
            secondary: d.secondary,
            bounces: d.bounces,
        }
    }
}

impl TraceOptions {
    /// Whether these options use the wide BVH.
    pub fn uses_wide(&self) -> bool {
        self.settings(1).uses_wide()
    }

    /// The same as [`RenderSettings`] with `spp` samples per pixel.
    pub fn settings(&self, spp: u32) -> RenderSettings {
        let u8c = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
        let [r, g, b] = self.background;
        RenderSettings {
            modality: self.modality,
            light: self.light,
            light_intensity: self.light_intensity,
            ambient: self.ambient,
            background: [u8c(r), u8c(g), u8c(b)],
            seed: self.seed,
            spp: spp.max(1),
            volume_shadows: self.volume_shadows,
            shadow_step_voxels: self.shadow_step_voxels,
            exposure: self.exposure,
            secondary: self.secondary,
            bounces: self.bounces,
            ..RenderSettings::default()
        }
    }
}

/// Renders `scene` into a new `width × height` frame with headlight shading.
pub fn render_bs(
    scene: &Model,
    camera: &Camera,
    width: u32,
    height: u32,
    opt: &RenderOptions,
    isa: Isa,
) -> Result<(Framebuffer, RenderStats), RenderError> {
    let mut fb = Framebuffer::new(width, height, opt.background)?;
    let stats = render_bs_into(scene, camera, &mut fb, opt, isa);
    Ok((fb, stats))
}

/// As [`render_bs`] into an existing frame.
pub fn render_bs_into(
    scene: &Model,
    camera: &Camera,
    fb: &mut Framebuffer,
    opt: &RenderOptions,
    isa: Isa,
) -> RenderStats {
    render_frame_into(Some(scene), None, camera, fb, opt, isa)
}

/// The headlight modes chosen by what is given (b&s, volume, vol+b&s) into `fb`.
///
/// # Panics
/// When neither `scene` nor `volume` is given.
pub fn render_frame_into(
    scene: Option<&Model>,
    volume: Option<&VolumeScene>,
    camera: &Camera,
    fb: &mut Framebuffer,
    opt: &RenderOptions,
    isa: Isa,
) -> RenderStats {
    let inp = FrameInputs {
        model: scene,
        volume,
        camera,
    };
    render_frame(&inp, &opt.settings(), fb, isa).unwrap_or_else(|e| panic!("{e}"))
}

/// Adds `spp` samples of a ray-traced modality into `acc` (see [`accumulate`]).
///
/// # Panics
/// When the options are invalid (see [`RenderSettings::validate`]).
pub fn render_modal_into(
    scene: &Model,
    volume: Option<&VolumeScene>,
    camera: &Camera,
    acc: &mut Accum,
    opt: &TraceOptions,
    spp: u32,
    isa: Isa,
) -> RenderStats {
    let inp = FrameInputs {
        model: Some(scene),
        volume,
        camera,
    };
    accumulate(&inp, &opt.settings(spp), acc, spp, isa).unwrap_or_else(|e| panic!("{e}"))
}

/// A new accumulation of `spp` samples, tone mapped to a frame.
#[allow(clippy::too_many_arguments)]
pub fn render_modal(
    scene: &Model,
    volume: Option<&VolumeScene>,
    camera: &Camera,
    width: u32,
    height: u32,
    opt: &TraceOptions,
    spp: u32,
    isa: Isa,
) -> Result<(Framebuffer, Accum, RenderStats), RenderError> {
    let mut acc = Accum::new(width, height)?;
    let st = render_modal_into(scene, volume, camera, &mut acc, opt, spp, isa);
    let linear = matches!(opt.modality, Modality::Path { .. });
    Ok((acc.to_framebuffer(linear, opt.exposure), acc, st))
}
