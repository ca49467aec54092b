//! volume (under construction)
