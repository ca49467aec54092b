//! `Bvh::sphere_spans` against brute force: every sphere a ray passes through within a range,
//! none missed and none invented, on random molecules with sticks, for random ranges, point
//! queries and degenerate rays.

use bvh::scenes::{random_molecule, Rng};
use bvh::{Bvh, Span, WideBvh};
use spmd::{Isa, Kernel, Simd};

/// Chord of the ray through sphere `i` with its radius times `k`, in f64, if it overlaps
/// `[lo, hi]`.
fn brute(
    g: &bvh::Geometry,
    o: [f64; 3],
    d: [f64; 3],
    lo: f64,
    hi: f64,
    i: usize,
    k: f64,
) -> Option<(f64, f64)> {
    let b = &g.balls;
    let c = [b.x[i] as f64, b.y[i] as f64, b.z[i] as f64];
    let r = b.radius[i] as f64 * k;
    let oc = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let tc = -(oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2]) / dd;
    let p = [oc[0] + tc * d[0], oc[1] + tc * d[1], oc[2] + tc * d[2]];
    let h2 = r * r - (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    if h2 < 0.0 {
        return None;
    }
    let h = (h2 / dd).sqrt();
    let (t0, t1) = (tc - h, tc + h);
    (t0 <= hi && t1 >= lo).then_some((t0, t1))
}

/// `WideBvh::sphere_spans` of one ray on a backend.
struct WideSpans<'a> {
    bvh: &'a Bvh,
    wide: &'a WideBvh,
    o: [f32; 3],
    d: [f32; 3],
    lo: f32,
    hi: f32,
}

impl Kernel for WideSpans<'_> {
    type Output = Vec<Span>;
    fn run<S: Simd>(self, s: S) -> Vec<Span> {
        let mut stack = vec![0u32; self.wide.spans_stack_size()];
        let mut out = Vec::new();
        self.wide.sphere_spans(
            s, self.bvh, self.o, self.d, self.lo, self.hi, &mut stack, &mut out,
        );
        out
    }
}

