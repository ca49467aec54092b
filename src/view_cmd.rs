//! `bnsview view`: the interactive window over a file or a built-in scene.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use spmd::Isa;
use viewer::{FrameSource, Toggles, ViewConfig};

use crate::input::InputArgs;
use crate::look::LookArgs;

/// Arguments of `bnsview view`.
#[derive(Args, Debug)]
pub struct ViewArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Drive the viewer from a file of commands, one per line (`orbit AZ EL`, `pan DX DY`,
    /// `zoom F`, `key NAME`, `frame K`, `wait-frames N`, `wait-still`, `screenshot FILE`,
    /// `quit`); the window works as usual meanwhile.
    #[arg(help_heading = "Viewer", long, value_name = "FILE")]
    pub script: Option<PathBuf>,
    /// Write one JSON line per presented frame (time, time step, mode, preview scale,
    /// samples, render time, whether a scene was loading) and per key to this file.
    #[arg(help_heading = "Viewer", long, value_name = "FILE")]
    pub log: Option<PathBuf>,
    /// Render every frame at full resolution, also while the camera moves (benchmarks).
    #[arg(help_heading = "Viewer", long)]
    pub no_preview: bool,
    /// Screenshots may overwrite existing files.
    #[arg(help_heading = "Viewer", short, long)]
    pub force: bool,
    /// AO rays per hit when the `a` key switches ambient occlusion on (default: --ao, else 8).
    #[arg(help_heading = "Viewer", long, value_name = "N")]
    pub ao_key_samples: Option<u32>,
    /// Threads that read and build time steps in the background (default: all cores). They
    /// run at the lowest priority, so they use only what the window's frames leave.
    #[arg(help_heading = "Viewer", long, value_name = "N")]
    pub build_threads: Option<usize>,
    #[command(flatten)]
    pub look: LookArgs,
}

/// The loader's pool size: `--build-threads`, else every core (refused beyond 16 per core).
fn build_threads(n: Option<usize>) -> Result<usize> {
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    let n = n.unwrap_or(cores);
    if n == 0 || n > 16 * cores {
        bail!(
            "--build-threads {n}: use 1 to {} (16 per core on this machine)",
            16 * cores
        );
    }
    Ok(n)
}

/// Run `bnsview view`.
pub fn run(args: ViewArgs, isa: Isa) -> Result<()> {
    args.look.init_threads(None)?;
    let build_threads = build_threads(args.build_threads)?;
    let look = args.look.look(args.input.pbc)?;
    look.validate()?;
    if args.look.geometry.legend {
        bail!("--legend is drawn by `bnsview render` only; the viewer's screenshots have none");
    }
    let script = match &args.script {
        Some(p) => Some(viewer::script::load(p)?),
        None => None,
    };
    let input = &args.input;
    let (source, first_frame) = FrameSource::open(&input.input()?, input.frame)?;
    let toggles = Toggles::of(&look);
    // The viewer's toggles set on a copy of the look: every frame is what `render` makes of
    // the same flags.
    let (bonds, size) = (input.bond_settings()?, args.look.size);
    let configure = move |t: &Toggles| {
        let l = t.apply(&look);
        l.validate().map_err(|e| e.to_string())?;
        Ok((l.scene_settings(bonds.clone(), size), l.render_settings()))
    };
    let camera = args.look.camera_choice(false)?;
    let cfg = ViewConfig {
        size: args.look.size,
        isa,
        toggles,
        ao_samples: args.ao_key_samples.or(args.look.ao).unwrap_or(8),
        configure: Box::new(configure),
        camera: Box::new(move |sphere| Ok(camera.camera(sphere, size))),
        first_frame,
        script,
        log: args.log.clone(),
        force: args.force,
        build_threads,
        preview: !args.no_preview,
    };
    let report = viewer::run(cfg, source).context("bnsview view")?;
    if args.look.verbose {
        eprintln!(
            "view: {} frames presented, {} screenshot(s)",
            report.presented,
            report.screenshots.len()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::build_threads;

    #[test]
    fn build_threads_default_to_every_core_and_refuse_zero_and_absurd_counts() {
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        assert_eq!(build_threads(None).unwrap(), cores);
        assert_eq!(build_threads(Some(1)).unwrap(), 1);
        assert_eq!(build_threads(Some(16 * cores)).unwrap(), 16 * cores);
        for bad in [0, 16 * cores + 1, usize::MAX] {
            let e = build_threads(Some(bad)).unwrap_err().to_string();
            assert!(
                e.contains("--build-threads") && e.contains("use 1 to"),
                "{e}"
            );
        }
    }
}
