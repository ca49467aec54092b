//! `render --follow` run as a user would, against a dump that a writer thread appends half a
//! frame at a time: exactly the frames written, equal to the finished file's, until
//! --max-frames; Ctrl-C finishes the frame being rendered and exits cleanly.

mod common;

use std::io::Write;
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

use common::{bnsview, generate_frames, refused, run, sample, scratch};

/// A 4-frame generated dump, written whole to `dir/whole.lammpstrj`; the text of each frame.
fn frames(dir: &Path) -> Vec<String> {
    let whole = dir.join("whole.lammpstrj");
    generate_frames(&whole, 300, 4);
    let text = std::fs::read_to_string(&whole).unwrap();
    let starts: Vec<usize> = text
        .match_indices("ITEM: TIMESTEP")
        .map(|(i, _)| i)
        .collect();
    assert_eq!(starts.len(), 4);
    (0..4)
        .map(|k| text[starts[k]..starts.get(k + 1).copied().unwrap_or(text.len())].to_string())
        .collect()
}

fn append(path: &Path, s: &str) {
    let mut f = std::fs::OpenOptions::new().append(true).open(path).unwrap();
    f.write_all(s.as_bytes()).unwrap();
}

fn rgba(p: &Path) -> Vec<u8> {
    image::open(p).unwrap().to_rgba8().into_raw()
}

#[test]
fn follow_renders_exactly_the_frames_written_until_max_frames() {
    let d = scratch("follow");
    let frames = frames(&d);
    let size = ["--size", "64x48"];
    let (ok, _, err) = run(bnsview()
        .arg("render")
        .arg(d.join("whole.lammpstrj"))
        .args(size)
        .args(["--frames", "0:3", "-o"])
        .arg(d.join("ref_%02d.png")));
    assert!(ok, "{err}");
    let growing = d.join("growing.lammpstrj");
    std::fs::write(&growing, "").unwrap();
    let writer = {
        let growing = growing.clone();
        std::thread::spawn(move || {
            for f in frames {
                let cut = f.len() / 2;
                append(&growing, &f[..cut]);
                std::thread::sleep(Duration::from_millis(150));
                append(&growing, &f[cut..]);
                std::thread::sleep(Duration::from_millis(150));
            }
        })
    };
    let (ok, _, err) = run(bnsview()
        .arg("render")
        .arg(&growing)
        .args(size)
        .args(["--follow", "--max-frames", "3", "--poll", "0.02", "-o"])
        .arg(d.join("live_%02d.png")));
    writer.join().unwrap();
    assert!(ok, "{err}");
    assert!(err.contains("wrote 3 frame(s)"), "{err}");
    for k in 0..3 {
        let (live, reference) = (
            d.join(format!("live_{k:02}.png")),
            d.join(format!("ref_{k:02}.png")),
        );
        assert!(rgba(&live) == rgba(&reference), "frame {k}");
    }
    assert!(!d.join("live_03.png").exists(), "past --max-frames");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn ctrl_c_finishes_the_frame_and_exits_cleanly() {
    let d = scratch("follow-int");
    let growing = d.join("growing.lammpstrj");
    std::fs::write(&growing, frames(&d)[..2].concat()).unwrap();
    let child = bnsview()
        .arg("render")
        .arg(&growing)
        .args(["--size", "48x48", "--follow", "--poll", "0.02", "-o"])
        .arg(d.join("live_%02d.png"))
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t = Instant::now();
    while !d.join("live_01.png").exists() {
        assert!(t.elapsed() < Duration::from_secs(120), "no second frame");
        std::thread::sleep(Duration::from_millis(20));
    }
    let kill = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("stopped by Ctrl-C") && err.contains("wrote 2 frame(s)"),
        "{err}"
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn follow_refuses_what_it_cannot_follow() {
    let d = scratch("follow-refuse");
    let gz = sample("spce_water.lammpstrj.gz");
    // `render ARGS` in the scratch directory.
    let render = |args: &[&dyn AsRef<std::ffi::OsStr>]| {
        let mut c = bnsview();
        c.current_dir(&d).arg("render").args(args);
        c
    };
    for (args, want) in [
        (&["--follow"][..], "uncompressed"),
        (&["--follow", "--poll", "0"], "--poll"),
        (&["--max-frames", "2"], "--follow"),
        (&["--follow", "--frame", "1"], "--frame"),
    ] {
        refused(render(&[&gz]).args(args), &[want]);
    }
    refused(
        &mut render(&[&"--scene", &"nanobowl", &"--follow"]),
        &["trajectory file"],
    );
    // Every frame cannot be known before the first is rendered.
    let xyz = d.join("a.xyz");
    std::fs::write(&xyz, "1\nc\nC 0 0 0\n").unwrap();
    let follow_all = ["--follow", "--frames", "all", "--fit", "all"];
    refused(render(&[&xyz]).args(follow_all), &["--fit all"]);
    refused(render(&[&xyz]).args(["--fit", "all"]), &["--frames"]);
    std::fs::remove_dir_all(&d).ok();
}
