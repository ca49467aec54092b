//! The CLI's ISA handling, run as a user would.

use std::process::Command;

fn bnsview() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_bnsview"));
    c.env_remove("BNS_ISA").env_remove("BNS_CPU_LIMIT");
    c
}

fn run(c: &mut Command) -> (bool, String, String) {
    let out = c.output().expect("run bnsview");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn version_reports_the_forced_isa() {
    for isa in spmd::Isa::supported() {
        let (ok, out, _) = run(bnsview().env("BNS_ISA", isa.name()).arg("--version"));
        assert!(ok);
        assert!(out.contains(&format!("isa: {},", isa.name())), "{out}");
        let (ok, out, _) = run(bnsview().args(["--isa", isa.name(), "--version"]));
        assert!(ok);
        assert!(out.contains(&format!("isa: {},", isa.name())), "{out}");
    }
}

#[test]
fn isa_lists_every_backend_and_marks_the_selected_one() {
    let (ok, out, _) = run(bnsview().arg("isa"));
    assert!(ok);
    for isa in spmd::Isa::ALL {
        let line = out
            .lines()
            .find(|l| l.starts_with(isa.name()))
            .unwrap_or_else(|| panic!("no line for {isa}: {out}"));
        assert_eq!(line.contains(" yes"), isa.is_supported(), "{line}");
        assert_eq!(
            line.trim_end().ends_with('*'),
            isa == spmd::Isa::detect(),
            "{line}"
        );
    }
}

#[test]
fn unsupported_or_unknown_isa_is_a_clear_error() {
    // BNS_CPU_LIMIT makes this machine pretend to stop at AVX2.
    let (ok, _, err) =
        run(bnsview()
            .env("BNS_CPU_LIMIT", "avx2")
            .args(["--isa", "avx512", "--version"]));
    assert!(!ok);
    assert!(err.contains("does not support avx512"), "{err}");
    let (ok, _, err) = run(bnsview()
        .env("BNS_CPU_LIMIT", "sse4.1")
        .env("BNS_ISA", "avx2")
        .arg("isa"));
    assert!(!ok);
    assert!(
        err.contains("BNS_ISA") && err.contains("does not support avx2"),
        "{err}"
    );
    let (ok, _, err) = run(bnsview().args(["--isa", "avx1024", "isa"]));
    assert!(!ok);
    assert!(err.contains("unknown ISA"), "{err}");
    // Without the override the widest is chosen, and with the cap it falls back.
    let (ok, out, _) = run(bnsview().env("BNS_CPU_LIMIT", "sse4.1").arg("--version"));
    assert!(ok);
    assert!(
        out.contains("isa: sse4.1,") || !spmd::Isa::Sse41.is_supported(),
        "{out}"
    );
}

/// Each ray tracing modality renders a PNG; unavailable or meaningless combinations are
/// refused with a message saying what is available.
#[test]
fn render_modalities_write_pngs_and_refuse_what_is_missing() {
    let dir = std::env::temp_dir().join(format!("bnsview-modal-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases: [&[&str]; 5] = [
        &["--shadows"],
        &["--ao", "2"],
        &["--mode", "path", "--spp", "2", "--material", "metal"],
        &["--mode", "path", "--spp", "1", "--material", "diffuse"],
        &[
            "--mode",
            "vol+bs",
            "--shadows",
            "--volume-shadows",
            "--voxels-per-angstrom",
            "1",
        ],
    ];
    for (i, extra) in cases.iter().enumerate() {
        let out = dir.join(format!("m{i}.png"));
        let (ok, _, err) = run(bnsview()
            .args([
                "render", "--scene", "nanobowl", "--atoms", "2000", "--size", "48x40", "-f",
            ])
            .args(*extra)
            .arg("-o")
            .arg(&out));
        assert!(ok, "{extra:?}: {err}");
        assert!(out.exists(), "{extra:?}");
    }
    let (ok, _, err) = run(bnsview()
        .args([
            "render",
            "--scene",
            "nanobowl",
            "--atoms",
            "2000",
            "--mode",
            "volume",
            "--volume-shadows",
            "-o",
        ])
        .arg(dir.join("x.png")));
    assert!(!ok && err.contains("not available"), "{err}");
    let (ok, _, err) = run(bnsview()
        .args([
            "render",
            "--scene",
            "nanobowl",
            "--shadows",
            "--ao",
            "4",
            "-o",
        ])
        .arg(dir.join("y.png")));
    assert!(!ok && err.contains("choose one"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
