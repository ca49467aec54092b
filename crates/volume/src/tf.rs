//! Transfer functions: a 256-entry RGBA table over a value range, presets, a text format, and
//! the per-render tables derived from it (step-corrected post-classification table,
//! pre-integration table, range-max opacity table for macrocell emptiness).
//!
//! ## Meaning of an entry
//! Entry `i` (0..=255) classifies the normalised value `i / 255` of the range `[lo, hi]`
//! (density units; by default `[0, Volume::max_value]`). Between entries the classification is
//! the linear interpolation of the entries. `r, g, b` are the emitted colour in `[0, 1]`; `a`
//! is the **opacity of one voxel of path length** (extinction `τ = −ln(1 − a)` per voxel), so a
//! step of `Δ` voxels has opacity `1 − (1 − a)^Δ` (opacity correction).
//!
//! ## Text format
//! One control point per line: `value r g b a`, five numbers separated by blanks (or commas),
//! `value` in `[0, 1]` of the normalised range, colour and opacity in `[0, 1]`. Values must not
//! decrease (two equal values make a step). `#` starts a comment; blank lines are ignored. At
//! least two points. Entries before the first / after the last point take that point's
//! colour. Example:
//! ```text
//! # value  r    g    b    a
//!   0.0    0.0  0.0  0.5  0.0
//!   0.2    0.0  0.0  0.5  0.0   # transparent below 0.2
//!   1.0    1.0  0.8  0.2  0.3
//! ```

use std::path::Path;

use rayon::prelude::*;

/// Number of transfer-function entries (bins).
pub const TF_SIZE: usize = 256;

/// A 256-entry RGBA table (colour in `[0,1]`, alpha = opacity per voxel of path).
#[derive(Clone, Debug, PartialEq)]
pub struct TransferFunction {
    /// The entries; entry `i` classifies normalised value `i / 255`.
    pub table: Vec<[f32; 4]>,
}

/// A control point of the text format: normalised value and RGBA.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlPoint {
    /// Position in `[0, 1]` of the normalised value range.
    pub value: f32,
    /// Colour and opacity per voxel, each in `[0, 1]`.
    pub rgba: [f32; 4],
}

/// Built-in transfer functions suited to the density: transparent below ~15 % of the range
/// (empty space and the tails of the Gaussians), then a smooth opacity ramp.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Preset {
    /// Moreland's diverging cool-warm (blue → grey → red).
    CoolWarm,
    /// A viridis-like ramp (purple → teal → yellow).
    Viridis,
    /// White, for tests and for checking shapes.
    Grayscale,
}

impl Preset {
    /// Every preset.
    pub const ALL: [Preset; 3] = [Preset::CoolWarm, Preset::Viridis, Preset::Grayscale];
    /// Name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Preset::CoolWarm => "coolwarm",
            Preset::Viridis => "viridis",
            Preset::Grayscale => "grayscale",
        }
    }
}

impl core::str::FromStr for Preset {
    type Err = String;
    fn from_str(s: &str) -> Result<Preset, String> {
        let l = s.trim().to_ascii_lowercase();
        Preset::ALL
            .into_iter()
            .find(|p| p.name() == l || (l == "cool-warm" && *p == Preset::CoolWarm))
            .ok_or_else(|| format!("unknown transfer function preset {s:?}: expected coolwarm, viridis or grayscale"))
    }
}

