//! Every WGSL file in `shaders/` parses and validates with naga, and the renderer's list of
//! shaders covers the whole folder.

use std::path::Path;

fn validate(name: &str, source: &str) {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
}

#[test]
fn every_shader_file_validates() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "wgsl") {
            let source = std::fs::read_to_string(&path).unwrap();
            validate(&path.display().to_string(), &source);
            count += 1;
        }
    }
    assert!(count >= 3, "expected the shaders in {}", dir.display());
}

#[test]
fn renderer_embeds_every_shader_file() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let on_disk: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".wgsl"))
        .collect();
    for name in &on_disk {
        let text = std::fs::read_to_string(dir.join(name)).unwrap();
        assert!(
            cloudsketch::render::shaders::ALL
                .iter()
                .any(|(_, src)| *src == text),
            "{name} is not in render::shaders::ALL"
        );
    }
    assert_eq!(on_disk.len(), cloudsketch::render::shaders::ALL.len());
}
