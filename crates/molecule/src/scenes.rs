//! Built-in reference scenes standing in for the paper's five (non-public) data sets.
//! Deterministic for a seed, scalable by atom count, generated in memory in parallel.
//!
//! | scene | default atoms | structure |
//! |---|---|---|
//! | `nanobowl` | 20,000 | Al₂O₃ hemispherical bowl shell (R_in = 0.8 R_out) |
//! | `ns90k` | 92,000 | carbon onion of nested icosahedral fullerenes C₆₀ₖ² |
//! | `ns740k` | 742,000 | the same, larger |
//! | `sio2` | 4,800,000 | β-cristobalite SiO₂ slab with a wedge-shaped fissure |
//! | `anp3` | 14,700,000 | Al nanoparticle: fcc core + Al₂O₃ shell, in O₂ gas |
//!
//! Alumina: idealised rock-salt-derived Al₂O₃ — O on an fcc lattice (a = 4.00 Å), Al in 2/3
//! of the octahedral sites (every third site vacant in a fixed pattern). Al–O = 2.00 Å
//! (corundum: 1.86-1.97 Å); Al–Al and O–O = 2.83 Å, just beyond the default Al–Al cutoff
//! (1.15·2·1.21 = 2.78 Å), so only Al–O bonds form (≈ 2.4 bonds/atom in the bulk).
//!
//! Carbon onions: shell k is the Goldberg–Coxeter fullerene GP(k,k) = C₆₀ₖ², built as the
//! leapfrog (truncation of the dual) of a frequency-k geodesic icosahedron, relaxed on the
//! sphere to equal bond lengths and scaled to a mean C–C of 1.42 Å; radius ≈ 3.55·k Å, so
//! shells are ≈ 3.5 Å apart. Every atom has exactly three neighbours (1.5 bonds/atom). Shells
//! are chosen greedily from the outside in so the total is within 60 atoms of the request
//! (inner shells may be skipped); each shell has a random orientation from the seed.
//!
//! SiO₂: ideal β-cristobalite (Si on a diamond lattice, O at the Si–Si midpoints,
//! a = 7.437 Å so Si–O = 1.61 Å); slab 2.5 s × 2.5 s × s with a V-shaped fissure from the top
//! (half-width 0.15·L_x at the surface, depth 0.6·s). Bulk 4/3 bonds/atom.
//!
//! ANP3: sphere of radius s: fcc Al core (a = 4.05 Å) for r < 0.85 s, alumina (above) for
//! 0.85 s + 1.6 Å < r < s; O₂ molecules (1.21 Å) on a jittered 5.4 Å lattice with random
//! orientations fill a cube of side 2.6 s outside r > s + 3 Å. Al–Al in fcc Al is 2.86 Å,
//! beyond the default cutoff, so the metal core has no sticks (as in reality the bond rule
//! is for covalent bonds); O₂ gives exactly one bond per molecule.

use crate::Molecule;
use rayon::prelude::*;
use std::fmt;
use std::str::FromStr;

/// A reference scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SceneName {
    /// Al₂O₃ nanobowl, 20K atoms.
    Nanobowl,
    /// Small carbon nanosphere (onion), 92K atoms.
    Ns90k,
    /// Large carbon nanosphere (onion), 742K atoms.
    Ns740k,
    /// SiO₂ slab with a fissure, 4.8M atoms.
    Sio2,
    /// Aluminium nanoparticle with oxide shell in O₂ gas, 14.7M atoms.
    Anp3,
}

impl SceneName {
    /// All scenes.
    pub const ALL: [SceneName; 5] = [
        SceneName::Nanobowl,
        SceneName::Ns90k,
        SceneName::Ns740k,
        SceneName::Sio2,
        SceneName::Anp3,
    ];

    /// Atom count of the paper's data set (Table 3).
    pub fn default_atoms(self) -> usize {
        match self {
            SceneName::Nanobowl => 20_000,
            SceneName::Ns90k => 92_000,
            SceneName::Ns740k => 742_000,
            SceneName::Sio2 => 4_800_000,
            SceneName::Anp3 => 14_700_000,
        }
    }

