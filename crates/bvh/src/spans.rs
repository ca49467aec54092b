//! Every sphere a ray passes through, with the stretch of the ray inside it: the query behind
//! grid-free RBF volumes, which sum the Gaussians of the atoms whose support spheres a ray
//! crosses (Knoll et al., "RBF volume ray casting on multicore and many-core CPUs", 2014).

use crate::geometry::PrimRecord;
use crate::tree::Bvh;

/// The part `[t0, t1]` of a ray inside the sphere in leaf slot `slot` (`t` in units of the
/// ray's direction vector).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Span {
    /// Entry parameter.
    pub t0: f32,
    /// Exit parameter.
    pub t1: f32,
    /// Slot in [`Bvh::records`] / [`Bvh::prim_ids`].
    pub slot: u32,
}

/// Relative widening of a chord, so rounding never drops a point the caller's own
/// `d² < r²` test would keep (the caller decides at each point; the span only culls).
const WIDEN: f32 = 1e-4;

/// One span query: the ray `o + t·d` and the range `[t_lo, t_hi]`, checked once, with what
/// both traversals ([`Bvh::sphere_spans`], [`crate::WideBvh::sphere_spans`]) share.
#[derive(Clone, Copy)]
pub(crate) struct SpanQuery {
    pub(crate) o: [f32; 3],
    pub(crate) d: [f32; 3],
    /// `d·d`.
    dd: f32,
    pub(crate) t_lo: f32,
    pub(crate) t_hi: f32,
}

impl SpanQuery {
    /// The query, or `None` when it can list nothing: a zero, NaN or infinite `o` or `d`, or
    /// an empty (or NaN) range.
    pub(crate) fn new(o: [f32; 3], d: [f32; 3], t_lo: f32, t_hi: f32) -> Option<SpanQuery> {
        let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let finite = o.iter().chain(d.iter()).all(|v| v.is_finite());
        (finite && dd > 0.0 && dd.is_finite() && t_lo <= t_hi).then_some(SpanQuery {
            o,
            d,
            dd,
            t_lo,
            t_hi,
        })
    }

    /// Appends the spans of the sphere records in `slots` (sticks skipped) that overlap the
    /// range: a leaf's part of the query.
    #[inline(always)]
    pub(crate) fn leaf(
        &self,
        records: &[PrimRecord],
        slots: std::ops::Range<usize>,
        out: &mut Vec<Span>,
    ) {
        for slot in slots {
            let rec = &records[slot];
            if !rec.is_sphere() {
                continue;
            }
            if let Some((t0, t1)) = chord(self.o, self.d, self.dd, rec.p0, rec.r) {
                if t0 <= self.t_hi && t1 >= self.t_lo {
                    out.push(Span {
                        t0,
                        t1,
                        slot: slot as u32,
                    });
                }
            }
        }
    }
}

impl Bvh {
    /// Appends to `out` every sphere (ball primitive; sticks are skipped) that the ray
    /// `o + t·d` passes through for some `t` in `[t_lo, t_hi]`, with its whole chord (not
    /// clipped to the range, so a caller walking the ray in windows can tell the spheres it
    /// has already met: those entered before the window) widened by 10⁻⁴ of the sphere's
    /// radius each way. `d` need not be unit; `t` is in units of it. Spans come in traversal
    /// order, not sorted. A zero, NaN or infinite `d` or `o`, or an empty range, gives none.
    /// `stack` must hold [`Bvh::stack_size`] entries.
    ///
    /// With `t_lo = t_hi = 0` this lists the spheres that contain the point `o`.
    pub fn sphere_spans(
        &self,
        o: [f32; 3],
        d: [f32; 3],
        t_lo: f32,
        t_hi: f32,
        stack: &mut [u32],
        out: &mut Vec<Span>,
    ) {
        let Some(q) = SpanQuery::new(o, d, t_lo, t_hi).filter(|_| !self.nodes.is_empty()) else {
            return;
        };
        let inv = d.map(|v| 1.0 / v);
        let mut sp = 0usize;
        let mut idx = 0usize;
        loop {
            let node = &self.nodes[idx];
            if slab_overlap(&node.min, &node.max, o, inv, t_lo, t_hi) {
                if node.is_leaf() {
                    let first = node.first as usize;
                    q.leaf(&self.records, first..first + node.count(), out);
                } else {
                    stack[sp] = node.first + 1;
                    sp += 1;
                    idx = node.first as usize;
                    continue;
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            idx = stack[sp] as usize;
        }
    }
}

/// True if the ray meets the box within `[t_lo, t_hi]` (slab test; a NaN from a flat axis
/// through a face is ignored by `max`/`min`, a ray parallel to a slab outside it fails).
#[inline(always)]
fn slab_overlap(
    lo: &[f32; 3],
    hi: &[f32; 3],
    o: [f32; 3],
    inv: [f32; 3],
    t_lo: f32,
    t_hi: f32,
) -> bool {
    let (mut near, mut far) = (t_lo, t_hi);
    for a in 0..3 {
        let (ta, tb) = ((lo[a] - o[a]) * inv[a], (hi[a] - o[a]) * inv[a]);
        near = near.max(ta.min(tb));
        far = far.min(ta.max(tb));
    }
    // Widened like the chords so a sphere touching its leaf's face is never lost.
    near <= far + WIDEN * far.abs().max(1.0)
}

/// The chord `[tc − h, tc + h]` of the ray through the sphere (centre `c`, radius `r`),
/// widened by `WIDEN·r`; `None` if the ray passes outside. Closest approach first, so the
/// perpendicular distance carries no cancellation from a far origin.
#[inline(always)]
fn chord(o: [f32; 3], d: [f32; 3], dd: f32, c: [f32; 3], r: f32) -> Option<(f32, f32)> {
    let oc = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
    let tc = -(oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2]) / dd;
    let p = [oc[0] + tc * d[0], oc[1] + tc * d[1], oc[2] + tc * d[2]];
    let perp2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    let rw = r * (1.0 + WIDEN);
    let h2 = rw * rw - perp2;
    if h2 < 0.0 {
        return None;
    }
    let h = (h2 / dd).sqrt();
    Some((tc - h, tc + h))
}
