//! The driver's partial renders against the whole frame, bit for bit: the union of every rank's
//! interleaved tiles and of row bands is the frame that one call renders, and a path-traced
//! frame is its accumulation (what MPI ranks, giant-frame bands and the viewer rely on); a
//! frame streamed band by band into a PNG decodes to the frame rendered whole.

use molecule::scenes::{generate, SceneName};
use std::path::PathBuf;

use render::{
    accumulate, band_rows, render_frame, render_frame_with_progress, render_png_streamed,
    render_rows, render_tiles, Accum, BandEncoder, Camera, FrameInputs, Framebuffer, Material,
    Modality, PngStream, RenderSettings, TileSet, View, DARK_BACKGROUND,
};
use scene::{Scene, SceneSettings, VolumeSettings};
use spmd::Isa;
use volume::{Lighting, MarchOptions};

/// A small nanobowl with geometry and a coarse density volume.
fn scene() -> Scene {
    let m = generate(SceneName::Nanobowl, Some(400), 3);
    let settings = SceneSettings {
        volume: Some(VolumeSettings {
            voxels_per_angstrom: 1.5,
            ..VolumeSettings::default()
        }),
        ..SceneSettings::default()
    };
    Scene::build(Isa::detect(), &m, &settings).unwrap()
}

/// One setting per integrator: headlight b&s, lit vol+b&s, shadows, AO, path (3 spp).
fn settings() -> Vec<(&'static str, RenderSettings, bool)> {
    let lit = MarchOptions {
        lighting: Lighting::Headlight,
        ..MarchOptions::default()
    };
    let traced = |m| RenderSettings::traced(m, DARK_BACKGROUND);
    vec![
        ("bs", RenderSettings::default(), false),
        (
            "vol+bs lit",
            RenderSettings {
                march: lit,
                ..RenderSettings::headlight(DARK_BACKGROUND)
            },
            true,
        ),
        ("shadows", traced(Modality::Direct { shadows: true }), false),
        (
            "ao",
            traced(Modality::Ao {
                samples: 3,
                distance: 4.0,
            }),
            false,
        ),
        (
            "path",
            RenderSettings {
                spp: 3,
                ..traced(Modality::Path {
                    material: Material::Diffuse,
                    max_depth: 3,
                    roughness: 0.0,
                })
            },
            false,
        ),
    ]
}

// An odd size: partial tiles on the right and bottom edges.
const W: u32 = 53;
const H: u32 = 37;

#[test]
fn every_ranks_tiles_together_are_the_whole_frame() {
    let sc = scene();
    let cam = Camera::view(
        View::Far,
        sc.sphere.center,
        sc.sphere.radius,
        45.0,
        W as f32 / H as f32,
    );
    for_every_case(&sc, &cam, (W, H), |isa, name, set, inp, whole| {
        for ranks in [1, 2, 3, 7] {
            // Every rank renders into the same buffer; each pixel is written by one rank.
            let mut union = Framebuffer::new(W, H, 0x1234_5678).unwrap();
            for rank in 0..ranks {
                render_tiles(
                    inp,
                    set,
                    TileSet::Interleaved { rank, ranks },
                    &mut union,
                    isa,
                )
                .unwrap();
            }
            assert!(
                union == *whole,
                "{isa} {name}: {ranks} ranks differ from one frame"
            );
        }
        // A rank's own tiles alone leave the others untouched.
        let mut one = Framebuffer::new(W, H, 7).unwrap();
        render_tiles(
            inp,
            set,
            TileSet::Interleaved { rank: 1, ranks: 2 },
            &mut one,
            isa,
        )
        .unwrap();
        let untouched = one.pixels.iter().filter(|&&p| p == 7).count();
        assert!(
            untouched > 0 && untouched < one.pixels.len(),
            "{isa} {name}"
        );
    });
}

