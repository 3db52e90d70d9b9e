//! The reference image's view (the paper's guide image, placed as Blender's reference images
//! are): loading a picture from the file picker, drag & drop or a path into the document as a
//! [`ReferenceImage`] facing the view, its texture, drawing it in the scene under or over the
//! cloud, and its group in the side panel. The picture itself lives in the document.

use egui::{Color32, Rect, Ui};

use super::notice::Notices;
use super::platform as files;
use crate::scene::{Document, Edit, OrbitCamera, ReferenceImage};

/// A file's name and bytes, or why it could not be read.
pub type Loaded = Result<(String, Vec<u8>), String>;

use std::collections::HashMap;
use std::sync::Arc;

use crate::limits::MAX_EMBEDDED_IMAGE_BYTES;

/// Share of the view's height a new reference image fills.
const FILL: f32 = 0.8;

/// The reference image's texture and the panel's state.
#[derive(Default)]
pub struct Guide {
    /// The texture of the document's picture, keyed by its bytes' allocation (`None` while it
    /// is being decoded, or when it could not be decoded or is not embedded).
    texture: Option<(u64, Option<egui::TextureHandle>)>,
    /// Files being decoded (the browser decodes asynchronously), by ticket.
    pending: HashMap<u64, (String, Arc<Vec<u8>>)>,
    /// The last ticket given.
    tickets: u64,
    /// Path typed in the panel (desktop).
    pub path: String,
    /// Last loading error.
    pub error: Option<String>,
}

impl Guide {
    /// Takes the loaded picture files (each becomes the document's reference image once
    /// decoded; the app routes scene files elsewhere) and finished decodes.
    pub fn input(
        &mut self,
        ctx: &egui::Context,
        doc: &mut Document,
        notices: &mut Notices,
        loaded: Vec<Loaded>,
    ) {
        for item in loaded {
            self.load(item);
        }
        let now = ctx.input(|i| i.time);
        for (key, result) in files::take_decoded() {
            if let Some((name, bytes)) = self.pending.remove(&key) {
                self.place(ctx, doc, notices, now, name, bytes, result);
            } else if self.texture.as_ref().is_some_and(|(k, _)| *k == key) {
                // The document's picture, decoded for its texture.
                let handle = match result {
                    Ok(img) => Some(upload(ctx, img)),
                    Err(e) => {
                        self.error = Some(e);
                        None
                    }
                };
                self.texture = Some((key, handle));
            }
        }
    }

    /// Starts decoding a loaded file (it replaces the picture only if it decodes).
    fn load(&mut self, item: Loaded) {
        match item {
            Ok((name, bytes)) => {
                // Tickets have the top bit set, so they never equal a picture's address.
                self.tickets += 1;
                let ticket = (1 << 63) | self.tickets;
                let bytes = Arc::new(bytes);
                self.pending.insert(ticket, (name, bytes.clone()));
                files::decode_image(ticket, bytes);
            }
            Err(e) => {
                log::warn!("reference image: {e}");
                self.error = Some(e);
            }
        }
    }

    /// A decoded file becomes the document's picture, facing the view.
    #[allow(clippy::too_many_arguments)]
    fn place(
        &mut self,
        ctx: &egui::Context,
        doc: &mut Document,
        notices: &mut Notices,
        now: f64,
        name: String,
        bytes: Arc<Vec<u8>>,
        decoded: Result<egui::ColorImage, String>,
    ) {
        let img = match decoded {
            Ok(img) => img,
            Err(e) => {
                let e = format!("{name}: {e}");
                log::warn!("reference image: {e}");
                self.error = Some(e);
                return;
            }
        };
        self.error = None;
        let embedded = bytes.len() <= MAX_EMBEDDED_IMAGE_BYTES;
        let size = [img.size[0] as u32, img.size[1] as u32];
        let image = ReferenceImage::facing(name.clone(), bytes, size, &doc.scene().camera, FILL);
        let key = Arc::as_ptr(&image.data) as u64;
        doc.apply(Edit::SetReference(Some(image)), None);
        self.texture = Some((key, Some(upload(ctx, img))));
        notices.note(
            now,
            if embedded {
                format!("{name} placed facing the view (Ctrl+Z undoes)")
            } else {
                format!(
                    "{name} placed facing the view; larger than {} MiB, so the document keeps only its name",
                    MAX_EMBEDDED_IMAGE_BYTES >> 20
                )
            },
        );
    }

    /// The texture of `image`, once decoded (decoding starts on the first call per picture).
    fn texture(&mut self, image: &ReferenceImage) -> Option<egui::TextureId> {
        let key = Arc::as_ptr(&image.data) as u64;
        if self.texture.as_ref().is_none_or(|(k, _)| *k != key) {
            self.texture = Some((key, None));
            if image.embedded() {
                files::decode_image(key, image.data.clone());
            }
        }
        self.texture.as_ref()?.1.as_ref().map(|t| t.id())
    }

