//! The window: a CPU framebuffer on X11 (minifb, Xlib loaded at run time; no GPU), its mouse
//! and keys turned into the viewer's [`Input`]s, the same ones `--script` produces.

use minifb::{Key, KeyRepeat, MouseButton, MouseMode, WindowOptions};

use crate::error::ViewError;
use crate::keys::{action, Action};

/// One user input, from the window or a script line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Input {
    /// Orbit by (azimuth, elevation) degrees.
    Orbit(f64, f64),
    /// Pan by (right, up) pixels.
    Pan(f64, f64),
    /// Zoom by a factor.
    Zoom(f64),
    /// A key's action.
    Key(Action),
}

/// Degrees of orbit per pixel dragged (half a turn across a 360-pixel drag).
const DEG_PER_PIXEL: f64 = 0.5;
/// Zoom factor of one wheel notch.
const WHEEL_ZOOM: f64 = 1.1;

/// An open window of fixed size.
pub struct Window {
    win: minifb::Window,
    width: usize,
    height: usize,
    buf: Vec<u32>,
    last_mouse: Option<(f32, f32)>,
}

impl Window {
    /// Opens a `width × height` window (error with what to do when there is no display).
    pub fn open(title: &str, width: u32, height: u32) -> Result<Window, ViewError> {
        let (w, h) = (width as usize, height as usize);
        let mut win = minifb::Window::new(title, w, h, WindowOptions::default()).map_err(|e| {
            ViewError::NoDisplay {
                reason: e.to_string(),
            }
        })?;
        // The render loop sets the pace; minifb must not sleep on its own.
        win.set_target_fps(0);
        Ok(Window {
            win,
            width: w,
            height: h,
            buf: vec![0; w * h],
            last_mouse: None,
        })
    }

    /// Whether the user has not closed it.
    pub fn is_open(&self) -> bool {
        self.win.is_open()
    }

    /// Sets the title bar.
    pub fn set_title(&mut self, title: &str) {
        self.win.set_title(title);
    }

    /// Shows `pixels` (packed RGBA8 as in [`render::Framebuffer`], the window's size) and
    /// collects input.
    pub fn present(&mut self, pixels: &[u32]) -> Result<(), ViewError> {
        for (d, s) in self.buf.iter_mut().zip(pixels) {
            // RGBA8 (r in the low byte) to minifb's 0RGB.
            *d = (s & 0xff) << 16 | (s & 0xff00) | (s >> 16 & 0xff);
        }
        self.win
            .update_with_buffer(&self.buf, self.width, self.height)
            .map_err(|e| ViewError::NoDisplay {
                reason: e.to_string(),
            })
    }

    /// Collects input without presenting (while nothing new is drawn).
    pub fn pump(&mut self) {
        self.win.update();
    }

    /// The inputs since the last call: drags as orbit (left) or pan (right, middle), the
    /// wheel as zoom, keys pressed as actions.
    pub fn inputs(&mut self) -> Vec<Input> {
        let mut out = Vec::new();
        let pos = self.win.get_mouse_pos(MouseMode::Discard);
        let left = self.win.get_mouse_down(MouseButton::Left);
        let pan = self.win.get_mouse_down(MouseButton::Right)
            || self.win.get_mouse_down(MouseButton::Middle);
        match (pos, self.last_mouse) {
            (Some((x, y)), Some((x0, y0))) if left || pan => {
                let (dx, dy) = ((x - x0) as f64, (y - y0) as f64);
                if dx != 0.0 || dy != 0.0 {
                    out.push(if left {
                        // Dragging right turns the scene right: the eye goes left.
                        Input::Orbit(-dx * DEG_PER_PIXEL, dy * DEG_PER_PIXEL)
                    } else {
                        Input::Pan(dx, -dy)
                    });
                }
            }
            _ => {}
        }
        self.last_mouse = if left || pan { pos } else { None };
        if let Some((_, wy)) = self.win.get_scroll_wheel() {
            if wy != 0.0 {
                out.push(Input::Zoom(WHEEL_ZOOM.powf(wy.signum() as f64)));
            }
        }
        let shift = self.win.is_key_down(Key::LeftShift) || self.win.is_key_down(Key::RightShift);
        for k in self.win.get_keys_pressed(KeyRepeat::No) {
            if let Some(a) = key_name(k, shift).and_then(action) {
                out.push(Input::Key(a));
            }
        }
        out
    }
}

/// The viewer's name of a key (see [`crate::keys::KEYS`]).
fn key_name(k: Key, shift: bool) -> Option<&'static str> {
    Some(match k {
        Key::Key1 | Key::NumPad1 => "1",
        Key::Key2 | Key::NumPad2 => "2",
        Key::Key3 | Key::NumPad3 => "3",
        Key::Key4 | Key::NumPad4 => "4",
        Key::V => "v",
        Key::S => "s",
        Key::A => "a",
        Key::L => "l",
        Key::RightBracket => "]",
        Key::LeftBracket => "[",
        Key::R => "r",
        Key::C => "c",
        Key::P => "p",
        Key::Space => "space",
        Key::Right | Key::Period => "right",
        Key::Left | Key::Comma => "left",
        Key::H => "h",
        Key::Slash if shift => "?",
        Key::Q => "q",
        Key::Escape => "escape",
        _ => return None,
    })
}
