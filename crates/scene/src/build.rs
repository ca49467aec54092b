//! `Scene::build`: a molecule frame and [`SceneSettings`] to bonds, the ball-and-stick model
//! with its BVH, the density volume with macrocells and classified transfer function, and the
//! light volume (paper §4.1 steps 3-5), with per-stage timings and a memory check first.

use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Instant;

use molecule::bonds::{try_build_bonds_with_progress, BondError, BondOptions};
use molecule::unwrap::{crosses, unwrap, UnwrapError, UnwrapMethod};
use molecule::{elements, MinimumImage, Molecule};
use spmd::Isa;
use volume::{
    build_density, density_work, ClassifiedTf, DensityParams, EmptySpace, Grid, LightVolume,
    Macrocells, MarchOptions, Medium, ParticleScene, Particles, TransferFunction, Volume,
    VolumeError, VolumeScene, Watch,
};

use crate::fit::{bounding_sphere, Sphere};
use crate::memory::MemoryEstimate;
use crate::model::{Coloring, Model, ModelOptions, Style};
use crate::progress::{Progress, Stage, Timings};
use crate::settings::{
    BondSettings, BondSource, ColorBy, DensitySource, ModelSettings, RadiusKind, SceneSettings,
    VolumeSettings,
};
use crate::SceneError;

/// Finest resolution (voxels per Å, i.e. steps of half of 1/this Å) of a grid-free volume.
pub const MAX_PARTICLE_RESOLUTION: f32 = 32.0;

/// Where the density volume's values come from.
#[derive(Clone, Debug)]
pub enum Density {
    /// A grid of RBF density and its macrocells.
    Grid {
        /// The grid.
        volume: Volume,
        /// Its macrocells.
        cells: Macrocells,
    },
    /// The atoms and the BVH over their support spheres (grid-free).
    Particles(Particles),
}

impl Density {
    /// The grid, when the density is sampled on one.
    pub fn grid(&self) -> Option<&Volume> {
        match self {
            Density::Grid { volume, .. } => Some(volume),
            Density::Particles(_) => None,
        }
    }

