//! BVH builders: binned SAH, parallel over subtrees (the fast one), and the paper's full-sweep
//! SAH over presorted lists (§4.1, the quality reference).

use std::sync::atomic::AtomicU64;
use std::time::Instant;

use glam::Vec3A;
use rayon::prelude::*;

use crate::geometry::{prim_refs, prim_refs_as_records, Aabb, Geometry, PrimRecord, PrimRef};
use crate::tree::{refs_bounds, Builder, Bvh, Node, INNER, LEAF_MAX};

mod cluster;
mod watch;

pub use watch::{Cancelled, Watch};

/// Most bins the binned builder supports.
pub const MAX_BINS: usize = 32;
/// Default of [`BuildOptions::cluster_above`]: below this the per-primitive build takes
/// milliseconds, and a top tree over a few dozen clusters costs more SAH (+2-3 % at 6-42K
/// primitives against +1-2 % at 0.1-10 M).
pub const CLUSTER_ABOVE: usize = 1 << 16;
/// Default of [`BuildOptions::cluster_upto`]: 64 M primitives (a 32 M-atom b&s scene).
pub const CLUSTER_UPTO: usize = 1 << 26;
/// Subtrees with at least this many primitives on both sides are built in parallel.
const PAR_SUBTREE: usize = 4096;
/// Nodes with at least this many primitives are binned in parallel.
const PAR_BIN: usize = 1 << 16;

/// Options of the binned SAH builder.
#[derive(Clone, Copy, Debug)]
pub struct BuildOptions {
    /// Number of bins per axis (2..=[`MAX_BINS`]); small nodes use at most one bin per primitive.
    pub bins: usize,
    /// Build over Morton-order clusters of primitives (1.4× faster, SAH +1-2 %) when there
    /// are more primitives than this and at most [`BuildOptions::cluster_upto`]; otherwise
    /// bin every primitive at every level (the reference the tests compare against).
    /// `usize::MAX`: never cluster.
    pub cluster_above: usize,
    /// Most primitives the clustered build takes: it holds the tree's nodes twice for a
    /// moment (≈ 22 B per primitive more at the peak), which a scene at the edge of memory
    /// cannot spare.
    pub cluster_upto: usize,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            bins: MAX_BINS,
            cluster_above: CLUSTER_ABOVE,
            cluster_upto: CLUSTER_UPTO,
        }
    }
}

/// A box for the builder's inner loops (SSE min/max through glam).
#[derive(Clone, Copy)]
struct BBox {
    lo: Vec3A,
    hi: Vec3A,
}

