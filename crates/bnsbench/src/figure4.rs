//! The table of the paper's Figure 4 (ray tracing modalities, §4.5) beside our modality
//! modes.

use std::collections::BTreeSet;

use molecule::scenes::SceneName;

use crate::mode::BenchMode;
use crate::paper::PAPER_FIGURE4;
use crate::plan::sidx;
use crate::record::Measurement;
use crate::report::{f2, far_close, pair};

/// The paper's Figure 4 beside our modality modes, one column per scene, for the
/// measurements `sel` of one ISA, size and thread count; nothing if none is a modality.
pub(crate) fn figure4_table(o: &mut String, sel: &[&Measurement]) {
    use std::fmt::Write as _;
    let Some(k) = sel
        .iter()
        .find(|m| PAPER_FIGURE4.iter().any(|f| f.2 == Some(m.key.mode)))
        .map(|m| (m.key, m.isa))
    else {
        return;
    };
    let scenes: BTreeSet<usize> = sel.iter().map(|m| sidx(m.key.scene)).collect();
    let _ = writeln!(
        o,
        "### The paper's Figure 4 (ray tracing modalities) beside ours, fps far / close, {}x{}, \
         {}, {} thread{}\n\n\
         Paper: Xeon Phi SE10P (61 cores, 1.1 GHz), not the CPU of Tables 1-3; its caption names \
         no scene, view, frame size, AO sample count or samples per pixel. Ours: one sample per \
         pixel per frame (bs-ao: 1 AO ray, path: 1 path); `--ao N` and `--spp N` cost about N \
         times as much.\n",
        k.0.w,
        k.0.h,
        k.1,
        k.0.threads,
        if k.0.threads == 1 { "" } else { "s" }
    );
    let mut head = String::from("| paper (Figure 4) | paper fps | ours |");
    let mut rule = String::from("|---|---|---|");
    for &si in &scenes {
        let _ = write!(head, " {} |", SceneName::ALL[si]);
        rule.push_str("---|");
    }
    let _ = writeln!(o, "{head}\n{rule}");
    for (what, fps, mode) in PAPER_FIGURE4 {
        let mut line = format!(
            "| {what} | {} | {} |",
            f2(fps),
            mode.map_or("-", BenchMode::name)
        );
        for &si in &scenes {
            let ours = mode
                .map(|m| far_close(sel, SceneName::ALL[si], m).map(|x| x.map(Measurement::fps)));
            let [f, c] = ours.unwrap_or([None, None]);
            let _ = write!(line, " {} |", pair(f, c));
        }
        let _ = writeln!(o, "{line}");
    }
    let _ = writeln!(o);
}
