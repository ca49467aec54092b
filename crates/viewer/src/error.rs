//! Errors of the viewer.

use std::path::PathBuf;

/// What stops the viewer.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// No window can be opened (no X display).
    #[error("cannot open a window ({reason}): no X display. Set DISPLAY (ssh -X, or a desktop session), or run headless under Xvfb: `xvfb-run -a bnsview view …` with a --script")]
    NoDisplay {
        /// What the window system said.
        reason: String,
    },
    /// A script line that is not a command.
    #[error("{}:{line}: {text:?}: expected {expected}", path.display())]
    Script {
        /// The script.
        path: PathBuf,
        /// Line number (1-based).
        line: usize,
        /// The line.
        text: String,
        /// What a line can be.
        expected: String,
    },
    /// A file could not be read or written.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        error: std::io::Error,
    },
    /// A screenshot would overwrite a file.
    #[error("{}: exists; the screenshot was not written (pass --force to overwrite)", path.display())]
    Exists {
        /// The file.
        path: PathBuf,
    },
    /// The first frame could not be read or built.
    #[error("{0}")]
    Scene(String),
    /// The settings of the command line cannot be rendered.
    #[error("{0}")]
    Settings(String),
    /// Rendering or saving failed.
    #[error(transparent)]
    Render(#[from] render::RenderError),
    /// A script step could not be done.
    #[error("--script: {0}")]
    ScriptStep(String),
}
