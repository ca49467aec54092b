//! `bnsview render`: a molecule file or a built-in scene to a PNG.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use render::{
    accumulate, render_frame, Accum, Camera, FrameInputs, Framebuffer, Material, Modality,
    RenderSettings, SecondaryTraversal, TraceOptions, View,
};
use scene::{LightVolumeSettings, Orbit, Scene, SceneSettings, LIGHT_VOLUME_STRIDE};
use spmd::Isa;
use volume::{
    Light, LightVolume, Lighting, MarchOptions, Preset, TransferFunction, VolumeScene,
    VolumeShadows,
};

use crate::input::InputArgs;
use crate::pipeline::{GeometryArgs, VolumeArgs};

/// What a frame shows (the rows of the paper's Table 3).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Ball-and-stick, headlight diffuse shading.
    Bs,
    /// Direct volume rendering of the RBF density alone.
    Volume,
    /// Ball-and-stick, then the volume in front of it.
    #[value(name = "vol+bs")]
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
}

/// BRDF of the path tracer (`--material`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialArg {
    /// Conductor with Schlick Fresnel (F0 = atom colour), blurred by --roughness.
    Metal,
    /// Lambertian.
    Diffuse,
}

/// Traversal of secondary rays (`--secondary`, `--bounce-traversal`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SecondaryArg {
    /// A pixel block's secondary rays as one packet over the binary BVH.
    Packet,
    /// One ray at a time through the binary BVH (scalar traversal).
    Single,
    /// One ray at a time through the 8-wide BVH (eight child boxes per SIMD op).
    Wide,
}

impl From<SecondaryArg> for SecondaryTraversal {
    fn from(a: SecondaryArg) -> Self {
        match a {
            SecondaryArg::Packet => SecondaryTraversal::Packet,
            SecondaryArg::Single => SecondaryTraversal::Single,
            SecondaryArg::Wide => SecondaryTraversal::Wide,
        }
    }
}

fn parse_dir(s: &str) -> Result<[f32; 3], String> {
    let v: Vec<Option<f32>> = s.split(',').map(|c| c.trim().parse().ok()).collect();
    match v.as_slice() {
        [Some(x), Some(y), Some(z)]
            if [x, y, z].iter().all(|a| a.is_finite()) && (x * x + y * y + z * z) > 0.0 =>
        {
            Ok([*x, *y, *z])
        }
        _ => Err(format!("{s:?}: expected a non-zero direction x,y,z")),
    }
}

/// Parses a point `x,y,z` (Å).
fn parse_point(s: &str) -> Result<[f32; 3], String> {
    let v: Vec<Option<f32>> = s.split(',').map(|c| c.trim().parse().ok()).collect();
    match v.as_slice() {
        [Some(x), Some(y), Some(z)] if [x, y, z].iter().all(|a| a.is_finite()) => Ok([*x, *y, *z]),
        _ => Err(format!(
            "{s:?}: expected a point x,y,z in Å (three finite numbers)"
        )),
    }
}

/// Which of the paper's views (Table 3).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewArg {
    /// The whole molecule fits in the frame.
    Far,
    /// A quarter of the far distance from the centre, the frame filled.
    Close,
}

