//! Ray marching against a double-precision reference integration, backends against scalar,
//! macrocell skipping against none, lighting, degenerate rays and volumetric shadows.

mod common;

use common::*;
use spmd::Isa;
use volume::*;

#[test]
fn single_atom_matches_double_precision_reference_integration() {
    // Fine grid so trilinear interpolation error is small against the analytic field.
    let r = 1.5f32;
    let atoms = Atoms {
        x: vec![0.0],
        y: vec![0.0],
        z: vec![0.0],
        r: vec![r],
    };
    let (v, mc) = volume_of(&atoms, 8.0, VolumeFormat::F32);
    let tf = ramp_tf();
    let hi = v.max_value;
    let ctf = ClassifiedTf::new(&tf, 0.0, hi, 0.5);
    let field = |q: [f64; 3]| phi(&atoms, q);
    let b = atom_rays(f32::INFINITY);
    let reference = Reference::new(&field, &tf, hi, &v.grid);
    let want = reference.batch(&b, 0.002, &unshaded);
    assert!(
        want.iter().filter(|w| w[3] > 0.2).count() > 10,
        "rays must cross dense parts"
    );
    assert!(
        want.iter().filter(|w| w[3] == 0.0).count() > 3,
        "and some must miss"
    );
    for (opts, tol, label) in classification_opts(3.0 / 255.0, 9.0 / 255.0) {
        let sc = VolumeScene::new(&v, &mc, &ctf, opts);
        for isa in Isa::supported() {
            assert_near(&format!("{label} {isa}"), &b.render(isa, &sc), &want, tol);
        }
    }
}

fn shell_scene(format: VolumeFormat) -> (Volume, Macrocells) {
    let mut a = shell(9.0);
    let b = shell(13.0);
    a.x.extend(b.x);
    a.y.extend(b.y);
    a.z.extend(b.z);
    a.r.extend(b.r);
    volume_of(&a, 3.0, format)
}

fn all_opts() -> Vec<MarchOptions> {
    let mut v = vec![];
    for preintegrated in [true, false] {
        for lighting in [
            Lighting::Unlit,
            Lighting::Headlight,
            Lighting::Directional([1.0, 2.0, 0.5]),
        ] {
            v.push(MarchOptions {
                preintegrated,
                lighting,
                ..Default::default()
            });
        }
    }
    v
}

#[test]
fn macrocell_skipping_matches_no_skipping_within_one_255th() {
    for format in [VolumeFormat::U8, VolumeFormat::F32] {
        let (v, mc) = shell_scene(format);
        for preset in Preset::ALL {
            let ctf = preset_tf(preset, v.max_value);
            // The test means something only if most cells are empty under this TF.
            let empty = (0..mc.minmax.len() / 2)
                .filter(|&c| {
                    let (b0, b1) = (ctf.bin(mc.minmax[2 * c]), ctf.bin(mc.minmax[2 * c + 1]));
                    ctf.range_max[b0.saturating_sub(1) * 256 + (b1 + 1).min(255)] == 0.0
                })
                .count();
            assert!(
                empty * 4 > mc.minmax.len() / 2,
                "{preset:?}: {empty} empty cells"
            );
            let b = scattered_rays(300, 3);
            let es = EmptySpace::build(&mc, &ctf);
            for opts in all_opts() {
                let off_opts = MarchOptions {
                    macrocells: false,
                    ..opts
                };
                let off = b.render(Isa::detect(), &VolumeScene::new(&v, &mc, &ctf, off_opts));
                let cells = VolumeScene::new(&v, &mc, &ctf, opts);
                for (sc, how) in [
                    (cells, "cell by cell"),
                    (cells.with_empty_space(&es), "jumps"),
                ] {
                    let on = b.render(Isa::detect(), &sc);
                    let mut worst = 0.0f32;
                    for (x, y) in on.iter().zip(&off) {
                        for c in 0..4 {
                            worst = worst.max((x[c] - y[c]).abs());
                        }
                    }
                    assert!(
                        worst <= 1.0 / 255.0,
                        "{format} {preset:?} {opts:?} {how}: {worst}"
                    );
                }
                assert!(off.iter().filter(|c| c[3] > 0.1).count() > 30);
            }
        }
    }
}

