//! Billows: the hierarchy of puffs on a primitive's surface (Bouthors & Neyret 2004, "Modeling
//! clouds shape"): smaller spheres on the surface of larger ones, level after level, which gives
//! a cumulus its cauliflower outline. The document holds the control; the puffs themselves are
//! derived (`field::billows`), seeded by the primitive's stable id.

use serde::{Deserialize, Serialize};

use crate::limits;

/// A primitive's billows control. A document made before billows existed has none (the
/// default): it keeps its look. New strokes and ellipsoids get [`Billows::NEW`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Billows {
    /// Levels of puffs on puffs (0: none).
    pub levels: u32,
    /// Each level's puff radius over the radius of what it sits on.
    pub ratio: f32,
    /// Share of each parent's surface its puffs cover.
    pub coverage: f32,
}

// Not derived: a default's ratio and coverage are a new primitive's, so a file that sets only
// `levels` gets puffs of the usual size (clippy reads `..Self::NEW` as the derived default).
#[allow(clippy::derivable_impls)]
impl Default for Billows {
    fn default() -> Self {
        Self {
            levels: 0,
            ..Self::NEW
        }
    }
}

impl Billows {
    /// What a new stroke or ellipsoid gets: a new user's first cloud looks like a cloud.
    pub const NEW: Self = Self {
        levels: limits::BILLOW_LEVELS.default as u32,
        ratio: limits::BILLOW_RATIO.default as f32,
        coverage: limits::BILLOW_COVERAGE.default as f32,
    };

    /// Whether the primitive has no puffs.
    pub fn is_off(&self) -> bool {
        self.levels == 0 || self.coverage <= 0.0
    }

    /// Whether a file leaves it out: no levels (a missing one reads as none). Billows with
    /// levels are kept whatever their coverage, so a coverage keyed to 0 at the time a
    /// document is saved does not lose them.
    pub fn is_unset(&self) -> bool {
        self.levels == 0
    }

    /// Clamps every value into its range (documents and links may carry anything).
    pub fn sanitize(&mut self) {
        self.levels = limits::BILLOW_LEVELS.fix_u32(self.levels);
        self.ratio = limits::BILLOW_RATIO.fix_f32(self.ratio);
        self.coverage = limits::BILLOW_COVERAGE.fix_f32(self.coverage);
    }

    /// The `(levels, ratio, coverage)` bits, for cache keys.
    pub fn key(&self) -> (u32, u32, u32) {
        if self.is_off() {
            (0, 0, 0)
        } else {
            (self.levels, self.ratio.to_bits(), self.coverage.to_bits())
        }
    }
}