/// Why a transfer-function file could not be used: where and what.
#[derive(Debug, thiserror::Error)]
pub enum TfError {
    /// A problem on one line (1-based) of `source`.
    #[error("{source_name}:{line}: {message}")]
    Line {
        /// File name (or a label for in-memory text).
        source_name: String,
        /// 1-based line number.
        line: usize,
        /// What was wrong and what was expected.
        message: String,
    },
    /// A problem with the whole file.
    #[error("{source_name}: {message}")]
    File {
        /// File name (or label).
        source_name: String,
        /// What was wrong.
        message: String,
    },
    /// A `--tf` value that is neither a preset nor an existing file.
    #[error("--tf {0:?}: neither a preset (coolwarm, viridis, grayscale) nor an existing file")]
    Unknown(String),
    /// The file could not be read.
    #[error("{source_name}: {err}")]
    Io {
        /// File name.
        source_name: String,
        /// The I/O error.
        err: std::io::Error,
    },
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl TransferFunction {
    /// From control points (sorted by non-decreasing value; at least one).
    pub fn from_control_points(points: &[ControlPoint]) -> TransferFunction {
        assert!(
            !points.is_empty(),
            "transfer function needs a control point"
        );
        let table = (0..TF_SIZE)
            .map(|i| {
                let x = i as f32 / 255.0;
                let j = points.partition_point(|p| p.value <= x);
                if j == 0 {
                    points[0].rgba
                } else if j == points.len() {
                    points[j - 1].rgba
                } else {
                    let (a, b) = (points[j - 1], points[j]);
                    let t = (x - a.value) / (b.value - a.value);
                    core::array::from_fn(|c| a.rgba[c] + (b.rgba[c] - a.rgba[c]) * t)
                }
            })
            .collect();
        TransferFunction { table }
    }

    /// A preset with its default opacity ramp: `a = 0.2 · smoothstep(0.15, 0.85, x)`.
    pub fn preset(p: Preset) -> TransferFunction {
        let colours: &[(f32, [f32; 3])] = match p {
            Preset::CoolWarm => &[
                (0.0, [0.230, 0.299, 0.754]),
                (0.25, [0.552, 0.690, 0.996]),
                (0.5, [0.865, 0.865, 0.865]),
                (0.75, [0.958, 0.604, 0.482]),
                (1.0, [0.706, 0.016, 0.150]),
            ],
            Preset::Viridis => &[
                (0.0, [0.267, 0.005, 0.329]),
                (0.125, [0.283, 0.141, 0.458]),
                (0.25, [0.254, 0.265, 0.530]),
                (0.375, [0.207, 0.372, 0.553]),
                (0.5, [0.164, 0.471, 0.558]),
                (0.625, [0.128, 0.567, 0.551]),
                (0.75, [0.135, 0.659, 0.518]),
                (0.875, [0.478, 0.821, 0.319]),
                (1.0, [0.993, 0.906, 0.144]),
            ],
            Preset::Grayscale => &[(0.0, [1.0, 1.0, 1.0]), (1.0, [1.0, 1.0, 1.0])],
        };
        let pts: Vec<ControlPoint> = colours
            .iter()
            .map(|&(value, c)| ControlPoint {
                value,
                rgba: [c[0], c[1], c[2], 0.0],
            })
            .collect();
        let mut tf = TransferFunction::from_control_points(&pts);
        for (i, e) in tf.table.iter_mut().enumerate() {
            e[3] = 0.2 * smoothstep(0.15, 0.85, i as f32 / 255.0);
        }
        tf
    }

    /// Multiplies every opacity by `k` (clamped to `[0, 1]`).
    pub fn scale_opacity(mut self, k: f32) -> Self {
        for e in &mut self.table {
            e[3] = (e[3] * k).clamp(0.0, 1.0);
        }
        self
    }

    /// Parses the text format (see the module docs); `source_name` labels errors.
    pub fn parse(text: &str, source_name: &str) -> Result<TransferFunction, TfError> {
        let err = |line: usize, message: String| TfError::Line {
            source_name: source_name.to_string(),
            line,
            message,
        };
        let mut points: Vec<ControlPoint> = Vec::new();
        for (n, raw) in text.lines().enumerate() {
            let line = n + 1;
            let body = raw.split('#').next().unwrap_or("");
            let fields: Vec<&str> = body
                .split(|c: char| c.is_whitespace() || c == ',')
                .filter(|f| !f.is_empty())
                .collect();
            if fields.is_empty() {
                continue;
            }
            if fields.len() != 5 {
                return Err(err(
                    line,
                    format!(
                        "expected 5 numbers `value r g b a`, found {} field(s)",
                        fields.len()
                    ),
                ));
            }
            let mut v = [0.0f32; 5];
            for (k, f) in fields.iter().enumerate() {
                let name = ["value", "r", "g", "b", "a"][k];
                let x: f32 = f
                    .parse()
                    .map_err(|_| err(line, format!("{name}: {f:?} is not a number")))?;
                if !(0.0..=1.0).contains(&x) {
                    return Err(err(line, format!("{name} = {f} is outside [0, 1]")));
                }
                v[k] = x;
            }
            if let Some(prev) = points.last() {
                if v[0] < prev.value {
                    return Err(err(
                        line,
                        format!(
                            "value {} is less than the previous point's {}: values must not decrease",
                            v[0], prev.value
                        ),
                    ));
                }
            }
            points.push(ControlPoint {
                value: v[0],
                rgba: [v[1], v[2], v[3], v[4]],
            });
        }
        if points.len() < 2 {
            return Err(TfError::File {
                source_name: source_name.to_string(),
                message: format!(
                    "need at least 2 control points `value r g b a`, found {}",
                    points.len()
                ),
            });
        }
        Ok(TransferFunction::from_control_points(&points))
    }

    /// A preset by name (see [`Preset`]) or else a control-point file at `spec` (the `--tf`
    /// flag).
    pub fn from_spec(spec: &str) -> Result<TransferFunction, TfError> {
        if let Ok(p) = spec.parse::<Preset>() {
            return Ok(TransferFunction::preset(p));
        }
        let path = Path::new(spec);
        if !path.exists() {
            return Err(TfError::Unknown(spec.to_string()));
        }
        TransferFunction::load(path)
    }

    /// Reads and parses a transfer-function file.
    pub fn load(path: &Path) -> Result<TransferFunction, TfError> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|err| TfError::Io {
            source_name: name.clone(),
            err,
        })?;
        TransferFunction::parse(&text, &name)
    }

    /// The continuous classification at bin coordinate `x ∈ [0, 255]` (linear interpolation of
    /// the entries; clamped outside).
    pub fn eval(&self, x: f64) -> [f64; 4] {
        let x = x.clamp(0.0, 255.0);
        let i = (x.floor() as usize).min(TF_SIZE - 2);
        let t = x - i as f64;
        let (a, b) = (self.table[i], self.table[i + 1]);
        core::array::from_fn(|c| a[c] as f64 * (1.0 - t) + b[c] as f64 * t)
    }
}

