//! The guide image (Wither et al. Fig 1): a picture loaded from a file picker, drag & drop or
//! a path, shown as a semi-transparent underlay behind the cloud to sketch over. It is part of
//! the view, not of the document (like a tracing sheet), so it never enters undo or links.

use egui::{Color32, Rect, Ui};

use super::platform as files;

/// A file's name and bytes, or why it could not be read.
pub type Loaded = Result<(String, Vec<u8>), String>;

use crate::limits::{MAX_DECODE_SIDE, MAX_GUIDE_SIDE};

/// A loaded guide image.
pub struct GuideImage {
    /// File name.
    pub name: String,
    /// Size in pixels (after any scaling down).
    pub size: [u32; 2],
    /// The egui texture.
    pub texture: egui::TextureHandle,
}

/// Guide image state.
pub struct Guide {
    /// The image, once loaded.
    pub image: Option<GuideImage>,
    /// Opacity of the underlay.
    pub opacity: f32,
    /// Shown or hidden.
    pub visible: bool,
    /// Path typed in the panel (desktop).
    pub path: String,
    /// Last loading error.
    pub error: Option<String>,
}

impl Default for Guide {
    fn default() -> Self {
        Self {
            image: None,
            opacity: 0.5,
            visible: true,
            path: String::new(),
            error: None,
        }
    }
}

/// Decodes PNG or JPEG bytes into RGBA, refusing huge images and scaling big ones down.
pub fn decode(bytes: &[u8]) -> Result<egui::ColorImage, String> {
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot read the image: {e}"))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_DECODE_SIDE);
    limits.max_image_height = Some(MAX_DECODE_SIDE);
    limits.max_alloc = Some(512 << 20);
    reader.limits(limits);
    if reader.format().is_none() {
        return Err("not a PNG or JPEG image".into());
    }
    let mut img = reader
        .decode()
        .map_err(|e| format!("cannot decode the image: {e}"))?;
    if img.width().max(img.height()) > MAX_GUIDE_SIDE {
        img = img.resize(
            MAX_GUIDE_SIDE,
            MAX_GUIDE_SIDE,
            image::imageops::FilterType::Triangle,
        );
    }
    let rgba = img.to_rgba8();
    Ok(egui::ColorImage::from_rgba_unmultiplied(
        [rgba.width() as usize, rgba.height() as usize],
        rgba.as_raw(),
    ))
}

impl Guide {
    /// Takes dropped and picked files; an image becomes the guide.
    pub fn input(&mut self, ctx: &egui::Context) {
        let dropped = ctx.input_mut(|i| std::mem::take(&mut i.raw.dropped_files));
        let mut loaded: Vec<Loaded> = dropped
            .into_iter()
            .filter_map(|f| files::read_dropped(f, ctx))
            .collect();
        loaded.extend(files::take_loaded());
        for item in loaded {
            self.load(ctx, item);
        }
    }

    fn load(&mut self, ctx: &egui::Context, item: Loaded) {
        let result = item.and_then(|(name, bytes)| {
            decode(&bytes)
                .map(|img| (name, img))
                .map_err(|e| e.to_string())
        });
        match result {
            Ok((name, img)) => {
                let size = [img.size[0] as u32, img.size[1] as u32];
                let texture = ctx.load_texture("guide image", img, egui::TextureOptions::LINEAR);
                self.image = Some(GuideImage {
                    name,
                    size,
                    texture,
                });
                self.visible = true;
                self.error = None;
            }
            Err(e) => {
                log::warn!("guide image: {e}");
                self.error = Some(e);
            }
        }
    }

    /// Paints the guide under the cloud, fitted into the viewport and centred.
    pub fn paint(&self, painter: &egui::Painter, rect: Rect) {
        let Some(image) = self.image.as_ref().filter(|_| self.visible) else {
            return;
        };
        let [w, h] = image.size.map(|v| v.max(1) as f32);
        let scale = (rect.width() / w).min(rect.height() / h);
        let fitted = Rect::from_center_size(rect.center(), egui::vec2(w * scale, h * scale));
        let alpha = (self.opacity.clamp(0.0, 1.0) * 255.0).round() as u8;
        painter.image(
            image.texture.id(),
            fitted,
            Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
            Color32::from_white_alpha(alpha),
        );
    }

    /// The Guide image group of the side panel.
    pub fn ui(&mut self, ui: &mut Ui) {
        egui::CollapsingHeader::new("Guide image")
            .default_open(false)
            .show(ui, |ui| {
                ui.horizontal(|ui| {
                    if files::HAS_PICKER
                        && ui
                            .button("Load…")
                            .on_hover_text("or drop a PNG/JPEG on the view")
                            .clicked()
                    {
                        files::open_picker();
                    }
                    if self.image.is_some() && ui.button("Remove").clicked() {
                        self.image = None;
                    }
                });
                if !files::HAS_PICKER {
                    ui.horizontal(|ui| {
                        ui.text_edit_singleline(&mut self.path)
                            .on_hover_text("path of a PNG or JPEG; or drop one on the view");
                        if ui.button("Load").clicked() {
                            let item = files::read_path(self.path.trim());
                            self.load(ui.ctx(), item);
                        }
                    });
                }
                if let Some(image) = &self.image {
                    ui.label(format!(
                        "{} ({}×{})",
                        image.name, image.size[0], image.size[1]
                    ));
                    ui.checkbox(&mut self.visible, "show");
                    ui.add(egui::Slider::new(&mut self.opacity, 0.0..=1.0).text("opacity"));
                } else {
                    ui.label("Drop a PNG or JPEG on the view to sketch over it.");
                }
                if let Some(e) = &self.error {
                    ui.colored_label(Color32::LIGHT_RED, e);
                }
            });
    }
}
