//! Synthetic nanosphere: nested graphitic shells (carbon, r = 0.76 Å, 0.38 atoms/Å², 3.4 Å
//! apart) from 20 Å outwards until `n` atoms, like the paper's ns740k. Shared by the benches
//! and the `ns740k` example; the real reference scenes live in the molecule crate.
#![allow(dead_code)]

pub struct Atoms {
    pub x: Vec<f32>,
    pub y: Vec<f32>,
    pub z: Vec<f32>,
    pub r: Vec<f32>,
}

pub fn nanosphere(n: usize, r0: f64) -> Atoms {
    let mut a = Atoms {
        x: vec![],
        y: vec![],
        z: vec![],
        r: vec![],
    };
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let mut radius = r0;
    while a.x.len() < n {
        let m = ((4.0 * std::f64::consts::PI * radius * radius * 0.38).round() as usize)
            .min(n - a.x.len());
        let full = (4.0 * std::f64::consts::PI * radius * radius * 0.38).round() as usize;
        for i in 0..m {
            let zz = 1.0 - 2.0 * (i as f64 + 0.5) / full as f64;
            let rr = (1.0 - zz * zz).max(0.0).sqrt();
            let th = golden * i as f64;
            a.x.push((radius * rr * th.cos()) as f32);
            a.y.push((radius * rr * th.sin()) as f32);
            a.z.push((radius * zz) as f32);
            a.r.push(0.76);
        }
        radius += 3.4;
    }
    a
}

/// Pinhole camera rays (`w × h`, 40° vertical field of view) from `eye` looking at the origin.
pub fn camera_rays(w: usize, h: usize, eye: [f32; 3]) -> [Vec<f32>; 6] {
    let len = (eye[0] * eye[0] + eye[1] * eye[1] + eye[2] * eye[2]).sqrt();
    let f = [-eye[0] / len, -eye[1] / len, -eye[2] / len];
    let up = [0.0f32, 1.0, 0.0];
    let mut rt = [
        f[1] * up[2] - f[2] * up[1],
        f[2] * up[0] - f[0] * up[2],
        f[0] * up[1] - f[1] * up[0],
    ];
    let rl = (rt[0] * rt[0] + rt[1] * rt[1] + rt[2] * rt[2]).sqrt();
    rt = rt.map(|c| c / rl);
    let u = [
        rt[1] * f[2] - rt[2] * f[1],
        rt[2] * f[0] - rt[0] * f[2],
        rt[0] * f[1] - rt[1] * f[0],
    ];
    let th = (20.0f32).to_radians().tan();
    let mut out: [Vec<f32>; 6] = Default::default();
    for j in 0..h {
        for i in 0..w {
            let sx = (2.0 * (i as f32 + 0.5) / w as f32 - 1.0) * th * w as f32 / h as f32;
            let sy = (1.0 - 2.0 * (j as f32 + 0.5) / h as f32) * th;
            for a in 0..3 {
                out[a].push(eye[a]);
                out[3 + a].push(f[a] + rt[a] * sx + u[a] * sy);
            }
        }
    }
    out
}
