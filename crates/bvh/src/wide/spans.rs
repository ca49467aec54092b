//! [`Bvh::sphere_spans`] through the 8-wide tree: each node's child boxes against the ray in
//! one SIMD op, children in any order (every sphere in the range is wanted, not the nearest).

use spmd::{Simd, V3};

use super::WideBvh;
use crate::spans::{chord, Span};
use crate::traverse::{slab_test, BOX_GROW};
use crate::tree::Bvh;

impl WideBvh {
    /// As [`Bvh::sphere_spans`] (same spans, in another order) for the tree `bvh` this was
    /// collapsed from. `stack` must hold [`WideBvh::spans_stack_size`] entries.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn sphere_spans<S: Simd>(
        &self,
        s: S,
        bvh: &Bvh,
        o: [f32; 3],
        d: [f32; 3],
        t_lo: f32,
        t_hi: f32,
        stack: &mut [u32],
        out: &mut Vec<Span>,
    ) {
        assert_eq!(self.records, bvh.records.len(), "wide BVH of another tree");
        let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let finite = o.iter().chain(d.iter()).all(|v| v.is_finite());
        if !(finite && dd > 0.0 && dd.is_finite() && t_lo <= t_hi) || self.nodes.is_empty() {
            return;
        }
        let ov: V3<S> = V3::splat(s, o);
        let inv: V3<S> = V3::new(
            s.rcp(s.splat(d[0])),
            s.rcp(s.splat(d[1])),
            s.rcp(s.splat(d[2])),
        );
        let (lo_t, hi_t, grow) = (s.splat(t_lo), s.splat(t_hi), s.splat(BOX_GROW));
        // Entries: a wide node's index, or a leaf as `LEAF | first slot` with its count
        // in the next entry.
        const LEAF: u32 = 0x8000_0000;
        stack[0] = 0;
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let e = stack[sp];
            if e & LEAF != 0 {
                sp -= 1;
                let (first, count) = ((e & !LEAF) as usize, stack[sp] as usize);
                for slot in first..first + count {
                    let rec = &bvh.records[slot];
                    if !rec.is_sphere() {
                        continue;
                    }
                    if let Some((t0, t1)) = chord(o, d, dd, rec.p0, rec.r) {
                        if t0 <= t_hi && t1 >= t_lo {
                            out.push(Span {
                                t0,
                                t1,
                                slot: slot as u32,
                            });
                        }
                    }
                }
                continue;
            }
            let node = &self.nodes[e as usize];
            let n = node.n as usize;
            let mut c = 0usize;
            while c < n {
                let lo = V3::new(
                    s.load_partial(&node.min[0][c..], 0.0),
                    s.load_partial(&node.min[1][c..], 0.0),
                    s.load_partial(&node.min[2][c..], 0.0),
                );
                let hi = V3::new(
                    s.load_partial(&node.max[0][c..], 0.0),
                    s.load_partial(&node.max[1][c..], 0.0),
                    s.load_partial(&node.max[2][c..], 0.0),
                );
                let (m, _) = slab_test(s, lo, hi, ov, inv, lo_t, hi_t, grow);
                let mut bits = s.bitmask(m & s.first_n(n - c));
                while bits != 0 {
                    let i = c + bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    let count = node.count[i] as u32;
                    if count > 0 {
                        stack[sp] = count;
                        stack[sp + 1] = LEAF | node.child[i];
                        sp += 2;
                    } else {
                        stack[sp] = node.child[i];
                        sp += 1;
                    }
                }
                c += S::LANES;
            }
        }
    }
}