    /// Largest density: over the lattice points, or over the atom centres.
    pub fn max_value(&self) -> f32 {
        match self {
            Density::Grid { volume, .. } => volume.max_value,
            Density::Particles(p) => p.max_value,
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> u64 {
        match self {
            Density::Grid { volume, cells } => volume.bytes() + cells.bytes(),
            Density::Particles(p) => p.bytes(),
        }
    }
}

/// The density volume with what the marcher needs besides its options.
#[derive(Clone, Debug)]
pub struct DensityVolume {
    /// The density: a grid, or the particles.
    pub density: Density,
    /// The transfer function classified over `[0, tf_max]`.
    pub tf: ClassifiedTf,
    /// The density at the top of the transfer function: `VolumeSettings::density_max`, or
    /// the volume's maximum.
    pub tf_max: f32,
    /// Distances to the nearest macrocell `tf` does not make empty (grids only), rebuilt
    /// with `tf`.
    pub empty: Option<EmptySpace>,
}

impl DensityVolume {
    /// The empty-space map of `density` under `tf` (`None` for grid-free volumes).
    fn empty_space(density: &Density, tf: &ClassifiedTf) -> Option<EmptySpace> {
        match density {
            Density::Grid { cells, .. } => Some(EmptySpace::build(cells, tf)),
            Density::Particles(_) => None,
        }
    }
}

/// Everything the renderer traces for one frame of a molecule.
#[derive(Debug)]
pub struct Scene {
    /// The settings it was built with (reused by [`Scene::rebuild`]).
    pub settings: SceneSettings,
    /// Bonds (pairs of atom indices; empty without a model).
    pub bonds: Vec<[u32; 2]>,
    /// Ball-and-stick model (geometry + BVH).
    pub model: Option<Arc<Model>>,
    /// Density volume.
    pub volume: Option<DensityVolume>,
    /// Light volume of volumetric shadows.
    pub light_volume: Option<LightVolume>,
    /// The sphere cameras are fitted to ([`bounding_sphere`]).
    pub sphere: Sphere,
    /// The estimate checked against the budget before building.
    pub estimate: MemoryEstimate,
    /// Per-stage wall times.
    pub timings: Timings,
    /// How the frame was unwrapped (`None`: [`BondSettings::unwrap`] off).
    pub unwrap: Option<UnwrapReport>,
    /// Per-atom radius and colour scratch, reused by [`Scene::rebuild`].
    scratch: (Vec<f32>, Vec<u32>),
}

/// A model already built for a frame, with the settings of the scene it was built for, that
/// [`Scene::build_sharing`] may take instead of building its own.
#[derive(Clone)]
pub struct SharedModel {
    /// The model.
    pub model: Arc<Model>,
    /// The settings it was built with (their `model` and `bonds` must match to share it).
    pub settings: SceneSettings,
}

impl Scene {
    /// Builds the scene of `m` with backend `isa` (density and light volume kernels).
    pub fn build(isa: Isa, m: &Molecule, settings: &SceneSettings) -> Result<Scene, SceneError> {
        Scene::build_with(isa, m, settings, &Progress::none())
    }

    /// [`Scene::build`] reporting each stage and its work done to `progress`.
    pub fn build_with(
        isa: Isa,
        m: &Molecule,
        settings: &SceneSettings,
        progress: &Progress,
    ) -> Result<Scene, SceneError> {
        Scene::build_sharing(isa, m, settings, progress, None)
    }

    /// [`Scene::build_with`] sharing `shared`'s model, built for the same frame `m`, when
    /// `settings` asks for the same model and bonds: no BVH is built and the model is not held
    /// twice (the viewer's first time step, built again with its volume behind the model on
    /// screen). Otherwise the model is built as usual.
    pub fn build_sharing(
        isa: Isa,
        m: &Molecule,
        settings: &SceneSettings,
        progress: &Progress,
        shared: Option<&SharedModel>,
    ) -> Result<Scene, SceneError> {
        let mut s = Scene {
            settings: settings.clone(),
            bonds: Vec::new(),
            model: None,
            volume: None,
            light_volume: None,
            sphere: Sphere {
                center: [0.0; 3],
                radius: 1.0,
            },
            estimate: MemoryEstimate::default(),
            timings: Timings::default(),
            unwrap: None,
            scratch: (Vec::new(), Vec::new()),
        };
        let shared = shared.filter(|sh| {
            settings.model.is_some()
                && sh.settings.model == settings.model
                && sh.settings.bonds == settings.bonds
        });
        s.build_frame(isa, m, progress, shared.map(|sh| &sh.model))?;
        Ok(s)
    }

    /// Rebuilds for the next trajectory frame `m` with the same settings. Reused: the bond
    /// Vec (refilled in place for file bonds) and the per-atom radius and colour scratch; the
    /// BVH, volume and light volume are built anew (their builders allocate).
    pub fn rebuild(&mut self, isa: Isa, m: &Molecule) -> Result<(), SceneError> {
        self.rebuild_with(isa, m, &Progress::none())
    }

    /// [`Scene::rebuild`] reporting each stage and its work done to `progress`.
    pub fn rebuild_with(
        &mut self,
        isa: Isa,
        m: &Molecule,
        progress: &Progress,
    ) -> Result<(), SceneError> {
        self.build_frame(isa, m, progress, None)
    }

    /// Builds every part the settings ask for over frame `m`, taking the model from `shared`
    /// (built for `m` with the same model and bond settings) instead of building it.
    fn build_frame(
        &mut self,
        isa: Isa,
        m: &Molecule,
        progress: &Progress,
        shared: Option<&Arc<Model>>,
    ) -> Result<(), SceneError> {
        if m.is_empty() {
            return Err(SceneError::NoAtoms);
        }
        self.model = None;
        self.volume = None;
        self.light_volume = None;
        self.timings = Timings::default();
        self.unwrap = None;
        let st = &self.settings;
        if let Some(ms) = &st.model {
            check_model(ms)?;
        }
        if st.model.is_some() || st.bonds.unwrap {
            progress.start(Stage::Bonds, m.len() as u64)?;
        }
        let t = Instant::now();
        let keep_crossing = st.model.as_ref().is_some_and(|ms| ms.periodic_bonds);
        let unwrapped = prepare_into(
            &st.bonds,
            st.model.is_some(),
            keep_crossing,
            m,
            &mut self.bonds,
            progress,
        )?;
        self.timings.bonds = t.elapsed().as_secs_f64();
        // From here on the frame is the unwrapped one (model, volume, camera sphere).
        let m = match &unwrapped {
            Some((u, report)) => {
                self.unwrap = Some(*report);
                u
            }
            None => m,
        };
        // Check the budget before the large allocations: the estimated peak of the process
        // (the figure `bnsview info` prints) less what is already resident (the baseline,
        // the frame and the bonds), since the budget is a share of the memory still available.
        self.estimate = MemoryEstimate::new(m, self.bonds.len(), st)?;
        let e = &self.estimate;
        // A shared model is resident already and not built again.
        let model_bytes = shared.map_or(0, |_| e.geometry + e.bvh + e.wide_bvh);
        let needed = e
            .peak_bytes()
            .saturating_sub(e.peak.baseline + e.atoms + self.bonds.len() as u64 * 8 + model_bytes);
        if let Some(budget) = st.budget_bytes.or_else(volume::default_budget_bytes) {
            if needed > budget {
                return Err(SceneError::TooLarge {
                    needed,
                    budget,
                    breakdown: self.estimate.breakdown(),
                });
            }
        }
        if let (Some(ms), Some(model)) = (&st.model, shared) {
            if ms.wide_bvh {
                model.wide();
            }
            self.model = Some(model.clone());
        } else if let Some(ms) = &st.model {
            let prims = model_prim_count(m.len(), self.bonds.len(), ms).1;
            progress.start(Stage::Model, prims as u64)?;
            let t = Instant::now();
            let model = build_model(m, &self.bonds, ms, &mut self.scratch, progress)?;
            if ms.wide_bvh {
                model.wide();
            }
            self.model = Some(Arc::new(model));
            self.timings.model = t.elapsed().as_secs_f64();
        }
        if let Some(vs) = &st.volume {
            let tf_max = match vs.density_max {
                Some(d) if d > 0.0 && d.is_finite() => Some(d),
                Some(d) => {
                    return Err(SceneError::BadSetting {
                        name: "density-max",
                        expected: "a positive number",
                        value: d,
                    })
                }
                None => None,
            };
            let density = match vs.source {
                DensitySource::Grid => {
                    let units = self
                        .estimate
                        .volume_dims
                        .map_or(0, |d| density_work(d, vs.format));
                    progress.start(Stage::Volume, units)?;
                    let t = Instant::now();
                    let volume =
                        build_volume(isa, m, vs, st.budget_bytes, &mut self.scratch.0, progress)?;
                    self.timings.volume = t.elapsed().as_secs_f64();
                    progress.start(Stage::Macrocells, 1)?;
                    let t = Instant::now();
                    let cells = Macrocells::build(&volume);
                    self.timings.macrocells = t.elapsed().as_secs_f64();
                    Density::Grid { volume, cells }
                }
                DensitySource::Particles => {
                    if vs.light_volume.is_some() {
                        return Err(SceneError::Unsupported(
                            "volumetric shadows need the density grid: drop --volume-shadows \
                             or use --volume grid",
                        ));
                    }
                    // The grid's size caps its resolution; here only time would grow (250×
                    // the samples of 4 /Å at 1000 /Å): cap it where steps are far finer than
                    // any atom (covalent radii ≥ 0.31 Å).
                    if vs.voxels_per_angstrom > MAX_PARTICLE_RESOLUTION {
                        return Err(SceneError::BadSetting {
                            name: "voxels-per-angstrom",
                            expected: "at most 32 with --volume particles (steps of 1/64 Å; \
                                       finer steps cost time and change nothing visible)",
                            value: vs.voxels_per_angstrom,
                        });
                    }
                    progress.start(Stage::Volume, 1)?;
                    let t = Instant::now();
                    density_radii(m, &mut self.scratch.0);
                    let p = Particles::build(
                        &m.x,
                        &m.y,
                        &m.z,
                        &self.scratch.0,
                        vs.voxels_per_angstrom,
                    )?;
                    self.timings.volume = t.elapsed().as_secs_f64();
                    Density::Particles(p)
                }
            };
            let t = Instant::now();
            let tf_max = tf_max.unwrap_or(density.max_value());
            // (A NaN maximum must not reach the classification either.)
            if tf_max.is_nan() || tf_max <= 0.0 {
                return Err(SceneError::EmptyDensity {
                    voxels_per_angstrom: vs.voxels_per_angstrom,
                });
            }
            let tf = ClassifiedTf::new(&vs.tf, 0.0, tf_max, vs.step_voxels);
            let empty = DensityVolume::empty_space(&density, &tf);
            self.timings.macrocells += t.elapsed().as_secs_f64();
            progress.done.store(1, Ordering::Relaxed);
            let d = DensityVolume {
                density,
                tf,
                tf_max,
                empty,
            };
            if let (Some(lv), Density::Grid { volume, cells }) = (&vs.light_volume, &d.density) {
                progress.start(
                    Stage::LightVolume,
                    LightVolume::planes(&volume.grid, lv.stride),
                )?;
                let t = Instant::now();
                let scene = VolumeScene::new(volume, cells, &d.tf, MarchOptions::default());
                self.light_volume = Some(LightVolume::build_with_progress(
                    isa,
                    &scene,
                    lv.shadows(),
                    lv.stride,
                    &progress.done,
                ));
                self.timings.light_volume = t.elapsed().as_secs_f64();
            }
            self.volume = Some(d);
        }
        if (progress.cancelled)() {
            return Err(SceneError::Cancelled);
        }
        self.sphere = bounding_sphere(m, self.model.as_deref());
        Ok(())
    }

    /// Bytes of the per-atom scratch kept between frames (capacity of the radius and colour
    /// vectors).
    pub(crate) fn scratch_bytes(&self) -> u64 {
        (self.scratch.0.capacity() * 4 + self.scratch.1.capacity() * 4) as u64
    }

    /// Replaces the volume's transfer function by `tf` (e.g. its opacity scaled) without
    /// rebuilding the density: the classification is redone exactly as [`Scene::build`] does
    /// it. Returns `false`, changing nothing, when there is no volume or a light volume was
    /// built with the old one (then the scene must be rebuilt).
    pub fn set_transfer_function(&mut self, tf: &TransferFunction) -> bool {
        let (Some(d), Some(vs)) = (self.volume.as_mut(), self.settings.volume.as_mut()) else {
            return false;
        };
        if self.light_volume.is_some() {
            return false;
        }
        d.tf = ClassifiedTf::new(tf, 0.0, d.tf_max, vs.step_voxels);
        d.empty = DensityVolume::empty_space(&d.density, &d.tf);
        vs.tf = tf.clone();
        true
    }

    /// The marcher's view of the volume with options `opts`, with the light volume attached
    /// when it was built for `opts.shadows`. Grid-free volumes have no shadows: `opts.shadows`
    /// is dropped for them (the settings' validation refuses the combination first).
    pub fn volume_scene(&self, opts: MarchOptions) -> Option<Medium<'_>> {
        let d = self.volume.as_ref()?;
        Some(match &d.density {
            Density::Grid { volume, cells } => {
                let mut vs = VolumeScene::new(volume, cells, &d.tf, opts);
                if let Some(es) = &d.empty {
                    vs = vs.with_empty_space(es);
                }
                Medium::Grid(match &self.light_volume {
                    Some(lv) if opts.shadows == Some(lv.shadows) => vs.with_light_volume(lv),
                    _ => vs,
                })
            }
            Density::Particles(p) => {
                let opts = MarchOptions {
                    shadows: None,
                    ..opts
                };
                Medium::Particles(ParticleScene::new(p, &d.tf, opts))
            }
        })
    }
}

/// Largest `radius-scale` and `stick-radius` (Å) accepted: a ball or stick 1000 Å across
/// (2000 Å for the largest element radii) is no molecule, and radii near 1e19 overflow the
/// boxes' squared extents and areas (SAH NaN, an empty picture) instead of failing.
const MAX_RADIUS: f32 = 1000.0;

/// Rejects out-of-range model settings.
fn check_model(ms: &ModelSettings) -> Result<(), SceneError> {
    if !(ms.radius_scale > 0.0 && ms.radius_scale <= MAX_RADIUS) {
        return Err(SceneError::BadSetting {
            name: "radius-scale",
            expected: "a positive number up to 1000",
            value: ms.radius_scale,
        });
    }
    if !(ms.stick_radius > 0.0 && ms.stick_radius <= MAX_RADIUS) {
        return Err(SceneError::BadSetting {
            name: "stick-radius",
            expected: "a positive number of Å up to 1000",
            value: ms.stick_radius,
        });
    }
    Ok(())
}

impl BondSettings {
    /// The bonds of `m` (pairs `i < j`, sorted, for [`BondSource::Auto`]); with
    /// [`BondSettings::unwrap`], the bonds [`BondSettings::prepare`] draws without
    /// `--pbc`.
    pub fn build(&self, m: &Molecule) -> Result<Vec<[u32; 2]>, SceneError> {
        Ok(self.prepare(m, false)?.bonds)
    }

