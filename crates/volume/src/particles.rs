//! Grid-free RBF volumes: the density Φ(x) = Σᵢ √rᵢ·exp(−d²/rᵢ²) over atoms with d < √2·rᵢ
//! evaluated at each sample from the atoms themselves, found through a BVH over their support
//! spheres (radius √2·rᵢ) — the paper's future work, published by Knoll et al. as "RBF volume
//! ray casting on multicore and many-core CPUs" (EuroVis 2014). Memory grows with the atoms
//! (≈ 80 B/atom), not with the voxels; the marcher is [`crate::particle_march`].

use bvh::{Bvh, Geometry, Span, WideBvh};
use rayon::prelude::*;

use crate::grid::Grid;
use crate::VolumeError;

/// The atoms of a grid-free density volume and the BVH over their support spheres.
#[derive(Clone, Debug)]
pub struct Particles {
    /// BVH over the support spheres: its records hold each atom's centre (Å) and support
    /// radius √2·rᵢ (Å).
    pub bvh: Bvh,
    /// Its 8-wide collapse, which the marcher walks.
    pub wide: WideBvh,
    /// rᵢ (Å) per BVH slot: the Gaussian's width, computed from the caller's radii exactly as
    /// the grid path does.
    pub radius: Vec<f32>,
    /// The lattice the grid path would sample at the same resolution: its box bounds the
    /// march and its spacing sets the step (0.5 voxel), so samples lie where the grid path's
    /// do. No voxel is stored.
    pub grid: Grid,
    /// Largest density at an atom centre (density units): the default top of the transfer
    /// function's range.
    pub max_value: f32,
}

impl Particles {
    /// Builds the BVH over the atoms' support spheres (positions and covalent radii `r` in Å,
    /// as [`crate::build_density`] takes them) and finds the density's maximum over the atom
    /// centres. `voxels_per_angstrom` only sets the sample spacing and the box.
    pub fn build(
        x: &[f32],
        y: &[f32],
        z: &[f32],
        r: &[f32],
        voxels_per_angstrom: f32,
    ) -> Result<Particles, VolumeError> {
        let grid = Grid::for_atoms(x, y, z, r, voxels_per_angstrom)?;
        let support: Vec<f32> = r.iter().map(|&ri| core::f32::consts::SQRT_2 * ri).collect();
        let g = Geometry::from_atoms(x, y, z, &support, &[], &[], 0.0);
        drop(support);
        let bvh = Bvh::build(&g);
        drop(g);
        let radius = bvh.prim_ids.iter().map(|&id| r[id as usize]).collect();
        let wide = WideBvh::new(&bvh);
        let mut p = Particles {
            wide,
            bvh,
            radius,
            grid,
            max_value: 0.0,
        };
        p.max_value = p
            .bvh
            .records
            .par_iter()
            .map_init(
                || (vec![0u32; p.bvh.stack_size()], Vec::new()),
                |(stack, spans), rec| p.density_with(rec.p0, stack, spans),
            )
            .reduce(|| 0.0, f32::max);
        Ok(p)
    }

    /// Bytes held: the BVHs (nodes, ids, records, wide nodes) and the radii.
    pub fn bytes(&self) -> u64 {
        (self.bvh.stats.bytes + self.wide.bytes() + self.radius.len() * 4) as u64
    }

    /// Bytes [`Particles::build`] holds for `atoms` atoms once built (≈ 80 per atom: 32-byte
    /// records, ids and radii, about 0.7 binary nodes of 32 bytes and 0.07 wide nodes of
    /// 256 bytes per atom; measured 75-77).
    pub fn estimate_bytes(atoms: u64) -> u64 {
        atoms * (32 + 4 + 4) + atoms * 7 / 10 * 32 + atoms * 7 / 100 * 256
    }

    /// Φ at `p` (Å), f32, as the marcher sums it.
    pub fn density(&self, p: [f32; 3]) -> f32 {
        self.density_with(p, &mut vec![0u32; self.bvh.stack_size()], &mut Vec::new())
    }

    fn density_with(&self, p: [f32; 3], stack: &mut [u32], spans: &mut Vec<Span>) -> f32 {
        spans.clear();
        self.bvh
            .sphere_spans(p, [1.0, 0.0, 0.0], 0.0, 0.0, stack, spans);
        spans
            .iter()
            .map(|sp| {
                let c = self.bvh.records[sp.slot as usize].p0;
                let r = self.radius[sp.slot as usize];
                let d2 = (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2);
                if d2 < 2.0 * r * r {
                    r.sqrt() * (-d2 / (r * r)).exp()
                } else {
                    0.0
                }
            })
            .sum()
    }
}
