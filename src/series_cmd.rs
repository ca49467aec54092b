//! `bnsview render FILE --frames …`: a trajectory to numbered images or an animated GIF
//! through the `series` crate (one pass through the file, the next frame built in the
//! background).

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use molecule::read::Follower;
use render::{Camera, Look};
use series::{
    follow_series, render_series, CameraChoice, FollowSettings, FrameRange, OutputKind,
    SeriesSettings, Sink,
};
use spmd::Isa;

use crate::input::InputArgs;
use crate::render_cmd::{FitFrames, RenderArgs};

/// Renders `args.frames` of the input file.
pub fn run(args: &RenderArgs, look: &Look, input: &InputArgs, isa: Isa) -> Result<()> {
    let frames = args.frames.unwrap_or(FrameRange::ALL);
    let Some(path) = input.file.clone() else {
        bail!("--frames and --follow render the frames of a trajectory file; built-in scenes have one frame");
    };
    if args.follow && !(args.poll.is_finite() && (0.01..=3600.0).contains(&args.poll)) {
        bail!("--poll {}: expected 0.01 to 3600 seconds", args.poll);
    }
    let output = args.output.clone().unwrap_or_else(|| {
        let stem = path
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "bnsview".into());
        let stem = stem.split('.').next().unwrap_or("bnsview").to_string();
        PathBuf::from(format!("{stem}_%05d.png"))
    });
    let kind = OutputKind::from_path(&output)?;
    let (w, h) = args.look.size;
    let scene = look.scene_settings(input.bond_settings()?, (w, h));
    let render = look.render_settings();
    let camera = match &args.look.camera {
        Some(spec) => CameraChoice::Fixed(spec.parse::<Camera>()?),
        None => {
            let (view, orbit) = args.look.view_and_orbit();
            let fov_deg = args.look.fov;
            match args.fit {
                FitFrames::First => CameraChoice::Fit {
                    view,
                    orbit,
                    fov_deg,
                },
                FitFrames::All => CameraChoice::FitAll {
                    view,
                    orbit,
                    fov_deg,
                },
            }
        }
    };
    let legend_ink = args.look.geometry.legend.then(|| look.legend_ink());
    let settings = SeriesSettings {
        frames,
        scene,
        render,
        size: (w, h),
        camera,
        legend_ink,
        pipelined: !args.no_pipeline,
        isa,
    };
    // Open the input before the output, so a bad input leaves no empty movie behind.
    let mut source = if args.follow {
        let opts = input.read_options()?;
        Source::Follow(Follower::new(&path, &opts)?)
    } else {
        Source::File(input.open_trajectory(&path)?)
    };
    let mut sink = Sink::open(&kind, args.force, args.gif_fps)?;
    let pb = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("{spinner} {pos} frames written ({elapsed}) {msg}")
    {
        pb.set_style(style);
    }
    pb.enable_steady_tick(std::time::Duration::from_millis(500));
    let verbose = args.look.verbose;
    let follow = args.follow.then(|| FollowSettings {
        poll: Duration::from_secs_f64(args.poll),
        max_frames: args.max_frames,
        stop: Arc::new(AtomicBool::new(false)),
    });
    if let Some(f) = &follow {
        stop_on_ctrl_c(f.stop.clone())?;
        pb.set_message(format!(
            "following {}, waiting for a complete frame (Ctrl-C to stop)",
            path.display()
        ));
    }
    let mut on_frame = |r: &series::FrameReport| {
        pb.inc(1);
        pb.set_message(if follow.is_some() {
            format!(
                "frame {} → {}; waiting for the next frame (Ctrl-C to stop)",
                r.frame,
                r.path.display()
            )
        } else {
            format!("frame {} → {}", r.frame, r.path.display())
        });
        if verbose {
            pb.suspend(|| {
                eprintln!(
                    "frame {:>5}: {} atoms, read {:.3} s, build {:.3} s, waited {:.3} s, render {:.3} s, write {:.3} s → {}",
                    r.frame, r.atoms, r.read_s, r.build_s, r.wait_s, r.render_s, r.write_s, r.path.display()
                );
                if let Some(u) = &r.unwrap {
                    eprintln!("             {}", u.describe());
                }
            });
        }
    };
    let report = match (&mut source, &follow) {
        (Source::Follow(f), Some(fs)) => follow_series(f, &settings, fs, &mut sink, &mut on_frame),
        (Source::File(t), _) => render_series(t, &settings, &mut sink, &mut on_frame),
        (Source::Follow(_), None) => bail!("internal: following without settings"),
    }
    .with_context(|| format!("rendering the frames of {}", path.display()))?;
    pb.finish_and_clear();
    let (warnings, decoded) = match &mut source {
        Source::Follow(f) => (f.warnings().to_vec(), None),
        Source::File(t) => (t.warnings().to_vec(), Some(t.decoded_bytes())),
    };
    for warning in warnings {
        eprintln!("warning: {warning}");
    }
    if follow
        .as_ref()
        .is_some_and(|f| f.stop.load(Ordering::Relaxed))
    {
        eprintln!("stopped by Ctrl-C");
    }
    if verbose {
        eprintln!(
            "isa:     {isa} ({} lanes), {} threads",
            isa.lanes(),
            rayon::current_num_threads()
        );
        if let Some(c) = report.camera {
            eprintln!("camera:  --camera {c}");
        }
        if let Some((lo, hi)) = report.color_range {
            eprintln!("color:   --color-range {lo}:{hi} (fixed by the first frame)");
        }
        if let Some(d) = report.density_max {
            eprintln!("volume:  --density-max {d} (fixed by the first frame)");
        }
        let hidden = (report.build_s - report.wait_s).max(0.0);
        eprintln!(
            "series:  {} frames in {:.2} s ({:.2} frames/s); read+build {:.2} s, of which {:.2} s hidden behind rendering{}; {} MB decoded from {}",
            report.frames,
            report.wall_s,
            report.frames as f64 / report.wall_s.max(1e-9),
            report.build_s,
            hidden,
            if settings.pipelined { "" } else { " (--no-pipeline)" },
            decoded.map_or("(followed)".into(), |b| (b / 1_000_000).to_string()),
            path.display()
        );
    }
    eprintln!(
        "wrote {} frame(s) of {} to {} ({w}x{h}, {}, {isa})",
        report.frames,
        path.display(),
        output.display(),
        args.look.mode.name()
    );
    Ok(())
}

/// Where the frames come from.
enum Source {
    /// A finished file, read once.
    File(molecule::read::Trajectory),
    /// A file still being written.
    Follow(Follower),
}

/// Sets `stop` on the first Ctrl-C (the series finishes the frame it renders and completes
/// its output); a second Ctrl-C exits at once.
fn stop_on_ctrl_c(stop: Arc<AtomicBool>) -> Result<()> {
    ctrlc::set_handler(move || {
        if stop.swap(true, Ordering::Relaxed) {
            std::process::exit(130);
        }
        eprintln!("\nCtrl-C: finishing the current frame (press again to quit at once)");
    })
    .context("installing the Ctrl-C handler")
}
