//! The series loop: frames read on one background thread two frames ahead of the renderer and
//! their scenes built on another one frame ahead (paper §4: the next time step is prepared
//! while the current one is shown), at most two scenes alive.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::sync_channel;
use std::time::Instant;

use molecule::read::Trajectory;
use molecule::Molecule;
use render::{render_scene, Camera, RenderSettings, SceneFrame};
use scene::{CameraChoice, ColorBy, Scene, SceneSettings};
use spmd::Isa;

use crate::fit_all::sphere_of_frames;
use crate::{FrameRange, SeriesError, Sink};

/// Everything a series is rendered with.
#[derive(Clone, Debug)]
pub struct SeriesSettings {
    /// Frames of the file to render.
    pub frames: FrameRange,
    /// What each frame's scene holds. A column colour range or density range left `None` is
    /// taken from the first rendered frame and kept for the rest.
    pub scene: SceneSettings,
    /// How each frame is rendered.
    pub render: RenderSettings,
    /// Image size (pixels).
    pub size: (u32, u32),
    /// The camera.
    pub camera: CameraChoice,
    /// Draw a colour legend (when colouring by a column) with text of this colour.
    pub legend_ink: Option<[u8; 3]>,
    /// Read the frame after next on one background thread and build the next on another
    /// while this one renders (off: read, build and render one after the other, for
    /// comparison).
    pub pipelined: bool,
    /// SIMD backend of the builds and the renderer.
    pub isa: Isa,
}

/// What one frame took (seconds).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameReport {
    /// Frame index in the file.
    pub frame: usize,
    /// Atoms in the frame.
    pub atoms: usize,
    /// Reading (and skipping the frames before it).
    pub read_s: f64,
    /// Building its scene.
    pub build_s: f64,
    /// Time the renderer waited for it (0 when the build was hidden behind rendering).
    pub wait_s: f64,
    /// Rendering.
    pub render_s: f64,
    /// Encoding and writing the image.
    pub write_s: f64,
    /// Where it went.
    pub path: std::path::PathBuf,
    /// How the frame was unwrapped (`None`: `BondSettings::unwrap` off).
    pub unwrap: Option<scene::UnwrapReport>,
}

/// What a whole series took.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeriesReport {
    /// Frames rendered.
    pub frames: usize,
    /// Wall time (s).
    pub wall_s: f64,
    /// Sums over the frames of read + build time, and of the renderer's waits (s): the
    /// difference is the build time hidden behind rendering.
    pub build_s: f64,
    /// Sum of the renderer's waits for the next scene (s).
    pub wait_s: f64,
    /// The camera used.
    pub camera: Option<Camera>,
    /// The sphere the camera was fitted to (Å; `None` for a fixed camera).
    pub fitted_to: Option<scene::Sphere>,
    /// The column colour range used, when colouring by a column.
    pub color_range: Option<(f32, f32)>,
    /// The density mapped to the transfer function's top, when there is a volume.
    pub density_max: Option<f32>,
}

/// A frame read and built, ready to render.
struct Built {
    frame: usize,
    atoms: usize,
    scene: Scene,
    read_s: f64,
    build_s: f64,
}

/// Where the frames of a series come from: a file read once from its start, or a growing
/// file followed as it is written.
pub(crate) trait Frames: Send {
    /// The next frame to render and its index in the file; `None` when the series is over,
    /// or when `cancel` is set while waiting for a frame.
    fn next_frame(&mut self, cancel: &AtomicBool)
        -> Result<Option<(usize, Molecule)>, SeriesError>;
    /// The error when the series ends before its first frame.
    fn none_error(&self) -> SeriesError;
    /// Whether a GIF or video holding the frames so far is completed, not removed, when the
    /// series stops on an error (a followed run: the frames already shown stay).
    fn keep_on_error(&self) -> bool {
        false
    }
}

/// The frames of `range` in a trajectory, read on from its current position.
struct Ranged<'a> {
    traj: &'a mut Trajectory,
    range: FrameRange,
    /// Index of the next frame the trajectory yields.
    next: usize,
}

