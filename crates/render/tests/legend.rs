//! The colour legend (issue #20): the bar shows the colormap from the low value at the bottom
//! to the high value at the top, the text is drawn in the ink colour, nothing outside the
//! legend's box changes, and too small a frame is left alone.

use render::{draw_legend, legend_label, rgba, Colormap, Framebuffer, Legend, MIN_LEGEND_FRAME};

const WHITE: u32 = rgba(255, 255, 255, 255);

fn legend() -> Legend {
    Legend {
        title: "q".into(),
        lo: -0.8,
        hi: 0.4,
        colormap: Colormap::Viridis,
    }
}

#[test]
fn the_bar_runs_from_lo_at_the_bottom_to_hi_at_the_top() {
    for (w, h) in [(256, 256), (640, 480), (1024, 1024), (2048, 1200)] {
        let mut fb = Framebuffer::new(w, h, WHITE).unwrap();
        let b = draw_legend(&mut fb, &legend(), [0, 0, 0]).unwrap();
        let [x0, y0, x1, y1] = b.bar;
        assert!(x1 <= w && y1 <= h && x0 < x1 && y0 < y1, "{b:?}");
        let xm = (x0 + x1) / 2;
        let px = |y: u32| {
            let [r, g, b, _] = fb.pixel(xm, y);
            [r, g, b]
        };
        assert_eq!(px(y1 - 1), Colormap::Viridis.map(0.0), "{w}x{h} bottom");
        assert_eq!(px(y0), Colormap::Viridis.map(1.0), "{w}x{h} top");
        // Linear in between: row y shows (y1 - 1 - y) / (bar height - 1).
        let ym = (y0 + y1) / 2;
        let t = (y1 - 1 - ym) as f32 / (y1 - y0 - 1) as f32;
        assert!((t - 0.5).abs() < 0.01, "{t}");
        assert_eq!(px(ym), Colormap::Viridis.map(t), "{w}x{h} middle");
        // Text and outline in the ink colour, inside the legend's box; the rest untouched.
        let [ox0, oy0, ox1, oy1] = b.outer;
        let mut ink = 0;
        for y in 0..h {
            for x in 0..w {
                let p = fb.pixel(x, y);
                let inside = (ox0.saturating_sub(1)..=ox1).contains(&x)
                    && (oy0.saturating_sub(1)..=oy1).contains(&y);
                if !inside {
                    assert_eq!(p, [255; 4], "{w}x{h}: pixel ({x}, {y}) outside {b:?}");
                } else if p == [0, 0, 0, 255] {
                    ink += 1;
                }
            }
        }
        // "0.4", "-0.8", "q" and the outline: well over a hundred font pixels.
        assert!(ink > 100, "{w}x{h}: {ink} ink pixels");
    }
}

#[test]
fn small_frames_get_no_legend() {
    let mut fb = Framebuffer::new(MIN_LEGEND_FRAME - 1, 200, WHITE).unwrap();
    assert!(draw_legend(&mut fb, &legend(), [0, 0, 0]).is_none());
    assert!(fb.pixels.iter().all(|&p| p == WHITE));
}

#[test]
fn labels_have_four_significant_digits() {
    for (v, s) in [
        (0.0, "0"),
        (0.4, "0.4"),
        (-0.8, "-0.8"),
        (1.0, "1"),
        (12.3456, "12.35"),
        (1234.4, "1234"),
        (99999.0, "99999"),
        (1e6, "1.00e6"),
        (-2.5e-5, "-2.50e-5"),
        (0.001234, "0.001234"),
    ] {
        assert_eq!(legend_label(v), s, "{v}");
    }
}