/// Extinction per voxel of an opacity per voxel (capped so fully opaque stays finite).
#[inline]
pub fn extinction(alpha: f64) -> f64 {
    -(1.0 - alpha.clamp(0.0, 1.0 - 1e-6)).ln()
}

/// Tables derived from a transfer function for one value range and one step length; cheap to
/// rebuild when the transfer function changes (no volume or macrocell rebuild).
#[derive(Clone, Debug)]
pub struct ClassifiedTf {
    /// Value mapped to entry 0.
    pub lo: f32,
    /// Value mapped to entry 255.
    pub hi: f32,
    /// `255 / (hi − lo)`: value → bin coordinate.
    pub to_bin: f32,
    /// Step length (voxels) the tables are corrected for.
    pub step_voxels: f32,
    /// Post-classification: per bin, premultiplied `[r·α, g·α, b·α, α]` with
    /// `α = 1 − (1 − a)^step` (interleaved, 256 × 4).
    pub post: Vec<f32>,
    /// Pre-integrated: per (front bin, back bin) the premultiplied colour and opacity of a
    /// segment of `step` voxels along which the value goes linearly from front to back
    /// (interleaved, index `(front·256 + back)·4`).
    pub preint: Vec<f32>,
    /// `preint` in IEEE binary16, two channels per word, as the marcher reads it: index
    /// `(front·256 + back)·2` holds `r | g << 16`, the next `b | a << 16`. Half the bytes
    /// (512 KiB) and half the gathers of `preint`, relative error ≤ 2⁻¹¹ (absolute ≤ 2⁻²⁵
    /// below 2⁻¹⁴).
    pub preint_half: Vec<i32>,
    /// Max opacity per voxel over entries `[i, j]` (either order), index `i·256 + j`;
    /// a macrocell is empty when this is 0 over its (widened) bin range.
    pub range_max: Vec<f32>,
    /// Extinction `τ = −ln(1 − a)` per voxel of path for each bin (256 entries), `a` the
    /// entry's opacity per voxel: what shadow rays sum (`crate::shadow`).
    pub tau: Vec<f32>,
}

