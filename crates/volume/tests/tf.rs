//! Transfer functions: the text format, the shipped file, and pre-integration against the
//! post-classification and a double-precision integral.

mod common;

use common::*;
use volume::*;

#[test]
fn transfer_function_text_format() {
    let text =
        "# density ramp\n0.0 0 0 0.5 0\n\n0.2, 0, 0, 0.5, 0   # transparent\n1.0 1 0.8 0.2 0.3\n";
    let tf = TransferFunction::parse(text, "ramp.tf").unwrap();
    assert_eq!(tf.table.len(), 256);
    assert_eq!(tf.table[0], [0.0, 0.0, 0.5, 0.0]);
    assert_eq!(tf.table[255], [1.0, 0.8, 0.2, 0.3]);
    assert_eq!(tf.table[51][3], 0.0); // 51/255 = 0.2
    let mid = tf.table[153]; // 0.6: halfway from 0.2 to 1.0
    assert!(
        (mid[0] - 0.5).abs() < 1e-5 && (mid[3] - 0.15).abs() < 1e-5,
        "{mid:?}"
    );

    let err = |t: &str| TransferFunction::parse(t, "x.tf").unwrap_err().to_string();
    assert_eq!(
        err("0 0 0 0 0\n0.5 1 1 1\n"),
        "x.tf:2: expected 5 numbers `value r g b a`, found 4 field(s)"
    );
    assert_eq!(
        err("0 0 0 0 0\n# c\n1 1 one 1 1\n"),
        "x.tf:3: g: \"one\" is not a number"
    );
    assert_eq!(
        err("0 0 0 0 1.5\n1 1 1 1 1\n"),
        "x.tf:1: a = 1.5 is outside [0, 1]"
    );
    assert_eq!(
        err("0.5 0 0 0 0\n0.25 1 1 1 1\n"),
        "x.tf:2: value 0.25 is less than the previous point's 0.5: values must not decrease"
    );
    assert_eq!(
        err("# only\n0 0 0 0 0\n"),
        "x.tf: need at least 2 control points `value r g b a`, found 1"
    );
    assert!(err("0 0 0 0 NaN\n1 1 1 1 1\n").starts_with("x.tf:1:"));
    let missing = TransferFunction::load(std::path::Path::new("/nonexistent/tf.txt")).unwrap_err();
    assert!(missing.to_string().starts_with("/nonexistent/tf.txt: "));
    for p in Preset::ALL {
        assert_eq!(p.name().parse::<Preset>().unwrap(), p);
    }
}

#[test]
fn preintegration_of_a_constant_segment_is_the_post_classification() {
    let tf = ramp_tf();
    let c = ClassifiedTf::new(&tf, 0.0, 1.0, 0.5);
    for i in [0usize, 60, 128, 200, 255] {
        for ch in 0..4 {
            let a = c.preint[(i * 256 + i) * 4 + ch];
            let b = c.post[i * 4 + ch];
            assert!((a - b).abs() < 1e-6, "bin {i} channel {ch}: {a} vs {b}");
        }
    }
    // A rising segment is less opaque than its back value and more than its front one.
    let (f, b) = (100usize, 220usize);
    let a = c.preint[(f * 256 + b) * 4 + 3];
    assert!(a > c.post[f * 4 + 3] && a < c.post[b * 4 + 3]);
    // Order matters for colour (what is in front is seen first), not for opacity.
    assert!((a - c.preint[(b * 256 + f) * 4 + 3]).abs() < 1e-6);
    assert_ne!(c.preint[(f * 256 + b) * 4], c.preint[(b * 256 + f) * 4]);
}

#[test]
fn shipped_transfer_function_file_parses() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tf/density-ramp.tf");
    let tf = TransferFunction::load(&path).unwrap();
    assert_eq!(tf.table[0][3], 0.0);
    assert!((tf.table[255][3] - 0.35).abs() < 1e-6);
    assert!(tf.table.windows(2).all(|w| w[1][3] >= w[0][3]));
}

#[test]
fn preintegration_table_matches_double_precision_integral() {
    let tf = ramp_tf();
    let c = ClassifiedTf::new(&tf, 0.0, 1.0, 0.5);
    let mut rng = Rng(17);
    let mut worst = 0.0f64;
    for _ in 0..2000 {
        let (f, b) = (
            (rng.next_u64() % 256) as usize,
            (rng.next_u64() % 256) as usize,
        );
        let want = preintegrate(&tf, f as f64, b as f64, 0.5);
        for (ch, w) in want.iter().enumerate() {
            worst = worst.max((c.preint[(f * 256 + b) * 4 + ch] as f64 - w).abs());
        }
    }
    assert!(worst < 2e-4, "table vs f64 integral: {worst}");
}