impl BBox {
    const EMPTY: BBox = BBox {
        lo: Vec3A::INFINITY,
        hi: Vec3A::NEG_INFINITY,
    };
    #[inline(always)]
    fn union(self, o: BBox) -> BBox {
        BBox {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }
    #[inline(always)]
    fn of(r: &PrimRef) -> BBox {
        BBox {
            lo: r.lo3(),
            hi: r.hi3(),
        }
    }
    #[inline(always)]
    fn grow(&mut self, p: Vec3A) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }
    /// Half the surface area (the factor 2 does not change any SAH decision); 0 if empty.
    #[inline(always)]
    fn half_area(&self) -> f32 {
        let d = (self.hi - self.lo).max(Vec3A::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
    fn aabb(&self) -> Aabb {
        Aabb {
            min: self.lo.into(),
            max: self.hi.into(),
        }
    }
}

#[derive(Clone, Copy)]
struct Bin {
    b: BBox,
    n: u32,
}

const EMPTY_BIN: Bin = Bin {
    b: BBox::EMPTY,
    n: 0,
};

type Bins = [[Bin; MAX_BINS]; 3];

/// Where a primitive's (doubled) centroid falls along each axis.
#[derive(Clone, Copy)]
struct Binner {
    min: Vec3A,
    scale: Vec3A,
    nb: usize,
}

impl Binner {
    fn new(cb: &Aabb, nb: usize) -> Binner {
        let mut scale = [0.0; 3];
        for (k, s) in scale.iter_mut().enumerate() {
            let ext = cb.max[k] - cb.min[k];
            if ext > 0.0 && ext.is_finite() {
                *s = nb as f32 * (1.0 - 1e-6) / ext;
            }
        }
        Binner {
            min: cb.min.into(),
            scale: scale.into(),
            nb,
        }
    }
    /// Bin of `r` along every axis: `(c − min)·scale − ½`, clamped to `[0, nb − 1]` (NaN -> 0),
    /// rounded to nearest by adding 2²³ and reading the low mantissa bits (no float-to-int
    /// conversions). Binning and partitioning both use this, so they always agree.
    #[inline(always)]
    fn bins(&self, r: &PrimRef) -> [usize; 3] {
        const MAGIC: f32 = 8_388_608.0;
        let f = (r.c2() - self.min) * self.scale - Vec3A::splat(0.5);
        let f = f.max(Vec3A::ZERO).min(Vec3A::splat((self.nb - 1) as f32)) + Vec3A::splat(MAGIC);
        [
            (f.x.to_bits() & 0xff) as usize,
            (f.y.to_bits() & 0xff) as usize,
            (f.z.to_bits() & 0xff) as usize,
        ]
    }
    fn fill(&self, refs: &[PrimRef], bins: &mut Bins) {
        for r in refs {
            let b = BBox::of(r);
            let idx = self.bins(r);
            for k in 0..3 {
                let bin = &mut bins[k][idx[k]];
                bin.b = bin.b.union(b);
                bin.n += 1;
            }
        }
    }
}

fn merge_bins(mut a: Bins, b: &Bins) -> Bins {
    for k in 0..3 {
        for i in 0..MAX_BINS {
            a[k][i].b = a[k][i].b.union(b[k][i].b);
            a[k][i].n += b[k][i].n;
        }
    }
    a
}

/// Result of splitting a node's refs in place: the left part is `refs[..nl]`.
struct Split {
    axis: u32,
    nl: usize,
    lb: Aabb,
    lcb: Aabb,
    rb: Aabb,
    rcb: Aabb,
}

/// Nodes this small get an exact SAH sweep over sorted centroids instead of bins.
const SMALL: usize = 16;
/// Longest run [`split_small`] takes (the clustered builder sweeps whole clusters).
const SMALL_MAX: usize = cluster::CLUSTER_MAX;

/// Exact SAH split of a small node: sort along the axis of largest centroid extent, sweep,
/// keep the best. (All three axes cost three times as much for SAH within 1 %.)
fn split_small(refs: &mut [PrimRef], cb: &Aabb) -> Split {
    // Scratch on the stack sized to the run (filling 128 slots for 5 primitives was a fifth
    // of the clustered build's time).
    match refs.len() {
        0..=16 => split_small_in::<16>(refs, cb),
        17..=32 => split_small_in::<32>(refs, cb),
        _ => split_small_in::<SMALL_MAX>(refs, cb),
    }
}

/// [`split_small`] with scratch for up to `N` primitives.
fn split_small_in<const N: usize>(refs: &mut [PrimRef], cb: &Aabb) -> Split {
    let n = refs.len();
    let ext = [0, 1, 2].map(|k| cb.max[k] - cb.min[k]);
    let k = if ext[0] >= ext[1] && ext[0] >= ext[2] {
        0
    } else if ext[1] >= ext[2] {
        1
    } else {
        2
    };
    // Sort by centroid, ties by position (a stable sort), as integers: the key's bits made
    // monotonic (centroids are sanitised to finite values; −0 counted as +0) above the index.
    let mut order = [0u64; N];
    for (i, (o, r)) in order.iter_mut().zip(refs.iter()).enumerate() {
        let bits = (r.c2()[k] + 0.0).to_bits();
        let key = bits ^ (((bits as i32) >> 31) as u32 | 0x8000_0000);
        *o = (key as u64) << 32 | i as u64;
    }
    let order = &mut order[..n];
    order.sort_unstable();
    let mut sorted = [refs[0]; N];
    for (t, &o) in sorted.iter_mut().zip(order.iter()) {
        *t = refs[o as u32 as usize];
    }
    let sorted = &sorted[..n];
    let mut rcost = [0.0f32; N];
    let mut acc = BBox::EMPTY;
    for i in (1..n).rev() {
        acc = acc.union(BBox::of(&sorted[i]));
        rcost[i] = acc.half_area() * (n - i) as f32;
    }
    let mut best = (f32::INFINITY, n / 2);
    let mut acc = BBox::EMPTY;
    for i in 1..n {
        acc = acc.union(BBox::of(&sorted[i - 1]));
        let cost = acc.half_area() * i as f32 + rcost[i];
        if cost < best.0 {
            best = (cost, i);
        }
    }
    let nl = best.1;
    refs.copy_from_slice(sorted);
    let side = |rs: &[PrimRef]| {
        let mut b = BBox::EMPTY;
        let mut cb = BBox::EMPTY;
        for r in rs {
            b = b.union(BBox::of(r));
            cb.grow(r.c2());
        }
        (b.aabb(), cb.aabb())
    };
    let (lb, lcb) = side(&refs[..nl]);
    let (rb, rcb) = side(&refs[nl..]);
    Split {
        axis: k as u32,
        nl,
        lb,
        lcb,
        rb,
        rcb,
    }
}

/// Bins ready for a node: the binner they were made with and the bins.
#[derive(Clone, Copy)]
pub(crate) struct Binned {
    binner: Binner,
    bins: Bins,
}

/// Bins of `refs` (in parallel for large runs).
fn compute_bins(refs: &[PrimRef], binner: &Binner) -> Bins {
    if refs.len() >= PAR_BIN {
        refs.par_chunks(1 << 14)
            .fold(
                || [[EMPTY_BIN; MAX_BINS]; 3],
                |mut acc, c| {
                    binner.fill(c, &mut acc);
                    acc
                },
            )
            .reduce(|| [[EMPTY_BIN; MAX_BINS]; 3], |a, b| merge_bins(a, &b))
    } else {
        let mut b = [[EMPTY_BIN; MAX_BINS]; 3];
        binner.fill(refs, &mut b);
        b
    }
}

#[inline(always)]
fn add_to(bins: &mut Bins, idx: [usize; 3], b: BBox) {
    for (k, axis_bins) in bins.iter_mut().enumerate() {
        let bin = &mut axis_bins[idx[k]];
        bin.b = bin.b.union(b);
        bin.n += 1;
    }
}

/// Binned SAH split (§4.1 step 4, binned after Wald 2007): bins centroids along x, y and z
/// (or takes the bins the parent made), sweeps the bins, and partitions `refs` in place.
/// The partition pass also bins each child's primitives (with the child's centroid range
/// estimated from the split plane), so every level reads the primitives once, not twice.
fn split(
    refs: &mut [PrimRef],
    cb: &Aabb,
    p: Params,
    pre: Option<Box<Binned>>,
) -> (Split, Option<Box<Binned>>, Option<Box<Binned>>) {
    let n = refs.len();
    let nb = p.nb;
    if n <= p.small {
        return (split_small(refs, cb), None, None);
    }
    let mut pre = pre.unwrap_or_else(|| {
        let binner = Binner::new(cb, nb.clamp(2, MAX_BINS));
        Box::new(Binned {
            binner,
            bins: compute_bins(refs, &binner),
        })
    });
    let (binner, bins) = (pre.binner, &pre.bins);
    let nb = binner.nb;

    // Sweep: cost of splitting after bin i = A(left)·N(left) + A(right)·N(right).
    let mut best: Option<(f32, usize, usize)> = None;
    for (k, axis_bins) in bins.iter().enumerate() {
        if binner.scale[k] == 0.0 {
            continue;
        }
        let mut rcost = [0.0f32; MAX_BINS];
        let mut rcount = [0u32; MAX_BINS];
        let mut acc = BBox::EMPTY;
        let mut cnt = 0u32;
        for i in (1..nb).rev() {
            acc = acc.union(axis_bins[i].b);
            cnt += axis_bins[i].n;
            rcost[i - 1] = acc.half_area() * cnt as f32;
            rcount[i - 1] = cnt;
        }
        let mut acc = BBox::EMPTY;
        let mut cnt = 0u32;
        for i in 0..nb - 1 {
            acc = acc.union(axis_bins[i].b);
            cnt += axis_bins[i].n;
            if cnt == 0 || rcount[i] == 0 {
                continue;
            }
            let cost = acc.half_area() * cnt as f32 + rcost[i];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, k, i));
            }
        }
    }

    let Some((_, k, pos)) = best else {
        // Every centroid in the same place: split the run in the middle.
        let nl = n / 2;
        let (l, r) = refs.split_at(nl);
        let s = Split {
            axis: 0,
            nl,
            lb: refs_bounds(l),
            lcb: *cb,
            rb: refs_bounds(r),
            rcb: *cb,
        };
        return (s, None, None);
    };
    let mut lb = BBox::EMPTY;
    let mut rb = BBox::EMPTY;
    for (i, bin) in bins[k][..nb].iter().enumerate() {
        if i <= pos {
            lb = lb.union(bin.b);
        } else {
            rb = rb.union(bin.b);
        }
    }
    // Children's centroid ranges, estimated: the parent's, cut at the split plane.
    let plane = binner.min[k] + (pos + 1) as f32 / binner.scale[k];
    let (mut lcb_est, mut rcb_est) = (*cb, *cb);
    lcb_est.max[k] = plane.min(cb.max[k]);
    rcb_est.min[k] = plane.max(cb.min[k]);
    let nl_est: u32 = bins[k][..=pos].iter().map(|b| b.n).sum();
    let nr_est = n as u32 - nl_est;
    let (lbinner, rbinner) = (
        Binner::new(&lcb_est, child_bins(nl_est as usize, nb)),
        Binner::new(&rcb_est, child_bins(nr_est as usize, nb)),
    );
    // The parent's bins are no longer needed: reuse their box for the left child.
    pre.binner = lbinner;
    pre.bins = [[EMPTY_BIN; MAX_BINS]; 3];
    let mut lpre = pre;
    let mut rpre = Box::new(Binned {
        binner: rbinner,
        bins: [[EMPTY_BIN; MAX_BINS]; 3],
    });
    let (lbins, rbins) = (&mut lpre.bins, &mut rpre.bins);
    // Partition in place; every element is classified (and binned for its child) once.
    let (mut i, mut j) = (0, n);
    let mut lcb = BBox::EMPTY;
    let mut rcb = BBox::EMPTY;
    while i < j {
        let r = refs[i];
        let c = r.c2();
        if binner.bins(&r)[k] <= pos {
            lcb.grow(c);
            add_to(lbins, lbinner.bins(&r), BBox::of(&r));
            i += 1;
        } else {
            rcb.grow(c);
            add_to(rbins, rbinner.bins(&r), BBox::of(&r));
            j -= 1;
            refs.swap(i, j);
        }
    }
    let s = Split {
        axis: k as u32,
        nl: i,
        lb: lb.aabb(),
        lcb: lcb.aabb(),
        rb: rb.aabb(),
        rcb: rcb.aabb(),
    };
    (s, Some(lpre), Some(rpre))
}