    /// Name as accepted by `FromStr`.
    pub fn name(self) -> &'static str {
        match self {
            SceneName::Nanobowl => "nanobowl",
            SceneName::Ns90k => "ns90k",
            SceneName::Ns740k => "ns740k",
            SceneName::Sio2 => "sio2",
            SceneName::Anp3 => "anp3",
        }
    }
}

impl fmt::Display for SceneName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for SceneName {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        SceneName::ALL
            .into_iter()
            .find(|n| n.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| {
                format!("unknown scene '{s}' (expected nanobowl, ns90k, ns740k, sio2 or anp3)")
            })
    }
}

/// Generate a scene with about `atoms` atoms (default: [`SceneName::default_atoms`]); the
/// result is within ~1% of the request for requests of a few thousand atoms or more, and
/// identical for identical `(name, atoms, seed)`.
pub fn generate(name: SceneName, atoms: Option<usize>, seed: u64) -> Molecule {
    let n = atoms.unwrap_or(name.default_atoms());
    match name {
        SceneName::Nanobowl => nanobowl(n),
        SceneName::Ns90k | SceneName::Ns740k => onion(n, seed),
        SceneName::Sio2 => sio2(n),
        SceneName::Anp3 => anp3(n, seed),
    }
}

/// Largest atom count [`try_generate`] accepts (2^31: atom indices are `u32`, and bonds of
/// twice as many atoms would overflow them).
pub const MAX_ATOMS: usize = 1 << 31;

/// Bytes per atom assumed by [`try_generate`]'s memory check: positions and element (13 B)
/// plus generator scratch (a lower bound; rendering needs several times more).
pub const BYTES_PER_ATOM: u64 = 64;

/// Why [`try_generate`] refused.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// Zero atoms asked for.
    #[error("0 atoms asked for; ask for at least 1 with --atoms")]
    NoAtoms,
    /// More atoms than [`MAX_ATOMS`].
    #[error("{atoms} atoms is more than the limit of {max} (2^31); ask for fewer with --atoms")]
    TooManyAtoms {
        /// Requested atoms.
        atoms: usize,
        /// [`MAX_ATOMS`].
        max: usize,
    },
    /// The model would not fit in the available memory.
    #[error(
        "{atoms} atoms need at least {bytes} bytes ({:.1} GB) but only {available} bytes \
         ({:.1} GB) are available; ask for fewer with --atoms",
        *bytes as f64 / 1e9,
        *available as f64 / 1e9
    )]
    OutOfMemory {
        /// Requested atoms.
        atoms: usize,
        /// Estimated bytes ([`BYTES_PER_ATOM`] per atom).
        bytes: u64,
        /// Available memory (bytes, `MemAvailable` of `/proc/meminfo`).
        available: u64,
    },
}

/// Available memory in bytes (`MemAvailable` from `/proc/meminfo`), if known.
pub fn available_memory() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = s.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kb.checked_mul(1024)
}

/// Check a requested atom count (at least 1) against [`MAX_ATOMS`] and `available` memory (bytes; `None`
/// = unknown, not checked) before anything is allocated.
pub fn check_atoms(atoms: usize, available: Option<u64>) -> Result<(), SceneError> {
    if atoms == 0 {
        return Err(SceneError::NoAtoms);
    }
    if atoms > MAX_ATOMS {
        return Err(SceneError::TooManyAtoms {
            atoms,
            max: MAX_ATOMS,
        });
    }
    let bytes = (atoms as u64).saturating_mul(BYTES_PER_ATOM);
    match available {
        Some(available) if bytes > available => Err(SceneError::OutOfMemory {
            atoms,
            bytes,
            available,
        }),
        _ => Ok(()),
    }
}

/// [`generate`] after [`check_atoms`] with [`available_memory`]: refuses absurd atom counts
/// instead of aborting on allocation.
pub fn try_generate(
    name: SceneName,
    atoms: Option<usize>,
    seed: u64,
) -> Result<Molecule, SceneError> {
    let n = atoms.unwrap_or(name.default_atoms());
    check_atoms(n, available_memory())?;
    Ok(generate(name, Some(n), seed))
}

// ---------------------------------------------------------------- helpers

