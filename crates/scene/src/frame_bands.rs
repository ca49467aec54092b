//! How much of a frame is held in memory: a frame up to [`STREAM_ABOVE_BYTES`] whole, a
//! larger one (the paper's 512-megapixel frame buffer, Figure 1) as bands of rows streamed to
//! its file one at a time (`render::PngStream`, encoded on its own thread while the next band
//! renders). The memory estimate counts what is held.

/// Frames above this many bytes of packed RGBA8 pixels are streamed in bands instead of held
/// whole (256 MiB: 64 megapixels).
pub const STREAM_ABOVE_BYTES: u64 = 256 << 20;

/// Bytes of one band's pixels at most (a band holds at least one row of tiles).
pub const BAND_BYTES: u64 = 64 << 20;

/// Bands are whole rows of the renderer's tiles: a multiple of this many rows (render's
/// `TILE`, pixels).
pub const BAND_ROW_MULTIPLE: u32 = 16;

/// Whether a frame of `size` pixels is streamed in bands rather than held whole.
pub fn is_streamed((w, h): (u32, u32)) -> bool {
    u64::from(w) * u64::from(h) * 4 > STREAM_ABOVE_BYTES
}

/// Rows per band of a streamed frame `width` pixels wide: whole rows of tiles, under
/// [`BAND_BYTES`], at least one row of tiles.
pub fn band_rows(width: u32) -> u32 {
    let rows = BAND_BYTES / (u64::from(width.max(1)) * 4);
    let m = u64::from(BAND_ROW_MULTIPLE);
    ((rows / m).max(1) * m).min(u64::from(u32::MAX)) as u32
}

/// Bytes of pixels held while a frame of `size` is drawn: the whole frame, or two bands (one
/// rendering while the other is encoded).
pub fn held_frame_bytes((w, h): (u32, u32)) -> u64 {
    let rows = if is_streamed((w, h)) {
        (2 * u64::from(band_rows(w))).min(u64::from(h))
    } else {
        u64::from(h)
    };
    u64::from(w) * rows * crate::memory::FRAME_BYTES_PER_PIXEL
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_over_256_mib_are_held_as_two_bands_of_whole_tile_rows() {
        // 8192² RGBA8 is exactly 256 MiB: held whole; one more row streams.
        assert!(!is_streamed((8192, 8192)) && is_streamed((8192, 8193)));
        assert_eq!(held_frame_bytes((8192, 8192)), 256 << 20);
        // The paper's 65536x8192 frame: bands of 256 rows, 64 MiB, two held.
        assert_eq!(band_rows(65536), 256);
        assert_eq!(held_frame_bytes((65536, 8192)), 128 << 20);
        // Rows in whole tile rows, at least one, even when one row is over the band budget.
        assert_eq!(band_rows(8193), 2032);
        assert_eq!(band_rows(u32::MAX), 16);
        assert_eq!(held_frame_bytes((u32::MAX, 8)), u64::from(u32::MAX) * 8 * 4);
    }
}
