//! The records of a run: one [`Preprocess`] per scene, one [`Measurement`] per key and ISA.

use molecule::scenes::SceneName;
use render::Model;
use spmd::Isa;

use crate::plan::{Key, Tables};

/// The timed frames of one key on one ISA.
#[derive(Clone, Debug, PartialEq)]
pub struct Measurement {
    /// What was measured.
    pub key: Key,
    /// The paper's tables it belongs to.
    pub tables: Tables,
    /// Atoms of the scene.
    pub atoms: usize,
    /// The SIMD backend.
    pub isa: Isa,
    /// Time of every timed frame (ms), in order.
    pub ms: Vec<f64>,
    /// 1-minute load average after the frames.
    pub load1: f64,
}

impl Measurement {
    /// The frame times (ms), ascending.
    pub fn sorted(&self) -> Vec<f64> {
        let mut v = self.ms.clone();
        v.sort_by(f64::total_cmp);
        v
    }
    /// Median frame time (ms; NaN without frames).
    pub fn ms_median(&self) -> f64 {
        let v = self.sorted();
        let n = v.len();
        if n == 0 {
            f64::NAN
        } else if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    }
    /// Frames per second of the median frame.
    pub fn fps(&self) -> f64 {
        1000.0 / self.ms_median()
    }
    /// Primary rays (one per pixel) per second of the median frame, in millions.
    pub fn mrays(&self) -> f64 {
        (self.key.w as f64 * self.key.h as f64) / (self.ms_median() * 1e-3) * 1e-6
    }
}

/// The preprocessing of one scene: sizes, build times, memory.
#[derive(Clone, Debug, PartialEq)]
pub struct Preprocess {
    /// The scene.
    pub scene: SceneName,
    /// Atoms.
    pub atoms: usize,
    /// Bonds.
    pub bonds: usize,
    /// Generating the atoms (s).
    pub load_s: f64,
    /// Building the bonds (s).
    pub bond_s: f64,
    /// Building the BVH (s), if built.
    pub bvh_s: Option<f64>,
    /// Building the density volume and macrocells (s), if built.
    pub volume_s: Option<f64>,
    /// Bytes of the ball-and-stick geometry (see [`model_bytes`]).
    pub geometry_bytes: Option<u64>,
    /// Bytes of the BVH proper.
    pub bvh_bytes: Option<u64>,
    /// Bytes of the density volume and its macrocells.
    pub volume_bytes: Option<u64>,
    /// Density resolution (voxels per Å).
    pub voxels_per_angstrom: f32,
    /// Voxels of the density volume per axis.
    pub volume_dims: Option<[usize; 3]>,
    /// Peak RSS (MB) after preprocessing.
    pub peak_rss_mb: Option<f64>,
    /// Whether the peak was reset before this scene (else it is the process's so far).
    pub peak_rss_reset: bool,
}

/// Megabytes (10⁶ bytes) of `b` bytes.
pub fn mb(b: u64) -> f64 {
    b as f64 / 1e6
}

impl Preprocess {
    /// Geometry + BVH bytes per atom.
    pub fn bytes_per_atom(&self) -> Option<f64> {
        match (self.geometry_bytes, self.bvh_bytes) {
            (Some(g), Some(b)) => Some((g + b) as f64 / self.atoms.max(1) as f64),
            _ => None,
        }
    }
}

/// Bytes of the ball-and-stick geometry (balls, sticks, the kernels' primitive records and
/// per-slot colours) and of the BVH proper (nodes and slot → primitive ids), the split of the
/// paper's "geometry size" and "BVH size".
pub fn model_bytes(s: &Model) -> (u64, u64) {
    let b = &s.geometry.balls;
    let geometry = std::mem::size_of_val(&b.x[..])
        + std::mem::size_of_val(&b.y[..])
        + std::mem::size_of_val(&b.z[..])
        + std::mem::size_of_val(&b.radius[..])
        + std::mem::size_of_val(&b.color[..])
        + std::mem::size_of_val(&s.geometry.sticks.a[..])
        + std::mem::size_of_val(&s.geometry.sticks.b[..])
        + std::mem::size_of_val(&s.bvh.records[..])
        + std::mem::size_of_val(&s.slot_color_a[..])
        + std::mem::size_of_val(&s.slot_color_b[..]);
    let bvh = std::mem::size_of_val(&s.bvh.nodes[..]) + std::mem::size_of_val(&s.bvh.prim_ids[..]);
    (geometry as u64, bvh as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_even_and_odd_counts() {
        let mut m = Measurement {
            key: Key {
                scene: SceneName::Nanobowl,
                mode: crate::BenchMode::Bs,
                far: true,
                w: 10,
                h: 10,
                threads: 1,
            },
            tables: Tables::T3,
            atoms: 1,
            isa: Isa::Scalar,
            ms: vec![3.0, 1.0, 2.0],
            load1: 0.0,
        };
        assert_eq!(m.ms_median(), 2.0);
        m.ms.push(10.0);
        assert_eq!(m.ms_median(), 2.5);
        assert_eq!(m.fps(), 400.0);
        assert!((m.mrays() - 100.0 / 2.5e-3 * 1e-6).abs() < 1e-12);
        m.ms.clear();
        assert!(m.ms_median().is_nan());
    }
}
