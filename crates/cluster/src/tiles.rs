//! A rank's share of a band of rows: whole rows of tiles, dealt round robin, so that each
//! share is a few contiguous runs of the band that go to rank 0 as they lie, with no packing
//! and no unpacking (no MPI here).

use std::ops::Range;

use render::TILE;

/// The rank that renders tile row `ty` (16 pixel rows from `16·ty`) of a frame shared by
/// `ranks` processes: round robin, so that neighbouring rows, which cost about the same,
/// go to different ranks (the paper's load balance by interleaving).
pub fn row_owner(ty: usize, ranks: usize) -> usize {
    ty % ranks.max(1)
}

/// The tile rows of the band `rows` (`rows.start` a multiple of the tile edge), each as
/// `(owner, pixels)`: the rank that renders it and its pixels' range in the band (a frame
/// `width` pixels wide, row major), top to bottom; the last may be cut short by the band.
pub fn tile_rows(
    width: u32,
    rows: Range<u32>,
    ranks: usize,
) -> impl Iterator<Item = (usize, Range<usize>)> {
    let (w, start, end) = (width as usize, rows.start as usize, rows.end as usize);
    assert!(start % TILE == 0, "a band starts at a row of tiles");
    (start / TILE..end.div_ceil(TILE)).map(move |ty| {
        let (y0, y1) = (ty * TILE, ((ty + 1) * TILE).min(end));
        (row_owner(ty, ranks), (y0 - start) * w..(y1 - start) * w)
    })
}

/// Number of tiles rank `rank` of `ranks` renders in the band `rows` of a frame `width`
/// pixels wide.
pub fn owned_tiles(width: u32, rows: Range<u32>, rank: usize, ranks: usize) -> usize {
    let across = (width as usize).div_ceil(TILE);
    tile_rows(width, rows, ranks)
        .filter(|(owner, _)| *owner == rank)
        .count()
        * across
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ranks_tile_rows_cover_each_band_once() {
        // Widths and bands with partial tiles at the right and bottom, 1 to 5 ranks.
        for (w, rows) in [
            (53u32, 0u32..37u32),
            (16, 32..48),
            (100, 48..50),
            (7, 16..17),
        ] {
            let len = w as usize * rows.len();
            for ranks in 1..=5 {
                let mut hits = vec![0u8; len];
                let mut owners = vec![usize::MAX; len];
                for (owner, px) in tile_rows(w, rows.clone(), ranks) {
                    assert!(owner < ranks);
                    for i in px {
                        hits[i] += 1;
                        owners[i] = owner;
                    }
                }
                assert!(hits.iter().all(|&n| n == 1), "{w} wide, rows {rows:?}");
                // Each pixel's owner is the owner of its tile row, by brute force.
                for (i, &o) in owners.iter().enumerate() {
                    let y = rows.start as usize + i / w as usize;
                    assert_eq!(o, (y / TILE) % ranks);
                }
                let tiles: usize = (0..ranks)
                    .map(|r| owned_tiles(w, rows.clone(), r, ranks))
                    .sum();
                assert_eq!(tiles, (w as usize).div_ceil(16) * rows.len().div_ceil(16));
            }
        }
    }
}
