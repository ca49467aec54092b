//! Text over the picture: the keys, messages, and the screen shown while the first time step
//! is read and built (the window has no picture yet, and a large file takes seconds).

use render::{draw_text, rgba, Framebuffer};

/// Draws `lines` at the top left of `fb` over a band darkened to a quarter, so the picture
/// shows through; 8×8-pixel glyphs, doubled from 1000 pixels wide; clipped to the frame.
pub(crate) fn draw_lines(fb: &mut Framebuffer, lines: &[String]) {
    if lines.is_empty() {
        return;
    }
    let scale = if fb.width >= 1000 { 2 } else { 1 };
    let line_h = 10 * scale;
    let box_h = (lines.len() as u32 * line_h + 8).min(fb.height);
    let bg = rgba(0, 0, 0, 255);
    for y in 0..box_h {
        let row = (y * fb.width) as usize;
        for p in &mut fb.pixels[row..row + fb.width as usize] {
            *p = (*p >> 2 & 0x003f_3f3f) | bg;
        }
    }
    for (i, l) in lines.iter().enumerate() {
        let y = 4 + i as u32 * line_h;
        draw_text(fb, l, 4, y, scale, rgba(255, 255, 255, 255));
    }
}

/// What the window says while its first scene is made: the input's `name`, the time step
/// `frame` (from 0) and the seconds since the viewer started.
pub(crate) fn loading_lines(name: &str, frame: usize, secs: f64) -> Vec<String> {
    vec![
        format!("bnsview: {name}"),
        format!(
            "reading time step {} and building its scene: {secs:.1} s",
            frame + 1
        ),
    ]
}

/// A black `width`×`height` frame with `lines` on it.
pub(crate) fn text_frame(width: u32, height: u32, lines: &[String]) -> Framebuffer {
    let black = rgba(0, 0, 0, 255);
    let mut fb = Framebuffer {
        width,
        height,
        pixels: vec![black; width as usize * height as usize],
    };
    draw_lines(&mut fb, lines);
    fb
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_loading_screen_says_what_is_loading_and_draws_it_top_left_only() {
        let lines = loading_lines("run.lammpstrj", 0, 2.34);
        assert!(lines[0].contains("run.lammpstrj"), "{lines:?}");
        assert!(
            lines[1].contains("time step 1") && lines[1].contains("2.3 s"),
            "{lines:?}"
        );
        assert!(loading_lines("a.xyz", 4, 0.0)[1].contains("time step 5"));
        let fb = text_frame(320, 200, &lines);
        let white = rgba(255, 255, 255, 255);
        let lit: Vec<(u32, u32)> = (0..fb.pixels.len() as u32)
            .filter(|&i| fb.pixels[i as usize] == white)
            .map(|i| (i % 320, i / 320))
            .collect();
        // Two lines of 8-pixel glyphs from (4, 4), 10 pixels apart; the rest stays black.
        assert!(lit.len() > 100, "{} lit pixels", lit.len());
        assert!(lit.iter().all(|&(x, y)| x >= 4 && (4..22).contains(&y)));
        assert!(lit.iter().any(|&(_, y)| y >= 14), "no second line");
        let black = rgba(0, 0, 0, 255);
        assert!(fb.pixels.iter().all(|&p| p == white || p == black));
    }

    #[test]
    fn text_is_clipped_to_windows_smaller_than_a_glyph() {
        for (w, h) in [(1, 1), (3, 40), (40, 3)] {
            let fb = text_frame(w, h, &loading_lines("x", 0, 1.0));
            assert_eq!(fb.pixels.len(), (w * h) as usize);
        }
    }
}
