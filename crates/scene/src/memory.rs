//! One memory estimate per component, computed before anything large is allocated from the
//! same sizes the build uses (element radii, the density [`Grid`], the light-volume stride),
//! and the same figures measured on a built [`Scene`] to check it; plus the peak resident set
//! of a `render` process ([`MemoryEstimate::peak_bytes`], modelled in [`peak`]).

use molecule::{elements, Molecule};
use volume::{Grid, MACROCELL};

use crate::build::{density_grid, model_prim_count, Density, Scene};
use crate::settings::DensitySource;
use crate::settings::SceneSettings;
use crate::SceneError;

mod peak;

pub use peak::{retained_bytes, Peak, PeakPhase, BASELINE_BYTES};

/// Binary BVH nodes per primitive (binned SAH builder, leaves of ≤ 4), sticks trimmed to the
/// part outside their balls: measured 0.658 (nanobowl), 0.652 (ns90k), 0.654 (ns740k), 0.763
/// (sio2 at 200 K atoms), 0.753 (sio2), 0.664 (anp3), so within ±10 %.
pub const BVH_NODES_PER_PRIM: f64 = 0.70;
/// 8-wide BVH nodes per primitive, with `bvh::wide`'s SAH collapse (nodes nearly full:
/// 6.3-6.7 children on average), sticks trimmed: measured 0.060 (nanobowl), 0.058 (ns90k),
/// 0.056 (ns740k), 0.072 (sio2 at 200 K atoms), 0.067 (sio2), 0.057 (anp3), so within ±13 %
/// (±10 % with whole sticks, whose larger boxes gave the SAH fewer splits at sio2's bottom
/// levels: 0.064, 0.059, 0.057, 0.068, 0.063, 0.060). (The greedy collapse before it: 0.097,
/// 0.122, 0.124, 0.085, 0.148, its half-empty bottom nodes depending on the depth of the
/// binary tree.)
pub const WIDE_NODES_PER_PRIM: f64 = 0.0635;
/// Bytes per pixel of the frame `render` draws: the packed RGBA8 framebuffer (the tile
/// driver keeps its sums per tile; the f32 `render::Accum` of progressive front ends, 12 B
/// more per pixel, is not counted). Measured: `render 2r9r-1b.xyz` (1,284 atoms) peaks 12.6 MB
/// higher at 2048² than at 1024² (4.1 B per added pixel, PNG encoding included).
pub const FRAME_BYTES_PER_PIXEL: u64 = 4;
/// Bytes of a binary BVH node.
const NODE_BYTES: u64 = 32;
/// Bytes of an 8-wide node.
const WIDE_NODE_BYTES: u64 = 256;
/// Bytes per primitive slot in the BVH: id (4) + intersection record (32).
const SLOT_BYTES: u64 = 36;

/// Bytes per component of a scene (estimated by [`MemoryEstimate::new`], or measured by
/// [`MemoryEstimate::measured`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemoryEstimate {
    /// The molecule frame (positions, elements, columns, file bonds); twice that with
    /// unwrapping ([`crate::BondSettings::unwrap`]: the unwrapped copy the build uses).
    pub atoms: u64,
    /// Bond list (8 B per bond).
    pub bonds: u64,
    /// Model geometry: ball centres, radii and colours (20 B/atom), stick ends (8 B/bond),
    /// per-slot colours (8 B/primitive).
    pub geometry: u64,
    /// Binary BVH: nodes (32 B), primitive ids and records (36 B/primitive).
    pub bvh: u64,
    /// 8-wide BVH (256 B/node), when the settings use it.
    pub wide_bvh: u64,
    /// Density voxels.
    pub volume: u64,
    /// Macrocell min/max pairs (8 B/cell) and the empty-space distances (1 B/cell).
    pub macrocells: u64,
    /// Light volume (1 B/point).
    pub light_volume: u64,
    /// Per-atom scratch the scene keeps between frames: radius (4 B) and colour (4 B) with a
    /// model, the density radii (4 B) for a volume alone.
    pub scratch: u64,
    /// Frame: packed RGBA8 pixels, 4 B per pixel, of the whole frame or, when it is streamed,
    /// of one band ([`crate::held_frame_bytes`]).
    pub framebuffer: u64,
    /// Lattice points of the density volume along x, y, z (`None`: no volume).
    pub volume_dims: Option<[usize; 3]>,
    /// Peak resident set of a `render` process building and drawing this scene (estimated
    /// by [`MemoryEstimate::new`]; zero from [`MemoryEstimate::measured`], which sees only the
    /// built scene at rest).
    pub peak: Peak,
}

