//! Tiles, pixel blocks and the ball-and-stick shading kernel (paper §4.2 `renderTile`).

use std::time::{Duration, Instant};

use bvh::{surface, RayPacket};
use rayon::prelude::*;
use spmd::{Isa, Kernel, Simd, V3};
use volume::VolumeScene;

use crate::framebuffer::{Framebuffer, RenderError};
use scene::{Camera, Model, Projection};

/// Tile edge in pixels (tiles are the rayon tasks).
pub const TILE: usize = 16;

/// Shading options of the `b&s` mode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Background colour, packed RGBA8 (see [`crate::rgba`]).
    pub background: u32,
    /// Ambient term of the headlight shading: colour × (ambient + (1 − ambient)·|n·v|).
    pub ambient: f32,
    /// SIMD registers per ray packet (1, 2 or 4; 0 = the measured default per ISA).
    pub packet_registers: usize,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            background: crate::rgba(255, 255, 255, 255),
            ambient: 0.15,
            packet_registers: 0,
        }
    }
}

/// What a render did.
#[derive(Clone, Copy, Debug)]
pub struct RenderStats {
    /// Backend used.
    pub isa: Isa,
    /// Wall time of the frame (tiles only, the framebuffer already allocated).
    pub time: Duration,
    /// Primary rays cast (one per pixel).
    pub rays: u64,
}

impl RenderStats {
    /// Million rays per second.
    pub fn mrays_per_s(&self) -> f64 {
        self.rays as f64 / self.time.as_secs_f64().max(1e-12) * 1e-6
    }
    /// Frames per second.
    pub fn fps(&self) -> f64 {
        1.0 / self.time.as_secs_f64().max(1e-12)
    }
}

/// Renders `scene` as seen by `camera` into a new `width × height` frame: one primary ray per
/// pixel, headlight diffuse shading. `isa` must be supported (see [`Isa::select`]).
pub fn render_bs(
    scene: &Model,
    camera: &Camera,
    width: u32,
    height: u32,
    opt: &RenderOptions,
    isa: Isa,
) -> Result<(Framebuffer, RenderStats), RenderError> {
    let mut fb = Framebuffer::new(width, height, opt.background)?;
    let stats = render_bs_into(scene, camera, &mut fb, opt, isa);
    Ok((fb, stats))
}

/// As [`render_bs_into`], with the passes of paper §4.2 chosen by what is given: the opaque
/// ball-and-stick pass when `scene` is `Some`, then the volume pass when `volume` is `Some`,
/// marched from the eye up to the opaque hit and composited in front of it
/// (`volume` alone: the paper's "volume" mode; both: "vol+b&s").
pub fn render_frame_into(
    scene: Option<&Model>,
    volume: Option<&VolumeScene>,
    camera: &Camera,
    fb: &mut Framebuffer,
    opt: &RenderOptions,
    isa: Isa,
) -> RenderStats {
    render_tiles(scene, volume, camera, fb, opt, isa)
}

/// As [`render_bs`] into an existing frame (reuse it across frames).
pub fn render_bs_into(
    scene: &Model,
    camera: &Camera,
    fb: &mut Framebuffer,
    opt: &RenderOptions,
    isa: Isa,
) -> RenderStats {
    render_tiles(Some(scene), None, camera, fb, opt, isa)
}