#[test]
fn spans_match_brute_force() {
    let (mut found, mut rays) = (0usize, 0usize);
    for (n, clustered, seed) in [(300, false, 1), (2000, true, 2), (5000, false, 3)] {
        // Radii ×3: about the size of the support spheres of a density (√2 × covalent).
        let mut g = random_molecule(n, clustered, seed);
        g.balls.radius.iter_mut().for_each(|r| *r *= 3.0);
        let bvh = Bvh::build(&g);
        bvh.validate(&g).unwrap();
        let wide = WideBvh::new(&bvh);
        wide.validate(&bvh, &g).unwrap();
        let lo_b = bvh.bounds.min;
        let hi_b = bvh.bounds.max;
        let mut rng = Rng(seed + 100);
        let mut stack = vec![0u32; bvh.stack_size()];
        let mut out: Vec<Span> = Vec::new();
        for k in 0..400 {
            // Towards a point inside the bounds from outside, direction length on a log scale.
            let at: [f64; 3] = std::array::from_fn(|a| rng.range(lo_b[a] as f64, hi_b[a] as f64));
            let u = rng.dir();
            let len = 10f64.powf(rng.range(-2.0, 2.0));
            let d = u.map(|v| v * len);
            let back = 60.0 / len;
            let o: [f64; 3] = std::array::from_fn(|a| at[a] - d[a] * back);
            let (lo, hi) = match k % 4 {
                0 => (0.0, f64::INFINITY),
                1 => (back * rng.range(0.5, 1.0), back * rng.range(1.0, 1.5)),
                2 => (back, back), // a point query at `at`
                _ => (-f64::INFINITY, back),
            };
            let (of, df) = (o.map(|v| v as f32), d.map(|v| v as f32));
            out.clear();
            bvh.sphere_spans(of, df, lo as f32, hi as f32, &mut stack, &mut out);
            // The 8-wide tree lists the same spans, on every backend.
            let mut by_slot = out.clone();
            by_slot.sort_by_key(|s| s.slot);
            for isa in Isa::supported() {
                let mut w = isa.dispatch(WideSpans {
                    bvh: &bvh,
                    wide: &wide,
                    o: of,
                    d: df,
                    lo: lo as f32,
                    hi: hi as f32,
                });
                w.sort_by_key(|s| s.slot);
                assert_eq!(w, by_slot, "{isa} ray {k}: wide spans differ");
            }
            let mut slots: Vec<u32> = out.iter().map(|s| s.slot).collect();
            slots.sort_unstable();
            assert!(
                slots.windows(2).all(|w| w[0] != w[1]),
                "a sphere listed twice"
            );
            let (o64, d64) = (of.map(|v| v as f64), df.map(|v| v as f64));
            for slot in 0..bvh.prim_ids.len() {
                let id = bvh.prim_ids[slot] as usize;
                if id >= g.balls.len() {
                    assert!(
                        slots.binary_search(&(slot as u32)).is_err(),
                        "a stick listed"
                    );
                    continue;
                }
                // The span must cover the true chord and lie within the chord of a sphere
                // 2·10⁻⁴ larger (it is widened by 10⁻⁴ of the radius), up to f32 rounding.
                let want = brute(&g, o64, d64, lo, hi, id, 1.0);
                let outer = brute(&g, o64, d64, lo, hi, id, 1.0 + 2e-4);
                let got = out.iter().find(|s| s.slot == slot as u32);
                let tol = 1e-5 * (back + 1.0);
                match (want, got) {
                    (Some((t0, t1)), Some(s)) => {
                        let (o0, o1) = outer.unwrap();
                        let (s0, s1) = (s.t0 as f64, s.t1 as f64);
                        assert!(
                            s0 <= t0 + tol && s1 >= t1 - tol && s0 >= o0 - tol && s1 <= o1 + tol,
                            "ray {k} sphere {id}: span {s:?} vs brute force {t0}..{t1} (outer {o0}..{o1})"
                        );
                        found += 1;
                    }
                    (None, None) => {}
                    // Grazing: the widened chord may keep a sphere the ray just misses.
                    (None, Some(s)) => assert!(
                        outer.is_some(),
                        "ray {k} sphere {id}: listed {s:?}, brute force misses"
                    ),
                    (Some((t0, t1)), None) => {
                        assert!(
                            t1.min(hi) - t0.max(lo) <= tol,
                            "ray {k} sphere {id}: missed a chord {t0}..{t1} in [{lo}, {hi}]"
                        )
                    }
                }
            }
            rays += 1;
        }
    }
    assert!(
        found > rays,
        "rays must pass through spheres ({found} chords over {rays} rays)"
    );
}

#[test]
fn degenerate_rays_and_empty_ranges_give_nothing() {
    let g = random_molecule(500, true, 9);
    let bvh = Bvh::build(&g);
    let c = g.balls.center(0);
    let mut stack = vec![0u32; bvh.stack_size()];
    let mut out = Vec::new();
    let cases: [([f32; 3], [f32; 3], f32, f32); 6] = [
        (c, [0.0; 3], 0.0, 1.0),
        (c, [f32::NAN, 0.0, 1.0], 0.0, 1.0),
        (c, [0.0, f32::INFINITY, 1.0], 0.0, 1.0),
        ([f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, 1.0),
        (c, [1.0, 0.0, 0.0], 1.0, 0.0),
        (c, [1.0, 0.0, 0.0], f32::NAN, 1.0),
    ];
    let wide = WideBvh::new(&bvh);
    for (o, d, lo, hi) in cases {
        bvh.sphere_spans(o, d, lo, hi, &mut stack, &mut out);
        assert!(out.is_empty(), "{o:?} {d:?} [{lo}, {hi}] listed {out:?}");
        for isa in Isa::supported() {
            let w = isa.dispatch(WideSpans {
                bvh: &bvh,
                wide: &wide,
                o,
                d,
                lo,
                hi,
            });
            assert!(
                w.is_empty(),
                "{isa} wide: {o:?} {d:?} [{lo}, {hi}] listed {w:?}"
            );
        }
    }
    // An axis-parallel ray through a centre finds that atom.
    bvh.sphere_spans(c, [0.0, 0.0, 2.0], 0.0, 0.0, &mut stack, &mut out);
    assert!(out.iter().any(|s| bvh.prim_ids[s.slot as usize] == 0));
}
