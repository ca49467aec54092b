//! The clustered SAH build (issue #19): primitives sorted once by the Morton code of their
//! centroids and cut into clusters of at most [`CLUSTER_MAX`] along that order (each a cell
//! of the Morton grid); a binned SAH tree over the clusters' boxes down to groups of at most
//! [`TOP_LEAF`] clusters; below each group, the per-primitive binned SAH build over its
//! primitives (exact sweeps from [`super::SMALL_MAX`] primitives down). The top ~10 levels
//! bin one box per cluster instead of one per primitive, the bottom ones are the reference
//! builder's own, so the tree is nearly as good (SAH +1-2 %) and no slower to trace. The
//! price: the groups' nodes exist twice while they are copied into the tree (the
//! per-primitive build frees its subtrees as it copies them).

use std::sync::atomic::AtomicU64;

use glam::Vec3A;
use rayon::prelude::*;

use super::{assemble, build_seq, build_skeleton, Cancelled, Params, Watch};
use crate::geometry::{Aabb, PrimRef};
use crate::tree::Node;

/// Most primitives in one cluster.
pub(crate) const CLUSTER_MAX: usize = 128;
/// Most clusters in a leaf of the top tree, i.e. under one per-primitive subtree. Measured
/// (`bvh` example `build_time`, 740K / 4.8 M-atom `random_molecule`, 2 threads, Zen 3, AVX2
/// camera rays, against the per-primitive build): 1 → 8.3 / 7.3 M prims/s, SAH +6.5 / +6.5 %,
/// far rays +7 / +5 %; 8 → 7.0 / 6.5, +2.3 / +2.4 %, +1 / +4 %; 16 → 6.9 / 6.3, +1.5 /
/// +1.9 %, ±0 / ±0 %; 32 → 6.6, +1.2 %, −1 %.
const TOP_LEAF: usize = 16;
/// Bits of the Morton code per axis.
const MORTON_BITS: u32 = 10;

/// Spreads the low 10 bits of `v` to every third bit (bit i to bit 3i).
fn spread3(v: u32) -> u32 {
    let mut x = v & 0x3ff;
    x = (x | (x << 16)) & 0x0300_00ff;
    x = (x | (x << 8)) & 0x0300_f00f;
    x = (x | (x << 4)) & 0x030c_30c3;
    (x | (x << 2)) & 0x0924_9249
}

/// Sort keys: the 30-bit Morton code of each reference's (doubled) centroid in the centroid
/// bounds `cb` in the high half, the reference's index in the low half.
fn morton_keys(refs: &[PrimRef], cb: &Aabb) -> Vec<u64> {
    let cells = (1u32 << MORTON_BITS) as f32;
    let lo = Vec3A::from(cb.min);
    let ext = Vec3A::from(cb.max) - lo;
    // Cells per Å along each axis; 0 on a flat axis (every code bit of it 0).
    let scale = Vec3A::select(
        ext.cmpgt(Vec3A::ZERO) & ext.is_finite_mask(),
        Vec3A::splat(cells * (1.0 - 1e-6)) / ext,
        Vec3A::ZERO,
    );
    refs.par_iter()
        .enumerate()
        .with_min_len(4096)
        .map(|(i, r)| {
            let q = ((r.c2() - lo) * scale).clamp(Vec3A::ZERO, Vec3A::splat(cells - 1.0));
            let code = spread3(q.x as u32) | spread3(q.y as u32) << 1 | spread3(q.z as u32) << 2;
            (code as u64) << 32 | i as u64
        })
        .collect()
}

/// Cuts the sorted `keys[lo..hi]`, whose codes agree above `bit`, into runs of at most
/// [`CLUSTER_MAX`] that are cells of the Morton grid (halved one code bit at a time);
/// runs of one code longer than that are cut into pieces.
fn cut(keys: &[u64], lo: usize, hi: usize, bit: u32, out: &mut Vec<(u32, u32)>) {
    if hi - lo <= CLUSTER_MAX {
        out.push((lo as u32, hi as u32));
    } else if bit == 0 {
        for s in (lo..hi).step_by(CLUSTER_MAX) {
            out.push((s as u32, (s + CLUSTER_MAX).min(hi) as u32));
        }
    } else {
        let b = 1u64 << (32 + bit - 1);
        let mid = lo + keys[lo..hi].partition_point(|k| k & b == 0);
        if mid > lo {
            cut(keys, lo, mid, bit - 1, out);
        }
        if hi > mid {
            cut(keys, mid, hi, bit - 1, out);
        }
    }
}

