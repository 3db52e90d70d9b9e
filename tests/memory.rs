//! Memory is bounded by the caps, not by the input: the heap's peak, measured by a counting
//! allocator while untrusted input is read, stays within a stated multiple of the cap.
//!
//! - A file read (`files::read_bounded`): at most the cap and one byte, whatever the file says
//!   it is: `/dev/zero`, a FIFO fed more than the cap, a regular file over the cap.
//! - A scene file just under the 64 MiB cap whose bulk is many small objects in a member the
//!   document does not know (it took 5–6 GB when the text was first built into a JSON tree):
//!   read and opened within the file's size and 16 MiB.
//! - A link that inflates to just over its cap: refused within twice the cap and 1 MiB.
//! - A recording's PNG frames (64 MiB of them) made a zip download: its pieces take under
//!   1 MiB beside the frames (an archive built whole took the frames' size again).
//!
//! One test, so nothing else in this binary allocates while it measures.

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use cloudsketch::files::{ReadError, read_bounded};
use cloudsketch::limits::MAX_FILE_BYTES;

struct Counting;

static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(by: usize) {
    let now = CURRENT.fetch_add(by, Ordering::Relaxed) + by;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        grew(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        grew(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        CURRENT.fetch_sub(layout.size(), Ordering::Relaxed);
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > layout.size() {
            grew(new_size - layout.size());
        } else {
            CURRENT.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Runs `f` and returns its result and the heap's peak during it above where it started.
fn peak_of<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = CURRENT.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let out = f();
    (out, PEAK.load(Ordering::Relaxed).saturating_sub(base))
}

const MIB: usize = 1 << 20;

#[test]
fn peak_memory_follows_the_caps_not_the_input() {
    let cap = MAX_FILE_BYTES as usize;
    let dir = std::env::temp_dir().join(format!("cloudsketch-memory-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();

    // /dev/zero reports no size and never ends.
    let (read, peak) = peak_of(|| read_bounded(Path::new("/dev/zero"), MAX_FILE_BYTES));
    assert!(matches!(read, Err(ReadError::TooLarge { .. })), "{read:?}");
    eprintln!("/dev/zero: peak {:.1} MiB", peak as f64 / MIB as f64);
    assert!(peak <= cap + MIB, "/dev/zero: peak {} MiB", peak / MIB);

    // A FIFO fed 80 MiB by another process.
    let fifo = dir.join("fifo");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let mut writer = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "head -c {} /dev/zero > '{}' 2>/dev/null",
            80 * MIB,
            fifo.display()
        ))
        .spawn()
        .unwrap();
    let (read, peak) = peak_of(|| read_bounded(&fifo, MAX_FILE_BYTES));
    assert!(matches!(read, Err(ReadError::TooLarge { .. })), "{read:?}");
    eprintln!("FIFO fed 80 MiB: peak {:.1} MiB", peak as f64 / MIB as f64);
    assert!(peak <= cap + MIB, "FIFO: peak {} MiB", peak / MIB);
    let _ = writer.kill();
    let _ = writer.wait();

    // A scene file of 60 MB: a scene, and a member nobody knows holding ~20 million empty
    // objects. Read and opened (the unknown member skipped) within its size and 16 MiB.
    let scene_path = dir.join("crafted.json");
    {
        let mut f = std::io::BufWriter::new(std::fs::File::create(&scene_path).unwrap());
        write!(f, "{{\"version\": 1, \"junk\": [").unwrap();
        let item = b"{},";
        for _ in 0..(60_000_000 / item.len()) {
            f.write_all(item).unwrap();
        }
        write!(f, "{{}}], \"seed\": 7}}").unwrap();
    }
    let size = std::fs::metadata(&scene_path).unwrap().len() as usize;
    assert!(size > 59_000_000 && size < cap);
    let (opened, peak) = peak_of(|| {
        let bytes = read_bounded(&scene_path, MAX_FILE_BYTES).unwrap();
        cloudsketch::share::open_scene_file("crafted.json", &bytes).map(|(s, _)| s.seed)
    });
    assert_eq!(opened.unwrap(), 7);
    eprintln!(
        "a {:.1} MB scene file read and opened: peak {:.1} MiB",
        size as f64 / 1e6,
        peak as f64 / MIB as f64
    );
    assert!(
        peak <= size + 16 * MIB,
        "a {} MB scene file: peak {} MiB",
        size / 1_000_000,
        peak / MIB
    );

    // The same bulk in a list the document knows stops at the list's cap.
    let planes_path = dir.join("planes.json");
    {
        let mut f = std::io::BufWriter::new(std::fs::File::create(&planes_path).unwrap());
        write!(f, "{{\"version\": 1, \"ellipsoids\": [").unwrap();
        for _ in 0..(60_000_000 / 3) {
            f.write_all(b"{},").unwrap();
        }
        write!(f, "{{}}]}}").unwrap();
    }
    let size = std::fs::metadata(&planes_path).unwrap().len() as usize;
    let (opened, peak) = peak_of(|| {
        let bytes = read_bounded(&planes_path, MAX_FILE_BYTES).unwrap();
        cloudsketch::share::open_scene_file("planes.json", &bytes).map(|_| ())
    });
    let err = opened.unwrap_err().to_string();
    assert!(err.contains("at most 4096"), "{err}");
    eprintln!(
        "60 MB of ellipsoids refused: peak {:.1} MiB",
        peak as f64 / MIB as f64
    );
    assert!(
        peak <= size + 16 * MIB,
        "ellipsoids: peak {} MiB",
        peak / MIB
    );

    // A link whose payload inflates to one byte over its cap.
    let cap = cloudsketch::share::MAX_INFLATED;
    let mut bytes = vec![cloudsketch::share::LINK_VERSION];
    bytes.extend(miniz_oxide::deflate::compress_to_vec(
        &vec![0u8; cap + 1],
        10,
    ));
    use base64::Engine as _;
    let link = format!(
        "#s={}",
        base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(bytes)
    );
    let (decoded, peak) = peak_of(|| cloudsketch::share::decode_link(&link).map(|_| ()));
    let err = decoded.unwrap_err().to_string();
    assert!(err.contains("inflates to more than"), "{err}");
    eprintln!(
        "a link over its cap: peak {:.2} MiB",
        peak as f64 / MIB as f64
    );
    assert!(
        peak <= 2 * cap + MIB,
        "a link over its {} MiB cap: peak {} MiB",
        cap / MIB,
        peak / MIB
    );

    // A recording's frames as one zip: its pieces borrow the frames.
    let frames: Vec<cloudsketch::export::File> = (0..64u8)
        .map(|k| cloudsketch::export::File {
            name: format!("cloud_{k:04}.png"),
            bytes: vec![k; MIB],
        })
        .collect();
    let (pieces, peak) = peak_of(|| cloudsketch::export::zip_pieces(&frames));
    eprintln!(
        "a zip of 64 MiB of frames, in pieces: peak {:.3} MiB",
        peak as f64 / MIB as f64
    );
    assert!(
        peak < MIB,
        "a zip of 64 MiB of frames: peak {peak} bytes beside them"
    );
    let whole = pieces.concat();
    assert_eq!(whole, cloudsketch::export::zip(&frames));
    assert!(whole.len() > 64 * MIB);
    std::fs::remove_dir_all(&dir).unwrap();
}
