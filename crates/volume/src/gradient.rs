//! Gradient shading from one stencil (paper §4.4): the lit marcher's sample and its
//! central-difference gradient read from twelve lattice rows instead of the 4 + 24 gathers of
//! a trilinear sample plus six more ([`crate::sampler::diffuse`]).
//!
//! The gradient is the trilinear interpolant of the lattice's central differences
//! `v[i + 1] − v[i − 1]` per axis. Since a trilinear sample one voxel away reads the same cell
//! shifted by one lattice point with the same fractions, this is exactly
//! `trilinear(p + eₐ) − trilinear(p − eₐ)` (the six-sample gradient) in real arithmetic wherever
//! neither sample is clamped to the box: cells with a lattice point on every side
//! ([`Stencil::inside`]). Lanes outside that (the outermost voxel layer, where the padded
//! density is near zero) keep the six-sample gradient.
//!
//! Cost on u8 voxels: the x-rows of the cell are read one voxel wider (`x − 1 ..= x + 2`, the
//! same single 4-byte gather per row), which gives the sample and the x-differences; the y-
//! and z-differences need the rows at `y − 1`, `y + 2` and `z − 1`, `z + 2` (eight gathers),
//! read only when some lane is shaded.

use spmd::{Simd, V3};

use crate::sampler::{blend, cell_of, diffuse, facing, trilinear, Cell, Lattice, Voxels};

/// A trilinear sample with what its gradient still needs.
pub(crate) struct Stencil<S: Simd> {
    /// The sample (density units), as [`trilinear`] gives it.
    pub(crate) value: S::F32,
    /// Its cell.
    cell: Cell<S>,
    /// The cell's corner values `v[z][y][x]` (raw units; lanes [`Stencil::inside`]).
    v: [[[S::F32; 2]; 2]; 2],
    /// x-component of the gradient (density units per voxel; lanes [`Stencil::inside`]).
    gx: S::F32,
    /// Lanes whose cell has a lattice point on every side (`1 ≤ i ≤ dims − 3` per axis).
    inside: S::M,
}

/// Lanes of `c` with a lattice point beyond the cell on every side.
#[inline(always)]
fn inside<S: Simd, V: Voxels>(s: S, l: &Lattice<V>, c: &Cell<S>) -> S::M {
    let one = s.splat(1.0);
    let mut m = s.splat_m(true);
    for a in 0..3 {
        m = m & s.ge(c.i[a], one) & s.le(c.i[a], s.splat(l.base_hi[a] - 1.0));
    }
    m
}

/// The central differences `v[x + 1] − v[x − 1]` at the two cell corners of a row read as
/// `v[x − 1 ..= x + 2]`.
#[inline(always)]
fn row_dx<S: Simd>(r: [S::F32; 4]) -> [S::F32; 2] {
    [r[2] - r[0], r[3] - r[1]]
}

