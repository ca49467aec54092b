//! The scene description the marcher, the shadow rays and the light volume read (types only,
//! plus the light volume's look-up): shading options, lights, the bundle [`VolumeScene`] and
//! the precomputed [`LightVolume`] (built by [`crate::light`]).

use spmd::{Simd, V3};

use crate::empty_space::EmptySpace;
use crate::grid::{Grid, Volume};
use crate::macrocell::{Macrocells, MACROCELL};
use crate::sampler::{trilinear, Lattice, U8Voxels};
use crate::tf::ClassifiedTf;

/// Shading of the volume samples.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Lighting {
    /// Emission/absorption only (the paper's "volume").
    #[default]
    Unlit,
    /// Diffuse, two-sided, light at the eye: colour × (a + (1 − a)·|n·v|), `n` the normalised
    /// gradient by central differences (one voxel each way; the trilinear interpolant of the
    /// lattice's central differences, eight extra gathers per shaded sample), `a` the ambient
    /// term of [`MarchOptions`] (0.3).
    Headlight,
    /// As `Headlight` with a fixed direction towards the light (world space, need not be unit).
    Directional([f32; 3]),
    /// As `Headlight` with the light at this point (world space, Å): `l` per sample.
    Point([f32; 3]),
}

/// Volumetric shadows (paper §4.5, Figure 4): every sample the transfer function makes
/// visible sends a shadow ray through the density towards `light`
/// ([`crate::shadow`]; coarser step, midpoint rule, one `exp`) and its colour is scaled by
/// `ambient + (1 − ambient)·T` (unlit) or `ambient + (1 − ambient)·|n·l|·T` (lit), `T` the
/// transmittance. Geometry does not shadow the volume.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeShadows {
    /// The light the shadows are cast from.
    pub light: Light,
    /// Step of the shadow rays, voxels (default 2; the primary step is 0.5).
    pub step_voxels: f32,
}

/// Options of the marcher.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarchOptions {
    /// Skip macrocells that the transfer function makes empty (3D DDA). Default on.
    pub macrocells: bool,
    /// Classify segments through the pre-integration table; off: post-classification of the
    /// sample at the back of each segment. Default on.
    pub preintegrated: bool,
    /// Gradient lighting.
    pub lighting: Lighting,
    /// Stop a ray when its opacity reaches this. Default 0.99.
    pub opacity_cutoff: f32,
    /// Shadows of the volume on itself (`None`: off, the default).
    pub shadows: Option<VolumeShadows>,
    /// Ambient term of lighting and shadows: colour × (ambient + (1 − ambient)·|n·l|·T).
    /// Default 0.3.
    pub ambient: f32,
}

impl Default for MarchOptions {
    fn default() -> Self {
        MarchOptions {
            macrocells: true,
            preintegrated: true,
            lighting: Lighting::Unlit,
            opacity_cutoff: 0.99,
            shadows: None,
            ambient: 0.3,
        }
    }
}

/// Everything the marcher reads: the volume, its macrocells, the classified transfer
/// function (whose `step_voxels` sets the step) and the options. Cheap to create per frame.
#[derive(Clone, Copy, Debug)]
pub struct VolumeScene<'a> {
    /// The density grid.
    pub volume: &'a Volume,
    /// Its macrocells ([`Macrocells::build`]).
    pub cells: &'a Macrocells,
    /// The classified transfer function ([`ClassifiedTf::new`]).
    pub tf: &'a ClassifiedTf,
    /// Options.
    pub opts: MarchOptions,
    /// Precomputed transmittance for `opts.shadows` ([`VolumeScene::with_light_volume`]);
    /// without it every shaded sample marches its own shadow ray (the reference).
    pub light: Option<&'a LightVolume>,
    /// Distances to the nearest non-empty macrocell under `tf`
    /// ([`VolumeScene::with_empty_space`]), so rays jump across empty space instead of
    /// walking it cell by cell (the reference). Pictures agree within rounding of the cell
    /// boundaries, as with macrocells on and off.
    pub empty: Option<&'a EmptySpace>,
}

impl<'a> VolumeScene<'a> {
    /// Bundles the parts. Panics if `cells` was not built for a grid of `volume`'s shape.
    pub fn new(
        volume: &'a Volume,
        cells: &'a Macrocells,
        tf: &'a ClassifiedTf,
        opts: MarchOptions,
    ) -> Self {
        let g = &volume.grid;
        assert!(
            (0..3).all(|a| cells.dims[a] == (g.dims[a] - 1).div_ceil(MACROCELL).max(1))
                && cells.minmax.len() == 2 * cells.dims.iter().product::<usize>(),
            "VolumeScene: macrocells do not match the volume's grid"
        );
        VolumeScene {
            volume,
            cells,
            tf,
            opts,
            light: None,
            empty: None,
        }
    }

