//! The JSON document of a run: writing it (atomically) and reading earlier runs back.

use std::path::{Path, PathBuf};

use molecule::scenes::SceneName;
use serde_json::{json, Value};
use spmd::Isa;

use crate::error::BenchError;
use crate::mode::BenchMode;
use crate::plan::{Key, Tables};
use crate::record::{mb, Measurement, Preprocess};

/// The record of a measurement.
pub fn measurement_json(m: &Measurement) -> Value {
    let v = m.sorted();
    json!({
        "kind": "frame",
        "tables": m.tables.list(),
        "scene": m.key.scene.to_string(),
        "atoms": m.atoms,
        "mode": m.key.mode.name(),
        "samples_per_pixel": m.key.mode.samples_per_pixel(),
        "view": m.key.view(),
        "width": m.key.w,
        "height": m.key.h,
        "isa": m.isa.name(),
        "threads": m.key.threads,
        "frames": m.ms.len(),
        "fps_median": m.fps(),
        "ms_median": m.ms_median(),
        "ms_min": v.first().copied().unwrap_or(f64::NAN),
        "ms_max": v.last().copied().unwrap_or(f64::NAN),
        "mrays_per_s": m.mrays(),
        "ms_all": m.ms,
        "load_avg_1min": m.load1,
    })
}

/// The record of a scene's preprocessing.
pub fn preprocess_json(p: &Preprocess) -> Value {
    json!({
        "kind": "preprocess",
        "scene": p.scene.to_string(),
        "atoms": p.atoms,
        "bonds": p.bonds,
        "load_s": p.load_s,
        "bond_s": p.bond_s,
        "bvh_s": p.bvh_s,
        "volume_s": p.volume_s,
        "geometry_mb": p.geometry_bytes.map(mb),
        "bvh_mb": p.bvh_bytes.map(mb),
        "volume_mb": p.volume_bytes.map(mb),
        "bytes_per_atom": p.bytes_per_atom(),
        "voxels_per_angstrom": p.voxels_per_angstrom,
        "volume_dims": p.volume_dims,
        "peak_rss_mb": p.peak_rss_mb,
        "peak_rss_scope": if p.peak_rss_reset { "this scene" } else { "process so far" },
    })
}

/// What a run's document says about the run besides its records.
#[derive(Clone, Debug, PartialEq)]
pub struct RunInfo {
    /// Version of bnsview.
    pub version: String,
    /// The command line.
    pub command: String,
    /// CPU model.
    pub cpu: String,
    /// Cores.
    pub cores: u32,
    /// The ISAs measured.
    pub isas: Vec<Isa>,
    /// Load averages (1, 5, 15 min) at the start.
    pub load_start: [f64; 3],
    /// Load averages at the end (or now).
    pub load_end: [f64; 3],
    /// Wall time so far (s).
    pub wall_s: f64,
    /// Whether every scene was measured.
    pub finished: bool,
}

/// The whole document of a run.
pub fn document(info: &RunInfo, pre: &[Preprocess], meas: &[Measurement]) -> Value {
    let mut records: Vec<Value> = pre.iter().map(preprocess_json).collect();
    records.extend(meas.iter().map(measurement_json));
    json!({
        "bnsview": info.version,
        "command": info.command,
        "cpu": info.cpu,
        "cores": info.cores,
        "isas": info.isas.iter().map(|i| i.name()).collect::<Vec<_>>(),
        "load_avg_start": info.load_start,
        "load_avg_end": info.load_end,
        "wall_s": info.wall_s,
        "finished": info.finished,
        "records": records,
    })
}

/// Writes the JSON document (via a temporary file, so a reader never sees half of it).
pub fn write_json(path: &Path, doc: &Value) -> Result<(), BenchError> {
    let tmp = path.with_extension("json.tmp");
    let text = serde_json::to_string_pretty(doc).map_err(BenchError::Serialise)?;
    std::fs::write(&tmp, text + "\n").map_err(|e| BenchError::Write(tmp.clone(), e))?;
    std::fs::rename(&tmp, path).map_err(|e| BenchError::Write(path.to_path_buf(), e))
}

/// The records of an earlier run.
#[derive(Clone, Debug, Default)]
pub struct Earlier {
    /// Preprocessing records.
    pub pre: Vec<Preprocess>,
    /// Frame records.
    pub meas: Vec<Measurement>,
    /// Load averages at the start and at the end (NaN if absent).
    pub load: ([f64; 3], [f64; 3]),
    /// Wall time (s; NaN if absent).
    pub wall_s: f64,
}

/// Reads the records of an earlier run from its JSON file.
pub fn read_report(path: &Path) -> Result<Earlier, BenchError> {
    let text = std::fs::read_to_string(path).map_err(|e| BenchError::Read(path.into(), e))?;
    let doc: Value =
        serde_json::from_str(&text).map_err(|e| BenchError::NotJson(path.into(), e))?;
    read_document(path, &doc)
}

