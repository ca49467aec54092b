//! Ambient-occlusion integrator: atom colour × the fraction of cosine-distributed rays from
//! the hit that travel the AO distance unoccluded; the volume composited in front.

use bvh::{Query, RayPacket, Stacks};
use scene::Model;
use spmd::{Simd, V3};

use super::{over_rgb, spawn, trace, TileJob};
use crate::rng::{cosine_dir, Rng};
use crate::settings::Modality;

/// One AO sample of a packet of camera rays.
#[inline(always)]
pub(super) fn sample<S: Simd>(
    s: S,
    k: &TileJob<'_>,
    model: &Model,
    q: &Query,
    ray: &RayPacket<S>,
    rng: &mut Rng<S>,
    st: &mut Stacks,
) -> V3<S> {
    let Modality::Ao { samples, distance } = k.set.modality else {
        unreachable!("ao::sample of another modality")
    };
    let opt = k.set;
    let bg = V3::splat(s, opt.background_unit());
    let tr = trace(s, Some(model), k.volume, ray, st.packet());
    let mut c = bg;
    if s.any(tr.mask) {
        let o = spawn(s, model, &tr);
        let ao = ao_factor(s, q, o, tr.n, tr.mask, samples, distance, rng, st);
        c = V3::select(s, tr.mask, tr.color.scale(ao), bg);
    }
    over_rgb(s, tr.volume, c)
}

/// Fraction of `samples` cosine-distributed rays from `o` about `n` that travel `distance`
/// without hitting geometry (lanes `m`; 0 elsewhere).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn ao_factor<S: Simd>(
    s: S,
    q: &Query,
    o: V3<S>,
    n: V3<S>,
    m: S::M,
    samples: u32,
    distance: f32,
    rng: &mut Rng<S>,
    st: &mut Stacks,
) -> S::F32 {
    let zero = s.splat(0.0);
    let one = s.splat(1.0);
    let mut free = zero;
    let n_samples = samples.max(1);
    for _ in 0..n_samples {
        let d = cosine_dir(s, n, rng);
        let ray = RayPacket {
            o,
            d,
            tmin: zero,
            tmax: s.splat(distance),
            active: m,
        };
        let occ = q.occluded(s, &ray, st);
        free += s.select(m & !occ, one, zero);
    }
    free * s.splat(1.0 / n_samples as f32)
}
