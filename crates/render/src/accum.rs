//! Progressive f32 accumulation of samples and its tone mapping to a [`Framebuffer`].

use rayon::prelude::*;

use crate::framebuffer::{Framebuffer, RenderError};

/// A progressive f32 accumulation buffer: per pixel the sum of the RGB samples so far.
#[derive(Clone, Debug)]
pub struct Accum {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `3 × width × height` sums, row major, top row first.
    pub rgb: Vec<f32>,
    /// Samples per pixel accumulated so far.
    pub samples: u32,
}

impl Accum {
    /// An empty buffer.
    pub fn new(width: u32, height: u32) -> Result<Accum, RenderError> {
        let n = (width as usize)
            .checked_mul(height as usize)
            .and_then(|n| n.checked_mul(3))
            .filter(|&n| n <= isize::MAX as usize / 4)
            .ok_or(RenderError::TooLarge(width, height))?;
        let mut rgb = Vec::new();
        rgb.try_reserve_exact(n)
            .map_err(|_| RenderError::TooLarge(width, height))?;
        rgb.resize(n, 0.0);
        Ok(Accum {
            width,
            height,
            rgb,
            samples: 0,
        })
    }

    /// Mean of the samples of pixel (x, y).
    pub fn mean(&self, x: u32, y: u32) -> [f32; 3] {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        let k = 1.0 / self.samples.max(1) as f32;
        [self.rgb[i] * k, self.rgb[i + 1] * k, self.rgb[i + 2] * k]
    }

    /// The picture: for path tracing (`linear`) exposure, clamp and gamma 2; otherwise the
    /// means are display values, clamped.
    pub fn to_framebuffer(&self, linear: bool, exposure: f32) -> Framebuffer {
        let k = 1.0 / self.samples.max(1) as f32;
        let pixels = self
            .rgb
            .par_chunks(3)
            .map(|c| tone(c, k, linear, exposure))
            .collect();
        Framebuffer {
            width: self.width,
            height: self.height,
            pixels,
        }
    }
}

/// The display pixel of the RGB sums `c` of `1/k` samples: for path tracing (`linear`)
/// exposure, clamp and gamma 2; otherwise the means are display values, clamped. Packed RGBA8.
#[inline]
pub(crate) fn tone(c: &[f32], k: f32, linear: bool, exposure: f32) -> u32 {
    let mut out = 0xff00_0000u32;
    for (ch, v) in c.iter().enumerate() {
        let mut x = v * k;
        if linear {
            x = (x * exposure).clamp(0.0, 1.0).sqrt();
        }
        let b = (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u32;
        out |= b << (8 * ch);
    }
    out
}
