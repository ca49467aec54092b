//! `bnsview view` under a real X server (Xvfb): scripted sessions against `bnsview render`,
//! playback order and a loader that never stops the window, errors. Without DISPLAY the
//! viewer runs under `xvfb-run -a` (Debian package `xvfb`; `.ci/run` installs it and runs the
//! whole suite under one Xvfb).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

use common::{bnsview, run, scratch};

/// One viewer at a time (parallel `xvfb-run -a` can race for a display number).
static ONE_WINDOW: Mutex<()> = Mutex::new(());

/// `bnsview view ARGS` with a display: this one, else a new Xvfb.
fn view(args: &[&str]) -> (bool, String, String) {
    let _one = ONE_WINDOW.lock().unwrap_or_else(|e| e.into_inner());
    let mut c = if std::env::var_os("DISPLAY").is_some() {
        bnsview()
    } else {
        let found = Command::new("xvfb-run").arg("--help").output().is_ok();
        assert!(
            found,
            "no DISPLAY and no xvfb-run: install xvfb (apt-get install xvfb)"
        );
        let mut c = Command::new("xvfb-run");
        c.args(["-a", env!("CARGO_BIN_EXE_bnsview")])
            .env_remove("BNS_ISA")
            .env_remove("BNS_CPU_LIMIT");
        c
    };
    c.arg("view").args(args);
    run(&mut c)
}

fn pixels(p: &Path) -> Vec<u8> {
    image::open(p)
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        .to_rgba8()
        .into_raw()
}

/// The `--camera '…' --mode …` lines the `c` key printed, as arguments.
fn printed_flags(stdout: &str) -> Vec<Vec<String>> {
    stdout
        .lines()
        .filter_map(|l| l.strip_prefix("--camera '"))
        .map(|l| {
            let (cam, rest) = l.split_once('\'').expect("closing quote");
            let mut v = vec!["--camera".to_string(), cam.to_string()];
            v.extend(rest.split_whitespace().map(String::from));
            v
        })
        .collect()
}

#[test]
fn a_scripted_session_screenshots_what_render_makes_of_the_printed_camera() {
    let d = scratch("view-shots");
    let script = d.join("tour.txt");
    // Orbit, zoom and pan, then each mode and lighting key; each screenshot fully refined.
    let shot = |name: &str| d.join(format!("{name}.png"));
    let text = format!(
        "wait-still\norbit 40 15\nzoom 1.4\npan 12 -7\nwait-still\nkey c\nscreenshot {}\n\
         key a\nkey c\nscreenshot {}\n\
         key 3\nkey l\nkey ]\nkey ]\norbit -75 -20\nkey c\nscreenshot {}\n\
         key v\nkey c\nscreenshot {}\n\
         key 4\nzoom 1.2\nwait-frames 2\nwait-still\nkey c\nscreenshot {}\nquit\n",
        shot("bs").display(),
        shot("ao").display(),
        shot("volbs").display(),
        shot("volume").display(),
        shot("path").display(),
    );
    std::fs::write(&script, text).unwrap();
    let size = "96x72";
    let (ok, out, err) = view(&[
        "--scene",
        "nanobowl",
        "--size",
        size,
        "--spp",
        "3",
        "--script",
        script.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let flags = printed_flags(&out);
    let shots = ["bs", "ao", "volbs", "volume", "path"];
    assert_eq!(flags.len(), shots.len(), "{out}");
    let modes: Vec<&str> = flags.iter().map(|f| f[3].as_str()).collect();
    assert_eq!(modes, ["bs", "bs", "vol+bs", "volume", "path"]);
    assert!(flags[1].contains(&"--ao".to_string()) && flags[2].contains(&"--lit".to_string()));
    assert!(
        flags[2].join(" ").contains("--opacity 1.5625"),
        "{:?}",
        flags[2]
    );
    for (name, f) in shots.iter().zip(&flags) {
        let reference = d.join(format!("render-{name}.png"));
        let mut c = bnsview();
        c.args([
            "render", "--scene", "nanobowl", "--size", size, "--spp", "3", "-o",
        ])
        .arg(&reference)
        .args(f);
        let (ok, _, err) = run(&mut c);
        assert!(ok, "{name}: {err}");
        assert!(
            pixels(&shot(name)) == pixels(&reference),
            "{name}: the viewer's screenshot differs from bnsview render {f:?}"
        );
    }
    // The views differ from each other (the keys did something).
    assert!(pixels(&d.join("render-bs.png")) != pixels(&d.join("render-ao.png")));
}

/// The JSON lines of a `--log` file as (key, value) text pairs.
fn log_lines(p: &Path) -> Vec<Vec<(String, String)>> {
    std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .map(|l| {
            l.trim_matches(['{', '}'])
                .split(',')
                .filter_map(|kv| kv.split_once(':'))
                .map(|(k, v)| {
                    (
                        k.trim_matches('"').to_string(),
                        v.trim_matches('"').to_string(),
                    )
                })
                .collect()
        })
        .collect()
}

fn field<'a>(l: &'a [(String, String)], k: &str) -> Option<&'a str> {
    l.iter().find(|(a, _)| a == k).map(|(_, v)| v.as_str())
}

