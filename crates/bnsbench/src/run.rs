//! A whole run: check the request, measure scene after scene (writing the JSON after each),
//! print the report; or report earlier runs from their JSON.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use molecule::scenes::SceneName;
use render::Framebuffer;
use scene::ModelSettings;
use spmd::Isa;
use volume::TransferFunction;

use crate::error::{chain, BenchError};
use crate::json::{document, read_report, write_json, RunInfo};
use crate::measure::Session;
use crate::plan::{plan, sidx, Key, PlanSpec, Tables};
use crate::probe::{cpu_model, load_avg, nproc};
use crate::record::{Measurement, Preprocess};
use crate::report::report;

/// Everything a run needs besides the ISAs.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// What to measure.
    pub spec: PlanSpec,
    /// Seed of the scene generators.
    pub seed: u64,
    /// How the balls and sticks are drawn (`wide_bvh` is ignored: the modes' traversals
    /// build what they need).
    pub model: ModelSettings,
    /// Transfer function of the volume modes.
    pub tf: TransferFunction,
    /// Timed frames per measurement, after the warm-up (default 10, quick 3).
    pub frames: Option<usize>,
    /// Warm-up frames before timing.
    pub warmup: usize,
    /// Density resolution (voxels per Å) for every scene, instead of the paper's.
    pub voxels_per_angstrom: Option<f32>,
    /// March every cell (no macrocell skipping).
    pub no_macrocells: bool,
    /// Write every measurement to this JSON file.
    pub json: Option<PathBuf>,
    /// Overwrite the JSON file if it exists.
    pub force: bool,
    /// The command line, for the JSON.
    pub command: String,
    /// bnsview's version, for the JSON.
    pub version: String,
}

/// Checks that the JSON output may be written.
fn check_json_path(cfg: &Config) -> Result<(), BenchError> {
    let Some(p) = &cfg.json else {
        return Ok(());
    };
    if p.exists() && !cfg.force {
        return Err(BenchError::Exists(p.clone()));
    }
    if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            return Err(BenchError::NoDirectory {
                file: p.clone(),
                dir: dir.to_path_buf(),
            });
        }
    }
    Ok(())
}

/// Runs the benchmark of `cfg` on the backends `isas`; prints
/// progress to stderr and the report to stdout. Scenes that fail are reported at the end
/// ([`BenchError::ScenesFailed`]) after the others were measured.
pub fn run(cfg: &Config, isas: &[Isa]) -> Result<(), BenchError> {
    if isas.is_empty() {
        return Err(BenchError::NoIsa);
    }
    check_json_path(cfg)?;
    let frames = cfg.frames.unwrap_or(if cfg.spec.quick { 3 } else { 10 });
    if frames == 0 {
        return Err(BenchError::NoFrames);
    }
    let nproc = nproc();
    let plan = plan(&cfg.spec, nproc);
    if plan.is_empty() {
        return Err(BenchError::NothingToMeasure(cfg.spec.table));
    }
    // Frame buffers are allocated per measurement; check the largest fits first.
    for (k, _) in &plan {
        Framebuffer::new(k.w, k.h, 0).map_err(|e| BenchError::Frame(k.w, k.h, e))?;
    }
    let total = plan.len() * isas.len();
    let started = Instant::now();
    let load_start = load_avg();
    eprintln!(
        "bench: {} measurements ({} ISA{}: {}), {frames} frames after {} warm-up, {} cores, load {:.2}",
        total,
        isas.len(),
        if isas.len() == 1 { "" } else { "s" },
        isas.iter().map(|i| i.name()).collect::<Vec<_>>().join(","),
        cfg.warmup,
        nproc,
        load_start[0]
    );

    let mut pre: Vec<Preprocess> = Vec::new();
    let mut meas: Vec<Measurement> = Vec::new();
    let mut failures: Vec<String> = Vec::new();
    let doc = |pre: &[Preprocess], meas: &[Measurement], finished: bool| {
        let info = RunInfo {
            version: cfg.version.clone(),
            command: cfg.command.clone(),
            cpu: cpu_model(),
            cores: nproc,
            isas: isas.to_vec(),
            load_start,
            load_end: load_avg(),
            wall_s: started.elapsed().as_secs_f64(),
            finished,
        };
        document(&info, pre, meas)
    };
    let mut session = Session {
        cfg,
        isas,
        frames,
        pools: BTreeMap::new(),
        done: 0,
        total,
    };
    let mut scenes: Vec<SceneName> = plan.iter().map(|(k, _)| k.scene).collect();
    scenes.dedup();
    for scene in scenes {
        let keys: Vec<(Key, Tables)> = plan
            .iter()
            .filter(|(k, _)| k.scene == scene)
            .copied()
            .collect();
        match session.scene(scene, &keys) {
            Ok((p, m)) => {
                pre.push(p);
                meas.extend(m);
            }
            Err(e) => {
                let e = chain(&e);
                eprintln!("bench: {scene}: error: {e}");
                failures.push(format!("{scene}: {e}"));
            }
        }
        if let Some(p) = &cfg.json {
            write_json(p, &doc(&pre, &meas, false))?;
        }
    }
    let wall = started.elapsed().as_secs_f64();
    if let Some(p) = &cfg.json {
        write_json(p, &doc(&pre, &meas, failures.is_empty()))?;
    }

    let mut out = String::new();
    let loads = (load_start, load_avg());
    report(&mut out, &pre, &meas, isas, nproc, loads, wall);
    print!("{out}");
    if let Some(p) = &cfg.json {
        eprintln!(
            "bench: wrote {} ({} records)",
            p.display(),
            pre.len() + meas.len()
        );
    }
    if !failures.is_empty() {
        return Err(BenchError::ScenesFailed {
            count: failures.len(),
            list: failures.join("; "),
        });
    }
    Ok(())
}