/// Bounds and centroid bounds of `refs`.
fn bounds(refs: &[PrimRef]) -> (Aabb, Aabb) {
    let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    let (mut clo, mut chi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    for r in refs {
        lo = lo.min(r.lo3());
        hi = hi.max(r.hi3());
        clo = clo.min(r.c2());
        chi = chi.max(r.c2());
    }
    let aabb = |min: Vec3A, max: Vec3A| Aabb {
        min: min.into(),
        max: max.into(),
    };
    (aabb(lo, hi), aabb(clo, chi))
}

/// Builds the tree over `refs` (all primitives; `cb` their centroid bounds): returns the
/// nodes (root at 0, children pairs adjacent) and the primitive id of every leaf slot. `refs`
/// is only read.
pub(crate) fn build_clustered(
    refs: &[PrimRef],
    cb: &Aabb,
    nb: usize,
    leaf_max: usize,
    watch: &Watch,
) -> Result<(Vec<Node>, Vec<u32>), Cancelled> {
    let mut keys = morton_keys(refs, cb);
    watch.check()?;
    keys.par_sort_unstable();
    watch.check()?;
    let mut runs = Vec::with_capacity(2 * refs.len() / CLUSTER_MAX + 1);
    cut(&keys, 0, keys.len(), 3 * MORTON_BITS, &mut runs);
    // The references in Morton order: cluster c is `sorted[runs[c].0..runs[c].1]`.
    let sorted: Vec<u32> = keys
        .par_iter()
        .with_min_len(4096)
        .map(|&k| k as u32)
        .collect();
    drop(keys);

    // One reference per cluster: its box, tagged with the cluster's index.
    let mut crefs: Vec<PrimRef> = runs
        .par_iter()
        .enumerate()
        .with_min_len(256)
        .map(|(c, &(lo, hi))| {
            let mut b = Aabb::EMPTY;
            for &i in &sorted[lo as usize..hi as usize] {
                b = b.union(refs[i as usize].aabb());
            }
            PrimRef::new(&b, c as u32)
        })
        .collect();
    let (top_bounds, top_cb) = bounds(&crefs);
    let top = Params {
        nb,
        leaf_max: TOP_LEAF,
        small: super::SMALL,
    };
    let sk = build_skeleton(
        &mut crefs,
        0,
        top_bounds,
        top_cb,
        top,
        None,
        &Watch {
            done: &AtomicU64::new(0),
            cancelled: watch.cancelled,
        },
    );
    watch.check()?;
    let top_nodes = assemble(sk);

    // The top tree's leaves (runs of `crefs`) in slot order, and the first slot of each.
    let mut leaves: Vec<(usize, usize)> = top_nodes
        .iter()
        .filter(|n| n.is_leaf())
        .map(|n| (n.first as usize, n.count()))
        .collect();
    leaves.sort_unstable();
    let mut bases = Vec::with_capacity(leaves.len());
    let mut acc = 0usize;
    for &(f, c) in &leaves {
        bases.push(acc);
        for r in &crefs[f..f + c] {
            let (lo, hi) = runs[r.id() as usize];
            acc += (hi - lo) as usize;
        }
    }
    let inner = Params {
        nb,
        leaf_max,
        small: super::SMALL_MAX,
    };
    // Each leaf's subtree (root at 0, leaves holding global slots) and the primitive of each
    // of its slots.
    let subs: Vec<(Vec<Node>, Vec<u32>)> = leaves
        .par_iter()
        .zip(bases.par_iter())
        .map(|(&(f, c), &base)| {
            if watch.check().is_err() {
                return (Vec::new(), Vec::new());
            }
            let mut local: Vec<PrimRef> = Vec::new();
            for r in &crefs[f..f + c] {
                let (lo, hi) = runs[r.id() as usize];
                local.extend(
                    sorted[lo as usize..hi as usize]
                        .iter()
                        .map(|&i| refs[i as usize]),
                );
            }
            let (b, cb) = bounds(&local);
            let mut nodes = Vec::with_capacity(local.len());
            nodes.push(Node::default());
            build_seq(&mut local, base, b, cb, inner, None, &mut nodes, 0);
            watch.add(local.len());
            (nodes, local.iter().map(|r| r.id()).collect())
        })
        .collect();
    drop(sorted);
    watch.check()?;
    let (subs, ids): (Vec<Vec<Node>>, Vec<Vec<u32>>) = subs.into_iter().unzip();
    let order = ids.concat();
    drop(ids);

    // A top leaf's `first` is its first slot of `crefs`; its subtree replaces it.
    let mut by_slot: Vec<&[Node]> = vec![&[]; crefs.len()];
    for (&(f, _), s) in leaves.iter().zip(&subs) {
        by_slot[f] = s;
    }
    let top = Top {
        nodes: &top_nodes,
        subs: by_slot,
    };
    let mut below = vec![0usize; top_nodes.len()];
    count_below(&top, 0, &mut below);
    // (Filled in parallel: the pages are first touched on both threads. `zeroed_vec` is a
    // one-thread `memset` for a 32-byte aligned type.)
    let mut out: Vec<Node> = (0..1 + below[0])
        .into_par_iter()
        .with_min_len(1 << 12)
        .map(|_| Node::default())
        .collect();
    let (root, rest) = out.split_first_mut().expect("one node at least");
    splice(&top, 0, &below, root, rest, 1);
    Ok((out, order))
}

/// The top tree over the clusters, and the subtree that replaces each of its leaves (by the
/// leaf's first slot of the clusters' references).
struct Top<'a> {
    nodes: &'a [Node],
    subs: Vec<&'a [Node]>,
}