/// `bnsview view INPUT --size 48x48 FLAGS` driven by `script` (written to `DIR/NAME.txt`) with
/// a `--log` (`DIR/NAME.jsonl`); must succeed. Its stdout and log lines.
fn view_logged(
    input: &Path,
    flags: &[&str],
    script: &str,
    dir: &Path,
    name: &str,
) -> (String, Vec<Vec<(String, String)>>) {
    let (path, log) = (
        dir.join(format!("{name}.txt")),
        dir.join(format!("{name}.jsonl")),
    );
    std::fs::write(&path, script).unwrap();
    let mut args = vec![input.to_str().unwrap(), "--size", "48x48"];
    args.extend_from_slice(flags);
    args.extend([
        "--script",
        path.to_str().unwrap(),
        "--log",
        log.to_str().unwrap(),
    ]);
    let (ok, out, err) = view(&args);
    assert!(ok, "{name}: {err}");
    (out, log_lines(&log))
}

/// `traj.xyz` in `d`: `frames` time steps of a 20k-atom ns90k.
fn ns90k_steps(d: &Path, frames: usize) -> PathBuf {
    let traj = d.join("traj.xyz");
    let mut c = bnsview();
    c.args(["generate", "ns90k", "--atoms", "20000", "--frames"])
        .arg(frames.to_string())
        .arg("-o")
        .arg(&traj);
    let (ok, _, err) = run(&mut c);
    assert!(ok, "{err}");
    traj
}

