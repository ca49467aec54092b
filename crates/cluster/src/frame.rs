//! One frame rendered by every rank (the paper's image-parallel renderer): the rows of tiles of
//! each band dealt round robin, rendered by each rank's threads, received by rank 0 straight
//! into the frame or into the band of a giant frame's streamed PNG.

use std::ops::Range;
use std::path::Path;
use std::time::Instant;

use mpi::traits::*;
use render::{
    band_buffer, band_rows, bands, draw_scene_legend, is_streamed, render_rows, BandEncoder,
    FrameInputs, Framebuffer, Legend, PngStream, RenderError, RenderStats, SceneFrame, TileSet,
};
use scene::Scene;

use crate::{owned_tiles, row_owner, tile_rows, ClusterError, ClusterFrame, RankStats, Ranks};

/// Where a rank's band of pixels lives.
enum Out {
    /// Rank 0 of a frame held whole: bands are rows of the frame.
    Whole(Framebuffer),
    /// Rank 0 of a giant frame: the band, then to the PNG's encoder thread (which gives back
    /// the buffer of the band before).
    Streamed(Box<BandEncoder>, Vec<u32>),
    /// Any other rank: its band, whose rows of tiles are sent to rank 0.
    Worker(Vec<u32>),
}

/// A rank's buffers for one frame, allocated before the ranks agree to render.
struct Buffers {
    out: Out,
}

impl Buffers {
    fn new(
        root: bool,
        path: &Path,
        (w, h): (u32, u32),
        rows_per_band: u32,
        background: u32,
    ) -> Result<Buffers, RenderError> {
        let band = || band_buffer(w, rows_per_band.min(h));
        let out = match (root, is_streamed((w, h))) {
            (false, _) => Out::Worker(band()?),
            (true, false) => Out::Whole(Framebuffer::new(w, h, background)?),
            (true, true) => {
                let png = PngStream::create(path, (w, h))?;
                Out::Streamed(Box::new(BandEncoder::spawn(png, band()?)?), band()?)
            }
        };
        Ok(Buffers { out })
    }

    /// The pixels of band `rows` of a frame `w` wide.
    fn band(&mut self, rows: &Range<u32>, w: u32) -> &mut [u32] {
        let (a, b) = (
            rows.start as usize * w as usize,
            rows.end as usize * w as usize,
        );
        match &mut self.out {
            Out::Whole(fb) => &mut fb.pixels[a..b],
            Out::Streamed(_, band) | Out::Worker(band) => &mut band[..b - a],
        }
    }

    /// Rank 0: the finished band `rows` into the PNG of a giant frame.
    fn write(&mut self, rows: &Range<u32>, w: u32) -> Result<(), RenderError> {
        let Out::Streamed(png, band) = &mut self.out else {
            return Ok(());
        };
        let len = band.len();
        match png.write(std::mem::take(band), rows.len() * w as usize) {
            Ok(next) => {
                *band = next;
                Ok(())
            }
            Err(e) => {
                // The buffer went down with the encoder: the ranks still meet at the next
                // band (rank 0 stops them there), so rank 0 needs one to render into.
                *band = vec![0; len];
                Err(e)
            }
        }
    }

    /// Rank 0: the legend drawn and the frame saved, or the PNG finished.
    fn finish(
        self,
        scene: &Scene,
        legend_ink: Option<[u8; 3]>,
        path: &Path,
    ) -> Result<Option<(Legend, bool)>, RenderError> {
        match self.out {
            Out::Whole(mut fb) => {
                let legend = draw_scene_legend(scene, &mut fb, legend_ink);
                fb.save(path)?;
                Ok(legend)
            }
            Out::Streamed(png, _) => png.finish().map(|()| None),
            Out::Worker(_) => Ok(None),
        }
    }
}

/// Rows of tiles whose messages are under way at once (each row of tiles is one message).
const REQUESTS_AT_ONCE: usize = 1024;

impl RankStats {
    /// As four numbers for one message: tiles, rays, render and wall time in nanoseconds.
    fn to_words(self) -> [u64; 4] {
        let ns = |s: f64| (s * 1e9) as u64;
        [self.tiles, self.rays, ns(self.render_s), ns(self.wall_s)]
    }

    /// The inverse of [`RankStats::to_words`].
    fn from_words(w: &[u64]) -> RankStats {
        RankStats {
            tiles: w[0],
            rays: w[1],
            render_s: w[2] as f64 * 1e-9,
            wall_s: w[3] as f64 * 1e-9,
        }
    }
}

impl Ranks {
    /// Renders `job` into the image file `path` with every rank (collective: every rank calls
    /// it with the same scene, camera, settings and size): as `render::render_scene_to_file`,
    /// pixel for pixel, with the rows of tiles of each band dealt to the ranks round robin and
    /// rank 0 receiving and writing. A frame over `render::STREAM_ABOVE_BYTES` is streamed in bands.
    /// `on_rows` (rank 0) is told the rows written. Returns on rank 0 what every rank did.
    pub fn render_scene_to_file(
        &self,
        job: &SceneFrame,
        on_rows: Option<&mut dyn FnMut(u32, u32)>,
        path: &Path,
    ) -> Result<ClusterFrame, ClusterError> {
        job.with_inputs(|inp| self.share_frame(job, inp, on_rows, path))
    }

