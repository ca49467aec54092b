//! Where the frames of a series go: numbered image files (`out_%05d.png`, each written under a
//! temporary name and renamed, so a watcher never sees half a picture), one animated GIF, or
//! a video encoded by `ffmpeg` (frames piped to it as raw RGBA).

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use render::{Framebuffer, ImageFormat};

use crate::SeriesError;

/// Frames per second of an animated GIF when not given.
pub const DEFAULT_GIF_FPS: f32 = 10.0;

/// What the output path names.
#[derive(Clone, Debug, PartialEq)]
pub enum OutputKind {
    /// One PNG or JPEG per frame, the name from a pattern with one `%d` or `%0Nd` (the frame
    /// index in the file).
    Numbered(String),
    /// One animated GIF.
    Gif(PathBuf),
    /// A video (`.mp4`, `.mkv`, `.webm`, `.mov`, `.avi`) encoded by `ffmpeg`.
    Video(PathBuf),
}

impl OutputKind {
    /// The kind `path` names: `.gif`, or a `.png`/`.jpg` pattern holding `%d` or `%0Nd`.
    pub fn from_path(path: &Path) -> Result<OutputKind, SeriesError> {
        let s = path.to_string_lossy().into_owned();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        if ext == "gif" {
            return Ok(OutputKind::Gif(path.to_path_buf()));
        }
        if ["mp4", "mkv", "webm", "avi", "mov"].contains(&ext.as_str()) {
            return Ok(OutputKind::Video(path.to_path_buf()));
        }
        ImageFormat::from_path(path)?;
        if expand(&s, 0).is_none() {
            return Err(SeriesError::Pattern(s));
        }
        Ok(OutputKind::Numbered(s))
    }
}

/// The numbered images a series of `input` goes to when no output is given:
/// `STEM_%05d.png`, STEM the file name up to its first dot.
pub fn default_output(input: &Path) -> PathBuf {
    let name = input.file_name().map(|s| s.to_string_lossy().into_owned());
    let stem = name
        .as_deref()
        .and_then(|n| n.split('.').next())
        .filter(|s| !s.is_empty());
    PathBuf::from(format!("{}_%05d.png", stem.unwrap_or("bnsview")))
}

/// `pattern` with its one `%d` / `%0Nd` replaced by `k`; `None` without exactly one.
pub fn expand(pattern: &str, k: usize) -> Option<String> {
    let start = pattern.find('%')?;
    let rest = &pattern[start + 1..];
    let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    let after = rest[digits.len()..].strip_prefix('d')?;
    if after.contains('%') {
        return None;
    }
    let width: usize = if digits.is_empty() {
        0
    } else {
        digits.parse().ok().filter(|&w| w <= 12)?
    };
    Some(format!("{}{k:0width$}{after}", &pattern[..start]))
}

/// An open output.
pub enum Sink {
    /// Numbered files.
    Files {
        /// The pattern.
        pattern: String,
        /// Overwrite existing files.
        force: bool,
        /// Files written so far.
        written: Vec<PathBuf>,
    },
    /// An animated GIF being written.
    Gif {
        /// The file.
        path: PathBuf,
        /// The encoder (frames are written as they come).
        encoder: Box<image::codecs::gif::GifEncoder<BufWriter<File>>>,
        /// Delay per frame.
        delay: image::Delay,
        /// Frames written.
        frames: usize,
    },
    /// A video: `ffmpeg` started at the first frame (when the size is known).
    Video {
        /// The file.
        path: PathBuf,
        /// Frames per second.
        fps: f32,
        /// The encoder process, once started.
        child: Option<std::process::Child>,
    },
}

impl Sink {
    /// Opens `kind` (a GIF is created now: refused if it exists and `force` is off; numbered
    /// files are checked one by one as they are written).
    pub fn open(kind: &OutputKind, force: bool, gif_fps: f32) -> Result<Sink, SeriesError> {
        match kind {
            OutputKind::Numbered(p) => {
                let dir = Path::new(p).parent().filter(|d| !d.as_os_str().is_empty());
                if let Some(dir) = dir.filter(|d| !d.is_dir()) {
                    return Err(SeriesError::NoDirectory {
                        pattern: p.clone(),
                        dir: dir.display().to_string(),
                    });
                }
                Ok(Sink::Files {
                    pattern: p.clone(),
                    force,
                    written: Vec::new(),
                })
            }
            OutputKind::Gif(path) => {
                refuse_existing(path, force)?;
                let file = File::create(path).map_err(|e| SeriesError::io(path, e))?;
                let mut encoder = image::codecs::gif::GifEncoder::new(BufWriter::new(file));
                encoder
                    .set_repeat(image::codecs::gif::Repeat::Infinite)
                    .map_err(|e| SeriesError::image(path, e))?;
                let fps = if gif_fps.is_finite() && gif_fps > 0.0 {
                    gif_fps
                } else {
                    DEFAULT_GIF_FPS
                };
                let ms = (1000.0 / fps).round().clamp(10.0, 60_000.0) as u32;
                Ok(Sink::Gif {
                    path: path.clone(),
                    encoder: Box::new(encoder),
                    delay: image::Delay::from_numer_denom_ms(ms, 1),
                    frames: 0,
                })
            }
            OutputKind::Video(path) => {
                refuse_existing(path, force)?;
                // Fail now, not after the first frame, when there is no encoder.
                let found = std::process::Command::new("ffmpeg")
                    .arg("-version")
                    .stdout(std::process::Stdio::null())
                    .stderr(std::process::Stdio::null())
                    .status()
                    .is_ok();
                if !found {
                    return Err(SeriesError::Video(path.display().to_string()));
                }
                Ok(Sink::Video {
                    path: path.clone(),
                    fps: if gif_fps.is_finite() && gif_fps > 0.0 {
                        gif_fps
                    } else {
                        DEFAULT_GIF_FPS
                    },
                    child: None,
                })
            }
        }
    }