impl Frames for Ranged<'_> {
    fn next_frame(&mut self, _: &AtomicBool) -> Result<Option<(usize, Molecule)>, SeriesError> {
        loop {
            if self.range.end.is_some_and(|e| self.next >= e) {
                return Ok(None);
            }
            let k = self.next;
            let Some(m) = self.traj.next() else {
                return Ok(None);
            };
            let m = m?;
            self.next += 1;
            if self.range.contains(k) {
                return Ok(Some((k, m)));
            }
        }
    }

    fn none_error(&self) -> SeriesError {
        SeriesError::NoFrames {
            range: self.range.to_string(),
            count: self.next,
        }
    }
}

/// Reads and builds the next frame of `frames` with `settings`.
fn read_and_build(
    frames: &mut dyn Frames,
    settings: &SceneSettings,
    isa: Isa,
) -> Result<Option<Built>, SeriesError> {
    let t = Instant::now();
    let Some((frame, m)) = frames.next_frame(&AtomicBool::new(false))? else {
        return Ok(None);
    };
    build(frame, m, t.elapsed().as_secs_f64(), settings, isa).map(Some)
}

/// Builds the scene of frame `frame`, read in `read_s` seconds.
fn build(
    frame: usize,
    m: Molecule,
    read_s: f64,
    settings: &SceneSettings,
    isa: Isa,
) -> Result<Built, SeriesError> {
    let t = Instant::now();
    let scene =
        Scene::build(isa, &m, settings).map_err(|error| SeriesError::Scene { frame, error })?;
    Ok(Built {
        frame,
        atoms: m.len(),
        scene,
        read_s,
        build_s: t.elapsed().as_secs_f64(),
    })
}

/// Sets its flag when dropped (however the scope it lives in is left).
struct SetOnDrop<'a>(&'a AtomicBool);

impl Drop for SetOnDrop<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

/// Renders the frames `s.frames` of `traj` (read from its current position onwards, once)
/// to `sink`, calling `on_frame` after each one is written. With [`CameraChoice::FitAll`] the
/// file is read once more first (from its start) to find the sphere holding every frame.
/// On an error a GIF or video being written is removed ([`Sink::abandon`]).
pub fn render_series(
    traj: &mut Trajectory,
    s: &SeriesSettings,
    sink: &mut Sink,
    on_frame: &mut dyn FnMut(&FrameReport),
) -> Result<SeriesReport, SeriesError> {
    let fitted;
    let mut fitted_to = None;
    let s = match s.camera {
        CameraChoice::FitAll { .. } => {
            let sphere = traj
                .reopen()
                .map_err(SeriesError::from)
                .and_then(|mut t| sphere_of_frames(&mut t, &s.frames, &s.scene));
            let sphere = sphere.inspect_err(|_| sink.abandon())?;
            fitted_to = Some(sphere);
            fitted = SeriesSettings {
                camera: CameraChoice::Fixed(s.camera.camera(sphere, s.size)),
                ..s.clone()
            };
            &fitted
        }
        _ => s,
    };
    let mut frames = Ranged {
        traj,
        range: s.frames,
        next: 0,
    };
    let mut report = run_frames(&mut frames, s, sink, on_frame)?;
    report.fitted_to = report.fitted_to.or(fitted_to);
    Ok(report)
}

/// [`run_series`], removing a GIF or video being written on an error.
pub(crate) fn run_frames(
    frames: &mut dyn Frames,
    s: &SeriesSettings,
    sink: &mut Sink,
    on_frame: &mut dyn FnMut(&FrameReport),
) -> Result<SeriesReport, SeriesError> {
    let r = run_series(frames, s, sink, on_frame);
    if r.is_err() {
        if frames.keep_on_error() {
            sink.finish().ok();
        } else {
            sink.abandon();
        }
    }
    r
}

