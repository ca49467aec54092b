//! Ray–primitive intersection kernels, generic over the SPMD backend (paper §4.3: a uniform
//! primitive against a packet of varying rays).
//!
//! Conventions: ray directions are unit vectors; distances `t` are in Å along the ray; a hit
//! counts when `tmin < t < tmax`. The kernels avoid `fma` and fast estimates, so every backend
//! gives bit-identical results. Non-finite inputs give misses (never a panic).

use spmd::{Simd, V3};

use crate::geometry::PrimRecord;
use crate::traverse::{PacketHit, RayPacket};

/// `|a| · sign(b)` with `select` (there are no float bit ops in [`Simd`]).
#[inline(always)]
fn copysign<S: Simd>(s: S, a: S::F32, b: S::F32) -> S::F32 {
    s.select(s.lt(b, s.splat(0.0)), -a, a)
}

/// Nearest root in `(tmin, tmax)` from the two roots `t0`, `t1` of a quadratic, each gated by
/// an extra validity mask (e.g. the finite extent of a cylinder).
#[inline(always)]
fn pick<S: Simd>(
    s: S,
    tn: S::F32,
    vn: S::M,
    tf: S::F32,
    vf: S::M,
    tmin: S::F32,
    tmax: S::F32,
) -> (S::M, S::F32) {
    let okn = vn & s.gt(tn, tmin) & s.lt(tn, tmax);
    let okf = vf & s.gt(tf, tmin) & s.lt(tf, tmax);
    (okn | okf, s.select(okn, tn, tf))
}

/// Ray–sphere (§4.3), in the numerically stable form of Haines et al., "Precision
/// Improvements for Ray/Sphere Intersection" (Ray Tracing Gems, ch. 7): the discriminant is
/// `r² − |f − (f·d)d|²` (distance from the centre to the line, no cancellation for distant
/// spheres) and the roots come from `q = b + sign(b)√Δ` as `c/q` and `q`.
///
/// `o`, `d`: ray origin (Å) and unit direction; `c`, `r`: centre and radius (Å).
/// Returns the lanes that hit in `(tmin, tmax)` and their nearest `t`.
#[inline(always)]
pub fn ray_sphere<S: Simd>(
    s: S,
    o: V3<S>,
    d: V3<S>,
    c: [f32; 3],
    r: f32,
    tmin: S::F32,
    tmax: S::F32,
) -> (S::M, S::F32) {
    let f = o - V3::splat(s, c);
    let b = -f.dot(d);
    let l = f.mul_add(d, b);
    let r2 = s.splat(r * r);
    let disc = r2 - l.dot(l);
    let hit = s.ge(disc, s.splat(0.0));
    let q = b + copysign(s, s.sqrt(s.max(disc, s.splat(0.0))), b);
    let cc = f.dot(f) - r2;
    let t0 = cc / q;
    let t1 = q;
    let tn = s.min(t0, t1);
    let tf = s.max(t0, t1);
    pick(s, tn, hit, tf, hit, tmin, tmax)
}

/// Ray–hemisphere cap of a capsule (§4.3, licorice sticks): [`ray_sphere`] keeping only the
/// roots on the outer side of the plane through `c` perpendicular to `axis`
/// (`(p − c)·axis · side ≥ 0`, `side` = −1 at the first endpoint, +1 at the second), so rays
/// from inside a capsule never stop at the part of a cap sphere inside the cylinder.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn ray_cap<S: Simd>(
    s: S,
    o: V3<S>,
    d: V3<S>,
    c: [f32; 3],
    axis: [f32; 3],
    side: f32,
    r: f32,
    tmin: S::F32,
    tmax: S::F32,
) -> (S::M, S::F32) {
    let f = o - V3::splat(s, c);
    let b = -f.dot(d);
    let l = f.mul_add(d, b);
    let r2 = s.splat(r * r);
    let disc = r2 - l.dot(l);
    let zero = s.splat(0.0);
    let hit = s.ge(disc, zero);
    let q = b + copysign(s, s.sqrt(s.max(disc, zero)), b);
    let cc = f.dot(f) - r2;
    let t0 = cc / q;
    let tn = s.min(t0, q);
    let tf = s.max(t0, q);
    let ax = V3::splat(s, [axis[0] * side, axis[1] * side, axis[2] * side]);
    let (fa, da) = (f.dot(ax), d.dot(ax));
    let vn = hit & s.ge(fa + tn * da, zero);
    let vf = hit & s.ge(fa + tf * da, zero);
    pick(s, tn, vn, tf, vf, tmin, tmax)
}

