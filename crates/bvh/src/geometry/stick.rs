//! Where a stick is drawn (paper §4.1 step 3): with the balls drawn, the part of a bond inside
//! its end balls is never seen from outside them, so the stick's record and box cover the bond
//! trimmed at both ends by the same length — the shorter of the two hidden lengths — which
//! keeps the colour change at the bond's midpoint and tightens the BVH's boxes (ns740k: SAH
//! 349 → 290).

use super::{Geometry, Prim};

/// Fraction of the hidden length trimmed: the last 0.1 % stays, so rounding never opens a gap
/// between a ball and its stick where the stick leaves the ball.
const TRIM: f64 = 0.999;

impl Geometry {
    /// Whether sticks are trimmed to the part outside their end balls: balls drawn and sticks
    /// open (a capped stick's cap would show beyond a ball).
    pub(crate) fn trims_sticks(&self) -> bool {
        self.show_balls && !self.capped
    }

    /// First point (Å), unit axis and length (Å) of stick `j` as drawn: the bond from endpoint
    /// `a` to `b`, trimmed as [`trimmed_stick`] says. A length of 0 means the stick is hidden
    /// whole (or degenerate); NaN axis and length for non-finite endpoints.
    pub(crate) fn stick_segment(&self, j: usize) -> ([f32; 3], [f32; 3], f32) {
        let (ia, ib) = (self.sticks.a[j], self.sticks.b[j]);
        let radius = |i: u32| self.balls.radius.get(i as usize).copied().unwrap_or(0.0);
        let (p, q) = (self.endpoint(ia), self.endpoint(ib));
        let (start, axis, len) = trimmed_stick(
            p,
            q,
            [radius(ia), radius(ib)],
            self.sticks.radius,
            self.trims_sticks(),
        );
        (start, axis.map(|v| v as f32), len as f32)
    }

    /// How far primitive `id` reaches beyond the segment `p0`–`p1` along x, y and z (Å): `r`
    /// for balls and capsules, `r·√(1 − a_k²)` for an open cylinder of unit axis `a`.
    pub(super) fn stick_reach(&self, id: u32, p0: [f32; 3], p1: [f32; 3], r: f32) -> [f32; 3] {
        if self.capped || matches!(self.prim(id), Prim::Ball(_)) {
            return [r; 3];
        }
        let d: [f64; 3] = std::array::from_fn(|k| p1[k] as f64 - p0[k] as f64);
        let len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if !(len2 > 0.0 && len2.is_finite()) {
            return [r; 3];
        }
        d.map(|v| (r as f64 * (1.0 - v * v / len2).max(0.0).sqrt()) as f32)
    }
}

/// A stick of radius `rs` from `p` to `q` as drawn (all Å): its first point, unit axis (f64, as
/// exact as the endpoints allow) and length. With `trim` (balls drawn, sticks open), both ends
/// lose the same length, [`TRIM`] × the shorter of `√(R² − rs²)` over the end balls' radii
/// `ball` (0 for a ball no wider than the stick or an extra end, radius 0): where the cylinder's
/// surface meets a ball, so what is cut lies inside both balls. Zero length and axis for
/// coincident endpoints; NaN axis and length for non-finite ones.
pub(crate) fn trimmed_stick(
    p: [f32; 3],
    q: [f32; 3],
    ball: [f32; 2],
    rs: f32,
    trim: bool,
) -> ([f32; 3], [f64; 3], f64) {
    let d: [f64; 3] = std::array::from_fn(|k| q[k] as f64 - p[k] as f64);
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    if len == 0.0 {
        return (p, [0.0; 3], 0.0);
    }
    if !len.is_finite() {
        return (p, [f64::NAN; 3], f64::NAN);
    }
    let axis = d.map(|v| v / len);
    let rs = rs as f64;
    let hidden = |r: f32| {
        let r = r as f64;
        if trim && r > rs {
            (r * r - rs * rs).sqrt()
        } else {
            0.0
        }
    };
    let cut = (TRIM * hidden(ball[0]).min(hidden(ball[1]))).min(len / 2.0);
    let start = std::array::from_fn(|k| (p[k] as f64 + axis[k] * cut) as f32);
    (start, axis, len - 2.0 * cut)
}
