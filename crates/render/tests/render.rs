//! Rendering: backends agree with scalar; analytic sphere and cylinder; big frames; PNG.

mod common;
use bvh::scenes::random_molecule;
use bvh::{Balls, Geometry, Ray, Sticks};
use common::render_bs;
use render::{
    rgba, Camera, Coloring, Colormap, Framebuffer, Model, ModelOptions, RenderSettings, Style, View,
};
use spmd::Isa;

fn agree(a: &Framebuffer, b: &Framebuffer) -> f64 {
    let ok = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| {
            p.to_le_bytes()
                .iter()
                .zip(q.to_le_bytes())
                .all(|(x, y)| (*x as i32 - y as i32).abs() <= 1)
        })
        .count();
    ok as f64 / a.pixels.len() as f64
}

#[test]
fn every_backend_matches_scalar() {
    for style in [Style::BallAndStick, Style::Licorice, Style::Spheres] {
        let g = random_molecule(3_000, true, 21);
        let radius_scale = if style == Style::Spheres { 2.0 } else { 0.5 };
        let opt = ModelOptions {
            style,
            radius_scale,
            ..Default::default()
        };
        let scene = Model::new(
            &g.balls.x,
            &g.balls.y,
            &g.balls.z,
            &g.balls.radius,
            &g.balls.color,
            &pairs(&g),
            &opt,
            None,
        )
        .unwrap();
        scene.bvh.validate(&scene.geometry).unwrap();
        for view in [View::Far, View::Close] {
            let (w, h) = (203, 150);
            let cam = Camera::view(view, scene.center, scene.radius, 40.0, w as f32 / h as f32);
            let ro = RenderSettings::default();
            let (reference, _) = render_bs(&scene, &cam, w, h, &ro, Isa::Scalar);
            let bg = reference
                .pixels
                .iter()
                .filter(|&&p| p == ro.background_packed())
                .count();
            assert!(
                bg < reference.pixels.len() * 95 / 100,
                "{style:?} {view:?}: picture nearly empty"
            );
            assert!(bg > 0 || view == View::Close);
            for isa in Isa::supported() {
                let (fb, stats) = render_bs(&scene, &cam, w, h, &ro, isa);
                assert_eq!(stats.isa, isa);
                let a = agree(&reference, &fb);
                assert!(
                    a >= 0.999,
                    "{isa} {style:?} {view:?}: only {a} of pixels within 1/255"
                );
            }
        }
    }
}

fn pairs(g: &Geometry) -> Vec<[u32; 2]> {
    g.sticks
        .a
        .iter()
        .zip(&g.sticks.b)
        .map(|(&a, &b)| [a, b])
        .collect()
}

/// Unit sphere at the origin (atom 0); an open cylinder of radius 0.5 from (3,−2,0) to (3,2,0)
/// (atoms 1 and 2 have radius 0, so they never show).
fn sphere_and_cylinder() -> Model {
    let g = Geometry {
        balls: Balls {
            x: vec![0.0, 3.0, 3.0],
            y: vec![0.0, -2.0, 2.0],
            z: vec![0.0, 0.0, 0.0],
            radius: vec![1.0, 0.0, 0.0],
            color: vec![
                rgba(200, 100, 50, 255),
                rgba(0, 255, 0, 255),
                rgba(0, 0, 255, 255),
            ],
        },
        sticks: Sticks {
            a: vec![1],
            b: vec![2],
            radius: 0.5,
            ..Sticks::default()
        },
        show_balls: true,
        capped: false,
    };
    Model::from_geometry(g, None).unwrap()
}

#[test]
fn analytic_sphere_and_cylinder_hits() {
    let scene = sphere_and_cylinder();
    scene.bvh.validate(&scene.geometry).unwrap();
    let mut rays = Vec::new();
    let mut expect = Vec::new();
    for i in 0..40 {
        let u = -0.95 + 1.9 * i as f64 / 39.0;
        // Sphere, ray along −z at (u/2, u, 10): t = 10 − √(1 − x² − y²), n = hit point.
        let (x, y) = (u * 0.5, u * 0.7);
        let zs = (1.0 - x * x - y * y).sqrt();
        rays.push(Ray::new([x as f32, y as f32, 10.0], [0.0, 0.0, -1.0]));
        expect.push((10.0 - zs, [x, y, zs], 0u32, false));
        // Cylinder, ray along −z at (3 + u/2, y, 10): t = 10 − √(0.25 − dx²), n = (dx, 0, z)/0.5.
        let dx = u * 0.5 * 0.99;
        let zc = (0.25 - dx * dx).sqrt();
        let yc = u * 1.9;
        rays.push(Ray::new(
            [(3.0 + dx) as f32, yc as f32, 10.0],
            [0.0, 0.0, -1.0],
        ));
        expect.push((10.0 - zc, [dx / 0.5, 0.0, zc / 0.5], 3u32, yc > 0.0));
    }
    // Rays along the cylinder axis or beyond its ends miss it; a ray from inside the sphere hits
    // the far side.
    rays.push(Ray::new([3.1, -10.0, 0.0], [0.0, 1.0, 0.0]));
    rays.push(Ray::new([3.0, 2.2, 10.0], [0.0, 0.0, -1.0]));
    rays.push(Ray::new([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]));
    for isa in Isa::supported() {
        let hits = scene.bvh.intersect_rays(isa, &rays);
        for (i, (h, e)) in hits.iter().zip(&expect).enumerate() {
            let h = h.unwrap_or_else(|| panic!("{isa}: ray {i} missed"));
            assert_eq!(h.prim, e.2, "{isa} ray {i}");
            assert!(
                (h.t as f64 - e.0).abs() < 2e-6 * 10.0,
                "{isa} ray {i}: t {} vs {}",
                h.t,
                e.0
            );
            for k in 0..3 {
                assert!(
                    (h.n[k] as f64 - e.1[k]).abs() < 1e-4,
                    "{isa} ray {i}: n {:?} vs {:?}",
                    h.n,
                    e.1
                );
            }
            assert_eq!(h.second_half, e.3, "{isa} ray {i}");
        }
        let n = expect.len();
        assert!(hits[n].is_none(), "{isa}: axial ray hit an open cylinder");
        assert!(
            hits[n + 1].is_none(),
            "{isa}: ray past the cylinder end hit"
        );
        let inside = hits[n + 2].expect("ray from the centre");
        assert!((inside.t - 1.0).abs() < 1e-6 && (inside.n[0] - 1.0).abs() < 1e-6);
    }
}