/// Ray–cylinder, finite and open (§4.3; the stick of a bond): the quadratic is solved in the
/// plane perpendicular to the axis with the same stable form as [`ray_sphere`]
/// (`Δ = r² − |f⊥ − (b/a)d⊥|²`, `a = |d⊥|²` computed from the projected vector, not as
/// `1 − (d·axis)²`), so grazing and near-parallel rays do not cancel catastrophically.
///
/// `p0`: first endpoint, `axis`: unit axis, `len`: length (Å), `r`: radius (Å). Hits beyond the
/// ends (`s ∉ [0, len]` along the axis) are rejected; rays parallel to the axis miss.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn ray_cylinder<S: Simd>(
    s: S,
    o: V3<S>,
    d: V3<S>,
    p0: [f32; 3],
    axis: [f32; 3],
    len: f32,
    r: f32,
    tmin: S::F32,
    tmax: S::F32,
) -> (S::M, S::F32) {
    let ax = V3::splat(s, axis);
    let f = o - V3::splat(s, p0);
    let fa = f.dot(ax);
    let da = d.dot(ax);
    let (hit, tn, tf) = tube(s, f - ax.scale(fa), d - ax.scale(da), r);
    let (zero, lenv) = (s.splat(0.0), s.splat(len));
    let sn = fa + tn * da;
    let sf = fa + tf * da;
    let vn = hit & s.ge(sn, zero) & s.le(sn, lenv);
    let vf = hit & s.ge(sf, zero) & s.le(sf, lenv);
    pick(s, tn, vn, tf, vf, tmin, tmax)
}

/// Near and far roots of `|f⊥ + t·d⊥|² = r²` (a ray against an infinite cylinder, in the plane
/// perpendicular to its axis) in [`ray_sphere`]'s stable form, and the lanes that have them
/// (`d⊥ ≠ 0`, real roots).
#[inline(always)]
fn tube<S: Simd>(s: S, fp: V3<S>, dp: V3<S>, r: f32) -> (S::M, S::F32, S::F32) {
    let a = dp.dot(dp);
    let b = fp.dot(dp);
    let r2 = s.splat(r * r);
    let l = fp - dp.scale(b / a);
    let disc = r2 - l.dot(l);
    let zero = s.splat(0.0);
    let hit = s.ge(disc, zero) & s.gt(a, zero);
    let q = -b - copysign(s, s.sqrt(s.max(a * disc, zero)), b);
    let t0 = (fp.dot(fp) - r2) / q;
    let t1 = q / a;
    (hit, s.min(t0, t1), s.max(t0, t1))
}

/// Ray–cylinder from `p` to `q` without a unit axis (§4.3, the compact layout's stick, issue
/// #19): the axis is `e = q − p` and positions along it are fractions of `e`, so the only
/// per-stick uniform work is `1/(e·e)` (no square root). Otherwise [`ray_cylinder`]'s stable
/// form. Hits outside the segment are rejected; degenerate sticks (`e = 0`) and rays parallel
/// to the axis miss.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn ray_bond<S: Simd>(
    s: S,
    o: V3<S>,
    d: V3<S>,
    p: [f32; 3],
    e: [f32; 3],
    r: f32,
    tmin: S::F32,
    tmax: S::F32,
) -> (S::M, S::F32) {
    let ee = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
    let zero = s.splat(0.0);
    if !(ee > 0.0 && ee.is_finite()) {
        return (s.splat_m(false), zero);
    }
    let inv = s.splat(1.0 / ee);
    let ev = V3::splat(s, e);
    let f = o - V3::splat(s, p);
    let fa = f.dot(ev) * inv;
    let da = d.dot(ev) * inv;
    let (hit, tn, tf) = tube(s, f - ev.scale(fa), d - ev.scale(da), r);
    let one = s.splat(1.0);
    let (un, uf) = (fa + tn * da, fa + tf * da);
    let vn = hit & s.ge(un, zero) & s.le(un, one);
    let vf = hit & s.ge(uf, zero) & s.le(uf, one);
    pick(s, tn, vn, tf, vf, tmin, tmax)
}

/// Leaf test of a stick from `p` to `q` for the compact layout: [`ray_bond`], and when
/// `capped` the hemispherical caps of [`ray_cap`] (whole spheres for a degenerate stick);
/// narrows `hit` as [`intersect_record`] does.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn intersect_bond<S: Simd>(
    s: S,
    ray: &RayPacket<S>,
    m: S::M,
    p: [f32; 3],
    q: [f32; 3],
    r: f32,
    capped: bool,
    slot: i32,
    hit: &mut PacketHit<S>,
) {
    let (o, d, tmin) = (ray.o, ray.d, ray.tmin);
    let e = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
    let (h, th) = ray_bond(s, o, d, p, e, r, tmin, hit.t);
    keep(s, h & m, th, slot, hit);
    if capped {
        for (c, side) in [(p, -1.0), (q, 1.0)] {
            let (h, th) = ray_cap(s, o, d, c, e, side, r, tmin, hit.t);
            keep(s, h & m, th, slot, hit);
        }
    }
}

