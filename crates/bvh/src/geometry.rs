//! Ball and stick primitives (paper §4.1 step 3): input arrays, per-primitive records used by
//! the intersection kernels, and bounds + centroids computed in one parallel pass.

use glam::{Vec3A, Vec4};
use rayon::prelude::*;

mod stick;

pub(crate) use stick::trimmed_stick;

/// Atoms drawn as balls, structure of arrays. Positions and radii in Ångström (Å).
///
/// The balls also give the stick endpoints, so they are needed even when balls are not drawn
/// (licorice style, see [`Geometry::show_balls`]).
#[derive(Clone, Debug, Default)]
pub struct Balls {
    /// Centre x (Å).
    pub x: Vec<f32>,
    /// Centre y (Å).
    pub y: Vec<f32>,
    /// Centre z (Å).
    pub z: Vec<f32>,
    /// Ball radius (Å), already scaled by the caller (e.g. 0.5 × covalent radius).
    pub radius: Vec<f32>,
    /// Colour per atom, packed RGBA8 (`r | g << 8 | b << 16 | a << 24`). Not used by the BVH;
    /// carried for the renderer. May be empty if the caller colours otherwise.
    pub color: Vec<u32>,
}

impl Balls {
    /// Number of atoms.
    pub fn len(&self) -> usize {
        self.x.len()
    }
    /// True when there are no atoms.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
    /// Centre of atom `i` (Å).
    #[inline]
    pub fn center(&self, i: usize) -> [f32; 3] {
        [self.x[i], self.y[i], self.z[i]]
    }
}

/// Bonds drawn as sticks: finite cylinders between two endpoints, each half coloured as its
/// endpoint. Endpoint `i < balls.len()` is atom `i`; endpoint `balls.len() + k` is the extra
/// point `ends[k]` — the outer end of a half-stick drawn for a bond across a periodic boundary,
/// or a corner of a drawn simulation cell (see [`Geometry::push_end`]).
#[derive(Clone, Debug, Default)]
pub struct Sticks {
    /// First endpoint of each stick (an atom, or an extra end).
    pub a: Vec<u32>,
    /// Second endpoint of each stick.
    pub b: Vec<u32>,
    /// Cylinder radius (Å), the same for every stick.
    pub radius: f32,
    /// Extra endpoints that are not atom centres (Å).
    pub ends: Vec<[f32; 3]>,
    /// Colour of each extra endpoint (packed RGBA8, as [`Balls::color`]).
    pub end_color: Vec<u32>,
}

impl Sticks {
    /// Number of sticks.
    pub fn len(&self) -> usize {
        self.a.len()
    }
    /// True when there are no sticks.
    pub fn is_empty(&self) -> bool {
        self.a.is_empty()
    }
}

/// Everything the BVH is built over: balls, sticks and the drawing style.
///
/// Primitive ids: balls come first (`0..n_ball_prims`, ball `i` is atom `i`), then sticks
/// (`n_ball_prims + j` is stick `j`).
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    /// Atoms (ball centres are also stick endpoints).
    pub balls: Balls,
    /// Bonds.
    pub sticks: Sticks,
    /// Draw the balls (false: licorice, sticks only).
    pub show_balls: bool,
    /// Give sticks round caps (spheres of the stick radius at both ends: a capsule). Use with
    /// licorice; with balls drawn the stick ends are hidden inside the balls anyway.
    pub capped: bool,
}

/// Which kind of primitive an id refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Prim {
    /// Ball of atom `i`.
    Ball(u32),
    /// Stick `j` (bond `sticks.a[j]`–`sticks.b[j]`).
    Stick(u32),
}

/// Per-primitive data read by the intersection kernels: 8 floats, 32 bytes.
///
/// Sphere: centre `p0`, radius `r`, `axis = 0`, `len = -1` (the marker for a sphere).
/// Stick: base point `p0`, radius `r`, unit `axis` towards endpoint b, length `len` (Å, may be
/// 0 for a degenerate or wholly hidden stick): the bond from endpoint a to b, trimmed at both
/// ends by the same length where balls are drawn (the part inside both balls; see
/// [`Geometry::record`]), so its midpoint is the bond's.
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(32))]
pub struct PrimRecord {
    /// Centre (sphere) or first endpoint (stick), Å.
    pub p0: [f32; 3],
    /// Radius, Å.
    pub r: f32,
    /// Unit axis from `p0` to the second endpoint (zero for spheres and degenerate sticks).
    pub axis: [f32; 3],
    /// Axis length in Å; negative marks a sphere.
    pub len: f32,
}

