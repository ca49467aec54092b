//! Running the measurements of one scene: preprocess it once with the scene crate, then time
//! the frames of every key and ISA through the render crate's one driver, with each mode's
//! [`BenchMode::settings`].

use std::collections::BTreeMap;
use std::time::Instant;

use molecule::scenes::{try_generate, SceneName};
use render::{render_frame, Camera, FrameInputs, Framebuffer, RenderSettings, View};
use scene::{ball_sphere, BondSettings, Model, Sphere, VolumeSettings, LIGHT_VOLUME_STRIDE};
use spmd::Isa;
use volume::{
    ClassifiedTf, EmptySpace, LightVolume, MarchOptions, Medium, VolumeFormat, VolumeScene,
};

use crate::error::BenchError;
use crate::mode::BenchMode;
use crate::paper::paper_voxels_per_angstrom;
use crate::plan::{Key, Tables};
use crate::probe::{load_avg, peak_rss_mb, reset_peak_rss};
use crate::record::{mb, model_bytes, Measurement, Preprocess};
use crate::run::Config;

/// Renders a mode's frame, again and again, as `bnsview render` renders it.
struct Renderer<'a> {
    inputs: FrameInputs<'a>,
    settings: RenderSettings,
    fb: Framebuffer,
}

impl<'a> Renderer<'a> {
    fn new(
        key: &Key,
        settings: RenderSettings,
        inputs: FrameInputs<'a>,
    ) -> Result<Renderer<'a>, BenchError> {
        settings
            .validate(inputs.model.is_some(), inputs.volume.is_some())
            .map_err(BenchError::Settings)?;
        let fb = Framebuffer::new(key.w, key.h, settings.background_packed())
            .map_err(|e| BenchError::Frame(key.w, key.h, e))?;
        Ok(Renderer {
            inputs,
            settings,
            fb,
        })
    }

    /// Renders one complete frame and returns its time in ms (a modality takes its samples
    /// from number 0 every frame, so every frame does the same work).
    fn frame(&mut self, isa: Isa) -> Result<f64, BenchError> {
        let t = Instant::now();
        render_frame(&self.inputs, &self.settings, &mut self.fb, isa)
            .map_err(BenchError::Settings)?;
        Ok(t.elapsed().as_secs_f64() * 1e3)
    }
}

/// The camera of a scene's `far` or `close` view: fitted to the ball-and-stick bounding
/// sphere for every mode, so all modes of a scene see the same frame, as in the paper's
/// Table 3.
pub fn camera_for(sphere: Sphere, far: bool, w: u32, h: u32) -> Camera {
    let view = if far { View::Far } else { View::Close };
    Camera::view(
        view,
        sphere.center,
        sphere.radius,
        45.0,
        w as f32 / h as f32,
    )
}

/// The state of a run across scenes: what to run it with, thread pools, progress.
pub(crate) struct Session<'a> {
    pub cfg: &'a Config,
    pub isas: &'a [Isa],
    pub frames: usize,
    pub pools: BTreeMap<u32, rayon::ThreadPool>,
    pub done: usize,
    pub total: usize,
}

/// A generated scene, its bonds and what building them took (s).
struct Generated {
    molecule: molecule::Molecule,
    bonds: Vec<[u32; 2]>,
    load_s: f64,
    bond_s: f64,
}

/// `atoms` atoms of `scene` and their bonds, as `bnsview render --scene` builds them.
fn generate(scene: SceneName, atoms: usize, seed: u64) -> Result<Generated, BenchError> {
    let t = Instant::now();
    let molecule = try_generate(scene, Some(atoms), seed).map_err(BenchError::Generate)?;
    let load_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let bonds = BondSettings::default()
        .build(&molecule)
        .map_err(BenchError::Scene)?;
    Ok(Generated {
        molecule,
        bonds,
        load_s,
        bond_s: t.elapsed().as_secs_f64(),
    })
}

