//! `--script FILE`: one camera move, key or wait per line, driving the same event code as the
//! mouse and keyboard (headless tests, benchmarks, reproducible movies).
//!
//! ```text
//! # comments and blank lines are skipped
//! orbit 30 0          # azimuth, elevation (degrees)
//! pan 40 -10          # pixels right, up
//! zoom 1.5            # 1.5 times closer
//! key v               # a key by name (see `h`)
//! frame 2             # go to time step 2
//! wait-frames 5       # until 5 more frames are on screen
//! wait-still          # until the view is fully refined and nothing is loading
//! screenshot out.png  # the fully refined frame (waits for it)
//! quit
//! ```

use std::path::{Path, PathBuf};

use crate::error::ViewError;
use crate::keys::{action, key_names, Action};

/// One line of a script.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// Orbit by (azimuth, elevation) degrees.
    Orbit(f64, f64),
    /// Pan by (right, up) pixels.
    Pan(f64, f64),
    /// Zoom by a factor (> 0).
    Zoom(f64),
    /// Press a key.
    Key(Action),
    /// Show time step `k`.
    Frame(usize),
    /// Wait until this many more frames have been presented.
    WaitFrames(u32),
    /// Wait until the view is fully refined and no scene is loading.
    WaitStill,
    /// Save the fully refined frame (waits for it).
    Screenshot(PathBuf),
    /// Close the viewer.
    Quit,
}

/// Reads a script file.
pub fn load(path: &Path) -> Result<Vec<Command>, ViewError> {
    let text = std::fs::read_to_string(path).map_err(|error| ViewError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    parse(&text, path)
}

/// Parses a script (`path` names it in errors).
pub fn parse(text: &str, path: &Path) -> Result<Vec<Command>, ViewError> {
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let err = |expected: String| ViewError::Script {
            path: path.to_path_buf(),
            line: i + 1,
            text: raw.trim().to_string(),
            expected,
        };
        let mut words = line.split_whitespace();
        let verb = words.next().unwrap_or("");
        let args: Vec<&str> = words.collect();
        let nums = |n: usize, what: &str| -> Result<Vec<f64>, ViewError> {
            let v: Vec<f64> = args.iter().filter_map(|a| a.parse().ok()).collect();
            if args.len() == n && v.len() == n && v.iter().all(|x| x.is_finite()) {
                Ok(v)
            } else {
                Err(err(format!("{verb} {what}")))
            }
        };
        out.push(match verb {
            "orbit" => {
                let v = nums(2, "AZIMUTH ELEVATION (degrees)")?;
                Command::Orbit(v[0], v[1])
            }
            "pan" => {
                let v = nums(2, "DX DY (pixels)")?;
                Command::Pan(v[0], v[1])
            }
            "zoom" => match nums(1, "FACTOR (a number > 0)")?[0] {
                f if f > 0.0 => Command::Zoom(f),
                _ => return Err(err("zoom FACTOR (a number > 0)".into())),
            },
            "key" => match args.as_slice() {
                [k] => Command::Key(
                    action(k).ok_or_else(|| err(format!("key NAME, one of: {}", key_names())))?,
                ),
                _ => return Err(err(format!("key NAME, one of: {}", key_names()))),
            },
            "frame" => match args.as_slice() {
                [k] => Command::Frame(
                    k.parse()
                        .map_err(|_| err("frame K (a time step, 0-based)".into()))?,
                ),
                _ => return Err(err("frame K (a time step, 0-based)".into())),
            },
            "wait-frames" => match args.as_slice() {
                [n] => Command::WaitFrames(
                    n.parse()
                        .map_err(|_| err("wait-frames N (a whole number)".into()))?,
                ),
                _ => return Err(err("wait-frames N (a whole number)".into())),
            },
            "wait-still" if args.is_empty() => Command::WaitStill,
            "screenshot" => match args.as_slice() {
                [p] => Command::Screenshot(PathBuf::from(p)),
                _ => return Err(err("screenshot FILE.png (no spaces)".into())),
            },
            "quit" if args.is_empty() => Command::Quit,
            _ => {
                return Err(err(
                    "orbit, pan, zoom, key, frame, wait-frames, wait-still, screenshot or quit"
                        .into(),
                ))
            }
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use render::Mode;

    #[test]
    fn every_command_parses() {
        let s = "# a tour\n\norbit 30 -5\npan 4 2.5 # right, up\nzoom 1.5\nkey v\nkey 2\n\
                 frame 3\nwait-frames 5\nwait-still\nscreenshot a.png\nquit\n";
        let c = parse(s, Path::new("t")).unwrap();
        assert_eq!(
            c,
            vec![
                Command::Orbit(30.0, -5.0),
                Command::Pan(4.0, 2.5),
                Command::Zoom(1.5),
                Command::Key(Action::NextMode),
                Command::Key(Action::Mode(Mode::Volume)),
                Command::Frame(3),
                Command::WaitFrames(5),
                Command::WaitStill,
                Command::Screenshot("a.png".into()),
                Command::Quit,
            ]
        );
    }

    #[test]
    fn bad_lines_name_the_file_line_and_what_was_expected() {
        for (line, want) in [
            ("orbit 30", "AZIMUTH ELEVATION"),
            ("orbit 30 nan", "AZIMUTH ELEVATION"),
            ("zoom 0", "FACTOR"),
            ("zoom -2", "FACTOR"),
            ("key F13", "one of: 1 2"),
            ("frame -1", "frame K"),
            ("wait-frames x", "wait-frames N"),
            ("screenshot", "screenshot FILE"),
            ("fly 3", "orbit, pan"),
            ("quit now", "orbit, pan"),
        ] {
            let text = format!("orbit 1 1\n{line}\n");
            let e = parse(&text, Path::new("tour.txt")).unwrap_err().to_string();
            assert!(e.starts_with("tour.txt:2:"), "{e}");
            assert!(e.contains(want), "{line}: {e}");
        }
    }
}