    /// What [`crate::Scene::build`] makes of frame `m` before the model: the unwrapped frame
    /// (with [`BondSettings::unwrap`]) and the bonds drawn; `keep_crossing` keeps the bonds
    /// that still cross the cell after unwrapping ([`ModelSettings::periodic_bonds`]).
    pub fn prepare(&self, m: &Molecule, keep_crossing: bool) -> Result<Prepared, SceneError> {
        let mut bonds = Vec::new();
        let u = prepare_into(self, true, keep_crossing, m, &mut bonds, &Progress::none())?;
        let (unwrapped, unwrap) = match u {
            Some((m, r)) => (Some(m), Some(r)),
            None => (None, None),
        };
        Ok(Prepared {
            unwrapped,
            bonds,
            unwrap,
        })
    }
}

/// A frame made ready for the model by [`BondSettings::prepare`].
#[derive(Debug)]
pub struct Prepared {
    /// The unwrapped frame (`None`: not unwrapped; use the input as it is).
    pub unwrapped: Option<Molecule>,
    /// The bonds drawn (pairs of atom indices `i < j`).
    pub bonds: Vec<[u32; 2]>,
    /// How it was unwrapped.
    pub unwrap: Option<UnwrapReport>,
}

/// How a frame was unwrapped ([`BondSettings::unwrap`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnwrapReport {
    /// Image flags, minimum image along bonds, or nothing to do.
    pub method: UnwrapMethod,
    /// Bonds that still cross the cell after unwrapping (molecules bonded to their own
    /// periodic image, such as a bulk network).
    pub crossing: usize,
    /// Whether those are drawn (as half-sticks, [`ModelSettings::periodic_bonds`]) or left out.
    pub crossing_drawn: bool,
}