impl MemoryEstimate {
    /// Estimates the scene `settings` would build for `m` with `bonds` bonds, allocating
    /// nothing large. Errors: the density grid cannot be laid out (no atoms, bad resolution).
    pub fn new(
        m: &Molecule,
        bonds: usize,
        settings: &SceneSettings,
    ) -> Result<MemoryEstimate, SceneError> {
        // With unwrapping, the unwrapped copy of the frame is alive during the whole build.
        let copies = if settings.bonds.unwrap { 2 } else { 1 };
        let mut e = MemoryEstimate {
            atoms: copies * m.memory_bytes() as u64,
            ..MemoryEstimate::default()
        };
        let all_bonds = bonds;
        let mut counts = peak::Counts {
            atoms: m.len() as u64,
            ..Default::default()
        };
        if let Some(ms) = &settings.model {
            let (bonds, prims) = model_prim_count(m.len(), bonds, ms);
            counts.bonds = all_bonds as u64;
            counts.sticks = bonds as u64;
            counts.prims = prims as u64;
            counts.nodes = (prims as f64 * BVH_NODES_PER_PRIM).ceil() as u64;
            counts.auto_bonds = settings.bonds.source == crate::BondSource::Auto;
            e.bonds = bonds as u64 * 8;
            e.geometry = m.len() as u64 * 20 + bonds as u64 * 8 + prims as u64 * 8;
            let nodes = (prims as f64 * BVH_NODES_PER_PRIM).ceil() as u64;
            e.bvh = nodes * NODE_BYTES + prims as u64 * SLOT_BYTES;
            if ms.wide_bvh {
                e.wide_bvh = (prims as f64 * WIDE_NODES_PER_PRIM).ceil() as u64 * WIDE_NODE_BYTES;
            }
        }
        if settings
            .volume
            .as_ref()
            .is_some_and(|vs| vs.source == DensitySource::Particles)
        {
            // The BVH over the support spheres; while it is built, the geometry copy
            // (20 B/atom), the support radii and the builder's 32-byte references, and for
            // the clustered build a second copy of the nodes and 4 B per sphere.
            let n = m.len() as u64;
            e.volume = volume::Particles::estimate_bytes(n);
            let clustered = (bvh::CLUSTER_ABOVE..=bvh::CLUSTER_UPTO).contains(&m.len());
            let second = if clustered {
                (n as f64 * BVH_NODES_PER_PRIM).ceil() as u64 * NODE_BYTES + 4 * n
            } else {
                0
            };
            counts.density_scratch = n * (20 + 4 + 32) + second;
        } else if let Some(vs) = &settings.volume {
            let grid = density_grid(m, vs)?;
            counts.slab_entries = slab_entries(m, &grid);
            counts.density_scratch = volume::estimate_bytes(&grid, vs.format)
                .saturating_sub(grid.voxel_count() * vs.format.bytes_per_voxel() + 4)
                .saturating_sub(macrocell_count(&grid) * 8);
            e.volume = grid.voxel_count() * vs.format.bytes_per_voxel() + 4;
            e.volume_dims = Some(grid.dims);
            e.macrocells = macrocell_count(&grid) * 9;
            if let Some(lv) = &vs.light_volume {
                e.light_volume = grid
                    .dims
                    .iter()
                    .map(|&d| ((d - 1).div_ceil(lv.stride.max(1)) + 1) as u64)
                    .product();
            }
        }
        if let Some(size) = settings.frame {
            e.framebuffer = crate::held_frame_bytes(size);
        }
        e.scratch = scratch_bytes(m.len(), settings);
        e.peak = Peak::new(&e, &counts);
        Ok(e)
    }

