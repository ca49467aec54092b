//! A rank's share of a band of rows: the row segments of the tiles it owns, packed into one
//! message in tile order and unpacked by rank 0 into the band (no MPI here).

use std::ops::Range;

use render::{TileSet, TILE};

/// The row segments `(offset, length)` in a band (rows `rows` of a frame `width` pixels wide,
/// `rows.start` a multiple of the tile edge) that belong to the tiles of `tiles`, tile by
/// tile (row major), each tile's rows top to bottom.
pub fn segments<'a>(
    width: u32,
    rows: Range<u32>,
    tiles: &'a TileSet<'a>,
) -> impl Iterator<Item = (usize, usize)> + 'a {
    let (w, start, end) = (width as usize, rows.start as usize, rows.end as usize);
    assert!(start % TILE == 0, "a band starts at a row of tiles");
    let across = w.div_ceil(TILE);
    (start / TILE..end.div_ceil(TILE)).flat_map(move |ty| {
        (0..across)
            .filter(move |&tx| tiles.owns(tx, ty, across))
            .flat_map(move |tx| {
                let (x0, cols) = (tx * TILE, TILE.min(w - tx * TILE));
                (ty * TILE..((ty + 1) * TILE).min(end)).map(move |y| ((y - start) * w + x0, cols))
            })
    })
}

/// Number of tiles of `tiles` in the band `rows` of a frame `width` pixels wide.
pub fn owned_tiles(width: u32, rows: Range<u32>, tiles: &TileSet) -> usize {
    let across = (width as usize).div_ceil(TILE);
    let tile_rows = rows.start as usize / TILE..(rows.end as usize).div_ceil(TILE);
    tile_rows
        .map(|ty| (0..across).filter(|&tx| tiles.owns(tx, ty, across)).count())
        .sum()
}

/// The pixels of `tiles` in `band` (see [`segments`]), in segment order.
pub fn pack(band: &[u32], width: u32, rows: Range<u32>, tiles: &TileSet) -> Vec<u32> {
    let mut out = Vec::new();
    for (o, n) in segments(width, rows, tiles) {
        out.extend_from_slice(&band[o..o + n]);
    }
    out
}

/// Writes `packed` (from [`pack`] with the same arguments) back into `band`.
pub fn unpack(packed: &[u32], band: &mut [u32], width: u32, rows: Range<u32>, tiles: &TileSet) {
    let mut rest = packed;
    for (o, n) in segments(width, rows, tiles) {
        let (seg, tail) = rest.split_at(n);
        band[o..o + n].copy_from_slice(seg);
        rest = tail;
    }
    assert!(rest.is_empty(), "the packed pixels are those of the tiles");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_ranks_packed_tiles_unpack_to_the_whole_band() {
        // Widths and bands with partial tiles at the right and bottom, 1 to 5 ranks.
        for (w, rows) in [
            (53u32, 0u32..37u32),
            (16, 32..48),
            (100, 48..50),
            (7, 16..17),
        ] {
            let band: Vec<u32> = (0..w * rows.len() as u32).map(|i| i * 7 + 1).collect();
            for ranks in 1..=5 {
                let mut back = vec![0u32; band.len()];
                let mut tiles = 0;
                for rank in 0..ranks {
                    let set = TileSet::Interleaved { rank, ranks };
                    let p = pack(&band, w, rows.clone(), &set);
                    tiles += owned_tiles(w, rows.clone(), &set);
                    unpack(&p, &mut back, w, rows.clone(), &set);
                }
                assert_eq!(back, band, "{w} wide, rows {rows:?}, {ranks} ranks");
                let all = owned_tiles(w, rows.clone(), &TileSet::All);
                assert_eq!(tiles, all);
                assert_eq!(all, (w as usize).div_ceil(16) * (rows.len()).div_ceil(16));
            }
        }
    }
}
