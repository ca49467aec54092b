//! Ray tracing modalities (issue 6): hard shadows against an analytic shadow test, ambient
//! occlusion of an open sphere and inside a closed shell, a furnace test of the path tracer,
//! and every backend against scalar for a fixed seed.

use bvh::scenes::random_molecule;
use bvh::{Balls, Geometry, Ray, Sticks};
use render::{
    accumulate, ambient_occlusion_at, rgba, Accum, Camera, FrameInputs, Framebuffer, Light,
    Material, Modality, Model, RenderSettings, SecondaryTraversal, View, WHITE_BACKGROUND,
};
use spmd::Isa;

const WHITE: u32 = rgba(255, 255, 255, 255);

/// Direct light with shadows on white, every other setting its default.
fn traced() -> RenderSettings {
    RenderSettings::traced(Modality::Direct { shadows: true }, WHITE_BACKGROUND)
}

/// `spp` samples of `set` accumulated over a new `w × h` frame: the picture and the sums.
fn render_modal(
    scene: &Model,
    cam: &Camera,
    (w, h): (u32, u32),
    set: &RenderSettings,
    spp: u32,
    isa: Isa,
) -> (Framebuffer, Accum) {
    let mut acc = Accum::new(w, h).unwrap();
    accumulate(&FrameInputs::geometry(scene, cam), set, &mut acc, spp, isa).unwrap();
    (acc.to_framebuffer(set.is_linear(), set.exposure), acc)
}

fn balls(centres: &[[f32; 3]], radius: &[f32], color: &[u32]) -> Model {
    let g = Geometry {
        balls: Balls {
            x: centres.iter().map(|c| c[0]).collect(),
            y: centres.iter().map(|c| c[1]).collect(),
            z: centres.iter().map(|c| c[2]).collect(),
            radius: radius.to_vec(),
            color: color.to_vec(),
        },
        sticks: Sticks {
            a: vec![],
            b: vec![],
            radius: 0.1,
            ..Sticks::default()
        },
        show_balls: true,
        capped: false,
    };
    Model::from_geometry(g, None).unwrap()
}

/// A 21×21 slab of overlapping unit balls in the plane y = 0 (spacing 1 Å, so its top is a
/// height field) and a ball of radius `R` centred `(0, H, 0)` above it.
const R: f64 = 2.0;
const H: f32 = 5.0;
fn sphere_over_slab() -> Model {
    let mut c = Vec::new();
    for i in -10..=10 {
        for k in -10..=10 {
            c.push([i as f32, 0.0, k as f32]);
        }
    }
    let n = c.len();
    c.push([0.0, H, 0.0]);
    let mut r = vec![1.0f32; n];
    r.push(R as f32);
    let col = vec![WHITE; n + 1];
    balls(&c, &r, &col)
}

/// The primary ray of pixel (x, y) of an orthographic camera, as the renderer forms it.
fn ortho_ray(cam: &Camera, w: u32, h: u32, x: u32, y: u32) -> Ray {
    let render::Projection::Orthographic { height } = cam.projection else {
        panic!("orthographic camera expected")
    };
    let hh = height as f64 * 0.5;
    let hw = hh * w as f64 / h as f64;
    let u = -hw + 2.0 * hw * (x as f64 + 0.5) / w as f64;
    let v = hh - 2.0 * hh * (y as f64 + 0.5) / h as f64;
    let o: [f32; 3] = std::array::from_fn(|a| {
        (cam.eye[a] as f64 + cam.right[a] as f64 * u + cam.up[a] as f64 * v) as f32
    });
    Ray::new(o, cam.forward)
}

