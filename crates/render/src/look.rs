//! What a frame shows and how it is lit, as one typed value ([`Look`]): the choices behind
//! `render`'s and `view`'s flags and `bench`'s modes, and the one place their policy lives —
//! which light the volume uses, which background a mode gets, when the light volume and the
//! wide BVH are built.

use scene::{
    BondSettings, DensitySource, LightVolumeSettings, ModelSettings, SceneSettings, VolumeSettings,
    LIGHT_VOLUME_STRIDE,
};
use volume::{Light, Lighting, MarchOptions, VolumeShadows};

use crate::settings::{
    Material, Modality, RenderSettings, SecondaryTraversal, SettingsError, DARK_BACKGROUND,
    DIRECT_AMBIENT, HEADLIGHT_AMBIENT, WHITE_BACKGROUND,
};

/// What a frame shows (the rows of the paper's Table 3, and path tracing).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Mode {
    /// Ball-and-stick, headlight diffuse shading.
    #[default]
    Bs,
    /// Direct volume rendering of the RBF density alone.
    Volume,
    /// Ball-and-stick, then the volume in front of it.
    #[cfg_attr(feature = "clap", value(name = "vol+bs"))]
    VolBs,
    /// Ball-and-stick, path traced (`--material`, `--spp`): progressive f32 accumulation.
    Path,
}

impl Mode {
    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Bs => "bs",
            Mode::Volume => "volume",
            Mode::VolBs => "vol+bs",
            Mode::Path => "path",
        }
    }

    /// Whether the frame shows the ball-and-stick model.
    pub fn has_model(self) -> bool {
        self != Mode::Volume
    }

    /// Whether the frame shows the density volume.
    pub fn has_volume(self) -> bool {
        matches!(self, Mode::Volume | Mode::VolBs)
    }
}

/// Everything that decides a frame's picture besides the atoms, the camera and the size.
/// [`Look::scene_settings`] says what to build, [`Look::render_settings`] how to shade it.
#[derive(Clone, Debug, PartialEq)]
pub struct Look {
    /// What to draw.
    pub mode: Mode,
    /// The ball-and-stick model (used when `mode` shows one; `wide_bvh` is decided here).
    pub model: ModelSettings,
    /// The density volume and its transfer function (used when `mode` shows one;
    /// `light_volume` is decided here).
    pub volume: VolumeSettings,
    /// Factor on every opacity of `volume.tf` (clamped to 1).
    pub opacity: f32,
    /// Background colour, RGB 0-255 (`None`: white for `Bs`, near-black for the others).
    pub background: Option<[u8; 3]>,
    /// Gradient lighting of the volume.
    pub lit: bool,
    /// Ball-and-stick: diffuse light with hard shadows.
    pub shadows: bool,
    /// Ball-and-stick: ambient occlusion with this many rays per hit.
    pub ao: Option<u32>,
    /// Ambient occlusion distance (Å).
    pub ao_distance: f32,
    /// The light of shadows, of the path tracer and of the lit volume (`None`: the default
    /// direction, and the lit volume uses a headlight unless `volume_shadows`).
    pub light: Option<Light>,
    /// Light intensity (shadows: factor of max(0, n·l); path: irradiance / π).
    pub light_intensity: f32,
    /// Ambient term of the traced modalities (the headlight modes use
    /// [`HEADLIGHT_AMBIENT`]).
    pub ambient: f32,
    /// The volume casts shadows (paper §4.5).
    pub volume_shadows: bool,
    /// Step of shadow rays through the volume (voxels).
    pub shadow_step: f32,
    /// Volumetric shadows by a shadow ray per sample instead of the precomputed light volume.
    pub shadow_rays: bool,
    /// Path tracing: BRDF of the atoms.
    pub material: Material,
    /// Path tracing: samples per pixel.
    pub spp: u32,
    /// Path tracing: maximum hits per path.
    pub max_depth: u32,
    /// Path tracing, metal: roughness (0 = mirror).
    pub roughness: f32,
    /// Path tracing: radiance multiplier before clamp and gamma 2.
    pub exposure: f32,
    /// Seed of the random numbers of AO and path tracing.
    pub sample_seed: u32,
    /// Traversal of shadow and AO rays and of the path tracer's light samples.
    pub secondary: SecondaryTraversal,
    /// Traversal of the path tracer's bounced rays.
    pub bounces: SecondaryTraversal,
    /// Volume: skip empty macrocells.
    pub macrocells: bool,
    /// Volume: pre-integrated classification (else post-classification).
    pub preintegrated: bool,
    /// Most bytes the scene build may allocate (its estimated peak, checked before anything
    /// large is allocated); `None`: 75 % of the memory available when the build starts.
    pub memory_budget: Option<u64>,
}

impl Default for Look {
    /// The CLI's defaults: ball-and-stick, default light, 16 spp metal paths.
    fn default() -> Self {
        let r = RenderSettings::default();
        Look {
            mode: Mode::Bs,
            model: ModelSettings::default(),
            volume: VolumeSettings::default(),
            opacity: 1.0,
            background: None,
            lit: false,
            shadows: false,
            ao: None,
            ao_distance: 4.0,
            light: None,
            light_intensity: r.light_intensity,
            ambient: DIRECT_AMBIENT,
            volume_shadows: false,
            shadow_step: r.shadow_step_voxels,
            shadow_rays: false,
            material: Material::Metal,
            spp: 16,
            max_depth: 6,
            roughness: 0.15,
            exposure: r.exposure,
            sample_seed: r.seed,
            secondary: r.secondary,
            bounces: r.bounces,
            macrocells: true,
            preintegrated: true,
            memory_budget: None,
        }
    }
}

