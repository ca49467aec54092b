//! The markdown tables of a run: preprocessing, Tables 1-3 and Figure 4 with the paper's
//! figures beside ours (whole machine and per core), fps per ISA, every measurement.

use std::collections::BTreeSet;

use molecule::scenes::SceneName;
use spmd::Isa;

use crate::mode::BenchMode;
use crate::paper::{paper_preprocess, paper_table3, PAPER_CORES, PAPER_TABLE1, PAPER_TABLE2};
use crate::plan::{sidx, Key, Tables};
use crate::probe::cpu_model;
use crate::record::{mb, Measurement, Preprocess};

/// A figure with 3 significant digits or so, `-` if not finite.
pub fn f2(x: f64) -> String {
    if !x.is_finite() {
        "-".into()
    } else if x >= 100.0 {
        format!("{x:.0}")
    } else if x >= 10.0 {
        format!("{x:.1}")
    } else if x >= 1.0 {
        format!("{x:.2}")
    } else {
        format!("{x:.3}")
    }
}

/// [`f2`] of a figure, `-` if missing.
pub(crate) fn opt_f(x: Option<f64>) -> String {
    x.map(f2).unwrap_or_else(|| "-".into())
}

/// `a / b`, a dash for a missing figure.
pub(crate) fn pair(a: Option<f64>, b: Option<f64>) -> String {
    format!("{} / {}", opt_f(a), opt_f(b))
}

/// The far and close measurements of a scene and mode among `sel` (one ISA, size, threads).
pub(crate) fn far_close<'a>(
    sel: &[&'a Measurement],
    scene: SceneName,
    mode: BenchMode,
) -> [Option<&'a Measurement>; 2] {
    [true, false].map(|far| {
        sel.iter()
            .find(|m| m.key.scene == scene && m.key.mode == mode && m.key.far == far)
            .copied()
    })
}

