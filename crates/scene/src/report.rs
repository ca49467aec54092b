//! What a build made and what it took, one line per stage, for `-v` and progress logs.

use crate::build::Scene;
use crate::Density;

impl Scene {
    /// One line per built stage (`unwrap:`, `bonds:`, `bvh:`, `volume:`, `light:`): wall time (s), size
    /// and the figures a user checks first (BVH nodes and SAH cost, lattice points, MB). The
    /// `bvh:` line gives bytes per atom in all (the kernels' primitive records + nodes and ids), then
    /// each part, and the build rate in million primitives per second.
    pub fn stage_report(&self) -> Vec<String> {
        let mut out = Vec::new();
        let t = &self.timings;
        if let Some(u) = &self.unwrap {
            out.push(u.describe());
        }
        if let Some(model) = &self.model {
            out.push(format!(
                "bonds:   {:.3} s  {} bonds",
                t.bonds,
                self.bonds.len()
            ));
            let st = &model.bvh.stats;
            out.push(format!(
                "bvh:     {:.3} s  {} prims, {} nodes, SAH {:.1}, {:.1} MB ({:.1} B/atom): records {:.1} + nodes {:.1} B/atom, {:.2} M prims/s, scene build {:.3} s",
                st.build_time.as_secs_f64(),
                st.prims,
                st.nodes,
                st.sah_cost,
                st.bytes as f64 / 1e6,
                st.bytes_per_atom(),
                st.record_bytes_per_atom(),
                st.node_bytes_per_atom(),
                st.prims_per_second() * 1e-6,
                t.model
            ));
        }
        if let (Some(d), Some(vs)) = (&self.volume, &self.settings.volume) {
            out.push(match &d.density {
                Density::Grid { volume, .. } => format!(
                    "volume:  {:.3} s  {:?} lattice points at {} /Å, {:.1} MB {}",
                    t.volume + t.macrocells,
                    volume.grid.dims,
                    vs.voxels_per_angstrom,
                    volume.bytes() as f64 / 1e6,
                    volume.format().name()
                ),
                Density::Particles(p) => format!(
                    "volume:  {:.3} s  grid-free, {} atoms in a BVH of {} nodes, step {:.3} Å, \
                     {:.1} MB ({:.1} B/atom), max density {:.3}",
                    t.volume + t.macrocells,
                    p.radius.len(),
                    p.bvh.stats.nodes,
                    vs.step_voxels / vs.voxels_per_angstrom,
                    p.bytes() as f64 / 1e6,
                    p.bytes() as f64 / p.radius.len().max(1) as f64,
                    p.max_value
                ),
            });
        }
        if let Some(lv) = &self.light_volume {
            out.push(format!(
                "light:   {:.3} s  light volume {:?} (every {} voxels), {:.1} MB",
                t.light_volume,
                lv.grid.dims,
                lv.stride,
                lv.bytes() as f64 / 1e6
            ));
        }
        out
    }
}