impl ClassifiedTf {
    /// Classifies `tf` over values `[lo, hi]` (density units) for steps of `step_voxels`.
    pub fn new(tf: &TransferFunction, lo: f32, hi: f32, step_voxels: f32) -> ClassifiedTf {
        assert!(hi > lo, "transfer function range must be non-empty");
        assert!(step_voxels > 0.0);
        let d = step_voxels as f64;
        let mut post = vec![0.0f32; TF_SIZE * 4];
        for (i, e) in tf.table.iter().enumerate() {
            let a = 1.0 - (-d * extinction(e[3] as f64)).exp();
            for c in 0..3 {
                post[i * 4 + c] = (e[c] as f64 * a) as f32;
            }
            post[i * 4 + 3] = a as f32;
        }
        // The classification sampled at 1/16 bin, with extinction instead of opacity, so the
        // 65536 integrals below need no logarithm (as `preintegrate`, in f32; ~3× faster).
        let fine: Vec<[f32; 4]> = (0..=255 * FINE)
            .map(|i| {
                let e = tf.eval(i as f64 / FINE as f64);
                [
                    e[0] as f32,
                    e[1] as f32,
                    e[2] as f32,
                    extinction(e[3]) as f32,
                ]
            })
            .collect();
        // A segment from bin f to bin b takes n = 2·|b − f| + 1 sub-steps, so the opacity of
        // a sub-step at each fine sample depends only on |b − f|: 256 tables of 4081 `exp`s
        // instead of one `exp` per sub-step of every pair (1.0 M instead of 11.2 M).
        let alphas: Vec<Vec<f32>> = (0..TF_SIZE)
            .into_par_iter()
            .map(|d| sub_step_opacities(&fine, sub_steps(d), step_voxels))
            .collect();
        // LANES rows at a time: for each signed bin distance Δ the rows' pairs (f, f + Δ) share
        // n and `alphas[|Δ|]`, so their latency-bound chains interleave (lanes whose f + Δ is
        // off the table compute a valid pair and are dropped).
        let mut preint = vec![0.0f32; TF_SIZE * TF_SIZE * 4];
        preint
            .par_chunks_mut(LANES * TF_SIZE * 4)
            .enumerate()
            .for_each(|(chunk, rows)| {
                let (f0, last) = ((chunk * LANES) as isize, TF_SIZE as isize - 1);
                for delta in -last..=last {
                    // The rows f whose back bin f + Δ is on the table.
                    let (lo, hi) = ((-delta).max(0), last.min(last - delta));
                    if f0 > hi || f0 + (LANES as isize) <= lo {
                        continue;
                    }
                    let f = core::array::from_fn(|l| (f0 + l as isize).clamp(lo, hi) as f32);
                    let v =
                        preintegrate_lanes(&fine, &alphas[delta.unsigned_abs()], f, delta as f32);
                    for (l, v) in v.iter().enumerate() {
                        let f = f0 + l as isize;
                        if (lo..=hi).contains(&f) {
                            let at = (l * TF_SIZE + (f + delta) as usize) * 4;
                            rows[at..at + 4].copy_from_slice(v);
                        }
                    }
                }
            });
        let preint_half = preint
            .chunks_exact(2)
            .map(|p| (half_bits(p[0]) as u32 | (half_bits(p[1]) as u32) << 16) as i32)
            .collect();
        let mut range_max = vec![0.0f32; TF_SIZE * TF_SIZE];
        for i in 0..TF_SIZE {
            let mut m = 0.0f32;
            for j in i..TF_SIZE {
                m = m.max(tf.table[j][3]);
                range_max[i * TF_SIZE + j] = m;
                range_max[j * TF_SIZE + i] = m;
            }
        }
        let tau = tf
            .table
            .iter()
            .map(|e| extinction(e[3] as f64) as f32)
            .collect();
        ClassifiedTf {
            lo,
            hi,
            to_bin: 255.0 / (hi - lo),
            step_voxels,
            post,
            preint,
            preint_half,
            range_max,
            tau,
        }
    }

    /// Bin (0..=255) of a value, as the kernels compute it: `round(clamp((v − lo)·to_bin))`.
    pub fn bin(&self, v: f32) -> usize {
        (((v - self.lo) * self.to_bin).clamp(0.0, 255.0) + 0.5) as usize
    }
}

