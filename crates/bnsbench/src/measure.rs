//! Running the measurements of one scene: preprocess it once through the application's
//! [`Pipeline`], then time the frames of every key and ISA.

use std::collections::BTreeMap;
use std::time::Instant;

use molecule::scenes::SceneName;
use molecule::Molecule;
use render::{
    render_frame_into, render_modal_into, Accum, Camera, Framebuffer, Model, RenderOptions,
    TraceOptions, View,
};
use spmd::Isa;
use volume::{
    ClassifiedTf, LightVolume, Macrocells, MarchOptions, TransferFunction, Volume, VolumeScene,
};

use crate::error::{BenchError, PipelineError};
use crate::mode::BenchMode;
use crate::paper::paper_voxels_per_angstrom;
use crate::plan::{Key, Tables};
use crate::probe::{load_avg, peak_rss_mb, reset_peak_rss};
use crate::record::{mb, model_bytes, Measurement, Preprocess};
use crate::run::Config;

/// A generated scene: atoms, bonds and their times.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The atoms.
    pub molecule: Molecule,
    /// Bonds, pairs i<j sorted.
    pub bonds: Vec<[u32; 2]>,
    /// Time to generate the atoms (s).
    pub load_s: f64,
    /// Time to build the bonds (s).
    pub bond_s: f64,
}

/// How a mode's frame is rendered.
#[derive(Clone, Debug)]
pub enum FrameSetup {
    /// `render_frame_into`: headlight b&s, volume, vol+b&s (as `bnsview render` without
    /// modality flags).
    Frame(RenderOptions),
    /// `render_modal_into` with these trace options and samples per pixel.
    Modal {
        /// Modality, light, background.
        opt: TraceOptions,
        /// Samples per pixel of one frame.
        spp: u32,
    },
}

/// The application's side of the benchmark: how a scene is built and how each mode is
/// rendered, exactly as the application renders it (so the figures are of its pictures).
pub trait Pipeline {
    /// Generates `atoms` atoms of `scene` and their bonds.
    fn load(&self, scene: SceneName, atoms: usize) -> Result<Loaded, PipelineError>;
    /// The ball-and-stick model (geometry and BVH) of a molecule.
    fn model(&self, m: &Molecule, bonds: &[[u32; 2]]) -> Result<Model, PipelineError>;
    /// The bounding sphere (centre, radius in Å) the model of `m` would have, for runs that
    /// build no model: every mode of a scene sees the same frame.
    fn sphere(&self, m: &Molecule) -> ([f32; 3], f32);
    /// The density volume of a molecule at `voxels_per_angstrom`, its macrocells and the
    /// build time (s), built on `isa`.
    fn volume(
        &self,
        isa: Isa,
        m: &Molecule,
        voxels_per_angstrom: f32,
    ) -> Result<(Volume, Macrocells, f64), PipelineError>;
    /// The transfer function of the volume modes.
    fn transfer_function(&self) -> Result<TransferFunction, PipelineError>;
    /// The marcher's options (lighting, volumetric shadows) of a volume mode.
    fn march_options(&self, mode: BenchMode) -> Result<MarchOptions, PipelineError>;
    /// How a mode's frame is rendered.
    fn frame_setup(&self, mode: BenchMode) -> Result<FrameSetup, PipelineError>;
    /// The light volume of `vs`'s volumetric shadows (`None` without them), built on `isa`;
    /// `log` takes a line about the build.
    fn light_volume(&self, vs: &VolumeScene, isa: Isa, log: &dyn Fn(String))
        -> Option<LightVolume>;
}

/// Renders a mode's frame, again and again.
enum Renderer<'a> {
    /// A frame of `render_frame_into`.
    Frame {
        geo: Option<&'a Model>,
        vol: Option<&'a VolumeScene<'a>>,
        fb: Framebuffer,
        opt: RenderOptions,
    },
    /// A frame of `render_modal_into`.
    Modal {
        scene: &'a Model,
        vol: Option<&'a VolumeScene<'a>>,
        acc: Accum,
        opt: TraceOptions,
        spp: u32,
    },
}