/// The tile loop shared by every mode.
fn render_tiles(
    scene: Option<&Model>,
    volume: Option<&VolumeScene>,
    camera: &Camera,
    fb: &mut Framebuffer,
    opt: &RenderOptions,
    isa: Isa,
) -> RenderStats {
    let start = Instant::now();
    let (w, h) = (fb.width as usize, fb.height as usize);
    let view = ViewRays::new(camera, w, h);
    let ntx = w.div_ceil(TILE);
    if w > 0 && h > 0 {
        fb.pixels
            .par_chunks_mut(TILE * w)
            .enumerate()
            .for_each(|(ty, band)| {
                // Each tile is a rayon task rendering into its own 16×16 buffer, then copied
                // into the band (rows of the frame are not contiguous per tile).
                let tiles: Vec<[u32; TILE * TILE]> = (0..ntx)
                    .into_par_iter()
                    .map(|tx| {
                        let mut out = [0u32; TILE * TILE];
                        isa.dispatch(TileKernel {
                            scene,
                            volume,
                            view: &view,
                            opt,
                            x0: tx * TILE,
                            y0: ty * TILE,
                            out: &mut out,
                        });
                        out
                    })
                    .collect();
                let rows = band.len() / w;
                for (tx, tile) in tiles.iter().enumerate() {
                    let x0 = tx * TILE;
                    let cols = TILE.min(w - x0);
                    for r in 0..rows {
                        band[r * w + x0..r * w + x0 + cols]
                            .copy_from_slice(&tile[r * TILE..r * TILE + cols]);
                    }
                }
            });
    }
    RenderStats {
        isa,
        time: start.elapsed(),
        rays: (w * h) as u64,
    }
}

/// Camera precomputed for a frame: ray of pixel (px, py) (pixel centres at +0.5) is
/// `o = org + du·px + dv·py` (orthographic) or `d = normalize(dir0 + du·px + dv·py)`.
pub(crate) struct ViewRays {
    pub(crate) perspective: bool,
    pub(crate) org: [f32; 3],
    pub(crate) dir0: [f32; 3],
    pub(crate) du: [f32; 3],
    pub(crate) dv: [f32; 3],
    pub(crate) width: f32,
    pub(crate) height: f32,
}

impl ViewRays {
    pub(crate) fn new(c: &Camera, w: usize, h: usize) -> ViewRays {
        let (wf, hf) = (w.max(1) as f64, h.max(1) as f64);
        let v = |a: [f32; 3], k: f64| [a[0] as f64 * k, a[1] as f64 * k, a[2] as f64 * k];
        let add = |a: [f64; 3], b: [f64; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
        let f32x3 = |a: [f64; 3]| [a[0] as f32, a[1] as f32, a[2] as f32];
        match c.projection {
            Projection::Perspective { fov_y_deg } => {
                let ty = ((fov_y_deg as f64).to_radians() * 0.5).tan();
                let tx = ty * wf / hf;
                // Top-left corner direction, then per-pixel steps.
                let corner = add(add(v(c.forward, 1.0), v(c.right, -tx)), v(c.up, ty));
                ViewRays {
                    perspective: true,
                    org: c.eye,
                    dir0: f32x3(corner),
                    du: f32x3(v(c.right, 2.0 * tx / wf)),
                    dv: f32x3(v(c.up, -2.0 * ty / hf)),
                    width: w as f32,
                    height: h as f32,
                }
            }
            Projection::Orthographic { height } => {
                let hh = height as f64 * 0.5;
                let hw = hh * wf / hf;
                let corner = add(add(v(c.eye, 1.0), v(c.right, -hw)), v(c.up, hh));
                ViewRays {
                    perspective: false,
                    org: f32x3(corner),
                    dir0: c.forward,
                    du: f32x3(v(c.right, 2.0 * hw / wf)),
                    dv: f32x3(v(c.up, -2.0 * hh / hf)),
                    width: w as f32,
                    height: h as f32,
                }
            }
        }
    }
}

struct TileKernel<'a> {
    scene: Option<&'a Model>,
    volume: Option<&'a VolumeScene<'a>>,
    view: &'a ViewRays,
    opt: &'a RenderOptions,
    x0: usize,
    y0: usize,
    out: &'a mut [u32; TILE * TILE],
}

/// Pixel block of a packet: `bw × bh = LANES`, as square as possible.
pub(crate) const fn block_width(lanes: usize) -> usize {
    match lanes {
        1 => 1,
        4 => 2,
        8 => 4,
        16 => 4,
        _ => 1,
    }
}

