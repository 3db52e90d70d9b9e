use super::*;
use crate::scene::Preset;
use crate::share::fixture;

fn payload_of(token: &str) -> Vec<u8> {
    let bytes = base64::engine::general_purpose::URL_SAFE_NO_PAD
        .decode(token)
        .unwrap();
    miniz_oxide::inflate::decompress_to_vec(&bytes[1..]).unwrap()
}

fn token_from_payload(payload: &[u8]) -> String {
    let mut bytes = vec![LINK_VERSION];
    bytes.extend(miniz_oxide::deflate::compress_to_vec(payload, 6));
    base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(bytes)
}

/// The settings of a scene as the link keeps them (numbers rounded), points apart.
fn settings(scene: &Scene) -> Value {
    let mut s = scene.clone();
    for p in &mut s.planes {
        let p = Arc::make_mut(p);
        p.points.clear();
        p.pressure.clear();
    }
    if let Some(r) = &mut s.reference {
        Arc::make_mut(r).data = Default::default();
    }
    to_rounded_value(&s)
}

#[test]
fn five_hand_drawn_strokes_fit_in_1500_characters_and_come_back_exactly() {
    let scene = fixture::hand_drawn();
    assert_eq!(scene.planes.len(), 5);
    assert!(scene.planes.iter().all(|p| p.points.len() == 200));
    let url = link_url(DEFAULT_BASE, &scene).unwrap();
    assert!(
        url.len() <= 1500,
        "the five-stroke link is {} characters",
        url.len()
    );
    let (back, repairs) = decode_link(&url).unwrap();
    assert!(repairs.is_empty(), "{repairs:?}");
    assert_eq!(settings(&back), settings(&scene));
    for (a, b) in scene.planes.iter().zip(&back.planes) {
        assert_eq!(
            a.points, b.points,
            "strokes made in the app are on their grid"
        );
    }
    assert_eq!(encode_link(&back).unwrap(), encode_link(&scene).unwrap());
}

