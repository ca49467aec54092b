//! The interactive viewer of bnsview (paper §5: exploring the data at interactive rates): a
//! window on a CPU framebuffer, turntable navigation with the mouse, keys that switch the
//! mode and the lighting, progressive refinement (previews while moving, the full frame and
//! more path samples while still), time steps read and built in the background, and
//! `--script` files that drive the same event code headless.
//!
//! Units: positions in Ångström (Å); angles in degrees; sizes in pixels.
#![warn(missing_docs)]

mod app;
mod error;
mod fit;
mod keys;
mod loader;
mod nav;
mod overlay;
mod refine;
pub mod script;
mod window;

pub use app::{run, Configure, ViewConfig, ViewReport};
pub use error::ViewError;
pub use keys::{action, help_lines, next_mode, toggle, Action, Toggles, KEYS};
pub use loader::{Answer, FrameSource, Loader, Request};
pub use nav::Navigation;
pub use refine::{Refiner, Step};
pub use window::{Input, Window};