/// What every node of one build shares: bins per axis and primitives per leaf.
#[derive(Clone, Copy)]
pub(crate) struct Params {
    /// Bins per axis (2..=[`MAX_BINS`]).
    pub nb: usize,
    /// Most primitives in a leaf (a run this long or shorter becomes one).
    pub leaf_max: usize,
    /// Runs this long or shorter get the exact sweep of [`split_small`] (≤ `SMALL_MAX`).
    pub small: usize,
}

/// Bins for a child of about `count` primitives: one per 4 primitives, 4 to `nb`. The sweep
/// over 3 × 32 bins costs as much as binning ~100 primitives, so small nodes take fewer:
/// 740K-atom `random_molecule`, 2 threads, best of 5: 352-363 → 325-341 ms, SAH +0.4 %.
fn child_bins(count: usize, nb: usize) -> usize {
    (count / 4).clamp(4.min(nb), nb)
}

/// The top of the tree, built in parallel: inner nodes down to subtrees small enough to build
/// sequentially, each into its own exactly sized node array.
pub(crate) enum Skeleton {
    Inner {
        bounds: Aabb,
        axis: u32,
        children: Box<(Skeleton, Skeleton)>,
    },
    /// A subtree: root at 0, children pairs adjacent, indices local to the array; leaves
    /// hold global primitive slots.
    Local(Vec<Node>),
}