#[test]
fn every_backend_agrees_with_scalar() {
    let (v, mc) = shell_scene(VolumeFormat::U8);
    let ctf = preset_tf(Preset::Viridis, v.max_value);
    let b = scattered_rays(203, 9); // not a multiple of any lane count
    let es = EmptySpace::build(&mc, &ctf);
    for opts in all_opts().into_iter().flat_map(|o| {
        [
            o,
            MarchOptions {
                macrocells: false,
                ..o
            },
        ]
    }) {
        let sc = VolumeScene::new(&v, &mc, &ctf, opts);
        for sc in [sc, sc.with_empty_space(&es)] {
            let want = b.render(Isa::Scalar, &sc);
            let jumps = sc.empty.is_some();
            for isa in Isa::supported() {
                let what = |_| format!("{isa} {opts:?} jumps {jumps} against scalar");
                assert_agree(&b.render(isa, &sc), &want, 1e-5, &what);
            }
        }
    }
}

#[test]
fn opaque_depth_and_empty_transfer_function() {
    let (v, mc) = shell_scene(VolumeFormat::F32);
    let ctf = preset_tf(Preset::CoolWarm, v.max_value);
    let sc = VolumeScene::new(&v, &mc, &ctf, MarchOptions::default());
    let mut b = Batch::new();
    // Straight through the centre along +x: crosses both shells twice.
    for tmax in [f32::INFINITY, 30.0, 19.0, 0.0] {
        b.push([-30.0, 0.3, 0.2], [1.0, 0.0, 0.0], tmax);
    }
    let out = b.render(Isa::detect(), &sc);
    assert!(
        out[0][3] > out[1][3] && out[1][3] > out[2][3] && out[2][3] > 0.0,
        "{out:?}"
    );
    assert_eq!(out[3], [0.0; 4]);
    for c in &out {
        assert!(c[3] <= 1.0 && c[..3].iter().all(|x| *x >= 0.0 && *x <= c[3] + 1e-6));
    }
    // Early termination: a very opaque TF stops at α ≥ 0.99 but never overshoots 1.
    let dense = ClassifiedTf::new(
        &TransferFunction::preset(Preset::Grayscale).scale_opacity(5.0),
        0.0,
        v.max_value,
        0.5,
    );
    let out = b.render(
        Isa::detect(),
        &VolumeScene::new(&v, &mc, &dense, MarchOptions::default()),
    );
    assert!(out[0][3] >= 0.99 && out[0][3] <= 1.0, "{:?}", out[0]);
    // A transparent TF renders nothing, with or without macrocells.
    let none = ClassifiedTf::new(
        &TransferFunction::preset(Preset::CoolWarm).scale_opacity(0.0),
        0.0,
        v.max_value,
        0.5,
    );
    for macrocells in [true, false] {
        let opts = MarchOptions {
            macrocells,
            ..Default::default()
        };
        let out = b.render(Isa::detect(), &VolumeScene::new(&v, &mc, &none, opts));
        assert!(out.iter().all(|c| *c == [0.0; 4]));
    }
}

#[test]
fn batch_sampler_and_classifier_match_scalar_references() {
    let (v, _) = shell_scene(VolumeFormat::U8);
    let mut rng = Rng(5);
    let n = 1001;
    let pts: Vec<[f64; 3]> = (0..n)
        .map(|_| {
            [
                rng.range(-17.0, 17.0),
                rng.range(-17.0, 17.0),
                rng.range(-17.0, 17.0),
            ]
        })
        .collect();
    let (x, y, z): (Vec<f32>, Vec<f32>, Vec<f32>) = (
        pts.iter().map(|p| p[0] as f32).collect(),
        pts.iter().map(|p| p[1] as f32).collect(),
        pts.iter().map(|p| p[2] as f32).collect(),
    );
    let ctf = preset_tf(Preset::Viridis, v.max_value);
    for isa in Isa::supported() {
        let mut out = vec![0.0; n];
        sample_points(isa, &v, &x, &y, &z, &mut out);
        for i in 0..n {
            let p = [x[i] as f64, y[i] as f64, z[i] as f64];
            let want = v.sample_trilinear(p);
            assert!(
                (out[i] as f64 - want).abs() <= 1e-5 * (1.0 + want),
                "{isa} {p:?}: {} vs {want}",
                out[i]
            );
        }
        let mut rgba = vec![[0.0; 4]; n];
        classify_values(isa, &ctf, &out, &mut rgba);
        for i in 0..n {
            let b = ctf.bin(out[i]);
            assert_eq!(
                rgba[i],
                [
                    ctf.post[4 * b],
                    ctf.post[4 * b + 1],
                    ctf.post[4 * b + 2],
                    ctf.post[4 * b + 3]
                ]
            );
        }
    }
}