/// `a − b` per corner.
#[inline(always)]
fn sub2<S: Simd>(a: [S::F32; 2], b: [S::F32; 2]) -> [S::F32; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

// Paper §4.4: the trilinear sample at `p` and the x-part of its central-difference gradient,
// from the cell's four x-rows read one voxel wider.
#[inline(always)]
pub(crate) fn sample_stencil<S: Simd, V: Voxels>(
    s: S,
    l: &Lattice<V>,
    p: V3<S>,
    m: S::M,
) -> Stencil<S> {
    let cell = cell_of(s, l, p);
    let inside = inside(s, l, &cell);
    let at = m & inside;
    let r0 = cell.b - s.splat_i(1);
    // r[z][y] = v[x − 1 ..= x + 2] at (y, z) of the cell.
    let [r00, r01, r10, r11] = l.vox.fetch4_rows(s, r0, [0, l.nx, l.nxy, l.nxy + l.nx], at);
    let v = [
        [[r00[1], r00[2]], [r01[1], r01[2]]],
        [[r10[1], r10[2]], [r11[1], r11[2]]],
    ];
    let d = [
        [row_dx::<S>(r00), row_dx::<S>(r01)],
        [row_dx::<S>(r10), row_dx::<S>(r11)],
    ];
    let scale = s.splat(l.scale);
    let mut value = blend::<S>(v, cell.f) * scale;
    let edge = m & !inside;
    if s.any(edge) {
        value = s.select(edge, trilinear(s, l, p, edge), value);
    }
    Stencil {
        value,
        gx: blend::<S>(d, cell.f) * scale,
        cell,
        v,
        inside,
    }
}

/// y- and z-parts of the gradient of `st` (lanes `m`, inside): the rows one voxel beyond the
/// cell along y and along z, eight gathers of two x-neighbours.
#[inline(always)]
fn gradient_yz<S: Simd, V: Voxels>(
    s: S,
    l: &Lattice<V>,
    st: &Stencil<S>,
    m: S::M,
) -> (S::F32, S::F32) {
    let v = &st.v;
    // The eight rows one voxel beyond the cell along y and z, from the lattice point one row
    // back in y and in z (so every offset is ≥ 0; inside lanes have that point).
    let (nx, nxy) = (l.nx, l.nxy);
    let base = st.cell.b - s.splat_i(nx + nxy);
    // (y, z) = (−1, 0), (2, 0), (−1, 1), (2, 1), then (0, −1), (1, −1), (0, 2), (1, 2).
    let offsets = [
        nxy,
        3 * nx + nxy,
        2 * nxy,
        3 * nx + 2 * nxy,
        nx,
        2 * nx,
        nx + 3 * nxy,
        2 * nx + 3 * nxy,
    ];
    let [ym_z0, yp_z0, ym_z1, yp_z1, zm_y0, zm_y1, zp_y0, zp_y1] =
        l.vox.fetch2_rows(s, base, offsets, m);
    // d[z][y] = v(·, y + 1, z) − v(·, y − 1, z) at the cell's corners.
    let dy = [
        [
            sub2::<S>(v[0][1], [ym_z0.0, ym_z0.1]),
            sub2::<S>([yp_z0.0, yp_z0.1], v[0][0]),
        ],
        [
            sub2::<S>(v[1][1], [ym_z1.0, ym_z1.1]),
            sub2::<S>([yp_z1.0, yp_z1.1], v[1][0]),
        ],
    ];
    // d[z][y] = v(·, y, z + 1) − v(·, y, z − 1).
    let dz = [
        [
            sub2::<S>(v[1][0], [zm_y0.0, zm_y0.1]),
            sub2::<S>(v[1][1], [zm_y1.0, zm_y1.1]),
        ],
        [
            sub2::<S>([zp_y0.0, zp_y0.1], v[0][0]),
            sub2::<S>([zp_y1.0, zp_y1.1], v[0][1]),
        ],
    ];
    let scale = s.splat(l.scale);
    (
        blend::<S>(dy, st.cell.f) * scale,
        blend::<S>(dz, st.cell.f) * scale,
    )
}

// Paper §4.4 (gradient shading): diffuse factor |n·l| at the sample of `st` (grid position
// `p`), n the normalised central-difference gradient; the stencil's rows where the cell is
// inside, the six-sample gradient where it is not.
#[inline(always)]
pub(crate) fn diffuse_stencil<S: Simd, V: Voxels>(
    s: S,
    l: &Lattice<V>,
    st: &Stencil<S>,
    p: V3<S>,
    light: V3<S>,
    m: S::M,
) -> S::F32 {
    let mut f = s.splat(1.0);
    let at = m & st.inside;
    if s.any(at) {
        let (gy, gz) = gradient_yz(s, l, st, at);
        f = facing(s, V3::<S>::new(st.gx, gy, gz), light);
    }
    let edge = m & !st.inside;
    if s.any(edge) {
        f = s.select(edge, diffuse(s, l, p, light, edge), f);
    }
    f
}