/// Builds the tree over `refs` (primitive slots from `ref_base`): rayon over subtrees while
/// both sides have at least [`PAR_SUBTREE`] primitives, then sequentially, adding the
/// primitives of each finished sequential subtree to `watch`. Once `watch` is cancelled,
/// subtrees not yet started are left as one empty node (the caller discards the tree).
pub(crate) fn build_skeleton(
    refs: &mut [PrimRef],
    ref_base: usize,
    bounds: Aabb,
    cb: Aabb,
    p: Params,
    pre: Option<Box<Binned>>,
    watch: &Watch,
) -> Skeleton {
    let n = refs.len();
    if watch.check().is_err() {
        return Skeleton::Local(vec![Node::default()]);
    }
    if n >= 2 * PAR_SUBTREE {
        let (s, lpre, rpre) = split(refs, &cb, p, pre);
        let nl = s.nl;
        let (lrefs, rrefs) = refs.split_at_mut(nl);
        if nl >= PAR_SUBTREE && n - nl >= PAR_SUBTREE {
            let (l, r) = rayon::join(
                || build_skeleton(lrefs, ref_base, s.lb, s.lcb, p, lpre, watch),
                || build_skeleton(rrefs, ref_base + nl, s.rb, s.rcb, p, rpre, watch),
            );
            return Skeleton::Inner {
                bounds,
                axis: s.axis,
                children: Box::new((l, r)),
            };
        }
        // Too lopsided to fork: the split is done, build both sides here.
        let mut nodes = Vec::with_capacity(n);
        let mut root = Node::default();
        root.set_aabb(&bounds);
        root.first = 1;
        root.meta = INNER | s.axis;
        nodes.extend([root, Node::default(), Node::default()]);
        build_seq(lrefs, ref_base, s.lb, s.lcb, p, lpre, &mut nodes, 1);
        build_seq(rrefs, ref_base + nl, s.rb, s.rcb, p, rpre, &mut nodes, 2);
        watch.add(n);
        return Skeleton::Local(nodes);
    }
    let mut nodes = Vec::with_capacity(n);
    nodes.push(Node::default());
    build_seq(refs, ref_base, bounds, cb, p, pre, &mut nodes, 0);
    watch.add(n);
    Skeleton::Local(nodes)
}

