//! A series against frames rendered one at a time (the same camera and colour range give the
//! same bytes), the one pass through a gzip dump (decoded bytes counted), the GIF's frame
//! count, and the refusals.

use std::io::Read;
use std::path::{Path, PathBuf};

use molecule::read::{open, ReadOptions};
use render::{render_frame, FrameInputs, Framebuffer, RenderSettings};
use scene::{ColorBy, Colormap, ModelSettings, Orbit, Scene, SceneSettings, View};
use series::{
    render_series, CameraChoice, FrameRange, OutputKind, SeriesError, SeriesSettings, Sink,
};
use spmd::Isa;

fn data(name: &str) -> PathBuf {
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    crate_dir
        .ancestors()
        .map(|a| a.join("shared/data").join(name))
        .find(|d| d.exists())
        .unwrap_or_else(|| panic!("no shared/data/{name} above {}", crate_dir.display()))
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bnsview-series-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The first `frames` frames of the water dump rewritten with a column `h` = the atom's
/// height z (Å), which changes from frame to frame, as a plain dump in `dir`.
fn water_with_height(dir: &Path, frames: usize) -> PathBuf {
    use std::fmt::Write;
    let mut t = open(&data("spce_water.lammpstrj.gz"), &ReadOptions::default()).unwrap();
    let mut s = String::new();
    for k in 0..frames {
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
    }
    let p = dir.join("water_h.lammpstrj");
    std::fs::write(&p, s).unwrap();
    p
}

/// Water coloured by the height column `h` of [`water_with_height`].
fn settings(frames: FrameRange, pipelined: bool) -> SeriesSettings {
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
fn by_element(frames: FrameRange) -> SeriesSettings {
    let mut s = settings(frames, true);
    s.scene.model.as_mut().unwrap().color = ColorBy::Element;
    s
}

fn png(p: &Path) -> Vec<u8> {
    image::open(p).unwrap().to_rgba8().into_raw()
}

#[test]
fn every_frame_equals_that_frame_rendered_alone_with_the_printed_camera_and_range() {
    for pipelined in [true, false] {
        let d = scratch(&format!("alone-{pipelined}"));
        let dump = water_with_height(&d, 11);
        let pattern = d.join("w_%03d.png");
        let s = settings("0:11:5".parse().unwrap(), pipelined);
        let mut traj = open(&dump, &ReadOptions::default()).unwrap();
        let mut sink = Sink::open(&OutputKind::from_path(&pattern).unwrap(), false, 10.0).unwrap();
        let mut seen = Vec::new();
        let report = render_series(&mut traj, &s, &mut sink, &mut |r| seen.push(r.frame)).unwrap();
        assert_eq!(seen, [0, 5, 10]);
        assert_eq!(report.frames, 3);
        let camera = report.camera.unwrap();
        let range = report.color_range.unwrap();
        for k in seen {
            let m = open(&dump, &ReadOptions::default())
                .unwrap()
                .read_frame(k)
                .unwrap();
            let mut st = s.scene.clone();
            if let ColorBy::Column { range: r, .. } = &mut st.model.as_mut().unwrap().color {
                *r = Some(range);
            }
            let sc = Scene::build(s.isa, &m, &st).unwrap();
            let mut fb = Framebuffer::new(64, 48, s.render.background_packed()).unwrap();
            render_frame(
                &FrameInputs::geometry(sc.model.as_ref().unwrap(), &camera),
                &s.render,
                &mut fb,
                s.isa,
            )
            .unwrap();
            let file = d.join(format!("w_{k:03}.png"));
            assert_eq!(
                png(&file),
                fb.as_bytes().to_vec(),
                "frame {k}, pipelined {pipelined}"
            );
        }
        // The range is the first frame's, not each frame's own: frame 10 alone differs.
        let m = open(&dump, &ReadOptions::default())
            .unwrap()
            .read_frame(10)
            .unwrap();
        let own = Scene::build(s.isa, &m, &s.scene).unwrap();
        assert_ne!(own.model.unwrap().color_range, Some(range));
        std::fs::remove_dir_all(&d).ok();
    }
}

#[test]
fn a_gzip_dump_is_decompressed_once_and_a_gif_holds_the_frames_asked_for() {
    let dump = data("spce_water.lammpstrj.gz");
    let mut whole = Vec::new();
    flate2::read::MultiGzDecoder::new(std::fs::File::open(&dump).unwrap())
        .read_to_end(&mut whole)
        .unwrap();
    let d = scratch("gif");
    let gif = d.join("movie.gif");
    let mut traj = open(&dump, &ReadOptions::default()).unwrap();
    let mut sink = Sink::open(&OutputKind::from_path(&gif).unwrap(), false, 5.0).unwrap();
    let report = render_series(
        &mut traj,
        &by_element(FrameRange::ALL),
        &mut sink,
        &mut |_| {},
    )
    .unwrap();
    drop(sink);
    assert_eq!(report.frames, 11);
    assert_eq!(traj.decoded_bytes(), whole.len() as u64, "one pass");
    let frames = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
        std::fs::File::open(&gif).unwrap(),
    ))
    .map(|dec| image::AnimationDecoder::into_frames(dec).count())
    .unwrap();
    assert_eq!(frames, 11);
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn bad_outputs_and_empty_ranges_are_refused() {
    let d = scratch("refuse");
    for bad in ["plain.png", "two_%d_%d.png", "x.tiff"] {
        assert!(OutputKind::from_path(&d.join(bad)).is_err(), "{bad}");
    }
    assert!(matches!(
        OutputKind::from_path(&d.join("m.mp4")),
        Ok(OutputKind::Video(_))
    ));
    // An existing numbered file is not overwritten without force.
    std::fs::write(d.join("f_00000.png"), b"mine").unwrap();
    let pattern = d.join("f_%05d.png");
    let dump = data("spce_water.lammpstrj.gz");
    let mut traj = open(&dump, &ReadOptions::default()).unwrap();
    let mut sink = Sink::open(&OutputKind::from_path(&pattern).unwrap(), false, 10.0).unwrap();
    let e = render_series(
        &mut traj,
        &by_element("0:1".parse().unwrap()),
        &mut sink,
        &mut |_| {},
    )
    .unwrap_err();
    assert!(matches!(e, SeriesError::Exists(_)), "{e}");
    assert_eq!(std::fs::read(d.join("f_00000.png")).unwrap(), b"mine");
    // A GIF cut short by an error is removed, not left half written.
    let gif = d.join("cut.gif");
    let mut traj = open(&dump, &ReadOptions::default()).unwrap();
    let mut sink = Sink::open(&OutputKind::from_path(&gif).unwrap(), false, 10.0).unwrap();
    let no_column = settings(FrameRange::ALL, true);
    assert!(render_series(&mut traj, &no_column, &mut sink, &mut |_| {}).is_err());
    assert!(!gif.exists());
    // A range past the end of the file.
    let mut traj = open(&dump, &ReadOptions::default()).unwrap();
    let e = render_series(
        &mut traj,
        &by_element("50:60".parse().unwrap()),
        &mut sink,
        &mut |_| {},
    )
    .unwrap_err();
    assert!(matches!(e, SeriesError::NoFrames { count: 11, .. }), "{e}");
    std::fs::remove_dir_all(&d).ok();
}