impl<'a> Renderer<'a> {
    fn new(
        key: &Key,
        setup: FrameSetup,
        geo: Option<&'a Model>,
        vol: Option<&'a VolumeScene<'a>>,
    ) -> Result<Renderer<'a>, BenchError> {
        let frame_err = |e| BenchError::Frame(key.w, key.h, e);
        Ok(match setup {
            FrameSetup::Frame(opt) => Renderer::Frame {
                geo,
                vol,
                fb: Framebuffer::new(key.w, key.h, opt.background).map_err(frame_err)?,
                opt,
            },
            FrameSetup::Modal { opt, spp } => Renderer::Modal {
                scene: geo.ok_or(BenchError::NoGeometry)?,
                vol,
                acc: Accum::new(key.w, key.h).map_err(frame_err)?,
                opt,
                spp,
            },
        })
    }

    /// Renders one complete frame and returns its time in ms. A modality starts from an empty
    /// accumulation every frame (sample numbers from 0, so every frame does the same work).
    fn frame(&mut self, camera: &Camera, isa: Isa) -> f64 {
        match self {
            Renderer::Frame { geo, vol, fb, opt } => {
                let t = Instant::now();
                render_frame_into(*geo, *vol, camera, fb, opt, isa);
                t.elapsed().as_secs_f64() * 1e3
            }
            Renderer::Modal {
                scene,
                vol,
                acc,
                opt,
                spp,
            } => {
                acc.rgb.fill(0.0);
                acc.samples = 0;
                let t = Instant::now();
                render_modal_into(scene, *vol, camera, acc, opt, *spp, isa);
                t.elapsed().as_secs_f64() * 1e3
            }
        }
    }
}

/// The camera of a scene's `far` or `close` view: fitted to the ball-and-stick bounding
/// sphere for every mode, so all modes of a scene see the same frame, as in the paper's
/// Table 3.
pub fn camera_for(sphere: ([f32; 3], f32), far: bool, w: u32, h: u32) -> Camera {
    let view = if far { View::Far } else { View::Close };
    Camera::view(view, sphere.0, sphere.1, 45.0, w as f32 / h as f32)
}

/// The state of a run across scenes: what to run it with, thread pools, progress.
pub(crate) struct Session<'a> {
    pub cfg: &'a Config,
    pub pipeline: &'a dyn Pipeline,
    pub isas: &'a [Isa],
    pub tf: &'a TransferFunction,
    pub frames: usize,
    pub pools: BTreeMap<u32, rayon::ThreadPool>,
    pub done: usize,
    pub total: usize,
}