    /// Removes a GIF or video left unfinished by an error (numbered files already written
    /// are complete and stay).
    pub fn abandon(&mut self) {
        match self {
            Sink::Files { .. } => {}
            Sink::Gif { path, .. } => {
                std::fs::remove_file(path).ok();
            }
            Sink::Video { path, child, .. } => {
                if let Some(mut c) = child.take() {
                    c.kill().ok();
                    c.wait().ok();
                }
                std::fs::remove_file(path).ok();
            }
        }
    }

    /// Finishes the output: closes a video encoder's input and waits for it. (Numbered files
    /// are complete as written; a GIF is finished when the sink is dropped.)
    pub fn finish(&mut self) -> Result<(), SeriesError> {
        if let Sink::Video { path, child, .. } = self {
            if let Some(mut c) = child.take() {
                drop(c.stdin.take());
                let status = c.wait().map_err(|e| SeriesError::io(path, e))?;
                if !status.success() {
                    return Err(SeriesError::io(
                        path,
                        std::io::Error::other(format!("ffmpeg failed ({status})")),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The file frame `k` goes to (numbered files) or the GIF.
    pub fn target(&self, k: usize) -> PathBuf {
        match self {
            Sink::Files { pattern, .. } => PathBuf::from(expand(pattern, k).unwrap_or_default()),
            Sink::Gif { path, .. } | Sink::Video { path, .. } => path.clone(),
        }
    }

    /// Writes frame `k` of the file.
    pub fn write(&mut self, k: usize, fb: &Framebuffer) -> Result<PathBuf, SeriesError> {
        let target = self.target(k);
        match self {
            Sink::Files { force, written, .. } => {
                refuse_existing(&target, *force)?;
                // Write beside the target and rename: readers never see a partial image.
                let name = target.file_name().map(|n| n.to_string_lossy().into_owned());
                let tmp = target.with_file_name(format!(
                    ".{}.part.{}",
                    name.unwrap_or_default(),
                    target.extension().and_then(|e| e.to_str()).unwrap_or("png")
                ));
                let format = ImageFormat::from_path(&target)?;
                let saved = match format {
                    ImageFormat::Png => fb.save_png(&tmp),
                    ImageFormat::Jpeg => fb.save_jpeg(&tmp),
                };
                if let Err(e) = saved {
                    std::fs::remove_file(&tmp).ok();
                    return Err(e.into());
                }
                std::fs::rename(&tmp, &target).map_err(|e| SeriesError::io(&target, e))?;
                written.push(target.clone());
            }
            Sink::Gif {
                path,
                encoder,
                delay,
                frames,
            } => {
                let img =
                    image::RgbaImage::from_raw(fb.width, fb.height, fb.as_bytes().into_owned())
                        .ok_or_else(|| {
                            SeriesError::io(path, std::io::Error::other("frame size"))
                        })?;
                encoder
                    .encode_frame(image::Frame::from_parts(img, 0, 0, *delay))
                    .map_err(|e| SeriesError::image(path, e))?;
                *frames += 1;
            }
            Sink::Video { path, fps, child } => {
                use std::io::Write;
                if child.is_none() {
                    let c = std::process::Command::new("ffmpeg")
                        .args(["-loglevel", "error", "-nostdin", "-y", "-f", "rawvideo"])
                        .args(["-pix_fmt", "rgba", "-s"])
                        .arg(format!("{}x{}", fb.width, fb.height))
                        .arg("-framerate")
                        .arg(fps.to_string())
                        .args(["-i", "-", "-pix_fmt", "yuv420p"])
                        // yuv420p needs even sizes: pad odd ones by a pixel.
                        .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2"])
                        .arg(path.as_os_str())
                        .stdin(std::process::Stdio::piped())
                        .spawn()
                        .map_err(|_| SeriesError::Video(path.display().to_string()))?;
                    *child = Some(c);
                }
                let stdin = child.as_mut().and_then(|c| c.stdin.as_mut());
                let Some(stdin) = stdin else {
                    return Err(SeriesError::io(
                        path,
                        std::io::Error::other("ffmpeg input closed"),
                    ));
                };
                stdin
                    .write_all(&fb.as_bytes())
                    .map_err(|e| SeriesError::io(path, e))?;
            }
        }
        Ok(target)
    }
}

fn refuse_existing(path: &Path, force: bool) -> Result<(), SeriesError> {
    if !force && path.exists() {
        return Err(SeriesError::Exists(path.to_path_buf()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_expand_once() {
        assert_eq!(expand("out_%05d.png", 42).unwrap(), "out_00042.png");
        assert_eq!(expand("f%d.jpg", 7).unwrap(), "f7.jpg");
        assert_eq!(expand("a/b_%3d.png", 1234).unwrap(), "a/b_1234.png");
        for bad in ["out.png", "out_%s.png", "%d_%d.png", "%x.png"] {
            assert!(expand(bad, 1).is_none(), "{bad}");
        }
    }
}