/// Renders `sphere_over_slab` lit by `light` with shadows on every backend and both secondary
/// traversals, and checks every slab pixel against `clearance(p)`: the distance (Å) by which
/// the segment from hit point `p` towards the light misses the ball's centre, minus `R`
/// (negative: in shadow), `None` where the slab's own bumps may shadow the point. Pixels
/// within 0.1 Å of the shadow's edge are not judged.
fn check_shadow(light: Light, clearance: impl Fn([f64; 3]) -> Option<f64>) {
    let scene = sphere_over_slab();
    let cam = Camera::orthographic([0.0, 30.0, 22.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 22.0);
    let (w, h) = (128, 128);
    let opt = RenderSettings {
        modality: Modality::Direct { shadows: true },
        light,
        light_intensity: 0.8,
        ambient: 0.2,
        ..traced()
    };
    let ambient = (0.2f32 * 255.0 + 0.5) as i32;
    let slab_prims = (scene.geometry.balls.len() - 1) as u32;
    for isa in Isa::under_test() {
        for secondary in [
            SecondaryTraversal::Packet,
            SecondaryTraversal::Single,
            SecondaryTraversal::Wide,
        ] {
            let opt = RenderSettings { secondary, ..opt };
            let (fb, _) = render_modal(&scene, &cam, (w, h), &opt, 1, isa);
            let (mut n_shadow, mut n_lit) = (0, 0);
            for y in 0..h {
                for x in 0..w {
                    let ray = ortho_ray(&cam, w, h, x, y);
                    let Some(hit) = scene.bvh.intersect_ray(&ray) else {
                        continue;
                    };
                    if hit.prim >= slab_prims || hit.n[1] < 0.2 {
                        continue; // the sphere itself, or a grazing slab point
                    }
                    let p: [f64; 3] =
                        std::array::from_fn(|a| ray.o[a] as f64 + ray.d[a] as f64 * hit.t as f64);
                    // Judge only points facing the light (n·l > 0.2): the rest are dark anyway.
                    let l: [f64; 3] = match light {
                        Light::Directional(d) => d.map(|x| x as f64),
                        Light::Point(q) => std::array::from_fn(|a| q[a] as f64 - p[a]),
                    };
                    let ln = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
                    let ndl: f64 = (0..3).map(|a| hit.n[a] as f64 * l[a] / ln).sum();
                    let Some(c) = clearance(p).filter(|_| ndl > 0.2) else {
                        continue;
                    };
                    if c.abs() < 0.1 {
                        continue; // too close to the shadow's edge to call
                    }
                    let red = fb.pixel(x, y)[0] as i32;
                    if c < 0.0 {
                        n_shadow += 1;
                        assert!(
                            (red - ambient).abs() <= 1,
                            "{isa} {secondary:?} {light:?}: pixel ({x},{y}) at {p:.2?} must be \
                             in shadow (ambient {ambient}), got {red}"
                        );
                    } else {
                        n_lit += 1;
                        assert!(
                            red > ambient + 30,
                            "{isa} {secondary:?} {light:?}: pixel ({x},{y}) at {p:.2?} must be \
                             lit, got {red}"
                        );
                    }
                }
            }
            assert!(
                n_shadow > 100 && n_lit > 1000,
                "{light:?}: {n_shadow} shadow, {n_lit} lit pixels"
            );
        }
    }
}

#[test]
fn hard_shadow_of_a_sphere_on_a_slab_is_where_geometry_puts_it() {
    // Light straight up: the point is in the sphere's shadow iff its vertical line passes
    // through the disc of radius R about the axis.
    check_shadow(Light::Directional([0.0, 1.0, 0.0]), |p| {
        Some((p[0] * p[0] + p[2] * p[2]).sqrt() - R)
    });
}

#[test]
fn point_light_shadow_is_the_cone_from_the_light() {
    // A point light 9 Å above the ball's centre, off the axis: the shadow is where the
    // segment from the slab point to the light passes within R of the centre (a wider,
    // shifted disc than the directional light's). Points that see the light lower than 55°
    // above the horizon are not judged (the slab's bumps shadow each other there).
    let q = [1.5f64, H as f64 + 9.0, 0.5];
    check_shadow(Light::Point([q[0] as f32, q[1] as f32, q[2] as f32]), |p| {
        let c = [0.0, H as f64, 0.0];
        let d: [f64; 3] = std::array::from_fn(|a| q[a] - p[a]);
        let w: [f64; 3] = std::array::from_fn(|a| c[a] - p[a]);
        let dd: f64 = d.iter().map(|x| x * x).sum();
        let u = (d.iter().zip(&w).map(|(a, b)| a * b).sum::<f64>() / dd).clamp(0.0, 1.0);
        let dist2: f64 = (0..3).map(|a| (w[a] - u * d[a]).powi(2)).sum();
        let horizontal = (d[0] * d[0] + d[2] * d[2]).sqrt();
        (d[1] > horizontal * 55f64.to_radians().tan()).then(|| dist2.sqrt() - R)
    });
}

#[test]
fn shadows_off_means_no_shadow() {
    let scene = sphere_over_slab();
    let cam = Camera::orthographic([0.0, 30.0, 22.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 22.0);
    let opt = RenderSettings {
        modality: Modality::Direct { shadows: false },
        light: Light::Directional([0.0, 1.0, 0.0]),
        ..traced()
    };
    let (fb, _) = render_modal(&scene, &cam, (64, 64), &opt, 1, Isa::detect());
    // The slab right under the sphere (image centre, below the sphere's silhouette) is lit.
    let ray = ortho_ray(&cam, 64, 64, 32, 40);
    let hit = scene.bvh.intersect_ray(&ray).unwrap();
    assert!(hit.prim < 441, "test pixel must see the slab");
    assert!(fb.pixel(32, 40)[0] > 200);
}

#[test]
fn ambient_occlusion_open_sphere_is_one_and_inside_a_closed_shell_is_zero() {
    // A lone ball: every point of its surface sees the whole hemisphere.
    let lone = balls(&[[1.0, 2.0, 3.0]], &[1.5], &[WHITE]);
    let mut pts = Vec::new();
    let mut nrm = Vec::new();
    for i in 0..100 {
        let n = fib(i, 100);
        nrm.push(n);
        pts.push([1.0 + 1.5 * n[0], 2.0 + 1.5 * n[1], 3.0 + 1.5 * n[2]]);
    }
    // A closed shell: 3000 overlapping balls of radius 1 Å on a sphere of radius 10 Å
    // (neighbours ≈ 0.65 Å apart).
    let shell_c: Vec<[f32; 3]> = (0..3000)
        .map(|i| {
            let n = fib(i, 3000);
            [10.0 * n[0], 10.0 * n[1], 10.0 * n[2]]
        })
        .collect();
    let shell = balls(&shell_c, &vec![1.0; 3000], &vec![WHITE; 3000]);
    let inside: Vec<[f32; 3]> = (0..40)
        .map(|i| {
            let n = fib(i, 40);
            let r = 7.0 * (i as f32 / 40.0);
            [r * n[0], r * n[1], r * n[2]]
        })
        .collect();
    let in_n: Vec<[f32; 3]> = (0..40).map(|i| fib(i * 7 + 3, 280)).collect();
    for isa in Isa::under_test() {
        let ao = ambient_occlusion_at(&lone, &pts, &nrm, 64, 100.0, 1e-4, 9, isa);
        assert!(ao.iter().all(|&a| a == 1.0), "{isa}: open sphere {ao:?}");
        let ao = ambient_occlusion_at(&shell, &inside, &in_n, 64, 100.0, 0.0, 9, isa);
        assert!(ao.iter().all(|&a| a == 0.0), "{isa}: inside shell {ao:?}");
        // The same points with a distance too short to reach the shell (≥ 2 Å away): 1.
        let ao = ambient_occlusion_at(&shell, &inside, &in_n, 64, 1.9, 0.0, 9, isa);
        assert!(ao.iter().all(|&a| a == 1.0), "{isa}: short AO rays {ao:?}");
        // Half-way: on the shell's inner surface, facing inwards, rays reach the far side.
        let ao = ambient_occlusion_at(
            &shell,
            &[[0.0, 0.0, -9.0]],
            &[[0.0, 0.0, 1.0]],
            256,
            100.0,
            0.0,
            9,
            isa,
        );
        assert_eq!(ao, vec![0.0]);
    }
}

/// Point `i` of `n` on a Fibonacci sphere (unit vectors, nearly uniform).
fn fib(i: usize, n: usize) -> [f32; 3] {
    let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
    let r = (1.0 - z * z).sqrt();
    let phi = i as f64 * std::f64::consts::PI * (3.0 - 5f64.sqrt());
    [(r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32]
}

#[test]
fn ao_image_of_an_unoccluded_sphere_is_its_colour() {
    let scene = balls(&[[0.0, 0.0, 0.0]], &[2.0], &[rgba(200, 120, 40, 255)]);
    let cam = Camera::view(View::Far, scene.center, scene.radius, 40.0, 1.0);
    let opt = RenderSettings {
        modality: Modality::Ao {
            samples: 16,
            distance: 50.0,
        },
        background: [0, 0, 0],
        ..traced()
    };
    for isa in Isa::under_test() {
        let (fb, _) = render_modal(&scene, &cam, (64, 64), &opt, 1, isa);
        let hit = fb
            .pixels
            .iter()
            .filter(|&&p| p != rgba(0, 0, 0, 255))
            .count();
        assert!(hit > 500, "{isa}: sphere covers {hit} pixels");
        assert!(
            fb.pixels
                .iter()
                .all(|&p| p == rgba(0, 0, 0, 255) || p == rgba(200, 120, 40, 255)),
            "{isa}: an unoccluded sphere must have AO 1 everywhere"
        );
    }
}

/// Furnace test: white diffuse atoms (albedo 1) under a uniform white sky of radiance 1 and no
/// other light. Every path that escapes within `max_depth` hits carries exactly 1, so every
/// pixel converges to 1 (bias: the probability of a path exceeding 64 hits in a loose cluster,
/// far below the tolerance).
#[test]
fn furnace_white_diffuse_under_white_sky_is_one() {
    let g = random_molecule(400, true, 5);
    let centres: Vec<[f32; 3]> = (0..g.balls.len()).map(|i| g.balls.center(i)).collect();
    let r: Vec<f32> = g.balls.radius.iter().map(|r| r * 1.5).collect();
    let scene = balls(&centres, &r, &vec![WHITE; centres.len()]);
    let cam = Camera::view(View::Far, scene.center, scene.radius, 40.0, 1.0);
    let opt = RenderSettings {
        modality: Modality::Path {
            material: Material::Diffuse,
            max_depth: 64,
            roughness: 0.0,
        },
        light_intensity: 0.0,
        background: [255, 255, 255],
        ..traced()
    };
    for isa in Isa::under_test() {
        let (_, acc) = render_modal(&scene, &cam, (48, 48), &opt, 8, isa);
        let mut lo = f32::INFINITY;
        let mut sum = 0.0f64;
        for y in 0..48 {
            for x in 0..48 {
                for c in acc.mean(x, y) {
                    lo = lo.min(c);
                    sum += c as f64;
                }
            }
        }
        let mean = sum / (48.0 * 48.0 * 3.0);
        assert!((mean - 1.0).abs() < 1e-3, "{isa}: furnace mean {mean}");
        assert!(lo > 0.85 && lo <= 1.0 + 1e-6, "{isa}: furnace min {lo}");
    }
}

/// A grey (sRGB 128 → linear 0.252) diffuse ball alone under a white sky: one bounce, so each
/// sample that hits it returns exactly its albedo; a grey metal ball returns the Fresnel-weighted
/// albedo, between albedo and 1.
#[test]
fn single_ball_under_white_sky_returns_its_albedo() {
    let scene = balls(&[[0.0, 0.0, 0.0]], &[2.0], &[rgba(128, 128, 128, 255)]);
    let cam = Camera::view(View::Far, scene.center, scene.radius, 40.0, 1.0);
    let albedo = (128.0f32 / 255.0).powi(2);
    for material in [Material::Diffuse, Material::Metal] {
        let opt = RenderSettings {
            modality: Modality::Path {
                material,
                max_depth: 4,
                roughness: 0.0,
            },
            light_intensity: 0.0,
            background: [255, 255, 255],
            ..traced()
        };
        let (_, acc) = render_modal(&scene, &cam, (64, 64), &opt, 4, Isa::detect());
        // The centre of the ball (normal incidence): metal's Fresnel factor is F0 there too.
        let c = acc.mean(32, 32);
        assert!(
            (c[0] - albedo).abs() < 2e-3,
            "{material:?}: {c:?} vs {albedo}"
        );
        // Sky pixels are exactly 1.
        assert_eq!(acc.mean(0, 0), [1.0, 1.0, 1.0]);
    }
}

fn molecule_scene() -> Model {
    let g = random_molecule(3_000, true, 21);
    let pairs: Vec<[u32; 2]> = g
        .sticks
        .a
        .iter()
        .zip(&g.sticks.b)
        .map(|(&a, &b)| [a, b])
        .collect();
    Model::new(
        &g.balls.x,
        &g.balls.y,
        &g.balls.z,
        &g.balls.radius,
        &g.balls.color,
        &pairs,
        &render::ModelOptions::default(),
        None,
    )
    .unwrap()
}

/// Fraction of pixels whose channels all lie within `tol` of the reference, and the mean
/// absolute channel difference.
fn compare(a: &Framebuffer, b: &Framebuffer, tol: i32) -> (f64, f64) {
    let mut ok = 0usize;
    let mut diff = 0.0f64;
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        let (p, q) = (p.to_le_bytes(), q.to_le_bytes());
        let d: Vec<i32> = (0..3).map(|c| (p[c] as i32 - q[c] as i32).abs()).collect();
        if d.iter().all(|&x| x <= tol) {
            ok += 1;
        }
        diff += d.iter().sum::<i32>() as f64;
    }
    let n = a.pixels.len() as f64;
    (ok as f64 / n, diff / (3.0 * n))
}

/// Every backend draws the same random numbers per pixel and sample, so for a fixed seed the
/// pictures agree with scalar except where fused multiply-adds (AVX2, AVX-512) flip a hit or
/// a grazing secondary ray. Tolerances: shadows ≥ 99.5 % of pixels within 2/255; AO and path
/// tracing ≥ 98 % within 2/255 (a flipped AO ray moves a pixel by 1/N), mean channel
/// difference below 0.5/255.
#[test]
fn every_backend_matches_scalar_for_a_fixed_seed() {
    let scene = molecule_scene();
    let (w, h) = (96, 80);
    let cam = Camera::view(
        View::Far,
        scene.center,
        scene.radius,
        40.0,
        w as f32 / h as f32,
    );
    let cases = [
        (Modality::Direct { shadows: true }, 1, 0.995),
        (
            Modality::Ao {
                samples: 8,
                distance: 4.0,
            },
            1,
            0.98,
        ),
        (
            Modality::Path {
                material: Material::Metal,
                max_depth: 4,
                roughness: 0.2,
            },
            2,
            0.98,
        ),
        (
            Modality::Path {
                material: Material::Diffuse,
                max_depth: 4,
                roughness: 0.0,
            },
            2,
            0.98,
        ),
    ];
    for (modality, spp, need) in cases {
        // The reference: scalar, every secondary ray in (one-lane) packets of the binary BVH.
        let opt = RenderSettings {
            modality,
            seed: 42,
            secondary: SecondaryTraversal::Packet,
            bounces: SecondaryTraversal::Packet,
            ..traced()
        };
        let (reference, _) = render_modal(&scene, &cam, (w, h), &opt, spp, Isa::Scalar);
        let bg = reference.pixels.iter().filter(|&&p| p == WHITE).count();
        assert!(
            bg < reference.pixels.len() * 9 / 10,
            "{modality:?}: nearly empty"
        );
        // Same seed twice: identical; another seed: a different picture (AO/path).
        let (again, _) = render_modal(&scene, &cam, (w, h), &opt, spp, Isa::Scalar);
        assert_eq!(again, reference);
        // Every backend and every traversal of the secondary rays (shadow, AO, bounces).
        for isa in Isa::under_test() {
            for how in [
                SecondaryTraversal::Packet,
                SecondaryTraversal::Single,
                SecondaryTraversal::Wide,
            ] {
                let opt = RenderSettings {
                    secondary: how,
                    bounces: how,
                    ..opt
                };
                let (fb, _) = render_modal(&scene, &cam, (w, h), &opt, spp, isa);
                let (frac, mean) = compare(&reference, &fb, 2);
                assert!(
                    frac >= need && mean < 0.5,
                    "{isa} {how:?} {modality:?}: {frac} of pixels within 2/255 (need {need}), \
                     mean diff {mean}"
                );
            }
        }
    }
}

#[test]
fn progressive_accumulation_does_not_depend_on_how_samples_are_split() {
    let scene = molecule_scene();
    let cam = Camera::view(View::Far, scene.center, scene.radius, 40.0, 1.0);
    let opt = RenderSettings {
        modality: Modality::Path {
            material: Material::Diffuse,
            max_depth: 3,
            roughness: 0.0,
        },
        ..traced()
    };
    let isa = Isa::detect();
    let (_, all) = render_modal(&scene, &cam, (40, 40), &opt, 4, isa);
    let mut acc = Accum::new(40, 40).unwrap();
    let inputs = FrameInputs::geometry(&scene, &cam);
    accumulate(&inputs, &opt, &mut acc, 1, isa).unwrap();
    accumulate(&inputs, &opt, &mut acc, 3, isa).unwrap();
    assert_eq!(acc.samples, 4);
    for (a, b) in acc.rgb.iter().zip(&all.rgb) {
        assert!((a - b).abs() <= 1e-5 * b.abs().max(1.0), "{a} vs {b}");
    }
    // A different seed gives a different picture.
    let (_, other) = render_modal(
        &scene,
        &cam,
        (40, 40),
        &RenderSettings { seed: 2, ..opt },
        4,
        isa,
    );
    assert_ne!(other.rgb, all.rgb);
}
