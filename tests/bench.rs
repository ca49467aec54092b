//! `bnsview bench` on tiny configurations: the JSON it writes is complete and consistent with
//! what was asked for. No timing assertions.

mod common;

use std::path::PathBuf;
use std::process::Command;

use common::bnsview;
use serde_json::Value;

fn tmp(name: &str) -> PathBuf {
    let p = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("bench-{}-{name}.json", std::process::id()));
    let _ = std::fs::remove_file(&p);
    p
}

/// `bnsview bench --scenes nanobowl --atoms ATOMS --frames FRAMES`.
fn nanobowl_bench(atoms: &str, frames: &str) -> Command {
    let mut c = bnsview();
    c.args(["bench", "--scenes", "nanobowl", "--atoms", atoms])
        .args(["--frames", frames]);
    c
}

fn run_ok(c: &mut Command) -> (String, String) {
    let out = c.output().expect("run bnsview");
    let (so, se) = (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    );
    assert!(out.status.success(), "bench failed:\n{so}\n{se}");
    (so, se)
}

const FRAME_FIELDS: [&str; 13] = [
    "scene",
    "atoms",
    "mode",
    "view",
    "width",
    "height",
    "isa",
    "threads",
    "frames",
    "fps_median",
    "ms_median",
    "ms_min",
    "ms_max",
];

const PRE_FIELDS: [&str; 11] = [
    "scene",
    "atoms",
    "bonds",
    "load_s",
    "bond_s",
    "bvh_s",
    "volume_s",
    "geometry_mb",
    "bvh_mb",
    "volume_mb",
    "peak_rss_mb",
];

fn records(path: &PathBuf) -> Vec<Value> {
    let text = std::fs::read_to_string(path).expect("json written");
    let doc: Value = serde_json::from_str(&text).expect("valid JSON");
    assert_eq!(doc["finished"], Value::Bool(true));
    doc["records"].as_array().expect("records array").clone()
}

fn check_frame(r: &Value) {
    for f in FRAME_FIELDS {
        assert!(r.get(f).is_some_and(|v| !v.is_null()), "{f} missing in {r}");
    }
    let (min, med, max) = (
        r["ms_min"].as_f64().unwrap(),
        r["ms_median"].as_f64().unwrap(),
        r["ms_max"].as_f64().unwrap(),
    );
    assert!(0.0 < min && min <= med && med <= max, "{r}");
    let fps = r["fps_median"].as_f64().unwrap();
    assert!((fps * med - 1000.0).abs() < 1e-6 * 1000.0, "{r}");
}

#[test]
fn tiny_table3_run_writes_a_record_per_measurement() {
    let json = tmp("t3");
    let (stdout, _) = run_ok(
        nanobowl_bench("2000", "2")
            .args(["--size", "64x64", "--threads", "1", "--json"])
            .arg(&json),
    );
    let recs = records(&json);
    let pre: Vec<&Value> = recs.iter().filter(|r| r["kind"] == "preprocess").collect();
    let frames: Vec<&Value> = recs.iter().filter(|r| r["kind"] == "frame").collect();
    assert_eq!(pre.len(), 1);
    for f in PRE_FIELDS {
        assert!(
            pre[0].get(f).is_some_and(|v| !v.is_null()),
            "{f} missing in {}",
            pre[0]
        );
    }
    assert_eq!(pre[0]["scene"], "nanobowl");
    let atoms = pre[0]["atoms"].as_u64().unwrap();
    assert!((1900..=2100).contains(&atoms), "{atoms}");
    assert!(pre[0]["bonds"].as_u64().unwrap() > atoms);
    assert!(pre[0]["volume_mb"].as_f64().unwrap() > 0.0);
    // 4 modes × 2 views on the selected ISA.
    assert_eq!(frames.len(), 8, "{recs:?}");
    let mut seen = Vec::new();
    for r in &frames {
        check_frame(r);
        assert_eq!(r["scene"], "nanobowl");
        assert_eq!(r["atoms"].as_u64(), Some(atoms));
        assert_eq!(
            (r["width"].as_u64(), r["height"].as_u64()),
            (Some(64), Some(64))
        );
        assert_eq!(r["threads"].as_u64(), Some(1));
        assert_eq!(r["frames"].as_u64(), Some(2));
        seen.push(format!(
            "{} {}",
            r["mode"].as_str().unwrap(),
            r["view"].as_str().unwrap()
        ));
    }
    seen.sort();
    assert_eq!(
        seen,
        [
            "bs close",
            "bs far",
            "vol+bs close",
            "vol+bs far",
            "vol+bs-lit close",
            "vol+bs-lit far",
            "volume close",
            "volume far"
        ]
    );
    assert!(stdout.contains("Table 3"), "{stdout}");
    // The paper's nanobowl b&s figures are printed beside ours.
    assert!(stdout.contains("63.0 / 55.0"), "{stdout}");

    // --report prints the same tables again from the file.
    let (again, _) = run_ok(bnsview().args(["bench", "--report"]).arg(&json));
    let table3 = |s: &str| -> Vec<String> {
        s.lines()
            .filter(|l| l.starts_with("| nanobowl | ") && l.contains(" / "))
            .map(String::from)
            .collect()
    };
    assert_eq!(table3(&again), table3(&stdout));
    assert_eq!(table3(&again).len(), 4);

    // An existing file is not overwritten without --force.
    let out = bnsview()
        .args([
            "bench", "--scenes", "nanobowl", "--atoms", "500", "--frames", "1",
        ])
        .args([
            "--size", "16x16", "--modes", "bs", "--views", "far", "--json",
        ])
        .arg(&json)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--force"));
    assert_eq!(records(&json).len(), 9, "the old file is intact");
    let _ = std::fs::remove_file(&json);
}