impl Look {
    /// The modality asked for (`Headlight`: the plain b&s / volume / vol+bs modes).
    pub fn modality(&self) -> Modality {
        match (self.mode, self.ao) {
            (Mode::Path, _) => Modality::Path {
                material: self.material,
                max_depth: self.max_depth,
                roughness: self.roughness,
            },
            (_, Some(samples)) => Modality::Ao {
                samples,
                distance: self.ao_distance,
            },
            _ if self.shadows => Modality::Direct { shadows: true },
            _ => Modality::Headlight,
        }
    }

    /// The light: the given one, else the default direction.
    pub fn light(&self) -> Light {
        self.light.unwrap_or(RenderSettings::default().light)
    }

    /// Background colour: the given one, else white for `Bs` and near-black for the others.
    pub fn background(&self) -> [u8; 3] {
        match (self.background, self.mode) {
            (Some(c), _) => c,
            (None, Mode::Bs) => WHITE_BACKGROUND,
            (None, _) => DARK_BACKGROUND,
        }
    }

    /// Colour of a legend's text: whichever of black and white stands out from the
    /// background (luma above or below half).
    pub fn legend_ink(&self) -> [u8; 3] {
        let [r, g, b] = self.background().map(f32::from);
        let luma = 0.299 * r + 0.587 * g + 0.114 * b;
        if luma > 128.0 {
            [0, 0, 0]
        } else {
            [255, 255, 255]
        }
    }

    /// The volume marcher's options: lighting (a headlight unless a light is given or
    /// shadows need one), volumetric shadows, macrocells and pre-integration.
    pub fn march_options(&self) -> MarchOptions {
        let explicit = self.light.is_some() || self.volume_shadows;
        let lighting = match (self.lit, explicit, self.light()) {
            (false, _, _) => Lighting::Unlit,
            (true, false, _) => Lighting::Headlight,
            (true, true, Light::Directional(d)) => Lighting::Directional(d),
            (true, true, Light::Point(p)) => Lighting::Point(p),
        };
        MarchOptions {
            macrocells: self.macrocells,
            preintegrated: self.preintegrated,
            lighting,
            shadows: self.volume_shadows.then(|| VolumeShadows {
                light: self.light(),
                step_voxels: self.shadow_step,
            }),
            ..MarchOptions::default()
        }
    }

    /// How to shade the frame (one sample per pixel except path tracing).
    pub fn render_settings(&self) -> RenderSettings {
        let modality = self.modality();
        RenderSettings {
            modality,
            march: self.march_options(),
            light: self.light(),
            light_intensity: self.light_intensity,
            ambient: match modality {
                Modality::Headlight => HEADLIGHT_AMBIENT,
                _ => self.ambient,
            },
            background: self.background(),
            exposure: self.exposure,
            seed: self.sample_seed,
            spp: if self.mode == Mode::Path { self.spp } else { 1 },
            volume_shadows: self.volume_shadows,
            shadow_step_voxels: self.shadow_step,
            secondary: self.secondary,
            bounces: self.bounces,
            packet_registers: 0,
        }
    }

    /// What to build for a frame of `frame` pixels with `bonds`: the model unless the mode is
    /// `Volume` (with the wide BVH when the traversal uses it), the volume for the volume
    /// modes (its transfer function scaled by `opacity`, with its light volume for volumetric
    /// shadows unless `shadow_rays`).
    pub fn scene_settings(&self, bonds: BondSettings, frame: (u32, u32)) -> SceneSettings {
        let render = self.render_settings();
        let light_volume = render
            .march
            .shadows
            .filter(|_| !self.shadow_rays)
            .map(|sh| LightVolumeSettings {
                light: sh.light,
                step_voxels: sh.step_voxels,
                stride: LIGHT_VOLUME_STRIDE,
            });
        SceneSettings {
            model: self.mode.has_model().then(|| ModelSettings {
                wide_bvh: render.uses_wide(),
                ..self.model.clone()
            }),
            bonds,
            volume: self.mode.has_volume().then(|| VolumeSettings {
                tf: if self.opacity == 1.0 {
                    self.volume.tf.clone()
                } else {
                    self.volume.tf.clone().scale_opacity(self.opacity)
                },
                light_volume,
                ..self.volume.clone()
            }),
            budget_bytes: self.memory_budget,
            frame: Some(frame),
        }
    }

    /// Refuses combinations that do nothing, with what to use instead (the rules of
    /// [`RenderSettings::validate`] on what the mode draws).
    pub fn validate(&self) -> Result<(), SettingsError> {
        if (self.shadows || self.ao.is_some()) && self.mode == Mode::Path {
            // The path tracer has its own lighting: these would be ignored.
            return Err(SettingsError::NeedsModel);
        }
        if self.volume_shadows && self.volume.source == DensitySource::Particles {
            return Err(SettingsError::VolumeShadowsNeedGrid);
        }
        self.render_settings()
            .validate(self.mode.has_model(), self.mode.has_volume())
    }
}
