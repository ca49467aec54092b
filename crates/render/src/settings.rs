//! Everything that chooses how a frame is shaded: [`RenderSettings`], its modality and its
//! validation (the rules that used to live in the CLI, plus cost caps).

use volume::{Light, Lighting, MarchOptions};

/// Ambient term of the headlight shading of the `bs` / `vol+bs` modes (paper §4.5 "b&s"):
/// colour × (ambient + (1 − ambient)·|n·v|).
pub const HEADLIGHT_AMBIENT: f32 = 0.15;
/// Ambient term of [`Modality::Direct`]: colour × (ambient + intensity·max(0, n·l)·V).
pub const DIRECT_AMBIENT: f32 = 0.2;
/// Background of the volume modes and of path tracing unless one is given (RGB 0-255): near
/// black, so that the volume's colours and the path tracer's environment stay readable.
pub const DARK_BACKGROUND: [u8; 3] = [12, 12, 20];
/// Background of the ball-and-stick modes unless one is given (RGB 0-255).
pub const WHITE_BACKGROUND: [u8; 3] = [255, 255, 255];
/// Cap on samples per pixel: 65,536 samples of a 1024² frame are ~7·10¹⁰ camera paths
/// (hours); accumulate in several calls ([`crate::accumulate`]) to go further.
pub const MAX_SPP: u32 = 65_536;
/// Cap on AO rays per hit: 4,096 rays per pixel are ~4·10⁹ rays for a 1024² frame.
pub const MAX_AO_SAMPLES: u32 = 4_096;
/// Cap on path length: a path that still carries energy after 64 hits is lost in noise.
pub const MAX_DEPTH: u32 = 64;

/// BRDF of the path tracer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Material {
    /// Lambertian, albedo = atom colour.
    Diffuse,
    /// Conductor: mirror reflection blurred by `roughness`, Schlick Fresnel with F0 = atom
    /// colour.
    Metal,
}

/// What the shader computes per pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Modality {
    /// The paper's plain modes, chosen by what is given: ball-and-stick with headlight diffuse
    /// shading ("b&s"), the volume alone ("volume") or the volume in front of the balls and
    /// sticks ("vol+b&s"). Packed RGBA8 per pixel, one sample.
    Headlight,
    /// Diffuse shading from the directional light: colour × (ambient + intensity·max(0, n·l)·V),
    /// V = 1, or the shadow-ray visibility when `shadows`.
    Direct {
        /// Cast a shadow ray per hit.
        shadows: bool,
    },
    /// Ambient occlusion: colour × fraction of `samples` cosine-distributed rays that travel
    /// `distance` Å without hitting geometry.
    Ao {
        /// Rays per hit (1 ..= [`MAX_AO_SAMPLES`]).
        samples: u32,
        /// Occlusion distance, Å.
        distance: f32,
    },
    /// Path tracing, progressive: every sample is one path of at most `max_depth` hits;
    /// environment = background colour, plus next-event estimation of the directional light
    /// on diffuse surfaces.
    Path {
        /// BRDF.
        material: Material,
        /// Maximum hits per path (1 ..= [`MAX_DEPTH`]); a path still bouncing then
        /// contributes nothing more.
        max_depth: u32,
        /// Metal only: radius of the random offset added to the mirror direction (0 = mirror).
        roughness: f32,
    },
}

/// How secondary rays (shadow, AO, path bounces) traverse the BVH.
///
/// Measured on ns90k, 1024², 2 threads, AVX2 (AMD EPYC, 2026-11-27), s per frame (path: per
/// sample, metal, 6 hits), packet / single / wide:
///
/// | ray kind | far | close |
/// |---|---|---|
/// | shadow | 0.245 / 0.337 / 0.367 | 0.176 / 0.527 / 0.390 |
/// | AO, 4 samples | 0.609 / 1.076 / 0.960 | 0.489 / 1.866 / 1.496 |
/// | path bounces | 3.73 / 2.99 / 2.04 | 8.40 / 7.11 / 5.25 |
///
/// Shadow rays (all towards one light) and short AO rays from neighbouring pixels stay
/// coherent, so packets win; bounced path rays do not, so the wide BVH wins (1.6-1.8×; on
/// SSE4.1 1.3×, 3.39 vs 2.63 s; the scalar backend tests 8 boxes one at a time, 3.10 vs
/// 3.33 s). Defaults: [`RenderSettings::secondary`] `Packet`, [`RenderSettings::bounces`]
/// `Wide`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum SecondaryTraversal {
    /// The rays of a pixel block as one packet over the binary BVH (any-hit early exit for
    /// shadow and AO rays).
    #[default]
    Packet,
    /// Each lane alone through the binary BVH on the scalar backend.
    Single,
    /// Each lane alone through the 8-wide BVH (`Model::wide`), eight child boxes per SIMD op.
    Wide,
}

