//! A colour legend drawn into a finished frame (issue #20): a vertical bar of the colormap
//! from the low value (bottom) to the high value (top), the two values beside it and the
//! column name above, in the public-domain 8×8 bitmap font of the `font8x8` crate.

use font8x8::UnicodeFonts;

use crate::{rgba, Colormap, Framebuffer};
use scene::ColorBy;

/// What a legend shows: a column name and the value range its colormap spans.
#[derive(Clone, Debug, PartialEq)]
pub struct Legend {
    /// Title above the bar (the column name).
    pub title: String,
    /// Value at the bottom of the bar (mapped to colormap 0).
    pub lo: f32,
    /// Value at the top of the bar (mapped to colormap 1).
    pub hi: f32,
    /// The colormap.
    pub colormap: Colormap,
}

impl Legend {
    /// The legend of a model coloured by `color` over `range` (the model's
    /// `color_range`): `None` when it is coloured by element or has no range.
    pub fn of(color: &ColorBy, range: Option<(f32, f32)>) -> Option<Legend> {
        match (color, range) {
            (ColorBy::Column { name, colormap, .. }, Some((lo, hi))) => Some(Legend {
                title: name.clone(),
                lo,
                hi,
                colormap: *colormap,
            }),
            _ => None,
        }
    }
}

/// Where [`draw_legend`] put the legend, in pixels (x right, y down, inclusive-exclusive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LegendBox {
    /// The whole legend, text included.
    pub outer: [u32; 4],
    /// The colour bar only: `[x0, y0, x1, y1]`.
    pub bar: [u32; 4],
}

/// Smallest frame side (pixels) a legend is drawn into.
pub const MIN_LEGEND_FRAME: u32 = 96;

/// The label of a legend value: 4 significant digits, scientific outside `[1e-3, 1e5)`.
pub fn legend_label(v: f32) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        format!("{v:.2e}")
    } else {
        let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        let s = format!("{v:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    }
}

/// Draws `legend` at the right edge of `fb` with text in `ink` (pick a colour that contrasts
/// with the background). The font and bar scale with the frame: one font pixel per 512 rows.
/// Returns where it went, or `None` (nothing drawn) when the frame is smaller than
/// [`MIN_LEGEND_FRAME`] on a side.
pub fn draw_legend(fb: &mut Framebuffer, legend: &Legend, ink: [u8; 3]) -> Option<LegendBox> {
    if fb.width < MIN_LEGEND_FRAME || fb.height < MIN_LEGEND_FRAME {
        return None;
    }
    let s = (fb.height / 512).max(1); // font pixel size
    let glyph = 8 * s;
    let margin = glyph;
    let labels = [legend_label(legend.hi), legend_label(legend.lo)];
    let label_w = labels
        .iter()
        .map(|l| l.chars().count() as u32)
        .max()
        .unwrap_or(0)
        * glyph;
    let bar_w = 2 * glyph;
    let bar_h = fb.height / 2;
    let bar_x1 = fb.width - margin;
    let bar_x0 = bar_x1 - bar_w;
    let bar_y0 = (fb.height - bar_h) / 2;
    let bar_y1 = bar_y0 + bar_h;
    for y in bar_y0..bar_y1 {
        // Top row is `hi`, bottom row `lo`: t runs from 1 down to 0 over the bar.
        let t = (bar_y1 - 1 - y) as f32 / (bar_h - 1).max(1) as f32;
        let [r, g, b] = legend.colormap.map(t);
        fill(fb, [bar_x0, y, bar_x1, y + 1], rgba(r, g, b, 255));
    }
    let ink_px = rgba(ink[0], ink[1], ink[2], 255);
    outline(fb, [bar_x0, bar_y0, bar_x1, bar_y1], ink_px);
    // Values right-aligned left of the bar, level with its ends; the title above it.
    let text_x1 = bar_x0.saturating_sub(glyph / 2);
    let hi_w = labels[0].chars().count() as u32 * glyph;
    let lo_w = labels[1].chars().count() as u32 * glyph;
    text(
        fb,
        &labels[0],
        text_x1.saturating_sub(hi_w),
        bar_y0,
        s,
        ink_px,
    );
    text(
        fb,
        &labels[1],
        text_x1.saturating_sub(lo_w),
        bar_y1 - glyph,
        s,
        ink_px,
    );
    let max_title = (fb.width / 2 / glyph) as usize;
    let title: String = legend.title.chars().take(max_title).collect();
    let title_w = title.chars().count() as u32 * glyph;
    let title_x = (bar_x1.saturating_sub(title_w)).min(bar_x0);
    let title_y = bar_y0.saturating_sub(glyph + glyph / 2);
    text(fb, &title, title_x, title_y, s, ink_px);
    let x0 = title_x.min(text_x1.saturating_sub(label_w));
    Some(LegendBox {
        outer: [x0, title_y, bar_x1, bar_y1],
        bar: [bar_x0, bar_y0, bar_x1, bar_y1],
    })
}

/// Fills `[x0, y0, x1, y1)` (clipped to the frame).
fn fill(fb: &mut Framebuffer, [x0, y0, x1, y1]: [u32; 4], px: u32) {
    let (w, h) = (fb.width, fb.height);
    for y in y0.min(h)..y1.min(h) {
        let row = y as usize * w as usize;
        fb.pixels[row + x0.min(w) as usize..row + x1.min(w) as usize].fill(px);
    }
}

/// A one-pixel frame just outside `[x0, y0, x1, y1)`.
fn outline(fb: &mut Framebuffer, [x0, y0, x1, y1]: [u32; 4], px: u32) {
    let (xa, ya) = (x0.saturating_sub(1), y0.saturating_sub(1));
    fill(fb, [xa, ya, x1 + 1, y0], px);
    fill(fb, [xa, y1, x1 + 1, y1 + 1], px);
    fill(fb, [xa, y0, x0, y1], px);
    fill(fb, [x1, y0, x1 + 1, y1], px);
}

/// Draws `s` in the 8×8 font with its top-left corner at pixel (x, y), each font pixel
/// `scale`² screen pixels, in the packed colour `px`; characters outside the font are drawn as
/// `?`, pixels outside the frame are clipped.
pub fn draw_text(fb: &mut Framebuffer, s: &str, x: u32, y: u32, scale: u32, px: u32) {
    text(fb, s, x, y, scale, px)
}

fn text(fb: &mut Framebuffer, s: &str, x: u32, y: u32, scale: u32, px: u32) {
    for (i, c) in s.chars().enumerate() {
        let rows = font8x8::BASIC_FONTS
            .get(c)
            .or_else(|| font8x8::BASIC_FONTS.get('?'))
            .unwrap_or([0; 8]);
        let cx = x + i as u32 * 8 * scale;
        for (r, bits) in rows.iter().enumerate() {
            for col in 0..8u32 {
                // Bit 0 is the leftmost pixel of a row in this font.
                if bits >> col & 1 == 1 {
                    let (px0, py0) = (cx + col * scale, y + r as u32 * scale);
                    fill(fb, [px0, py0, px0 + scale, py0 + scale], px);
                }
            }
        }
    }
}

impl Legend {
    /// One line for `-v`: the column, the range (as the flag that repeats it) and the colormap.
    pub fn describe(&self) -> String {
        let Legend { title, lo, hi, .. } = self;
        format!(
            "color:   {title} over --color-range {lo}:{hi} ({:?})",
            self.colormap
        )
    }
}
