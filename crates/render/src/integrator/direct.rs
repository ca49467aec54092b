//! Direct integrator (§4.5): diffuse shading from the light, with hard shadow rays when asked,
//! attenuated by the volume for soft shadows; the volume composited in front.

use bvh::{Query, RayPacket, Stacks};
use scene::Model;
use spmd::{Simd, V3};

use super::{over_rgb, spawn, trace, TileJob};
use crate::settings::Modality;

/// One Direct sample of a packet of camera rays.
#[inline(always)]
pub(super) fn sample<S: Simd>(
    s: S,
    k: &TileJob<'_>,
    model: &Model,
    q: &Query,
    ray: &RayPacket<S>,
    st: &mut Stacks,
) -> V3<S> {
    let shadows = matches!(k.set.modality, Modality::Direct { shadows: true });
    let opt = k.set;
    let bg = V3::splat(s, opt.background_unit());
    let zero = s.splat(0.0);
    let one = s.splat(1.0);
    let tr = trace(s, Some(model), k.volume, ray, st.packet());
    let mut c = bg;
    if s.any(tr.mask) {
        let o = spawn(s, model, &tr);
        let (l, dist) = opt.light.towards(s, o);
        let ndl = s.max(tr.n.dot(l), zero);
        let lit = tr.mask & s.gt(ndl, zero);
        let mut vis = s.select(lit, one, zero);
        if shadows && s.any(lit) {
            vis = visibility(s, k, q, o, l, dist, lit, st);
        }
        let shade = s.splat(opt.ambient) + s.splat(opt.light_intensity) * ndl * vis;
        c = V3::select(s, tr.mask, tr.color.scale(shade), bg);
    }
    over_rgb(s, tr.volume, c)
}

/// Visibility of the light along unit `l` from origins `o` over `(0, dist)` Å (lanes `m`):
/// 0 where geometry is in the way, else the volume's transmittance when volume shadows are
/// on, else 1.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn visibility<S: Simd>(
    s: S,
    k: &TileJob<'_>,
    q: &Query,
    o: V3<S>,
    l: V3<S>,
    dist: S::F32,
    m: S::M,
    st: &mut Stacks,
) -> S::F32 {
    let zero = s.splat(0.0);
    let one = s.splat(1.0);
    let sray = RayPacket {
        o,
        d: l,
        tmin: zero,
        tmax: dist,
        active: m,
    };
    let occ = q.occluded(s, &sray, st);
    let free = m & !occ;
    let mut vis = s.select(free, one, zero);
    if let (true, Some(vs)) = (k.set.volume_shadows, k.volume.and_then(|m| m.grid())) {
        if s.any(free) {
            let tr = volume::transmittance(s, vs, o, l, dist, free, k.set.shadow_step_voxels);
            vis = s.select(free, tr, vis);
        }
    }
    vis
}