/// Sequential build of the subtree of `refs` into `nodes[at]` (children pairs pushed at the
/// end). Recurses into the smaller child and loops on the larger: stack depth O(log n).
#[allow(clippy::too_many_arguments)]
pub(crate) fn build_seq(
    mut refs: &mut [PrimRef],
    mut ref_base: usize,
    mut bounds: Aabb,
    mut cb: Aabb,
    p: Params,
    mut pre: Option<Box<Binned>>,
    nodes: &mut Vec<Node>,
    mut at: usize,
) {
    loop {
        nodes[at].set_aabb(&bounds);
        let n = refs.len();
        if n <= p.leaf_max {
            nodes[at].first = ref_base as u32;
            nodes[at].meta = n as u32;
            return;
        }
        let (s, lpre, rpre) = split(refs, &cb, p, pre);
        let (nl, nr) = (s.nl, n - s.nl);
        let c = nodes.len();
        nodes[at].first = c as u32;
        nodes[at].meta = INNER | s.axis;
        nodes.push(Node::default());
        nodes.push(Node::default());
        let (lrefs, rrefs) = std::mem::take(&mut refs).split_at_mut(nl);
        if nl <= nr {
            build_seq(lrefs, ref_base, s.lb, s.lcb, p, lpre, nodes, c);
            (refs, ref_base, bounds, cb, pre, at) =
                (rrefs, ref_base + nl, s.rb, s.rcb, rpre, c + 1);
        } else {
            build_seq(rrefs, ref_base + nl, s.rb, s.rcb, p, rpre, nodes, c + 1);
            (refs, ref_base, bounds, cb, pre, at) = (lrefs, ref_base, s.lb, s.lcb, lpre, c);
        }
    }
}

