//! Following a dump while a writer thread appends it half a frame at a time: exactly the
//! frames written are rendered, each equal to the same frame of the finished file rendered as
//! a series, until --max-frames; a stop request completes the GIF with the frames so far.

mod common;

use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use common::{gif_frames, png, scratch, settings, water_frames};
use molecule::read::{open, Follower, ReadOptions};
use series::{follow_series, render_series, FollowSettings, FrameRange, OutputKind, Sink};

/// Appends each frame in two halves (the cut inside an atom line), pausing between writes.
fn write_slowly(path: std::path::PathBuf, frames: Vec<String>, pause: Duration) {
    for f in frames {
        let cut = f.len() / 2;
        for part in [&f[..cut], &f[cut..]] {
            let mut file = std::fs::OpenOptions::new()
                .append(true)
                .open(&path)
                .unwrap();
            file.write_all(part.as_bytes()).unwrap();
            drop(file);
            std::thread::sleep(pause);
        }
    }
}

fn follow(max_frames: Option<usize>, stop: Arc<AtomicBool>) -> FollowSettings {
    FollowSettings {
        poll: Duration::from_millis(5),
        max_frames,
        stop,
    }
}

#[test]
fn a_followed_dump_gives_exactly_the_frames_written_until_max_frames() {
    for pipelined in [true, false] {
        let d = scratch(&format!("follow-{pipelined}"));
        let frames = water_frames(5);
        // The reference: the finished file rendered as a series.
        let whole = d.join("whole.lammpstrj");
        std::fs::write(&whole, frames.concat()).unwrap();
        let s = settings(FrameRange::ALL, pipelined);
        let reference = d.join("ref_%02d.png");
        let mut traj = open(&whole, &ReadOptions::default()).unwrap();
        let mut sink =
            Sink::open(&OutputKind::from_path(&reference).unwrap(), false, 10.0).unwrap();
        render_series(&mut traj, &s, &mut sink, &mut |_| {}).unwrap();

        let growing = d.join("growing.lammpstrj");
        std::fs::write(&growing, "").unwrap();
        let writer = {
            let (p, f) = (growing.clone(), frames.clone());
            std::thread::spawn(move || write_slowly(p, f, Duration::from_millis(30)))
        };
        let mut follower = Follower::new(&growing, &ReadOptions::default()).unwrap();
        let out = d.join("live_%02d.png");
        let mut sink = Sink::open(&OutputKind::from_path(&out).unwrap(), false, 10.0).unwrap();
        let mut seen = Vec::new();
        let f = follow(Some(3), Arc::new(AtomicBool::new(false)));
        let report = follow_series(&mut follower, &s, &f, &mut sink, &mut |r| {
            seen.push(r.frame)
        })
        .unwrap();
        writer.join().unwrap();
        assert_eq!(seen, [0, 1, 2], "pipelined {pipelined}");
        assert_eq!(report.frames, 3);
        for k in 0..5 {
            let live = d.join(format!("live_{k:02}.png"));
            if k < 3 {
                let r = d.join(format!("ref_{k:02}.png"));
                assert_eq!(png(&live), png(&r), "frame {k}, pipelined {pipelined}");
            } else {
                assert!(!live.exists(), "frame {k} rendered past --max-frames");
            }
        }
        std::fs::remove_dir_all(&d).ok();
    }
}

/// Follows a file holding two water frames (and never more) in `d`, to `out`, pipelined,
/// until `stop` is set or an error; `on_frame` runs after each frame is written.
fn follow_two_frames(
    d: &Path,
    out: &Path,
    stop: Arc<AtomicBool>,
    on_frame: &mut dyn FnMut(&series::FrameReport),
) -> Result<series::SeriesReport, series::SeriesError> {
    let growing = d.join("growing.lammpstrj");
    std::fs::write(&growing, water_frames(2).concat()).unwrap();
    let mut follower = Follower::new(&growing, &ReadOptions::default()).unwrap();
    let mut sink = Sink::open(&OutputKind::from_path(out).unwrap(), false, 10.0).unwrap();
    let s = settings(FrameRange::ALL, true);
    follow_series(&mut follower, &s, &follow(None, stop), &mut sink, on_frame)
}

#[test]
fn a_stop_request_completes_the_gif_with_the_frames_so_far() {
    let d = scratch("follow-stop");
    let gif = d.join("live.gif");
    let stop = Arc::new(AtomicBool::new(false));
    // Stop once two frames are written; the file holds no third, so only the stop ends it.
    let mut n = 0;
    let report = follow_two_frames(&d, &gif, stop.clone(), &mut |_| {
        n += 1;
        if n == 2 {
            stop.store(true, Ordering::Relaxed);
        }
    })
    .unwrap();
    assert_eq!(report.frames, 2);
    assert_eq!(gif_frames(&gif), 2);
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn an_error_while_following_ends_the_series_instead_of_waiting_on() {
    // The output directory vanishes after the first frame: writing the second fails while
    // the reader waits for a third frame that never comes; the error must end the wait.
    let d = scratch("follow-error");
    let out = d.join("out");
    std::fs::create_dir(&out).unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let e = follow_two_frames(&d, &out.join("f_%d.png"), stop, &mut |_| {
        std::fs::remove_dir_all(&out).unwrap()
    })
    .unwrap_err();
    assert!(e.to_string().contains("f_1"), "{e}");
    std::fs::remove_dir_all(&d).ok();
}