    /// Volumetric shadows from a precomputed light volume instead of a shadow ray per shaded
    /// sample. Panics unless `light` was built for this volume's lattice and for
    /// `opts.shadows` (same light and step).
    pub fn with_light_volume(mut self, light: &'a LightVolume) -> Self {
        let g = &self.volume.grid;
        assert!(
            (0..3).all(|a| light.grid.dims[a] == (g.dims[a] - 1).div_ceil(light.stride) + 1)
                && self.opts.shadows == Some(light.shadows),
            "VolumeScene: the light volume was built for another lattice, light or step"
        );
        self.light = Some(light);
        self
    }

    /// Empty-space jumps from `empty`. Panics unless it was built for these macrocells and
    /// this transfer function ([`EmptySpace::build`]).
    pub fn with_empty_space(mut self, empty: &'a EmptySpace) -> Self {
        assert!(
            empty.matches(self.cells, self.tf),
            "VolumeScene: the empty-space map was built for other macrocells or another transfer function"
        );
        self.empty = Some(empty);
        self
    }
}

/// A light source of the shading modes (world space, Å).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Infinitely far away, in this direction *towards* the light (need not be unit).
    Directional([f32; 3]),
    /// A point at this position, no distance fall-off (a lamp for visualisation, not a
    /// physical source: what it lights keeps its brightness however far away it is).
    Point([f32; 3]),
}

impl Light {
    /// The directional light's unit direction (`[0, 1, 0]` for a zero or non-finite one);
    /// `None` for a point light.
    pub fn unit_direction(&self) -> Option<[f32; 3]> {
        match *self {
            Light::Directional(l) => {
                let n = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
                Some(if n > 0.0 && n.is_finite() {
                    [l[0] / n, l[1] / n, l[2] / n]
                } else {
                    [0.0, 1.0, 0.0]
                })
            }
            Light::Point(_) => None,
        }
    }

    /// The light in `g`'s grid coordinates (voxels): a point light's position is mapped,
    /// a direction is unchanged (the grid is isotropic).
    pub(crate) fn in_grid(&self, g: &Grid) -> Light {
        match *self {
            Light::Directional(d) => Light::Directional(d),
            Light::Point(q) => Light::Point([
                (q[0] - g.origin[0]) / g.spacing,
                (q[1] - g.origin[1]) / g.spacing,
                (q[2] - g.origin[2]) / g.spacing,
            ]),
        }
    }

    /// Unit directions towards the light from points `p` and the distance to it along them
    /// (`+∞` for a directional light). A point light at a lane's point gives direction
    /// `[0, 1, 0]` and distance 0 (nothing lies between).
    #[inline(always)]
    pub fn towards<S: Simd>(&self, s: S, p: V3<S>) -> (V3<S>, S::F32) {
        match *self {
            Light::Directional(_) => (
                V3::splat(s, self.unit_direction().unwrap_or([0.0, 1.0, 0.0])),
                s.splat(f32::INFINITY),
            ),
            Light::Point(q) => {
                let d = V3::splat(s, q) - p;
                let len2 = d.dot(d);
                let ok = s.gt(len2, s.splat(0.0)) & s.lt(len2, s.splat(f32::INFINITY));
                let len = s.sqrt(len2);
                let u = d.scale(s.splat(1.0) / s.select(ok, len, s.splat(1.0)));
                (
                    V3::select(s, ok, u, V3::splat(s, [0.0, 1.0, 0.0])),
                    s.select(ok, len, s.splat(0.0)),
                )
            }
        }
    }
}

/// Transmittance towards one light on every `stride`-th lattice point, 8 bits per point.
#[derive(Clone, Debug)]
pub struct LightVolume {
    /// The lattice of the stored points (origin of the density grid, spacing × stride).
    pub grid: Grid,
    /// Density lattice cells per light lattice cell (1, 2, 4 or 8: divides the macrocell).
    pub stride: usize,
    /// `round(255·T)` per point, x fastest.
    pub data: Vec<u8>,
    /// The light and step it was built for.
    pub shadows: VolumeShadows,
}

impl LightVolume {
    /// Bytes held.
    pub fn bytes(&self) -> u64 {
        self.data.len() as u64
    }

    /// Transmittance at density-grid coordinates `p` (voxels), trilinear.
    #[inline(always)]
    pub(crate) fn sample<S: Simd>(&self, s: S, p: V3<S>, m: S::M) -> S::F32 {
        let lat = Lattice::new(&self.grid, U8Voxels(&self.data), 1.0 / 255.0);
        trilinear(s, &lat, p.scale(s.splat(1.0 / self.stride as f32)), m)
    }
}
