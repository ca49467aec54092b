//! The peak resident set of a `render` process, modelled phase by phase.
//!
//! The components of [`MemoryEstimate`] are the scene at rest. A process holds more at its
//! worst moment: while the bonds are searched, the wide BVH is collapsed or the density is
//! built, their temporaries are alive beside what is built already; glibc keeps the blocks
//! freed during the BVH build (the builder's per-subtree node arrays, copied into the final
//! array) resident; and the binary, its libraries and the thread stacks are there from the
//! start. [`Peak::new`] sums what is alive in each phase, takes the largest and adds the
//! baseline and the retention.
//!
//! The BVH build writes each primitive record over the builder's reference to it (the same
//! 32 B) and takes the model's scaled radii and colours over as the balls' arrays, so what is
//! alive then is the scene at rest less the slot colours, ids and frame made after it, plus,
//! for the clustered build (more than `bvh::CLUSTER_ABOVE` primitives, at most
//! `bvh::CLUSTER_UPTO`), a second copy of the nodes and 4 B per primitive for a moment
//! ([`PeakPhase::BvhBuild`]). (Before, references and records were two arrays: 32 B per
//! primitive more, the peak of every model.)
//!
//! Measured (BENCHMARKS.md, "Scale"): with `MALLOC_TRIM_THRESHOLD_=0` (glibc gives freed
//! memory back at once) the live sum is the peak RSS within 2 %, 100 M-atom anp3 included
//! (18,787 MB estimated, 18,680 MB measured); the retention is about the node arrays' size.

use super::MemoryEstimate;
use crate::BVH_NODES_PER_PRIM;

/// Resident bytes of a `render` process before any scene exists: binary text, libraries,
/// rayon's threads and their stacks. Measured: `render --scene nanobowl --atoms 10 --size
/// 16x16` peaks at 5,688 KiB (5.82 MB) of which the scene is a few kB.
pub const BASELINE_BYTES: u64 = 5_800_000;

/// Bytes per atom of the bond search's cell grid: cell key, atom list and cell of each atom
/// (3 × u32) plus the cell starts (u32, at most 2 cells per atom).
const BOND_GRID_BYTES_PER_ATOM: u64 = 20;
/// Bytes per binary BVH node of the wide collapse's plan (`bvh::wide`'s cut of each binary
/// node, a u32), alive while the wide nodes are written.
const WIDE_PLAN_BYTES_PER_NODE: u64 = 4;
/// Bytes of a bond in the bond list (two atom indices).
const BOND_BYTES: u64 = 8;

/// The phase of a `render` process in which the most bytes are alive.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PeakPhase {
    /// Bond search: molecule, cell grid, per-chunk bond lists and their concatenation.
    Bonds,
    /// Clustered BVH build (`bvh::BuildOptions::cluster_above`): the model at rest plus a
    /// second copy of the nodes (the clusters' subtrees while they are copied into the tree)
    /// and their slots' primitive ids (4 B per primitive).
    BvhBuild,
    /// 8-wide BVH build: the model at rest plus the wide nodes and the collapse's plan.
    WideBvh,
    /// Density build: the model at rest (if any), the per-slab atom lists, the per-thread
    /// block scratch and the voxels.
    Volume,
    /// Drawing the frame: every component at rest.
    #[default]
    Frame,
}

impl PeakPhase {
    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            PeakPhase::Bonds => "bonds",
            PeakPhase::BvhBuild => "bvh build",
            PeakPhase::WideBvh => "wide bvh build",
            PeakPhase::Volume => "volume build",
            PeakPhase::Frame => "frame",
        }
    }
}

/// The estimated peak resident set of a `render` process (bytes in each field).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Peak {
    /// The phase with the most bytes alive.
    pub phase: PeakPhase,
    /// Bytes alive (allocated and written) in that phase.
    pub live: u64,
    /// Bytes freed earlier in the build that the allocator keeps resident.
    pub retained: u64,
    /// The process baseline ([`BASELINE_BYTES`]; 0 in a default `Peak`).
    pub baseline: u64,
}