/// Leaf test of a ball for the compact layout: [`ray_sphere`], narrowing `hit`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn intersect_ball<S: Simd>(
    s: S,
    ray: &RayPacket<S>,
    m: S::M,
    c: [f32; 3],
    r: f32,
    slot: i32,
    hit: &mut PacketHit<S>,
) {
    let (h, th) = ray_sphere(s, ray.o, ray.d, c, r, ray.tmin, hit.t);
    keep(s, h & m, th, slot, hit);
}

/// Leaf test (§4.3): intersects the lanes `m` of `ray` with one primitive record (sphere, open
/// cylinder, or capsule = cylinder with hemispherical caps when `capped`), narrowing `hit.t` and
/// recording `slot` in `hit.slot` where a lane hits nearer. Lanes off in `m` are untouched.
#[inline(always)]
pub fn intersect_record<S: Simd>(
    s: S,
    ray: &RayPacket<S>,
    m: S::M,
    rec: &PrimRecord,
    capped: bool,
    slot: i32,
    hit: &mut PacketHit<S>,
) {
    let (o, d, tmin) = (ray.o, ray.d, ray.tmin);
    if rec.is_sphere() {
        let (h, th) = ray_sphere(s, o, d, rec.p0, rec.r, tmin, hit.t);
        keep(s, h & m, th, slot, hit);
        return;
    }
    if rec.len > 0.0 {
        let (h, th) = ray_cylinder(s, o, d, rec.p0, rec.axis, rec.len, rec.r, tmin, hit.t);
        keep(s, h & m, th, slot, hit);
    }
    if capped {
        let p1 = end_point(rec);
        // Degenerate sticks (no axis) are capped by a whole sphere: both halves.
        let ax = if rec.len > 0.0 { rec.axis } else { [0.0; 3] };
        for (c, side) in [(rec.p0, -1.0), (p1, 1.0)] {
            let (h, th) = ray_cap(s, o, d, c, ax, side, rec.r, tmin, hit.t);
            keep(s, h & m, th, slot, hit);
        }
    }
}

/// Takes the nearer hit `th` in the lanes `h` as primitive `slot`.
#[inline(always)]
fn keep<S: Simd>(s: S, h: S::M, th: S::F32, slot: i32, hit: &mut PacketHit<S>) {
    hit.t = s.select(h, th, hit.t);
    hit.slot = s.select_i(h, s.splat_i(slot), hit.slot);
}

/// Second endpoint of a stick record (`p0 + axis·len`; `p0` for degenerate sticks).
#[inline(always)]
pub fn end_point(rec: &PrimRecord) -> [f32; 3] {
    let l = rec.len.max(0.0);
    [
        rec.p0[0] + rec.axis[0] * l,
        rec.p0[1] + rec.axis[1] * l,
        rec.p0[2] + rec.axis[2] * l,
    ]
}

/// Surface data at a hit, per lane.
#[derive(Clone, Copy, Debug)]
pub struct Surface<S: Simd> {
    /// Unit outward normal.
    pub n: V3<S>,
    /// On a stick: the hit lies on the half of the second atom (`b`). False on balls.
    pub second_half: S::M,
}

/// Normal (and stick half) at the hits `t` / `slot` of a packet (deferred from traversal:
/// computed once per ray from the record gathered by slot). Lanes off in `m` get garbage.
///
/// The normal is `p − closest point on the primitive's axis segment`, normalised, with
/// `p − p0` formed as `(o − p0) + t·d` so it stays accurate far from the origin. For spheres
/// the segment is the centre; for capsules the clamp makes the caps round.
#[inline(always)]
pub fn surface<S: Simd>(
    s: S,
    records: &[PrimRecord],
    o: V3<S>,
    d: V3<S>,
    t: S::F32,
    slot: S::I32,
    m: S::M,
) -> Surface<S> {
    let flat: &[f32] = bytemuck::cast_slice(records);
    let base = s.shl(slot, 3);
    let zero = s.splat(0.0);
    // (No closures on the hot path: they would not inherit the entry point's target features.)
    let p0 = V3::new(
        gather_at(s, flat, base, 0, m),
        gather_at(s, flat, base, 1, m),
        gather_at(s, flat, base, 2, m),
    );
    let ax = V3::new(
        gather_at(s, flat, base, 4, m),
        gather_at(s, flat, base, 5, m),
        gather_at(s, flat, base, 6, m),
    );
    let len = gather_at(s, flat, base, 7, m);
    let pr = (o - p0).mul_add(d, t);
    let lenc = s.max(len, zero);
    let along = s.min(s.max(pr.dot(ax), zero), lenc);
    let n = (pr - ax.scale(along)).normalize(s);
    Surface {
        n,
        second_half: s.gt(along + along, lenc) & s.gt(lenc, zero),
    }
}

#[inline(always)]
fn gather_at<S: Simd>(s: S, flat: &[f32], base: S::I32, k: i32, m: S::M) -> S::F32 {
    s.gather(flat, base + s.splat_i(k), m, s.splat(0.0))
}
