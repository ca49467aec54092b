//! Camera rays of a frame (paper §4.2): the one generator of primary rays of every modality.

use bvh::{Corners, Origin, RayPacket};
use scene::{Camera, Projection};
use spmd::{Simd, V3};

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

impl ViewRays {
    /// Camera rays through the frame points `(px, py)` (pixels; centres at +0.5) of lanes
    /// `active`, over `(0, ∞)`.
    #[inline(always)]
    pub(crate) fn rays<S: Simd>(&self, s: S, px: S::F32, py: S::F32, active: S::M) -> RayPacket<S> {
        let step = V3::splat(s, self.du).scale(px) + V3::splat(s, self.dv).scale(py);
        let (o, d) = if self.perspective {
            (
                V3::splat(s, self.org),
                (V3::splat(s, self.dir0) + step).normalize(s),
            )
        } else {
            (V3::splat(s, self.org) + step, V3::splat(s, self.dir0))
        };
        RayPacket {
            o,
            d,
            tmin: s.splat(0.0),
            tmax: s.splat(f32::INFINITY),
            active,
        }
    }

    /// The rays through the corners of the pixel rectangle `[x0, x1] × [y0, y1]` (pixel
    /// edges, so the rays through its pixel centres lie strictly inside), in f64.
    pub(crate) fn corners(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> Corners {
        let f = |a: [f32; 3]| [a[0] as f64, a[1] as f64, a[2] as f64];
        let (org, dir0, du, dv) = (f(self.org), f(self.dir0), f(self.du), f(self.dv));
        let at = |px: f64, py: f64| -> ([f64; 3], [f64; 3]) {
            let step = [0, 1, 2].map(|a| du[a] * px + dv[a] * py);
            if self.perspective {
                (org, [0, 1, 2].map(|a| dir0[a] + step[a]))
            } else {
                ([0, 1, 2].map(|a| org[a] + step[a]), dir0)
            }
        };
        let c = [at(x0, y0), at(x1, y0), at(x1, y1), at(x0, y1)];
        Corners {
            o: c.map(|r| r.0),
            d: c.map(|r| r.1),
        }
    }

    /// Where the camera rays start, for [`bvh::Frusta`].
    pub(crate) fn origin(&self) -> Origin {
        if self.perspective {
            Origin::Point(self.org)
        } else {
            Origin::Plane {
                org: self.org,
                forward: self.dir0,
            }
        }
    }

    /// The (unnormalised) direction of the ray through frame point `(px, py)`.
    pub(crate) fn direction(&self, px: f32, py: f32) -> [f32; 3] {
        let step = [0, 1, 2].map(|a| self.du[a] * px + self.dv[a] * py);
        if self.perspective {
            [0, 1, 2].map(|a| self.dir0[a] + step[a])
        } else {
            self.dir0
        }
    }

    /// Lanes of `(px, py)` inside the frame.
    #[inline(always)]
    pub(crate) fn inside<S: Simd>(&self, s: S, px: S::F32, py: S::F32) -> S::M {
        s.lt(px, s.splat(self.width)) & s.lt(py, s.splat(self.height))
    }
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