    /// [`Ranks::render_scene_to_file`] with the frame driver's inputs made.
    fn share_frame(
        &self,
        job: &SceneFrame,
        inp: &FrameInputs,
        mut on_rows: Option<&mut dyn FnMut(u32, u32)>,
        path: &Path,
    ) -> Result<ClusterFrame, ClusterError> {
        let SceneFrame {
            scene,
            settings,
            size: (w, h),
            legend_ink,
            isa,
            ..
        } = *job;
        let (rank, ranks) = (self.rank(), self.size());
        let mine = move |_tx: usize, ty: usize| row_owner(ty, ranks) == rank;
        let tiles = TileSet::Where(&mine);
        let rows_per_band = if is_streamed((w, h)) { band_rows(w) } else { h };
        // All that can fail on one rank but not the others, before the ranks agree.
        let ready = settings
            .validate(inp.model.is_some(), inp.volume.is_some())
            .map_err(RenderError::from)
            .and_then(|()| {
                let bg = settings.background_packed();
                Buffers::new(rank == 0, path, (w, h), rows_per_band, bg)
            });
        let mut buf = self.agree(ready.map_err(|e| e.to_string()))?;
        let root = self.world.process_at_rank(0);
        let start = Instant::now();
        let mut done = RankStats::default();
        // Rank 0's last write; the others learn of it at the next band.
        let mut written: Result<(), RenderError> = Ok(());
        for rows in bands(h, rows_per_band) {
            let px = buf.band(&rows, w);
            let t = Instant::now();
            let s = render_rows(inp, settings, tiles, w, h, rows.clone(), px, isa)
                .expect("the settings were validated before the ranks agreed");
            done.render_s += t.elapsed().as_secs_f64();
            done.rays += s.rays;
            done.tiles += owned_tiles(w, rows.clone(), rank, ranks) as u64;
            self.share_band(px, w, &rows);
            self.go_on(&written)?;
            if rank == 0 {
                written = buf.write(&rows, w);
                if let Some(f) = on_rows.as_mut() {
                    f(rows.end, h);
                }
            }
        }
        done.wall_s = start.elapsed().as_secs_f64();
        let mut legend = None;
        if rank == 0 {
            written =
                written.and_then(|()| buf.finish(scene, legend_ink, path).map(|l| legend = l));
        }
        self.go_on(&written)?;
        let words = done.to_words();
        if rank != 0 {
            root.gather_into(&words[..]);
            return Ok(ClusterFrame {
                stats: RenderStats {
                    isa,
                    time: start.elapsed(),
                    rays: done.rays,
                },
                legend: None,
                ranks: Vec::new(),
            });
        }
        // The frame's time: its bands rendered, gathered (and streamed), not the file saved.
        let time = std::time::Duration::from_secs_f64(done.wall_s);
        let mut all = vec![0u64; 4 * ranks];
        root.gather_into_root(&words[..], &mut all[..]);
        let per_rank: Vec<RankStats> = all.chunks(4).map(RankStats::from_words).collect();
        Ok(ClusterFrame {
            stats: RenderStats {
                isa,
                time,
                rays: per_rank.iter().map(|r| r.rays).sum(),
            },
            legend,
            ranks: per_rank,
        })
    }

    /// Collective: the rows of tiles of band `rows` (a frame `w` wide) that each rank
    /// rendered into its `px`, received by rank 0 into its `px` in place (no packing: a row of
    /// tiles is contiguous); rank 0's own rows are already there. Single tiles packed and
    /// gathered cost 5× the wait (ARCHITECTURE.md, "Rejected").
    fn share_band(&self, px: &mut [u32], w: u32, rows: &Range<u32>) {
        let (rank, ranks) = (self.rank(), self.size());
        // Each row of tiles as its own slice of the band, with the rank that rendered it, in
        // groups of the same rows of tiles on every rank (so a tall narrow frame does not post
        // a million requests at once, and each group's sends meet its receives).
        let mut groups: Vec<Vec<(usize, &mut [u32])>> = Vec::new();
        let mut rest = px;
        for (i, (owner, run)) in tile_rows(w, rows.clone(), ranks).enumerate() {
            let (part, tail) = std::mem::take(&mut rest).split_at_mut(run.len());
            rest = tail;
            if i % REQUESTS_AT_ONCE == 0 {
                groups.push(Vec::new());
            }
            if owner != 0 && (rank == 0 || owner == rank) {
                groups.last_mut().expect("pushed above").push((owner, part));
            }
        }
        for group in &mut groups {
            mpi::request::scope(|scope| {
                let pending: Vec<_> = group
                    .iter_mut()
                    .map(|(owner, part)| match rank {
                        0 => self
                            .world
                            .process_at_rank(*owner as i32)
                            .immediate_receive_into(scope, &mut **part),
                        _ => self.world.process_at_rank(0).immediate_send(scope, &**part),
                    })
                    .collect();
                for p in pending {
                    p.wait();
                }
            });
        }
    }

    /// Collective: rank 0 says whether its last write succeeded; if not, every rank stops
    /// (rank 0 with its error).
    fn go_on(&self, written: &Result<(), RenderError>) -> Result<(), ClusterError> {
        let mut ok = u8::from(written.is_ok());
        self.world.process_at_rank(0).broadcast_into(&mut ok);
        match (ok, written) {
            (1, _) => Ok(()),
            (_, Err(e)) if self.rank() == 0 => Err(ClusterError::Failed {
                rank: 0,
                ranks: self.size(),
                message: e.to_string(),
            }),
            _ => Err(ClusterError::Stopped),
        }
    }
}
