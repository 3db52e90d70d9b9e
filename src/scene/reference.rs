//! The reference image (Wither et al. Fig. 1's guide, placed as Blender's reference images
//! are): a picture on a plane in the scene, facing the view it was loaded in, to trace over.
//! It belongs to the document: saved with it (the file's bytes, base64, within
//! [`MAX_EMBEDDED_IMAGE_BYTES`]; a larger file keeps only its name) and undone like any edit.

use std::sync::Arc;

use glam::{Quat, Vec3};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::OrbitCamera;
use crate::limits::MAX_EMBEDDED_IMAGE_BYTES;

/// A picture placed in the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ReferenceImage {
    /// File name.
    pub name: String,
    /// The file as loaded (PNG or JPEG); empty when it was too large to embed.
    #[serde(with = "base64_bytes")]
    pub data: Arc<Vec<u8>>,
    /// Size in pixels (width, height).
    pub size: [u32; 2],
    /// Centre of the picture in the world.
    pub origin: Vec3,
    /// Orientation: the picture's right and up are this rotation of the world's x and y.
    pub rotation: Quat,
    /// Height in world units (the width follows the picture's aspect).
    pub height: f32,
    /// Opacity, 0–1.
    pub opacity: f32,
    /// Shown or hidden.
    pub visible: bool,
    /// Drawn over the cloud (to trace a photo's outline) instead of under it.
    pub in_front: bool,
}

impl Default for ReferenceImage {
    fn default() -> Self {
        Self {
            name: String::new(),
            data: Arc::default(),
            size: [1, 1],
            origin: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            height: 1.0,
            opacity: 0.5,
            visible: true,
            in_front: false,
        }
    }
}

impl ReferenceImage {
    /// A picture of `size` pixels facing `camera`, centred on its focus point and filling
    /// `fill` of the view's height there. `data` is embedded when it is within the cap.
    pub fn facing(
        name: String,
        data: Arc<Vec<u8>>,
        size: [u32; 2],
        camera: &OrbitCamera,
        fill: f32,
    ) -> Self {
        let mut image = Self {
            name,
            data: if data.len() <= MAX_EMBEDDED_IMAGE_BYTES {
                data
            } else {
                Arc::default()
            },
            size: size.map(|v| v.max(1)),
            ..Default::default()
        };
        image.face(camera, fill);
        image
    }

    /// Turns the picture to face `camera` through its focus point, `fill` of the view high.
    pub fn face(&mut self, camera: &OrbitCamera, fill: f32) {
        let (right, up) = (camera.right(), camera.up());
        self.rotation = Quat::from_mat3(&glam::Mat3::from_cols(right, up, right.cross(up)));
        self.origin = camera.target;
        self.height = camera.world_per_px(camera.distance, 1.0) * fill;
    }

    /// Whether the document holds the picture's bytes (not only its name).
    pub fn embedded(&self) -> bool {
        !self.data.is_empty()
    }

    /// World position of a point of the picture, `uv` in 0–1 from its top-left corner.
    pub fn at(&self, uv: [f32; 2]) -> Vec3 {
        let [w, h] = self.size.map(|v| v.max(1) as f32);
        let width = self.height * w / h;
        let local = Vec3::new((uv[0] - 0.5) * width, (0.5 - uv[1]) * self.height, 0.0);
        self.origin + self.rotation * local
    }

    /// Repairs what can be repaired (see [`super::Scene::validate`]); non-finite placement is
    /// refused.
    pub(super) fn validate(&mut self) -> Result<(), String> {
        if !(self.origin.is_finite() && self.rotation.is_finite() && self.height.is_finite()) {
            return Err("the reference image has a non-finite placement".into());
        }
        if self.data.len() > MAX_EMBEDDED_IMAGE_BYTES {
            self.data = Arc::default();
        }
        if let Some(r) = super::unit_rotation(self.rotation) {
            self.rotation = r;
        }
        self.height = if self.height > 0.0 {
            self.height.min(1e6)
        } else {
            1.0
        };
        self.size = self
            .size
            .map(|v| v.clamp(1, crate::limits::MAX_DECODE_SIDE));
        self.opacity = super::finite_or(self.opacity, 0.5).clamp(0.0, 1.0);
        Ok(())
    }
}

/// Bytes as one base64 string in the document.
mod base64_bytes {
    use super::*;
    use base64::Engine as _;
    use base64::engine::general_purpose::STANDARD;

    pub fn serialize<S: Serializer>(data: &Arc<Vec<u8>>, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&STANDARD.encode(data.as_slice()))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Arc<Vec<u8>>, D::Error> {
        let text = String::deserialize(d)?;
        STANDARD.decode(text.as_bytes()).map(Arc::new).map_err(|e| {
            serde::de::Error::custom(format!("reference image data is not base64: {e}"))
        })
    }
}
