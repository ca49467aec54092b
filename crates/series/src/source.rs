//! Where the frames of a series come from — a finished file read once, or a file a simulation
//! is still writing — and what a finished series reports.

use std::path::Path;
use std::sync::atomic::Ordering;

use molecule::read::{open, Follower, ReadOptions, Trajectory};

use crate::{
    follow_series, render_series, FollowSettings, FrameReport, SeriesError, SeriesReport,
    SeriesSettings, Sink,
};

/// The frames' source.
pub enum Source {
    /// A finished file, read once.
    File(Trajectory),
    /// A file still being written, followed as it grows.
    Follow(Follower, FollowSettings),
}

impl Source {
    /// Opens `path` with `options`, to follow when `follow` is given.
    pub fn open(
        path: &Path,
        options: &ReadOptions,
        follow: Option<FollowSettings>,
    ) -> Result<Source, SeriesError> {
        Ok(match follow {
            Some(f) => Source::Follow(Follower::new(path, options)?, f),
            None => Source::File(open(path, options)?),
        })
    }

    /// Renders the series `s` of this source to `sink` ([`render_series`] or
    /// [`follow_series`]), calling `on_frame` after each frame is written.
    pub fn render(
        &mut self,
        s: &SeriesSettings,
        sink: &mut Sink,
        on_frame: &mut dyn FnMut(&FrameReport),
    ) -> Result<SeriesReport, SeriesError> {
        match self {
            Source::File(t) => render_series(t, s, sink, on_frame),
            Source::Follow(f, fs) => follow_series(f, s, fs, sink, on_frame),
        }
    }

    /// The reader's warnings so far (unknown elements, a truncated last frame, …).
    pub fn warnings(&mut self) -> Vec<String> {
        match self {
            Source::File(t) => t.warnings().to_vec(),
            Source::Follow(f, _) => f.warnings().to_vec(),
        }
    }

    /// Whether a followed series was stopped ([`FollowSettings::stop`]).
    pub fn stopped(&self) -> bool {
        matches!(self, Source::Follow(_, f) if f.stop.load(Ordering::Relaxed))
    }

    /// The lines `render -v` prints after the series: the camera, colour and density ranges
    /// it fixed (flags that repeat it), and where the time went.
    pub fn describe(&self, r: &SeriesReport, pipelined: bool) -> Vec<String> {
        let mut lines = Vec::new();
        if let Some(c) = r.camera {
            lines.push(format!("camera:  --camera {c}"));
        }
        if let Some((lo, hi)) = r.color_range {
            lines.push(format!(
                "color:   --color-range {lo}:{hi} (fixed by the first frame)"
            ));
        }
        if let Some(d) = r.density_max {
            lines.push(format!(
                "volume:  --density-max {d} (fixed by the first frame)"
            ));
        }
        let (decoded, path) = match self {
            Source::File(t) => ((t.decoded_bytes() / 1_000_000).to_string(), t.path()),
            Source::Follow(f, _) => ("(followed)".into(), f.path()),
        };
        lines.push(format!(
            "series:  {} frames in {:.2} s ({:.2} frames/s); read+build {:.2} s, of which {:.2} s hidden behind rendering{}; {decoded} MB decoded from {}",
            r.frames,
            r.wall_s,
            r.frames as f64 / r.wall_s.max(1e-9),
            r.build_s,
            (r.build_s - r.wait_s).max(0.0),
            if pipelined { "" } else { " (--no-pipeline)" },
            path.display()
        ));
        lines
    }
}
