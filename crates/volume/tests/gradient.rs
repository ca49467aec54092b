//! Gradient shading of the grid marcher against a double-precision reference: the grid's own
//! trilinear field, shaded with the six-sample central-difference gradient (one voxel each way,
//! clamped to the box), on a lattice whose density reaches its border.

mod common;

use common::*;
use spmd::Isa;
use volume::*;

/// A 13 × 11 × 12 lattice (0.5 Å apart) of a few Gaussian blobs, two of them on the box's
/// faces, plus noise: non-zero up to the border, so both the stencil and its border fallback
/// shade.
fn blob_volume(format: VolumeFormat) -> Volume {
    let grid = Grid {
        origin: [-3.0, -2.5, -2.75],
        spacing: 0.5,
        dims: [13, 11, 12],
    };
    let mut rng = Rng(7);
    let centres = [
        [0.0, 0.0, 0.0],
        [-3.0, 1.0, 0.5],
        [1.5, -2.5, -1.0],
        [2.0, 1.5, 2.0],
    ];
    let mut vals = Vec::with_capacity(13 * 11 * 12);
    for k in 0..12 {
        for j in 0..11 {
            for i in 0..13 {
                let p = grid.point(i, j, k).map(|x| x as f64);
                let mut v = 0.0;
                for c in &centres {
                    let d2: f64 = (0..3).map(|a| (p[a] - c[a]).powi(2)).sum();
                    v += (-d2 / 2.0).exp();
                }
                vals.push((v * rng.range(0.9, 1.1)) as f32);
            }
        }
    }
    let max_value = vals.iter().copied().fold(0.0, f32::max);
    let data = match format {
        VolumeFormat::F32 => VolumeData::F32(vals),
        VolumeFormat::U8 => {
            let scale = max_value / 255.0;
            let mut q: Vec<u8> = vals.iter().map(|v| (v / scale).round() as u8).collect();
            q.extend([0; 4]);
            VolumeData::U8 { data: q, scale }
        }
    };
    Volume {
        grid,
        data,
        max_value,
    }
}

/// Rays from all sides through the box, some grazing its faces.
fn box_rays(n: usize) -> Batch {
    let mut rng = Rng(11);
    let mut b = Batch::new();
    for _ in 0..n {
        let target = [
            rng.range(-3.2, 3.2),
            rng.range(-2.7, 2.7),
            rng.range(-3.0, 3.0),
        ];
        let d = [
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        ];
        let o: [f64; 3] = core::array::from_fn(|a| target[a] - 12.0 * d[a]);
        b.push(o, d, f32::INFINITY);
    }
    b
}

#[test]
fn lit_grid_march_matches_central_differences_in_double_precision() {
    let light = [0.3f64, -0.5, 0.8];
    let ambient = 0.3;
    for format in [VolumeFormat::U8, VolumeFormat::F32] {
        let v = blob_volume(format);
        let mc = Macrocells::build(&v);
        let h = v.grid.spacing as f64;
        let field = |q: [f64; 3]| v.sample_trilinear(q);
        // |n·l| with n the six-sample gradient, as the kernels' `facing` (1 where it vanishes).
        let shade = |q: [f64; 3]| {
            let g: [f64; 3] = core::array::from_fn(|a| {
                let (mut p, mut m) = (q, q);
                p[a] += h;
                m[a] -= h;
                field(p) - field(m)
            });
            let gg: f64 = g.iter().map(|x| x * x).sum();
            let ll: f64 = light.iter().map(|x| x * x).sum();
            let gl: f64 = (0..3).map(|a| g[a] * light[a]).sum();
            let f = if gg > 1e-20 {
                (gl.abs() / (gg * ll).sqrt()).min(1.0)
            } else {
                1.0
            };
            ambient + (1.0 - ambient) * f
        };
        let tf = ramp_tf();
        let hi = v.max_value;
        let reference = Reference::new(&field, &tf, hi, &v.grid);
        let b = box_rays(150);
        let want = reference.batch(&b, 0.01, &shade);
        let flat = reference.batch(&b, 0.01, &unshaded);
        // The test means something only if the shading matters.
        let shaded = want
            .iter()
            .zip(&flat)
            .filter(|(w, u)| (u[0] - w[0]).abs() > 0.05)
            .count();
        assert!(shaded > 30, "{format}: shading changes only {shaded} rays");
        let ctf = ClassifiedTf::new(&tf, 0.0, hi, 0.05);
        for preintegrated in [true, false] {
            let opts = MarchOptions {
                preintegrated,
                lighting: Lighting::Directional(light.map(|x| x as f32)),
                ambient: ambient as f32,
                ..Default::default()
            };
            let sc = VolumeScene::new(&v, &mc, &ctf, opts);
            for isa in Isa::supported() {
                let label = format!("{format} preint {preintegrated} {isa}");
                assert_near(&label, &b.render(isa, &sc), &want, 3.0 / 255.0);
            }
        }
    }
}
