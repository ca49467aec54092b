//! One memory estimate per component, computed before anything large is allocated from the
//! same sizes the build uses (element radii, the density [`Grid`], the light-volume stride),
//! and the same figures measured on a built [`Scene`] to check it.

use molecule::Molecule;
use volume::{Grid, MACROCELL};

use crate::build::{density_grid, model_prim_count, Scene};
use crate::settings::SceneSettings;
use crate::SceneError;

/// Binary BVH nodes per primitive (binned SAH builder, leaves of ≤ 4): measured 0.696 on
/// nanobowl and 0.654 on ns90k.
pub const BVH_NODES_PER_PRIM: f64 = 0.70;
/// 8-wide BVH nodes per primitive: measured 0.085 (sio2, 200K atoms), 0.097 (nanobowl) and
/// 0.122 (ns90k), so one constant is within ±25 % of the wide BVH (a fifth of the model's
/// bytes); the total is held within 10 % by `crates/scene/tests/build.rs`.
pub const WIDE_NODES_PER_PRIM: f64 = 0.10;
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
    /// The molecule frame (positions, elements, columns, file bonds).
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
    /// Macrocell min/max pairs (8 B/cell).
    pub macrocells: u64,
    /// Light volume (1 B/point).
    pub light_volume: u64,
    /// Frame: packed pixels (4 B) + f32 RGB accumulation (12 B) per pixel.
    pub framebuffer: u64,
    /// Lattice points of the density volume along x, y, z (`None`: no volume).
    pub volume_dims: Option<[usize; 3]>,
}

impl MemoryEstimate {
    /// Estimates the scene `settings` would build for `m` with `bonds` bonds, allocating
    /// nothing large. Errors: the density grid cannot be laid out (no atoms, bad resolution).
    pub fn new(
        m: &Molecule,
        bonds: usize,
        settings: &SceneSettings,
    ) -> Result<MemoryEstimate, SceneError> {
        let mut e = MemoryEstimate {
            atoms: m.memory_bytes() as u64,
            ..MemoryEstimate::default()
        };
        if let Some(ms) = &settings.model {
            let (bonds, prims) = model_prim_count(m.len(), bonds, ms);
            e.bonds = bonds as u64 * 8;
            e.geometry = m.len() as u64 * 20 + bonds as u64 * 8 + prims as u64 * 8;
            let nodes = (prims as f64 * BVH_NODES_PER_PRIM).ceil() as u64;
            e.bvh = nodes * NODE_BYTES + prims as u64 * SLOT_BYTES;
            if ms.wide_bvh {
                e.wide_bvh = (prims as f64 * WIDE_NODES_PER_PRIM).ceil() as u64 * WIDE_NODE_BYTES;
            }
        }
        if let Some(vs) = &settings.volume {
            let grid = density_grid(m, vs)?;
            e.volume = grid.voxel_count() * vs.format.bytes_per_voxel() + 4;
            e.volume_dims = Some(grid.dims);
            e.macrocells = macrocell_count(&grid) * 8;
            if let Some(lv) = &vs.light_volume {
                e.light_volume = grid
                    .dims
                    .iter()
                    .map(|&d| ((d - 1).div_ceil(lv.stride.max(1)) + 1) as u64)
                    .product();
            }
        }
        if let Some((w, h)) = settings.frame {
            e.framebuffer = w as u64 * h as u64 * 16;
        }
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
        if let Some(d) = &scene.volume {
            e.volume = d.volume.bytes();
            e.volume_dims = Some(d.volume.grid.dims);
            e.macrocells = d.cells.bytes();
        }
        if let Some(lv) = &scene.light_volume {
            e.light_volume = lv.bytes();
        }
        if let Some((w, h)) = scene.settings.frame {
            e.framebuffer = w as u64 * h as u64 * 16;
        }
        e
    }

    /// Sum of the components (bytes).
    pub fn total(&self) -> u64 {
        self.components().iter().map(|(_, b)| b).sum()
    }

    /// `(name, bytes)` of every component, in a fixed order.
    pub fn components(&self) -> [(&'static str, u64); 9] {
        [
            ("atoms", self.atoms),
            ("bonds", self.bonds),
            ("geometry", self.geometry),
            ("bvh", self.bvh),
            ("wide_bvh", self.wide_bvh),
            ("volume", self.volume),
            ("macrocells", self.macrocells),
            ("light_volume", self.light_volume),
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

/// Macrocells of a grid, as [`volume::Macrocells::build`] lays them out.
fn macrocell_count(g: &Grid) -> u64 {
    g.dims
        .iter()
        .map(|&d| (d - 1).div_ceil(MACROCELL).max(1) as u64)
        .product()
}
