//! The peak resident set of a `render` process, modelled phase by phase.
//!
//! The components of [`MemoryEstimate`] are the scene at rest. A process holds more at its
//! worst moment: while the BVH is built, the primitive references (32 B each), the per-atom
//! scaled radii and colours of the model and the records being written are alive together
//! with the molecule and the bonds; glibc keeps most blocks freed during the build (the
//! builder's per-subtree node arrays, the bond search's per-chunk lists) resident; and the
//! binary, its libraries and the thread stacks are there from the start. [`Peak::new`] sums
//! what is alive in each phase, takes the largest and adds the baseline and the retention.
//!
//! Measured on the five built-in scenes (BENCHMARKS.md, "Memory: info's estimate vs peak RSS"),
//! the live sum of the BVH phase is the peak RSS to within 1 % when glibc is told to give
//! freed memory back at once (`MALLOC_TRIM_THRESHOLD_=0`, b&s: sio2 1,349.0 MB estimated,
//! 1,355.5 MB measured; ns740k 227.6 and 228.5 MB); with glibc's defaults the retention
//! ([`retained_bytes`]) is added.

use super::MemoryEstimate;

/// Resident bytes of a `render` process before any scene exists: binary text, libraries,
/// rayon's threads and their stacks. Measured: `render --scene nanobowl --atoms 10 --size
/// 16x16` peaks at 5,688 KiB (5.82 MB) of which the scene is a few kB.
pub const BASELINE_BYTES: u64 = 5_800_000;

/// Bytes of a builder primitive reference (`bvh::geometry::PrimRef`: box and centroid as two
/// 16-byte halves).
const PRIM_REF_BYTES: u64 = 32;
/// Bytes per atom of `scene::Model::new`'s temporaries, alive during the BVH build: radii
/// scaled by the radius factor (4 B) and colours (4 B).
const MODEL_TEMP_BYTES_PER_ATOM: u64 = 8;
/// Bytes per atom of the bond search's cell grid: cell key, atom list and cell of each atom
/// (3 × u32) plus the cell starts (u32, at most 2 cells per atom).
const BOND_GRID_BYTES_PER_ATOM: u64 = 20;
/// Bytes per binary BVH node of the wide collapse's plan (`bvh::wide`'s cut of each binary
/// node, a u32), alive while the wide nodes are written.
const WIDE_PLAN_BYTES_PER_NODE: u64 = 4;
/// Bytes of a ball's geometry (x, y, z, radius, colour).
const BALL_BYTES: u64 = 20;
/// Bytes of a stick's geometry (two atom indices) and of a bond in the bond list.
const BOND_BYTES: u64 = 8;

/// Allocator retention fitted at 1 M primitives (bytes); see [`retained_bytes`].
const RETAINED_AT_1M_PRIMS: f64 = 29.0e6;
/// Exponent of the retention's growth with the primitive count; see [`retained_bytes`].
const RETAINED_EXPONENT: f64 = 0.8;

/// The phase of a `render` process in which the most bytes are alive.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PeakPhase {
    /// Bond search: molecule, cell grid, per-chunk bond lists and their concatenation.
    Bonds,
    /// BVH build, while the records are written: molecule, bonds, scratch, the model's
    /// temporaries, geometry, primitive references, nodes, ids and records.
    Bvh,
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
            PeakPhase::Bvh => "bvh build",
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
        if has_model {
            let bvh = e.atoms
                + bond_list
                + e.scratch
                + c.atoms * (MODEL_TEMP_BYTES_PER_ATOM + BALL_BYTES)
                + c.sticks * BOND_BYTES
                + c.prims * PRIM_REF_BYTES
                + e.bvh;
            phases.push((PeakPhase::Bvh, bvh));
            if e.wide_bvh > 0 {
                let wide = e.atoms
                    + bond_list
                    + e.scratch
                    + model_rest
                    + e.wide_bvh
                    + c.nodes * WIDE_PLAN_BYTES_PER_NODE;
                phases.push((PeakPhase::WideBvh, wide));
            }
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
/// `prims` BVH primitives: `29 MB · (prims / 10⁶)^0.8`.
///
/// An empirical fit, not a derivation: the builder frees its per-subtree node arrays (≤ 256
/// KiB each, 0.7 × 32 B per primitive in all) and the bond search its per-chunk lists just
/// before the peak, and glibc keeps a share of them in its arenas, a share that falls with
/// scale. Measured as peak RSS with glibc's defaults minus peak RSS with
/// `MALLOC_TRIM_THRESHOLD_=0` (`render --size 256x256`, b&s): nanobowl 2.9 MB (63 K
/// primitives), ns90k 7.6 MB (230 K), ns740k 47.6 MB (1.85 M), sio2 172-220 MB (11.1 M),
/// anp3 276-457 MB (28.9 M; the spread is run to run). The fit gives 3.2, 8.9, 47.6, 199
/// and 427 MB.
pub fn retained_bytes(prims: u64) -> u64 {
    if prims == 0 {
        return 0;
    }
    (RETAINED_AT_1M_PRIMS * (prims as f64 / 1e6).powf(RETAINED_EXPONENT)) as u64
}