#[test]
fn playback_shows_every_time_step_in_order_while_the_next_is_built_behind() {
    let d = scratch("view-play");
    // Three time steps of 20k atoms: each build takes far longer than a 48×48 frame.
    let traj = ns90k_steps(&d, 3);
    let shot = |k: usize| d.join(format!("step{k}.png"));
    // Play while orbiting a little every frame (so frames keep coming during builds), then
    // a screenshot of each time step, stepped to with the keys.
    let mut text = String::from("wait-still\nkey space\n");
    for _ in 0..150 {
        text += "orbit 0.5 0\nwait-frames 1\n";
    }
    text += &format!(
        "wait-still\nkey c\nscreenshot {}\nkey left\nwait-still\nscreenshot {}\nframe 0\nwait-still\nscreenshot {}\nquit\n",
        shot(2).display(),
        shot(1).display(),
        shot(0).display()
    );
    let (out, lines) = view_logged(&traj, &[], &text, &d, "play");
    let presented: Vec<(usize, bool)> = lines
        .iter()
        .filter(|l| field(l, "presented").is_some())
        .map(|l| {
            (
                field(l, "frame").unwrap().parse().unwrap(),
                field(l, "loading") == Some("true"),
            )
        })
        .collect();
    // Playback: 0, 1, 2 in order, each on screen, up to the stepping back at the end.
    let played: Vec<usize> = presented.iter().map(|p| p.0).collect();
    let until_back = played
        .windows(2)
        .position(|w| w[1] < w[0])
        .map_or(played.len(), |i| i + 1);
    let mut seen = played[..until_back].to_vec();
    assert!(seen.windows(2).all(|w| w[0] <= w[1]), "{played:?}");
    seen.dedup();
    assert_eq!(seen, [0, 1, 2], "{played:?}");
    // The window went on presenting while a later step was being built.
    let during = presented.iter().filter(|p| p.1).count();
    assert!(
        during >= 1,
        "no frame presented during a build: {presented:?}"
    );
    // Each step's screenshot is what `render --frame K` makes with the printed camera.
    let flags = printed_flags(&out);
    assert_eq!(flags.len(), 1, "{out}");
    for k in 0..3 {
        let reference = d.join(format!("render{k}.png"));
        let mut c = bnsview();
        c.arg("render")
            .arg(&traj)
            .args(["--frame", &k.to_string(), "--size", "48x48", "-o"])
            .arg(&reference)
            .args(&flags[0]);
        let (ok, _, err) = run(&mut c);
        assert!(ok, "{err}");
        assert!(pixels(&shot(k)) == pixels(&reference), "time step {k}");
    }
    assert!(
        pixels(&shot(0)) != pixels(&shot(2)),
        "the time steps look the same"
    );
}

