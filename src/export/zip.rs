//! A minimal ZIP archive (entries stored, not compressed): how the browser hands over an
//! export of several files (Mitsuba's XML and its grid) as one download.

use std::borrow::Cow;

use super::File;

/// CRC-32 (IEEE 802.3, reflected), as ZIP stores it.
pub(super) fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = (crc >> 1) ^ (0xEDB8_8320 & (crc & 1).wrapping_neg());
        }
    }
    !crc
}

/// The files as one ZIP archive (at most 4 GiB in all; exports are far below).
pub fn zip(files: &[File]) -> Vec<u8> {
    zip_pieces(files).concat()
}

/// [`zip`]'s archive in pieces, in order: each entry's local header and its bytes (borrowed,
/// not copied), then the central directory with its end. The page hands the pieces to one
/// download, so a recording's frames are never copied into an archive beside themselves in
/// the wasm's memory (768 MiB of frames would take 1.5 GiB).
pub fn zip_pieces(files: &[File]) -> Vec<Cow<'_, [u8]>> {
    let mut pieces = Vec::with_capacity(2 * files.len() + 1);
    let mut offset = 0usize;
    let mut central = Vec::new();
    for f in files {
        let crc = crc32(&f.bytes);
        let (size, name) = (f.bytes.len() as u32, f.name.as_bytes());
        // Local header: signature, version 2.0, flags (UTF-8 names), stored, time, date.
        let common = |v: &mut Vec<u8>| {
            v.extend(20u16.to_le_bytes());
            v.extend(0x0800u16.to_le_bytes());
            v.extend(0u16.to_le_bytes());
            v.extend(0u16.to_le_bytes());
            v.extend(0x21u16.to_le_bytes()); // 1980-01-01
            v.extend(crc.to_le_bytes());
            v.extend(size.to_le_bytes());
            v.extend(size.to_le_bytes());
            v.extend((name.len() as u16).to_le_bytes());
            v.extend(0u16.to_le_bytes());
        };
        let mut local = Vec::with_capacity(30 + name.len());
        local.extend(0x0403_4b50u32.to_le_bytes());
        common(&mut local);
        local.extend(name);
        central.extend(0x0201_4b50u32.to_le_bytes());
        central.extend(20u16.to_le_bytes()); // made by
        common(&mut central);
        central.extend([0u8; 8]); // comment length, disk, internal and external attributes
        central.extend([0u8; 2]);
        central.extend((offset as u32).to_le_bytes());
        central.extend(name);
        offset += local.len() + f.bytes.len();
        pieces.push(Cow::Owned(local));
        pieces.push(Cow::Borrowed(f.bytes.as_slice()));
    }
    let (start, size, count) = (offset as u32, central.len() as u32, files.len() as u16);
    central.extend(0x0605_4b50u32.to_le_bytes());
    central.extend([0u8; 4]);
    central.extend(count.to_le_bytes());
    central.extend(count.to_le_bytes());
    central.extend(size.to_le_bytes());
    central.extend(start.to_le_bytes());
    central.extend(0u16.to_le_bytes());
    pieces.push(Cow::Owned(central));
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc_of_the_check_string() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn the_archive_lists_its_files_with_their_bytes() {
        let files = vec![
            File {
                name: "a.xml".into(),
                bytes: b"<scene/>".to_vec(),
            },
            File {
                name: "a.vol".into(),
                bytes: vec![1, 2, 3],
            },
        ];
        let z = zip(&files);
        assert_eq!(&z[..4], b"PK\x03\x04");
        let end = z.len() - 22;
        assert_eq!(&z[end..end + 4], b"PK\x05\x06");
        assert_eq!(u16::from_le_bytes([z[end + 10], z[end + 11]]), 2);
        let dir = u32::from_le_bytes(z[end + 16..end + 20].try_into().unwrap()) as usize;
        assert_eq!(&z[dir..dir + 4], b"PK\x01\x02");
        // The second entry's data follows its local header.
        let second = 30 + 5 + 8;
        assert_eq!(&z[second..second + 4], b"PK\x03\x04");
        assert_eq!(&z[second + 30 + 5..second + 30 + 5 + 3], &[1, 2, 3]);
    }
}