#[test]
fn lighting_scales_colour_only() {
    // One atom; lighting must leave opacity unchanged, never brighten, and on the axis
    // through the centre the headlight sees the gradient head-on (almost no darkening).
    let atoms = Atoms {
        x: vec![0.0],
        y: vec![0.0],
        z: vec![0.0],
        r: vec![1.5],
    };
    let (v, mc) = volume_of(&atoms, 8.0, VolumeFormat::F32);
    let ctf = ClassifiedTf::new(&ramp_tf(), 0.0, v.max_value, 0.5);
    let mut b = atom_rays(f32::INFINITY);
    b.push([-8.0, 0.0, 0.0], [1.0, 0.0, 0.0], f32::INFINITY);
    let unlit = b.render(
        Isa::detect(),
        &VolumeScene::new(&v, &mc, &ctf, MarchOptions::default()),
    );
    let mut darker = 0;
    for lighting in [Lighting::Headlight, Lighting::Directional([0.0, 1.0, 0.0])] {
        let opts = MarchOptions {
            lighting,
            ..Default::default()
        };
        let lit = b.render(Isa::detect(), &VolumeScene::new(&v, &mc, &ctf, opts));
        for (l, u) in lit.iter().zip(&unlit) {
            assert!(
                (l[3] - u[3]).abs() < 1e-6,
                "{lighting:?}: opacity changed {l:?} vs {u:?}"
            );
            for c in 0..3 {
                assert!(
                    l[c] <= u[c] + 1e-6 && l[c] >= 0.3 * u[c] - 1e-6,
                    "{lighting:?}: {l:?} vs {u:?}"
                );
            }
            darker += (l[0] < 0.95 * u[0]) as usize;
        }
    }
    assert!(
        darker > 10,
        "lighting must visibly shade some rays ({darker})"
    );
    let opts = MarchOptions {
        lighting: Lighting::Headlight,
        ..Default::default()
    };
    let lit = b.render(Isa::detect(), &VolumeScene::new(&v, &mc, &ctf, opts));
    let (l, u) = (lit.last().unwrap(), unlit.last().unwrap());
    assert!(
        u[3] > 0.3 && l[0] > 0.9 * u[0],
        "axis ray: lit {l:?} unlit {u:?}"
    );
}

#[test]
fn degenerate_rays_terminate_with_nothing() {
    let (v, mc) = shell_scene(VolumeFormat::U8);
    let ctf = preset_tf(Preset::CoolWarm, v.max_value);
    let mut b = Batch::new();
    b.push([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], f32::INFINITY); // zero direction
    b.push([f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], f32::INFINITY);
    b.push([0.0, 0.0, 0.0], [1.0, f64::NAN, 0.0], f32::INFINITY);
    b.push([-30.0, 0.0, 0.0], [1.0, 0.0, 0.0], f32::NAN);
    b.push([-30.0, 0.0, 0.0], [1.0, 0.0, 0.0], -5.0);
    b.push([-30.0, 0.0, 0.0], [-1.0, 0.0, 0.0], f32::INFINITY); // pointing away
    b.push([-30.0, 0.0, 0.0], [1e-30, 0.0, 0.0], f32::INFINITY); // tiny direction
    for opts in all_opts().into_iter().flat_map(|o| {
        [
            o,
            MarchOptions {
                macrocells: false,
                ..o
            },
        ]
    }) {
        for isa in Isa::supported() {
            let out = b.render(isa, &VolumeScene::new(&v, &mc, &ctf, opts));
            for (i, c) in out.iter().enumerate().take(6) {
                assert_eq!(*c, [0.0; 4], "{isa} {opts:?} ray {i}");
            }
            assert!(out[6].iter().all(|x| x.is_finite()));
        }
    }
}