/// Arguments of `bnsview render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Output PNG (default: <scene or file stem>.png).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Overwrite the output if it exists.
    #[arg(short, long)]
    pub force: bool,
    /// Image size, WIDTHxHEIGHT pixels.
    #[arg(long, default_value = "1024x1024", value_parser = parse_size)]
    pub size: (u32, u32),
    /// What to draw.
    #[arg(long, value_enum, default_value_t = Mode::Bs)]
    pub mode: Mode,
    /// Camera preset (ignored when --camera is given).
    #[arg(long, value_enum, default_value_t = ViewArg::Far)]
    pub view: ViewArg,
    /// Explicit camera: `eye=x,y,z:at=x,y,z[:up=x,y,z][:fov=deg][:ortho=height_Å]`.
    #[arg(long)]
    pub camera: Option<String>,
    /// Vertical field of view of the presets (degrees).
    #[arg(long, default_value_t = 45.0)]
    pub fov: f32,
    /// Background colour `r,g,b` (0-255; default white for bs, near-black for volume modes).
    #[arg(long, value_parser = parse_rgb)]
    pub background: Option<[u8; 3]>,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    #[command(flatten)]
    pub volume: VolumeArgs,
    /// Transfer function: a preset (coolwarm, viridis, grayscale) or a file of control
    /// points `value r g b a` (value in [0,1] of the density range).
    #[arg(long, default_value = "coolwarm")]
    pub tf: String,
    /// Volume: gradient lighting by central differences (headlight, or from --light-dir /
    /// --light-pos when given or when --volume-shadows is on).
    #[arg(long)]
    pub lit: bool,
    /// Ball-and-stick (bs, vol+bs): diffuse light from --light-dir or --light-pos with hard
    /// shadows.
    #[arg(long)]
    pub shadows: bool,
    /// Ball-and-stick (bs, vol+bs): ambient occlusion with N cosine-distributed rays per hit.
    #[arg(long, value_name = "N")]
    pub ao: Option<u32>,
    /// Ambient occlusion distance (Å).
    #[arg(long, default_value_t = 4.0)]
    pub ao_distance: f32,
    /// Direction towards a directional light, world space `x,y,z` (default 1,2,1.5).
    #[arg(long, value_parser = parse_dir, conflicts_with = "light_pos", allow_hyphen_values = true)]
    pub light_dir: Option<[f32; 3]>,
    /// Position of a point light instead, world space `x,y,z` in Å (no distance fall-off).
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    pub light_pos: Option<[f32; 3]>,
    /// Light intensity (shadows: factor of max(0, n·l); path: irradiance / π).
    #[arg(long, default_value_t = 0.85)]
    pub light_intensity: f32,
    /// Ambient term of --shadows shading.
    #[arg(long, default_value_t = 0.2)]
    pub ambient: f32,
    /// The volume casts shadows (paper §4.5, Figure 4): with --mode volume every visible
    /// sample is shadowed by the density towards the light; with --mode vol+bs --shadows also
    /// the balls and sticks (soft shadows).
    #[arg(long)]
    pub volume_shadows: bool,
    /// Step of shadow rays through the volume (voxels).
    #[arg(long, default_value_t = 2.0)]
    pub shadow_step: f32,
    /// Volumetric shadows: march a shadow ray from every shaded volume sample instead of
    /// looking up the light volume precomputed every 2 voxels (slower; the reference).
    #[arg(long)]
    pub shadow_rays: bool,
    /// Path tracing: BRDF of the atoms.
    #[arg(long, value_enum, default_value_t = MaterialArg::Metal)]
    pub material: MaterialArg,
    /// Path tracing: samples per pixel.
    #[arg(long, default_value_t = 16)]
    pub spp: u32,
    /// Path tracing: maximum hits per path.
    #[arg(long, default_value_t = 6)]
    pub max_depth: u32,
    /// Path tracing, metal: roughness (0 = mirror).
    #[arg(long, default_value_t = 0.15)]
    pub roughness: f32,
    /// Path tracing: exposure (radiance multiplier before clamp and gamma 2).
    #[arg(long, default_value_t = 1.0)]
    pub exposure: f32,
    /// Seed of the random numbers of AO and path tracing (`--seed` seeds scene generators).
    #[arg(long, default_value_t = 1)]
    pub sample_seed: u32,
    /// Traversal of shadow and AO rays (and the path tracer's light samples): packets with
    /// any-hit exit, single rays, or single rays over the 8-wide BVH.
    #[arg(long, value_enum, default_value_t = SecondaryArg::Packet)]
    pub secondary: SecondaryArg,
    /// Traversal of the path tracer's bounced rays (camera rays always go in packets).
    #[arg(long, value_enum, default_value_t = SecondaryArg::Wide)]
    pub bounce_traversal: SecondaryArg,
    /// Volume: march every cell (no macrocell skipping), for comparison.
    #[arg(long)]
    pub no_macrocells: bool,
    /// Volume: post-classification instead of pre-integration, for comparison.
    #[arg(long)]
    pub no_preintegration: bool,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Print timings of every stage and the ISA to stderr.
    #[arg(short, long)]
    pub verbose: bool,
}

/// Parses `WIDTHxHEIGHT`.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{s:?}: expected WIDTHxHEIGHT, e.g. 1024x1024"))?;
    let p = |v: &str| v.trim().parse::<u32>().ok().filter(|&n| n > 0);
    match (p(w), p(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(format!("{s:?}: width and height must be positive integers")),
    }
}

