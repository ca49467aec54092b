//! Shared by the series tests: sample data, scratch directories, a water dump with a
//! per-frame height column, and the settings that colour by it.
#![allow(dead_code)] // each test binary uses a different part

use std::path::{Path, PathBuf};

use molecule::read::{open, ReadOptions};
use render::RenderSettings;
use scene::{ColorBy, Colormap, ModelSettings, Orbit, SceneSettings, View};
use series::{CameraChoice, FrameRange, SeriesSettings};
use spmd::Isa;

pub fn data(name: &str) -> PathBuf {
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    crate_dir
        .ancestors()
        .map(|a| a.join("shared/data").join(name))
        .find(|d| d.exists())
        .unwrap_or_else(|| panic!("no shared/data/{name} above {}", crate_dir.display()))
}

pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bnsview-series-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The first `frames` frames of the water dump rewritten with a column `h` = the atom's
/// height z (Å), which changes from frame to frame, as a plain dump in `dir`.
pub fn water_with_height(dir: &Path, frames: usize) -> PathBuf {
    let p = dir.join("water_h.lammpstrj");
    std::fs::write(&p, water_frames(frames).concat()).unwrap();
    p
}

/// The text of each frame of [`water_with_height`].
pub fn water_frames(frames: usize) -> Vec<String> {
    use std::fmt::Write;
    let mut t = open(&data("spce_water.lammpstrj.gz"), &ReadOptions::default()).unwrap();
    let mut out = Vec::new();
    for k in 0..frames {
        let mut s = String::new();
        let m = t.read_frame(k).unwrap();
        let c = m.cell.unwrap();
        let hi = [0, 1, 2].map(|a| c.origin[a] + c.edges[a][a]);
        write!(
            s,
            "ITEM: TIMESTEP\n{k}\nITEM: NUMBER OF ATOMS\n{}\n",
            m.len()
        )
        .unwrap();
        s.push_str("ITEM: BOX BOUNDS pp pp pp\n");
        for (lo, hi) in c.origin.iter().zip(hi) {
            writeln!(s, "{lo} {hi}").unwrap();
        }
        s.push_str("ITEM: ATOMS id type x y z h\n");
        for i in 0..m.len() {
            let ty = if m.elements[i] == 8 { 1 } else { 2 };
            writeln!(
                s,
                "{} {ty} {} {} {} {}",
                i + 1,
                m.x[i],
                m.y[i],
                m.z[i],
                m.z[i]
            )
            .unwrap();
        }
        out.push(s);
    }
    out
}

/// Water coloured by the height column `h` of [`water_with_height`].
pub fn settings(frames: FrameRange, pipelined: bool) -> SeriesSettings {
    SeriesSettings {
        frames,
        scene: SceneSettings {
            model: Some(ModelSettings {
                color: ColorBy::Column {
                    name: "h".into(),
                    colormap: Colormap::Viridis,
                    range: None,
                },
                ..ModelSettings::default()
            }),
            budget_bytes: Some(u64::MAX),
            ..SceneSettings::default()
        },
        render: RenderSettings::default(),
        size: (64, 48),
        camera: CameraChoice::Fit {
            view: View::Far,
            orbit: Orbit::default(),
            fov_deg: 45.0,
        },
        legend_ink: None,
        pipelined,
        isa: Isa::detect(),
    }
}

/// [`settings`] with CPK colours (for the plain water dump), pipelined.
pub fn by_element(frames: FrameRange) -> SeriesSettings {
    let mut s = settings(frames, true);
    s.scene.model.as_mut().unwrap().color = ColorBy::Element;
    s
}

pub fn png(p: &Path) -> Vec<u8> {
    image::open(p).unwrap().to_rgba8().into_raw()
}

/// Frames in the animated GIF at `p`, decoded.
pub fn gif_frames(p: &Path) -> usize {
    let dec = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
        std::fs::File::open(p).unwrap(),
    ))
    .unwrap();
    image::AnimationDecoder::into_frames(dec).count()
}
