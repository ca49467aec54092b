//! A series over a file that a running simulation is still writing (`render --follow`): every
//! frame is rendered as soon as it is complete, until a frame limit, the end of the frame
//! range, or a stop request (Ctrl-C).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use molecule::read::Follower;
use molecule::Molecule;

use crate::run::{run_frames, Frames};
use crate::{FrameRange, FrameReport, SeriesError, SeriesReport, SeriesSettings, Sink};

/// How a growing file is followed.
#[derive(Clone, Debug)]
pub struct FollowSettings {
    /// Time between two looks at the file (its size) while waiting for a frame.
    pub poll: Duration,
    /// Stop after this many rendered frames (`None`: until stopped).
    pub max_frames: Option<usize>,
    /// Set (e.g. by a Ctrl-C handler) to finish after the frame being rendered; the output is
    /// completed, not abandoned.
    pub stop: Arc<AtomicBool>,
}

/// The frames of `range` of a followed file, waiting for each one.
struct Followed<'a> {
    follower: &'a mut Follower,
    range: FrameRange,
    f: &'a FollowSettings,
    /// Frames handed out.
    given: usize,
}

impl Frames for Followed<'_> {
    fn next_frame(
        &mut self,
        cancel: &AtomicBool,
    ) -> Result<Option<(usize, Molecule)>, SeriesError> {
        loop {
            if self.f.max_frames.is_some_and(|n| self.given >= n)
                || self.range.end.is_some_and(|e| self.follower.frames() >= e)
            {
                return Ok(None);
            }
            let m = loop {
                if self.f.stop.load(Ordering::Relaxed) || cancel.load(Ordering::Relaxed) {
                    return Ok(None);
                }
                match self.follower.try_next()? {
                    Some(m) => break m,
                    None => std::thread::sleep(self.f.poll),
                }
            };
            let k = self.follower.frames() - 1;
            if self.range.contains(k) {
                self.given += 1;
                return Ok(Some((k, m)));
            }
        }
    }

    fn none_error(&self) -> SeriesError {
        SeriesError::NothingFollowed {
            path: self.follower.path().display().to_string(),
            frames: self.follower.frames(),
        }
    }

    fn keep_on_error(&self) -> bool {
        self.given > 0
    }
}

/// Renders the frames `s.frames` of the file `follower` reads, each as soon as the file holds
/// all of it, to `sink`, calling `on_frame` after each one is written; returns when
/// `f.max_frames` frames are done, the range ends, or `f.stop` is set. The camera and ranges
/// come from the first frame, as in [`crate::render_series`]. An error (a malformed frame, a
/// file that shrinks or is replaced) removes a GIF or video being written.
pub fn follow_series(
    follower: &mut Follower,
    s: &SeriesSettings,
    f: &FollowSettings,
    sink: &mut Sink,
    on_frame: &mut dyn FnMut(&FrameReport),
) -> Result<SeriesReport, SeriesError> {
    if matches!(s.camera, crate::CameraChoice::FitAll { .. }) {
        sink.abandon();
        return Err(SeriesError::FitAllFollow);
    }
    let mut frames = Followed {
        follower,
        range: s.frames,
        f,
        given: 0,
    };
    run_frames(&mut frames, s, sink, on_frame)
}
