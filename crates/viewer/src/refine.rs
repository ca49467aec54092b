//! Progressive refinement of the picture on screen: while the camera moves, frames at 2× or
//! 4× fewer pixels per side (chosen so a preview takes about 1/30 s); when it stops, the full
//! frame — exactly `render_frame`'s, as `bnsview render` makes it — and for path tracing one
//! more sample per pixel per pass until `--spp`.

use std::collections::HashMap;
use std::time::Instant;

use render::{accumulate, render_frame, Accum, FrameInputs, Framebuffer, RenderSettings};
use spmd::Isa;

use crate::error::ViewError;

/// Target time of a preview frame (s).
const PREVIEW_S: f64 = 1.0 / 30.0;

/// What one refinement step drew.
#[derive(Clone, Copy, Debug)]
pub struct Step {
    /// Pixels per side of a rendered pixel (1: full resolution).
    pub scale: u32,
    /// Samples per pixel in the picture now (1 for the one-pass modes).
    pub samples: u32,
    /// Seconds spent rendering.
    pub render_s: f64,
}

/// The picture on screen and how far it is refined.
pub struct Refiner {
    width: u32,
    height: u32,
    /// The picture on screen (window size, packed RGBA8).
    pub shown: Vec<u32>,
    /// The last full-resolution frame (valid when `done` and not progressive).
    full: Option<Framebuffer>,
    accum: Option<Accum>,
    /// Whether the picture is as refined as it gets for this view.
    pub done: bool,
    /// Seconds of the last full-resolution pass (one sample for path tracing) of each kind
    /// of frame (see [`Refiner::set_kind`]).
    full_s: HashMap<String, f64>,
    /// What is being drawn (the render flags), to look up its cost.
    kind: String,
}

impl Refiner {
    /// A refiner for a `width × height` window.
    pub fn new(width: u32, height: u32) -> Refiner {
        Refiner {
            width,
            height,
            shown: vec![0xff00_0000; width as usize * height as usize],
            full: None,
            accum: None,
            done: false,
            full_s: HashMap::new(),
            kind: String::new(),
        }
    }

    /// Something changed (camera, settings or scene): refine from the start.
    pub fn invalidate(&mut self) {
        self.done = false;
        self.full = None;
        self.accum = None;
    }

    /// What is drawn from now on (e.g. the render flags): previews are sized by the last
    /// full frame of the same kind.
    pub fn set_kind(&mut self, kind: String) {
        self.kind = kind;
    }

    /// The preview scale for the last full frame's time: 1, 2 or 4.
    fn preview_scale(&self) -> u32 {
        match self.full_s.get(&self.kind).copied() {
            Some(t) if t <= PREVIEW_S => 1,
            Some(t) if t / 4.0 <= PREVIEW_S => 2,
            // Unknown cost (a mode not drawn yet): the cheapest preview.
            Some(_) | None => 4,
        }
    }

    /// Renders the next step: a preview while `moving`, else the next refinement; `None`
    /// when the picture is done.
    pub fn step(
        &mut self,
        inp: &FrameInputs,
        rs: &RenderSettings,
        isa: Isa,
        moving: bool,
    ) -> Result<Option<Step>, ViewError> {
        let path = rs.is_linear();
        let scale = if moving { self.preview_scale() } else { 1 };
        if scale > 1 {
            let (w, h) = (self.width.div_ceil(scale), self.height.div_ceil(scale));
            let t = Instant::now();
            let one = RenderSettings { spp: 1, ..*rs };
            let mut fb = Framebuffer::new(w, h, rs.background_packed())?;
            render_frame(inp, &one, &mut fb, isa).map_err(settings)?;
            self.upscale(&fb, scale);
            self.invalidate();
            return Ok(Some(Step {
                scale,
                samples: 1,
                render_s: t.elapsed().as_secs_f64(),
            }));
        }
        if self.done && !moving {
            return Ok(None);
        }
        let t = Instant::now();
        if path {
            if moving || self.accum.is_none() {
                self.accum = Some(Accum::new(self.width, self.height)?);
            }
            let acc = self.accum.as_mut().expect("made above");
            accumulate(inp, rs, acc, 1, isa).map_err(settings)?;
            self.shown = acc.to_framebuffer(true, rs.exposure).pixels;
            let render_s = t.elapsed().as_secs_f64();
            self.full_s.insert(self.kind.clone(), render_s);
            self.done = acc.samples >= rs.spp;
            return Ok(Some(Step {
                scale: 1,
                samples: acc.samples,
                render_s,
            }));
        }
        let fb = self.render_full(inp, rs, isa)?;
        let render_s = t.elapsed().as_secs_f64();
        self.full_s.insert(self.kind.clone(), render_s);
        self.shown.copy_from_slice(&fb.pixels);
        self.full = Some(fb);
        self.done = true;
        Ok(Some(Step {
            scale: 1,
            samples: 1,
            render_s,
        }))
    }

    /// The frame `bnsview render` makes of this view, bit for bit: the refined picture when
    /// it is one, else rendered now (path tracing: all `--spp` samples in one pass).
    pub fn screenshot(
        &mut self,
        inp: &FrameInputs,
        rs: &RenderSettings,
        isa: Isa,
    ) -> Result<Framebuffer, ViewError> {
        match &self.full {
            Some(fb) if self.done => Ok(fb.clone()),
            _ => self.render_full(inp, rs, isa),
        }
    }

    fn render_full(
        &self,
        inp: &FrameInputs,
        rs: &RenderSettings,
        isa: Isa,
    ) -> Result<Framebuffer, ViewError> {
        let mut fb = Framebuffer::new(self.width, self.height, rs.background_packed())?;
        render_frame(inp, rs, &mut fb, isa).map_err(settings)?;
        Ok(fb)
    }

    /// Nearest-neighbour enlargement of a preview into the picture on screen.
    fn upscale(&mut self, fb: &Framebuffer, scale: u32) {
        let (w, s) = (self.width as usize, scale as usize);
        for (y, row) in self.shown.chunks_mut(w).enumerate() {
            let src = &fb.pixels[(y / s) * fb.width as usize..];
            for (x, px) in row.iter_mut().enumerate() {
                *px = src[x / s];
            }
        }
    }
}

fn settings(e: render::SettingsError) -> ViewError {
    ViewError::Settings(e.to_string())
}