    /// Draws the document's reference image where it stands in the scene, if it is shown and
    /// belongs to this layer (`in_front`: over the cloud, else under it).
    pub fn paint(&mut self, painter: &egui::Painter, rect: Rect, doc: &Document, in_front: bool) {
        let scene = doc.scene();
        let Some(image) = scene
            .reference
            .as_deref()
            .filter(|r| r.visible && r.in_front == in_front)
        else {
            return;
        };
        let Some(texture) = self.texture(image) else {
            return;
        };
        let alpha = (image.opacity.clamp(0.0, 1.0) * 255.0).round() as u8;
        painter.add(mesh(
            &scene.camera,
            rect,
            image,
            texture,
            Color32::from_white_alpha(alpha),
        ));
    }

    /// The Reference image group of the side panel.
    pub fn ui(&mut self, ui: &mut Ui, doc: &mut Document, notices: &mut Notices) {
        super::widgets::group(ui, "Reference image", false, |ui| {
            let now = ui.input(|i| i.time);
            ui.horizontal(|ui| {
                    if files::HAS_PICKER
                        && ui
                            .button("Load…")
                            .on_hover_text("A PNG or JPEG to trace (or drop one on the view): it is placed in the scene, facing the view")
                            .clicked()
                    {
                        files::open_picker();
                    }
                    if doc.scene().reference.is_some()
                        && ui.button("Remove").clicked()
                        && doc.apply(Edit::SetReference(None), None)
                    {
                        notices.note(now, "Removed the reference image (Ctrl+Z undoes)");
                    }
                });
            if !files::HAS_PICKER {
                ui.horizontal(|ui| {
                    // The field leaves room for its button within the panel.
                    let width = (ui.available_width() - 56.0).max(60.0);
                    ui.add(egui::TextEdit::singleline(&mut self.path).desired_width(width))
                        .on_hover_text("path of a PNG or JPEG; or drop one on the view");
                    if ui.button("Load").clicked() {
                        self.load(files::read_path(self.path.trim()));
                    }
                });
            }
            if let Some(current) = doc.scene().reference.as_deref() {
                let mut image = current.clone();
                ui.label(format!(
                    "{} ({}×{})",
                    image.name, image.size[0], image.size[1]
                ));
                if !image.embedded() {
                    ui.label(
                        egui::RichText::new(
                            "not in the document (too large): load it again after reopening",
                        )
                        .small()
                        .color(ui.visuals().warn_fg_color),
                    );
                }
                ui.horizontal(|ui| {
                    ui.checkbox(&mut image.visible, "show");
                    ui.checkbox(&mut image.in_front, "over the cloud")
                        .on_hover_text(
                            "Draw the picture in front of the cloud, to trace a photo's outline",
                        );
                });
                ui.add(egui::Slider::new(&mut image.opacity, 0.0..=1.0).text("opacity"));
                if ui
                    .button("Face the view")
                    .on_hover_text(
                        "Turn the picture to face the current view, through its focus point",
                    )
                    .clicked()
                {
                    image.face(&doc.scene().camera, FILL);
                }
                if image != *current {
                    doc.apply(Edit::SetReference(Some(image)), Some("reference"));
                }
            } else {
                ui.label("Drop a PNG or JPEG on the view to trace over it.");
            }
            if let Some(e) = &self.error {
                ui.colored_label(Color32::LIGHT_RED, e);
            }
        });
    }
}

/// A decoded picture as a smoothly filtered texture.
fn upload(ctx: &egui::Context, img: egui::ColorImage) -> egui::TextureHandle {
    ctx.load_texture("reference image", img, egui::TextureOptions::LINEAR)
}

/// The picture as a grid of small quads projected through the camera, so it keeps its place
/// and perspective in the scene (a single quad's texture would shear across its diagonal).
fn mesh(
    camera: &OrbitCamera,
    rect: Rect,
    image: &ReferenceImage,
    texture: egui::TextureId,
    tint: Color32,
) -> egui::Mesh {
    const N: u32 = 16;
    let mut mesh = egui::Mesh::with_texture(texture);
    let mut index = vec![None; ((N + 1) * (N + 1)) as usize];
    for j in 0..=N {
        for i in 0..=N {
            let uv = [i as f32 / N as f32, j as f32 / N as f32];
            if let Some(ndc) = camera.project(image.at(uv), rect.aspect_ratio()) {
                let pos = egui::pos2(
                    rect.left() + (ndc.x + 1.0) * 0.5 * rect.width(),
                    rect.top() + (1.0 - ndc.y) * 0.5 * rect.height(),
                );
                index[(j * (N + 1) + i) as usize] = Some(mesh.vertices.len() as u32);
                mesh.vertices.push(egui::epaint::Vertex {
                    pos,
                    uv: egui::pos2(uv[0], uv[1]),
                    color: tint,
                });
            }
        }
    }
    let at = |i: u32, j: u32| index[(j * (N + 1) + i) as usize];
    for j in 0..N {
        for i in 0..N {
            if let (Some(a), Some(b), Some(c), Some(d)) =
                (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1))
            {
                mesh.add_triangle(a, b, d);
                mesh.add_triangle(a, d, c);
            }
        }
    }
    mesh
}
