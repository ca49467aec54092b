//! Camera rays by blocks (`Bvh::traverse_blocks`): the nearest hits of every pixel equal brute
//! force over all primitives, on every backend, for perspective and orthographic cameras
//! inside and outside the scene, fields of view drawn on a log scale, frames whose edges cut
//! blocks, and degenerate (NaN, zero-size) cameras.

use bvh::scenes::random_molecule;
use bvh::{load_packet, Bvh, Corners, Frusta, Geometry, Origin, PacketHit, Ray};
use spmd::{Isa, Kernel, Simd};

/// A pinhole or orthographic camera over a `w × h` frame: pixel (px, py) (centres at +0.5)
/// looks along `dir0 + du·px + dv·py` from `org` (perspective) or along `dir0` from
/// `org + du·px + dv·py` (orthographic).
#[derive(Clone, Copy)]
struct Cam {
    perspective: bool,
    org: [f64; 3],
    dir0: [f64; 3],
    du: [f64; 3],
    dv: [f64; 3],
    w: usize,
    h: usize,
}

impl Cam {
    fn at(&self, px: f64, py: f64) -> ([f64; 3], [f64; 3]) {
        let step = [0, 1, 2].map(|a| self.du[a] * px + self.dv[a] * py);
        if self.perspective {
            (self.org, [0, 1, 2].map(|a| self.dir0[a] + step[a]))
        } else {
            ([0, 1, 2].map(|a| self.org[a] + step[a]), self.dir0)
        }
    }
    fn ray(&self, x: usize, y: usize) -> Ray {
        let (o, d) = self.at(x as f64 + 0.5, y as f64 + 0.5);
        let f = |v: [f64; 3]| v.map(|c| c as f32);
        Ray::new(f(o), f(d))
    }
    fn origin(&self) -> Origin {
        let f = |v: [f64; 3]| v.map(|c| c as f32);
        if self.perspective {
            Origin::Point(f(self.org))
        } else {
            let n = self.dir0.iter().map(|c| c * c).sum::<f64>().sqrt();
            Origin::Plane {
                org: f(self.org),
                forward: f(self.dir0.map(|c| c / n)),
            }
        }
    }
}

/// Every pixel's nearest hit (t, slot) by `traverse_blocks`, groups of LANES blocks of LANES
/// rays as the renderer makes them.
struct Frame<'a> {
    bvh: &'a Bvh,
    cam: Cam,
}

impl Kernel for Frame<'_> {
    type Output = Vec<(f32, i32)>;
    fn run<S: Simd>(self, s: S) -> Vec<(f32, i32)> {
        let c = self.cam;
        let bw = match S::LANES {
            16 | 8 => 4,
            4 => 2,
            _ => 1,
        };
        let bh = S::LANES / bw;
        let (gw, gh) = (bh, bw);
        let mut out = vec![(f32::NAN, -2); c.w * c.h];
        let mut stack = vec![0u32; self.bvh.stack_size()];
        for gy in (0..c.h).step_by(bh * gh) {
            for gx in (0..c.w).step_by(bw * gw) {
                let mut rays = Vec::new();
                let mut corners = Vec::new();
                let mut present = 0u32;
                for b in 0..S::LANES {
                    let (bx, by) = (gx + (b % gw) * bw, gy + (b / gw) * bh);
                    let mut block = Vec::new();
                    for i in 0..S::LANES {
                        let (x, y) = (bx + i % bw, by + i / bw);
                        if x < c.w && y < c.h {
                            block.push(c.ray(x, y));
                        } else {
                            // Outside the frame: an inactive lane.
                            block.push(Ray {
                                tmax: f32::NAN,
                                ..c.ray(0, 0)
                            });
                        }
                    }
                    let mut p = load_packet(s, &block);
                    let mut inside = [false; 16];
                    for (i, v) in inside.iter_mut().enumerate().take(S::LANES) {
                        *v = bx + i % bw < c.w && by + i / bw < c.h;
                    }
                    let bits = (0..S::LANES).fold(0u32, |m, i| m | (inside[i] as u32) << i);
                    p.active = s.mask_from_bits(bits);
                    p.tmax = s.select(p.active, p.tmax, s.splat(0.0));
                    if bits != 0 {
                        present |= 1 << b;
                    }
                    rays.push(p);
                    let (x0, y0) = (bx as f64, by as f64);
                    let k = [
                        (x0, y0),
                        (x0 + bw as f64, y0),
                        (x0 + bw as f64, y0 + bh as f64),
                        (x0, y0 + bh as f64),
                    ];
                    let r = k.map(|(x, y)| c.at(x, y));
                    corners.push(Corners {
                        o: r.map(|v| v.0),
                        d: r.map(|v| v.1),
                    });
                }
                let centre = c.at((gx + bw * gw / 2) as f64, (gy + bh * gh / 2) as f64).1;
                let fr = Frusta::new(s, &corners, present, c.origin(), centre.map(|v| v as f32));
                let mut hits = vec![
                    PacketHit {
                        t: s.splat(0.0),
                        slot: s.splat_i(-1)
                    };
                    S::LANES
                ];
                self.bvh
                    .traverse_blocks(s, &fr, &rays, &mut hits, &mut stack);
                for (b, hit) in hits.iter().enumerate() {
                    let (bx, by) = (gx + (b % gw) * bw, gy + (b / gw) * bh);
                    for i in 0..S::LANES {
                        let (x, y) = (bx + i % bw, by + i / bw);
                        if x < c.w && y < c.h {
                            out[y * c.w + x] = (s.extract(hit.t, i), s.extract_i(hit.slot, i));
                        }
                    }
                }
            }
        }
        out
    }
}

