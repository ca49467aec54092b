//! Why a series stopped.

use std::path::{Path, PathBuf};

/// Errors of [`crate::render_series`] and its outputs.
#[derive(Debug, thiserror::Error)]
pub enum SeriesError {
    /// Reading a frame failed.
    #[error(transparent)]
    Read(#[from] molecule::read::ReadError),
    /// Following a growing file failed (it shrank, was replaced, or cannot be followed).
    #[error(transparent)]
    Follow(#[from] molecule::read::FollowError),
    /// A followed file had no complete frame in the range when the series stopped.
    #[error("{path}: stopped before a frame to render was complete ({frames} complete frame(s) in the file)")]
    NothingFollowed {
        /// The file.
        path: String,
        /// Complete frames seen.
        frames: usize,
    },
    /// `--fit all` asked of a followed file (its frames are not all there yet).
    #[error("--fit all needs every frame before the first is rendered, which a followed file does not have; the camera follows the first frame, or pass --camera (e.g. printed by -v on the finished file)")]
    FitAllFollow,
    /// Building a frame's scene failed.
    #[error("frame {frame}: {error}")]
    Scene {
        /// Frame index in the file.
        frame: usize,
        /// Why.
        error: scene::SceneError,
    },
    /// Rendering or writing an image failed.
    #[error(transparent)]
    Render(#[from] render::RenderError),
    /// The render settings are invalid.
    #[error(transparent)]
    Settings(#[from] render::SettingsError),
    /// An output exists and overwriting was not asked for.
    #[error("{} exists; pass --force to overwrite it", .0.display())]
    Exists(PathBuf),
    /// A numbered output without one `%d` / `%0Nd`.
    #[error("{0}: a series of frames needs a numbered name with one %d or %0Nd (e.g. out_%05d.png), or a .gif")]
    Pattern(String),
    /// A video was asked for and `ffmpeg` is not on PATH.
    #[error("{0}: videos are encoded by ffmpeg, which is not on PATH (install it, e.g. apt install ffmpeg); or write numbered PNGs (-o out_%05d.png) or an animated .gif instead")]
    Video(String),
    /// The range selects no frame of the file.
    #[error("--frames {range}: the file has {count} frame(s), none of them in the range")]
    NoFrames {
        /// The range asked for.
        range: String,
        /// Frames in the file.
        count: usize,
    },
    /// File system error. The message includes the underlying error's text, so it is not
    /// also a `source()` (an error chain printer would repeat it).
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        error: std::io::Error,
    },
    /// Image encoder error (its text in the message, not a `source()`, as for `Io`).
    #[error("writing {path}: {error}")]
    Image {
        /// The file.
        path: String,
        /// Why.
        error: image::ImageError,
    },
    /// The directory of a numbered output does not exist.
    #[error("cannot write {pattern}: directory {dir} does not exist (create it first)")]
    NoDirectory {
        /// The output pattern.
        pattern: String,
        /// Its directory.
        dir: String,
    },
}

impl SeriesError {
    pub(crate) fn io(path: &Path, source: std::io::Error) -> SeriesError {
        SeriesError::Io {
            path: path.display().to_string(),
            error: source,
        }
    }
    pub(crate) fn image(path: &Path, source: image::ImageError) -> SeriesError {
        SeriesError::Image {
            path: path.display().to_string(),
            error: source,
        }
    }
}
