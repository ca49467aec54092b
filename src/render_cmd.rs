//! `bnsview render`: a molecule file or a built-in scene to a PNG.

use std::io::IsTerminal;
use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use cluster::Ranks;
use render::render_scene_to_file;
use scene::Scene;
use spmd::Isa;

use crate::input::InputArgs;
use crate::look::LookArgs;

/// Which frames of a series the camera is fitted to.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FitFrames {
    /// The first frame rendered.
    First,
    /// Every frame rendered.
    All,
}

/// Arguments of `bnsview render`.
#[derive(Args, Debug)]
#[command(group(clap::ArgGroup::new("series").args(["frames", "follow"]).multiple(true)))]
pub struct RenderArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Output image, .png or .jpg (default: the scene name or the file's stem, with .png).
    /// With --frames: a numbered name such as out_%05d.png (%d or %0Nd is the frame index in
    /// the file; the default is STEM_%05d.png) or an animated .gif.
    #[arg(help_heading = "Output", short, long)]
    pub output: Option<PathBuf>,
    /// Render frames of a trajectory, `all` or `A:B[:STEP]` (A up to but not including B,
    /// every STEP-th), in one pass through the file, the next frame built while this one
    /// renders. The camera and the colour and density ranges are fixed by the first frame.
    #[arg(
        help_heading = "Output",
        long,
        value_name = "all|A:B[:STEP]",
        conflicts_with = "frame"
    )]
    pub frames: Option<series::FrameRange>,
    /// Follow a dump (XYZ, .gro or LAMMPS dump, uncompressed) that a simulation is still
    /// writing: render every frame (of --frames, default all) as soon as it is complete, until
    /// Ctrl-C or --max-frames. Works on NFS (polls the file size).
    #[arg(help_heading = "Output", long, conflicts_with = "frame")]
    pub follow: bool,
    /// With --follow: stop after this many rendered frames.
    #[arg(help_heading = "Output", long, value_name = "N", requires = "follow")]
    pub max_frames: Option<usize>,
    /// With --follow: seconds between two looks at the file while waiting for a frame.
    #[arg(
        help_heading = "Output",
        long,
        value_name = "SECONDS",
        default_value_t = 0.5,
        requires = "follow"
    )]
    pub poll: f64,
    /// With --frames or --follow: build each frame after the previous one is rendered instead
    /// of in the background (for comparison).
    #[arg(help_heading = "Output", long, requires = "series")]
    pub no_pipeline: bool,
    /// With --frames or --follow and -o movie.gif: frames per second of the GIF.
    #[arg(help_heading = "Output", long, default_value_t = series::DEFAULT_GIF_FPS, requires = "series")]
    pub gif_fps: f32,
    /// Overwrite the output if it exists.
    #[arg(help_heading = "Output", short, long)]
    pub force: bool,
    /// With --frames: fit the camera to the first frame, or to all the frames rendered (the
    /// file is read twice: once to find where the atoms go, once to render).
    #[arg(help_heading = "Camera", long, value_enum, default_value_t = FitFrames::First, requires = "frames", conflicts_with = "camera")]
    pub fit: FitFrames,
    #[command(flatten)]
    pub look: LookArgs,
}

/// Run `bnsview render`.
/// `ranks`: the MPI job this process is a rank of (the frame's tiles are shared out, rank 0
/// writes and reports).
pub fn run(args: RenderArgs, isa: Isa, ranks: Option<&Ranks>) -> Result<()> {
    args.look.init_threads(ranks.map(Ranks::default_threads))?;
    let root = ranks.is_none_or(|r| r.rank() == 0);
    let look = args.look.look(args.input.pbc)?;
    look.validate()?;
    let input = &args.input;
    if args.frames.is_some() || args.follow {
        if let Some(r) = ranks {
            bail!("--frames and --follow run as one process; under mpirun ({} ranks) only one frame is shared out", r.size());
        }
        return crate::series_cmd::run(&args, &look, input, isa);
    }
    let output = match &args.output {
        Some(o) => o.clone(),
        None => PathBuf::from(format!("{}.png", input.input()?.stem())),
    };
    if root {
        render::ImageFormat::for_output(&output, args.force)?;
    }
    // Check the frame (or its band, when streamed) fits before the expensive preprocessing.
    let (w, h) = args.look.size;
    render::check_frame((w, h), &output, args.look.geometry.legend)?;
    let l = input.load(false, false)?;
    let m = &l.molecule;
    if m.is_empty() {
        bail!("{}: no atoms to render", l.source);
    }
    let verbose = |msg: String| {
        if args.look.verbose && root {
            eprintln!("{msg}");
        }
    };
    verbose(crate::isa_line(isa));
    verbose(format!(
        "load:    {:.3} s  {} ({} atoms)",
        l.load_s,
        l.source,
        m.len()
    ));
    let settings = look.scene_settings(input.bond_settings()?, args.look.size);
    let sc = crate::progress::follow_stages("building the scene", |p| {
        Scene::build_with(isa, m, &settings, p)
    })?;
    sc.stage_report().into_iter().for_each(verbose);
    // Fit the camera to the scene's bounding sphere (the atoms' one, padded by the density's
    // support, when there is no geometry).
    let camera = args.look.camera_choice(false)?.camera(sc.sphere, (w, h));
    verbose(format!("camera:  --camera {camera}"));
    let settings = look.render_settings();
    let pb = crate::progress::bar(
        &format!("rendering {w}x{h} {}", args.look.mode.name()),
        h as u64,
    );
    let ink = args.look.geometry.legend.then(|| look.legend_ink());
    // Bands cost up to ~10-20 % on a 50-150 ms frame (threads idle at each band's end:
    // BENCHMARKS.md, "Progress bands"), so only when a bar can be seen.
    let mut on_rows = |done: u32, _: u32| pb.set_position(done as u64);
    let on_rows = std::io::stderr().is_terminal().then_some(&mut on_rows as _);
    let job = render::SceneFrame {
        scene: &sc,
        camera: &camera,
        settings: &settings,
        size: (w, h),
        legend_ink: ink,
        isa,
    };
    let (stats, legend) = match ranks {
        None => render_scene_to_file(&job, on_rows, &output)?,
        Some(r) => {
            let f = r.render_scene_to_file(&job, on_rows, &output)?;
            f.describe().into_iter().for_each(verbose);
            (f.stats, f.legend)
        }
    };
    pb.finish_and_clear();
    if let Some((legend, drawn)) = &legend {
        verbose(legend.describe());
        if ink.is_some() && !drawn {
            eprintln!(
                "warning: --legend: the image is too small for a legend (under {} pixels on a side)",
                render::MIN_LEGEND_FRAME
            );
        }
    }
    let mode = args.look.mode.name();
    verbose(stats.describe(&settings, (w, h), mode));
    if render::is_streamed((w, h)) {
        verbose(format!(
            "stream:  {} rows a band, one in memory",
            render::band_rows(w)
        ));
    }
    if root {
        let (out, more) = (output.display(), settings.describe());
        eprintln!("wrote {out} ({w}x{h}, {mode}{more}, {isa})");
    }
    Ok(())
}
