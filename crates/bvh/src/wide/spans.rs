//! [`Bvh::sphere_spans`] through the 8-wide tree: each node's child boxes against the ray in
//! one SIMD op, children in any order (every sphere in the range is wanted, not the nearest).

use spmd::{Simd, V3};

use super::WideBvh;
use crate::spans::{Span, SpanQuery};
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
        let Some(q) = SpanQuery::new(o, d, t_lo, t_hi).filter(|_| !self.nodes.is_empty()) else {
            return;
        };
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
                q.leaf(&bvh.records, first..first + count, out);
                continue;
            }
            let node = &self.nodes[e as usize];
            let n = node.n as usize;
            let mut c = 0usize;
            while c < n {
                let (lo, hi) = node.boxes(s, c);
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