impl Session<'_> {
    /// Preprocesses `scene` and measures its `keys` on every ISA.
    pub fn scene(
        &mut self,
        scene: SceneName,
        keys: &[(Key, Tables)],
    ) -> Result<(Preprocess, Vec<Measurement>), BenchError> {
        let pl = self.pipeline;
        let need_geometry = keys.iter().any(|(k, _)| k.mode.geometry());
        let need_volume = keys.iter().any(|(k, _)| k.mode.volume());
        let atoms = self.cfg.spec.scene_atoms(scene);
        let reset = reset_peak_rss();
        eprintln!("bench: {scene}: generating {atoms} atoms and bonds");
        let l = pl.load(scene, atoms).map_err(BenchError::Pipeline)?;
        let m = &l.molecule;
        eprintln!(
            "bench: {scene}: {} atoms, {} bonds (load {:.2} s, bonds {:.2} s)",
            m.len(),
            l.bonds.len(),
            l.load_s,
            l.bond_s
        );
        let build_isa = *self.isas.iter().max().expect("non-empty");
        let model = if need_geometry {
            let s = pl.model(m, &l.bonds).map_err(BenchError::Pipeline)?;
            eprintln!(
                "bench: {scene}: BVH {:.2} s ({} nodes, SAH {:.1})",
                s.bvh.stats.build_time.as_secs_f64(),
                s.bvh.stats.nodes,
                s.bvh.stats.sah_cost
            );
            Some(s)
        } else {
            None
        };
        let vpa = self
            .cfg
            .voxels_per_angstrom
            .unwrap_or_else(|| paper_voxels_per_angstrom(scene));
        let vol = if need_volume {
            eprintln!("bench: {scene}: building the density volume at {vpa} voxels/Å");
            let v = pl.volume(build_isa, m, vpa).map_err(BenchError::Pipeline)?;
            eprintln!(
                "bench: {scene}: volume {:.2} s, {:?} voxels, {:.1} MB",
                v.2,
                v.0.grid.dims,
                mb(v.0.bytes())
            );
            Some(v)
        } else {
            None
        };
        let sizes = model.as_ref().map(model_bytes);
        let p = Preprocess {
            scene,
            atoms: m.len(),
            bonds: l.bonds.len(),
            load_s: l.load_s,
            bond_s: l.bond_s,
            bvh_s: model.as_ref().map(|s| s.bvh.stats.build_time.as_secs_f64()),
            volume_s: vol.as_ref().map(|v| v.2),
            geometry_bytes: sizes.map(|s| s.0),
            bvh_bytes: sizes.map(|s| s.1),
            volume_bytes: vol.as_ref().map(|v| v.0.bytes() + v.1.bytes()),
            voxels_per_angstrom: vpa,
            volume_dims: vol.as_ref().map(|v| v.0.grid.dims),
            peak_rss_mb: peak_rss_mb(),
            peak_rss_reset: reset,
        };

        let ctf = vol
            .as_ref()
            .map(|(v, _, _)| ClassifiedTf::new(self.tf, 0.0, v.max_value, 0.5));
        let no_macrocells = self.cfg.no_macrocells;
        // The marcher's options of a mode, as the application renders it.
        let vscene = |mode: BenchMode| -> Result<Option<VolumeScene<'_>>, BenchError> {
            Ok(match (&vol, &ctf, mode.volume()) {
                (Some((v, cells, _)), Some(ctf), true) => {
                    let opts = MarchOptions {
                        macrocells: !no_macrocells,
                        ..pl.march_options(mode).map_err(BenchError::Pipeline)?
                    };
                    Some(VolumeScene::new(v, cells, ctf, opts))
                }
                _ => None,
            })
        };
        let sphere = match &model {
            Some(s) => (s.center, s.radius),
            None => pl.sphere(m),
        };
        let mut out = Vec::new();
        let mut lights: Vec<LightVolume> = Vec::new();
        for &(key, tables) in keys {
            let camera = camera_for(sphere, key.far, key.w, key.h);
            let geo = model.as_ref().filter(|_| key.mode.geometry());
            let vs = vscene(key.mode)?;
            // Volumetric shadows read a light volume built once per light and scene, as
            // `bnsview render` builds it once per picture (its build is preprocessing,
            // printed, not part of the frame time).
            let shadows = vs.as_ref().and_then(|v| v.opts.shadows);
            if let (Some(v), Some(sh)) = (&vs, shadows) {
                if !lights.iter().any(|l| l.shadows == sh) {
                    let log = |msg: String| eprintln!("bench: {scene}: {msg}");
                    lights.extend(pl.light_volume(v, Isa::detect(), &log));
                }
            }
            let light = shadows.and_then(|sh| lights.iter().find(|l| l.shadows == sh));
            let vs = match (vs, light) {
                (Some(v), Some(l)) => Some(v.with_light_volume(l)),
                (v, _) => v,
            };
            let setup = pl.frame_setup(key.mode).map_err(BenchError::Pipeline)?;
            let mut renderer = Renderer::new(&key, setup, geo, vs.as_ref())?;
            let pool = match self.pools.entry(key.threads) {
                std::collections::btree_map::Entry::Occupied(e) => e.into_mut(),
                std::collections::btree_map::Entry::Vacant(e) => e.insert(
                    rayon::ThreadPoolBuilder::new()
                        .num_threads(key.threads as usize)
                        .build()
                        .map_err(BenchError::ThreadPool)?,
                ),
            };
            for &isa in self.isas {
                let (warmup, frames) = (self.cfg.warmup, self.frames);
                let ms = pool.install(|| {
                    for _ in 0..warmup {
                        renderer.frame(&camera, isa);
                    }
                    (0..frames)
                        .map(|_| renderer.frame(&camera, isa))
                        .collect::<Vec<f64>>()
                });
                let load1 = load_avg()[0];
                let m = Measurement {
                    key,
                    tables,
                    atoms: p.atoms,
                    isa,
                    ms,
                    load1,
                };
                self.done += 1;
                eprintln!(
                    "[{}/{}] {} {} {} {}x{} {}t {}: {:.1} ms median ({:.2} fps, {:.1} Mrays/s), load {:.2}",
                    self.done,
                    self.total,
                    scene,
                    key.mode.name(),
                    key.view(),
                    key.w,
                    key.h,
                    key.threads,
                    isa,
                    m.ms_median(),
                    m.fps(),
                    m.mrays(),
                    load1
                );
                out.push(m);
            }
        }
        Ok((p, out))
    }
}
