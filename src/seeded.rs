//! Seeded randomness (pure): one well-mixed 64-bit hash and a tiny generator built on it.
//!
//! Everything random in cloudsketch is derived from seeds stored in the document through these
//! two, so native, wasm and tests agree bit for bit.

/// SplitMix64's finaliser: a fast, well-mixed hash of a 64-bit value.
pub fn hash64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// FNV-1a over bytes: a 64-bit hash that is the same in every process and build (std's hasher
/// is not promised to be), for keys written to files (a sequence's sidecars, checkpoints).
pub fn stable_hash(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// SplitMix64: a deterministic stream of numbers from a seed.
#[derive(Clone, Debug)]
pub struct SplitMix(u64);

impl SplitMix {
    /// A generator starting from `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        let out = hash64(self.0);
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        out
    }

    /// A uniform number in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stream_is_deterministic_and_uniform_enough() {
        let mut a = SplitMix::new(5);
        let mut b = SplitMix::new(5);
        let xs: Vec<f64> = (0..4000).map(|_| a.next_f64()).collect();
        assert!(
            xs.iter()
                .zip((0..4000).map(|_| b.next_f64()))
                .all(|(x, y)| *x == y)
        );
        assert!(xs.iter().all(|x| (0.0..1.0).contains(x)));
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        assert!((mean - 0.5).abs() < 0.02, "{mean}");
        assert_ne!(hash64(1), hash64(2));
    }
}