    /// The same components measured on a scene built from `m` (`framebuffer` from its settings).
    pub fn measured(scene: &Scene, m: &Molecule) -> MemoryEstimate {
        let mut e = MemoryEstimate {
            atoms: m.memory_bytes() as u64,
            bonds: scene.bonds.len() as u64 * 8,
            ..MemoryEstimate::default()
        };
        if let Some(md) = &scene.model {
            let g = &md.geometry;
            e.geometry = g.balls.len() as u64 * 20
                + g.sticks.len() as u64 * 8
                + (md.slot_color_a.len() + md.slot_color_b.len()) as u64 * 4;
            e.bvh = md.bvh.stats.bytes as u64;
            if scene.settings.model.as_ref().is_some_and(|s| s.wide_bvh) {
                e.wide_bvh = md.wide().bytes() as u64;
            }
        }
        match scene.volume.as_ref().map(|d| (&d.density, &d.empty)) {
            Some((Density::Grid { volume, cells }, empty)) => {
                e.volume = volume.bytes();
                e.volume_dims = Some(volume.grid.dims);
                e.macrocells = cells.bytes() + empty.as_ref().map_or(0, |es| es.bytes());
            }
            Some((Density::Particles(p), _)) => e.volume = p.bytes(),
            None => {}
        }
        if let Some(lv) = &scene.light_volume {
            e.light_volume = lv.bytes();
        }
        if let Some(size) = scene.settings.frame {
            e.framebuffer = crate::held_frame_bytes(size);
        }
        e.scratch = scene.scratch_bytes();
        e
    }

    /// Sum of the components: the scene at rest, while a frame is drawn (bytes).
    pub fn total(&self) -> u64 {
        self.components().iter().map(|(_, b)| b).sum()
    }

    /// Estimated peak resident set of a `render` process for this scene (bytes): the
    /// process baseline, the bytes alive at the worst moment of the build (often the BVH
    /// build, not the scene at rest) and what the allocator keeps of blocks freed before it
    /// ([`Peak`]). Never below [`MemoryEstimate::total`]. This is the figure `bnsview info`
    /// prints and [`crate::Scene::build`] checks against the memory budget.
    pub fn peak_bytes(&self) -> u64 {
        self.peak.bytes().max(self.total())
    }

    /// `(name, bytes)` of every component, in a fixed order.
    pub fn components(&self) -> [(&'static str, u64); 10] {
        [
            ("atoms", self.atoms),
            ("bonds", self.bonds),
            ("geometry", self.geometry),
            ("bvh", self.bvh),
            ("wide_bvh", self.wide_bvh),
            ("volume", self.volume),
            ("macrocells", self.macrocells),
            ("light_volume", self.light_volume),
            ("scratch", self.scratch),
            ("framebuffer", self.framebuffer),
        ]
    }

    /// The non-zero components, largest first, as `name 12.3 MB, …`.
    pub fn breakdown(&self) -> String {
        let mut c: Vec<_> = self.components().into_iter().filter(|c| c.1 > 0).collect();
        c.sort_by_key(|c| std::cmp::Reverse(c.1));
        c.iter()
            .map(|(n, b)| format!("{n} {:.1} MB", *b as f64 / 1e6))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Bytes of the per-atom scratch [`Scene`] keeps (radius and colour with a model, else the
/// density radii of a volume).
fn scratch_bytes(atoms: usize, settings: &SceneSettings) -> u64 {
    let per_atom = if settings.model.is_some() {
        8
    } else if settings.volume.is_some() {
        4
    } else {
        0
    };
    atoms as u64 * per_atom
}

/// Lattice planes per z-slab of the density builder (`volume::grid`'s `SLAB`).
const DENSITY_SLAB: f64 = 4.0;

/// Entries of the density builder's per-slab atom lists: an atom is listed in every slab of
/// [`DENSITY_SLAB`] planes its support (√2·r + one voxel) reaches, on average
/// `1 + 2·reach / (spacing · SLAB)` slabs.
fn slab_entries(m: &Molecule, g: &Grid) -> u64 {
    m.element_counts()
        .into_iter()
        .map(|(z, count)| {
            let reach = std::f64::consts::SQRT_2 * elements::element(z).covalent_radius as f64
                + g.spacing as f64;
            let slabs = 1.0 + 2.0 * reach / (g.spacing as f64 * DENSITY_SLAB);
            (count as f64 * slabs).ceil() as u64
        })
        .sum()
}

/// Macrocells of a grid, as [`volume::Macrocells::build`] lays them out.
fn macrocell_count(g: &Grid) -> u64 {
    g.dims
        .iter()
        .map(|&d| (d - 1).div_ceil(MACROCELL).max(1) as u64)
        .product()
}
