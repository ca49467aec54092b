//! What each rank of a job did, as rank 0 reports it (`-v`).

use render::{Legend, RenderStats};

/// One rank's share of a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RankStats {
    /// Tiles it rendered.
    pub tiles: u64,
    /// Rays it cast (camera rays × samples).
    pub rays: u64,
    /// Seconds rendering its tiles.
    pub render_s: f64,
    /// Seconds from the start of the frame to its last band sent (rendering and waiting).
    pub wall_s: f64,
}

/// A frame rendered by several ranks.
pub struct ClusterFrame {
    /// The frame as a whole: its wall time on rank 0 (bands rendered and gathered, and
    /// streamed for a giant frame; a whole frame's file is saved after) and every rank's rays.
    pub stats: RenderStats,
    /// The legend of a model coloured by a column, and whether it was drawn (rank 0).
    pub legend: Option<(Legend, bool)>,
    /// Every rank's share, by rank (rank 0 only; empty on the others).
    pub ranks: Vec<RankStats>,
}

impl ClusterFrame {
    /// A `-v` line per rank: tiles, render time, rate and time waiting for the others.
    pub fn describe(&self) -> Vec<String> {
        let n = self.ranks.len();
        self.ranks
            .iter()
            .enumerate()
            .map(|(r, s)| {
                format!(
                    "rank {r}/{n}: {} tiles, render {:.3} s ({:.1} Mrays/s), waited {:.3} s",
                    s.tiles,
                    s.render_s,
                    s.rays as f64 / s.render_s.max(1e-9) / 1e6,
                    (s.wall_s - s.render_s).max(0.0)
                )
            })
            .collect()
    }
}
