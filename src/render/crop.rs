//! The part of a view the volume is drawn in: the pixels the cloud's box covers on screen.
//! The viewport slices, refines and composites only those; the shafts of light over the rest
//! of the view are drawn apart ([`super::VolumeRenderer::draw_outside_shafts`]).

/// The part of the viewport the volume is drawn in, in whole pixels (x0, y0, x1, y1; y down).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelCrop {
    /// Left, top, right, bottom, in pixels.
    pub px: [u32; 4],
}

impl PixelCrop {
    /// The pixels covering a rectangle of normalised device coordinates, one pixel of margin.
    pub fn snap(ndc: [f32; 4], view: [u32; 2]) -> Self {
        let [w, h] = view.map(|v| v as f32);
        let [x0, y0, x1, y1] = ndc;
        let px = |v: f32, max: u32| (v.max(0.0) as u32).min(max);
        let left = px(((x0 + 1.0) * 0.5 * w).floor() - 1.0, view[0] - 1);
        let right = px(((x1 + 1.0) * 0.5 * w).ceil() + 1.0, view[0]).max(left + 1);
        let top = px(((1.0 - y1) * 0.5 * h).floor() - 1.0, view[1] - 1);
        let bottom = px(((1.0 - y0) * 0.5 * h).ceil() + 1.0, view[1]).max(top + 1);
        Self {
            px: [left, top, right, bottom],
        }
    }

    /// Its size in pixels.
    pub fn size(&self) -> [u32; 2] {
        [self.px[2] - self.px[0], self.px[3] - self.px[1]]
    }

    /// The crop in normalised device coordinates of a `view`-sized viewport (y up).
    pub fn ndc(&self, view: [u32; 2]) -> [f32; 4] {
        let [w, h] = view.map(|v| v as f32);
        let [x0, y0, x1, y1] = self.px.map(|v| v as f32);
        [
            x0 / w * 2.0 - 1.0,
            1.0 - y1 / h * 2.0,
            x1 / w * 2.0 - 1.0,
            1.0 - y0 / h * 2.0,
        ]
    }
}

/// The shafts of light outside the cloud's box are drawn at this fraction of the view's size
/// (the viewport halves it again while a drag is under way): their light is soft, and a CPU
/// adapter pays for every pixel of every shell.
pub const OUTSIDE_SHAFTS_DIVISOR: u32 = 4;