impl UnwrapReport {
    /// One line for `-v`: the method and what became of the bonds still crossing.
    pub fn describe(&self) -> String {
        let mut s = format!("unwrap:  by {}", self.method.describe());
        if self.crossing > 0 {
            s += &format!(
                "; {} bonds still cross the cell (bonded to their own image), {}",
                self.crossing,
                if self.crossing_drawn {
                    "drawn as half-sticks"
                } else {
                    "not drawn (add --pbc for half-sticks)"
                }
            );
        }
        s
    }
}

/// Fills `out` with the bonds drawn (`draw`: there is a model) and, with `b.unwrap`, returns
/// the unwrapped copy of `m`: the bonds used to unwrap are detected with the minimum image
/// (or the file's); those still crossing after unwrapping stay only with `keep_crossing`.
fn prepare_into(
    b: &BondSettings,
    draw: bool,
    keep_crossing: bool,
    m: &Molecule,
    out: &mut Vec<[u32; 2]>,
    progress: &Progress,
) -> Result<Option<(Molecule, UnwrapReport)>, SceneError> {
    if !b.unwrap {
        if draw {
            fill_bonds(b, m, out, progress)?;
        } else {
            out.clear();
        }
        return Ok(None);
    }
    let cell = m.cell.ok_or(UnwrapError::NoCell)?;
    let method = UnwrapMethod::of(m);
    out.clear();
    if (draw && b.source != BondSource::None) || method == UnwrapMethod::Bonds {
        let pbc = BondSettings {
            source: if b.source == BondSource::File {
                BondSource::File
            } else {
                BondSource::Auto
            },
            options: BondOptions {
                pbc: true,
                ..b.options.clone()
            },
            unwrap: false,
        };
        fill_bonds(&pbc, m, out, progress)?;
    }
    let mut u = m.clone();
    unwrap(&mut u, out)?;
    let mut report = UnwrapReport {
        method,
        crossing: 0,
        crossing_drawn: keep_crossing,
    };
    if !draw || b.source == BondSource::None {
        out.clear();
    } else if let Some(mi) = MinimumImage::new(&cell) {
        let before = out.len();
        if keep_crossing {
            report.crossing = out.iter().filter(|b| crosses(&u, &mi, b)).count();
        } else {
            out.retain(|b| !crosses(&u, &mi, b));
            report.crossing = before - out.len();
        }
    }
    Ok(Some((u, report)))
}

