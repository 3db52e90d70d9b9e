//! The one way files are written and read natively (the CLI, the desktop window's Save,
//! autosave, exports and screenshots).
//!
//! - [`write_atomic`]: a temporary file in the same folder, renamed over the target on success
//!   and removed on failure, so a full disk or a crash never leaves a truncated file under the
//!   final name, and an old file stays whole until its replacement is.
//! - [`read_bounded`]: reads at most a cap, whatever the file claims to be (`/dev/zero`, a FIFO,
//!   a file that grows while read), so memory is bounded by the cap and not by the input.
//!
//! `tests/architecture.rs` rejects any other `std::fs::write` or `File::create` under `src/`.

use std::io::{Read, Write};

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `bytes` at `path` through a temporary file beside it, making its folder first where
/// it does not exist: on success the file holds exactly `bytes`; on failure it is as it was
/// (absent, or its old content) and no temporary file is left.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    if let Some(folder) = path.parent().filter(|f| !f.as_os_str().is_empty())
        && !folder.exists()
    {
        std::fs::create_dir_all(folder)?;
    }
    let tmp = temporary_beside(path);
    let written = (|| {
        let mut file = std::fs::File::create(&tmp)?;
        file.write_all(bytes)?;
        file.sync_all()
    })();
    let renamed = written.and_then(|()| std::fs::rename(&tmp, path));
    if renamed.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    renamed
}

/// Whether `path` can be written, found out before the work that would fill it: a temporary file
/// is made beside it and removed. A folder at `path` is refused.
pub fn check_writable(path: &Path) -> std::io::Result<()> {
    if path.is_dir() {
        return Err(std::io::Error::other("a folder, not a file"));
    }
    let tmp = temporary_beside(path);
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)?;
    std::fs::remove_file(&tmp)
}

/// A name for a temporary file in `path`'s folder that no other writer in this or another
/// process picks: `.NAME.PID.N.tmp`.
fn temporary_beside(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = format!(".{name}.{}.{n}.tmp", std::process::id());
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.join(tmp),
        _ => PathBuf::from(tmp),
    }
}

/// Why a bounded read failed.
#[derive(Debug)]
pub enum ReadError {
    /// The path was empty.
    Empty,
    /// The operating system's error (not found, a folder, permission…).
    Io(std::io::Error),
    /// More than `cap` bytes: nothing past the cap was read.
    TooLarge {
        /// The cap in bytes.
        cap: u64,
    },
}

impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReadError::Empty => write!(f, "no file named: the path is empty"),
            ReadError::Io(e) if e.kind() == std::io::ErrorKind::NotFound => {
                write!(f, "no such file")
            }
            ReadError::Io(e) => write!(f, "{e}"),
            ReadError::TooLarge { cap } => write!(f, "larger than the {} limit", size_text(*cap)),
        }
    }
}

impl ReadError {
    /// The error as a message that names `path` (an empty path is not named: it is the error).
    pub fn at(&self, path: &Path) -> String {
        match self {
            ReadError::Empty => self.to_string(),
            e => format!("{}: {e}", path.display()),
        }
    }
}

/// `64 MiB`, `512 KiB` or `100 bytes`.
pub fn size_text(bytes: u64) -> String {
    if bytes >= 1 << 20 && bytes.is_multiple_of(1 << 20) {
        format!("{} MiB", bytes >> 20)
    } else if bytes >= 1 << 10 && bytes.is_multiple_of(1 << 10) {
        format!("{} KiB", bytes >> 10)
    } else {
        format!("{bytes} bytes")
    }
}