#[test]
fn volumetric_shadows_match_double_precision_reference() {
    // Atom A at the origin, an occluder B 4.5 Å above it (the supports, √2·r = 2.1 Å, do
    // not overlap, so the field has no cutoff jump where rays cross A): with the light
    // straight up (or a point light above), A's top is in B's shadow. Rays cross A along x.
    let atoms = Atoms {
        x: vec![0.0, 0.3],
        y: vec![0.0, 4.5],
        z: vec![0.0, -0.2],
        r: vec![1.5, 1.5],
    };
    let (v, mc) = volume_of(&atoms, 8.0, VolumeFormat::F32);
    let tf = ramp_tf();
    let hi = v.max_value;
    let ctf = ClassifiedTf::new(&tf, 0.0, hi, 0.5);
    let field = |q: [f64; 3]| phi(&atoms, q);
    let reference = Reference::new(&field, &tf, hi, &v.grid);
    let b = atom_rays(f32::INFINITY);
    let ambient = 0.3;
    for light in [
        Light::Directional([0.0, 1.0, 0.0]),
        Light::Point([0.5, 9.0, 0.5]),
    ] {
        let shadows = VolumeShadows {
            light,
            step_voxels: 0.5,
        };
        let shade = |q: [f64; 3]| {
            let t = reference.transmittance(q, light, 0.05);
            ambient + (1.0 - ambient) * t
        };
        let want = reference.batch(&b, 0.01, &shade);
        let unshadowed = reference.batch(&b, 0.01, &unshaded);
        // The shadows must matter: B darkens A by a lot on some rays, not on others.
        let darkening: Vec<f64> = want
            .iter()
            .zip(&unshadowed)
            .map(|(w, u)| u[0] - w[0])
            .collect();
        assert!(
            darkening.iter().filter(|&&d| d > 0.05).count() > 5,
            "{light:?}: shadows too weak to test: {darkening:?}"
        );
        let opts = MarchOptions {
            shadows: Some(shadows),
            ..Default::default()
        };
        let sc = VolumeScene::new(&v, &mc, &ctf, opts);
        let lv = LightVolume::build(Isa::Scalar, &sc, shadows, 2);
        let sc_lv = sc.with_light_volume(&lv);
        let rays_scalar = b.render(Isa::Scalar, &sc);
        let lv_scalar = b.render(Isa::Scalar, &sc_lv);
        for isa in Isa::under_test() {
            for (what, scene, scalar, tol) in [
                ("shadow rays", &sc, &rays_scalar, 4.0 / 255.0),
                ("light volume", &sc_lv, &lv_scalar, 4.0 / 255.0),
            ] {
                let got = b.render(isa, scene);
                let e = max_err(&got, &want);
                eprintln!("{light:?} {what} {isa}: max error {:.2}/255", e * 255.0);
                assert!(e <= tol, "{light:?} {what} {isa}: max error {e}");
                // Every backend against scalar, tighter (fma and rcp differences only).
                for (x, y) in got.iter().zip(scalar.iter()) {
                    for c in 0..4 {
                        assert!(
                            (x[c] - y[c]).abs() <= 1.0 / 255.0,
                            "{light:?} {what} {isa}: {x:?} vs scalar {y:?}"
                        );
                    }
                }
            }
        }
        // Opacity is the volume's, whatever the lighting.
        let plain = b.render(
            Isa::Scalar,
            &VolumeScene::new(&v, &mc, &ctf, MarchOptions::default()),
        );
        for (x, y) in rays_scalar.iter().zip(&plain) {
            assert!(
                (x[3] - y[3]).abs() < 1e-6 && x[0] <= y[0] + 1e-6,
                "{x:?} vs {y:?}"
            );
        }
    }
}