/// Replaces `out` with the bonds of `m` (adding the atoms searched to `progress`, and
/// stopping with [`SceneError::Cancelled`] once it is cancelled).
fn fill_bonds(
    b: &BondSettings,
    m: &Molecule,
    out: &mut Vec<[u32; 2]>,
    progress: &Progress,
) -> Result<(), SceneError> {
    match b.source {
        BondSource::Auto => {
            *out = match try_build_bonds_with_progress(
                m,
                &b.options,
                &progress.done,
                progress.cancelled,
            ) {
                Err(BondError::Cancelled) => return Err(SceneError::Cancelled),
                r => r?,
            }
        }
        BondSource::File => {
            let fb = m.file_bonds.as_ref().ok_or(SceneError::NoFileBonds)?;
            out.clear();
            out.extend_from_slice(fb);
        }
        BondSource::None => out.clear(),
    }
    Ok(())
}

/// Bonds drawn and BVH primitives of a model of `atoms` atoms and `bonds` bonds.
pub(crate) fn model_prim_count(atoms: usize, bonds: usize, ms: &ModelSettings) -> (usize, usize) {
    let bonds = if ms.style == Style::Spheres { 0 } else { bonds };
    let balls = if ms.style == Style::Licorice {
        0
    } else {
        atoms
    };
    (bonds, balls + bonds)
}

