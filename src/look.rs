//! The flags of what a frame shows and how it is lit — size, mode, camera, style, volume,
//! lighting, path tracing, performance — shared by `render` and `view`, and their mapping onto
//! the typed [`render::Look`] (whose methods give the scene and render settings).

use anyhow::{bail, Context, Result};
use clap::Args;
use render::{Camera, Look, Material, Mode, SecondaryTraversal};
use scene::{CameraChoice, Orbit, ViewPreset};
use volume::{Light, TransferFunction};

use scene::text::{non_negative, parse_dir, parse_point, parse_rgb, parse_size, positive};

use crate::pipeline::{GeometryArgs, VolumeArgs};

/// What a frame shows and how (the flags `render` and `view` share).
#[derive(Args, Debug, Clone)]
pub struct LookArgs {
    /// Image size, WIDTHxHEIGHT pixels.
    #[arg(help_heading = "Output", long, default_value = "1024x1024", value_parser = parse_size)]
    pub size: (u32, u32),
    /// What to draw.
    #[arg(help_heading = "Output", long, value_enum, default_value_t = Mode::Bs)]
    pub mode: Mode,
    /// Camera preset (ignored when --camera is given).
    #[arg(help_heading = "Camera", long, value_enum, default_value_t = ViewPreset::Far)]
    pub view: ViewPreset,
    /// Orbit `AZ,EL` (degrees): the eye turned about +y by AZ and raised by EL around the
    /// centre, instead of the preset's direction.
    #[arg(help_heading = "Camera", long, allow_hyphen_values = true)]
    pub orbit: Option<Orbit>,
    /// Zoom factor of the preset's distance (2 = half as far).
    #[arg(help_heading = "Camera", long, default_value_t = 1.0, value_parser = positive)]
    pub zoom: f32,
    /// Explicit camera: `eye=x,y,z:at=x,y,z[:up=x,y,z][:fov=deg][:ortho=height_Å]`.
    #[arg(help_heading = "Camera", long)]
    pub camera: Option<String>,
    /// Vertical field of view of the presets (degrees).
    #[arg(help_heading = "Camera", long, default_value_t = 45.0)]
    pub fov: f32,
    /// Background colour `r,g,b` (0-255; default white for bs, near-black for volume modes).
    #[arg(help_heading = "Output", long, value_parser = parse_rgb)]
    pub background: Option<[u8; 3]>,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    #[command(flatten)]
    pub volume: VolumeArgs,
    /// Transfer function: a preset (coolwarm, viridis, grayscale) or a file of control
    /// points `value r g b a` (value from 0 to 1 over the density range).
    #[arg(help_heading = "Volume", long, default_value = "coolwarm")]
    pub tf: String,
    /// Volume: multiply every opacity of the transfer function by this factor (clamped to 1).
    #[arg(help_heading = "Volume", long, default_value_t = 1.0, value_parser = positive)]
    pub opacity: f32,
    /// Volume: gradient lighting by central differences (headlight, or from --light-dir /
    /// --light-pos when given or when --volume-shadows is on).
    #[arg(help_heading = "Volume", long)]
    pub lit: bool,
    /// Ball-and-stick (bs, vol+bs): diffuse light from --light-dir or --light-pos with hard
    /// shadows.
    #[arg(help_heading = "Lighting", long, conflicts_with = "ao")]
    pub shadows: bool,
    /// Ball-and-stick (bs, vol+bs): ambient occlusion with N cosine-distributed rays per hit.
    #[arg(help_heading = "Lighting", long, value_name = "N")]
    pub ao: Option<u32>,
    /// Ambient occlusion distance (Å).
    #[arg(help_heading = "Lighting", long, default_value_t = 4.0, value_parser = positive)]
    pub ao_distance: f32,
    /// Direction towards a directional light, world space `x,y,z` (default 1,2,1.5).
    #[arg(help_heading = "Lighting", long, value_parser = parse_dir, conflicts_with = "light_pos", allow_hyphen_values = true)]
    pub light_dir: Option<[f32; 3]>,
    /// Position of a point light instead, world space `x,y,z` in Å (no distance fall-off).
    #[arg(help_heading = "Lighting", long, value_parser = parse_point, allow_hyphen_values = true)]
    pub light_pos: Option<[f32; 3]>,
    /// Light intensity (shadows: factor of max(0, n·l); path: irradiance / π).
    #[arg(help_heading = "Lighting", long, default_value_t = 0.85)]
    pub light_intensity: f32,
    /// Ambient term of --shadows shading.
    #[arg(help_heading = "Lighting", long, default_value_t = 0.2)]
    pub ambient: f32,
    /// The volume casts shadows (paper §4.5, Figure 4): with --mode volume every visible
    /// sample is shadowed by the density towards the light; with --mode vol+bs --shadows also
    /// the balls and sticks (soft shadows).
    #[arg(help_heading = "Volume", long)]
    pub volume_shadows: bool,
    /// Step of shadow rays through the volume (voxels).
    #[arg(help_heading = "Volume", long, default_value_t = 2.0)]
    pub shadow_step: f32,
    /// Volumetric shadows: march a shadow ray from every shaded volume sample instead of
    /// looking up the light volume precomputed every 2 voxels (slower; the reference).
    #[arg(help_heading = "Volume", long)]
    pub shadow_rays: bool,
    /// Path tracing: BRDF of the atoms.
    #[arg(help_heading = "Path tracing", long, value_enum, default_value_t = Material::Metal)]
    pub material: Material,
    /// Path tracing: samples per pixel.
    #[arg(help_heading = "Path tracing", long, default_value_t = 16)]
    pub spp: u32,
    /// Path tracing: maximum hits per path.
    #[arg(help_heading = "Path tracing", long, default_value_t = 6, value_parser = clap::value_parser!(u32).range(1..))]
    pub max_depth: u32,
    /// Path tracing, metal: roughness (0 = mirror).
    #[arg(help_heading = "Path tracing", long, default_value_t = 0.15, value_parser = non_negative)]
    pub roughness: f32,
    /// Path tracing: exposure (radiance multiplier before clamp and gamma 2).
    #[arg(help_heading = "Path tracing", long, default_value_t = 1.0)]
    pub exposure: f32,
    /// Seed of the random numbers of AO and path tracing (`--seed` seeds scene generators).
    #[arg(help_heading = "Path tracing", long, default_value_t = 1)]
    pub sample_seed: u32,
    /// Traversal of shadow and AO rays (and the path tracer's light samples): packets with
    /// any-hit exit, single rays, or single rays over the 8-wide BVH.
    #[arg(help_heading = "Performance", long, value_enum, default_value_t = SecondaryTraversal::Packet)]
    pub secondary: SecondaryTraversal,
    /// Traversal of the path tracer's bounced rays (camera rays always go in packets).
    #[arg(help_heading = "Path tracing", long, value_enum, default_value_t = SecondaryTraversal::Wide)]
    pub bounce_traversal: SecondaryTraversal,
    /// Volume: march every cell (no macrocell skipping), for comparison.
    #[arg(help_heading = "Volume", long)]
    pub no_macrocells: bool,
    /// Volume: post-classification instead of pre-integration, for comparison.
    #[arg(help_heading = "Volume", long)]
    pub no_preintegration: bool,
    /// Memory the scene build may use, MB (10⁶ bytes): its estimated peak (what `bnsview info`
    /// prints) is checked against this before anything large is allocated. Default: 75 % of
    /// the memory available (`MemAvailable`) when the build starts.
    #[arg(help_heading = "Performance", long, value_name = "MB", value_parser = clap::value_parser!(u64).range(1..))]
    pub memory_budget: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(help_heading = "Performance", long)]
    pub threads: Option<usize>,
    /// Print timings of every stage and the ISA to stderr.
    #[arg(help_heading = "Output", short, long)]
    pub verbose: bool,
}

