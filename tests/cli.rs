//! The CLI run as a user would: ISA handling, output files, cameras, memory, volumes,
//! modalities, bad input and help. Cells and colouring are in `tests/cell.rs`, frames of a
//! trajectory in `tests/frames.rs`.

mod common;

use common::{bnsview, run, scratch};

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
fn views_orbit_and_zoom_move_the_camera_and_v_prints_it_as_a_camera_spec() {
    let d = scratch("views");
    let args = [
        "render", "--scene", "nanobowl", "--atoms", "2000", "--size", "80x60", "-v", "-o",
    ];
    let render = |name: &str, extra: &[&str]| {
        let out = d.join(name);
        let (ok, _, err) = run(bnsview().args(args).arg(&out).args(extra));
        assert!(ok, "{err}");
        let spec = err
            .lines()
            .find_map(|l| l.strip_prefix("camera:  --camera "))
            .unwrap_or_else(|| panic!("no camera line in {err}"))
            .to_string();
        (std::fs::read(&out).unwrap(), spec)
    };
    let (front, _) = render("front.png", &["--view", "front"]);
    let (far, _) = render("far.png", &[]);
    assert_eq!(front, far, "front is the far view");
    let (side, spec) = render("side.png", &["--view", "side"]);
    assert_ne!(side, far);
    // The printed camera renders the same picture.
    let (again, spec2) = render("again.png", &["--camera", &spec]);
    assert_eq!(again, side, "--camera {spec}");
    assert_eq!(spec2, spec);
    // An orbit of 90° azimuth is the side view; zoom changes the picture.
    let (orbit, _) = render("orbit.png", &["--orbit", "90,0"]);
    assert_eq!(orbit, side);
    let (zoom, _) = render("zoom.png", &["--zoom", "2"]);
    assert_ne!(zoom, far);
    for bad in [["--orbit", "30,100"], ["--zoom", "0"], ["--orbit", "x"]] {
        let (ok, _, err) = run(bnsview().args(args).arg(d.join("bad.png")).args(bad));
        assert!(
            !ok && err.contains(bad[0]) && err.contains("expected"),
            "{err}"
        );
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn v_and_info_report_bytes_per_atom_of_records_and_nodes_and_the_build_rate() {
    let d = scratch("bytes-per-atom");
    let (ok, _, err) = run(bnsview()
        .args([
            "render", "--scene", "nanobowl", "--atoms", "2000", "--size", "40x30",
        ])
        .args(["-v", "-o"])
        .arg(d.join("a.png")));
    assert!(ok, "{err}");
    // bvh: T s  N prims, M nodes, SAH S, X MB (Y B/atom): records R + nodes K B/atom, P M prims/s
    let line = err
        .lines()
        .find(|l| l.starts_with("bvh:"))
        .expect("bvh line");
    let num = |after: &str| -> f64 {
        let rest = &line[line
            .find(after)
            .unwrap_or_else(|| panic!("{after} in {line}"))
            + after.len()..];
        rest.split(|c: char| c != '.' && !c.is_ascii_digit())
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let total = num("MB (");
    let (records, nodes) = (num("records "), num("+ nodes "));
    assert!(
        line.contains(&format!("({total:.1} B/atom): records")),
        "{line}"
    );
    assert!((records + nodes - total).abs() <= 0.11, "{line}");
    assert!(
        num("B/atom, ") > 0.0 && line.contains(" M prims/s"),
        "{line}"
    );
    // info: bytes per atom beside every component that grows with the atoms.
    let (ok, out, err) = run(bnsview().args(["info", "--scene", "nanobowl", "--atoms", "2000"]));
    assert!(ok, "{err}");
    for part in ["    geometry", "    bvh", "    atoms"] {
        let l = out.lines().find(|l| l.starts_with(part)).expect(part);
        assert!(l.ends_with(" B/atom)"), "{l}");
    }
    let fb = out
        .lines()
        .find(|l| l.starts_with("    framebuffer"))
        .unwrap();
    assert!(!fb.contains("B/atom"), "{fb}");
    std::fs::remove_dir_all(&d).ok();
}

/// The memory budget: a scene over it is refused before the build, saying how much it needs
/// and how to get by (`--memory-budget` among the ways out), and nothing is written; a budget
/// above the estimate renders. The estimate is `info`'s figure, independent of the render.
#[test]
fn memory_budget_refuses_with_the_way_out_and_allows_what_fits() {
    let d = scratch("memory-budget");
    let out = d.join("a.png");
    let render = |budget: &str| {
        run(bnsview()
            .args([
                "render", "--scene", "ns90k", "--atoms", "20000", "--size", "40x30",
            ])
            .args(["--memory-budget", budget, "-o"])
            .arg(&out))
    };
    let (ok, _, err) = render("1");
    assert!(!ok);
    assert!(err.contains("over the memory budget of 1 MB"), "{err}");
    assert!(err.contains("--memory-budget MB allows more"), "{err}");
    assert!(!out.exists(), "nothing written when refused");
    let (ok, _, err) = render("0");
    assert!(
        !ok && err.contains("--memory-budget"),
        "0 MB is refused by the parser: {err}"
    );
    let (ok, _, err) = render("100000");
    assert!(ok, "{err}");
    assert!(out.exists());
}

/// Hostile resolutions of the density grid: too coarse to hold any density, or too fine for
/// 2³¹ lattice points (up to past `usize`, which once wrapped to a tiny grid), are refused
/// with the way out and no panic; `info` refuses them too instead of printing a wrapped size.
#[test]
fn density_resolutions_that_cannot_work_are_refused_with_the_way_out() {
    let d = scratch("density-resolution");
    let out = d.join("v.png");
    for (vpa, says) in [
        ("0.01", "finer --voxels-per-angstrom"),
        ("1e30", "2^31-voxel limit"),
    ] {
        let (ok, _, err) = run(bnsview()
            .args([
                "render", "--scene", "nanobowl", "--atoms", "500", "--size", "40x30",
            ])
            .args(["--mode", "volume", "--voxels-per-angstrom", vpa, "-o"])
            .arg(&out));
        assert!(
            !ok && err.contains(says) && !err.contains("panicked"),
            "{vpa}: {err}"
        );
        assert!(!out.exists(), "nothing written when refused");
    }
    let (ok, _, err) = run(bnsview().args([
        "info",
        "--scene",
        "nanobowl",
        "--atoms",
        "500",
        "--voxels-per-angstrom",
        "1e30",
    ]));
    assert!(!ok && err.contains("2^31-voxel limit"), "{err}");
}

/// `--volume particles`: the grid-free volume renders the picture the f32 grid does (same
/// camera, transfer function range and step; the grid's interpolation is the difference),
/// says so under -v, and refuses volumetric shadows with the way out.
#[test]
fn grid_free_volume_renders_the_grid_picture_and_refuses_shadows() {
    let d = scratch("particles");
    let render = |source: &str, name: &str, extra: &[&str]| {
        let out = d.join(name);
        let r = run(bnsview()
            .args([
                "render", "--scene", "nanobowl", "--size", "96x72", "--mode", "volume",
            ])
            .args([
                "--volume",
                source,
                "--volume-format",
                "f32",
                "--density-max",
                "1.1",
            ])
            .args(extra)
            .arg("-v")
            .arg("-o")
            .arg(&out));
        (r, out)
    };
    let ((ok, _, err), part) = render("particles", "p.png", &[]);
    assert!(ok, "{err}");
    assert!(
        err.contains("grid-free"),
        "-v names the grid-free volume: {err}"
    );
    let ((ok, _, err), grid) = render("grid", "g.png", &[]);
    assert!(ok, "{err}");
    let (a, b) = (
        image::open(&part).unwrap().to_rgb8(),
        image::open(&grid).unwrap().to_rgb8(),
    );
    let diffs: Vec<u8> = a
        .pixels()
        .zip(b.pixels())
        .map(|(p, q)| (0..3).map(|c| p.0[c].abs_diff(q.0[c])).max().unwrap())
        .collect();
    let mean = diffs.iter().map(|&v| v as f64).sum::<f64>() / diffs.len() as f64;
    let lit = a.pixels().filter(|p| p.0.iter().any(|&c| c > 40)).count();
    assert!(lit * 4 > diffs.len(), "the bowl covers the frame: {lit}");
    assert!(mean < 4.0, "mean difference {mean}");
    let ((ok, _, err), shadowed) = render("particles", "s.png", &["--volume-shadows"]);
    assert!(!ok && err.contains("--volume grid"), "{err}");
    assert!(!shadowed.exists());
    // No grid to outgrow the memory: a hostile resolution is refused, not marched for hours.
    let ((ok, _, err), fine) = render("particles", "f.png", &["--voxels-per-angstrom", "1000"]);
    assert!(
        !ok && err.contains("at most 32 with --volume particles"),
        "{err}"
    );
    assert!(!fine.exists());
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

#[test]
fn render_help_is_grouped_under_headings() {
    let (ok, out, err) = run(bnsview().args(["render", "--help"]));
    assert!(ok, "{err}");
    let headings = [
        "Input and bonds:",
        "Output:",
        "Camera:",
        "Style and colour:",
        "Volume:",
        "Lighting:",
        "Path tracing:",
        "Performance:",
    ];
    let at: Vec<usize> = headings
        .iter()
        .map(|h| {
            out.find(&format!("\n{h}\n"))
                .unwrap_or_else(|| panic!("no heading {h:?} in\n{out}"))
        })
        .collect();
    // The heading a flag is listed under: the last heading before it.
    let heading_of = |flag: &str| {
        // A flag's own line: indented, then a space (its value) or the end of the line.
        let f = [format!("  {flag} "), format!("  {flag}\n")]
            .iter()
            .filter_map(|p| out.find(p.as_str()))
            .min()
            .unwrap_or_else(|| panic!("no {flag} in\n{out}"));
        headings[at
            .iter()
            .rposition(|&h| h < f)
            .expect("a flag before every heading")]
    };
    for (flag, want) in [
        ("--scene", "Input and bonds:"),
        ("--pbc", "Input and bonds:"),
        ("--unwrap", "Input and bonds:"),
        ("--frames", "Output:"),
        ("--orbit", "Camera:"),
        ("--legend", "Style and colour:"),
        ("--tf", "Volume:"),
        ("--shadows", "Lighting:"),
        ("--spp", "Path tracing:"),
        ("--threads", "Performance:"),
    ] {
        assert_eq!(heading_of(flag), want, "{flag}");
    }
}