impl PrimRecord {
    /// True for a sphere record.
    #[inline(always)]
    pub fn is_sphere(&self) -> bool {
        self.len < 0.0
    }
}

/// Axis-aligned box (Å). Empty when `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: [f32; 3],
    /// Upper corner.
    pub max: [f32; 3],
}

impl Default for Aabb {
    fn default() -> Self {
        Aabb::EMPTY
    }
}

impl Aabb {
    /// The empty box (identity of [`Aabb::union`]).
    pub const EMPTY: Aabb = Aabb {
        min: [f32::INFINITY; 3],
        max: [f32::NEG_INFINITY; 3],
    };

    /// Smallest box holding both.
    #[inline(always)]
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: [
                self.min[0].min(o.min[0]),
                self.min[1].min(o.min[1]),
                self.min[2].min(o.min[2]),
            ],
            max: [
                self.max[0].max(o.max[0]),
                self.max[1].max(o.max[1]),
                self.max[2].max(o.max[2]),
            ],
        }
    }

    /// Grows the box to hold point `p`.
    #[inline(always)]
    pub fn grow(&mut self, p: [f32; 3]) {
        for (k, v) in p.into_iter().enumerate() {
            self.min[k] = self.min[k].min(v);
            self.max[k] = self.max[k].max(v);
        }
    }

    /// True if the box holds nothing.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        !(self.min[0] <= self.max[0] && self.min[1] <= self.max[1] && self.min[2] <= self.max[2])
    }

    /// Surface area (Å²); 0 for an empty box.
    #[inline(always)]
    pub fn area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = [
            self.max[0] - self.min[0],
            self.max[1] - self.min[1],
            self.max[2] - self.min[2],
        ];
        2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0])
    }

    /// Centre of the box.
    pub fn center(&self) -> [f32; 3] {
        [
            0.5 * (self.min[0] + self.max[0]),
            0.5 * (self.min[1] + self.max[1]),
            0.5 * (self.min[2] + self.max[2]),
        ]
    }

    /// True if `o` lies inside `self` (an empty `o` is inside anything).
    pub fn contains(&self, o: &Aabb) -> bool {
        o.is_empty() || (0..3).all(|k| self.min[k] <= o.min[k] && o.max[k] <= self.max[k])
    }
}

impl Geometry {
    /// Builds the geometry from atom positions (Å), per-atom ball radius (Å), per-atom colour
    /// (packed RGBA8, see [`Balls::color`]), bond pairs and a stick radius (Å).
    ///
    /// Bonds naming an atom that does not exist are dropped (never a panic later on).
    /// Panics if `x`, `y`, `z`, `radius` (and a non-empty `color`) differ in length.
    pub fn from_atoms(
        x: &[f32],
        y: &[f32],
        z: &[f32],
        radius: &[f32],
        color: &[u32],
        bonds: &[[u32; 2]],
        stick_radius: f32,
    ) -> Geometry {
        let balls = Balls {
            x: x.to_vec(),
            y: y.to_vec(),
            z: z.to_vec(),
            radius: radius.to_vec(),
            color: color.to_vec(),
        };
        Geometry::from_balls(balls, bonds, stick_radius)
    }

    /// [`Geometry::from_atoms`] taking the atoms' arrays over instead of copying them.
    pub fn from_balls(balls: Balls, bonds: &[[u32; 2]], stick_radius: f32) -> Geometry {
        let n = balls.x.len();
        assert!(
            balls.y.len() == n && balls.z.len() == n && balls.radius.len() == n,
            "x, y, z and radius must have one entry per atom"
        );
        assert!(
            balls.color.is_empty() || balls.color.len() == n,
            "one colour per atom"
        );
        let (a, b): (Vec<u32>, Vec<u32>) = bonds
            .iter()
            .filter(|p| (p[0] as usize) < n && (p[1] as usize) < n)
            .map(|p| (p[0], p[1]))
            .unzip();
        Geometry {
            balls,
            sticks: Sticks {
                a,
                b,
                radius: stick_radius,
                ends: Vec::new(),
                end_color: Vec::new(),
            },
            show_balls: true,
            capped: false,
        }
    }