/// The ball-and-stick model of `m` with `bonds`; `scratch` holds the per-atom radii and
/// colours between frames.
pub(crate) fn build_model(
    m: &Molecule,
    bonds: &[[u32; 2]],
    ms: &ModelSettings,
    scratch: &mut (Vec<f32>, Vec<u32>),
    progress: &Progress,
) -> Result<Model, SceneError> {
    check_model(ms)?;
    let (radius, colors) = scratch;
    radius.clear();
    radius.extend(m.elements.iter().map(|&z| {
        let e = elements::element(z);
        match ms.radius {
            RadiusKind::Covalent => e.covalent_radius,
            RadiusKind::Vdw => e.vdw_radius,
        }
    }));
    colors.clear();
    colors.extend(m.elements.iter().map(|&z| {
        let [r, g, b] = elements::element(z).color;
        crate::rgba(r, g, b, 255)
    }));
    let coloring = match &ms.color {
        ColorBy::Element => Coloring::PerAtom,
        ColorBy::Column {
            name,
            colormap,
            range,
        } => {
            if let Some((lo, hi)) = *range {
                if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                    return Err(SceneError::BadColorRange { lo, hi });
                }
            }
            let values = m.scalar(name).ok_or_else(|| SceneError::NoSuchColumn {
                name: name.clone(),
                available: m.scalars.iter().map(|(n, _)| n.clone()).collect(),
            })?;
            Coloring::Scalar {
                values: values.to_vec(),
                colormap: *colormap,
                range: *range,
            }
        }
    };
    let opt = ModelOptions {
        radius_scale: ms.radius_scale,
        stick_radius: ms.stick_radius,
        style: ms.style,
        coloring,
        cell: m.cell,
        periodic_bonds: ms.periodic_bonds,
        draw_cell: ms.draw_cell,
    };
    if ms.draw_cell && m.cell.is_none() {
        return Err(SceneError::NoCell);
    }
    let watch = bvh::Watch {
        done: &progress.done,
        cancelled: progress.cancelled,
    };
    Model::new(&m.x, &m.y, &m.z, radius, colors, bonds, &opt, Some(&watch))
        .map_err(|bvh::Cancelled| SceneError::Cancelled)
}