impl Session<'_> {
    /// Preprocesses `scene` and measures its `keys` on every ISA.
    pub fn scene(
        &mut self,
        scene: SceneName,
        keys: &[(Key, Tables)],
    ) -> Result<(Preprocess, Vec<Measurement>), BenchError> {
        let cfg = self.cfg;
        let need_geometry = keys.iter().any(|(k, _)| k.mode.geometry());
        let need_volume = keys.iter().any(|(k, _)| k.mode.volume());
        let atoms = cfg.spec.scene_atoms(scene);
        let reset = reset_peak_rss();
        eprintln!("bench: {scene}: generating {atoms} atoms and bonds");
        let l = generate(scene, atoms, cfg.seed)?;
        let m = &l.molecule;
        eprintln!(
            "bench: {scene}: {} atoms, {} bonds (load {:.2} s, bonds {:.2} s)",
            m.len(),
            l.bonds.len(),
            l.load_s,
            l.bond_s
        );
        let build_isa = *self.isas.iter().max().expect("non-empty");
        let model: Option<Model> = if need_geometry {
            let s = cfg
                .model
                .build_model(m, &l.bonds)
                .map_err(BenchError::Scene)?;
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
        let vpa = cfg
            .voxels_per_angstrom
            .unwrap_or_else(|| paper_voxels_per_angstrom(scene));
        let vol = if need_volume {
            eprintln!("bench: {scene}: building the density volume at {vpa} voxels/Å");
            let settings = VolumeSettings {
                voxels_per_angstrom: vpa,
                format: VolumeFormat::U8,
                tf: cfg.tf.clone(),
                ..VolumeSettings::default()
            };
            let t = Instant::now();
            let (v, cells) = settings
                .build_density(build_isa, m)
                .map_err(BenchError::Scene)?;
            let secs = t.elapsed().as_secs_f64();
            eprintln!(
                "bench: {scene}: volume {secs:.2} s, {:?} voxels, {:.1} MB",
                v.grid.dims,
                mb(v.bytes())
            );
            let ctf = ClassifiedTf::new(&cfg.tf, 0.0, v.max_value, settings.step_voxels);
            let empty = EmptySpace::build(&cells, &ctf);
            Some((v, cells, secs, ctf, empty))
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
            volume_bytes: vol
                .as_ref()
                .map(|v| v.0.bytes() + v.1.bytes() + v.4.bytes()),
            voxels_per_angstrom: vpa,
            volume_dims: vol.as_ref().map(|v| v.0.grid.dims),
            peak_rss_mb: peak_rss_mb(),
            peak_rss_reset: reset,
        };

        // The marcher's view of the volume with a mode's options.
        let vscene = |mode: BenchMode| -> Option<VolumeScene<'_>> {
            let (v, cells, _, ctf, empty) = vol.as_ref().filter(|_| mode.volume())?;
            let opts = MarchOptions {
                macrocells: !cfg.no_macrocells,
                ..mode.settings().march
            };
            Some(VolumeScene::new(v, cells, ctf, opts).with_empty_space(empty))
        };
        // Every mode of a scene sees the same frame: the ball-and-stick sphere.
        let sphere = match &model {
            Some(s) => Sphere {
                center: s.center,
                radius: s.radius,
            },
            None => ball_sphere(m, &cfg.model),
        };
        let mut out = Vec::new();
        let mut lights: Vec<LightVolume> = Vec::new();
        for &(key, tables) in keys {
            let camera = camera_for(sphere, key.far, key.w, key.h);
            let vs = vscene(key.mode);
            // Volumetric shadows read a light volume built once per light and scene, as
            // `bnsview render` builds it once per picture (its build is preprocessing,
            // printed, not part of the frame time).
            let shadows = vs.as_ref().and_then(|v| v.opts.shadows);
            if let (Some(v), Some(sh)) = (&vs, shadows) {
                if !lights.iter().any(|l| l.shadows == sh) {
                    let t = Instant::now();
                    let lv = LightVolume::build(Isa::detect(), v, sh, LIGHT_VOLUME_STRIDE);
                    eprintln!(
                        "bench: {scene}: light volume {:.2} s, {:?} (every {LIGHT_VOLUME_STRIDE} voxels), {:.1} MB",
                        t.elapsed().as_secs_f64(),
                        lv.grid.dims,
                        mb(lv.bytes())
                    );
                    lights.push(lv);
                }
            }
            let light = shadows.and_then(|sh| lights.iter().find(|l| l.shadows == sh));
            let vs = match (vs, light) {
                (Some(v), Some(l)) => Some(v.with_light_volume(l)),
                (v, _) => v,
            }
            .map(Medium::Grid);
            let inputs = FrameInputs {
                model: model.as_ref().filter(|_| key.mode.geometry()),
                volume: vs.as_ref(),
                camera: &camera,
            };
            let mut renderer = Renderer::new(&key, key.mode.settings(), inputs)?;
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
                let (warmup, frames) = (cfg.warmup, self.frames);
                let ms = pool.install(|| {
                    for _ in 0..warmup {
                        renderer.frame(isa)?;
                    }
                    (0..frames)
                        .map(|_| renderer.frame(isa))
                        .collect::<Result<Vec<f64>, BenchError>>()
                })?;
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