/// Flattens a skeleton into one node array (root at 0, children pairs adjacent), allocated
/// at its exact size.
pub(crate) fn assemble(sk: Skeleton) -> Vec<Node> {
    let mut out = Vec::with_capacity(node_count(&sk));
    out.push(Node::default());
    place(sk, 0, &mut out);
    out
}

/// Nodes of the tree a skeleton flattens to.
fn node_count(sk: &Skeleton) -> usize {
    match sk {
        Skeleton::Inner { children, .. } => 1 + node_count(&children.0) + node_count(&children.1),
        Skeleton::Local(v) => v.len(),
    }
}

fn place(sk: Skeleton, at: usize, out: &mut Vec<Node>) {
    match sk {
        Skeleton::Inner {
            bounds,
            axis,
            children,
        } => {
            let c = out.len();
            out[at].set_aabb(&bounds);
            out[at].first = c as u32;
            out[at].meta = INNER | axis;
            out.push(Node::default());
            out.push(Node::default());
            let (l, r) = *children;
            place(l, c, out);
            place(r, c + 1, out);
        }
        Skeleton::Local(v) => {
            // Local index i >= 1 goes to base + i - 1; the local root to `at`.
            let base = out.len();
            let fix = |mut n: Node| {
                if !n.is_leaf() {
                    n.first = (base + n.first as usize - 1) as u32;
                }
                n
            };
            out[at] = fix(v[0]);
            out.extend(v[1..].iter().map(|&n| fix(n)));
        }
    }
}

impl Bvh {
    /// Binned SAH build with default options (32 bins, ≤ 4 primitives per leaf), parallel over
    /// subtrees on the current rayon pool. Panics beyond 2³⁰ primitives.
    pub fn build(g: &Geometry) -> Bvh {
        Bvh::build_with(g, &BuildOptions::default())
    }

    /// Binned SAH build (§4.1 step 4, binned as in Wald 2007 instead of the paper's sweep).
    pub fn build_with(g: &Geometry, opt: &BuildOptions) -> Bvh {
        match Bvh::build_watched(g, opt, None) {
            Ok(b) => b,
            Err(Cancelled) => unreachable!("an unwatched build is never cancelled"),
        }
    }

    /// [`Bvh::build_with`] reporting to `watch`, if given: the primitives placed in finished
    /// subtrees are added to its count (which reaches [`Geometry::prim_count`] when the tree
    /// is built), and once its cancel test returns true the build stops after at most a few
    /// thousand more primitives per thread and returns [`Cancelled`].
    pub fn build_watched(
        g: &Geometry,
        opt: &BuildOptions,
        watch: Option<&Watch>,
    ) -> Result<Bvh, Cancelled> {
        let start = Instant::now();
        let unwatched = AtomicU64::new(0);
        let watch = watch.copied().unwrap_or(Watch {
            done: &unwatched,
            cancelled: &|| false,
        });
        let nb = opt.bins.clamp(2, MAX_BINS);
        // One 32-byte array: the builder's references first, the records written over them
        // (the peak holds one of the two, not both).
        let n = g.prim_count();
        let (mut records, bounds, cb) = prim_refs_as_records(g);
        watch.check()?;
        let refs: &mut [PrimRef] = bytemuck::cast_slice_mut(&mut records);
        let (nodes, order) = if n == 0 {
            (vec![Node::default()], Vec::new())
        } else if n > opt.cluster_above && n <= opt.cluster_upto {
            cluster::build_clustered(refs, &cb, nb, LEAF_MAX, &watch)?
        } else {
            let p = Params {
                nb,
                leaf_max: LEAF_MAX,
                small: SMALL,
            };
            let sk = build_skeleton(refs, 0, bounds, cb, p, None, &watch);
            watch.check()?;
            let order = refs.par_iter().with_min_len(4096).map(|r| r.id()).collect();
            (assemble(sk), order)
        };
        watch.check()?;
        Ok(Bvh::finish(
            g,
            nodes,
            order,
            records,
            Builder::Binned,
            start,
        ))
    }

