//! The tools driven through egui as the window drives them: strokes over frames, outlines in
//! front of and behind the cloud, upright planes, and the modal G with typed numbers.

use glam::Vec3;

use super::*;
use crate::ui::transform::drawing_axes;

/// A stroke through egui as the window gets it: the pointer over the view, then pressed at
/// the right of a circle, 60 moves around it and the release, those events split over
/// `frames` frames 0.15 s apart (a slow adapter's), then two idle frames. Returns each drawing plane's
/// point count.
fn stroke_over_frames(frames: usize) -> Vec<usize> {
    let tool = Toolbox {
        tool: Tool::Sketch,
        ..Default::default()
    };
    let doc = Document::new(crate::scene::Scene::preset(crate::scene::Preset::Empty));
    let (doc, _) = draw_circle(doc, tool, frames, 120.0);
    doc.scene().planes.iter().map(|p| p.points.len()).collect()
}

/// Draws a circle of `radius` points about the view's centre with `tool` over `doc`, its
/// events split over `frames` frames; returns the document and the tool.
fn draw_circle(
    mut doc: Document,
    mut tool: Toolbox,
    frames: usize,
    radius: f32,
) -> (Document, Toolbox) {
    use egui::{Event, Modifiers, PointerButton, pos2};
    let at = |i: usize| {
        let a = i as f32 / 60.0 * std::f32::consts::TAU;
        pos2(640.0 + radius * a.cos(), 400.0 + radius * a.sin())
    };
    let button = |pressed| Event::PointerButton {
        pos: at(60),
        button: PointerButton::Primary,
        pressed,
        modifiers: Modifiers::NONE,
    };
    let mut events = vec![button(true)];
    events.extend((1..=60).map(|i| Event::PointerMoved(at(i))));
    events.push(button(false));
    let per_frame = events.len().div_ceil(frames);
    // A frame with the pointer over the view first (egui hit-tests against the last frame).
    let mut chunks = vec![vec![Event::PointerMoved(at(0))]];
    chunks.extend(events.chunks(per_frame).map(<[_]>::to_vec));
    chunks.extend([Vec::new(), Vec::new()]);

    let mut selection = Selection::default();
    run_frames(chunks, &mut doc, &mut selection, |_, view, _, tc| {
        tool.input(view, tc);
    });
    (doc, tool)
}

/// Runs one egui frame of the test view per entry of `frames` (its events; frames 0.15 s
/// apart, a slow adapter's), calling `each` with the frame's number, the view's input, its
/// `Ui` and a tool context over `doc` and `selection`.
fn run_frames(
    frames: Vec<Vec<egui::Event>>,
    doc: &mut Document,
    selection: &mut Selection,
    mut each: impl FnMut(usize, &ViewInput<'_>, &egui::Response, &mut ToolContext<'_>),
) {
    let rect = crate::ui::test_view();
    let ctx = egui::Context::default();
    let (mut derived, mut notices) = Default::default();
    for (frame, events) in frames.into_iter().enumerate() {
        let raw = egui::RawInput {
            screen_rect: Some(rect),
            time: Some(frame as f64 * 0.15),
            events,
            ..Default::default()
        };
        let mut output = ctx.run_ui(raw, |ui| {
            let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
            let view = ViewInput {
                ui,
                response: &response,
                rect,
            };
            let mut tc = ToolContext {
                doc,
                derived: &mut derived,
                selection,
                notices: &mut notices,
            };
            each(frame, &view, &response, &mut tc);
        });
        // No painter here: the font atlas's first upload is dropped on purpose.
        output.textures_delta.clear();
    }
}

/// The depth along the view of the plane a small outline drawn over the default cumulus's
/// middle lands on, in front or behind.
fn outline_depth(behind: bool) -> f32 {
    let scene = crate::scene::Scene::default();
    let camera = scene.camera.clone();
    let mut tool = Toolbox {
        tool: Tool::Sketch,
        ..Default::default()
    };
    tool.sketch.behind = behind;
    let (doc, _) = draw_circle(Document::new(scene), tool, 5, 40.0);
    let plane = doc.scene().planes.last().expect("a plane").clone();
    (plane.origin - camera.eye()).dot(camera.forward())
}