impl From<SecondaryTraversal> for bvh::Traversal {
    fn from(t: SecondaryTraversal) -> bvh::Traversal {
        match t {
            SecondaryTraversal::Packet => bvh::Traversal::Packet,
            SecondaryTraversal::Single => bvh::Traversal::Single,
            SecondaryTraversal::Wide => bvh::Traversal::Wide,
        }
    }
}

/// Every option of a frame (one typed struct for all modalities; check it with
/// [`RenderSettings::validate`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// What to compute.
    pub modality: Modality,
    /// Options of the volume pass. The caller builds its `VolumeScene` with these; they are
    /// here so that [`RenderSettings::validate`] can check them against the modality.
    pub march: MarchOptions,
    /// The light of `Direct` shading and of the path tracer's next-event estimation
    /// (directional, or a point without distance fall-off).
    pub light: Light,
    /// Light intensity (Direct: factor of `max(0, n·l)`; Path: irradiance / π).
    pub light_intensity: f32,
    /// Ambient term of the shading: [`HEADLIGHT_AMBIENT`] for `Headlight`, [`DIRECT_AMBIENT`]
    /// for `Direct` (the constructors set the right one).
    pub ambient: f32,
    /// Background colour, RGB 0-255 (Path: environment radiance `(c/255)²`).
    pub background: [u8; 3],
    /// Path tracing: radiance multiplier before clamp and gamma 2.
    pub exposure: f32,
    /// Seed of the random numbers (AO, path tracing).
    pub seed: u32,
    /// Samples per pixel of a whole-frame path-traced render (1 ..= [`MAX_SPP`]). The other
    /// modalities trace the pixel centre once.
    pub spp: u32,
    /// Shadow rays (Direct shadows, Path next-event estimation) are attenuated by the volume
    /// when one is given (paper §4.5 soft shadows).
    pub volume_shadows: bool,
    /// Step of shadow rays through the volume, voxels (coarser than the primary 0.5).
    pub shadow_step_voxels: f32,
    /// Traversal of shadow and AO rays (and the path tracer's light samples).
    pub secondary: SecondaryTraversal,
    /// Traversal of the path tracer's bounced rays (primary rays always go in packets).
    pub bounces: SecondaryTraversal,
    /// Headlight: SIMD registers per primary ray packet (1, 2 or 4; 0 = the measured default
    /// per ISA).
    pub packet_registers: usize,
}

impl Default for RenderSettings {
    /// The headlight modes with a white background.
    fn default() -> Self {
        RenderSettings {
            modality: Modality::Headlight,
            march: MarchOptions::default(),
            light: Light::Directional([1.0, 2.0, 1.5]),
            light_intensity: 0.85,
            ambient: HEADLIGHT_AMBIENT,
            background: [255, 255, 255],
            exposure: 1.0,
            seed: 1,
            spp: 1,
            volume_shadows: true,
            shadow_step_voxels: 2.0,
            secondary: SecondaryTraversal::Packet,
            bounces: SecondaryTraversal::Wide,
            packet_registers: 0,
        }
    }
}

/// A refused [`RenderSettings`] (messages name the CLI flags).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SettingsError {
    /// The modality shades ball-and-stick hits but there is no model.
    #[error(
        "--shadows and --ao shade ball-and-stick hits: use them with --mode bs or vol+bs \
         (--mode path has its own lighting; for volumetric shadows use --mode volume \
         --volume-shadows)"
    )]
    NeedsModel,
    /// Nothing to draw.
    #[error("nothing to render: give a model, a volume or both")]
    Empty,
    /// Volume lighting without a volume.
    #[error("--lit lights the volume: use it with --mode volume or --mode vol+bs")]
    LitWithoutVolume,
    /// A value out of its range.
    #[error("{0}")]
    Range(&'static str),
    /// A value above its cost cap.
    #[error("{what} = {value} is above the cap {cap} ({cost}); {way_out}")]
    TooExpensive {
        /// The flag.
        what: &'static str,
        /// Its value.
        value: u32,
        /// The cap.
        cap: u32,
        /// What it would cost.
        cost: &'static str,
        /// What to do instead.
        way_out: &'static str,
    },
    /// Volume shadows on vol+b&s without shadow rays.
    #[error(
        "--mode vol+bs --volume-shadows needs --shadows (the balls and sticks are then \
         shadowed by the geometry and the volume, and the volume by itself)"
    )]
    VolumeShadowsNeedShadows,
    /// Volume shadows without a volume.
    #[error(
        "--volume-shadows: the volume casts the shadows, so use it with --mode volume \
         or --mode vol+bs --shadows"
    )]
    VolumeShadowsWithoutVolume,
    /// Volume shadows through a grid-free volume.
    #[error(
        "--volume-shadows marches the density grid towards the light: use --volume grid \
         (the default) or drop --volume-shadows with --volume particles"
    )]
    VolumeShadowsNeedGrid,
}