#[test]
fn light_volume_is_the_shadow_rays_on_a_shell() {
    // Two nested shells lit from the side: the light volume's look-up against a shadow ray
    // per sample, u8 and f32 volumes, with and without gradient lighting. The light volume
    // (every 2 voxels = 0.67 Å here, 8 bits) blurs shadow edges on the atomic scale: measured
    // worst 13.1/255, mean 1.3/255 per channel.
    for format in [VolumeFormat::U8, VolumeFormat::F32] {
        let (v, mc) = shell_scene(format);
        let ctf = preset_tf(Preset::CoolWarm, v.max_value);
        let b = scattered_rays(203, 5);
        for lighting in [Lighting::Unlit, Lighting::Directional([1.0, 0.3, 0.2])] {
            let shadows = VolumeShadows {
                light: Light::Directional([1.0, 0.3, 0.2]),
                step_voxels: 2.0,
            };
            let opts = MarchOptions {
                lighting,
                shadows: Some(shadows),
                ..Default::default()
            };
            let sc = VolumeScene::new(&v, &mc, &ctf, opts);
            let rays = b.render(Isa::detect(), &sc);
            let lv = LightVolume::build(Isa::detect(), &sc, shadows, 2);
            let looked_up = b.render(Isa::detect(), &sc.with_light_volume(&lv));
            let unshadowed = b.render(
                Isa::detect(),
                &VolumeScene::new(
                    &v,
                    &mc,
                    &ctf,
                    MarchOptions {
                        shadows: None,
                        ..opts
                    },
                ),
            );
            let (mut worst, mut mean, mut dark) = (0.0f32, 0.0f64, 0);
            for ((x, y), u) in looked_up.iter().zip(&rays).zip(&unshadowed) {
                for c in 0..4 {
                    worst = worst.max((x[c] - y[c]).abs());
                    mean += (x[c] - y[c]).abs() as f64;
                }
                dark += (u[0] - y[0] > 0.05) as usize;
            }
            mean /= 4.0 * rays.len() as f64;
            eprintln!(
                "{format} {lighting:?}: worst {:.2}/255, mean {:.3}/255, {dark} darkened",
                worst * 255.0,
                mean * 255.0
            );
            assert!(
                dark > 20,
                "{format} {lighting:?}: shadows must darken rays ({dark})"
            );
            assert!(
                worst <= 16.0 / 255.0 && mean <= 2.0 / 255.0,
                "{format} {lighting:?}: worst {worst}, mean {mean}"
            );
        }
    }
}