/// `bnsview bench --report FILE...`: prints the tables of earlier runs, merged (a later
/// file's record of the same measurement wins).
pub fn run_report(files: &[PathBuf]) -> Result<(), BenchError> {
    let mut pre: Vec<Preprocess> = Vec::new();
    let mut meas: Vec<Measurement> = Vec::new();
    let mut load = ([f64::NAN; 3], [f64::NAN; 3]);
    let mut wall = 0.0;
    for (i, f) in files.iter().enumerate() {
        let earlier = read_report(f)?;
        if i == 0 {
            load.0 = earlier.load.0;
        }
        load.1 = earlier.load.1;
        for mut q in earlier.pre {
            // A later run of the same scene wins, but keeps what only the earlier one built
            // (e.g. a volume-only run has no BVH figures).
            if let Some(i) = pre.iter().position(|x| x.scene == q.scene) {
                let old = pre.remove(i);
                q.bvh_s = q.bvh_s.or(old.bvh_s);
                q.volume_s = q.volume_s.or(old.volume_s);
                q.geometry_bytes = q.geometry_bytes.or(old.geometry_bytes);
                q.bvh_bytes = q.bvh_bytes.or(old.bvh_bytes);
                q.volume_bytes = q.volume_bytes.or(old.volume_bytes);
            }
            pre.push(q);
        }
        for mut q in earlier.meas {
            // The same measurement in a later file wins and belongs to both files' tables.
            if let Some(i) = meas.iter().position(|x| x.key == q.key && x.isa == q.isa) {
                q.tables |= meas.remove(i).tables;
            }
            meas.push(q);
        }
        wall += earlier.wall_s;
    }
    pre.sort_by_key(|p| sidx(p.scene));
    let mut isas: Vec<Isa> = meas.iter().map(|m| m.isa).collect();
    isas.sort();
    isas.dedup();
    let mut out = format!(
        "Report of {}",
        files
            .iter()
            .map(|f| f.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    report(&mut out, &pre, &meas, &isas, nproc(), load, wall);
    print!("{out}");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mode::TableSel;

    fn config() -> Config {
        Config {
            spec: PlanSpec {
                scenes: Some(vec![SceneName::Nanobowl]),
                table: TableSel::T3,
                ..PlanSpec::default()
            },
            seed: 1,
            model: ModelSettings::default(),
            tf: TransferFunction::preset(volume::Preset::CoolWarm),
            frames: None,
            warmup: 0,
            voxels_per_angstrom: None,
            no_macrocells: false,
            json: None,
            force: false,
            command: "test".into(),
            version: "0".into(),
        }
    }

    #[test]
    fn bad_requests_are_refused_before_any_work() {
        let isa = [Isa::Scalar];
        let err = |c: &Config, isas: &[Isa]| run(c, isas).unwrap_err();
        assert!(matches!(err(&config(), &[]), BenchError::NoIsa));
        let c = Config {
            frames: Some(0),
            ..config()
        };
        assert!(matches!(err(&c, &isa), BenchError::NoFrames));
        let mut c = config();
        c.spec.table = TableSel::T1;
        c.spec.scenes = Some(vec![]);
        assert!(matches!(err(&c, &isa), BenchError::NothingToMeasure(_)));
        let existing = std::env::temp_dir().join(format!("bnsbench-{}.json", std::process::id()));
        std::fs::write(&existing, "{}").unwrap();
        let c = Config {
            json: Some(existing.clone()),
            ..config()
        };
        let e = err(&c, &isa);
        assert!(matches!(e, BenchError::Exists(_)), "{e}");
        assert!(e
            .to_string()
            .ends_with("exists; pass --force to overwrite it"));
        let _ = std::fs::remove_file(&existing);
        let c = Config {
            json: Some(existing.join("no-such-dir").join("x.json")),
            ..config()
        };
        assert!(matches!(err(&c, &isa), BenchError::NoDirectory { .. }));
    }

    #[test]
    fn a_report_of_no_file_is_empty_and_of_a_missing_file_an_error() {
        assert!(run_report(&[]).is_ok());
        let e = run_report(&[PathBuf::from("/nonexistent/bench.json")]).unwrap_err();
        assert!(matches!(e, BenchError::Read(..)), "{e}");
    }
}