impl ModelSettings {
    /// The ball-and-stick model of `m` with `bonds` (what [`Scene::build`] builds).
    pub fn build_model(&self, m: &Molecule, bonds: &[[u32; 2]]) -> Result<Model, SceneError> {
        build_model(
            m,
            bonds,
            self,
            &mut (Vec::new(), Vec::new()),
            &Progress::none(),
        )
    }
}

/// Covalent radii of the atoms (Å): the RBF widths of the density.
fn density_radii(m: &Molecule, out: &mut Vec<f32>) {
    out.clear();
    out.extend(
        m.elements
            .iter()
            .map(|&z| elements::element(z).covalent_radius),
    );
}

/// The density lattice [`build_volume`] will use.
pub(crate) fn density_grid(m: &Molecule, vs: &VolumeSettings) -> Result<Grid, SceneError> {
    let mut r = Vec::new();
    density_radii(m, &mut r);
    let grid = Grid::for_atoms(&m.x, &m.y, &m.z, &r, vs.voxels_per_angstrom)?;
    // Past 2³¹ points no budget matters (and the estimate's sums would overflow): refuse
    // here, with the resolution that fits.
    let params = DensityParams {
        voxels_per_angstrom: vs.voxels_per_angstrom,
        format: vs.format,
        budget_bytes: None,
    };
    volume::check_size(&grid, [&m.x, &m.y, &m.z, &r], &params, None)?;
    Ok(grid)
}

/// The density volume of `m` (`radii` is scratch).
fn build_volume(
    isa: Isa,
    m: &Molecule,
    vs: &VolumeSettings,
    budget_bytes: Option<u64>,
    radii: &mut Vec<f32>,
    progress: &Progress,
) -> Result<Volume, SceneError> {
    density_radii(m, radii);
    let params = DensityParams {
        voxels_per_angstrom: vs.voxels_per_angstrom,
        format: vs.format,
        budget_bytes,
    };
    let watch = Watch {
        done: &progress.done,
        cancelled: progress.cancelled,
    };
    match build_density(isa, &m.x, &m.y, &m.z, radii, &params, Some(&watch)) {
        Err(VolumeError::Cancelled) => Err(SceneError::Cancelled),
        r => Ok(r?),
    }
}

impl VolumeSettings {
    /// The density volume of `m` and its macrocells (what [`Scene::build`] builds; the
    /// volume crate's own budget check applies).
    pub fn build_density(
        &self,
        isa: Isa,
        m: &Molecule,
    ) -> Result<(Volume, Macrocells), SceneError> {
        let v = build_volume(isa, m, self, None, &mut Vec::new(), &Progress::none())?;
        let c = Macrocells::build(&v);
        Ok((v, c))
    }
}