/// Reads a whole file of at most `cap` bytes. It never reads more than `cap + 1` bytes nor
/// allocates for more, whatever the file's reported size (a device or a FIFO reports none), and
/// a folder is an error.
pub fn read_bounded(path: &Path, cap: u64) -> Result<Vec<u8>, ReadError> {
    if path.as_os_str().is_empty() {
        return Err(ReadError::Empty);
    }
    let file = std::fs::File::open(path).map_err(ReadError::Io)?;
    let meta = file.metadata().map_err(ReadError::Io)?;
    if meta.is_dir() {
        return Err(ReadError::Io(std::io::Error::other("a folder, not a file")));
    }
    if meta.is_file() && meta.len() > cap {
        return Err(ReadError::TooLarge { cap });
    }
    // A regular file's size is a hint only (it may grow). The buffer grows by doubling but
    // never past the cap and one byte (`read_to_end` would double past it: twice the cap).
    let limit = usize::try_from(cap.saturating_add(1)).unwrap_or(usize::MAX);
    let hint = if meta.is_file() {
        usize::try_from(meta.len())
            .unwrap_or(usize::MAX)
            .saturating_add(1)
    } else {
        0
    };
    let mut bytes = Vec::with_capacity(hint.min(limit));
    let mut file = file;
    let mut chunk = vec![0u8; 64 << 10];
    loop {
        let room = limit - bytes.len();
        if room == 0 {
            return Err(ReadError::TooLarge { cap });
        }
        let want = room.min(chunk.len());
        let n = match file.read(&mut chunk[..want]) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(ReadError::Io(e)),
        };
        if bytes.len() + n > bytes.capacity() {
            let grown = (bytes.capacity() * 2).max(bytes.len() + n).min(limit);
            bytes.reserve_exact(grown - bytes.len());
        }
        bytes.extend_from_slice(&chunk[..n]);
    }
    if bytes.len() as u64 > cap {
        return Err(ReadError::TooLarge { cap });
    }
    Ok(bytes)
}

/// [`read_bounded`] as UTF-8 text; a leading byte-order mark is dropped.
pub fn read_bounded_text(path: &Path, cap: u64) -> Result<String, ReadError> {
    let bytes = read_bounded(path, cap)?;
    let text = String::from_utf8(bytes).map_err(|_| {
        ReadError::Io(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "not UTF-8 text",
        ))
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_owned(),
        None => text,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("cloudsketch-files-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn listing(d: &Path) -> Vec<String> {
        let mut names: Vec<_> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn a_write_replaces_the_whole_file_and_leaves_nothing_beside_it() {
        let d = dir("write");
        let path = d.join("out.png");
        write_atomic(&path, b"old content, longer").unwrap();
        write_atomic(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(listing(&d), ["out.png"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_failed_write_keeps_the_old_file_and_leaves_no_temporary() {
        let d = dir("fail");
        // The target is a non-empty folder: the rename fails after the bytes were written.
        let path = d.join("taken");
        std::fs::create_dir(&path).unwrap();
        std::fs::write(path.join("inside"), b"kept").unwrap();
        assert!(write_atomic(&path, b"bytes").is_err());
        assert_eq!(listing(&d), ["taken"]);
        assert_eq!(std::fs::read(path.join("inside")).unwrap(), b"kept");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_bounded_read_stops_at_the_cap_whatever_the_file() {
        let d = dir("read");
        let path = d.join("a.json");
        std::fs::write(&path, b"\xef\xbb\xbf{}").unwrap();
        assert_eq!(
            read_bounded_text(&path, 16).unwrap(),
            "{}",
            "the BOM is dropped"
        );
        assert!(matches!(
            read_bounded(&path, 4),
            Err(ReadError::TooLarge { cap: 4 })
        ));
        // An endless device reports no size: the read still stops just past the cap.
        if Path::new("/dev/zero").exists() {
            assert!(matches!(
                read_bounded(Path::new("/dev/zero"), 1 << 20),
                Err(ReadError::TooLarge { .. })
            ));
        }
        assert!(matches!(
            read_bounded(Path::new(""), 4),
            Err(ReadError::Empty)
        ));
        let missing = read_bounded(&d.join("missing"), 4).unwrap_err();
        assert_eq!(missing.to_string(), "no such file");
        assert!(read_bounded(&d, 4).is_err(), "a folder");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
