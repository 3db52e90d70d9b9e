//! Any bytes into the link decoders, through `share::check_untrusted` (which says what must
//! hold). The crate's pure core is compiled from ../src directly: no window, GPU or browser
//! crates, so the sanitised build stays small.
#![no_main]
#![allow(dead_code, unused_imports)]

#[path = "../../src/atmosphere.rs"]
mod atmosphere;
#[path = "../../src/density.rs"]
mod density;
#[path = "../../src/derive/mod.rs"]
mod derive;
#[path = "../../src/field/mod.rs"]
mod field;
#[path = "../../src/limits.rs"]
mod limits;
#[path = "../../src/scene/mod.rs"]
mod scene;
#[path = "../../src/seeded.rs"]
mod seeded;
#[path = "../../src/share/mod.rs"]
mod share;
#[path = "../../src/simulate/mod.rs"]
mod simulate;
#[path = "../../src/sketch/mod.rs"]
mod sketch;

libfuzzer_sys::fuzz_target!(|data: &[u8]| share::check_untrusted(data));