#[test]
fn bad_scripts_missing_displays_and_existing_files_are_clear_errors() {
    let d = scratch("view-errors");
    let script = d.join("bad.txt");
    std::fs::write(&script, "orbit 10 10\nzoom zero\n").unwrap();
    let (ok, _, err) = view(&["--script", script.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        err.contains("bad.txt:2:") && err.contains("zoom FACTOR"),
        "{err}"
    );
    // No display: what to do, not a panic.
    let mut c = bnsview();
    c.env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .args(["view", "--size", "32x32"]);
    let (ok, _, err) = run(&mut c);
    assert!(!ok);
    assert!(
        err.contains("no X display") && err.contains("xvfb-run -a"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    // A screenshot over an existing file is refused without --force; with it, written.
    let shot = d.join("kept.png");
    std::fs::write(&shot, b"precious").unwrap();
    std::fs::write(&script, format!("screenshot {}\nquit\n", shot.display())).unwrap();
    let (ok, _, err) = view(&["--size", "32x32", "--script", script.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("exists") && err.contains("--force"), "{err}");
    assert_eq!(std::fs::read(&shot).unwrap(), b"precious");
    let (ok, _, err) = view(&[
        "--size",
        "32x32",
        "-f",
        "--script",
        script.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert_eq!(pixels(&shot).len(), 32 * 32 * 4);
    // Flags the viewer cannot honour are refused up front.
    let (ok, _, err) = view(&["--legend", "--color", "q"]);
    assert!(!ok && err.contains("--legend"), "{err}");
}

#[test]
fn the_first_step_shows_what_the_mode_needs_first_and_the_volume_follows_behind() {
    let d = scratch("view-upgrade");
    // A 20k-atom trajectory: its volume takes far longer to build than a 48×48 frame.
    let traj = ns90k_steps(&d, 1);
    // The vol+bs key once everything is built, and right after the first frame (while the
    // volume is still on its way: the key then waits for it rather than asking for more).
    for (name, start) in [("still", "wait-still"), ("early", "wait-frames 1")] {
        let script = format!("{start}\nkey 3\nwait-frames 1\nwait-still\nquit\n");
        let (_, lines) = view_logged(&traj, &["--mode", "bs"], &script, &d, name);
        let loaded: Vec<(usize, &str)> = lines
            .iter()
            .enumerate()
            .filter(|(_, l)| field(l, "loaded").is_some())
            .map(|(i, l)| (i, field(l, "upgrade").unwrap_or("missing")))
            .collect();
        // Two builds of time step 0: balls and sticks (what --mode bs needs), then the model
        // and the volume, asked for once the first is on screen; the first frame in between.
        // The key needs no third.
        assert_eq!(
            loaded.iter().map(|l| l.1).collect::<Vec<_>>(),
            ["false", "true"],
            "{name}: {lines:?}"
        );
        let first_frame = lines.iter().position(|l| field(l, "presented").is_some());
        assert!(
            first_frame.is_some_and(|f| loaded[0].0 < f && f < loaded[1].0),
            "{name}: {lines:?}"
        );
        // And no build was thrown away.
        assert!(
            lines.iter().all(|l| field(l, "discarded").is_none()),
            "{name}: {lines:?}"
        );
        // After the key, frames are vol+bs once the volume is in, never a scene without it.
        let key = lines
            .iter()
            .position(|l| field(l, "key").is_some())
            .unwrap();
        let after: Vec<&str> = lines[key..]
            .iter()
            .filter(|l| field(l, "presented").is_some())
            .map(|l| field(l, "mode").unwrap())
            .collect();
        assert!(after.last() == Some(&"vol+bs"), "{name}: {lines:?}");
        if name == "still" {
            assert!(
                key > loaded[1].0 && after.iter().all(|m| *m == "vol+bs"),
                "{lines:?}"
            );
        }
    }
}

#[test]
fn two_quick_steps_go_two_steps_and_the_step_passed_over_is_not_built() {
    let d = scratch("view-steps");
    let traj = ns90k_steps(&d, 3);
    // Two presses of → at once (the second before the first step has arrived).
    let script = "wait-still\nkey right\nkey right\nwait-still\nquit\n";
    let (_, lines) = view_logged(&traj, &[], script, &d, "steps");
    let loaded: Vec<&str> = lines
        .iter()
        .filter(|l| field(l, "loaded").is_some() && field(l, "upgrade") == Some("false"))
        .map(|l| field(l, "loaded").unwrap())
        .collect();
    // Step 2, not step 1 twice; step 1 is dropped or stopped, never finished and thrown away.
    assert_eq!(loaded, ["0", "2"], "{lines:?}");
    assert!(
        lines.iter().all(|l| field(l, "discarded").is_none()),
        "{lines:?}"
    );
    let last = lines.iter().rev().find(|l| field(l, "presented").is_some());
    assert_eq!(last.and_then(|l| field(l, "frame")), Some("2"), "{lines:?}");
}

#[test]
fn stepping_back_to_the_step_on_screen_builds_nothing() {
    let d = scratch("view-back");
    let traj = ns90k_steps(&d, 3);
    // `←` on the first step; `→` and `←` at once; then the vol+bs key, which the first
    // step's upgrade (model and volume) serves.
    let script = "wait-still\nkey left\nwait-still\nkey right\nkey left\nwait-still\nkey 3\nwait-frames 1\nwait-still\nquit\n";
    let (_, lines) = view_logged(&traj, &["--mode", "bs"], script, &d, "back");
    let loaded: Vec<(&str, &str)> = lines
        .iter()
        .filter(|l| field(l, "loaded").is_some())
        .map(|l| (field(l, "loaded").unwrap(), field(l, "upgrade").unwrap()))
        .collect();
    // Step 0 and its upgrade only: not rebuilt, step 1 never finished.
    assert_eq!(loaded, [("0", "false"), ("0", "true")], "{lines:?}");
    assert!(
        lines.iter().all(|l| field(l, "discarded").is_none()),
        "{lines:?}"
    );
    let modes: Vec<(&str, &str)> = lines
        .iter()
        .filter(|l| field(l, "presented").is_some())
        .map(|l| (field(l, "frame").unwrap(), field(l, "mode").unwrap()))
        .collect();
    assert!(modes.iter().all(|m| m.0 == "0"), "{modes:?}");
    assert_eq!(modes.last(), Some(&("0", "vol+bs")), "{modes:?}");
}
