//! A frame read the caller stops (`Trajectory::read_frame_unless`): stopped before its first
//! buffer or in the middle of the frame, it says "cancelled" and has decoded no more than the
//! buffers it was let read; the trajectory then reads that frame and the others exactly as a
//! fresh reader does, plain and gzip-compressed.

use std::io::Write;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use molecule::read::{open, ReadError, ReadOptions};
use molecule::scenes::{generate, SceneName};
use molecule::write::write_xyz;

#[test]
fn a_cancelled_read_stops_and_the_next_read_starts_afresh() {
    let dir = std::env::temp_dir().join(format!("bns_cancel_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // 100K atoms: a frame of about 3 MB, three buffers of the reader's 1 MiB.
    let frames: Vec<_> = (0..3)
        .map(|k| generate(SceneName::Ns90k, Some(100_000), k + 1))
        .collect();
    let mut text = Vec::new();
    let mut starts = Vec::new();
    for (k, m) in frames.iter().enumerate() {
        starts.push(text.len() as u64);
        write_xyz(&mut text, m, &format!("frame {k}")).unwrap();
    }
    let frame_bytes = text.len() as u64 / 3;
    assert!(frame_bytes > 2 << 20, "{frame_bytes}");
    let plain = dir.join("three.xyz");
    std::fs::write(&plain, &text).unwrap();
    let gz = dir.join("three.xyz.gz");
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    enc.write_all(&text).unwrap();
    std::fs::write(&gz, enc.finish().unwrap()).unwrap();

    for path in [&plain, &gz] {
        let mut t = open(path, &ReadOptions::default()).unwrap();
        t.count_frames().unwrap();
        let before = t.decoded_bytes();
        // Stopped before it starts: nothing decoded.
        let e = t.read_frame_unless(1, Arc::new(|| true)).unwrap_err();
        assert!(matches!(e, ReadError::Cancelled { .. }), "{e}");
        assert!(e.to_string().contains("cancelled"), "{e}");
        assert_eq!(t.decoded_bytes(), before, "{}", path.display());
        // Stopped at its second refill (the test's third call): one buffer of the frame
        // decoded, less than the frame (a gzip stream is first decompressed from its start
        // up to the frame's: that is the seek, not the read).
        let seek = if path == &gz { starts[1] } else { 0 };
        let calls = Arc::new(AtomicUsize::new(0));
        let c = calls.clone();
        let second = Arc::new(move || c.fetch_add(1, Ordering::Relaxed) >= 2);
        let before = t.decoded_bytes();
        let e = t.read_frame_unless(1, second).unwrap_err();
        assert!(matches!(e, ReadError::Cancelled { .. }), "{e}");
        assert_eq!(calls.load(Ordering::Relaxed), 3, "{}", path.display());
        let read = t.decoded_bytes() - before - seek;
        assert!(
            read > 0 && read < frame_bytes,
            "{}: {read} of {frame_bytes}",
            path.display()
        );
        // Then every frame as a fresh reader reads it, in any order.
        let fresh = |k: usize| {
            let mut f = open(path, &ReadOptions::default()).unwrap();
            f.read_frame(k).unwrap()
        };
        for k in [1, 2, 0, 1] {
            let (m, want) = (t.read_frame(k).unwrap(), fresh(k));
            assert_eq!(m.len(), frames[k].len(), "{} frame {k}", path.display());
            assert!(
                (&m.x, &m.y, &m.z) == (&want.x, &want.y, &want.z),
                "frame {k}"
            );
        }
        // A read never cancelled is the plain read.
        let m = t.read_frame_unless(2, Arc::new(|| false)).unwrap();
        assert!(m.y == fresh(2).y);
    }
    std::fs::remove_dir_all(&dir).ok();
}
