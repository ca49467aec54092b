//! Colormaps for colouring atoms by a per-atom scalar.

/// A colormap from `[0, 1]` to RGB.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Colormap {
    /// matplotlib's viridis (9 stops, linearly interpolated).
    Viridis,
    /// Black to white.
    #[cfg_attr(feature = "clap", value(alias = "grey"))]
    Gray,
}

const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// Viridis at `v` (clamped to `[0, 1]`; NaN maps to 0).
pub fn viridis(v: f32) -> [u8; 3] {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let x = v * (VIRIDIS.len() - 1) as f32;
    let i = (x as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f32;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |k: usize| (a[k] as f32 + (b[k] as f32 - a[k] as f32) * f + 0.5) as u8;
    [mix(0), mix(1), mix(2)]
}

impl Colormap {
    /// Colour at `v` in `[0, 1]` (clamped).
    pub fn map(self, v: f32) -> [u8; 3] {
        match self {
            Colormap::Viridis => viridis(v),
            Colormap::Gray => {
                let g = (if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) } * 255.0 + 0.5) as u8;
                [g, g, g]
            }
        }
    }
}
