//! PNG of an RGBA image, written with the deflate the page already carries (`miniz_oxide`, for
//! share links): how Record packs each frame of a range as PNG (the page's zip, the desktop's
//! files) without a codec crate in the page or a round trip through the browser's asynchronous
//! image encoder. The CLI keeps the `png` crate; both are read back the same.

use super::zip::crc32;

/// One chunk: length, type, data, CRC of type and data.
fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend((data.len() as u32).to_be_bytes());
    let start = out.len();
    out.extend(kind);
    out.extend(data);
    let crc = crc32(&out[start..]);
    out.extend(crc.to_be_bytes());
}

/// A PNG (8-bit RGBA, straight alpha, each row filtered by its upper neighbour's difference)
/// of `rgba`, `width * height * 4` bytes. `None` where the sizes disagree or a side is 0.
pub fn encode_rgba(width: u32, height: u32, rgba: &[u8]) -> Option<Vec<u8>> {
    let row = width as usize * 4;
    if width == 0 || height == 0 || rgba.len() != row.checked_mul(height as usize)? {
        return None;
    }
    // Filter "Up" (2) on every row but the first (none): skies and clouds change slowly from
    // row to row, so the differences deflate to a fraction of the raw bytes.
    let mut raw = Vec::with_capacity((row + 1) * height as usize);
    for y in 0..height as usize {
        let line = &rgba[y * row..(y + 1) * row];
        if y == 0 {
            raw.push(0);
            raw.extend(line);
        } else {
            raw.push(2);
            let above = &rgba[(y - 1) * row..y * row];
            raw.extend(line.iter().zip(above).map(|(a, b)| a.wrapping_sub(*b)));
        }
    }
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut header = Vec::with_capacity(13);
    header.extend(width.to_be_bytes());
    header.extend(height.to_be_bytes());
    // 8 bits, colour type 6 (RGBA), deflate, adaptive filtering, no interlace.
    header.extend([8, 6, 0, 0, 0]);
    chunk(&mut out, b"IHDR", &header);
    chunk(
        &mut out,
        b"IDAT",
        &miniz_oxide::deflate::compress_to_vec_zlib(&raw, 6),
    );
    chunk(&mut out, b"IEND", &[]);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A gradient with a transparent corner, as the `png` crate decodes it.
    #[test]
    fn the_png_crate_reads_back_every_pixel() {
        let (w, h) = (37u32, 23u32);
        let rgba: Vec<u8> = (0..w * h)
            .flat_map(|i| {
                let (x, y) = (i % w, i / w);
                [
                    (x * 7) as u8,
                    (y * 11) as u8,
                    (x * y) as u8,
                    if x < 3 { 0 } else { 255 },
                ]
            })
            .collect();
        let png = encode_rgba(w, h, &rgba).unwrap();
        let decoder = png::Decoder::new(std::io::Cursor::new(&png));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (w, h));
        assert_eq!(info.color_type, png::ColorType::Rgba);
        assert_eq!(&buf[..info.buffer_size()], &rgba[..]);
    }

    #[test]
    fn sizes_that_disagree_are_refused() {
        assert!(encode_rgba(2, 2, &[0; 15]).is_none());
        assert!(encode_rgba(0, 2, &[]).is_none());
        // A sky deflates: a flat 64×64 image is far below its 16 KiB of pixels.
        assert!(encode_rgba(64, 64, &[200; 64 * 64 * 4]).unwrap().len() < 1000);
    }
}