#[test]
fn every_isa_and_tables_one_and_two() {
    let json = tmp("isa-all");
    let (stdout, _) = run_ok(
        bnsview()
            .args([
                "--isa",
                "all",
                "bench",
                "--table",
                "1",
                "--scenes",
                "nanobowl",
                "--atoms",
                "1000",
                "--frames",
                "1",
                "--sizes",
                "16,32",
                "--threads",
                "1,2",
                "--json",
            ])
            .arg(&json),
    );
    let recs = records(&json);
    let frames: Vec<&Value> = recs.iter().filter(|r| r["kind"] == "frame").collect();
    let isas = spmd::Isa::supported();
    assert_eq!(frames.len(), 2 * 2 * isas.len());
    for r in &frames {
        check_frame(r);
        assert_eq!(r["mode"], "volume");
        assert_eq!(r["view"], "far");
    }
    for isa in &isas {
        assert!(frames.iter().any(|r| r["isa"] == isa.name()), "{isa}");
    }
    // Volume only: no BVH was built, and the record says so with nulls.
    let pre = recs.iter().find(|r| r["kind"] == "preprocess").unwrap();
    assert!(
        pre["bvh_s"].is_null() && !pre["volume_s"].is_null(),
        "{pre}"
    );
    assert!(stdout.contains("Table 1"), "{stdout}");
    if isas.len() > 1 {
        assert!(stdout.contains("fps per ISA"), "{stdout}");
    }
    let _ = std::fs::remove_file(&json);

    let json = tmp("t2");
    let (stdout, _) = run_ok(
        bnsview()
            .args([
                "bench", "--table", "2", "--scenes", "nanobowl", "--atoms", "1000", "--frames",
                "1", "--size", "32x16", "--json",
            ])
            .arg(&json),
    );
    let frames: Vec<Value> = records(&json)
        .into_iter()
        .filter(|r| r["kind"] == "frame")
        .collect();
    let nproc = std::thread::available_parallelism().unwrap().get() as u64;
    let threads: Vec<u64> = frames
        .iter()
        .map(|r| r["threads"].as_u64().unwrap())
        .collect();
    assert_eq!(threads, (1..=nproc).collect::<Vec<_>>());
    assert!(stdout.contains("Table 2"), "{stdout}");
    let _ = std::fs::remove_file(&json);
}

#[test]
fn modality_modes_write_records_and_the_figure_4_table() {
    let json = tmp("modal");
    let modes = ["bs-shadows", "bs-ao", "path", "vol+bs-shadows"];
    let (stdout, _) = run_ok(
        nanobowl_bench("1000", "2")
            .args([
                "--size",
                "48x32",
                "--threads",
                "1",
                "--views",
                "far",
                "--modes",
            ])
            .arg(modes.join(","))
            .arg("--json")
            .arg(&json),
    );
    let frames: Vec<Value> = records(&json)
        .into_iter()
        .filter(|r| r["kind"] == "frame")
        .collect();
    let seen: Vec<&str> = frames.iter().map(|r| r["mode"].as_str().unwrap()).collect();
    assert_eq!(seen, modes, "{frames:?}");
    for r in &frames {
        check_frame(r);
        assert!(r["fps_median"].as_f64().unwrap() > 0.0, "{r}");
        assert_eq!(r["frames"].as_u64(), Some(2));
        assert_eq!(
            (r["width"].as_u64(), r["height"].as_u64()),
            (Some(48), Some(32))
        );
        // AO and path tracing time one sample per pixel per frame.
        let spp = r["samples_per_pixel"].as_u64();
        match r["mode"].as_str().unwrap() {
            "bs-ao" | "path" => assert_eq!(spp, Some(1), "{r}"),
            _ => assert!(r["samples_per_pixel"].is_null(), "{r}"),
        }
    }
    // Table 3 has a row per mode (no paper figure); the paper's Figure 4 is printed beside ours.
    for m in modes {
        let row = stdout
            .lines()
            .find(|l| l.starts_with("| nanobowl | ") && l.contains(&format!(" | {m} | ")));
        let cells: Vec<&str> = row.expect(m).split('|').map(str::trim).collect();
        assert_eq!(cells[5], "- / -", "{m}: no paper figure in Table 3");
    }
    assert!(stdout.contains("Figure 4"), "{stdout}");
    assert!(
        stdout.contains(
            "| ball-and-stick with diffuse illumination and shadows | 58.0 | bs-shadows |"
        ),
        "{stdout}"
    );
    // --report reads the new modes back.
    let (again, _) = run_ok(bnsview().args(["bench", "--report"]).arg(&json));
    assert!(
        again.contains("| path traced with a metal BRDF | 0.250 | path |"),
        "{again}"
    );
    let _ = std::fs::remove_file(&json);
}

#[test]
fn isa_all_is_refused_outside_bench() {
    let out = bnsview()
        .args(["--isa", "all", "--version"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("only for `bnsview bench`"));
}