fn parse_rgb(s: &str) -> Result<[u8; 3], String> {
    let v: Vec<Option<u8>> = s.split(',').map(|c| c.trim().parse().ok()).collect();
    match v.as_slice() {
        [Some(r), Some(g), Some(b)] => Ok([*r, *g, *b]),
        _ => Err(format!("{s:?}: expected r,g,b with each 0-255")),
    }
}

fn parse_vec3(key: &str, v: &str) -> Result<[f32; 3]> {
    let c: Vec<f32> = v
        .split(',')
        .map(|x| x.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--camera {key}={v}: expected three numbers x,y,z"))?;
    match c.as_slice() {
        [x, y, z] if c.iter().all(|a| a.is_finite()) => Ok([*x, *y, *z]),
        _ => bail!("--camera {key}={v}: expected three finite numbers x,y,z"),
    }
}

/// Parses `--camera eye=..:at=..[:up=..][:fov=..][:ortho=..]`.
pub fn parse_camera(spec: &str) -> Result<Camera> {
    let (mut eye, mut at, mut up, mut fov, mut ortho) =
        (None, None, [0.0, 1.0, 0.0], 45.0f32, None);
    for part in spec.split(':').filter(|p| !p.trim().is_empty()) {
        let (k, v) = part
            .split_once('=')
            .with_context(|| format!("--camera: {part:?} is not key=value"))?;
        match k.trim() {
            "eye" => eye = Some(parse_vec3(k, v)?),
            "at" => at = Some(parse_vec3(k, v)?),
            "up" => up = parse_vec3(k, v)?,
            "fov" => {
                fov = v
                    .trim()
                    .parse()
                    .ok()
                    .filter(|f: &f32| *f > 0.0 && *f < 180.0)
                    .with_context(|| format!("--camera fov={v}: expected degrees in (0, 180)"))?
            }
            "ortho" => {
                ortho = Some(
                    v.trim()
                        .parse::<f32>()
                        .ok()
                        .filter(|h| *h > 0.0)
                        .with_context(|| {
                            format!("--camera ortho={v}: expected a positive height in Å")
                        })?,
                )
            }
            other => bail!("--camera: unknown key {other:?} (expected eye, at, up, fov, ortho)"),
        }
    }
    let eye = eye.context("--camera needs eye=x,y,z")?;
    let at = at.context("--camera needs at=x,y,z")?;
    if eye == at {
        bail!("--camera: eye and at are the same point");
    }
    Ok(match ortho {
        Some(h) => Camera::orthographic(eye, at, up, h),
        None => Camera::look_at(eye, at, up, fov),
    })
}

/// Loads a transfer function: a preset name or a control-point file.
pub fn load_tf(spec: &str) -> Result<TransferFunction> {
    if let Ok(p) = spec.parse::<Preset>() {
        return Ok(TransferFunction::preset(p));
    }
    let path = std::path::Path::new(spec);
    if path.exists() {
        return TransferFunction::load(path).map_err(Into::into);
    }
    bail!("--tf {spec:?}: neither a preset (coolwarm, viridis, grayscale) nor an existing file")
}

/// Run `bnsview render`.
pub fn run(args: RenderArgs, isa: Isa) -> Result<()> {
    if let Some(n) = args.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n.max(1))
            .build_global()
            .context("--threads")?;
    }
    check_modalities(&args)?;
    let mut input = args.input.clone();
    if input.file.is_none() && input.scene.is_none() {
        input.scene = Some(molecule::scenes::SceneName::Nanobowl);
    }
    let output = args.output.clone().unwrap_or_else(|| {
        let stem = match (&input.file, input.scene) {
            (Some(f), _) => f
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "bnsview".into()),
            (None, Some(sc)) => sc.to_string(),
            _ => "bnsview".into(),
        };
        PathBuf::from(format!("{stem}.png"))
    });
    if output.exists() && !args.force {
        bail!("{} exists; pass --force to overwrite it", output.display());
    }
    if let Some(dir) = output.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            bail!(
                "cannot write {}: directory {} does not exist",
                output.display(),
                dir.display()
            );
        }
    }
    // Check the frame fits before the expensive preprocessing.
    let (w, h) = args.size;
    let probe = Framebuffer::new(w, h, 0).context("allocating the frame")?;
    drop(probe);
    let tf = if matches!(args.mode, Mode::Bs | Mode::Path) {
        None
    } else {
        Some(load_tf(&args.tf)?)
    };

    let l = input.load_frame(false)?;
    let m = &l.molecule;
    if m.is_empty() {
        bail!("{}: no atoms to render", l.source);
    }
    let verbose = |msg: String| {
        if args.verbose {
            eprintln!("{msg}");
        }
    };
    verbose(format!(
        "isa:     {isa} ({} lanes), {} threads",
        isa.lanes(),
        rayon::current_num_threads()
    ));
    verbose(format!(
        "load:    {:.3} s  {} ({} atoms)",
        l.load_s,
        l.source,
        m.len()
    ));
    let settings = scene_settings(&args, &input, tf)?;
    let pb = crate::input::spinner("building the scene");
    let sc = Scene::build_with(isa, m, &settings, &|st| {
        pb.set_message(format!("building the scene: {st:?}"))
    })?;
    pb.finish_and_clear();
    if let Some(model) = &sc.model {
        verbose(format!(
            "bonds:   {:.3} s  {} bonds",
            sc.timings.bonds,
            sc.bonds.len()
        ));
        let st = &model.bvh.stats;
        verbose(format!(
            "bvh:     {:.3} s  {} prims, {} nodes, SAH {:.1}, {:.1} MB ({:.1} B/atom), scene build {:.3} s",
            st.build_time.as_secs_f64(),
            st.prims,
            st.nodes,
            st.sah_cost,
            st.bytes as f64 / 1e6,
            st.bytes_per_atom(),
            sc.timings.model
        ));
    }
    if let Some(d) = &sc.volume {
        verbose(format!(
            "volume:  {:.3} s  {:?} lattice points at {} /Å, {:.1} MB {}",
            sc.timings.volume + sc.timings.macrocells,
            d.volume.grid.dims,
            args.volume.voxels_per_angstrom,
            d.volume.bytes() as f64 / 1e6,
            d.volume.format().name()
        ));
    }
    if let Some(lv) = &sc.light_volume {
        verbose(format!(
            "light:   {:.3} s  light volume {:?} (every {} voxels), {:.1} MB",
            sc.timings.light_volume,
            lv.grid.dims,
            lv.stride,
            lv.bytes() as f64 / 1e6
        ));
    }
    // Fit the camera to the scene's bounding sphere (the atoms' one, padded by the density's
    // support, when there is no geometry).
    let camera = match &args.camera {
        Some(spec) => parse_camera(spec)?,
        None => Camera::fit(
            match args.view {
                ViewArg::Far => View::Far,
                ViewArg::Close => View::Close,
            },
            sc.sphere,
            args.fov,
            w as f32 / h as f32,
            Orbit::default(),
        ),
    };
    let scene = sc.model.as_ref();
    let vscene = sc.volume_scene(march_options(&args));
    let settings = render_settings(&args);
    let inputs = FrameInputs {
        model: scene,
        volume: vscene.as_ref(),
        camera: &camera,
    };
    let t = Instant::now();
    let fb = if settings.modality == Modality::Headlight {
        let mut fb = Framebuffer::new(w, h, settings.background_packed())?;
        let stats = render_frame(&inputs, &settings, &mut fb, isa)?;
        verbose(format!(
            "render:  {:.3} s  {}x{} {}{} ({:.1} Mrays/s, {:.2} fps)",
            t.elapsed().as_secs_f64(),
            w,
            h,
            args.mode.name(),
            volume_suffix(&args),
            stats.mrays_per_s(),
            stats.fps()
        ));
        fb
    } else {
        let path = args.mode == Mode::Path;
        let spp = samples_per_pixel(&args);
        let mut acc = Accum::new(w, h)?;
        let stats = accumulate(&inputs, &settings, &mut acc, spp, isa)?;
        let secs = stats.time.as_secs_f64();
        verbose(format!(
            "render:  {secs:.3} s  {w}x{h} {}{} ({:.2} fps{})",
            args.mode.name(),
            modality_name(&args),
            1.0 / secs.max(1e-12),
            if path {
                format!(", {spp} spp, {:.3} s per spp", secs / spp.max(1) as f64)
            } else {
                String::new()
            }
        ));
        acc.to_framebuffer(path, args.exposure)
    };
    fb.save_png(&output)
        .with_context(|| format!("writing {}", output.display()))?;
    eprintln!(
        "wrote {} ({w}x{h}, {}{}{}, {isa})",
        output.display(),
        args.mode.name(),
        modality_name(&args),
        volume_suffix(&args)
    );
    Ok(())
}