/// Counts the phases need besides the components (from the same sizes as the estimate).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Counts {
    /// Atoms.
    pub atoms: u64,
    /// Bonds in the bond list (drawn or not).
    pub bonds: u64,
    /// Bonds drawn as sticks.
    pub sticks: u64,
    /// BVH primitives.
    pub prims: u64,
    /// Estimated binary BVH nodes.
    pub nodes: u64,
    /// The bonds are searched ([`crate::BondSource::Auto`]), not copied from the file.
    pub auto_bonds: bool,
    /// Entries of the density builder's per-slab atom lists (u32 each).
    pub slab_entries: u64,
    /// The density builder's per-thread f32 block scratch (bytes).
    pub density_scratch: u64,
}

impl Peak {
    /// The peak of a process building the scene `e` estimates, with the counts `c`.
    pub(super) fn new(e: &MemoryEstimate, c: &Counts) -> Peak {
        let bond_list = c.bonds * BOND_BYTES;
        let mut phases = vec![(PeakPhase::Frame, e.total())];
        let has_model = c.prims > 0 || e.geometry > 0;
        if has_model && c.auto_bonds {
            let grid = c.atoms * BOND_GRID_BYTES_PER_ATOM;
            phases.push((PeakPhase::Bonds, e.atoms + grid + 2 * bond_list));
        }
        let model_rest = e.geometry + e.bvh;
        let clustered = bvh::CLUSTER_ABOVE..=bvh::CLUSTER_UPTO;
        if has_model && clustered.contains(&(c.prims as usize)) {
            let build = e.atoms + bond_list + e.scratch + model_rest + c.nodes * 32 + c.prims * 4;
            phases.push((PeakPhase::BvhBuild, build));
        }
        if has_model && e.wide_bvh > 0 {
            let wide = e.atoms
                + bond_list
                + e.scratch
                + model_rest
                + e.wide_bvh
                + c.nodes * WIDE_PLAN_BYTES_PER_NODE;
            phases.push((PeakPhase::WideBvh, wide));
        }
        if e.volume > 0 {
            let volume = e.atoms
                + bond_list
                + e.scratch
                + model_rest
                + e.wide_bvh
                + 4 * c.slab_entries
                + c.density_scratch
                + e.volume;
            phases.push((PeakPhase::Volume, volume));
        }
        let (phase, live) = phases
            .into_iter()
            .max_by_key(|p| p.1)
            .unwrap_or((PeakPhase::Frame, 0));
        Peak {
            phase,
            live,
            retained: if has_model {
                retained_bytes(c.prims)
            } else {
                0
            },
            baseline: BASELINE_BYTES,
        }
    }

    /// Baseline + live + retained (bytes).
    pub fn bytes(&self) -> u64 {
        self.baseline + self.live + self.retained
    }
}

/// Bytes freed during a model build that glibc's allocator keeps resident at the peak, for
/// `prims` BVH primitives: the builder's per-subtree node arrays (≤ 256 KiB each, below
/// glibc's mmap threshold once the first has been freed), as many bytes as the tree's nodes,
/// 0.70 × 32 B per primitive.
///
/// Measured as peak RSS with glibc's defaults minus peak RSS with `MALLOC_TRIM_THRESHOLD_=0`
/// (b&s, BENCHMARKS.md "Scale"): 0.5-1.1 × this on the five scenes and 1.07 × at 197.5 M
/// primitives (100 M-atom anp3: 4,720 MB). (A power law fitted on the five scenes, 29 MB ·
/// (prims / 10⁶)^0.8, gave 1,990 MB there: the estimate 11 % under the peak.)
pub fn retained_bytes(prims: u64) -> u64 {
    (prims as f64 * BVH_NODES_PER_PRIM).ceil() as u64 * 32
}
