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

/// A fresh directory for one test's files.
fn scratch(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("bnsview-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn render_writes_a_png_of_the_scene_and_never_overwrites_unasked() {
    let d = scratch("render");
    let out = d.join("bowl.png");
    let args = [
        "render", "--scene", "nanobowl", "--atoms", "3000", "--size", "96x64", "-o",
    ];
    let (ok, _, err) = run(bnsview().args(args).arg(&out));
    assert!(ok, "{err}");
    let img = image::open(&out).expect("a PNG").to_rgba8();
    assert_eq!(img.dimensions(), (96, 64));
    // The far view frames the molecule: background at the corners, geometry at the centre.
    assert_eq!(img.get_pixel(0, 0).0, [255, 255, 255, 255]);
    let drawn = img.pixels().filter(|p| p.0 != [255, 255, 255, 255]).count();
    assert!(
        drawn > 96 * 64 / 10,
        "only {drawn} pixels show the molecule"
    );
    let before = std::fs::read(&out).unwrap();
    let (ok, _, err) = run(bnsview().args(args).arg(&out).args(["--mode", "volume"]));
    assert!(!ok && err.contains("--force"), "{err}");
    assert_eq!(
        std::fs::read(&out).unwrap(),
        before,
        "the existing file was changed"
    );
    let (ok, _, err) = run(bnsview()
        .args(args)
        .arg(&out)
        .args(["--mode", "vol+bs", "--force"]));
    assert!(ok, "{err}");
    assert_ne!(std::fs::read(&out).unwrap(), before);
}

#[test]
fn the_output_format_follows_the_extension_and_threads_are_capped() {
    let d = scratch("formats");
    let args = [
        "render", "--scene", "nanobowl", "--atoms", "2000", "--size", "64x48", "-o",
    ];
    let (png, jpg) = (d.join("a.png"), d.join("a.JPG"));
    for out in [&png, &jpg] {
        let (ok, _, err) = run(bnsview().args(args).arg(out));
        assert!(ok, "{err}");
    }
    // A JPEG (its magic number, read back by the decoder) of the PNG's picture.
    assert_eq!(std::fs::read(&jpg).unwrap()[..3], [0xFF, 0xD8, 0xFF]);
    let a = image::open(&png).unwrap().to_rgb8();
    let b = image::open(&jpg).unwrap().to_rgb8();
    assert_eq!(b.dimensions(), (64, 48));
    let diff: f64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| (*x as f64 - *y as f64).abs())
        .sum::<f64>()
        / a.as_raw().len() as f64;
    assert!(diff < 6.0, "mean difference {diff} from the PNG");
    // Any other extension is refused before the work, and nothing is written.
    let bmp = d.join("a.bmp");
    let (ok, _, err) = run(bnsview().args(args).arg(&bmp));
    assert!(
        !ok && err.contains("unknown image format") && err.contains(".jpg"),
        "{err}"
    );
    assert!(!bmp.exists());
    // Threads beyond 16 per core (a million would start a million) and zero are refused.
    for n in ["1000000", "0"] {
        let (ok, _, err) = run(bnsview()
            .args(args)
            .arg(d.join("t.png"))
            .args(["--threads", n]));
        assert!(
            !ok && err.contains(&format!("--threads {n}: use 1 to")),
            "{err}"
        );
    }
    assert!(!d.join("t.png").exists());
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn render_reports_bad_input_with_file_and_line() {
    let d = scratch("bad");
    let f = d.join("broken.xyz");
    std::fs::write(&f, "3\ncomment\nC 0 0 0\nO 1.2 nope 0\nH 0 1 0\n").unwrap();
    let (ok, _, err) = run(bnsview()
        .arg("render")
        .arg(&f)
        .arg("-o")
        .arg(d.join("x.png")));
    assert!(!ok);
    assert!(
        err.contains("broken.xyz:4:") && err.contains("expected a number"),
        "{err}"
    );
    assert!(!d.join("x.png").exists());
    let (ok, _, err) = run(bnsview().args(["render", "--size", "0x10"]));
    assert!(!ok && err.contains("positive"), "{err}");
    let (ok, _, err) = run(bnsview()
        .args(["render", "--camera", "eye=0,0,0:at=0,0,0", "-o"])
        .arg(d.join("y.png")));
    assert!(!ok && err.contains("same point"), "{err}");
}

/// Each ray tracing modality renders a PNG; unavailable or meaningless combinations are
/// refused with a message saying what is available.
#[test]
fn render_modalities_write_pngs_and_refuse_what_is_missing() {
    let dir = std::env::temp_dir().join(format!("bnsview-modal-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let vol = ["--voxels-per-angstrom", "1"];
    let cases: [&[&str]; 11] = [
        &["--shadows"],
        &["--ao", "2", "--secondary", "wide"],
        &[
            "--mode",
            "path",
            "--spp",
            "1",
            "--material",
            "diffuse",
            "--bounce-traversal",
            "packet",
            "--secondary",
            "single",
        ],
        &["--shadows", "--light-pos", "-5,40,0"],
        &["--ao", "2"],
        &["--mode", "path", "--spp", "2", "--material", "metal"],
        &["--mode", "path", "--spp", "1", "--material", "diffuse"],
        &[
            "--mode",
            "vol+bs",
            "--shadows",
            "--volume-shadows",
            vol[0],
            vol[1],
        ],
        &["--mode", "volume", "--volume-shadows", vol[0], vol[1]],
        &[
            "--mode",
            "volume",
            "--lit",
            "--volume-shadows",
            "--light-pos",
            "5,30,5",
            vol[0],
            vol[1],
        ],
        &[
            "--mode",
            "volume",
            "--volume-shadows",
            "--shadow-rays",
            vol[0],
            vol[1],
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
            "vol+bs",
            "--volume-shadows",
            "-o",
        ])
        .arg(dir.join("x.png")));
    assert!(!ok && err.contains("needs --shadows"), "{err}");
    let (ok, _, err) = run(bnsview()
        .args([
            "render",
            "--light-dir",
            "1,0,0",
            "--light-pos",
            "0,0,0",
            "-o",
        ])
        .arg(dir.join("x.png")));
    assert!(!ok && err.contains("cannot be used with"), "{err}");
    assert!(!dir.join("x.png").exists());
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
    assert!(
        !ok && err.contains("'--shadows' cannot be used with '--ao"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
