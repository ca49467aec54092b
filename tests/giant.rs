//! Giant frames from the command line: a frame over 256 MiB is streamed to its PNG in bands
//! (the library test in crates/render/tests/driver.rs checks the pixels against the frame
//! rendered whole); what cannot be streamed is refused before the work.

mod common;
use common::{bnsview, refused, run, scratch};

/// Width and height from a PNG's IHDR chunk.
fn png_size(path: &std::path::Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n");
    let be = |o: usize| u32::from_be_bytes(b[o..o + 4].try_into().unwrap());
    (be(16), be(20))
}

#[test]
fn a_frame_over_256_mib_is_streamed_in_bands_to_a_png() {
    let d = scratch("giant");
    let out = d.join("wall.png");
    // 8208x8192: 269 MB whole, so streamed in bands of 2032 rows.
    let args = ["render", "--scene", "nanobowl", "--atoms", "300", "-v"];
    let (ok, _, err) = run(bnsview()
        .args(args)
        .args(["--size", "8208x8192", "-o"])
        .arg(&out));
    assert!(ok, "{err}");
    assert!(err.contains("stream:  2032 rows a band"), "{err}");
    assert_eq!(png_size(&out), (8208, 8192));
    let decoded = image::open(&out).unwrap().into_rgba8();
    assert!(
        decoded.pixels().any(|p| p.0 != decoded.get_pixel(0, 0).0),
        "a blank frame"
    );
    // Nothing but the image is left beside it.
    let files: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(files, ["wall.png"]);
    // A JPEG or a legend of a streamed frame is refused before the work; nothing is written.
    let jpg = d.join("wall.jpg");
    let big = ["--size", "8208x8192", "-o"];
    refused(
        bnsview().args(args).args(big).arg(&jpg),
        &["streamed", ".png"],
    );
    assert!(!jpg.exists());
    let legend = ["--color", "q", "--legend"];
    let png = d.join("legend.png");
    refused(
        bnsview().args(args).args(legend).args(big).arg(&png),
        &["streamed", "leave out --legend"],
    );
    // A frame wider than PNG allows, or one whose band cannot be allocated, says so.
    for (size, wants) in [
        ("3000000000x16", "pixels a side"),
        ("2000000000x100", "make the frame narrower"),
    ] {
        refused(
            bnsview().args(args).args(["--size", size, "-o"]).arg(&png),
            &[wants],
        );
    }
    assert!(!png.exists());
    std::fs::remove_dir_all(d).ok();
}
