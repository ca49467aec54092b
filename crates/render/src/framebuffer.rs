//! RGBA8 framebuffer and its output as PNG or JPEG.

use std::path::Path;

/// Errors of image output.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// Writing the image failed.
    #[error("writing {path}: {source}")]
    Png {
        /// The file.
        path: String,
        /// Why.
        source: image::ImageError,
    },
    /// The file name asks for a format that is not written.
    #[error("{0}: unknown image format; name the output .png or .jpg")]
    UnknownFormat(String),
    /// The frame is too large for the PNG encoder or for memory.
    #[error(
        "a {0}x{1} frame needs {mib} MiB, more than can be allocated: make it smaller with --size",
        mib = (u64::from(*.0) * u64::from(*.1) * 4) >> 20
    )]
    TooLarge(u32, u32),
    /// The output exists and overwriting was not asked for.
    #[error("{0} exists; pass --force to overwrite it")]
    Exists(String),
    /// The output's directory does not exist.
    #[error("cannot write {path}: directory {dir} does not exist")]
    NoDirectory {
        /// The output file.
        path: String,
        /// Its missing directory.
        dir: String,
    },
    /// A frame too large to hold whole cannot be made as asked.
    #[error("a {}x{} frame is streamed to its file in bands of rows (over {} MiB whole), so {reason}", size.0, size.1, crate::STREAM_ABOVE_BYTES >> 20)]
    Streamed {
        /// The frame size (pixels).
        size: (u32, u32),
        /// What cannot be done, and the way out.
        reason: String,
    },
    /// The render settings are refused (see [`crate::SettingsError`]).
    #[error(transparent)]
    Settings(#[from] crate::SettingsError),
}

/// An image file format a frame is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// PNG, 8-bit RGBA, lossless.
    Png,
    /// JPEG, 8-bit RGB at quality [`JPEG_QUALITY`] (alpha dropped).
    Jpeg,
}

/// JPEG quality (1-100) of [`Framebuffer::save`].
pub const JPEG_QUALITY: u8 = 95;

impl ImageFormat {
    /// The format `path`'s extension names (`.png`, `.jpg` or `.jpeg`, any case): check it
    /// before rendering, so a long render is not lost to a typo.
    pub fn from_path(path: &Path) -> Result<ImageFormat, RenderError> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        match ext.to_ascii_lowercase().as_str() {
            "png" => Ok(ImageFormat::Png),
            "jpg" | "jpeg" => Ok(ImageFormat::Jpeg),
            _ => Err(RenderError::UnknownFormat(path.display().to_string())),
        }
    }

    /// [`ImageFormat::from_path`], and `path` can be written: its directory exists, and it
    /// does not exist unless `force` (checked before rendering, so nothing the user has is
    /// overwritten unasked and a long render is not lost at the end).
    pub fn for_output(path: &Path, force: bool) -> Result<ImageFormat, RenderError> {
        let format = ImageFormat::from_path(path)?;
        let shown = || path.display().to_string();
        if path.exists() && !force {
            return Err(RenderError::Exists(shown()));
        }
        match path.parent().filter(|d| !d.as_os_str().is_empty()) {
            Some(dir) if !dir.is_dir() => Err(RenderError::NoDirectory {
                path: shown(),
                dir: dir.display().to_string(),
            }),
            _ => Ok(format),
        }
    }
}

/// Row-major RGBA8 pixels, one packed `u32` each (`r | g << 8 | b << 16 | a << 24`, so the
/// bytes in memory are R, G, B, A), top row first. One flat allocation: 16384² is 1 GiB.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Framebuffer {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` packed pixels.
    pub pixels: Vec<u32>,
}

impl Framebuffer {
    /// A frame filled with `color` (packed RGBA8).
    pub fn new(width: u32, height: u32, color: u32) -> Result<Framebuffer, RenderError> {
        let n = (width as usize)
            .checked_mul(height as usize)
            .filter(|&n| n <= isize::MAX as usize / 4)
            .ok_or(RenderError::TooLarge(width, height))?;
        let mut pixels = Vec::new();
        pixels
            .try_reserve_exact(n)
            .map_err(|_| RenderError::TooLarge(width, height))?;
        pixels.resize(n, color);
        Ok(Framebuffer {
            width,
            height,
            pixels,
        })
    }

    /// RGBA bytes of pixel (x, y).
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 4] {
        self.pixels[y as usize * self.width as usize + x as usize].to_le_bytes()
    }

    /// The pixels as R, G, B, A bytes (no copy on little-endian machines).
    pub fn as_bytes(&self) -> std::borrow::Cow<'_, [u8]> {
        crate::streamed::rgba_bytes(&self.pixels)
    }

    /// Writes the frame in the format of `path`'s extension ([`ImageFormat::from_path`]).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), RenderError> {
        let path = path.as_ref();
        match ImageFormat::from_path(path)? {
            ImageFormat::Png => self.save_png(path),
            ImageFormat::Jpeg => self.save_jpeg(path),
        }
    }

    /// Writes an 8-bit RGB JPEG at [`JPEG_QUALITY`] (whatever the extension).
    pub fn save_jpeg(&self, path: impl AsRef<Path>) -> Result<(), RenderError> {
        use std::io::Write;
        let path = path.as_ref();
        let err = |source| RenderError::Png {
            path: path.display().to_string(),
            source,
        };
        let rgb: Vec<u8> = self
            .pixels
            .iter()
            .flat_map(|p| {
                let [r, g, b, _] = p.to_le_bytes();
                [r, g, b]
            })
            .collect();
        let file = std::fs::File::create(path).map_err(|e| err(e.into()))?;
        let mut out = std::io::BufWriter::new(file);
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, JPEG_QUALITY)
            .encode(
                &rgb,
                self.width,
                self.height,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(err)?;
        out.flush().map_err(|e| err(e.into()))
    }

    /// Writes an 8-bit RGBA PNG (whatever the extension).
    pub fn save_png(&self, path: impl AsRef<Path>) -> Result<(), RenderError> {
        let path = path.as_ref();
        let err = |source| RenderError::Png {
            path: path.display().to_string(),
            source,
        };
        image::save_buffer_with_format(
            path,
            &self.as_bytes(),
            self.width,
            self.height,
            image::ExtendedColorType::Rgba8,
            image::ImageFormat::Png,
        )
        .map_err(err)
    }
}
