//! Where a stick is drawn (paper §4.1 step 3): with the balls drawn, the part of a bond inside
//! its end balls is never seen from outside them, so the stick's record and box cover the bond
//! trimmed at both ends by the same length — the shorter of the two hidden lengths — which
//! keeps the colour change at the bond's midpoint and tightens the BVH's boxes (ns740k: SAH
//! 349 → 290).

use super::Geometry;

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

    /// Segment (Å) a box around stick `j` must cover, and how far the stick reaches beyond it
    /// along x, y and z (Å): `r` for a capsule, `r·√(1 − a_k²)` for an open cylinder of unit
    /// axis `a`. In f32 for the builder's speed, the trim 10⁻⁴ shorter than the record's so the
    /// rounding of either stays inside the box. `None`: hidden whole (no box).
    pub(super) fn stick_extent(&self, j: usize) -> Option<([f32; 3], [f32; 3], [f32; 3])> {
        let (ia, ib) = (self.sticks.a[j], self.sticks.b[j]);
        let (p, q, rs) = (self.endpoint(ia), self.endpoint(ib), self.sticks.radius);
        let d: [f32; 3] = std::array::from_fn(|k| q[k] - p[k]);
        let len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if !(len2 > 0.0 && len2.is_finite()) {
            // Degenerate (or non-finite, which the caller rejects): the endpoints' spheres.
            let hidden = self.trims_sticks() && len2 == 0.0;
            return (!hidden).then_some((p, q, [rs; 3]));
        }
        let reach = if self.capped {
            [rs; 3]
        } else {
            d.map(|v| rs * (1.0 - v * v / len2).max(0.0).sqrt())
        };
        let ball = |i: u32| self.balls.radius.get(i as usize).copied().unwrap_or(0.0);
        let rmin = ball(ia).min(ball(ib));
        if !self.trims_sticks() || rmin <= rs {
            return Some((p, q, reach));
        }
        let len = len2.sqrt();
        let cut = (TRIM * (1.0 - 1e-4)) as f32 * (rmin * rmin - rs * rs).sqrt();
        if 2.0 * cut >= len {
            return None;
        }
        let f = cut / len;
        let start = std::array::from_fn(|k| p[k] + d[k] * f);
        let end = std::array::from_fn(|k| q[k] - d[k] * f);
        Some((start, end, reach))
    }
}

/// A stick of radius `rs` from `p` to `q` as drawn (all Å): its first point, unit axis (f64, as
/// exact as the endpoints allow) and length. With `trim` (balls drawn, sticks open), both ends
/// lose the same length, [`TRIM`] × the shorter of `√(R² − rs²)` over the end balls' radii
/// `ball` (0 for a ball no wider than the stick or an extra end, radius 0): where the cylinder's
/// surface meets a ball, so what is cut lies inside both balls. Zero length and axis for
/// coincident endpoints; NaN axis and length for non-finite ones.
#[inline]
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
    // The smaller ball hides less: √(R² − rs²) grows with R.
    let (rs, rmin) = (rs as f64, ball[0].min(ball[1]) as f64);
    let hidden = if trim && rmin > rs {
        (rmin * rmin - rs * rs).sqrt()
    } else {
        0.0
    };
    let cut = (TRIM * hidden).min(len / 2.0);
    let start = std::array::from_fn(|k| (p[k] as f64 + axis[k] * cut) as f32);
    (start, axis, len - 2.0 * cut)
}