/// splitmix64's finaliser: a 64-bit mix of `x`.
pub(crate) fn splitmix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// Deterministic uniform numbers in [0, 1) for (seed, index, stream).
fn uniform(seed: u64, index: u64, stream: u64) -> f64 {
    let h = splitmix(seed ^ splitmix(index ^ splitmix(stream)));
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// Random rotation matrix from a uniform random unit quaternion.
fn rotation(seed: u64, index: u64) -> [[f64; 3]; 3] {
    let (u1, u2, u3) = (
        uniform(seed, index, 101),
        uniform(seed, index, 102),
        uniform(seed, index, 103),
    );
    let tau = std::f64::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let (w, x, y, z) = (
        a * (tau * u2).sin(),
        a * (tau * u2).cos(),
        b * (tau * u3).sin(),
        b * (tau * u3).cos(),
    );
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

fn rot(m: &[[f64; 3]; 3], p: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2])
}

fn norm(p: [f64; 3]) -> f64 {
    (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt()
}

fn normalize(p: [f64; 3]) -> [f64; 3] {
    let n = norm(p);
    [p[0] / n, p[1] / n, p[2] / n]
}

/// Generated atoms grouped by lattice layer: position (Å) and atomic number.
type Layers = Vec<Vec<([f32; 3], u8)>>;

/// Atoms of one kind on a lattice: `a` (Å), basis in fractions of the cubic cell.
struct Lattice<'b> {
    a: f64,
    offset: [f64; 3],
    basis: &'b [([f64; 3], u8)],
}

impl Lattice<'_> {
    /// Visit lattice points inside [lo, hi] (Å) for which `keep(p, basis_index, cell)`
    /// returns an element; returns them grouped by z-layer (parallel, ordered).
    fn collect<F>(&self, lo: [f64; 3], hi: [f64; 3], count_only: bool, keep: F) -> (usize, Layers)
    where
        F: Fn([f64; 3], usize, [i64; 3]) -> Option<u8> + Sync,
    {
        let c0 = [0, 1, 2].map(|k| ((lo[k] - self.offset[k]) / self.a).floor() as i64 - 1);
        let c1 = [0, 1, 2].map(|k| ((hi[k] - self.offset[k]) / self.a).ceil() as i64 + 1);
        let layers: Vec<(usize, Vec<_>)> = (c0[2]..=c1[2])
            .into_par_iter()
            .map(|kz| {
                let mut out = Vec::new();
                let mut cnt = 0usize;
                for ky in c0[1]..=c1[1] {
                    for kx in c0[0]..=c1[0] {
                        for (b, (f, _)) in self.basis.iter().enumerate() {
                            let p = [
                                self.offset[0] + (kx as f64 + f[0]) * self.a,
                                self.offset[1] + (ky as f64 + f[1]) * self.a,
                                self.offset[2] + (kz as f64 + f[2]) * self.a,
                            ];
                            if (0..3).any(|k| p[k] < lo[k] || p[k] > hi[k]) {
                                continue;
                            }
                            if let Some(z) = keep(p, b, [kx, ky, kz]) {
                                cnt += 1;
                                if !count_only {
                                    out.push(([p[0] as f32, p[1] as f32, p[2] as f32], z));
                                }
                            }
                        }
                    }
                }
                (cnt, out)
            })
            .collect();
        let total = layers.iter().map(|l| l.0).sum();
        (total, layers.into_iter().map(|l| l.1).collect())
    }
}

fn append(m: &mut Molecule, layers: Layers) {
    let add: usize = layers.iter().map(Vec::len).sum();
    m.x.reserve(add);
    m.y.reserve(add);
    m.z.reserve(add);
    m.elements.reserve(add);
    for l in layers {
        for (p, z) in l {
            m.push(p, z);
        }
    }
}

/// Scale parameter `s` so that `count(s)` ≈ `target`, assuming count ∝ s³.
fn fit_scale(target: usize, mut s: f64, count: impl Fn(f64) -> usize) -> f64 {
    for _ in 0..4 {
        let c = count(s).max(1);
        let ratio = target as f64 / c as f64;
        if (ratio - 1.0).abs() < 0.002 {
            break;
        }
        s *= ratio.cbrt();
    }
    s
}