/// Fills `below[t]` for the top subtree at `t`: the nodes under it in the final tree.
fn count_below(top: &Top, t: usize, below: &mut [usize]) -> usize {
    let n = top.nodes[t];
    let b = if n.is_leaf() {
        top.subs[n.first as usize].len() - 1
    } else {
        let c = n.first as usize;
        2 + count_below(top, c, below) + count_below(top, c + 1, below)
    };
    below[t] = b;
    b
}

/// Writes the top tree's node `t` into `slot` and the nodes under it into `rest` (which starts
/// at index `base` of the final array), each top leaf replaced by its cluster's subtree; both
/// halves in parallel when large.
fn splice(top: &Top, t: usize, below: &[usize], slot: &mut Node, rest: &mut [Node], base: usize) {
    let n = top.nodes[t];
    if n.is_leaf() {
        let sub = top.subs[n.first as usize];
        // The subtree's nodes are indexed from its root (local 0); local i >= 1 goes to
        // base + i - 1.
        let fix = |mut m: Node| {
            if !m.is_leaf() {
                m.first = (base + m.first as usize - 1) as u32;
            }
            m
        };
        *slot = fix(sub[0]);
        for (o, &m) in rest.iter_mut().zip(&sub[1..]) {
            *o = fix(m);
        }
        return;
    }
    *slot = n;
    slot.first = base as u32;
    let c = n.first as usize;
    let (kids, rest) = rest.split_at_mut(2);
    let (l, r) = kids.split_at_mut(1);
    let (lrest, rrest) = rest.split_at_mut(below[c]);
    let (lbase, rbase) = (base + 2, base + 2 + below[c]);
    if below[t] > 1 << 14 {
        rayon::join(
            || splice(top, c, below, &mut l[0], lrest, lbase),
            || splice(top, c + 1, below, &mut r[0], rrest, rbase),
        );
    } else {
        splice(top, c, below, &mut l[0], lrest, lbase);
        splice(top, c + 1, below, &mut r[0], rrest, rbase);
    }
}
