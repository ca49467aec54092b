//! Simulation cells, periodic bonds, unwrapping and colouring by a column, through the CLI.

mod common;

use common::{bnsview, refused, run, sample, scratch};

/// A water molecule split by the x boundary of a 1 nm `.gro` box (the case).
fn split_water_gro(path: &std::path::Path) {
    let atom = |n: usize, name: &str, x: f32, y: f32| {
        format!(
            "{:5}{:<5}{:>5}{:5}{:8.3}{:8.3}{:8.3}\n",
            1, "SOL", name, n, x, y, 0.5
        )
    };
    let gro = format!(
        "split water\n3\n{}{}{}   1.00000   1.00000   1.00000\n",
        atom(1, "OW", 0.03, 0.50),
        atom(2, "HW1", 0.98, 0.53),
        atom(3, "HW2", 0.09, 0.56)
    );
    std::fs::write(path, gro).unwrap();
}

#[test]
fn pbc_draws_half_sticks_and_cell_draws_the_box() {
    let d = scratch("pbc");
    let gro = d.join("water.gro");
    split_water_gro(&gro);
    let (w, h) = (120u32, 90u32);
    let render = |name: &str, extra: &[&str]| {
        let out = d.join(name);
        let (ok, _, err) = run(bnsview()
            .arg("render")
            .arg(&gro)
            .args(["--size", "120x90", "--view", "front", "-o"])
            .arg(&out)
            .args(extra));
        assert!(ok, "{err}");
        image::open(&out).unwrap().to_rgba8()
    };
    // With --pbc the O-H bond through the boundary is found (the picture changes) and drawn
    // as two half-sticks at the sides of the box: the middle column, which one stick spanning
    // the box would cross, stays empty.
    let middle_is_empty =
        |img: &image::RgbaImage| (0..h).all(|y| img.get_pixel(w / 2, y).0 == [255; 4]);
    let pbc = render("pbc.png", &["--pbc"]);
    assert!(middle_is_empty(&pbc));
    assert_ne!(
        pbc,
        render("nopbc.png", &[]),
        "--pbc adds the bond across the boundary"
    );
    // --cell adds the box's edges: more non-background pixels than without.
    let inked = |img: &image::RgbaImage| img.pixels().filter(|p| p.0 != [255; 4]).count();
    let boxed = render("cell.png", &["--pbc", "--cell"]);
    assert!(inked(&boxed) > inked(&render("pbc2.png", &["--pbc"])) + 100);
    // An input without a cell says so.
    let xyz = d.join("nocell.xyz");
    std::fs::write(&xyz, "2\nno cell\nC 0 0 0\nC 1.5 0 0\n").unwrap();
    let (ok, _, err) = run(bnsview()
        .arg("render")
        .arg(&xyz)
        .args(["--size", "64x64", "--cell", "-o"])
        .arg(d.join("x.png")));
    assert!(
        !ok && err.contains("--cell") && err.contains("no simulation cell"),
        "{err}"
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn unwrap_draws_the_split_water_as_the_hand_unwrapped_one() {
    let d = scratch("unwrap");
    let gro = d.join("water.gro");
    split_water_gro(&gro);
    // The same water put together by hand: HW1 at 0.98 - 1 nm.
    let whole = d.join("whole.gro");
    let text = std::fs::read_to_string(&gro).unwrap();
    std::fs::write(&whole, text.replace("   0.980", "  -0.020")).unwrap();
    let render = |file: &std::path::Path, name: &str, extra: &[&str]| {
        let out = d.join(name);
        let (ok, _, err) = run(bnsview()
            .arg("render")
            .arg(file)
            .args(["--size", "120x90", "--view", "front", "-v", "-o"])
            .arg(&out)
            .args(extra));
        assert!(ok, "{err}");
        (image::open(&out).unwrap().to_rgba8(), err)
    };
    // Pixels differing by more than a rounding step.
    let differ = |a: &image::RgbaImage, b: &image::RgbaImage| {
        a.pixels()
            .zip(b.pixels())
            .filter(|(p, q)| (0..4).any(|k| p.0[k].abs_diff(q.0[k]) > 8))
            .count()
    };
    let (want, _) = render(&whole, "whole.png", &[]);
    let (unwrapped, err) = render(&gro, "unwrapped.png", &["--unwrap"]);
    assert!(
        err.contains("unwrap:  by minimum image along the bonds"),
        "-v names the method: {err}"
    );
    assert!(
        differ(&unwrapped, &want) < 50,
        "{}",
        differ(&unwrapped, &want)
    );
    // --pbc --unwrap: nothing crosses any more, so the same picture (no half-sticks).
    let (both, _) = render(&gro, "both.png", &["--unwrap", "--pbc"]);
    assert!(differ(&both, &want) < 50);
    // Without --unwrap the molecule is split over the box: a different picture.
    let (split, _) = render(&gro, "split.png", &["--pbc"]);
    assert!(differ(&split, &want) > 500, "{}", differ(&split, &want));
    // info --unwrap reports the method and the unwrapped bounds (x from -0.2 Å).
    let (ok, out, err) = run(bnsview().arg("info").arg(&gro).arg("--unwrap"));
    assert!(ok, "{err}");
    assert!(out.contains("unwrap:    by minimum image"), "{out}");
    assert!(out.contains("bounds:    [-0.200,"), "{out}");
    // An input without a cell says --unwrap needs one.
    let xyz = d.join("nocell.xyz");
    std::fs::write(&xyz, "2\nno cell\nC 0 0 0\nC 1.5 0 0\n").unwrap();
    let wants = ["--unwrap", "cell"];
    refused(bnsview().arg("info").arg(&xyz).arg("--unwrap"), &wants);
    let png = d.join("x.png");
    refused(
        bnsview()
            .arg("render")
            .arg(&xyz)
            .args(["--unwrap", "--size", "64x64", "-o"])
            .arg(&png),
        &wants,
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn colour_range_is_printed_and_obeyed_and_the_legend_sits_at_the_right() {
    let d = scratch("legend");
    let dump = sample("mass_q_elem.lammpstrj");
    let render = |name: &str, extra: &[&str]| {
        let out = d.join(name);
        let (ok, _, err) = run(bnsview()
            .arg("render")
            .arg(&dump)
            .args(["--size", "200x150", "--color", "q", "-v", "-o"])
            .arg(&out)
            .args(extra));
        (ok, err, out)
    };
    let (ok, err, own) = render("own.png", &[]);
    assert!(ok, "{err}");
    assert!(
        err.contains("color:   q over --color-range -0.51:0.51"),
        "{err}"
    );
    let (ok, err, given) = render("given.png", &["--color-range", "-1:1"]);
    assert!(ok && err.contains("--color-range -1:1"), "{err}");
    let (own, given) = (std::fs::read(own).unwrap(), std::fs::read(&given).unwrap());
    assert_ne!(own, given, "the range changes the colours");
    let (ok, err, legend) = render("legend.png", &["--color-range", "-1:1", "--legend"]);
    assert!(ok, "{err}");
    let (a, b) = (
        image::load_from_memory(&given).unwrap().to_rgba8(),
        image::open(legend).unwrap().to_rgba8(),
    );
    let changed: Vec<u32> = a
        .enumerate_pixels()
        .filter(|(x, y, p)| b.get_pixel(*x, *y) != *p)
        .map(|(x, _, _)| x)
        .collect();
    assert!(changed.len() > 500, "{} pixels changed", changed.len());
    assert!(
        changed.iter().all(|&x| x > 100),
        "the legend stays in the right half"
    );
    for (bad, want) in [
        (&["--color-range", "1:-1"][..], "expected LO:HI"),
        (&["--color-range", "x"][..], "expected LO:HI"),
    ] {
        let (ok, err, _) = render("bad.png", bad);
        assert!(!ok && err.contains(want), "{bad:?}: {err}");
    }
    let (ok, _, err) = run(bnsview()
        .args([
            "render", "--scene", "nanobowl", "--atoms", "500", "--legend", "-o",
        ])
        .arg(d.join("el.png")));
    assert!(!ok && err.contains("--color COLUMN"), "{err}");
    std::fs::remove_dir_all(&d).ok();
}
