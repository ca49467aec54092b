//! Synthetic motion for multi-frame test trajectories (`bnsview generate --frames N`): every
//! atom jittered as by thermal motion and the whole model breathing about its centre,
//! deterministic in the seed and frame index, so tests and benchmarks get long dumps of any
//! size without a simulation.

use crate::scenes::splitmix as mix;
use crate::Molecule;

/// Root-mean-square displacement per Cartesian component at 300 K (Å): the order of
/// thermal vibration of atoms in a solid.
pub const JITTER_AT_300K: f64 = 0.05;
/// Relative amplitude of the breathing (scale about the centre).
pub const BREATHING: f64 = 0.02;
/// Frames per breathing period.
pub const BREATHING_PERIOD: f64 = 20.0;

/// Uniform in (0, 1] from a key.
fn unit(key: u64) -> f64 {
    ((mix(key) >> 11) as f64 + 1.0) / (1u64 << 53) as f64
}

/// A standard normal number from a key (Box–Muller).
fn normal(key: u64) -> f64 {
    let (u, v) = (unit(key), unit(key ^ 0x5555_5555_5555_5555));
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

/// Frame `frame` of a synthetic trajectory of `base`: each coordinate moved by a normal
/// displacement of RMS `JITTER_AT_300K · sqrt(temperature_k / 300)` Å, then the model scaled
/// about its box centre by `1 + BREATHING · sin(2π · frame / BREATHING_PERIOD)`. Frame 0 has
/// jitter but no breathing. Same `(base, frame, seed, temperature_k)`, same frame.
pub fn thermal_frame(base: &Molecule, frame: usize, seed: u64, temperature_k: f32) -> Molecule {
    let sigma = JITTER_AT_300K * (f64::from(temperature_k.max(0.0)) / 300.0).sqrt();
    let scale = 1.0 + BREATHING * (std::f64::consts::TAU * frame as f64 / BREATHING_PERIOD).sin();
    let (lo, hi) = base.bounds();
    let c = [0, 1, 2].map(|k| 0.5 * (f64::from(lo[k]) + f64::from(hi[k])));
    let mut m = base.clone();
    let key = mix(seed ^ mix(frame as u64));
    for (axis, coords) in [&mut m.x, &mut m.y, &mut m.z].into_iter().enumerate() {
        for (i, v) in coords.iter_mut().enumerate() {
            let d = sigma * normal(key ^ mix((i as u64) << 2 | axis as u64));
            *v = (c[axis] + (f64::from(*v) + d - c[axis]) * scale) as f32;
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jitter_has_the_asked_rms_and_is_deterministic() {
        let n = 20_000;
        let base = Molecule {
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: vec![0.0; n],
            elements: vec![6; n],
            ..Molecule::default()
        };
        let a = thermal_frame(&base, 0, 7, 1200.0);
        assert_eq!(a, thermal_frame(&base, 0, 7, 1200.0));
        assert_ne!(a, thermal_frame(&base, 1, 7, 1200.0));
        let rms = (a.x.iter().map(|v| f64::from(*v).powi(2)).sum::<f64>() / n as f64).sqrt();
        let want = JITTER_AT_300K * 2.0; // sqrt(1200 / 300)
        assert!((rms / want - 1.0).abs() < 0.03, "rms {rms}, want {want}");
    }
}