/// " lit", " volume-shadowed" or both: how the volume is shaded, for reports.
fn volume_suffix(args: &RenderArgs) -> String {
    let mut s = String::new();
    if args.lit {
        s.push_str(" lit");
    }
    if args.volume_shadows && args.mode == Mode::Volume {
        s.push_str(" volume-shadowed");
    }
    s
}

/// What `render` builds for the flags: the model unless `--mode volume`, the volume with
/// `tf` (given for the volume modes) and its light volume for volumetric shadows unless
/// `--shadow-rays`, the wide BVH when secondary or bounced rays use it.
fn scene_settings(
    args: &RenderArgs,
    input: &InputArgs,
    tf: Option<TransferFunction>,
) -> Result<SceneSettings> {
    let model = if args.mode == Mode::Volume {
        None
    } else {
        let mut ms = args.geometry.settings()?;
        ms.wide_bvh = modality(args).is_some()
            && (args.secondary == SecondaryArg::Wide
                || (args.mode == Mode::Path && args.bounce_traversal == SecondaryArg::Wide));
        Some(ms)
    };
    let volume = match tf {
        Some(tf) => {
            let shadows = march_options(args).shadows.filter(|_| !args.shadow_rays);
            Some(scene::VolumeSettings {
                tf,
                light_volume: shadows.map(|sh| LightVolumeSettings {
                    light: sh.light,
                    step_voxels: sh.step_voxels,
                    stride: LIGHT_VOLUME_STRIDE,
                }),
                ..args.volume.settings()?
            })
        }
        None => None,
    };
    Ok(SceneSettings {
        model,
        bonds: input.bond_settings()?,
        volume,
        budget_bytes: None,
        frame: Some(args.size),
    })
}