#[test]
fn early_termination_stops_at_the_first_segment_past_the_cutoff() {
    // A constant medium: every half-voxel segment has the same opacity, so the cut-off's
    // segment is unambiguous. Rays enter at staggered depths, so lanes of one packet pass
    // the cut-off in different iterations while their neighbours march on.
    let dims = [24, 12, 12];
    let v = Volume {
        grid: Grid {
            origin: [0.0; 3],
            spacing: 1.0,
            dims,
        },
        data: VolumeData::F32(vec![1.0; dims.iter().product()]),
        max_value: 1.0,
    };
    let mc = Macrocells::build(&v);
    let ctf = ClassifiedTf::new(
        &TransferFunction::preset(Preset::Grayscale).scale_opacity(2.0),
        0.0,
        2.0,
        0.5,
    );
    let start = |j: usize| 2.0 + 0.37 * j as f32; // entry depth of ray j, Å
    let ray = |b: &mut Batch, j: usize, tmax: f32| {
        let y = 3.0 + 0.25 * (j % 20) as f64;
        b.push([-start(j) as f64, y, 5.5], [1.0, 0.0, 0.0], tmax);
    };
    let rays = 37;
    for (base, _, label) in classification_opts(0.0, 0.0) {
        for isa in Isa::supported() {
            // Without a cut-off, ray j after n segments (tmax at the n-th segment's back).
            let never = VolumeScene::new(
                &v,
                &mc,
                &ctf,
                MarchOptions {
                    opacity_cutoff: 2.0,
                    ..base
                },
            );
            let mut prefix = Batch::new();
            for j in 0..rays {
                for n in 1..=40 {
                    ray(&mut prefix, j, start(j) + 0.5 * n as f32);
                }
            }
            let after = prefix.render(isa, &never);
            let step = after[1][3] - after[0][3];
            assert!(
                after[0][3] > 0.02 && step > 0.01 && after[39][3] > 0.95,
                "{label} {isa}: the medium must be neither too thin nor too dense: {after:?}"
            );
            for cutoff in [0.3f32, 0.6, 0.9] {
                let sc = VolumeScene::new(
                    &v,
                    &mc,
                    &ctf,
                    MarchOptions {
                        opacity_cutoff: cutoff,
                        ..base
                    },
                );
                let mut b = Batch::new();
                for j in 0..rays {
                    ray(&mut b, j, f32::INFINITY);
                }
                let got = b.render(isa, &sc);
                for (j, g) in got.iter().enumerate() {
                    let a = &after[40 * j..40 * (j + 1)];
                    let n = a.iter().position(|c| c[3] >= cutoff).unwrap();
                    for c in 0..4 {
                        assert!(
                            (g[c] - a[n][c]).abs() <= 1e-4,
                            "{label} {isa} cut-off {cutoff}, ray {j}: {g:?}, want segment {} {:?}",
                            n + 1,
                            a[n]
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn empty_space_jumps_match_the_walk_in_a_sparse_scene() {
    // Three small clusters far apart: most macrocells are far from anything visible, so
    // rays jump several cells at a time, in every direction, and land next to the atoms.
    let mut a = Atoms {
        x: vec![],
        y: vec![],
        z: vec![],
        r: vec![],
    };
    let centres = [
        [-20.0, -18.0, -15.0],
        [17.0, 19.0, -16.0],
        [2.0, 15.0, 19.0],
    ];
    for c in centres {
        for (dx, dy, dz) in [(0.0, 0.0, 0.0), (1.4, 0.3, 0.0), (0.2, -1.2, 0.9)] {
            a.x.push(c[0] + dx);
            a.y.push(c[1] + dy);
            a.z.push(c[2] + dz);
            a.r.push(1.6);
        }
    }
    let (v, mc) = volume_of(&a, 2.0, VolumeFormat::U8);
    let ctf = preset_tf(Preset::CoolWarm, v.max_value);
    let es = EmptySpace::build(&mc, &ctf);
    assert!(
        es.distance.iter().filter(|&&d| d >= 3).count() * 2 > es.distance.len(),
        "the test needs mostly far-empty cells: {:?}",
        es.dims
    );
    // Rays from all sides aimed at the clusters (with scatter), some missing them.
    let mut rng = Rng(11);
    let mut b = Batch::new();
    for i in 0..400 {
        let c = centres[i % 3];
        let t: [f64; 3] = core::array::from_fn(|k| c[k] as f64 + rng.range(-3.0, 3.0));
        let o: [f64; 3] = core::array::from_fn(|_| rng.range(-45.0, 45.0));
        let d: [f64; 3] = core::array::from_fn(|k| t[k] - o[k]);
        b.push(o, d, f32::INFINITY);
    }
    for opts in all_opts() {
        let off = MarchOptions {
            macrocells: false,
            ..opts
        };
        let want = b.render(Isa::Scalar, &VolumeScene::new(&v, &mc, &ctf, off));
        assert!(want.iter().filter(|c| c[3] > 0.1).count() > 100);
        let sc = VolumeScene::new(&v, &mc, &ctf, opts).with_empty_space(&es);
        for isa in Isa::supported() {
            let what = |_| format!("{isa} {opts:?}: jumps against no skipping");
            assert_agree(&b.render(isa, &sc), &want, 1.0 / 255.0, &what);
        }
    }
}

#[test]
#[should_panic(expected = "another transfer function")]
fn an_empty_space_map_of_another_transfer_function_is_refused() {
    let (v, mc) = shell_scene(VolumeFormat::U8);
    let a = preset_tf(Preset::CoolWarm, v.max_value);
    let b = ClassifiedTf::new(
        &TransferFunction::preset(Preset::CoolWarm).scale_opacity(0.0),
        0.0,
        v.max_value,
        0.5,
    );
    let es = EmptySpace::build(&mc, &a);
    assert!(es.matches(&mc, &a) && !es.matches(&mc, &b));
    let _ = VolumeScene::new(&v, &mc, &b, MarchOptions::default()).with_empty_space(&es);
}
