//! A series against frames rendered one at a time (the same camera and colour range give the
//! same bytes), the one pass through a gzip dump (decoded bytes counted), the GIF's frame
//! count, and the refusals.

mod common;

use std::io::Read;

use common::{by_element, data, gif_frames, png, scratch, settings, water_with_height};
use molecule::read::{open, ReadOptions};
use render::{render_frame, FrameInputs, Framebuffer};
use scene::{ColorBy, Scene};
use series::{render_series, CameraChoice, FrameRange, OutputKind, SeriesError, Sink};

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
    assert_eq!(gif_frames(&gif), 11);
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
    // The water dump's frames `range` to `out`; the error.
    let fails = |range: &str, out: &std::path::Path| {
        let mut traj = open(&dump, &ReadOptions::default()).unwrap();
        let mut sink = Sink::open(&OutputKind::from_path(out).unwrap(), false, 10.0).unwrap();
        let s = by_element(range.parse().unwrap());
        render_series(&mut traj, &s, &mut sink, &mut |_| {}).unwrap_err()
    };
    let e = fails("0:1", &pattern);
    assert!(matches!(e, SeriesError::Exists(_)), "{e}");
    assert_eq!(std::fs::read(d.join("f_00000.png")).unwrap(), b"mine");
    // A GIF cut short by an error is removed, not left half written.
    let gif = d.join("cut.gif");
    let mut traj = open(&dump, &ReadOptions::default()).unwrap();
    let mut sink = Sink::open(&OutputKind::from_path(&gif).unwrap(), false, 10.0).unwrap();
    let no_column = settings(FrameRange::ALL, true);
    assert!(render_series(&mut traj, &no_column, &mut sink, &mut |_| {}).is_err());
    assert!(!gif.exists());
    // The error of opening the sink for `name` in scratch.
    let open_err = |name: &str| {
        Sink::open(&OutputKind::from_path(&d.join(name)).unwrap(), false, 10.0)
            .err()
            .unwrap()
    };
    // A numbered output in a missing directory is refused before any frame, once.
    let e = open_err("nodir/f_%05d.png");
    assert!(matches!(e, SeriesError::NoDirectory { .. }), "{e}");
    assert!(e.to_string().contains("nodir"), "{e}");
    // A file-system error says its cause once, in the message, not again as a source.
    let e = open_err("nodir/m.gif");
    assert!(std::error::Error::source(&e).is_none(), "{e}");
    assert!(e.to_string().contains("m.gif"), "{e}");
    // A range past the end of the file.
    let e = fails("50:60", &d.join("g_%05d.png"));
    assert!(matches!(e, SeriesError::NoFrames { count: 11, .. }), "{e}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn fit_all_holds_every_frame_tightly_and_fit_first_only_the_first() {
    use scene::{Camera, Orbit, View};
    let d = scratch("fitall");
    // A small bowl drifting 4 Å along x per frame.
    let base = molecule::scenes::generate(molecule::scenes::SceneName::Nanobowl, Some(400), 3);
    let path = d.join("drift.xyz");
    let mut text = Vec::new();
    for k in 0..6 {
        let mut m = base.clone();
        m.x.iter_mut().for_each(|x| *x += 4.0 * k as f32);
        molecule::write::write_xyz(&mut text, &m, &format!("frame {k}")).unwrap();
    }
    std::fs::write(&path, text).unwrap();
    let render = |fit_all: bool| {
        let mut s = by_element("0:6:2".parse().unwrap());
        let (view, orbit, fov_deg) = (View::Far, Orbit::default(), 45.0);
        s.camera = if fit_all {
            CameraChoice::FitAll {
                view,
                orbit,
                fov_deg,
            }
        } else {
            CameraChoice::Fit {
                view,
                orbit,
                fov_deg,
            }
        };
        let mut traj = open(&path, &ReadOptions::default()).unwrap();
        let out = d.join(format!("f{fit_all}_%d.png"));
        let mut sink = Sink::open(&OutputKind::from_path(&out).unwrap(), false, 10.0).unwrap();
        let r = render_series(&mut traj, &s, &mut sink, &mut |_| {}).unwrap();
        let sphere = r.fitted_to.unwrap();
        let camera = Camera::fit(view, sphere, fov_deg, 64.0 / 48.0, orbit);
        assert_eq!(r.camera, Some(camera));
        (s, sphere)
    };
    // Each rendered frame's scene sphere (built in full) and how far it reaches from `c`.
    let (s, all) = render(true);
    let reach = |c: [f32; 3], k: usize| {
        let m = open(&path, &ReadOptions::default())
            .unwrap()
            .read_frame(k)
            .unwrap();
        let f = Scene::build(s.isa, &m, &s.scene).unwrap().sphere;
        let d: f32 = (0..3)
            .map(|i| (f.center[i] - c[i]).powi(2))
            .sum::<f32>()
            .sqrt();
        d + f.radius
    };
    let reaches: Vec<f32> = [0, 2, 4].iter().map(|&k| reach(all.center, k)).collect();
    for (k, r) in reaches.iter().enumerate() {
        assert!(
            *r <= all.radius * 1.001,
            "frame {}: {r} > {}",
            2 * k,
            all.radius
        );
    }
    let widest = reaches.iter().copied().fold(0.0, f32::max);
    assert!(
        widest >= all.radius * 0.999,
        "not tight: {widest} < {}",
        all.radius
    );
    // Fitted to the first frame only, the last one sticks out.
    let (_, first) = render(false);
    assert!((reach(first.center, 0) - first.radius).abs() <= first.radius * 1e-3);
    assert!(reach(first.center, 4) > first.radius * 1.05);
    std::fs::remove_dir_all(&d).ok();
}