impl Kernel for TileKernel<'_> {
    type Output = ();
    #[inline(always)]
    fn run<S: Simd>(mut self, s: S) {
        match self.opt.packet_registers {
            2 => render_tile::<S, 2>(s, &mut self),
            4 => render_tile::<S, 4>(s, &mut self),
            1 => render_tile::<S, 1>(s, &mut self),
            // Default from measurements (1024², 500K-atom random molecule, 1 thread, min of 7
            // interleaved frames, far / close, Mrays/s for 1 / 2 / 4 registers):
            //   scalar  2.96 / 3.27 / 4.11   1.59 / 1.51 / 2.23   -> 4 registers
            //   sse4.1  6.76 / 6.17 / 6.52   4.32 / 4.41 / 4.30   -> 1 (no clear gain)
            //   avx2    9.02 / 8.12 / 8.41   8.05 / 6.85 / 6.90   -> 1
            //   avx512 10.58 /10.04 /10.00   9.70 / 9.12 / 8.56   -> 1
            // Wider packets lose more to divergence than they save in traversal overhead.
            _ => {
                if S::LANES == 1 {
                    render_tile::<S, 4>(s, &mut self)
                } else {
                    render_tile::<S, 1>(s, &mut self)
                }
            }
        }
    }
}

/// Renders one 16×16 tile (§4.2 `renderTile`): groups of `N` pixel blocks of `LANES` primary
/// rays each, traced as one packet (§4.3), shaded with a headlight (§4.5 "b&s").
#[inline(always)]
fn render_tile<S: Simd, const N: usize>(s: S, k: &mut TileKernel<'_>) {
    let v = k.view;
    let mut stack = vec![0u32; k.scene.map_or(0, |sc| sc.bvh.stack_size())];
    // One register covers bw × bh pixels; N registers a gw × gh grid of those.
    let bw = block_width(S::LANES);
    let bh = S::LANES / bw;
    let (mut gw, mut gh) = (N, 1);
    for cand in [1, 2, 4] {
        let (w, h) = (cand, N / cand);
        if cand <= N && w * h == N && (w * bw).abs_diff(h * bh) < (gw * bw).abs_diff(gh * bh) {
            (gw, gh) = (w, h);
        }
    }
    let mut lx = [0.0f32; spmd::MAX_LANES];
    let mut ly = [0.0f32; spmd::MAX_LANES];
    for i in 0..S::LANES {
        lx[i] = (i % bw) as f32 + 0.5;
        ly[i] = (i / bw) as f32 + 0.5;
    }
    let (lx, ly) = (s.load(&lx), s.load(&ly));
    let zero = s.splat(0.0);
    let bg = s.splat_i(k.opt.background as i32);
    let du = V3::splat(s, v.du);
    let dv = V3::splat(s, v.dv);
    let mut px_buf = [0i32; spmd::MAX_LANES];
    let mut rays = [RayPacket {
        o: V3::splat(s, [0.0; 3]),
        d: V3::splat(s, [0.0; 3]),
        tmin: zero,
        tmax: zero,
        active: s.splat_m(false),
    }; N];
    let mut offs = [(0usize, 0usize); N];
    for gy in (0..TILE).step_by(bh * gh) {
        for gx in (0..TILE).step_by(bw * gw) {
            let mut any = false;
            for j in 0..N {
                let (bx, by) = (gx + (j % gw) * bw, gy + (j / gw) * bh);
                offs[j] = (bx, by);
                let px = lx + s.splat((k.x0 + bx) as f32);
                let py = ly + s.splat((k.y0 + by) as f32);
                let active = s.lt(px, s.splat(v.width)) & s.lt(py, s.splat(v.height));
                any |= s.any(active);
                let step = du.scale(px) + dv.scale(py);
                let (o, d) = if v.perspective {
                    (
                        V3::splat(s, v.org),
                        (V3::splat(s, v.dir0) + step).normalize(s),
                    )
                } else {
                    (V3::splat(s, v.org) + step, V3::splat(s, v.dir0))
                };
                rays[j] = RayPacket {
                    o,
                    d,
                    tmin: zero,
                    tmax: s.splat(f32::INFINITY),
                    active,
                };
            }
            if !any {
                continue;
            }
            // Pass 1 (§4.2): opaque geometry, shaded; the hit depth bounds the volume pass.
            // (No closure here: closures do not inherit the entry point's target features.)
            #[allow(clippy::manual_map)]
            let hits = match k.scene {
                Some(sc) => Some(sc.bvh.traverse_packets::<S, N>(s, &rays, &mut stack)),
                None => None,
            };
            for j in 0..N {
                let ray = &rays[j];
                let (color, depth) = match (k.scene, &hits) {
                    (Some(sc), Some(hits)) => shade_bs(s, sc, k.opt, ray, &hits[j], bg),
                    _ => (bg, s.splat(f32::INFINITY)),
                };
                // Pass 2 (§4.2, §4.4): the volume in front of the opaque hit, composited over it.
                let color = match k.volume {
                    Some(vs) => {
                        let c = volume::march(s, vs, ray.o, ray.d, depth, ray.active);
                        s.select_i(ray.active, over(s, c, color), color)
                    }
                    None => color,
                };
                s.store_i(color, &mut px_buf);
                let (bx, by) = offs[j];
                for (i, p) in px_buf.iter().enumerate().take(S::LANES) {
                    let (x, y) = (bx + i % bw, by + i / bw);
                    k.out[y * TILE + x] = *p as u32;
                }
            }
        }
    }
}

