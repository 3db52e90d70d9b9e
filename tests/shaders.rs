//! Every shader module the renderer compiles parses and validates with naga, every WGSL file in
//! `shaders/` is part of one, and each WGSL uniform struct has exactly the size and member
//! offsets of the Rust struct it mirrors (`Volume`/`VolumeUniforms`,
//! `FieldSlice`/`FieldSliceUniforms`, `Sky`/`SkyUniforms`, `Behind`/`BehindUniforms`,
//! `LightSlice`/`LightSliceUniforms`).

use std::path::Path;

use cloudsketch::render::gpu_types::{
    BehindUniforms, FieldSliceUniforms, LightSliceUniforms, SkyUniforms, VolumeUniforms,
};
use cloudsketch::render::shaders::MODULES;

fn parse(name: &str, source: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    module
}

#[test]
fn every_composed_module_validates() {
    for (name, _, source) in MODULES {
        parse(name, source);
    }
}

#[test]
fn every_shader_file_is_composed_into_a_module() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut on_disk = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if !name.ends_with(".wgsl") {
            continue;
        }
        on_disk += 1;
        let text = std::fs::read_to_string(dir.join(&name)).unwrap();
        let users: Vec<&str> = MODULES
            .iter()
            .filter(|(_, files, source)| files.contains(&name.as_str()) && source.contains(&text))
            .map(|(m, _, _)| *m)
            .collect();
        assert!(!users.is_empty(), "{name} is in no shader module");
    }
    // And every file a module names exists, in the order the module's source holds them.
    for (module, files, source) in MODULES {
        let texts: Vec<String> = files
            .iter()
            .map(|f| std::fs::read_to_string(dir.join(f)).unwrap())
            .collect();
        assert_eq!(texts.concat(), *source, "{module} is not exactly {files:?}");
    }
    assert!(on_disk >= 4);
}

/// The WGSL struct `name` of `module`: its members' names and offsets, then its size.
fn wgsl_layout(module: &str, name: &str) -> Vec<(String, usize)> {
    let (_, _, source) = MODULES.iter().find(|(n, _, _)| *n == module).unwrap();
    let parsed = parse(module, source);
    let (members, span) = parsed
        .types
        .iter()
        .find_map(|(_, ty)| match (&ty.name, &ty.inner) {
            (Some(n), naga::TypeInner::Struct { members, span }) if n == name => {
                Some((members.clone(), *span))
            }
            _ => None,
        })
        .unwrap_or_else(|| panic!("struct {name} in {module}"));
    members
        .iter()
        .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
        .chain(std::iter::once((String::new(), span as usize)))
        .collect()
}

fn rust_layout(layout: &[(&str, usize)]) -> Vec<(String, usize)> {
    layout.iter().map(|(n, o)| (n.to_string(), *o)).collect()
}

#[test]
fn wgsl_volume_struct_matches_the_rust_layout() {
    assert_eq!(
        wgsl_layout("volume", "Volume"),
        rust_layout(&VolumeUniforms::LAYOUT),
        "WGSL Volume vs Rust VolumeUniforms (name, offset; last: size)"
    );
    assert_eq!(
        VolumeUniforms::LAYOUT.last().unwrap().1,
        std::mem::size_of::<VolumeUniforms>()
    );
}

#[test]
fn wgsl_field_slice_struct_matches_the_rust_layout() {
    assert_eq!(
        wgsl_layout("field_eval", "FieldSlice"),
        rust_layout(&FieldSliceUniforms::LAYOUT),
        "WGSL FieldSlice vs Rust FieldSliceUniforms (name, offset; last: size)"
    );
}

#[test]
fn wgsl_sky_struct_matches_the_rust_layout() {
    assert_eq!(
        wgsl_layout("sky", "Sky"),
        rust_layout(&SkyUniforms::LAYOUT),
        "WGSL Sky vs Rust SkyUniforms (name, offset; last: size)"
    );
}

#[test]
fn wgsl_behind_struct_matches_the_rust_layout() {
    assert_eq!(
        wgsl_layout("composite", "Behind"),
        rust_layout(&BehindUniforms::LAYOUT),
        "WGSL Behind vs Rust BehindUniforms (name, offset; last: size)"
    );
}

#[test]
fn wgsl_light_slice_struct_matches_the_rust_layout() {
    assert_eq!(
        wgsl_layout("light_march", "LightSlice"),
        rust_layout(&LightSliceUniforms::LAYOUT),
        "WGSL LightSlice vs Rust LightSliceUniforms (name, offset; last: size)"
    );
}