#[test]
fn analytic_shading_orthographic() {
    // Orthographic view down −z of the unit sphere: pixel colour = colour × (a + (1−a)·n_z).
    let scene = sphere_and_cylinder();
    let (w, h) = (64u32, 64u32);
    let cam = Camera::orthographic([0.0, 0.0, 10.0], [0.0; 3], [0.0, 1.0, 0.0], 2.5);
    let ro = RenderSettings {
        background: [0, 0, 0],
        ambient: 0.2,
        ..Default::default()
    };
    for isa in Isa::supported() {
        let (fb, _) = render_bs(&scene, &cam, w, h, &ro, isa);
        let mut checked = 0;
        for py in 0..h {
            for px in 0..w {
                let x = (px as f64 + 0.5) / w as f64 * 2.5 - 1.25;
                let y = 1.25 - (py as f64 + 0.5) / h as f64 * 2.5;
                let r2 = x * x + y * y;
                let p = fb.pixel(px, py);
                if r2 > 1.02 {
                    assert_eq!(p, [0, 0, 0, 255], "{isa} ({px},{py}) should be background");
                } else if r2 < 0.98 {
                    let nz = (1.0 - r2).sqrt();
                    let shade = 0.2 + 0.8 * nz;
                    for (k, c) in [200.0, 100.0, 50.0].iter().enumerate() {
                        let e = c * shade;
                        assert!(
                            (p[k] as f64 - e).abs() <= 1.0,
                            "{isa} ({px},{py}) ch {k}: {} vs {e}",
                            p[k]
                        );
                    }
                    checked += 1;
                }
            }
        }
        assert!(checked > 1500, "{checked}");
    }
}

#[test]
fn scalar_colormap_and_png() {
    let g = random_molecule(500, false, 3);
    let values: Vec<f32> = (0..500).map(|i| i as f32).collect();
    let opt = ModelOptions {
        coloring: Coloring::Scalar {
            values,
            colormap: Colormap::Viridis,
            range: None,
        },
        ..Default::default()
    };
    let scene = Model::new(
        &g.balls.x,
        &g.balls.y,
        &g.balls.z,
        &g.balls.radius,
        &[],
        &pairs(&g),
        &opt,
        None,
    )
    .unwrap();
    assert_eq!(scene.geometry.balls.color[0], rgba(68, 1, 84, 255));
    assert_eq!(scene.geometry.balls.color[499], rgba(253, 231, 37, 255));
    let cam = Camera::view(View::Far, scene.center, scene.radius, 45.0, 1.0);
    let (fb, _) = render_bs(
        &scene,
        &cam,
        100,
        100,
        &RenderSettings::default(),
        Isa::detect(),
    );
    let dir = std::env::temp_dir().join(format!("bnsview-render-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("t.png");
    fb.save_png(&path).unwrap();
    let back = image::open(&path).unwrap().to_rgba8();
    assert_eq!(back.as_raw().as_slice(), &*fb.as_bytes());
    // An output check before rendering: the written file is kept unless forced, a missing
    // directory and an unknown extension are named.
    use render::{ImageFormat, RenderError};
    let err = |p: &std::path::Path, force| ImageFormat::for_output(p, force).unwrap_err();
    assert!(matches!(err(&path, false), RenderError::Exists(_)));
    assert_eq!(
        ImageFormat::for_output(&path, true).unwrap(),
        ImageFormat::Png
    );
    let jpg = dir.join("new.JPG");
    assert_eq!(
        ImageFormat::for_output(&jpg, false).unwrap(),
        ImageFormat::Jpeg
    );
    let lost = dir.join("no-such-dir").join("x.png");
    assert!(matches!(err(&lost, true), RenderError::NoDirectory { .. }));
    assert!(matches!(
        err(&dir.join("x.tif"), true),
        RenderError::UnknownFormat(_)
    ));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn huge_framebuffer() {
    // 16384² (1 GiB of pixels): flat buffer, no per-pixel allocations.
    let scene = sphere_and_cylinder();
    let cam = Camera::view(View::Far, scene.center, scene.radius, 30.0, 1.0);
    let (fb, stats) = render_bs(
        &scene,
        &cam,
        16384,
        16384,
        &RenderSettings::default(),
        Isa::detect(),
    );
    assert_eq!(fb.pixels.len(), 16384 * 16384);
    assert_eq!(stats.rays, 16384 * 16384);
    // The centre of the frame is near the scene centre (between sphere and cylinder): somewhere
    // along the middle row there is sphere colour.
    let row = 8192u32;
    assert!((0..16384).any(|x| fb.pixel(x, row)[0] > 100 && fb.pixel(x, row)[2] < 100));
    assert!(Framebuffer::new(u32::MAX, u32::MAX, 0).is_err());
}
