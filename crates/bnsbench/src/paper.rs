//! The paper's figures (Knoll, Wald et al., UltraVis 2013, §5): a dual 8-core (16 cores)
//! 2.7 GHz Xeon E5-2680 (Sandy Bridge, 8-wide AVX), 1024×1024 unless stated otherwise.

use molecule::scenes::SceneName;

use crate::mode::BenchMode;

/// Cores of the paper's CPU node.
pub const PAPER_CORES: f64 = 16.0;

/// Table 3, rows "bnsView (CPU) Intel Xeon E5-2680": fps (far, close) at 1024² for the rows
/// b&s, volume, vol+b&s, vol+b&s lit, per scene.
pub fn paper_table3(scene: SceneName) -> [[f64; 2]; 4] {
    match scene {
        SceneName::Nanobowl => [[63.0, 55.0], [15.1, 7.94], [22.0, 15.0], [6.15, 4.02]],
        SceneName::Ns90k => [[42.0, 45.0], [8.75, 9.31], [8.6, 10.2], [2.42, 2.97]],
        SceneName::Ns740k => [[39.0, 40.0], [6.82, 7.91], [6.07, 7.85], [1.57, 2.46]],
        SceneName::Sio2 => [[33.0, 45.0], [15.3, 7.67], [13.3, 7.65], [4.51, 2.02]],
        SceneName::Anp3 => [[17.4, 30.0], [1.3, 4.0], [1.31, 6.4], [0.35, 1.91]],
    }
}

/// Table 3, preprocessing rows: (geometry MB, BVH MB, volume MB, voxels/Å, bond build s,
/// BVH build s, volume build s).
pub fn paper_preprocess(scene: SceneName) -> [f64; 7] {
    match scene {
        SceneName::Nanobowl => [0.7, 0.5, 1.1, 4.0, 0.03, 0.08, 0.6],
        SceneName::Ns90k => [6.0, 4.0, 11.0, 4.0, 0.18, 0.9, 1.1],
        SceneName::Ns740k => [52.0, 34.0, 720.0, 4.0, 2.0, 7.5, 128.0],
        SceneName::Sio2 => [130.0, 160.0, 92.0, 1.0, 10.0, 50.0, 35.0],
        SceneName::Anp3 => [504.0, 430.0, 2012.0, 1.0, 28.0, 128.0, 70.0],
    }
}

/// Table 1, row "bnsView": ns740k far, volume, fps by frame-buffer size in megapixels
/// (256² = .0625 MP … 4096² = 16 MP), 16 cores.
pub const PAPER_TABLE1: [(f64, f64); 5] = [
    (0.0625, 44.0),
    (0.25, 14.0),
    (1.0, 4.0),
    (4.0, 1.1),
    (16.0, 0.3),
];

/// Table 2, row "bnsView": ns740k far, volume, 1024², fps by number of cores.
pub const PAPER_TABLE2: [(u32, f64); 5] =
    [(1, 0.394), (2, 0.779), (4, 1.54), (8, 3.05), (16, 5.93)];

/// The paper's Figure 4 caption (§4.5), whole: "Ray tracing modalities with bnsView. From left
/// to right: ball-and-stick with diffuse illumination and shadows (58 fps on the Xeon Phi),
/// ambient occlusion (1.8 fps), and path traced with a metal BRDF (0.25 fps); unlit volume
/// rendering with volumetric shadows (16 fps), and the same with gradient lighting (3.7 fps)."
/// Measured on the Xeon Phi SE10P (61 cores), not the Table 1-3 CPU; no scene, view, frame
/// size, AO sample count or spp is given. Each figure with the caption's words and our mode of
/// the same modality.
pub const PAPER_FIGURE4: [(&str, f64, Option<BenchMode>); 5] = [
    (
        "ball-and-stick with diffuse illumination and shadows",
        58.0,
        Some(BenchMode::BsShadows),
    ),
    ("ambient occlusion", 1.8, Some(BenchMode::BsAo)),
    ("path traced with a metal BRDF", 0.25, Some(BenchMode::Path)),
    (
        "unlit volume rendering with volumetric shadows",
        16.0,
        Some(BenchMode::VolumeShadows),
    ),
    (
        "the same with gradient lighting",
        3.7,
        Some(BenchMode::VolumeLitShadows),
    ),
];

/// Density resolution the paper used (Table 3).
pub fn paper_voxels_per_angstrom(scene: SceneName) -> f32 {
    paper_preprocess(scene)[3] as f32
}