/// The light volume of `vs`'s volumetric shadows (`None` without them), timed.
pub(crate) fn build_light_volume(
    vs: &VolumeScene,
    isa: Isa,
    verbose: &dyn Fn(String),
) -> Option<LightVolume> {
    let sh = vs.opts.shadows?;
    let t = Instant::now();
    let lv = LightVolume::build(isa, vs, sh, LIGHT_VOLUME_STRIDE);
    verbose(format!(
        "light:   {:.3} s  light volume {:?} (every {} voxels), {:.1} MB",
        t.elapsed().as_secs_f64(),
        lv.grid.dims,
        LIGHT_VOLUME_STRIDE,
        lv.bytes() as f64 / 1e6
    ));
    Some(lv)
}

/// The `RenderArgs` of `bnsview render FLAGS` (clap's defaults for every flag not given), so
/// that other commands (`bnsview bench`) render exactly what `render` would.
pub(crate) fn parse_render_flags(flags: &[&str]) -> Result<RenderArgs> {
    use clap::Parser;
    #[derive(Parser)]
    struct Render {
        #[command(flatten)]
        args: RenderArgs,
    }
    let argv = std::iter::once("render").chain(flags.iter().copied());
    Render::try_parse_from(argv)
        .map(|r| r.args)
        .with_context(|| format!("parsing the render flags {}", flags.join(" ")))
}

/// Background colour: `--background`, else white for `bs` and near-black for the others.
fn background(args: &RenderArgs) -> [u8; 3] {
    args.background.unwrap_or(if args.mode == Mode::Bs {
        [255, 255, 255]
    } else {
        [12, 12, 20]
    })
}

/// Samples per pixel of a modality render: `--spp` for path tracing, else 1 (Direct and AO
/// trace the pixel centre, so more samples would only repeat it).
pub(crate) fn samples_per_pixel(args: &RenderArgs) -> u32 {
    if args.mode == Mode::Path {
        args.spp
    } else {
        1
    }
}

/// The light of the flags: `--light-pos`, else `--light-dir`, else the default direction.
pub(crate) fn light(args: &RenderArgs) -> Light {
    match (args.light_pos, args.light_dir) {
        (Some(p), _) => Light::Point(p),
        (None, Some(d)) => Light::Directional(d),
        (None, None) => RenderSettings::default().light,
    }
}

/// The volume marcher's options from the flags: lighting (headlight unless a light is given
/// or shadows need one), volumetric shadows, macrocells and pre-integration.
pub(crate) fn march_options(args: &RenderArgs) -> MarchOptions {
    let explicit = args.light_pos.is_some() || args.light_dir.is_some() || args.volume_shadows;
    let lighting = match (args.lit, explicit, light(args)) {
        (false, _, _) => Lighting::Unlit,
        (true, false, _) => Lighting::Headlight,
        (true, true, Light::Directional(d)) => Lighting::Directional(d),
        (true, true, Light::Point(p)) => Lighting::Point(p),
    };
    MarchOptions {
        macrocells: !args.no_macrocells,
        preintegrated: !args.no_preintegration,
        lighting,
        shadows: args.volume_shadows.then(|| VolumeShadows {
            light: light(args),
            step_voxels: args.shadow_step,
        }),
        ..MarchOptions::default()
    }
}