const AL: u8 = 13;
const O: u8 = 8;
const C: u8 = 6;
const SI: u8 = 14;

/// Rock-salt-derived Al₂O₃: 8 sites per cubic cell (4 O fcc + 4 octahedral), a = 4.0 Å.
const ALUMINA_A: f64 = 4.0;
static ALUMINA_BASIS: [([f64; 3], u8); 8] = [
    ([0.0, 0.0, 0.0], O),
    ([0.5, 0.5, 0.0], O),
    ([0.5, 0.0, 0.5], O),
    ([0.0, 0.5, 0.5], O),
    ([0.5, 0.0, 0.0], AL),
    ([0.0, 0.5, 0.0], AL),
    ([0.0, 0.0, 0.5], AL),
    ([0.5, 0.5, 0.5], AL),
];

/// Element at an alumina site, `None` for the vacant third of the octahedral sites.
fn alumina_site(b: usize, cell: [i64; 3]) -> Option<u8> {
    let (f, z) = ALUMINA_BASIS[b];
    if z == O {
        return Some(O);
    }
    let h = [0, 1, 2].map(|k| 2 * cell[k] + (2.0 * f[k]) as i64);
    ((h[0] + h[1] + 2 * h[2]).rem_euclid(3) != 0).then_some(AL)
}

// ---------------------------------------------------------------- nanobowl

fn nanobowl(n: usize) -> Molecule {
    let lat = Lattice {
        a: ALUMINA_A,
        offset: [0.37, 0.21, 0.13],
        basis: &ALUMINA_BASIS,
    };
    let run = |r: f64, count_only: bool| {
        let rin = 0.8 * r;
        lat.collect([-r, -r, -r], [r, r, 0.0], count_only, |p, b, c| {
            let d = norm(p);
            if d < rin || d > r || p[2] > 0.0 {
                return None;
            }
            alumina_site(b, c)
        })
    };
    let density = 6.667 / ALUMINA_A.powi(3);
    let s0 = (n as f64 / (density * 2.0 / 3.0 * std::f64::consts::PI * (1.0 - 0.512))).cbrt();
    let r = fit_scale(n, s0, |s| run(s, true).0);
    let mut m = Molecule::default();
    append(&mut m, run(r, false).1);
    m
}

// ---------------------------------------------------------------- carbon onion

/// Atoms of one GP(k,k) fullerene shell on the unit sphere, relaxed, plus its bond list.
fn fullerene(k: usize) -> (Vec<[f64; 3]>, Vec<[u32; 2]>) {
    fullerene_iter(k, RELAX_ITERS)
}

const RELAX_ITERS: usize = 100;