/// Headlight-shaded colour of the b&s hits of one packet (background where missed) and the
/// hit depth (+inf where missed).
#[inline(always)]
fn shade_bs<S: Simd>(
    s: S,
    scene: &Model,
    opt: &RenderOptions,
    ray: &RayPacket<S>,
    hit: &bvh::PacketHit<S>,
    bg: S::I32,
) -> (S::I32, S::F32) {
    let bvh = &scene.bvh;
    let m = hit.hit_mask(s) & ray.active;
    if s.none(m) {
        return (bg, s.splat(f32::INFINITY));
    }
    let srf = surface(s, &bvh.records, ray.o, ray.d, hit.t, hit.slot, m);
    let zi = s.splat_i(0);
    let ca = s.gather_i(&scene.slot_color_a, hit.slot, m, zi);
    let cb = s.gather_i(&scene.slot_color_b, hit.slot, m, zi);
    let c = s.select_i(srf.second_half, cb, ca);
    // Headlight: the light is at the eye, so the cosine is |n·d|.
    let ambient = s.splat(opt.ambient);
    let shade = ambient + s.splat(1.0 - opt.ambient) * s.abs(srf.n.dot(ray.d));
    let rgb = channel(s, c, 0, shade)
        | channel(s, c, 8, shade)
        | channel(s, c, 16, shade)
        | s.splat_i(0xff << 24);
    (
        s.select_i(m, rgb, bg),
        s.select(m, hit.t, s.splat(f32::INFINITY)),
    )
}

/// Premultiplied volume colour `c` (`[r, g, b, a]` in [0, 1]) over packed opaque colours
/// `under`: `c·255 + (1 − a)·under` per channel, rounded; alpha 255.
#[inline(always)]
fn over<S: Simd>(s: S, c: [S::F32; 4], under: S::I32) -> S::I32 {
    let t = s.splat(1.0) - c[3];
    let mut out = s.splat_i(0xff << 24);
    for (ch, shift) in [(0usize, 0u32), (1, 8), (2, 16)] {
        let u = s.to_f32(s.shr(under, shift) & s.splat_i(255));
        let v = s.fma(c[ch], s.splat(255.0), u * t) + s.splat(0.5);
        let v = s.min(s.max(v, s.splat(0.0)), s.splat(255.0));
        out = out | s.shl(s.to_i32(v), shift);
    }
    out
}

/// One 8-bit channel of packed colours `c` at bit `shift`, scaled by `shade` and rounded.
/// (A function, not a closure: closures would not inherit the entry point's target features.)
#[inline(always)]
fn channel<S: Simd>(s: S, c: S::I32, shift: u32, shade: S::F32) -> S::I32 {
    let k = s.to_f32(s.shr(c, shift) & s.splat_i(255));
    let v = s.min(
        s.max(k * shade + s.splat(0.5), s.splat(0.0)),
        s.splat(255.0),
    );
    s.shl(s.to_i32(v), shift)
}