impl RenderSettings {
    /// The headlight modes (b&s, volume, vol+b&s) with `background`.
    pub fn headlight(background: [u8; 3]) -> RenderSettings {
        RenderSettings {
            background,
            ..RenderSettings::default()
        }
    }

    /// A ray-traced modality with its defaults (ambient [`DIRECT_AMBIENT`], volume shadows
    /// on when a volume is given).
    pub fn traced(modality: Modality, background: [u8; 3]) -> RenderSettings {
        RenderSettings {
            modality,
            ambient: DIRECT_AMBIENT,
            background,
            ..RenderSettings::default()
        }
    }

    /// Whether the modality produces linear radiance (tone mapped by exposure and gamma 2).
    pub fn is_linear(&self) -> bool {
        matches!(self.modality, Modality::Path { .. })
    }

    /// What the settings shade, for reports: `" lit"`, `" ao 4x4Å"`, `" shadows"`,
    /// `" metal"`, `" volume-shadowed"`… (empty for the plain headlight modes).
    pub fn describe(&self) -> String {
        let mut s = match self.modality {
            Modality::Headlight => String::new(),
            Modality::Direct { .. } if self.volume_shadows && self.march.shadows.is_some() => {
                " shadows (volume-attenuated)".into()
            }
            Modality::Direct { .. } => " shadows".into(),
            Modality::Ao { samples, distance } => format!(" ao {samples}x{distance}Å"),
            Modality::Path { material, .. } => format!(" {material:?}").to_lowercase(),
        };
        if self.march.lighting != Lighting::Unlit {
            s.push_str(" lit");
        }
        if self.modality == Modality::Headlight && self.march.shadows.is_some() {
            s.push_str(" volume-shadowed");
        }
        s
    }

    /// Whether these settings use the wide BVH (so it is built before the tiles start).
    pub fn uses_wide(&self) -> bool {
        let wide = SecondaryTraversal::Wide;
        match self.modality {
            Modality::Headlight => false,
            Modality::Direct { shadows } => shadows && self.secondary == wide,
            Modality::Ao { .. } => self.secondary == wide,
            Modality::Path { .. } => self.bounces == wide || self.secondary == wide,
        }
    }

    /// Background as packed RGBA8 (alpha 255).
    pub fn background_packed(&self) -> u32 {
        let [r, g, b] = self.background;
        scene::rgba(r, g, b, 255)
    }

    /// Background as display RGB in [0, 1].
    pub fn background_unit(&self) -> [f32; 3] {
        let [r, g, b] = self.background;
        [r as f32 / 255.0, g as f32 / 255.0, b as f32 / 255.0]
    }

    /// Samples per pixel a whole frame takes: `spp` for path tracing, else 1.
    pub fn frame_samples(&self) -> u32 {
        if self.is_linear() {
            self.spp
        } else {
            1
        }
    }