    /// The paper's builder (§4.1): primitives presorted along x, y and z; each node sweeps all
    /// three sorted lists and takes the split of least SAH cost. Exact but sequential and
    /// slow (O(n log n) per level): meant as the quality reference on ≤ 100K primitives.
    pub fn build_full_sweep(g: &Geometry) -> Bvh {
        let start = Instant::now();
        let (refs, _, _) = prim_refs(g);
        let n = refs.len();
        if n == 0 {
            return Bvh::finish(
                g,
                vec![Node::default()],
                Vec::new(),
                Vec::new(),
                Builder::FullSweep,
                start,
            );
        }
        let sorted = |k: usize| {
            let mut v: Vec<u32> = (0..n as u32).collect();
            v.par_sort_unstable_by(|&a, &b| {
                refs[a as usize]
                    .centroid2(k)
                    .total_cmp(&refs[b as usize].centroid2(k))
                    .then(a.cmp(&b))
            });
            v
        };
        let (mut lx, mut ly, mut lz) = (sorted(0), sorted(1), sorted(2));
        let mut st = Sweep {
            refs: &refs,
            nodes: vec![Node::default()],
            order: Vec::with_capacity(n),
            left: vec![false; n],
            tmp: Vec::with_capacity(n),
            rcost: vec![0.0; n],
        };
        st.build([&mut lx, &mut ly, &mut lz], 0);
        let Sweep { nodes, order, .. } = st;
        drop(refs);
        let records = vec![PrimRecord::default(); order.len()];
        Bvh::finish(g, nodes, order, records, Builder::FullSweep, start)
    }
}

struct Sweep<'r> {
    refs: &'r [PrimRef],
    nodes: Vec<Node>,
    order: Vec<u32>,
    left: Vec<bool>,
    tmp: Vec<u32>,
    rcost: Vec<f32>,
}

impl Sweep<'_> {
    fn build(&mut self, lists: [&mut [u32]; 3], at: usize) {
        let n = lists[0].len();
        let bounds = lists[0]
            .iter()
            .fold(Aabb::EMPTY, |b, &i| b.union(self.refs[i as usize].aabb()));
        self.nodes[at].set_aabb(&bounds);
        if n <= LEAF_MAX {
            self.nodes[at].first = self.order.len() as u32;
            self.nodes[at].meta = n as u32;
            self.order.extend_from_slice(lists[0]);
            return;
        }
        // Sweep every axis: cost of putting the first i primitives left.
        let mut best = (f32::INFINITY, 0usize, n / 2);
        for (k, list) in lists.iter().enumerate() {
            let mut acc = Aabb::EMPTY;
            for i in (1..n).rev() {
                acc = acc.union(self.refs[list[i] as usize].aabb());
                self.rcost[i] = acc.area() * (n - i) as f32;
            }
            let mut acc = Aabb::EMPTY;
            for i in 1..n {
                acc = acc.union(self.refs[list[i - 1] as usize].aabb());
                let cost = acc.area() * i as f32 + self.rcost[i];
                if cost < best.0 {
                    best = (cost, k, i);
                }
            }
        }
        let (_, k, nl) = best;
        for &id in lists[k][..nl].iter() {
            self.left[id as usize] = true;
        }
        for &id in lists[k][nl..].iter() {
            self.left[id as usize] = false;
        }
        let [a, b, c] = lists;
        let mut parts = [a, b, c];
        for (kk, list) in parts.iter_mut().enumerate() {
            if kk == k {
                continue;
            }
            // Stable partition by the left flags.
            self.tmp.clear();
            let mut w = 0;
            for r in 0..n {
                let id = list[r];
                if self.left[id as usize] {
                    list[w] = id;
                    w += 1;
                } else {
                    self.tmp.push(id);
                }
            }
            list[w..].copy_from_slice(&self.tmp);
        }
        let child = self.nodes.len();
        self.nodes[at].first = child as u32;
        self.nodes[at].meta = INNER | k as u32;
        self.nodes.push(Node::default());
        self.nodes.push(Node::default());
        let [a, b, c] = parts;
        let (al, ar) = a.split_at_mut(nl);
        let (bl, br) = b.split_at_mut(nl);
        let (cl, cr) = c.split_at_mut(nl);
        self.build([al, bl, cl], child);
        self.build([ar, br, cr], child + 1);
    }
}