#[test]
fn row_bands_together_are_the_whole_frame() {
    let sc = scene();
    let cam = Camera::view(
        View::Close,
        sc.sphere.center,
        sc.sphere.radius,
        45.0,
        W as f32 / H as f32,
    );
    for_every_case(&sc, &cam, (W, H), |isa, name, set, inp, whole| {
        // Bands that start and end inside tiles, one a single row.
        let mut rows = Vec::new();
        for (a, b) in [(0, 5), (5, 6), (6, 20), (20, H)] {
            let mut band = vec![0u32; ((b - a) * W) as usize];
            render_rows(inp, set, TileSet::All, W, H, a..b, &mut band, isa).unwrap();
            rows.extend(band);
        }
        assert!(
            rows == whole.pixels,
            "{isa} {name}: bands differ from one frame"
        );
        // The progress bar's bands: the same frame, rows reported in order up to H.
        let mut banded = Framebuffer::new(W, H, 0).unwrap();
        let mut done = Vec::new();
        render_frame_with_progress(inp, set, &mut banded, isa, &mut |d, h| done.push((d, h)))
            .unwrap();
        assert!(banded == *whole, "{isa} {name}: progress bands differ");
        assert!(done.len() > 1 && done.last() == Some(&(H, H)), "{done:?}");
        assert!(done.windows(2).all(|p| p[0].0 < p[1].0), "{done:?}");
    });
}

#[test]
fn a_whole_path_traced_frame_is_its_accumulation_tone_mapped() {
    // (How samples split between `accumulate` calls is tested in modalities.rs.)
    let sc = scene();
    let model = sc.model.as_ref().unwrap();
    let cam = Camera::view(
        View::Far,
        sc.sphere.center,
        sc.sphere.radius,
        45.0,
        W as f32 / H as f32,
    );
    let inp = FrameInputs::geometry(model, &cam);
    for isa in Isa::under_test() {
        for (name, set, _) in settings().into_iter().filter(|(_, s, _)| s.is_linear()) {
            let mut acc = Accum::new(W, H).unwrap();
            accumulate(&inp, &set, &mut acc, set.spp, isa).unwrap();
            let mut fb = Framebuffer::new(W, H, 0).unwrap();
            render_frame(&inp, &set, &mut fb, isa).unwrap();
            assert!(fb == acc.to_framebuffer(true, set.exposure), "{isa} {name}");
        }
    }
}

/// A fresh directory for this test's files.
fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bns-render-{}-{name}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The RGBA bytes of a PNG, decoded by the `image` crate.
fn decode(path: &std::path::Path) -> (u32, u32, Vec<u8>) {
    let im = image::open(path).unwrap().into_rgba8();
    (im.width(), im.height(), im.into_raw())
}

/// Calls `check(isa, name, settings, inputs, whole)` for every backend under test and every
/// setting of [`settings`]: the scene `sc` seen by `cam` (its volume only where the setting
/// wants it), `whole` the `size` frame one call of the driver renders.
fn for_every_case(
    sc: &Scene,
    cam: &Camera,
    (w, h): (u32, u32),
    mut check: impl FnMut(Isa, &str, &RenderSettings, &FrameInputs, &Framebuffer),
) {
    for isa in Isa::under_test() {
        for (name, set, vol) in settings() {
            let vs = sc.volume_scene(set.march).filter(|_| vol);
            let inp = FrameInputs {
                model: sc.model.as_deref(),
                volume: vs.as_ref(),
                camera: cam,
            };
            let mut whole = Framebuffer::new(w, h, 0).unwrap();
            render_frame(&inp, &set, &mut whole, isa).unwrap();
            check(isa, name, &set, &inp, &whole);
        }
    }
}

/// Streams the frame of `whole`'s size into `path` in bands of `rows` rows and checks the
/// decoded PNG is `whole`; returns the rows reported done and the rays cast.
fn assert_streamed_is_whole(
    inp: &FrameInputs,
    set: &RenderSettings,
    whole: &Framebuffer,
    rows: u32,
    path: &std::path::Path,
    isa: Isa,
) -> (Vec<u32>, u64) {
    let (w, h) = (whole.width, whole.height);
    let mut done = Vec::new();
    let stats =
        render_png_streamed(inp, set, (w, h), rows, path, isa, &mut |d, _| done.push(d)).unwrap();
    let (dw, dh, bytes) = decode(path);
    assert!(
        (dw, dh) == (w, h) && bytes == *whole.as_bytes(),
        "{isa}, bands of {rows} rows: the streamed PNG differs from the frame rendered whole"
    );
    (done, stats.rays)
}