#[test]
fn a_stroke_off_its_grid_moves_by_at_most_half_a_step() {
    let mut scene = fixture::hand_drawn();
    for plane in &mut scene.planes {
        let plane = Arc::make_mut(plane);
        for (i, p) in plane.points.iter_mut().enumerate() {
            *p = *p * 1.000_37 + glam::Vec2::splat(1e-4 * (i % 7) as f32);
        }
    }
    let (back, _) = decode_link(&format!("#s={}", encode_link(&scene).unwrap())).unwrap();
    for (a, b) in scene.planes.iter().zip(&back.planes) {
        let (lo, hi) = a.points.iter().fold(
            (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let step = crate::scene::grid_step(grid_exponent(&a.points));
        assert!(step <= (hi - lo).max_element() as f64 / crate::scene::STROKE_GRID * 1.0906);
        let worst = a
            .points
            .iter()
            .zip(&b.points)
            .map(|(p, q)| (*p - *q).abs().max_element())
            .fold(0.0f32, f32::max);
        assert!(worst as f64 <= step * 0.5001, "{worst} > half of {step}");
        assert!(worst > 0.0, "these points were off the grid");
    }
}

#[test]
fn every_preset_round_trips_with_its_settings() {
    for (preset, name) in Preset::ALL {
        let scene = Scene::preset(preset);
        let (back, repairs) = decode_link(&link_url(DEFAULT_BASE, &scene).unwrap()).unwrap();
        assert!(repairs.is_empty(), "{name}: {repairs:?}");
        assert_eq!(settings(&back), settings(&scene), "{name}");
    }
}

#[test]
fn a_clock_travels_in_a_link_only_when_it_is_not_the_default() {
    let mut scene = Scene::preset(Preset::Cumulus);
    assert!(!settings(&scene).as_object().unwrap().contains_key("clock"));
    scene.clock = crate::scene::Clock {
        fps: 30.0,
        start: 12,
        end: 90,
    };
    assert!(settings(&scene).as_object().unwrap().contains_key("clock"));
    let (back, repairs) = decode_link(&link_url(DEFAULT_BASE, &scene).unwrap()).unwrap();
    assert!(repairs.is_empty(), "{repairs:?}");
    assert_eq!(back.clock, scene.clock);
}

#[test]
fn pressure_cuts_and_a_reference_without_its_bytes_come_back() {
    let mut scene = fixture::hand_drawn();
    {
        let p = Arc::make_mut(&mut scene.planes[1]);
        p.kind = crate::scene::StrokeKind::Cut;
        p.closed = false;
        p.pressure = (0..p.points.len())
            .map(|i| (i % 50) as f32 / 49.0)
            .collect();
        p.sketch.inflate = 0.7;
        p.hidden = true;
    }
    scene.reference = Some(Arc::new(crate::scene::ReferenceImage {
        name: "photo.jpg".into(),
        data: Arc::new(vec![1, 2, 3]),
        size: [640, 480],
        height: 7.5,
        in_front: true,
        ..Default::default()
    }));
    scene.render.noise_octaves = 7;
    scene.light.sun_color = [0.9, 0.5, 0.25];
    scene.camera.yaw_deg = 33.3;
    let (back, _) = decode_link(&format!("#s={}", encode_link(&scene).unwrap())).unwrap();
    assert_eq!(settings(&back), settings(&scene));
    let r = back.reference.as_deref().unwrap();
    assert!(r.data.is_empty(), "a link never carries the picture");
    assert_eq!(r.name, "photo.jpg");
    let (p, q) = (&scene.planes[1].pressure, &back.planes[1].pressure);
    assert_eq!(p.len(), q.len());
    assert!(
        p.iter()
            .zip(q)
            .all(|(a, b)| (a - b).abs() <= 0.5 / 255.0 + 1e-6)
    );
    assert!(back.planes[0].pressure.is_empty());
}

#[test]
fn a_link_is_found_in_a_url_a_fragment_or_alone() {
    let token = encode_link(&Scene::preset(Preset::Stratus)).unwrap();
    for text in [
        format!("https://example.org/app/?x=1#s={token}"),
        format!("#s={token}"),
        format!("s={token}"),
        format!("  {DEFAULT_BASE}#s={token}&other=1 "),
    ] {
        assert!(decode_link(&text).is_ok(), "{text}");
    }
    assert!(matches!(
        decode_link("https://example.org/"),
        Err(LinkError::NotALink)
    ));
}

#[test]
fn broken_links_give_a_clear_error_and_never_panic() {
    let token = encode_link(&fixture::hand_drawn()).unwrap();
    // Every truncation.
    for n in 0..token.len() {
        assert!(
            decode_link(&format!("#s={}", &token[..n])).is_err(),
            "cut at {n}"
        );
    }
    // Changed characters.
    let mut rng = crate::seeded::SplitMix::new(5);
    for _ in 0..300 {
        let mut bytes = token.clone().into_bytes();
        let at = (rng.next_u64() as usize) % bytes.len();
        bytes[at] = b"ABCxyz019-_"[(rng.next_u64() % 11) as usize];
        let _ = decode_link(&format!("#s={}", String::from_utf8(bytes).unwrap()));
    }
    let err = decode_link("#s=%%%").unwrap_err().to_string();
    assert!(err.contains("damaged"), "{err}");
    // A newer format is named as such.
    let newer = base64::engine::general_purpose::URL_SAFE_NO_PAD.encode([LINK_VERSION + 1, 0]);
    assert!(matches!(
        decode_link(&format!("#s={newer}")),
        Err(LinkError::Newer { .. })
    ));
    assert!(matches!(
        decode_link(&format!("#s={}", "A".repeat(MAX_LINK_CHARS + 1))),
        Err(LinkError::TooLong { .. })
    ));
}

#[test]
fn hostile_payloads_are_refused_before_they_cost_anything() {
    // A decompression bomb: 64 MiB of zeros in a few kilobytes.
    let bomb = token_from_payload(&vec![0u8; 32 << 20]);
    assert!(bomb.len() < MAX_LINK_CHARS);
    let err = decode_link(&format!("#s={bomb}")).unwrap_err().to_string();
    assert!(err.contains("inflates to more than"), "{err}");

    let with_json = |json: &str, strokes: &[u8]| {
        let mut w = Writer::default();
        w.uvar(json.len() as u64);
        w.0.extend_from_slice(json.as_bytes());
        w.0.extend_from_slice(strokes);
        decode_payload(&w.0)
    };
    // Absurd counts.
    let many = format!("{{\"planes\":[{}{{}}]}}", "{},".repeat(MAX_PLANES));
    let err = with_json(&many, &[]).unwrap_err().to_string();
    assert!(err.contains("at most 256"), "{err}");
    let mut huge = Writer::default();
    huge.uvar(1 << 40);
    let err = with_json("{\"planes\":[{}]}", &huge.0)
        .unwrap_err()
        .to_string();
    assert!(err.contains("damaged"), "{err}");
    // A JSON length beyond the payload.
    let mut w = Writer::default();
    w.uvar(u64::MAX);
    assert!(decode_payload(&w.0).is_err());
    // Out-of-range and infinite settings are repaired and said so; non-finite geometry is
    // refused.
    let (scene, repairs) = with_json(
        "{\"light\":{\"ambient\":1e39},\"render\":{\"slices\":100000}}",
        &[],
    )
    .unwrap();
    assert!(scene.light.ambient.is_finite());
    assert!(!repairs.is_empty());
    let err = with_json("{\"ellipsoids\":[{\"radii\":[1e39,1,1]}]}", &[])
        .unwrap_err()
        .to_string();
    assert!(err.contains("non-finite"), "{err}");
    // Trailing bytes and wrong shapes.
    assert!(with_json("{}", &[0]).is_err());
    assert!(with_json("[]", &[]).is_err());
    assert!(with_json("{\"planes\":3}", &[]).is_err());
    // A stroke that walks off its grid.
    let mut off = Writer::default();
    off.uvar(3);
    off.ivar(0);
    for v in [MAX_STEPS, 0, MAX_STEPS, 0, MAX_STEPS, 0] {
        off.ivar(v);
    }
    off.uvar(0);
    let err = with_json("{\"planes\":[{}]}", &off.0)
        .unwrap_err()
        .to_string();
    assert!(err.contains("off its grid"), "{err}");
}

#[test]
fn a_scene_too_large_for_a_link_says_so() {
    let mut scene = Scene::preset(Preset::Empty);
    let mut rng = crate::seeded::SplitMix::new(9);
    for _ in 0..20 {
        scene.planes.push(Arc::new(DrawingPlane {
            points: (0..5000)
                .map(|_| glam::Vec2::new(rng.next_f64() as f32, rng.next_f64() as f32) * 10.0)
                .collect(),
            ..Default::default()
        }));
    }
    let err = encode_link(&scene).unwrap_err();
    assert!(matches!(err, LinkError::SceneTooLarge { .. }));
    assert!(err.to_string().contains("save it as a file"));
}

#[test]
fn the_payload_holds_only_what_differs_from_the_base() {
    let payload = payload_of(&encode_link(&Scene::preset(Preset::Empty)).unwrap());
    let json = std::str::from_utf8(&payload[1..]).unwrap();
    assert_eq!(json, "{\"ellipsoids\":[],\"planes\":[]}");
}

#[test]
fn a_scene_a_link_cannot_carry_is_refused_not_written_damaged() {
    // Stroke points of 1e38: their grid does not fit the link's integers, so the token would
    // decode as damaged. The encoder refuses the scene instead.
    let mut scene = fixture::hand_drawn();
    {
        let plane = Arc::make_mut(&mut scene.planes[0]);
        for p in &mut plane.points {
            *p *= 1e37;
        }
    }
    match encode_link(&scene) {
        Err(LinkError::Unfit(why)) => assert!(!why.is_empty()),
        Ok(token) => {
            // Or, if it was written, it opens.
            decode_link(&format!("#s={token}")).expect("what link writes, --decode opens");
        }
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn each_link_version_keeps_its_own_base() {
    // The current version's base is written from today's defaults when a version is added.
    if std::env::var_os("CLOUDSKETCH_WRITE_LINK_BASE").is_some() {
        let path = format!(
            "{}/src/share/link/base_v{LINK_VERSION}.json",
            env!("CARGO_MANIFEST_DIR")
        );
        let text = serde_json::to_string_pretty(&todays_bases()).unwrap();
        std::fs::write(path, text + "\n").unwrap();
    }
    for version in 1..=LINK_VERSION {
        let bases = bases(version);
        for (name, base) in [
            ("scene", &bases.scene),
            ("plane", &bases.plane),
            ("ellipsoid", &bases.ellipsoid),
        ] {
            assert!(
                base.as_object().is_some_and(|o| !o.is_empty()),
                "base_v{version}.json has no {name}"
            );
        }
        // The stored base is data: decoding does not look at today's defaults. A base that
        // no longer deserialises (a member renamed without a version bump) fails here.
        let scene: Scene = serde_json::from_value(bases.scene.clone()).unwrap();
        assert!(scene.planes.is_empty() && scene.ellipsoids.is_empty());
    }
    // The bases differ where the defaults moved between versions: the ground's height.
    assert_eq!(bases(1).scene["light"]["ground_height"], 0.0);
    assert_eq!(bases(2).scene["light"]["ground_height"], -5.0);
    // Today's defaults are the current version's base (as links round them), or a version is
    // due.
    // A link carries no version (the decoder writes today's), so a new document version alone
    // is no new link format.
    let without_version = |v: &Value| {
        let mut v = rounded(v);
        if let Value::Object(o) = &mut v {
            o.remove("version");
        }
        v
    };
    assert_eq!(
        without_version(&todays_bases()["scene"]),
        without_version(&bases(LINK_VERSION).scene),
        "the defaults moved: add link format {} with its base (see docs/scene-format.md)",
        LINK_VERSION + 1
    );
}

/// The paths of `value`'s leaves (arrays are leaves: vectors, colours) equal to `base`'s.
fn leaves_equal_to(path: &str, value: &Value, base: &Value, out: &mut Vec<String>) {
    match (value, base) {
        (Value::Object(v), Value::Object(b)) => {
            for (key, item) in v {
                if let Some(b) = b.get(key) {
                    leaves_equal_to(&format!("{path}/{key}"), item, b, out);
                }
            }
        }
        (v, b) if v == b => out.push(path.to_owned()),
        _ => {}
    }
}

#[test]
fn the_fixture_sets_every_field_the_link_carries_apart_from_its_base() {
    // Every serialised field of the every-part scene differs from version 1's base, so each
    // one travels in the fixture's link: a field that changed its meaning, or a new one set
    // to something, changes the fixture's payload and asks for a version bump.
    let scene = fixture::every_part();
    let value = to_rounded_value(&scene);
    let bases = bases(LINK_VERSION);
    let mut same = Vec::new();
    let mut top = value.clone();
    if let Value::Object(o) = &mut top {
        for key in ["version", "planes", "ellipsoids"] {
            o.remove(key);
        }
    }
    leaves_equal_to("", &top, &rounded(&bases.scene), &mut same);
    // A list's field counts as set when any one item sets it apart from the base.
    for (list, base) in [("planes", &bases.plane), ("ellipsoids", &bases.ellipsoid)] {
        let items = value[list].as_array().unwrap();
        assert!(!items.is_empty(), "the fixture has no {list}");
        let mut in_every: Option<Vec<String>> = None;
        for item in items {
            let mut equal = Vec::new();
            leaves_equal_to(&format!("/{list}/*"), item, &rounded(base), &mut equal);
            in_every = Some(match in_every {
                None => equal,
                Some(before) => before.into_iter().filter(|p| equal.contains(p)).collect(),
            });
        }
        same.extend(in_every.unwrap_or_default());
    }
    assert!(
        same.is_empty(),
        "fields of the fixture equal to the base: {same:#?}"
    );
}

#[test]
fn a_crafted_link_with_the_reference_pictures_bytes_opens_without_them() {
    // The encoder never writes them; a link made by hand that does loses them on decoding.
    let settings = serde_json::json!({
        "reference": {"name": "photo.png", "data": "AQID", "size": [2, 2]},
        "planes": [],
        "ellipsoids": [],
    });
    let json = serde_json::to_vec(&settings).unwrap();
    let mut payload = Vec::new();
    let mut w = Writer::default();
    w.uvar(json.len() as u64);
    payload.extend(w.0);
    payload.extend(json);
    let (scene, _) = decode_link(&format!("#s={}", token_from_payload(&payload))).unwrap();
    let r = scene
        .reference
        .as_deref()
        .expect("the reference's placement");
    assert_eq!(r.name, "photo.png");
    assert!(
        r.data.is_empty(),
        "the picture's bytes came through the link"
    );
}

#[test]
fn keys_travel_unrounded_so_a_key_stays_on_its_frame() {
    let scene = fixture::every_part();
    let token = encode_link(&scene).unwrap();
    let (opened, repairs) = decode_link(&format!("#s={token}")).unwrap();
    assert!(repairs.is_empty(), "{repairs:?}");
    assert_eq!(opened.animation, scene.animation);
    let seventh = scene.clock.seconds(7);
    assert!(
        opened.animation.times(None).contains(&seventh),
        "frame 7's key at {seventh} s"
    );
}