impl LookArgs {
    /// Sets the size of rayon's global pool from `--threads` (refused beyond 16 per core),
    /// else to `default` when given (an MPI rank's share of the cores).
    pub fn init_threads(&self, default: Option<usize>) -> Result<()> {
        if let Some(n) = self.threads.or(default) {
            // More threads than this per core only add overhead (and a stack each).
            let cap = 16 * std::thread::available_parallelism().map_or(1, |c| c.get());
            if n == 0 || n > cap {
                bail!("--threads {n}: use 1 to {cap} (16 per core on this machine)");
            }
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build_global()
                .context("--threads")?;
        }
        Ok(())
    }

    /// The typed look of the flags; `pbc` (an input flag) draws bonds across the cell as
    /// half-sticks. Parses `--tf` whatever the mode, so the viewer can switch to a volume
    /// mode.
    pub fn look(&self, pbc: bool) -> Result<Look> {
        let tf = TransferFunction::from_spec(&self.tf)?;
        let light = match (self.light_pos, self.light_dir) {
            (Some(p), _) => Some(Light::Point(p)),
            (None, d) => d.map(Light::Directional),
        };
        Ok(Look {
            mode: self.mode,
            model: scene::ModelSettings {
                periodic_bonds: pbc,
                ..self.geometry.settings()?
            },
            volume: scene::VolumeSettings {
                tf,
                ..self.volume.settings()?
            },
            opacity: self.opacity,
            background: self.background,
            lit: self.lit,
            shadows: self.shadows,
            ao: self.ao,
            ao_distance: self.ao_distance,
            light,
            light_intensity: self.light_intensity,
            ambient: self.ambient,
            volume_shadows: self.volume_shadows,
            shadow_step: self.shadow_step,
            shadow_rays: self.shadow_rays,
            material: self.material,
            spp: self.spp,
            max_depth: self.max_depth,
            roughness: self.roughness,
            exposure: self.exposure,
            sample_seed: self.sample_seed,
            secondary: self.secondary,
            bounces: self.bounce_traversal,
            macrocells: !self.no_macrocells,
            preintegrated: !self.no_preintegration,
            memory_budget: self.memory_budget.map(|mb| mb.saturating_mul(1_000_000)),
        })
    }

    /// The camera the flags ask for: `--camera`, else the view fitted to the first frame
    /// (`fit_all`: to every frame rendered).
    pub fn camera_choice(&self, fit_all: bool) -> Result<CameraChoice> {
        if let Some(spec) = &self.camera {
            return Ok(CameraChoice::Fixed(spec.parse::<Camera>()?));
        }
        let ((view, orbit), fov_deg) = (self.view_and_orbit(), self.fov);
        Ok(match fit_all {
            false => CameraChoice::Fit {
                view,
                orbit,
                fov_deg,
            },
            true => CameraChoice::FitAll {
                view,
                orbit,
                fov_deg,
            },
        })
    }

    /// The preset's distance and the orbit of `--view`, `--orbit` and `--zoom`.
    pub fn view_and_orbit(&self) -> (scene::View, Orbit) {
        let (view, mut orbit) = self.view.view_and_orbit();
        if let Some(o) = self.orbit {
            (orbit.azimuth_deg, orbit.elevation_deg) = (o.azimuth_deg, o.elevation_deg);
        }
        orbit.zoom = self.zoom;
        (view, orbit)
    }
}