/// Options of the ray tracing modalities from the flags.
pub(crate) fn trace_options(args: &RenderArgs, modality: Modality) -> TraceOptions {
    let [r, g, b] = background(args);
    TraceOptions {
        modality,
        light: light(args),
        light_intensity: args.light_intensity,
        ambient: args.ambient,
        background: [r as f32 / 255.0, g as f32 / 255.0, b as f32 / 255.0],
        seed: args.sample_seed,
        volume_shadows: args.volume_shadows,
        shadow_step_voxels: args.shadow_step,
        exposure: args.exposure,
        secondary: args.secondary.into(),
        bounces: args.bounce_traversal.into(),
    }
}

/// Every render option of the flags as one [`RenderSettings`] (headlight modes: ambient
/// [`render::HEADLIGHT_AMBIENT`]; `--ambient` is the ambient term of `--shadows`).
pub(crate) fn render_settings(args: &RenderArgs) -> RenderSettings {
    let background = background(args);
    match modality(args) {
        None => RenderSettings {
            march: march_options(args),
            ..RenderSettings::headlight(background)
        },
        Some(modality) => RenderSettings {
            march: march_options(args),
            spp: args.spp,
            background,
            ..trace_options(args, modality).settings(args.spp)
        },
    }
}

/// Rejects combinations of modality flags that do nothing, with what to use instead: the
/// flag conflicts here, every rule on the resulting settings in [`RenderSettings::validate`].
pub(crate) fn check_modalities(args: &RenderArgs) -> Result<()> {
    let m = args.mode;
    if args.lit && matches!(m, Mode::Bs | Mode::Path) {
        bail!("--lit lights the volume: use it with --mode volume or --mode vol+bs");
    }
    if args.shadows && args.ao.is_some() {
        bail!("--shadows and --ao are separate modalities: choose one");
    }
    if (args.shadows || args.ao.is_some()) && matches!(m, Mode::Volume | Mode::Path) {
        bail!(
            "--shadows and --ao shade ball-and-stick hits: use them with --mode bs or vol+bs \
             (--mode path has its own lighting; for volumetric shadows use --mode volume \
             --volume-shadows)"
        );
    }
    // Values of flags the chosen modality does not use are still checked.
    if !(args.ao_distance > 0.0 && args.ao_distance.is_finite()) {
        bail!("--ao-distance must be a positive number of Å");
    }
    if args.max_depth == 0 {
        bail!("--max-depth must be at least 1");
    }
    if !(args.roughness >= 0.0 && args.roughness.is_finite()) {
        bail!("--roughness must be a non-negative number");
    }
    let has_model = m != Mode::Volume;
    let has_volume = matches!(m, Mode::Volume | Mode::VolBs);
    render_settings(args).validate(has_model, has_volume)?;
    Ok(())
}

/// The ray tracing modality the flags ask for (`None`: the plain headlight / volume modes).
pub(crate) fn modality(args: &RenderArgs) -> Option<Modality> {
    if args.mode == Mode::Path {
        return Some(Modality::Path {
            material: match args.material {
                MaterialArg::Metal => Material::Metal,
                MaterialArg::Diffuse => Material::Diffuse,
            },
            max_depth: args.max_depth,
            roughness: args.roughness,
        });
    }
    if let Some(n) = args.ao {
        return Some(Modality::Ao {
            samples: n,
            distance: args.ao_distance,
        });
    }
    if args.shadows {
        return Some(Modality::Direct { shadows: true });
    }
    None
}

/// Suffix naming the modality in reports.
fn modality_name(args: &RenderArgs) -> String {
    match modality(args) {
        Some(Modality::Path { material, .. }) => format!(" {material:?}").to_lowercase(),
        Some(Modality::Ao { samples, distance }) => format!(" ao {samples}x{distance}Å"),
        Some(Modality::Direct { .. }) => {
            if args.volume_shadows {
                " shadows (volume-attenuated)".into()
            } else {
                " shadows".into()
            }
        }
        Some(Modality::Headlight) | None => String::new(),
    }
}