#[test]
fn an_outline_over_the_cloud_lands_in_front_or_behind_it() {
    let target = {
        let c = crate::scene::Scene::default().camera;
        (c.target - c.eye()).dot(c.forward())
    };
    let (front, back) = (outline_depth(false), outline_depth(true));
    // In front: nearer than the focus point (the cloud's near side); behind: beyond it.
    assert!(front < target - 0.5, "front {front} vs focus {target}");
    assert!(back > target + 0.5, "behind {back} vs focus {target}");
}

#[test]
fn a_view_near_level_draws_on_vertical_planes() {
    let mut camera = crate::scene::Scene::default().camera;
    assert!((camera.pitch_deg - 8.0).abs() < 1e-3, "the default view");
    let (_, up, normal) = drawing_axes(&camera);
    assert_eq!(up, Vec3::Y);
    assert!(normal.y.abs() < 1e-6, "{normal}");
    // The plane of an outline drawn in the default view stands upright.
    let doc = Document::new(crate::scene::Scene::preset(crate::scene::Preset::Empty));
    let tool = Toolbox {
        tool: Tool::Sketch,
        ..Default::default()
    };
    let (doc, _) = draw_circle(doc, tool, 3, 120.0);
    let plane_up = doc.scene().planes[0].rotation * Vec3::Y;
    assert!(plane_up.abs_diff_eq(Vec3::Y, 1e-5), "{plane_up}");
    // Looking down steeply, the plane faces the view.
    camera.pitch_deg = 40.0;
    let (_, up, normal) = drawing_axes(&camera);
    assert!(up.abs_diff_eq(camera.up(), 1e-6));
    assert!(normal.abs_diff_eq(-camera.forward(), 1e-6));
}

#[test]
fn a_stroke_keeps_every_sample_however_its_events_fall_into_frames() {
    // 61 samples (the press and 60 moves), all kept: within one frame and over two egui
    // sees no drag (the press record draws it), over more the drag starts a frame after
    // the press (and begins with every sample since it).
    for frames in [1, 2, 3, 5, 31, 63] {
        assert_eq!(stroke_over_frames(frames), [61], "over {frames} frames");
    }
}

/// A right-click that cancels a grab, pressed, moved 50 px and released within one frame (a
/// busy machine's): the grab goes back and the camera takes none of the drag. Before, the
/// cancel ended the transform and the release freed the button within that frame, so the
/// camera's quick-drag path panned by the whole move.
#[test]
fn a_right_click_that_cancels_a_grab_within_one_frame_moves_no_camera() {
    use egui::{Event, Modifiers, PointerButton, pos2};
    let mut scene = crate::scene::Scene::preset(crate::scene::Preset::Empty);
    scene
        .ellipsoids
        .push(std::sync::Arc::new(crate::scene::Ellipsoid::default()));
    scene.settle();
    let mut doc = Document::new(scene);
    let before = doc.scene().clone();
    let mut selection = Selection::default();
    selection.set(Item::Ellipsoid(0));
    let mut tool = Toolbox::default();
    let (a, b) = (pos2(600.0, 400.0), pos2(650.0, 400.0));
    let button = |pos, pressed| Event::PointerButton {
        pos,
        button: PointerButton::Secondary,
        pressed,
        modifiers: Modifiers::NONE,
    };
    let frames = [
        vec![Event::PointerMoved(a)],
        // G was pressed: the grab follows the pointer.
        vec![Event::PointerMoved(pos2(620.0, 380.0))],
        vec![button(a, true), Event::PointerMoved(b), button(b, false)],
        Vec::new(),
    ];
    let mut camera = doc.scene().camera.clone();
    run_frames(
        frames.into(),
        &mut doc,
        &mut selection,
        |frame, view, response, tc| {
            // As the viewport runs it: the tool, then the camera with what the tool leaves.
            let drawing = tool.input(view, tc);
            crate::ui::camera_input::handle(
                view.ui,
                response,
                &mut camera,
                !drawing,
                tool.quick_drags(),
            );
            if frame == 0 {
                tool.shortcut(Shortcut::Modal(ModalKind::Grab), tc, 0.0);
                assert!(tool.modal_active(), "G starts a grab");
            }
        },
    );
    assert!(!tool.modal_active(), "the right-click cancels the grab");
    assert_eq!(
        doc.scene().ellipsoids,
        before.ellipsoids,
        "back where it began"
    );
    assert_eq!(
        camera, before.camera,
        "the cancelling click moved the camera"
    );
    assert_eq!(
        tool.quick_drags(),
        Some(true),
        "the next frame's drags are the camera's"
    );
}