    /// Position (Å) of stick endpoint `i`: atom `i`, or extra end `i - balls.len()`; NaN for
    /// an index that names neither (such a stick is never hit).
    #[inline]
    pub fn endpoint(&self, i: u32) -> [f32; 3] {
        let n = self.balls.len();
        match (i as usize).checked_sub(n) {
            None => self.balls.center(i as usize),
            Some(k) => self.sticks.ends.get(k).copied().unwrap_or([f32::NAN; 3]),
        }
    }

    /// Colour (packed RGBA8) of stick endpoint `i`, `None` where none was given.
    pub fn endpoint_color(&self, i: u32) -> Option<u32> {
        let n = self.balls.len();
        match (i as usize).checked_sub(n) {
            None => self.balls.color.get(i as usize).copied(),
            Some(k) => self.sticks.end_color.get(k).copied(),
        }
    }

    /// Adds an extra stick endpoint at `p` (Å) coloured `color` and returns its endpoint
    /// index. Add all atoms first: the index counts from `balls.len()`.
    pub fn push_end(&mut self, p: [f32; 3], color: u32) -> u32 {
        self.sticks.ends.push(p);
        self.sticks.end_color.push(color);
        (self.balls.len() + self.sticks.ends.len() - 1) as u32
    }

    /// Adds a stick between endpoints `a` and `b` (atoms or extra ends).
    pub fn push_stick(&mut self, a: u32, b: u32) {
        self.sticks.a.push(a);
        self.sticks.b.push(b);
    }

    /// Number of ball primitives (0 in licorice style).
    pub fn n_ball_prims(&self) -> usize {
        if self.show_balls {
            self.balls.len()
        } else {
            0
        }
    }

    /// Number of primitives (balls drawn + sticks).
    pub fn prim_count(&self) -> usize {
        self.n_ball_prims() + self.sticks.len()
    }

    /// What primitive `id` is.
    #[inline]
    pub fn prim(&self, id: u32) -> Prim {
        let nb = self.n_ball_prims() as u32;
        if id < nb {
            Prim::Ball(id)
        } else {
            Prim::Stick(id - nb)
        }
    }

    /// The kernel record of primitive `id`. With balls drawn and open sticks, a stick is
    /// trimmed at both ends by the same length, 0.999 × the shorter of `√(R² − r²)` over its
    /// two balls (R: ball radius, r: stick radius): what is cut lies inside both balls, so no
    /// ray from outside them sees a difference, and the BVH's stick boxes are smaller
    /// (ns740k: SAH cost 349 → 290).
    pub fn record(&self, id: u32) -> PrimRecord {
        match self.prim(id) {
            Prim::Ball(i) => {
                let i = i as usize;
                PrimRecord {
                    p0: self.balls.center(i),
                    r: self.balls.radius[i],
                    axis: [0.0; 3],
                    len: -1.0,
                }
            }
            Prim::Stick(j) => {
                let (p0, axis, len) = self.stick_segment(j as usize);
                PrimRecord {
                    p0,
                    r: self.sticks.radius,
                    axis,
                    len,
                }
            }
        }
    }

    /// Bounds of primitive `id`. Primitives with a non-finite coordinate or radius get an empty
    /// box (they can never be hit).
    pub fn prim_bounds(&self, id: u32) -> Aabb {
        let (p0, p1, reach) = match self.prim(id) {
            Prim::Ball(i) => {
                let (c, r) = (self.balls.center(i as usize), self.balls.radius[i as usize]);
                (c, c, [r; 3])
            }
            Prim::Stick(j) => match self.stick_extent(j as usize) {
                Some(e) => e,
                None => return Aabb::EMPTY,
            },
        };
        let r = reach[0].max(reach[1]).max(reach[2]);
        let finite = p0.iter().chain(p1.iter()).all(|v| v.is_finite()) && r.is_finite();
        if !finite || r < 0.0 {
            return Aabb::EMPTY;
        }
        // The segment's box grown by the reach per axis; padded by a few ulps so rounding in
        // the kernels never pokes outside.
        let mut b = Aabb::EMPTY;
        for k in 0..3 {
            let lo = p0[k].min(p1[k]) - reach[k];
            let hi = p0[k].max(p1[k]) + reach[k];
            let pad = (lo.abs().max(hi.abs()) + r) * 4.0 * f32::EPSILON;
            b.min[k] = lo - pad;
            b.max[k] = hi + pad;
        }
        b
    }
}

