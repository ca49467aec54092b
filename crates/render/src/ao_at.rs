//! Ambient occlusion at given surface points: the AO integrator outside the frame driver, for
//! tests and tools.

use scene::Model;
use spmd::{Isa, Kernel, Simd, V3};

use crate::integrator::{ao_factor, query, stacks};
use crate::rng::Rng;
use crate::settings::SecondaryTraversal;

/// Ambient occlusion at given surface points (Å) with outward unit normals: the fraction of
/// `samples` cosine-distributed rays from each point (offset along its normal by `offset` Å)
/// that travel `distance` Å without hitting geometry. Random numbers as in the renderer with
/// the point index as the pixel index. For tests and tools.
#[allow(clippy::too_many_arguments)]
pub fn ambient_occlusion_at(
    scene: &Model,
    points: &[[f32; 3]],
    normals: &[[f32; 3]],
    samples: u32,
    distance: f32,
    offset: f32,
    seed: u32,
    isa: Isa,
) -> Vec<f32> {
    assert_eq!(points.len(), normals.len());
    isa.dispatch(AoAtKernel {
        scene,
        points,
        normals,
        samples,
        distance,
        offset,
        seed,
    })
}

struct AoAtKernel<'a> {
    scene: &'a Model,
    points: &'a [[f32; 3]],
    normals: &'a [[f32; 3]],
    samples: u32,
    distance: f32,
    offset: f32,
    seed: u32,
}

impl Kernel for AoAtKernel<'_> {
    type Output = Vec<f32>;
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.points.len());
        let mut stack = stacks(self.scene, false);
        let q = query(self.scene, SecondaryTraversal::Packet, false);
        let mut buf = [[0.0f32; spmd::MAX_LANES]; 6];
        let mut res = [0.0f32; spmd::MAX_LANES];
        for (c, (pts, nrm)) in self
            .points
            .chunks(S::LANES)
            .zip(self.normals.chunks(S::LANES))
            .enumerate()
        {
            for i in 0..S::LANES {
                let (p, n) = if i < pts.len() {
                    (pts[i], nrm[i])
                } else {
                    ([0.0; 3], [0.0, 0.0, 1.0])
                };
                for a in 0..3 {
                    buf[a][i] = p[a] + n[a] * self.offset;
                    buf[3 + a][i] = n[a];
                }
            }
            let o = V3::new(s.load(&buf[0]), s.load(&buf[1]), s.load(&buf[2]));
            let n = V3::new(s.load(&buf[3]), s.load(&buf[4]), s.load(&buf[5]));
            let m = s.first_n(pts.len());
            let pixel = s.lane_index() + s.splat_i((c * S::LANES) as i32);
            let mut rng = Rng::new(s, self.seed, pixel, 0);
            let ao = ao_factor(
                s,
                &q,
                o,
                n,
                m,
                self.samples,
                self.distance,
                &mut rng,
                &mut stack,
            );
            s.store(ao, &mut res);
            out.extend_from_slice(&res[..pts.len()]);
        }
        out
    }
}