/// Small deterministic generator (xorshift), values in [0, 1).
struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Log-uniform in [lo, hi].
    fn log(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + self.f() * (hi.ln() - lo.ln())).exp()
    }
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = a.iter().map(|c| c * c).sum::<f64>().sqrt();
    a.map(|c| c / n)
}

/// A camera looking from `eye` at `at` with vertical field `fov` (radians; orthographic
/// frame height `fov · distance` when not `perspective`).
fn camera(eye: [f64; 3], at: [f64; 3], fov: f64, perspective: bool, w: usize, h: usize) -> Cam {
    let f = unit([at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]]);
    let r = unit(cross(f, [0.3, 1.0, 0.1]));
    let u = cross(r, f);
    let (wf, hf) = (w as f64, h as f64);
    if perspective {
        let ty = (fov / 2.0).tan();
        let tx = ty * wf / hf;
        Cam {
            perspective,
            org: eye,
            dir0: [0, 1, 2].map(|a| f[a] - r[a] * tx + u[a] * ty),
            du: r.map(|c| c * 2.0 * tx / wf),
            dv: u.map(|c| -c * 2.0 * ty / hf),
            w,
            h,
        }
    } else {
        let dist = (0..3).map(|a| (at[a] - eye[a]).powi(2)).sum::<f64>().sqrt();
        let hh = 0.5 * fov * dist;
        let hw = hh * wf / hf;
        Cam {
            perspective,
            org: [0, 1, 2].map(|a| eye[a] - r[a] * hw + u[a] * hh),
            dir0: f,
            du: r.map(|c| c * 2.0 * hw / wf),
            dv: u.map(|c| -c * 2.0 * hh / hf),
            w,
            h,
        }
    }
}

/// Every pixel of `cam` on every backend against brute force on the same rays (same backend:
/// the same kernels, so `t` is bit-identical; ties may pick either primitive).
fn check(g: &Geometry, bvh: &Bvh, cam: Cam, what: &str) -> usize {
    let rays: Vec<Ray> = (0..cam.h)
        .flat_map(|y| (0..cam.w).map(move |x| (x, y)))
        .map(|(x, y)| cam.ray(x, y))
        .collect();
    let mut hits = 0;
    for isa in Isa::supported() {
        let brute = bvh.intersect_rays_brute(isa, &rays);
        let got = isa.dispatch(Frame { bvh, cam });
        for (i, (b, (t, slot))) in brute.iter().zip(&got).enumerate() {
            match b {
                None => assert_eq!(
                    *slot, -1,
                    "{what} {isa} pixel {i}: hit {t} where brute force has none"
                ),
                Some(h) => {
                    assert!(
                        *slot >= 0,
                        "{what} {isa} pixel {i}: missed the hit at {}",
                        h.t
                    );
                    assert_eq!(
                        h.t.to_bits(),
                        t.to_bits(),
                        "{what} {isa} pixel {i}: t {t} vs {}",
                        h.t
                    );
                    hits += 1;
                }
            }
        }
    }
    let _ = g;
    hits
}

#[test]
fn blocks_match_brute_force_from_many_cameras() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for (n, clustered) in [(300, false), (2000, true)] {
        let g = random_molecule(n, clustered, 7);
        let bvh = Bvh::build(&g);
        bvh.validate(&g).unwrap();
        let b = bvh.bounds;
        let c = [0, 1, 2].map(|a| 0.5 * (b.min[a] + b.max[a]) as f64);
        let ext = (0..3)
            .map(|a| (b.max[a] - b.min[a]) as f64)
            .fold(0.0, f64::max);
        let mut hits = 0;
        for k in 0..16 {
            // Eyes from inside the molecule to far away, on a log scale.
            let dist = ext * rng.log(0.01, 20.0);
            let dir = unit([rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5]);
            let eye = [0, 1, 2].map(|a| c[a] + dir[a] * dist);
            let at = [0, 1, 2].map(|a| c[a] + (rng.f() - 0.5) * ext * 0.3);
            let fov = rng.log(0.002, 2.5);
            let (w, h) = (17 + k * 3, 9 + k * 2);
            let cam = camera(eye, at, fov, k % 3 != 2, w, h);
            hits += check(&g, &bvh, cam, &format!("{n} atoms, camera {k}"));
        }
        assert!(hits > 1000, "too few hits to mean anything: {hits}");
    }
}

#[test]
fn degenerate_cameras_do_not_panic_and_match_brute_force() {
    let g = random_molecule(300, false, 3);
    let bvh = Bvh::build(&g);
    let b = bvh.bounds;
    let c = [0, 1, 2].map(|a| 0.5 * (b.min[a] + b.max[a]) as f64);
    // A zero field of view (every ray the same), then a NaN eye (no ray hits anything).
    let cam = camera([c[0], c[1], c[2] - 500.0], c, 0.0, true, 12, 7);
    check(&g, &bvh, cam, "zero fov");
    let cam = camera([f64::NAN, c[1], c[2]], c, 0.5, true, 12, 7);
    assert_eq!(check(&g, &bvh, cam, "NaN eye"), 0);
    // The empty tree.
    let empty = Geometry::from_atoms(&[], &[], &[], &[], &[], &[], 0.15);
    let e = Bvh::build(&empty);
    check(
        &empty,
        &e,
        camera([0.0, 0.0, -5.0], [0.0; 3], 0.5, true, 5, 5),
        "empty",
    );
}
