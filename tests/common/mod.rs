//! Shared by the CLI tests: the binary, run as a user would, sample files and scratch
//! directories.
#![allow(dead_code)] // each test binary uses a different part

use std::path::PathBuf;
use std::process::Command;

/// The `bnsview` binary with no ISA forced.
pub fn bnsview() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_bnsview"));
    c.env_remove("BNS_ISA").env_remove("BNS_CPU_LIMIT");
    c
}

/// Runs `c`: success, stdout, stderr.
pub fn run(c: &mut Command) -> (bool, String, String) {
    let out = c.output().expect("run bnsview");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fresh empty directory for one test.
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bnsview-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A sample file of `../shared/data`.
pub fn sample(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data")
        .join(name)
}

/// Runs `c` and checks it fails with every text of `wants` in its stderr and no panic;
/// returns the stderr.
pub fn refused(c: &mut Command, wants: &[&str]) -> String {
    let (ok, _, err) = run(c);
    assert!(!ok, "{c:?} succeeded: {err}");
    assert!(!err.contains("panicked"), "{c:?} panicked: {err}");
    for w in wants {
        assert!(err.contains(w), "{c:?}: no {w:?} in {err}");
    }
    err
}

/// Writes a generated nanobowl trajectory of `atoms` atoms and `frames` frames (seed 1) to
/// `out` with `bnsview generate`, as a user would; panics with its stderr if it fails.
pub fn generate_frames(out: &std::path::Path, atoms: usize, frames: usize) {
    let (ok, _, err) = run(bnsview()
        .args(["generate", "nanobowl", "--atoms", &atoms.to_string()])
        .args(["--frames", &frames.to_string(), "-o"])
        .arg(out));
    assert!(ok, "generate {}: {err}", out.display());
}
