//! `bnsview render`: a molecule file or a built-in scene to a PNG.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use render::{render_frame_into, Camera, Framebuffer, RenderOptions, View};
use spmd::Isa;
use volume::{ClassifiedTf, Lighting, MarchOptions, Preset, TransferFunction, VolumeScene};

use crate::input::InputArgs;
use crate::pipeline::{build_scene, build_volume, GeometryArgs, VolumeArgs};

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
}

impl Mode {
    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Bs => "bs",
            Mode::Volume => "volume",
            Mode::VolBs => "vol+bs",
        }
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
    /// Background colour `r,g,b` (0-255).
    #[arg(long, default_value = "255,255,255", value_parser = parse_rgb)]
    pub background: [u8; 3],
    #[command(flatten)]
    pub geometry: GeometryArgs,
    #[command(flatten)]
    pub volume: VolumeArgs,
    /// Transfer function: a preset (coolwarm, viridis, grayscale) or a file of control
    /// points `value r g b a` (value in [0,1] of the density range).
    #[arg(long, default_value = "coolwarm")]
    pub tf: String,
    /// Volume: gradient lighting by central differences (headlight).
    #[arg(long)]
    pub lit: bool,
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
    if args.lit && args.mode == Mode::Bs {
        bail!("--lit lights the volume: use it with --mode volume or --mode vol+bs");
    }
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
    let tf = if args.mode == Mode::Bs {
        None
    } else {
        Some(load_tf(&args.tf)?)
    };

    let l = input.load(false)?;
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
    verbose(format!(
        "bonds:   {:.3} s  {} bonds",
        l.bond_s,
        l.bonds.len()
    ));

    let scene = if args.mode == Mode::Volume {
        None
    } else {
        let (scene, secs) = build_scene(m, &l.bonds, &args.geometry)?;
        let st = &scene.bvh.stats;
        verbose(format!(
            "bvh:     {:.3} s  {} prims, {} nodes, SAH {:.1}, {:.1} MB ({:.1} B/atom), scene build {:.3} s",
            st.build_time.as_secs_f64(),
            st.prims,
            st.nodes,
            st.sah_cost,
            st.bytes as f64 / 1e6,
            st.bytes_per_atom(),
            secs
        ));
        Some(scene)
    };
    let vol = if args.mode == Mode::Bs {
        None
    } else {
        let (vol, cells, secs) = build_volume(isa, m, &args.volume)?;
        verbose(format!(
            "volume:  {:.3} s  {:?} lattice points at {} /Å, {:.1} MB {}",
            secs,
            vol.grid.dims,
            args.volume.voxels_per_angstrom,
            vol.bytes() as f64 / 1e6,
            vol.format().name()
        ));
        Some((vol, cells))
    };
    // Fit the camera to the scene's bounding sphere (the volume's box when there is no
    // geometry).
    let (center, radius) = match (&scene, &vol) {
        (Some(sc), _) => (sc.center, sc.radius),
        (None, Some((v, _))) => {
            let lo = v.grid.origin;
            let hi = v.grid.max_corner();
            let c = [
                (lo[0] + hi[0]) * 0.5,
                (lo[1] + hi[1]) * 0.5,
                (lo[2] + hi[2]) * 0.5,
            ];
            let r = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2))
                .sqrt()
                * 0.5;
            (c, r)
        }
        _ => unreachable!("every mode draws geometry or volume"),
    };
    let camera = match &args.camera {
        Some(spec) => parse_camera(spec)?,
        None => Camera::view(
            match args.view {
                ViewArg::Far => View::Far,
                ViewArg::Close => View::Close,
            },
            center,
            radius,
            args.fov,
            w as f32 / h as f32,
        ),
    };
    let classified = match (&tf, &vol) {
        (Some(tf), Some((v, _))) => Some(ClassifiedTf::new(tf, 0.0, v.max_value, 0.5)),
        _ => None,
    };
    let vscene = match (&vol, &classified) {
        (Some((v, cells)), Some(ctf)) => Some(VolumeScene::new(
            v,
            cells,
            ctf,
            MarchOptions {
                macrocells: !args.no_macrocells,
                preintegrated: !args.no_preintegration,
                lighting: if args.lit {
                    Lighting::Headlight
                } else {
                    Lighting::Unlit
                },
                ..MarchOptions::default()
            },
        )),
        _ => None,
    };
    let [r, g, b] = args.background;
    let opt = RenderOptions {
        background: render::rgba(r, g, b, 255),
        ..RenderOptions::default()
    };
    let mut fb = Framebuffer::new(w, h, opt.background)?;
    let t = Instant::now();
    let stats = render_frame_into(scene.as_ref(), vscene.as_ref(), &camera, &mut fb, &opt, isa);
    verbose(format!(
        "render:  {:.3} s  {}x{} {} ({:.1} Mrays/s, {:.2} fps)",
        t.elapsed().as_secs_f64(),
        w,
        h,
        args.mode.name(),
        stats.mrays_per_s(),
        stats.fps()
    ));
    fb.save_png(&output)
        .with_context(|| format!("writing {}", output.display()))?;
    eprintln!(
        "wrote {} ({w}x{h}, {}, {isa})",
        output.display(),
        args.mode.name()
    );
    Ok(())
}
