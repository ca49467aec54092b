//! Path-tracing integrator: progressive, linear radiance; metal (Schlick Fresnel, blurred
//! mirror) or diffuse BRDF with next-event estimation of the light; environment = background.

use bvh::{Query, RayPacket, Stacks};
use scene::Model;
use spmd::{Simd, V3};

use super::direct::visibility;
use super::{spawn, trace, trace_secondary, TileJob};
use crate::rng::{cosine_dir, unit_vector, Rng};
use crate::settings::{Material, Modality};

/// One path of a packet of camera rays (`bounce`: the query of bounced rays, `q`: of light
/// samples).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn sample<S: Simd>(
    s: S,
    k: &TileJob<'_>,
    model: &Model,
    bounce: &Query,
    q: &Query,
    ray: &RayPacket<S>,
    rng: &mut Rng<S>,
    st: &mut Stacks,
) -> V3<S> {
    let Modality::Path {
        material,
        max_depth,
        roughness,
    } = k.set.modality
    else {
        unreachable!("path::sample of another modality")
    };
    let opt = k.set;
    let bg = V3::splat(s, opt.background_unit());
    let zero = s.splat(0.0);
    let one = s.splat(1.0);
    let env = bg * bg;
    let mut radiance = V3::splat(s, [0.0; 3]);
    let mut tp = V3::splat(s, [1.0; 3]);
    let mut r = *ray;
    for depth in 0..max_depth.max(1) {
        // Camera rays are coherent (packets); bounced rays use `opt.bounces`.
        let tr = if depth == 0 {
            trace(s, Some(model), None, &r, st.packet())
        } else {
            trace_secondary(s, model, bounce, &r, st)
        };
        let miss = r.active & !tr.mask;
        radiance = V3::select(s, miss, radiance + tp * env, radiance);
        let alive = tr.mask;
        if s.none(alive) {
            break;
        }
        let albedo = tr.color * tr.color;
        let o = spawn(s, model, &tr);
        let n = tr.n;
        let nd;
        let mut alive2 = alive;
        match material {
            Material::Diffuse => {
                if opt.light_intensity > 0.0 {
                    let (l, dist) = opt.light.towards(s, o);
                    let ndl = s.max(n.dot(l), zero);
                    let lit = alive & s.gt(ndl, zero);
                    if s.any(lit) {
                        let vis = visibility(s, k, q, o, l, dist, lit, st);
                        let e = s.splat(opt.light_intensity) * ndl * vis;
                        radiance = V3::select(s, lit, radiance + (tp * albedo).scale(e), radiance);
                    }
                }
                nd = cosine_dir(s, n, rng);
                tp = V3::select(s, alive, tp * albedo, tp);
            }
            Material::Metal => {
                let cos_i = -(r.d.dot(n));
                let refl = r.d.mul_add(n, cos_i + cos_i);
                let fuzz = unit_vector(s, rng).scale(s.splat(roughness));
                let d2 = refl + fuzz;
                let l2 = d2.dot(d2);
                let ok = s.gt(l2, s.splat(1e-12));
                let d2 = d2.scale(s.rsqrt(s.select(ok, l2, one)));
                let d2 = V3::select(s, ok, d2, refl);
                // Absorbed when the blurred direction points into the surface.
                alive2 = alive & s.gt(d2.dot(n), zero);
                // Schlick: F = F0 + (1 − F0)(1 − cos)^5.
                let m1 = s.max(one - s.max(cos_i, zero), zero);
                let m2 = m1 * m1;
                let m5 = m2 * m2 * m1;
                let f = albedo + (V3::splat(s, [1.0; 3]) - albedo).scale(m5);
                tp = V3::select(s, alive, tp * f, tp);
                nd = d2;
            }
        }
        r = RayPacket {
            o,
            d: nd,
            tmin: zero,
            tmax: s.splat(f32::INFINITY),
            active: alive2,
        };
    }
    radiance
}