fn fullerene_iter(k: usize, iters: usize) -> (Vec<[f64; 3]>, Vec<[u32; 2]>) {
    use std::collections::HashMap;
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let iv: [[f64; 3]; 12] = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let faces: [[usize; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    // Geodesic vertices keyed by exact barycentric weights on icosahedron vertices.
    let mut vid: HashMap<Vec<(usize, usize)>, u32> = HashMap::new();
    let mut verts: Vec<[f64; 3]> = Vec::new();
    let mut tris: Vec<[u32; 3]> = Vec::new();
    for f in &faces {
        let mut idx = vec![vec![0u32; k + 1]; k + 1];
        #[allow(clippy::needless_range_loop)] // (i, j) are lattice coordinates, not just indices
        for i in 0..=k {
            for j in 0..=k - i {
                let mut key: Vec<(usize, usize)> = [(f[0], k - i - j), (f[1], i), (f[2], j)]
                    .into_iter()
                    .filter(|w| w.1 > 0)
                    .collect();
                key.sort_unstable();
                let id = *vid.entry(key).or_insert_with(|| {
                    let w = [(k - i - j) as f64, i as f64, j as f64];
                    let p = [0, 1, 2]
                        .map(|c| w[0] * iv[f[0]][c] + w[1] * iv[f[1]][c] + w[2] * iv[f[2]][c]);
                    verts.push(normalize(p));
                    (verts.len() - 1) as u32
                });
                idx[i][j] = id;
            }
        }
        for i in 0..k {
            for j in 0..k - i {
                tris.push([idx[i][j], idx[i + 1][j], idx[i][j + 1]]);
                if i + j + 2 <= k {
                    tris.push([idx[i + 1][j], idx[i + 1][j + 1], idx[i][j + 1]]);
                }
            }
        }
    }
    // Truncation: one atom per directed edge u→v at u + (v-u)/3.
    let mut aid: HashMap<(u32, u32), u32> = HashMap::new();
    let mut atoms: Vec<[f64; 3]> = Vec::new();
    let mut ends: Vec<(u32, u32)> = Vec::new();
    let mut atom_of = |u: u32, v: u32, atoms: &mut Vec<[f64; 3]>| -> u32 {
        *aid.entry((u, v)).or_insert_with(|| {
            let (a, b) = (verts[u as usize], verts[v as usize]);
            atoms.push(normalize([0, 1, 2].map(|c| a[c] + (b[c] - a[c]) / 3.0)));
            ends.push((u, v));
            (atoms.len() - 1) as u32
        })
    };
    let mut bonds = Vec::new();
    for tr in &tris {
        for e in 0..3 {
            let (u, v, w) = (tr[e], tr[(e + 1) % 3], tr[(e + 2) % 3]);
            let uv = atom_of(u, v, &mut atoms);
            let vu = atom_of(v, u, &mut atoms);
            let uw = atom_of(u, w, &mut atoms);
            if u < v {
                bonds.push([uv.min(vu), uv.max(vu)]);
            }
            bonds.push([uv.min(uw), uv.max(uw)]);
        }
    }
    bonds.sort_unstable();
    bonds.dedup();
    // Second-neighbour ("angle") springs: target 2·sin(θ/2)·L with θ = 108° inside the
    // pentagons around the 12 icosahedron vertices, 120° elsewhere.
    let mut vdeg = vec![0u8; verts.len()];
    for tr in &tris {
        for &v in tr {
            vdeg[v as usize] = vdeg[v as usize].saturating_add(1);
        }
    }
    let mut nbr: Vec<Vec<u32>> = vec![Vec::with_capacity(3); atoms.len()];
    for b in &bonds {
        nbr[b[0] as usize].push(b[1]);
        nbr[b[1] as usize].push(b[0]);
    }
    let mut angles: Vec<(u32, u32, f64)> = Vec::new();
    for (a, ns) in nbr.iter().enumerate() {
        let (u, _) = ends[a];
        for x in 0..ns.len() {
            for y in x + 1..ns.len() {
                let (p, q) = (ns[x], ns[y]);
                // Both neighbours on the polygon around u → polygon angle at u.
                let poly = ends[p as usize].0 == u && ends[q as usize].0 == u;
                let ratio = if poly && vdeg[u as usize] == 5 {
                    1.618_034
                } else {
                    3f64.sqrt()
                };
                angles.push((p, q, ratio));
            }
        }
    }
    // Relax: springs toward the mean bond length, projected back on the sphere.
    let nb = bonds.len() as f64;
    for _ in 0..iters {
        let mean = bonds
            .iter()
            .map(|b| dist(atoms[b[0] as usize], atoms[b[1] as usize]))
            .sum::<f64>()
            / nb;
        let mut force = vec![[0f64; 3]; atoms.len()];
        let spring = |i: usize, j: usize, target: f64, w: f64, force: &mut Vec<[f64; 3]>| {
            let (p, q) = (atoms[i], atoms[j]);
            let d = dist(p, q);
            let s = w * (d - target) / d;
            for c in 0..3 {
                let f = s * (q[c] - p[c]);
                force[i][c] += f;
                force[j][c] -= f;
            }
        };
        for b in &bonds {
            spring(b[0] as usize, b[1] as usize, mean, 0.2, &mut force);
        }
        for &(p, q, r) in &angles {
            spring(p as usize, q as usize, r * mean, 0.1, &mut force);
        }
        for (a, f) in atoms.iter_mut().zip(&force) {
            *a = normalize([a[0] + f[0], a[1] + f[1], a[2] + f[2]]);
        }
    }
    (atoms, bonds)
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm([b[0] - a[0], b[1] - a[1], b[2] - a[2]])
}

/// Shell indices k (outside in) whose C₆₀ₖ² atoms sum to at most `n`, within 60 atoms.
fn onion_shells(n: usize) -> Vec<usize> {
    let full = |k: usize| 10 * k * (k + 1) * (2 * k + 1);
    let mut kmax = 1;
    while full(kmax) < n {
        kmax += 1;
    }
    let mut total = 0;
    let mut shells = Vec::new();
    for k in (1..=kmax).rev() {
        if total + 60 * k * k <= n {
            total += 60 * k * k;
            shells.push(k);
        }
    }
    if shells.is_empty() {
        shells.push(1);
    }
    shells
}

fn onion(n: usize, seed: u64) -> Molecule {
    let shells = onion_shells(n);
    let parts: Vec<Vec<[f32; 3]>> = shells
        .par_iter()
        .map(|&k| {
            let (atoms, bonds) = fullerene(k);
            let mean = bonds
                .iter()
                .map(|b| dist(atoms[b[0] as usize], atoms[b[1] as usize]))
                .sum::<f64>()
                / bonds.len() as f64;
            let r = 1.42 / mean;
            let m = rotation(seed, k as u64);
            atoms
                .iter()
                .map(|&p| rot(&m, p).map(|c| (c * r) as f32))
                .collect()
        })
        .collect();
    let mut m = Molecule::with_capacity(parts.iter().map(Vec::len).sum());
    for p in parts {
        for q in p {
            m.push(q, C);
        }
    }
    m
}

// ---------------------------------------------------------------- SiO2

const CRISTOBALITE_A: f64 = 7.437;
static FCC: [([f64; 3], u8); 4] = [
    ([0.0, 0.0, 0.0], SI),
    ([0.5, 0.5, 0.0], SI),
    ([0.5, 0.0, 0.5], SI),
    ([0.0, 0.5, 0.5], SI),
];
const DIAMOND_DIRS: [[f64; 3]; 4] = [
    [0.25, 0.25, 0.25],
    [0.25, -0.25, -0.25],
    [-0.25, 0.25, -0.25],
    [-0.25, -0.25, 0.25],
];

fn sio2(n: usize) -> Molecule {
    let a = CRISTOBALITE_A;
    // Basis: A-site Si, B-site Si (A + d0), and the 4 O at A + d/2.
    let mut basis: Vec<([f64; 3], u8)> = Vec::new();
    for (f, _) in FCC.iter() {
        basis.push((*f, SI));
        basis.push(([0, 1, 2].map(|c| f[c] + DIAMOND_DIRS[0][c]), SI));
        for d in DIAMOND_DIRS {
            basis.push(([0, 1, 2].map(|c| f[c] + d[c] / 2.0), O));
        }
    }
    let lat = Lattice {
        a,
        offset: [0.0; 3],
        basis: &basis,
    };
    let run = |s: f64, count_only: bool| {
        let (lx, ly, lz) = (2.5 * s, 2.5 * s, s);
        let inside = move |p: [f64; 3]| -> bool {
            if p[0] < 0.0 || p[0] >= lx || p[1] < 0.0 || p[1] >= ly || p[2] < 0.0 || p[2] >= lz {
                return false;
            }
            let depth = 0.6 * lz;
            let top = lz - depth;
            if p[2] > top {
                let half = 0.15 * lx * (p[2] - top) / depth;
                if (p[0] - lx / 2.0).abs() < half {
                    return false;
                }
            }
            true
        };
        let pad = a;
        lat.collect(
            [-pad, -pad, -pad],
            [lx + pad, ly + pad, lz + pad],
            count_only,
            |p, b, _| {
                let (_, z) = basis[b];
                if z == SI {
                    return inside(p).then_some(SI);
                }
                // O between an A-site Si and a B neighbour: keep if either Si is kept.
                let k = b % 6; // 0: A, 1: B, 2..6: O with direction k-2
                let d = DIAMOND_DIRS[k - 2];
                let si_a = [0, 1, 2].map(|c| p[c] - d[c] * a / 2.0);
                let si_b = [0, 1, 2].map(|c| p[c] + d[c] * a / 2.0);
                (inside(si_a) || inside(si_b)).then_some(O)
            },
        )
    };
    let density = 24.0 / a.powi(3);
    let s0 = (n as f64 / (density * (6.25 - 0.5625))).cbrt();
    let s = fit_scale(n, s0, |s| run(s, true).0);
    let mut m = Molecule::default();
    append(&mut m, run(s, false).1);
    m
}

// ---------------------------------------------------------------- ANP3

const AL_FCC_A: f64 = 4.05;
const O2_BOND: f64 = 1.21;
const GAS_SPACING: f64 = 5.4;

fn anp3(n: usize, seed: u64) -> Molecule {
    static AL_FCC: [([f64; 3], u8); 4] = [
        ([0.0, 0.0, 0.0], AL),
        ([0.5, 0.5, 0.0], AL),
        ([0.5, 0.0, 0.5], AL),
        ([0.0, 0.5, 0.5], AL),
    ];
    static GAS: [([f64; 3], u8); 1] = [([0.0, 0.0, 0.0], O)];
    let core = Lattice {
        a: AL_FCC_A,
        offset: [0.11, 0.07, 0.03],
        basis: &AL_FCC,
    };
    let shell = Lattice {
        a: ALUMINA_A,
        offset: [0.29, 0.17, 0.41],
        basis: &ALUMINA_BASIS,
    };
    let gas = Lattice {
        a: GAS_SPACING,
        offset: [0.5, 0.5, 0.5],
        basis: &GAS,
    };
    let run = |s: f64, count_only: bool| {
        let rc = 0.85 * s;
        let half = 1.3 * s;
        let (n1, l1) = core.collect([-rc; 3], [rc; 3], count_only, |p, _, _| {
            (norm(p) < rc).then_some(AL)
        });
        let (n2, l2) = shell.collect([-s; 3], [s; 3], count_only, |p, b, c| {
            let d = norm(p);
            if d <= rc + 1.6 || d >= s {
                return None;
            }
            alumina_site(b, c)
        });
        let (n3, l3) = gas.collect([-half; 3], [half; 3], count_only, |p, _, _| {
            (norm(p) > s + 3.0).then_some(O)
        });
        (n1 + n2 + 2 * n3, [l1, l2, l3])
    };
    let s0 = (n as f64 / 0.493).cbrt();
    let s = fit_scale(n, s0, |s| run(s, true).0);
    let (_, [l1, l2, l3]) = run(s, false);
    let mut m = Molecule::default();
    append(&mut m, l1);
    append(&mut m, l2);
    // Gas: each lattice site becomes an O₂ molecule with jittered centre and random axis.
    let molecules: Vec<([f32; 3], u8)> = l3.into_iter().flatten().collect();
    let gas_atoms: Vec<[[f32; 3]; 2]> = molecules
        .par_iter()
        .enumerate()
        .map(|(i, (p, _))| {
            let i = i as u64;
            let j = [0, 1, 2].map(|c| (uniform(seed, i, c) - 0.5) * 1.2);
            let cz = 2.0 * uniform(seed, i, 3) - 1.0;
            let phi = std::f64::consts::TAU * uniform(seed, i, 4);
            let sz = (1.0 - cz * cz).max(0.0).sqrt();
            let axis = [sz * phi.cos(), sz * phi.sin(), cz];
            let c = [0, 1, 2].map(|k| f64::from(p[k]) + j[k]);
            let h = O2_BOND / 2.0;
            [
                [0, 1, 2].map(|k| (c[k] - h * axis[k]) as f32),
                [0, 1, 2].map(|k| (c[k] + h * axis[k]) as f32),
            ]
        })
        .collect();
    for [a, b] in gas_atoms {
        m.push(a, O);
        m.push(b, O);
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fullerene_counts() {
        for k in 1..=4 {
            let (a, b) = fullerene(k);
            assert_eq!(a.len(), 60 * k * k);
            assert_eq!(b.len(), 90 * k * k);
        }
    }

    #[test]
    fn onion_shell_choice() {
        let s = onion_shells(92_000);
        let total: usize = s.iter().map(|k| 60 * k * k).sum();
        assert!(total <= 92_000 && total + 60 > 92_000 - 1000, "{total}");
    }
}
