//! Time series (paper §4, issue #15): the frames of a trajectory rendered in order, in one
//! pass through the file, with the frame after next read on one background thread and the
//! next one's scene (bonds, BVH, volume) built on another while the current one renders. The camera and the colour and
//! density ranges are fixed by the first frame, so a movie does not jump or flicker. Frames go
//! to numbered PNG/JPEG files, an animated GIF or a video ([`Sink`]). A file a simulation is
//! still writing can be followed, each frame rendered when it is complete ([`follow_series`]).
//!
//! Units: positions in Ångström (Å), times in seconds.
#![warn(missing_docs)]

mod error;
mod fit_all;
mod follow;
mod output;
mod range;
mod run;
mod source;

pub use error::SeriesError;
pub use follow::{follow_series, FollowSettings};
pub use output::{default_output, expand, OutputKind, Sink, DEFAULT_GIF_FPS};
pub use range::{FrameRange, FrameRangeError};
pub use run::{render_series, FrameReport, SeriesReport, SeriesSettings};
pub use scene::CameraChoice;
pub use source::Source;
