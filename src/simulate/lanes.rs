//! Words of cells as the automaton's rule takes them: one `u64`, or a [`Pair`] of words side
//! by side.
//!
//! The step runs on pairs. On wasm32 with SIMD128 a pair is one `v128`: the page's
//! size-optimised build vectorises no loop itself, and the step on pairs is 1.7 times as fast
//! there. Elsewhere a pair is a `[u64; 2]`, which the optimiser puts in one SIMD register. A
//! word at a time is the baseline the page's benchmark and the tests compare pairs with.

use std::ops::{BitAnd, BitOr, Not, Shl, Shr};

pub use imp::Pair;

/// A word or words of cells, loaded from and stored to runs of words.
pub trait Lanes:
    Copy
    + BitOr<Output = Self>
    + BitAnd<Output = Self>
    + Not<Output = Self>
    + Shl<u32, Output = Self>
    + Shr<u32, Output = Self>
{
    /// Words it holds.
    const WIDTH: usize;

    /// Words `k..k + WIDTH` of `s`, unchecked: a loop checks its runs' lengths once, since
    /// the page's size-optimised build keeps a check per load otherwise (a third of the
    /// rule's time there).
    ///
    /// # Safety
    /// `k + WIDTH <= s.len()`.
    unsafe fn load(s: &[u64], k: usize) -> Self;

    /// Writes itself to words `k..k + WIDTH` of `s`, unchecked.
    ///
    /// # Safety
    /// `k + WIDTH <= s.len()`.
    unsafe fn store(self, s: &mut [u64], k: usize);
}

impl Lanes for u64 {
    const WIDTH: usize = 1;

    #[inline(always)]
    unsafe fn load(s: &[u64], k: usize) -> Self {
        // SAFETY: the caller keeps k in `s`.
        unsafe { *s.get_unchecked(k) }
    }

    #[inline(always)]
    unsafe fn store(self, s: &mut [u64], k: usize) {
        // SAFETY: the caller keeps k in `s`.
        unsafe { *s.get_unchecked_mut(k) = self }
    }
}

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
mod imp {
    use core::arch::wasm32::{
        i64x2_shl, u64x2_shr, v128, v128_and, v128_load, v128_not, v128_or, v128_store,
    };

    /// Two words in one SIMD register.
    #[derive(Clone, Copy)]
    pub struct Pair(v128);

    impl super::Lanes for Pair {
        const WIDTH: usize = 2;

        #[inline(always)]
        unsafe fn load(s: &[u64], k: usize) -> Self {
            // SAFETY: the caller keeps words k and k + 1 in `s`; v128_load reads unaligned.
            Self(unsafe { v128_load(s.as_ptr().add(k).cast()) })
        }

        #[inline(always)]
        unsafe fn store(self, s: &mut [u64], k: usize) {
            // SAFETY: the caller keeps words k and k + 1 in `s`; v128_store writes unaligned.
            unsafe { v128_store(s.as_mut_ptr().add(k).cast(), self.0) }
        }
    }

    impl super::BitOr for Pair {
        type Output = Self;
        #[inline(always)]
        fn bitor(self, o: Self) -> Self {
            Self(v128_or(self.0, o.0))
        }
    }

    impl super::BitAnd for Pair {
        type Output = Self;
        #[inline(always)]
        fn bitand(self, o: Self) -> Self {
            Self(v128_and(self.0, o.0))
        }
    }

    impl super::Not for Pair {
        type Output = Self;
        #[inline(always)]
        fn not(self) -> Self {
            Self(v128_not(self.0))
        }
    }

    impl super::Shl<u32> for Pair {
        type Output = Self;
        #[inline(always)]
        fn shl(self, n: u32) -> Self {
            Self(i64x2_shl(self.0, n))
        }
    }

    impl super::Shr<u32> for Pair {
        type Output = Self;
        #[inline(always)]
        fn shr(self, n: u32) -> Self {
            Self(u64x2_shr(self.0, n))
        }
    }
}

#[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
mod imp {
    /// Two words.
    #[derive(Clone, Copy)]
    pub struct Pair([u64; 2]);

    impl super::Lanes for Pair {
        const WIDTH: usize = 2;

        #[inline(always)]
        unsafe fn load(s: &[u64], k: usize) -> Self {
            // SAFETY: the caller keeps words k and k + 1 in `s`.
            unsafe { Self([*s.get_unchecked(k), *s.get_unchecked(k + 1)]) }
        }

        #[inline(always)]
        unsafe fn store(self, s: &mut [u64], k: usize) {
            // SAFETY: the caller keeps words k and k + 1 in `s`.
            unsafe {
                *s.get_unchecked_mut(k) = self.0[0];
                *s.get_unchecked_mut(k + 1) = self.0[1];
            }
        }
    }

    impl super::BitOr for Pair {
        type Output = Self;
        #[inline(always)]
        fn bitor(self, o: Self) -> Self {
            Self([self.0[0] | o.0[0], self.0[1] | o.0[1]])
        }
    }

    impl super::BitAnd for Pair {
        type Output = Self;
        #[inline(always)]
        fn bitand(self, o: Self) -> Self {
            Self([self.0[0] & o.0[0], self.0[1] & o.0[1]])
        }
    }

    impl super::Not for Pair {
        type Output = Self;
        #[inline(always)]
        fn not(self) -> Self {
            Self(self.0.map(|w| !w))
        }
    }

    impl super::Shl<u32> for Pair {
        type Output = Self;
        #[inline(always)]
        fn shl(self, n: u32) -> Self {
            Self(self.0.map(|w| w << n))
        }
    }

    impl super::Shr<u32> for Pair {
        type Output = Self;
        #[inline(always)]
        fn shr(self, n: u32) -> Self {
            Self(self.0.map(|w| w >> n))
        }
    }
}
