//! `bnsview render FILE --frames …`: a trajectory to numbered images or an animated GIF
//! through the `series` crate (one pass through the file, the next frame built in the
//! background).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use render::Look;
use series::{FollowSettings, FrameRange, OutputKind, SeriesSettings, Sink, Source};
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
    let output = (args.output.clone()).unwrap_or_else(|| series::default_output(&path));
    let kind = OutputKind::from_path(&output)?;
    let (w, h) = args.look.size;
    let scene = look.scene_settings(input.bond_settings()?, (w, h));
    let render = look.render_settings();
    let camera = args.look.camera_choice(args.fit == FitFrames::All)?;
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
    let follow = args.follow.then(|| FollowSettings {
        poll: Duration::from_secs_f64(args.poll),
        max_frames: args.max_frames,
        stop: Arc::new(AtomicBool::new(false)),
    });
    // Open the input before the output, so a bad input leaves no empty movie behind.
    let mut source = Source::open(&path, &input.read_options()?, follow.clone())?;
    let mut sink = Sink::open(&kind, args.force, args.gif_fps)?;
    let pb = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("{spinner} {pos} frames written ({elapsed}) {msg}")
    {
        pb.set_style(style);
    }
    pb.enable_steady_tick(std::time::Duration::from_millis(500));
    let verbose = args.look.verbose;
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
    let report = (source.render(&settings, &mut sink, &mut on_frame))
        .with_context(|| format!("rendering the frames of {}", path.display()))?;
    pb.finish_and_clear();
    for warning in source.warnings() {
        eprintln!("warning: {warning}");
    }
    if source.stopped() {
        eprintln!("stopped by Ctrl-C");
    }
    if verbose {
        eprintln!("{}", crate::isa_line(isa));
        for line in source.describe(&report, settings.pipelined) {
            eprintln!("{line}");
        }
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