#[test]
fn a_frame_streamed_in_bands_decodes_to_the_frame_rendered_whole() {
    let dir = temp_dir("streamed");
    let sc = scene();
    let (w, h) = (203, 150); // partial tiles at both edges; bands of 32 rows: five bands
    let cam = Camera::view(
        View::Far,
        sc.sphere.center,
        sc.sphere.radius,
        45.0,
        203.0 / 150.0,
    );
    for_every_case(&sc, &cam, (w, h), |isa, name, set, inp, whole| {
        let path = dir.join(format!("{name}-{isa}.png"));
        let (done, rays) = assert_streamed_is_whole(inp, set, whole, 32, &path, isa);
        assert_eq!(done, [32, 64, 96, 128, 150], "{isa} {name}");
        assert_eq!(rays, u64::from(w * h * set.frame_samples()), "{isa} {name}");
    });
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn a_4096_square_frame_streamed_in_bands_is_the_frame_rendered_whole() {
    let dir = temp_dir("streamed4096");
    let sc = scene();
    let (w, h) = (4096, 4096);
    let cam = Camera::view(View::Close, sc.sphere.center, sc.sphere.radius, 45.0, 1.0);
    let inp = FrameInputs::geometry(sc.model.as_ref().unwrap(), &cam);
    let set = RenderSettings::default();
    let isa = Isa::detect();
    let mut whole = Framebuffer::new(w, h, 0).unwrap();
    render_frame(&inp, &set, &mut whole, isa).unwrap();
    // The band a frame this wide gets (4,096 rows: one band) and eight of 512 rows.
    assert_eq!(band_rows(w), 4096);
    for rows in [band_rows(w), 512] {
        let path = dir.join(format!("bands-{rows}.png"));
        assert_streamed_is_whole(&inp, &set, &whole, rows, &path, isa);
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn a_stream_dropped_unfinished_leaves_the_old_file_and_no_partial_one() {
    let dir = temp_dir("unfinished");
    let path = dir.join("frame.png");
    std::fs::write(&path, b"the user's old image").unwrap();
    let mut png = PngStream::create(&path, (16, 4)).unwrap();
    png.write_rows(&[0xff00_00ff; 32]).unwrap();
    assert_eq!(png.rows(), 2);
    drop(png); // a band failed: two rows of four written
    assert_eq!(std::fs::read(&path).unwrap(), b"the user's old image");
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["frame.png"], "only the old file is left");
    // Finished, it replaces the file.
    let mut png = PngStream::create(&path, (16, 4)).unwrap();
    png.write_rows(&[0xff00_00ff; 64]).unwrap();
    png.finish().unwrap();
    let (w, h, bytes) = decode(&path);
    assert!((w, h) == (16, 4) && bytes.chunks(4).all(|p| p == [255, 0, 0, 255]));
    // Through the encoder thread: two bands, finished; dropped unfinished, nothing is left.
    let mut enc =
        BandEncoder::spawn(PngStream::create(&path, (16, 4)).unwrap(), vec![0; 32]).unwrap();
    let back = enc.write(vec![0xff00_ff00; 32], 32).unwrap();
    assert_eq!(back.len(), 32, "the spare buffer");
    enc.write(back.iter().map(|_| 0xffff_0000).collect(), 32)
        .unwrap();
    enc.finish().unwrap();
    let (_, _, bytes) = decode(&path);
    assert!(bytes[..128].chunks(4).all(|p| p == [0, 255, 0, 255]));
    assert!(bytes[128..].chunks(4).all(|p| p == [0, 0, 255, 255]));
    let mut enc =
        BandEncoder::spawn(PngStream::create(&path, (16, 4)).unwrap(), vec![0; 32]).unwrap();
    enc.write(vec![0; 32], 32).unwrap();
    drop(enc);
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["frame.png"], "the finished image only");
    let (_, _, again) = decode(&path);
    assert_eq!(again, bytes, "the earlier image is kept");
    // A directory that is not there: the error names the file.
    let missing = dir.join("no-such-dir").join("frame.png");
    let err = PngStream::create(&missing, (16, 4))
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("no-such-dir/frame.png"), "{err}");
    std::fs::remove_dir_all(dir).ok();
}