/// Appends the report of a run to `o`: the records `pre` and `meas` of the backends `isas`
/// on `nproc` cores, load averages at the start and end, wall time (s).
pub fn report(
    o: &mut String,
    pre: &[Preprocess],
    meas: &[Measurement],
    isas: &[Isa],
    nproc: u32,
    (load_start, load_end): ([f64; 3], [f64; 3]),
    wall: f64,
) {
    use std::fmt::Write as _;
    let _ = writeln!(
        o,
        "\nbnsview bench on {} ({} cores), ISA {}; load average {:.2} {:.2} {:.2} at start, {:.2} {:.2} {:.2} at end; wall {:.0} s",
        cpu_model(),
        nproc,
        isas.iter().map(|i| i.name()).collect::<Vec<_>>().join(", "),
        load_start[0],
        load_start[1],
        load_start[2],
        load_end[0],
        load_end[1],
        load_end[2],
        wall
    );
    let _ = writeln!(
        o,
        "Paper: dual 8-core 2.7 GHz Xeon E5-2680 (16 cores, AVX); per core = fps / threads vs paper fps / 16.\n"
    );

    if !pre.is_empty() {
        let _ = writeln!(
            o,
            "### Preprocessing (paper's Table 3 figure in brackets)\n"
        );
        let _ = writeln!(
            o,
            "| scene | atoms | bonds | load s | bonds s | BVH s | volume s (vox/Å) | geometry MB | BVH MB | volume MB | B/atom | peak RSS MB |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|---|---|---|---|---|");
        for p in pre {
            let pp = paper_preprocess(p.scene);
            let _ = writeln!(
                o,
                "| {} | {} | {} | {} | {} [{}] | {} [{}] | {} [{}] ({}) | {} [{}] | {} [{}] | {} [{}] | {} | {}{} |",
                p.scene,
                p.atoms,
                p.bonds,
                f2(p.load_s),
                f2(p.bond_s),
                pp[4],
                opt_f(p.bvh_s),
                pp[5],
                opt_f(p.volume_s),
                pp[6],
                p.voxels_per_angstrom,
                opt_f(p.geometry_bytes.map(mb)),
                pp[0],
                opt_f(p.bvh_bytes.map(mb)),
                pp[1],
                opt_f(p.volume_bytes.map(mb)),
                pp[2],
                opt_f(p.bytes_per_atom()),
                opt_f(p.peak_rss_mb),
                if p.peak_rss_reset { "" } else { " (process)" }
            );
        }
        let _ = writeln!(o);
    }

    // Table 3: rows scene × mode, far / close side by side.
    let t3: Vec<&Measurement> = meas
        .iter()
        .filter(|m| m.tables.contains(Tables::T3))
        .collect();
    let combos: BTreeSet<(Isa, u32, u32, u32)> = t3
        .iter()
        .map(|m| (m.isa, m.key.w, m.key.h, m.key.threads))
        .collect();
    for (isa, w, h, threads) in combos {
        // The paper measured at 1024²: at other sizes compare per pixel (ours × pixels/1024²).
        let scale = w as f64 * h as f64 / (1024.0 * 1024.0);
        let _ = writeln!(
            o,
            "### Table 3: fps far / close, {w}x{h}, {isa}, {threads} thread{}{}\n",
            if threads == 1 { "" } else { "s" },
            if scale == 1.0 {
                String::new()
            } else {
                format!(
                    " (paper at 1024²: per-core columns scale ours by {scale:.3}, the pixel ratio)"
                )
            }
        );
        let _ = writeln!(
            o,
            "| scene | atoms | mode | ours fps | paper fps (16 cores) | ours per core | paper per core | per-core ratio |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|---|");
        let sel: Vec<&Measurement> = t3
            .iter()
            .filter(|m| (m.isa, m.key.w, m.key.h, m.key.threads) == (isa, w, h, threads))
            .copied()
            .collect();
        let rows: BTreeSet<(usize, BenchMode)> = sel
            .iter()
            .map(|m| (sidx(m.key.scene), m.key.mode))
            .collect();
        for (si, mode) in rows {
            let scene = SceneName::ALL[si];
            let [f, c] = far_close(&sel, scene, mode);
            let atoms = f.or(c).map(|m| m.atoms).unwrap_or(0);
            let ours = [f.map(|m| m.fps()), c.map(|m| m.fps())];
            let paper = mode.paper_row().map(|r| paper_table3(scene)[r]);
            let per_core = |x: Option<f64>| x.map(|v| v * scale / threads as f64);
            let paper_core = |i: usize| paper.map(|p| p[i] / PAPER_CORES);
            let ratio = |i: usize| match (per_core(ours[i]), paper_core(i)) {
                (Some(a), Some(b)) => Some(a / b),
                _ => None,
            };
            let ratio_s = |x: Option<f64>| x.map(|r| format!("{r:.2}×")).unwrap_or("-".into());
            let _ = writeln!(
                o,
                "| {} | {} | {} | {} | {} | {} | {} | {} / {} |",
                scene,
                atoms,
                mode.name(),
                pair(ours[0], ours[1]),
                pair(paper.map(|p| p[0]), paper.map(|p| p[1])),
                pair(per_core(ours[0]), per_core(ours[1])),
                pair(paper_core(0), paper_core(1)),
                ratio_s(ratio(0)),
                ratio_s(ratio(1)),
            );
        }
        let _ = writeln!(o);
        crate::figure4::figure4_table(o, &sel);
    }

    // Table 1: frame-buffer size.
    let t1: Vec<&Measurement> = meas
        .iter()
        .filter(|m| m.tables.contains(Tables::T1))
        .collect();
    let combos: BTreeSet<(usize, Isa, u32)> = t1
        .iter()
        .map(|m| (sidx(m.key.scene), m.isa, m.key.threads))
        .collect();
    for (si, isa, threads) in combos {
        let scene = SceneName::ALL[si];
        let _ = writeln!(
            o,
            "### Table 1: {scene} far, volume, by frame-buffer size, {isa}, {threads} thread{}\n",
            if threads == 1 { "" } else { "s" }
        );
        let _ = writeln!(
            o,
            "| size | MP | ours fps | ms median [min-max] | paper fps (16 cores) | ours per core | paper per core | per-core ratio |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|---|");
        let mut rows: Vec<&&Measurement> = t1
            .iter()
            .filter(|m| (m.key.scene, m.isa, m.key.threads) == (scene, isa, threads))
            .collect();
        rows.sort_by_key(|m| m.key.w as u64 * m.key.h as u64);
        for m in rows {
            let mp = m.key.w as f64 * m.key.h as f64 / (1024.0 * 1024.0);
            let paper = PAPER_TABLE1
                .iter()
                .find(|(p, _)| (p - mp).abs() < 1e-9)
                .map(|x| x.1);
            let v = m.sorted();
            let ours_core = m.fps() / threads as f64;
            let _ = writeln!(
                o,
                "| {}x{} | {} | {} | {} [{}-{}] | {} | {} | {} | {} |",
                m.key.w,
                m.key.h,
                f2(mp),
                f2(m.fps()),
                f2(m.ms_median()),
                f2(v[0]),
                f2(v[v.len() - 1]),
                opt_f(paper),
                f2(ours_core),
                opt_f(paper.map(|p| p / PAPER_CORES)),
                paper
                    .map(|p| format!("{:.2}×", ours_core / (p / PAPER_CORES)))
                    .unwrap_or("-".into())
            );
        }
        let _ = writeln!(o);
    }

    // Table 2: threads.
    let t2: Vec<&Measurement> = meas
        .iter()
        .filter(|m| m.tables.contains(Tables::T2))
        .collect();
    let combos: BTreeSet<(usize, Isa, u32, u32)> = t2
        .iter()
        .map(|m| (sidx(m.key.scene), m.isa, m.key.w, m.key.h))
        .collect();
    for (si, isa, w, h) in combos {
        let scene = SceneName::ALL[si];
        let scale = w as f64 * h as f64 / (1024.0 * 1024.0);
        let _ = writeln!(
            o,
            "### Table 2: {scene} far, volume, {w}x{h}, by threads, {isa}{}\n",
            if scale == 1.0 {
                String::new()
            } else {
                format!(
                    " (paper at 1024²: ours ÷ paper scales ours by {scale:.3}, the pixel ratio)"
                )
            }
        );
        let _ = writeln!(
            o,
            "| threads | ours fps | ms median [min-max] | speedup over 1 | paper fps (same cores) | paper speedup over 1 | ours ÷ paper |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|");
        let mut rows: Vec<&&Measurement> = t2
            .iter()
            .filter(|m| (m.key.scene, m.isa, m.key.w, m.key.h) == (scene, isa, w, h))
            .collect();
        rows.sort_by_key(|m| m.key.threads);
        let one = rows.iter().find(|m| m.key.threads == 1).map(|m| m.fps());
        for m in rows {
            let paper = PAPER_TABLE2
                .iter()
                .find(|(c, _)| *c == m.key.threads)
                .map(|x| x.1);
            let v = m.sorted();
            let _ = writeln!(
                o,
                "| {} | {} | {} [{}-{}] | {} | {} | {} | {} |",
                m.key.threads,
                f2(m.fps()),
                f2(m.ms_median()),
                f2(v[0]),
                f2(v[v.len() - 1]),
                one.map(|x| format!("{:.2}×", m.fps() / x))
                    .unwrap_or("-".into()),
                opt_f(paper),
                paper
                    .map(|p| format!("{:.2}×", p / PAPER_TABLE2[0].1))
                    .unwrap_or("-".into()),
                paper
                    .map(|p| format!("{:.2}×", m.fps() * scale / p))
                    .unwrap_or("-".into()),
            );
        }
        let _ = writeln!(o);
    }

    // Speedups over scalar.
    if isas.len() > 1 {
        let _ = writeln!(o, "### fps per ISA (speedup over the first ISA listed)\n");
        let mut head = String::from("| scene | mode | view | size | threads |");
        let mut sep = String::from("|---|---|---|---|---|");
        for i in isas {
            let _ = write!(head, " {i} |");
            sep.push_str("---|");
        }
        let _ = writeln!(o, "{head}\n{sep}");
        let mut keys: Vec<Key> = Vec::new();
        for m in meas {
            if !keys.contains(&m.key) {
                keys.push(m.key);
            }
        }
        for k in keys {
            let fps: Vec<Option<f64>> = isas
                .iter()
                .map(|&i| {
                    meas.iter()
                        .find(|m| m.key == k && m.isa == i)
                        .map(|m| m.fps())
                })
                .collect();
            let base = fps[0];
            let mut line = format!(
                "| {} | {} | {} | {}x{} | {} |",
                k.scene,
                k.mode.name(),
                k.view(),
                k.w,
                k.h,
                k.threads
            );
            for (j, f) in fps.iter().enumerate() {
                match (f, base) {
                    (Some(f), Some(b)) if j > 0 => {
                        let _ = write!(line, " {} ({:.2}×) |", f2(*f), f / b);
                    }
                    (Some(f), _) => {
                        let _ = write!(line, " {} |", f2(*f));
                    }
                    _ => line.push_str(" - |"),
                }
            }
            let _ = writeln!(o, "{line}");
        }
        let _ = writeln!(o);
    }

    // Every measurement.
    let _ = writeln!(o, "### All measurements\n");
    let _ = writeln!(
        o,
        "| scene | atoms | mode | view | size | threads | isa | frames | ms median | ms min | ms max | fps | Mrays/s | load |"
    );
    let _ = writeln!(
        o,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for m in meas {
        let v = m.sorted();
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {}x{} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} |",
            m.key.scene,
            m.atoms,
            m.key.mode.name(),
            m.key.view(),
            m.key.w,
            m.key.h,
            m.key.threads,
            m.isa,
            m.ms.len(),
            f2(m.ms_median()),
            f2(v[0]),
            f2(v[v.len() - 1]),
            f2(m.fps()),
            f2(m.mrays()),
            m.load1
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn meas(mode: BenchMode, far: bool, ms: f64, tables: Tables) -> Measurement {
        Measurement {
            key: Key {
                scene: SceneName::Ns90k,
                mode,
                far,
                w: 1024,
                h: 1024,
                threads: 4,
            },
            tables,
            atoms: 90_000,
            isa: Isa::Scalar,
            ms: vec![ms],
            load1: 0.0,
        }
    }

    #[test]
    fn table3_rows_put_the_paper_beside_ours_per_core() {
        let m = [
            meas(BenchMode::Bs, true, 100.0, Tables::T3),
            meas(BenchMode::Bs, false, 50.0, Tables::T3),
            meas(BenchMode::BsAo, true, 1000.0, Tables::T3),
        ];
        let mut o = String::new();
        report(
            &mut o,
            &[],
            &m,
            &[Isa::Scalar],
            4,
            ([0.0; 3], [0.0; 3]),
            1.0,
        );
        assert!(o.contains("### Table 3: fps far / close, 1024x1024, scalar, 4 threads\n"));
        // ns90k b&s: paper 42 / 45 fps on 16 cores; ours 10 / 20 fps on 4 threads.
        let ratio_far = (10.0 / 4.0) / (42.0 / 16.0);
        let ratio_close = (20.0 / 4.0) / (45.0 / 16.0);
        let row = format!(
            "| ns90k | 90000 | bs | 10.0 / 20.0 | 42.0 / 45.0 | 2.50 / 5.00 | {:.2} / {:.2} | \
             {ratio_far:.2}× / {ratio_close:.2}× |",
            42.0 / 16.0,
            45.0 / 16.0
        );
        assert!(o.contains(&row), "{row}\n{o}");
        // A modality has no Table 3 figure, but a Figure 4 one.
        assert!(
            o.contains("| ns90k | 90000 | bs-ao | 1.00 / - | - / - |"),
            "{o}"
        );
        assert!(
            o.contains("| ambient occlusion | 1.80 | bs-ao | 1.00 / - |"),
            "{o}"
        );
        // No Table 1 or 2 without their measurements; every measurement listed.
        assert!(!o.contains("### Table 1") && !o.contains("### Table 2"));
        assert_eq!(o.matches("| 1024x1024 | 4 | scalar | 1 |").count(), 3);
    }

    #[test]
    fn figures_keep_about_three_digits() {
        assert_eq!(f2(f64::NAN), "-");
        assert_eq!(f2(123.4), "123");
        assert_eq!(f2(12.34), "12.3");
        assert_eq!(f2(1.234), "1.23");
        assert_eq!(f2(0.1234), "0.123");
    }
}