fn run_series(
    frames: &mut dyn Frames,
    s: &SeriesSettings,
    sink: &mut Sink,
    on_frame: &mut dyn FnMut(&FrameReport),
) -> Result<SeriesReport, SeriesError> {
    s.render
        .validate(s.scene.model.is_some(), s.scene.volume.is_some())?;
    let wall = Instant::now();
    let mut settings = s.scene.clone();
    // The first frame fixes the camera and the ranges.
    let Some(first) = read_and_build(frames, &settings, s.isa)? else {
        return Err(frames.none_error());
    };
    if matches!(s.camera, CameraChoice::FitAll { .. }) {
        return Err(SeriesError::FitAllFollow);
    }
    let camera = s.camera.camera(first.scene.sphere, s.size);
    let color_range = first.scene.model.as_ref().and_then(|m| m.color_range);
    if let Some(ms) = settings.model.as_mut() {
        if let ColorBy::Column { range, .. } = &mut ms.color {
            *range = range.or(color_range);
        }
    }
    let density_max = first.scene.volume.as_ref().map(|d| d.tf_max);
    if let Some(vs) = settings.volume.as_mut() {
        vs.density_max = vs.density_max.or(density_max);
    }
    let mut report = SeriesReport {
        camera: Some(camera),
        fitted_to: matches!(s.camera, CameraChoice::Fit { .. }).then_some(first.scene.sphere),
        color_range,
        density_max,
        ..SeriesReport::default()
    };
    let mut render_one = |b: Built, wait_s: f64| -> Result<(), SeriesError> {
        let t = Instant::now();
        let job = SceneFrame {
            scene: &b.scene,
            camera: &camera,
            settings: &s.render,
            size: s.size,
            legend_ink: s.legend_ink,
            isa: s.isa,
        };
        let image = render_scene(&job, None)?;
        let render_s = t.elapsed().as_secs_f64();
        let unwrap = b.scene.unwrap;
        drop(b.scene);
        let t = Instant::now();
        let path = sink.write(b.frame, &image.frame)?;
        let r = FrameReport {
            frame: b.frame,
            atoms: b.atoms,
            read_s: b.read_s,
            build_s: b.build_s,
            wait_s,
            render_s,
            write_s: t.elapsed().as_secs_f64(),
            path,
            unwrap,
        };
        report.frames += 1;
        report.build_s += r.read_s + r.build_s;
        report.wait_s += wait_s;
        on_frame(&r);
        Ok(())
    };
    let first_wait = first.read_s + first.build_s;
    if !s.pipelined {
        render_one(first, first_wait)?;
        while let Some(b) = read_and_build(frames, &settings, s.isa)? {
            let wait = b.read_s + b.build_s;
            render_one(b, wait)?;
        }
    } else {
        // Three stages on rendezvous channels: a reader parses frame k+2 (serial work, one
        // core) while a builder builds frame k+1 (parallel) and this thread renders frame k.
        // The builder blocks with k+1 built until the renderer takes it, so at most two scenes
        // are alive (k rendering, k+1 waiting) and one parsed frame waits for the builder.
        let (mtx, mrx) = sync_channel::<Result<(usize, Molecule, f64), SeriesError>>(0);
        let (tx, rx) = sync_channel::<Result<Built, SeriesError>>(0);
        let settings = &settings;
        let cancel = AtomicBool::new(false);
        let cancel = &cancel;
        std::thread::scope(|scope| -> Result<(), SeriesError> {
            // Owned here, so an error return drops it: the builder's `send` fails, it exits
            // and drops `mrx`, and the reader's `send` fails. `_stop` tells a reader that is
            // waiting for a followed file to grow to give up.
            let rx = rx;
            let _stop = SetOnDrop(cancel);
            scope.spawn(move || loop {
                let t = Instant::now();
                let item = match frames.next_frame(cancel) {
                    Ok(Some((k, m))) => Ok((k, m, t.elapsed().as_secs_f64())),
                    Ok(None) => return,
                    Err(e) => Err(e),
                };
                let last = item.is_err();
                if mtx.send(item).is_err() || last {
                    return;
                }
            });
            scope.spawn(move || {
                for item in mrx {
                    let built = item
                        .and_then(|(frame, m, read_s)| build(frame, m, read_s, settings, s.isa));
                    let last = built.is_err();
                    if tx.send(built).is_err() || last {
                        return;
                    }
                }
            });
            render_one(first, first_wait)?;
            loop {
                let t = Instant::now();
                let Ok(b) = rx.recv() else { break };
                render_one(b?, t.elapsed().as_secs_f64())?;
            }
            Ok(())
        })?;
    }
    sink.finish()?;
    report.wall_s = wall.elapsed().as_secs_f64();
    Ok(report)
}