    /// Checks the settings against what will be drawn (`has_model`: a ball-and-stick model;
    /// `has_volume`: a volume scene built with `self.march`).
    pub fn validate(&self, has_model: bool, has_volume: bool) -> Result<(), SettingsError> {
        use SettingsError::*;
        if !has_model && !has_volume {
            return Err(Empty);
        }
        if self.march.lighting != Lighting::Unlit && !has_volume {
            return Err(LitWithoutVolume);
        }
        match self.modality {
            Modality::Headlight => {}
            Modality::Direct { .. } if !has_model => return Err(NeedsModel),
            Modality::Direct { .. } => {}
            Modality::Ao { samples, distance } => {
                if !has_model {
                    return Err(NeedsModel);
                }
                if samples == 0 {
                    return Err(Range("--ao N needs at least one sample"));
                }
                if samples > MAX_AO_SAMPLES {
                    return Err(TooExpensive {
                        what: "--ao",
                        value: samples,
                        cap: MAX_AO_SAMPLES,
                        cost: "4,096 rays per pixel are 4·10⁹ rays per megapixel",
                        way_out: "AO converges with far fewer rays; try 16-64",
                    });
                }
                if !(distance > 0.0 && distance.is_finite()) {
                    return Err(Range("--ao-distance must be a positive number of Å"));
                }
            }
            Modality::Path {
                max_depth,
                roughness,
                ..
            } => {
                if !has_model {
                    return Err(Range(
                        "--mode path traces ball-and-stick geometry: give a model",
                    ));
                }
                if max_depth == 0 {
                    return Err(Range("--max-depth must be at least 1"));
                }
                if max_depth > MAX_DEPTH {
                    return Err(TooExpensive {
                        what: "--max-depth",
                        value: max_depth,
                        cap: MAX_DEPTH,
                        cost: "every hit adds a traversal and paths this long add only noise",
                        way_out: "use --max-depth 6-16",
                    });
                }
                if !(roughness >= 0.0 && roughness.is_finite()) {
                    return Err(Range("--roughness must be a non-negative number"));
                }
            }
        }
        if !(self.shadow_step_voxels > 0.0 && self.shadow_step_voxels.is_finite()) {
            return Err(Range("--shadow-step must be a positive number of voxels"));
        }
        if self.spp == 0 {
            return Err(Range("--spp must be at least 1"));
        }
        if self.spp > MAX_SPP {
            return Err(TooExpensive {
                what: "--spp",
                value: self.spp,
                cap: MAX_SPP,
                cost: "65,536 paths per pixel take hours per megapixel",
                way_out: "accumulate progressively in several calls instead",
            });
        }
        if !(self.exposure > 0.0 && self.exposure.is_finite()) {
            return Err(Range("--exposure must be a positive number"));
        }
        if self.march.shadows.is_some() {
            let shadow_rays = matches!(self.modality, Modality::Direct { shadows: true });
            match (has_model, has_volume) {
                (false, true) => {}
                (true, true) if shadow_rays => {}
                (true, true) => return Err(VolumeShadowsNeedShadows),
                _ => return Err(VolumeShadowsWithoutVolume),
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use volume::VolumeShadows;

    #[test]
    fn validate_refuses_what_the_cli_refused() {
        let ok = RenderSettings::default();
        assert_eq!(ok.validate(true, false), Ok(()));
        assert_eq!(ok.validate(false, false), Err(SettingsError::Empty));
        let lit = RenderSettings {
            march: MarchOptions {
                lighting: Lighting::Headlight,
                ..MarchOptions::default()
            },
            ..ok
        };
        assert_eq!(
            lit.validate(true, false),
            Err(SettingsError::LitWithoutVolume)
        );
        assert_eq!(lit.validate(true, true), Ok(()));
        let ao =
            |samples, distance| RenderSettings::traced(Modality::Ao { samples, distance }, [0; 3]);
        assert_eq!(
            ao(4, 1.0).validate(false, true),
            Err(SettingsError::NeedsModel)
        );
        assert!(ao(0, 1.0).validate(true, false).is_err());
        assert!(ao(4, -1.0).validate(true, false).is_err());
        assert!(ao(4, f32::NAN).validate(true, false).is_err());
        assert!(matches!(
            ao(MAX_AO_SAMPLES + 1, 1.0).validate(true, false),
            Err(SettingsError::TooExpensive { .. })
        ));
        assert_eq!(ao(MAX_AO_SAMPLES, 1.0).validate(true, false), Ok(()));
        let path = |max_depth, roughness, spp| RenderSettings {
            spp,
            ..RenderSettings::traced(
                Modality::Path {
                    material: Material::Metal,
                    max_depth,
                    roughness,
                },
                [0; 3],
            )
        };
        assert_eq!(path(6, 0.1, 16).validate(true, false), Ok(()));
        assert!(path(0, 0.1, 16).validate(true, false).is_err());
        assert!(path(MAX_DEPTH + 1, 0.1, 16).validate(true, false).is_err());
        assert!(path(6, -0.1, 16).validate(true, false).is_err());
        assert!(path(6, 0.1, 0).validate(true, false).is_err());
        assert!(path(6, 0.1, MAX_SPP + 1).validate(true, false).is_err());
        let vs = |modality| RenderSettings {
            march: MarchOptions {
                shadows: Some(VolumeShadows {
                    light: Light::Directional([0.0, 1.0, 0.0]),
                    step_voxels: 2.0,
                }),
                ..MarchOptions::default()
            },
            ..RenderSettings::traced(modality, [0; 3])
        };
        assert_eq!(vs(Modality::Headlight).validate(false, true), Ok(()));
        assert_eq!(
            vs(Modality::Headlight).validate(true, true),
            Err(SettingsError::VolumeShadowsNeedShadows)
        );
        assert_eq!(
            vs(Modality::Direct { shadows: true }).validate(true, true),
            Ok(())
        );
        assert_eq!(
            vs(Modality::Headlight).validate(true, false),
            Err(SettingsError::VolumeShadowsWithoutVolume)
        );
        let bad = RenderSettings {
            exposure: 0.0,
            ..ok
        };
        assert!(bad.validate(true, false).is_err());
        let bad = RenderSettings {
            shadow_step_voxels: f32::INFINITY,
            ..ok
        };
        assert!(bad.validate(true, false).is_err());
    }
}