/// IEEE binary16 bits of `x`, rounded to nearest even; `x` finite, in `[0, 65504]` (table
/// entries are in `[0, 1]`).
pub fn half_bits(x: f32) -> u16 {
    assert!((0.0..=65504.0).contains(&x), "half_bits: {x} out of range");
    if x < 6.103_515_6e-5 {
        // Subnormal (or the smallest normal after rounding): units of 2⁻²⁴.
        return (x as f64 * 16_777_216.0).round_ties_even() as u16;
    }
    let b = x.to_bits();
    let e = (b >> 23) + 15 - 127; // ≥ 1: x ≥ 2⁻¹⁴ here (no u32 underflow)
    let (q, r) = ((b & 0x7f_ffff) >> 13, b & 0x1fff);
    let up = r > 0x1000 || (r == 0x1000 && q & 1 == 1);
    (e << 10 | q) as u16 + up as u16
}

/// Sub-samples per bin of the classification table used to pre-integrate.
const FINE: usize = 16;

/// Sub-steps of the pre-integration of a segment spanning `d` bins (as [`preintegrate`]).
fn sub_steps(d: usize) -> usize {
    2 * d + 1
}

/// Opacity `1 − exp(−τ·len/n)` of one of `n` sub-steps of a `len`-voxel segment at every
/// fine sample of `fine` (`[r, g, b, τ]`).
fn sub_step_opacities(fine: &[[f32; 4]], n: usize, len: f32) -> Vec<f32> {
    let dl = len / n as f32;
    fine.iter().map(|e| 1.0 - (-dl * e[3]).exp()).collect()
}

/// Pre-integrated rows processed together (independent chains per loop iteration).
const LANES: usize = 16;
const _: () = assert!(TF_SIZE.is_multiple_of(LANES));

/// [`preintegrate`] from whole bin `f[l]` to `f[l] + delta` for each lane `l`, with the
/// classification looked up in `fine` (`[r, g, b, τ]` every 1/16 bin, nearest) and each
/// sub-step's opacity in `alpha` ([`sub_step_opacities`] for `|delta|`), in f32; each lane does
/// the f32 operations of the single-pair loop in its order, so the result is bit for bit that.
fn preintegrate_lanes(
    fine: &[[f32; 4]],
    alpha: &[f32],
    f: [f32; LANES],
    delta: f32,
) -> [[f32; 4]; LANES] {
    let n = sub_steps(delta.abs() as usize);
    assert_eq!(alpha.len(), fine.len());
    let (mut c, mut t) = ([[0.0f32; 4]; LANES], [1.0f32; LANES]);
    for k in 0..n {
        // `(b − f)·(k + ½)/n`, the same for every lane (b − f = delta exactly).
        let dx = delta * (k as f32 + 0.5) / n as f32;
        // Each lane's fine sample: `as i32` truncates as `as usize` would (0 < x < 4081) with
        // fewer instructions.
        let i: [i32; LANES] = core::array::from_fn(|l| ((f[l] + dx) * FINE as f32 + 0.5) as i32);
        for l in 0..LANES {
            let (e, a) = (fine[i[l] as usize], alpha[i[l] as usize]);
            let w = t[l] * a;
            // Four channels so that the loop is one vector operation; the fourth (w·τ) is unused.
            for ch in 0..4 {
                c[l][ch] += w * e[ch];
            }
            t[l] *= 1.0 - a;
        }
    }
    core::array::from_fn(|l| [c[l][0], c[l][1], c[l][2], 1.0 - t[l]])
}

