//! Shader sources, compiled into the binary. WGSL has no include: modules that share the
//! `Volume` uniforms are composed here from `shaders/volume_common.wgsl` and their own file,
//! and `tests/shaders.rs` validates every composed module with naga.

/// `shaders/volume_common.wgsl`: the `Volume` uniforms and the slice bind group.
pub const VOLUME_COMMON: &str = include_str!("../../shaders/volume_common.wgsl");

/// The slice shader: `volume_common.wgsl` + `volume_noise.wgsl` + `sun_shadow.wgsl` +
/// `volume.wgsl`.
pub const VOLUME: &str = concat!(
    include_str!("../../shaders/volume_common.wgsl"),
    include_str!("../../shaders/volume_noise.wgsl"),
    include_str!("../../shaders/sun_shadow.wgsl"),
    include_str!("../../shaders/volume.wgsl")
);

/// The marched slices (compute): `volume_common.wgsl` + `volume_noise.wgsl` +
/// `sun_shadow.wgsl` + `volume.wgsl` + `volume_march.wgsl`.
pub const VOLUME_MARCH: &str = concat!(
    include_str!("../../shaders/volume_common.wgsl"),
    include_str!("../../shaders/volume_noise.wgsl"),
    include_str!("../../shaders/sun_shadow.wgsl"),
    include_str!("../../shaders/volume.wgsl"),
    include_str!("../../shaders/volume_march.wgsl")
);

/// The media at probe points (tests): `volume_common.wgsl` + `volume_noise.wgsl` +
/// `media_probe.wgsl`.
pub const MEDIA_PROBE: &str = concat!(
    include_str!("../../shaders/volume_common.wgsl"),
    include_str!("../../shaders/volume_noise.wgsl"),
    include_str!("../../shaders/media_probe.wgsl")
);

/// `fullscreen.wgsl` + `march_blend.wgsl`: marched slices over the accumulation targets.
pub const MARCH_BLEND: &str = concat!(
    include_str!("../../shaders/fullscreen.wgsl"),
    include_str!("../../shaders/march_blend.wgsl")
);

/// The light volume pass: `volume_common.wgsl` + `volume_noise.wgsl` + `fullscreen.wgsl` +
/// `light_march.wgsl`.
pub const LIGHT_MARCH: &str = concat!(
    include_str!("../../shaders/volume_common.wgsl"),
    include_str!("../../shaders/volume_noise.wgsl"),
    include_str!("../../shaders/fullscreen.wgsl"),
    include_str!("../../shaders/light_march.wgsl")
);

/// The benchmark baseline: `volume_common.wgsl` + `plain_slices.wgsl`.
pub const PLAIN_SLICES: &str = concat!(
    include_str!("../../shaders/volume_common.wgsl"),
    include_str!("../../shaders/plain_slices.wgsl")
);

/// `fullscreen.wgsl` + `tone.wgsl` + `composite.wgsl`.
pub const COMPOSITE: &str = concat!(
    include_str!("../../shaders/fullscreen.wgsl"),
    include_str!("../../shaders/tone.wgsl"),
    include_str!("../../shaders/composite.wgsl")
);

/// `fullscreen.wgsl` + `field_eval.wgsl`: the field evaluated on the GPU (the bench's
/// baseline).
pub const FIELD_EVAL: &str = concat!(
    include_str!("../../shaders/fullscreen.wgsl"),
    include_str!("../../shaders/field_eval.wgsl")
);

/// The sky behind the cloud (physical, a gradient or flat, and the ground): `sun_shadow.wgsl` +
/// `fullscreen.wgsl` + `tone.wgsl` + `sky.wgsl`.
pub const SKY: &str = concat!(
    include_str!("../../shaders/sun_shadow.wgsl"),
    include_str!("../../shaders/fullscreen.wgsl"),
    include_str!("../../shaders/tone.wgsl"),
    include_str!("../../shaders/sky.wgsl")
);

/// A flat colour (the side panel's background): `fullscreen.wgsl` + `fill.wgsl`.
pub const FILL: &str = concat!(
    include_str!("../../shaders/fullscreen.wgsl"),
    include_str!("../../shaders/fill.wgsl")
);

/// The view behind the cloud laid again from its texture: `fullscreen.wgsl` + `backdrop.wgsl`.
pub const BACKDROP: &str = concat!(
    include_str!("../../shaders/fullscreen.wgsl"),
    include_str!("../../shaders/backdrop.wgsl")
);

/// Every shader module with the files it is composed of, in order.
pub const MODULES: [(&str, &[&str], &str); 11] = [
    (
        "volume",
        &[
            "volume_common.wgsl",
            "volume_noise.wgsl",
            "sun_shadow.wgsl",
            "volume.wgsl",
        ],
        VOLUME,
    ),
    (
        "volume_march",
        &[
            "volume_common.wgsl",
            "volume_noise.wgsl",
            "sun_shadow.wgsl",
            "volume.wgsl",
            "volume_march.wgsl",
        ],
        VOLUME_MARCH,
    ),
    (
        "media_probe",
        &[
            "volume_common.wgsl",
            "volume_noise.wgsl",
            "media_probe.wgsl",
        ],
        MEDIA_PROBE,
    ),
    (
        "march_blend",
        &["fullscreen.wgsl", "march_blend.wgsl"],
        MARCH_BLEND,
    ),
    (
        "light_march",
        &[
            "volume_common.wgsl",
            "volume_noise.wgsl",
            "fullscreen.wgsl",
            "light_march.wgsl",
        ],
        LIGHT_MARCH,
    ),
    (
        "plain_slices",
        &["volume_common.wgsl", "plain_slices.wgsl"],
        PLAIN_SLICES,
    ),
    (
        "composite",
        &["fullscreen.wgsl", "tone.wgsl", "composite.wgsl"],
        COMPOSITE,
    ),
    (
        "field_eval",
        &["fullscreen.wgsl", "field_eval.wgsl"],
        FIELD_EVAL,
    ),
    (
        "sky",
        &[
            "sun_shadow.wgsl",
            "fullscreen.wgsl",
            "tone.wgsl",
            "sky.wgsl",
        ],
        SKY,
    ),
    ("fill", &["fullscreen.wgsl", "fill.wgsl"], FILL),
    ("backdrop", &["fullscreen.wgsl", "backdrop.wgsl"], BACKDROP),
];
