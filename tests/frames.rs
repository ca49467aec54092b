//! Frames of a trajectory and `generate`, through the CLI.

mod common;

use std::process::Command;

use common::{bnsview, generate_frames, run, sample, scratch};

#[test]
fn frames_of_a_trajectory_equal_single_frames_with_the_printed_camera_and_range() {
    let d = scratch("frames");
    let dump = sample("spce_water.lammpstrj.gz");
    let common = ["--types", "1=O,2=H", "--size", "64x48", "--color", "id"];
    let (ok, _, err) = run(bnsview()
        .arg("render")
        .arg(&dump)
        .args(common)
        .args(["--frames", "2:9:3", "-v", "-o"])
        .arg(d.join("w_%02d.png")));
    assert!(ok, "{err}");
    let line = |prefix: &str| {
        err.lines()
            .find_map(|l| l.strip_prefix(prefix))
            .unwrap_or_else(|| panic!("no {prefix:?} in {err}"))
            .split_whitespace()
            .next()
            .unwrap()
            .to_string()
    };
    let (camera, range) = (line("camera:  --camera "), line("color:   --color-range "));
    assert!(err.contains("3 frames"), "{err}");
    for k in [2, 5, 8] {
        let single = d.join(format!("single_{k}.png"));
        let (ok, _, e) = run(bnsview()
            .arg("render")
            .arg(&dump)
            .args(common)
            .args([
                "--frame",
                &k.to_string(),
                "--camera",
                &camera,
                "--color-range",
                &range,
                "-o",
            ])
            .arg(&single));
        assert!(ok, "{e}");
        let a = image::open(&single).unwrap().to_rgba8();
        let b = image::open(d.join(format!("w_{k:02}.png")))
            .unwrap()
            .to_rgba8();
        assert!(a == b, "frame {k} differs from render --frame {k}");
    }
    // An animated GIF with the frames asked for.
    let gif = d.join("m.gif");
    let (ok, _, err) = run(bnsview()
        .arg("render")
        .arg(&dump)
        .args(["--size", "48x48", "--frames", "0:3", "-o"])
        .arg(&gif));
    assert!(ok, "{err}");
    let dec = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
        std::fs::File::open(&gif).unwrap(),
    ))
    .unwrap();
    assert_eq!(image::AnimationDecoder::into_frames(dec).count(), 3);
    // A video through ffmpeg (CI installs it): ffprobe counts the frames.
    let mp4 = d.join("m.mp4");
    let args = ["--size", "48x48", "--frames", "0:3", "-o"];
    if Command::new("ffprobe").arg("-version").output().is_ok() {
        let (ok, _, err) = run(bnsview().arg("render").arg(&dump).args(args).arg(&mp4));
        assert!(ok, "{err}");
        let probe = Command::new("ffprobe")
            .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
            .args(["-show_entries", "stream=nb_read_frames", "-of", "csv=p=0"])
            .arg(&mp4)
            .output()
            .unwrap();
        assert_eq!(String::from_utf8_lossy(&probe.stdout).trim(), "3");
    } else {
        eprintln!("ffprobe not on PATH: the video encode is not checked here (CI installs ffmpeg)");
    }
    // Without ffmpeg on PATH the error says what to do.
    let (ok, _, err) = run(bnsview()
        .env("PATH", "")
        .arg("render")
        .arg(&dump)
        .args(args)
        .arg(d.join("n.mp4")));
    assert!(
        !ok && err.contains("ffmpeg") && err.contains("%05d"),
        "{err}"
    );
    // Refusals: a single-frame scene, a name without a frame number, a bad range.
    for (extra, want) in [
        (
            vec!["--scene", "nanobowl", "--frames", "all"],
            "trajectory file",
        ),
        (vec!["--frames", "all", "-o", "one.png"], "%0Nd"),
        (vec!["--frames", "3:1"], "expected all or A:B"),
    ] {
        let mut c = bnsview();
        c.current_dir(&d).arg("render");
        if extra[0] != "--scene" {
            c.arg(&dump);
        }
        let (ok, _, err) = run(c.args(&extra));
        assert!(!ok && err.contains(want), "{extra:?}: {err}");
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn generate_writes_a_trajectory_of_the_frames_asked_for() {
    let d = scratch("genframes");
    let out = d.join("t.lammpstrj.gz");
    generate_frames(&out, 500, 4);
    let (ok, info, err) = run(bnsview().arg("info").arg(&out));
    assert!(ok && info.contains("frames:    4"), "{info}{err}");
    // The frames move (jitter and breathing) and are the same again for the same seed.
    let render = |k: &str, name: &str| {
        let png = d.join(name);
        let (ok, _, err) = run(bnsview()
            .arg("render")
            .arg(&out)
            .args(["--size", "48x48", "--frame", k, "-o"])
            .arg(&png));
        assert!(ok, "{err}");
        std::fs::read(png).unwrap()
    };
    assert_ne!(render("0", "a.png"), render("3", "b.png"));
    let again = d.join("again.lammpstrj.gz");
    generate_frames(&again, 500, 4);
    let gunzip = |p: &std::path::Path| {
        let mut s = String::new();
        std::io::Read::read_to_string(
            &mut flate2::read::GzDecoder::new(std::fs::File::open(p).unwrap()),
            &mut s,
        )
        .unwrap();
        s
    };
    assert_eq!(gunzip(&out), gunzip(&again));
    for bad in ["0", "100001"] {
        let (ok, _, err) = run(bnsview()
            .args(["generate", "nanobowl", "--frames", bad, "-o"])
            .arg(d.join("x.xyz")));
        assert!(!ok && err.contains("--frames"), "{err}");
    }
    std::fs::remove_dir_all(&d).ok();
}