/// Premultiplied RGBA of a segment of `len` voxels whose bin coordinate goes linearly from
/// `f` to `b`: front-to-back composition of `2·|b − f| + 1` sub-steps classified at their
/// midpoints, each with exact opacity `1 − exp(−τ·len/n)`.
pub fn preintegrate(tf: &TransferFunction, f: f64, b: f64, len: f64) -> [f64; 4] {
    let n = (2.0 * (b - f).abs()).ceil() as usize + 1;
    let dl = len / n as f64;
    let (mut c, mut t) = ([0.0f64; 3], 1.0f64);
    for k in 0..n {
        let x = f + (b - f) * (k as f64 + 0.5) / n as f64;
        let e = tf.eval(x);
        let a = 1.0 - (-dl * extinction(e[3])).exp();
        for ch in 0..3 {
            c[ch] += t * e[ch] * a;
        }
        t *= 1.0 - a;
    }
    [c[0], c[1], c[2], 1.0 - t]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// binary16 bits → value, from the format's definition (independent of `half_bits`).
    fn half_value(h: u16) -> f64 {
        let (e, m) = ((h >> 10) & 0x1f, (h & 0x3ff) as f64);
        if e == 0 {
            m * 2f64.powi(-24)
        } else {
            (1.0 + m / 1024.0) * 2f64.powi(e as i32 - 15)
        }
    }

    #[test]
    fn half_bits_known_values_and_rounding() {
        assert_eq!(half_bits(0.0), 0);
        assert_eq!(half_bits(1.0), 0x3c00);
        assert_eq!(half_bits(0.5), 0x3800);
        assert_eq!(half_bits(65504.0), 0x7bff);
        assert_eq!(half_bits(2f32.powi(-24)), 1);
        assert_eq!(half_bits(2f32.powi(-14)), 0x0400);
        // 1 + 2⁻¹¹ is halfway between 1 and 1 + 2⁻¹⁰: ties to even (1).
        assert_eq!(half_bits(1.0 + 2f32.powi(-11)), 0x3c00);
        assert_eq!(half_bits(1.0 + 3.0 * 2f32.powi(-11)), 0x3c02);
        // Every f32 in [0, 1] on a log scale: nearest binary16 within half an ulp.
        let mut x = 1e-9f32;
        while x <= 1.0 {
            let h = half_bits(x);
            let v = half_value(h);
            let ulp = if x < 2f32.powi(-14) {
                2f64.powi(-24)
            } else {
                2f64.powi((x as f64).log2().floor() as i32 - 10)
            };
            assert!(
                (v - x as f64).abs() <= 0.5 * ulp + 1e-30,
                "{x}: {h:#x} = {v}"
            );
            x *= 1.0123;
        }
    }

    /// The table's entries are the per-pair f32 integration's bit for bit, the opacities
    /// shared per bin distance included (that integration with its own `exp` per sub-step,
    /// as the table was built before they were shared), at two step lengths.
    #[test]
    fn shared_sub_step_opacities_change_no_bit_of_the_table() {
        let tf = TransferFunction::preset(Preset::CoolWarm);
        for len in [0.5f32, 0.173] {
            let c = ClassifiedTf::new(&tf, 0.0, 1.0, len);
            let fine: Vec<[f32; 4]> = (0..=255 * FINE)
                .map(|i| {
                    let e = tf.eval(i as f64 / FINE as f64);
                    let ext = extinction(e[3]) as f32;
                    [e[0] as f32, e[1] as f32, e[2] as f32, ext]
                })
                .collect();
            for f in 0..TF_SIZE {
                for b in 0..TF_SIZE {
                    let (f32f, f32b) = (f as f32, b as f32);
                    let n = (2.0 * (f32b - f32f).abs()).ceil() as usize + 1;
                    let dl = len / n as f32;
                    let (mut col, mut t) = ([0.0f32; 3], 1.0f32);
                    for k in 0..n {
                        let x = f32f + (f32b - f32f) * (k as f32 + 0.5) / n as f32;
                        let e = fine[(x * FINE as f32 + 0.5) as usize];
                        let a = 1.0 - (-dl * e[3]).exp();
                        let w = t * a;
                        for ch in 0..3 {
                            col[ch] += w * e[ch];
                        }
                        t *= 1.0 - a;
                    }
                    let want = [col[0], col[1], col[2], 1.0 - t].map(f32::to_bits);
                    let at = (f * TF_SIZE + b) * 4;
                    let got = [0, 1, 2, 3].map(|ch| c.preint[at + ch].to_bits());
                    assert!(got == want, "len {len}, ({f}, {b}): {got:?} vs {want:?}");
                }
            }
        }
    }

    #[test]
    fn packed_preintegration_table_matches_f32_table() {
        let c = ClassifiedTf::new(&TransferFunction::preset(Preset::CoolWarm), 0.0, 1.0, 0.5);
        assert_eq!(c.preint_half.len() * 2, c.preint.len());
        for (i, &w) in c.preint_half.iter().enumerate() {
            for (k, h) in [w as u32 as u16, (w as u32 >> 16) as u16]
                .into_iter()
                .enumerate()
            {
                let want = c.preint[2 * i + k] as f64;
                let got = half_value(h);
                assert!(
                    (got - want).abs() <= want * 2f64.powi(-11) + 2f64.powi(-25),
                    "entry {}: {got} vs {want}",
                    2 * i + k
                );
            }
        }
    }
}