/// Primitive bounds, as the builders see them: two SSE-friendly vectors, the primitive id
/// tagged into both `w` lanes (as a normal/inf/NaN float, never a denormal, so arithmetic on
/// the whole vector never hits slow paths). 32 bytes, as a [`PrimRecord`]: the binned
/// builder works on its record array viewed as references and writes the records over them.
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub(crate) struct PrimRef {
    pub lo: Vec4,
    pub hi: Vec4,
}

const TAG: u32 = 0x4000_0000;
/// Most primitives the builders handle (the id tag uses 30 bits).
pub const MAX_PRIMS: usize = 1 << 30;

impl PrimRef {
    #[inline(always)]
    pub fn new(b: &Aabb, id: u32) -> PrimRef {
        let w = f32::from_bits(TAG | id);
        PrimRef {
            lo: Vec4::new(b.min[0], b.min[1], b.min[2], w),
            hi: Vec4::new(b.max[0], b.max[1], b.max[2], w),
        }
    }
    #[inline(always)]
    pub fn id(&self) -> u32 {
        self.lo.w.to_bits() & !TAG
    }
    #[inline(always)]
    pub fn lo3(&self) -> Vec3A {
        Vec3A::from_vec4(self.lo)
    }
    #[inline(always)]
    pub fn hi3(&self) -> Vec3A {
        Vec3A::from_vec4(self.hi)
    }
    /// Twice the centroid (`lo + hi`), 0 for empty boxes.
    #[inline(always)]
    pub fn c2(&self) -> Vec3A {
        let c = self.lo3() + self.hi3();
        Vec3A::select(c.is_finite_mask(), c, Vec3A::ZERO)
    }
    /// Twice the centroid along axis `k`.
    #[inline(always)]
    pub fn centroid2(&self, k: usize) -> f32 {
        self.c2()[k]
    }
    #[inline(always)]
    pub fn aabb(&self) -> Aabb {
        Aabb {
            min: self.lo3().into(),
            max: self.hi3().into(),
        }
    }
}

/// Bounds and centroids of every primitive, with the global bounds and the centroid bounds
/// (paper §4.1 step 3). Centroids are kept doubled (`lo + hi`).
pub(crate) fn prim_refs(g: &Geometry) -> (Vec<PrimRef>, Aabb, Aabb) {
    let refs: Vec<PrimRef> = prim_ref_iter(g).collect();
    let (bounds, cbounds) = refs_bounds_par(&refs);
    (refs, bounds, cbounds)
}

/// [`prim_refs`] in a record array, whose records the builder later writes over them.
pub(crate) fn prim_refs_as_records(g: &Geometry) -> (Vec<PrimRecord>, Aabb, Aabb) {
    let records: Vec<PrimRecord> = prim_ref_iter(g).map(bytemuck::cast).collect();
    let (bounds, cbounds) = refs_bounds_par(bytemuck::cast_slice(&records));
    (records, bounds, cbounds)
}

/// The reference of every primitive of `g`, in id order, computed in parallel. (Collected by
/// rayon straight into the new array: its pages are first touched by the threads that fill
/// them. Zeroing it first — `bytemuck::zeroed_vec`, a `memset` on one thread for a 32-byte
/// aligned type, not `calloc` — took 40-46 ms of a 220 ms build at 1.56 M primitives.)
fn prim_ref_iter(g: &Geometry) -> impl IndexedParallelIterator<Item = PrimRef> + '_ {
    let n = g.prim_count();
    assert!(n < MAX_PRIMS, "{n} primitives: at most 2^30 supported");
    (0..n as u32)
        .into_par_iter()
        .with_min_len(1 << 12)
        .map(|id| PrimRef::new(&g.prim_bounds(id), id))
}

/// Bounds and centroid bounds of `refs`, in parallel.
fn refs_bounds_par(refs: &[PrimRef]) -> (Aabb, Aabb) {
    const CHUNK: usize = 1 << 13;
    refs.par_chunks(CHUNK)
        .map(|chunk| {
            let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
            let (mut clo, mut chi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
            for r in chunk {
                lo = lo.min(r.lo3());
                hi = hi.max(r.hi3());
                let c = r.c2();
                clo = clo.min(c);
                chi = chi.max(c);
            }
            (
                Aabb {
                    min: lo.into(),
                    max: hi.into(),
                },
                Aabb {
                    min: clo.into(),
                    max: chi.into(),
                },
            )
        })
        .reduce(
            || (Aabb::EMPTY, Aabb::EMPTY),
            |a, b| (a.0.union(b.0), a.1.union(b.1)),
        )
}