/// The records of the document `doc` read from `path`.
fn read_document(path: &Path, doc: &Value) -> Result<Earlier, BenchError> {
    let bad = |what: &'static str| BenchError::BadRecord {
        file: PathBuf::from(path),
        what,
    };
    let mut out = Earlier::default();
    for r in doc["records"]
        .as_array()
        .ok_or_else(|| bad("records array"))?
    {
        let scene: SceneName = r["scene"]
            .as_str()
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| bad("scene"))?;
        let num = |k: &str| r[k].as_f64();
        let bytes = |k: &str| num(k).map(|v| (v * 1e6).round() as u64);
        match r["kind"].as_str() {
            Some("preprocess") => out.pre.push(Preprocess {
                scene,
                atoms: num("atoms").ok_or_else(|| bad("atoms"))? as usize,
                bonds: num("bonds").unwrap_or(0.0) as usize,
                load_s: num("load_s").unwrap_or(f64::NAN),
                bond_s: num("bond_s").unwrap_or(f64::NAN),
                bvh_s: num("bvh_s"),
                volume_s: num("volume_s"),
                geometry_bytes: bytes("geometry_mb"),
                bvh_bytes: bytes("bvh_mb"),
                volume_bytes: bytes("volume_mb"),
                voxels_per_angstrom: num("voxels_per_angstrom").unwrap_or(f64::NAN) as f32,
                volume_dims: None,
                peak_rss_mb: num("peak_rss_mb"),
                peak_rss_reset: r["peak_rss_scope"] == "this scene",
            }),
            Some("frame") => {
                let mode: BenchMode = r["mode"]
                    .as_str()
                    .and_then(|m| m.parse().ok())
                    .ok_or_else(|| bad("mode"))?;
                let isa: Isa = r["isa"]
                    .as_str()
                    .and_then(|m| m.parse().ok())
                    .ok_or_else(|| bad("isa"))?;
                let mut tables = Tables::NONE;
                for t in r["tables"].as_array().into_iter().flatten() {
                    tables |= t.as_u64().map_or(Tables::NONE, Tables::number);
                }
                let ms: Vec<f64> = match r["ms_all"].as_array() {
                    Some(v) => v.iter().filter_map(Value::as_f64).collect(),
                    None => vec![num("ms_median").ok_or_else(|| bad("ms_median"))?],
                };
                let key = Key {
                    scene,
                    mode,
                    far: r["view"] == "far",
                    w: num("width").ok_or_else(|| bad("width"))? as u32,
                    h: num("height").ok_or_else(|| bad("height"))? as u32,
                    threads: num("threads").ok_or_else(|| bad("threads"))? as u32,
                };
                out.meas.push(Measurement {
                    key,
                    tables,
                    atoms: num("atoms").unwrap_or(0.0) as usize,
                    isa,
                    ms,
                    load1: num("load_avg_1min").unwrap_or(f64::NAN),
                });
            }
            _ => return Err(bad("kind")),
        }
    }
    let load =
        |k: &str| -> [f64; 3] { serde_json::from_value(doc[k].clone()).unwrap_or([f64::NAN; 3]) };
    out.load = (load("load_avg_start"), load("load_avg_end"));
    out.wall_s = doc["wall_s"].as_f64().unwrap_or(f64::NAN);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_read_back_as_written() {
        let m = Measurement {
            key: Key {
                scene: SceneName::Sio2,
                mode: BenchMode::VolBsLit,
                far: false,
                w: 64,
                h: 32,
                threads: 3,
            },
            tables: Tables::T3 | Tables::T1,
            atoms: 123,
            isa: Isa::Scalar,
            ms: vec![2.0, 1.0, 4.0],
            load1: 0.5,
        };
        let p = Preprocess {
            scene: SceneName::Sio2,
            atoms: 123,
            bonds: 45,
            load_s: 0.25,
            bond_s: 0.5,
            bvh_s: Some(0.125),
            volume_s: None,
            geometry_bytes: Some(2_000_000),
            bvh_bytes: Some(1_000_000),
            volume_bytes: None,
            voxels_per_angstrom: 1.0,
            volume_dims: None,
            peak_rss_mb: Some(12.5),
            peak_rss_reset: true,
        };
        let info = RunInfo {
            version: "0".into(),
            command: "bench".into(),
            cpu: "cpu".into(),
            cores: 2,
            isas: vec![Isa::Scalar],
            load_start: [1.0, 2.0, 3.0],
            load_end: [4.0, 5.0, 6.0],
            wall_s: 7.0,
            finished: true,
        };
        let doc = document(&info, std::slice::from_ref(&p), std::slice::from_ref(&m));
        let text = serde_json::to_string(&doc).unwrap();
        let back =
            read_document(Path::new("x.json"), &serde_json::from_str(&text).unwrap()).unwrap();
        assert_eq!(back.pre, [p]);
        assert_eq!(back.meas, [m]);
        assert_eq!(back.load, ([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]));
        assert_eq!(back.wall_s, 7.0);
        let broken = json!({"records": [{"kind": "frame", "scene": "sio2", "mode": "nope"}]});
        let e = read_document(Path::new("x.json"), &broken).unwrap_err();
        assert_eq!(e.to_string(), "x.json: record without a valid mode");
    }
}
