//! Progress on stderr for the steps that can take a while: spinners for steps of unknown
//! length, bars for reading a file, each stage of a scene build and rendering a frame. Nothing is drawn when stderr is not a
//! terminal, and nothing before half a second has passed.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{channel, RecvTimeoutError};
use std::sync::Arc;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use scene::{Progress, Stage};

/// A spinner with `msg` and the time elapsed.
pub fn spinner(msg: &str) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
        pb.set_style(style);
    }
    pb.set_message(msg.to_string());
    pb.enable_steady_tick(Duration::from_millis(500));
    pb
}

/// A bar of `len` steps with `msg`, the percentage and the time left.
pub fn bar(msg: &str, len: u64) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    let template = "{msg} [{bar:30}] {percent}% ({elapsed}, {eta} left)";
    if let Ok(style) = ProgressStyle::with_template(template) {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_message(msg.to_string());
    pb.enable_steady_tick(Duration::from_millis(500));
    pb
}

/// Runs `work` while `pb` follows the byte count `read` (every 0.2 s): as its position when
/// the bar has a length, else in its message after `what`.
fn follow_bytes<T>(pb: &ProgressBar, read: &AtomicU64, what: &str, work: impl FnOnce() -> T) -> T {
    let (done, wait) = channel::<()>();
    std::thread::scope(|s| {
        s.spawn(move || loop {
            let b = read.load(Ordering::Relaxed);
            if pb.length().is_some() {
                pb.set_position(b);
            } else {
                pb.set_message(format!("{what} ({} MB decoded)", b / 1_000_000));
            }
            match wait.recv_timeout(Duration::from_millis(200)) {
                Err(RecvTimeoutError::Timeout) => {}
                _ => return,
            }
        });
        let out = work();
        drop(done);
        out
    })
}

/// Runs `work` (a scene build or a load) with a bar per stage headed `title`: `work` reports
/// through the [`Progress`] it is given, each stage restarts the bar with its name and units
/// (a stage of unknown length shows the count in its message instead).
pub fn follow_stages<T>(title: &str, work: impl FnOnce(&Progress) -> T) -> T {
    let pb = bar(title, 1);
    let done = Arc::new(AtomicU64::new(0));
    let stage = |s: Stage, units: u64| {
        // Zero the count before the bar's length changes, so no poll shows the last
        // stage's count against this one's length.
        done.store(0, Ordering::Relaxed);
        pb.set_message(format!("{title}: {s}"));
        pb.reset();
        match (s, units) {
            (Stage::Read | Stage::CountFrames, 0) => pb.unset_length(),
            _ => pb.set_length(units.max(1)),
        }
    };
    let progress = Progress::new(&stage, done.clone());
    let out = follow_bytes(&pb, &done, title, || work(&progress));
    pb.finish_and_clear();
    out
}
