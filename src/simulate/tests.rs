use super::reference::Reference;
use super::*;

fn random_automaton(dims: [usize; 3], seed: u64) -> Automaton {
    let mut a = Automaton::new(dims, seed);
    let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    let [nx, _, _] = dims;
    let tail = if nx % 64 == 0 {
        u64::MAX
    } else {
        (1 << (nx % 64)) - 1
    };
    let words = a.words();
    // Act is sparse (one cell in 16) and vapour dense (three in four), so that most cells
    // could activate and have no act neighbour, and each neighbour counts: with denser act
    // nearly every cell has one, and a neighbour read across a row's end would go unseen.
    for (bits, density) in [(&mut a.hum, 3), (&mut a.act, 0), (&mut a.cld, 1)] {
        for (i, w) in bits.iter_mut().enumerate() {
            let r = match density {
                0 => next() & next() & next() & next(),
                1 => next() & next(),
                _ => next() | next(),
            };
            *w = r & if (i + 1) % words == 0 { tail } else { u64::MAX };
        }
    }
    let levels: Vec<u8> = (0..dims.iter().product::<usize>() * 3)
        .map(|_| (next() % 8) as u8)
        .collect();
    for (k, kind) in [Kind::Hum, Kind::Act, Kind::Ext].into_iter().enumerate() {
        let l = &levels;
        a.set_levels(kind, |x, y, z| l[k + 3 * ((y * dims[2] + z) * dims[0] + x)]);
    }
    a
}

#[test]
fn the_bit_parallel_step_equals_the_plain_one_bit_for_bit() {
    // A word at a time (the page benchmark's baseline) and two words at a time (the step on
    // every target; here on plain pairs, as natively); rows of an odd number of words end with
    // a single word. The wind is
    // `a·y + b` cells a step: within a word both ways, and (the last grid) more than a word a
    // step both ways across a row of three words.
    for paired in [false, true] {
        for (dims, seed, [a, b], steps) in [
            ([70, 5, 6], 1, [1.7, -2.3], 12),
            ([130, 4, 3], 2, [1.7, -2.3], 12),
            ([64, 6, 5], 3, [1.7, -2.3], 12),
            ([9, 7, 8], 4, [1.7, -2.3], 12),
            ([9, 5, 7], 6, [1.7, -2.3], 12),
            ([128, 4, 24], 9, [1.7, -2.3], 12),
            ([256, 3, 12], 7, [1.7, -2.3], 12),
            ([320, 3, 8], 8, [1.7, -2.3], 12),
            ([150, 4, 3], 5, [-47.0, 70.5], 6),
        ] {
            let mut automaton = random_automaton(dims, seed);
            automaton.set_paired(paired);
            let wind = move |y: usize| a * y as f32 + b;
            automaton.set_wind(wind);
            let mut r = Reference::of(&automaton);
            for step in 0..steps {
                r.step(&automaton, &wind);
                automaton.advance();
                assert!(
                    r.same_as(&automaton),
                    "{dims:?}, paired {paired}: differs after step {}",
                    step + 1
                );
            }
            assert!(automaton.cloud_cells() > 0);
        }
    }
}

#[test]
fn rows_shift_across_words_and_lose_what_leaves() {
    let mut row = vec![1u64 << 63, 1, 0];
    shift_row(&mut row, 1);
    assert_eq!(row, vec![0, 1 << 1 | 1, 0]);
    shift_row(&mut row, 64);
    assert_eq!(row, vec![0, 0, 1 << 1 | 1]);
    shift_row(&mut row, -130);
    assert_eq!(row, vec![0, 0, 0]);
    // Every shift, whole words with and without a remainder, either way, against the cells
    // moved one by one.
    let start = [
        0x8000_0000_0000_0001u64,
        0xdead_beef_0123_4567,
        0x0f0f_f0f0_1234_8765,
    ];
    let cells = 3 * 64;
    for s in (-200i64..=200).chain([i64::MIN / 2, i64::MAX / 2, 1 << 40, -(1 << 40)]) {
        let mut row = start.to_vec();
        shift_row(&mut row, s);
        for x in 0..cells {
            let from = x as i64 - s;
            let want = (0..cells as i64).contains(&from)
                && start[from as usize / 64] >> (from as usize % 64) & 1 == 1;
            assert_eq!(
                row[x / 64] >> (x % 64) & 1 == 1,
                want,
                "shift {s}, cell {x}"
            );
        }
    }
}

#[test]
fn certain_extinction_clears_every_cloud_in_one_step() {
    let mut a = random_automaton([40, 5, 6], 9);
    a.set_levels(Kind::Ext, |_, _, _| (LEVELS.len() - 1) as u8);
    assert!(a.cloud_cells() > 0);
    a.advance();
    assert_eq!(a.cloud_cells(), 0);
}

#[test]
fn without_resupply_the_cloud_stops_growing_once_the_vapour_is_used() {
    let mut a = Automaton::new([48, 12, 12], 3);
    // Vapour in a block, one activated seed cell, no re-supply, no extinction.
    for y in 2..10 {
        for z in 2..10 {
            for x in 10..30 {
                let (w, b) = a.at(x, y, z);
                a.hum[w] |= 1 << b;
            }
        }
    }
    let (w, b) = a.at(15, 3, 5);
    a.act[w] |= 1 << b;
    let mut counts = Vec::new();
    for _ in 0..60 {
        a.advance();
        counts.push(a.cloud_cells());
    }
    assert!(
        counts.windows(2).all(|c| c[1] >= c[0]),
        "never shrinks: {counts:?}"
    );
    assert!(counts[5] > counts[0], "it grows: {counts:?}");
    let vapour: u64 = a.hum.iter().map(|w| w.count_ones() as u64).sum();
    assert_eq!(vapour, 0, "the vapour is used up");
    assert_eq!(counts[40], counts[59], "then the mass stays");
    assert!(
        counts[59] <= 8 * 8 * 20 + 1,
        "no more cloud than vapour was: {}",
        counts[59]
    );
}

fn parcel_settings() -> (Settings, Vec<Parcel>) {
    let settings = Settings {
        cells: [64, 16, 32],
        origin: [0.0, 0.0, 0.0],
        cell_size: 1.0,
        wind: [0.0, 0.0],
        ..Settings::default()
    };
    let parcel = Parcel {
        center: Vec3::new(20.0, 7.0, 16.0),
        radii: Vec3::new(9.0, 5.0, 9.0),
        rotation: Quat::IDENTITY,
    };
    (settings, vec![parcel])
}

#[test]
fn clouds_form_inside_parcels_and_not_far_outside() {
    let (settings, parcels) = parcel_settings();
    let mut sim = Simulation::new(&settings, &parcels);
    sim.advance(60);
    let a = sim.automaton();
    let [nx, ny, nz] = a.dims;
    let (mut inside, mut far) = (0, 0);
    for y in 0..ny {
        for z in 0..nz {
            for x in 0..nx {
                if a.get(&a.cld, x, y, z) {
                    let w = parcels[0].weight(settings.center(x, y, z));
                    let local = (settings.center(x, y, z) - parcels[0].center) / parcels[0].radii;
                    if w > 0.0 {
                        inside += 1;
                    } else if local.length() > 1.5 {
                        far += 1;
                    }
                }
            }
        }
    }
    assert!(inside > 200, "{inside} cloud cells inside the parcel");
    assert!(far * 50 < inside, "{far} far outside vs {inside} inside");
    // Moving the parcel moves the cloud.
    let moved = vec![Parcel {
        center: Vec3::new(44.0, 7.0, 16.0),
        ..parcels[0]
    }];
    let mut sim2 = Simulation::new(&settings, &moved);
    sim2.advance(60);
    let cx = |s: &Simulation| {
        let a = s.automaton();
        let [nx, ny, nz] = a.dims;
        let (mut sum, mut n) = (0.0, 0.0);
        for y in 0..ny {
            for z in 0..nz {
                for x in 0..nx {
                    if a.get(&a.cld, x, y, z) {
                        sum += x as f64;
                        n += 1.0;
                    }
                }
            }
        }
        sum / n
    };
    assert!(
        (cx(&sim2) - cx(&sim) - 24.0).abs() < 3.0,
        "{} → {}",
        cx(&sim),
        cx(&sim2)
    );
}

#[test]
fn wind_moves_the_cloud_mass_by_its_speed() {
    // A frozen cloud (no vapour, no activation, no extinction) blown at 1.5 cells per step.
    let mut a = Automaton::new([200, 4, 4], 5);
    for y in 0..4 {
        for z in 0..4 {
            for x in 20..40 {
                let (w, b) = a.at(x, y, z);
                a.cld[w] |= 1 << b;
            }
        }
    }
    a.set_wind(|_| 1.5);
    let centroid = |a: &Automaton| {
        let (mut s, mut n) = (0.0, 0.0);
        for y in 0..4 {
            for z in 0..4 {
                for x in 0..200 {
                    if a.get(&a.cld, x, y, z) {
                        s += x as f64;
                        n += 1.0;
                    }
                }
            }
        }
        s / n
    };
    let c0 = centroid(&a);
    for _ in 0..40 {
        a.advance();
    }
    assert!(
        (centroid(&a) - c0 - 60.0).abs() < 1e-9,
        "{} → {}",
        c0,
        centroid(&a)
    );
    assert_eq!(a.cloud_cells(), 20 * 16);
}

#[test]
fn the_same_seed_gives_the_same_run_and_another_seed_another() {
    let (settings, parcels) = parcel_settings();
    let run = |seed| {
        let mut sim = Simulation::new(
            &Settings {
                seed,
                ..settings.clone()
            },
            &parcels,
        );
        sim.advance(30);
        sim.automaton().cld.clone()
    };
    assert_eq!(run(7), run(7));
    assert_ne!(run(7), run(8));
}

#[test]
fn the_smoothed_density_is_the_share_of_cloud_around_each_cell() {
    let (settings, parcels) = parcel_settings();
    let mut sim = Simulation::new(&settings, &parcels);
    sim.advance(40);
    let v = sim.density(None, 1.0);
    assert_eq!(v.values.len(), 64 * 16 * 32);
    assert!(v.values.iter().all(|&q| (0.0..=1.0).contains(&q)));
    // Brute force at every cell, edges included (cells past them count as empty): the mean of
    // its (2r+1)³ neighbourhood, for the default half-width and a wider one.
    let brute = |sim: &Simulation, r: i32| -> Vec<f32> {
        let a = sim.automaton();
        let [nx, ny, nz] = a.dims.map(|d| d as i32);
        let mut out = Vec::new();
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let mut sum = 0u32;
                    for dz in -r..=r {
                        for dy in -r..=r {
                            for dx in -r..=r {
                                let (i, j, k) = (x + dx, y + dy, z + dz);
                                let inside = (0..nx).contains(&i)
                                    && (0..ny).contains(&j)
                                    && (0..nz).contains(&k);
                                sum += (inside && a.get(&a.cld, i as usize, j as usize, k as usize))
                                    as u32;
                            }
                        }
                    }
                    out.push(sum as f32 / ((2 * r + 1) as f32).powi(3));
                }
            }
        }
        out
    };
    // Exact up to half-width 2; half-widths 3 and 4 keep counts halved or quartered (to fit a
    // byte), within half a step of that.
    let same = |a: &[f32], b: &[f32]| {
        a.len() == b.len() && a.iter().zip(b).all(|(p, q)| (p - q).abs() < 1e-6)
    };
    let near = |a: &[f32], b: &[f32], r: u32| {
        let step = [1.0, 1.0, 1.0, 2.0, 4.0][r as usize] / ((2 * r + 1) as f32).powi(3);
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(p, q)| (p - q).abs() <= 0.5 * step + 1e-6)
    };
    assert!(v.values.iter().any(|&q| q > 0.5), "no cloud to smooth");
    assert!(same(&v.values, &brute(&sim, 1)));
    let wide = Simulation {
        settings: Settings {
            smoothing: 3,
            ..sim.settings.clone()
        },
        automaton: sim.automaton.clone(),
        sources: sim.sources.clone(),
        steered_at: sim.steered_at,
        posing_every: sim.posing_every,
    };
    assert!(near(&wide.smoothed().shares(), &brute(&wide, 3), 3));
    // A grid big enough to be smoothed on several threads (2^18 cells), its layers shared out.
    let big_settings = Settings {
        cells: [128, 32, 64],
        ..settings.clone()
    };
    let big_parcel = Parcel {
        center: Vec3::new(60.0, 12.0, 30.0),
        radii: Vec3::new(50.0, 10.0, 28.0),
        rotation: Quat::IDENTITY,
    };
    let mut big = Simulation::new(&big_settings, &[big_parcel]);
    big.advance(30);
    assert!(
        big.smoothed().shares().iter().any(|&q| q > 0.5),
        "no cloud in the big grid"
    );
    assert!(same(&big.smoothed().shares(), &brute(&big, 1)));
    // Each radius the settings allow on the small grid (one slab), and 0 and 2 on the big one
    // (several slabs, each warming its window).
    for r in 0..=4 {
        let at_r = |s: &Simulation| Simulation {
            settings: Settings {
                smoothing: r,
                ..s.settings.clone()
            },
            automaton: s.automaton.clone(),
            sources: s.sources.clone(),
            steered_at: s.steered_at,
            posing_every: s.posing_every,
        };
        assert!(
            near(&at_r(&sim).smoothed().shares(), &brute(&sim, r as i32), r),
            "radius {r}"
        );
        if r % 2 == 0 && r < 4 {
            assert!(
                near(&at_r(&big).smoothed().shares(), &brute(&big, r as i32), r),
                "radius {r}, big"
            );
        }
    }
    let (x, y, z) = (20, 7, 16);
    // Halfway between two steps: the mean of both.
    let before = sim.smoothed();
    sim.advance(1);
    let half = sim.density(Some(&before), 0.5);
    let (before, after) = (before.shares(), sim.smoothed().shares());
    let i = ((z * 16 + y) * 64 + x) as usize;
    assert!((half.values[i] - 0.5 * (before[i] + after[i])).abs() < 1e-6);
}

#[test]
fn a_player_scrubbed_back_and_forth_shows_what_a_fresh_run_shows() {
    let (settings, parcels) = parcel_settings();
    let fresh = |time: f32| {
        Player::new(&settings, Sources::fixed(parcels.clone()))
            .density(time)
            .0
            .values
    };
    let mut player = Player::new(&settings, Sources::fixed(parcels.clone()));
    let late = player.density(9.05).0.values; // 90 steps and a half
    let early = player.density(3.0).0.values; // back to step 30 (from a snapshot)
    assert_eq!(early, fresh(3.0));
    assert_eq!(player.density(9.05).0.values, late);
    assert_eq!(late, fresh(9.05));
    // Between two steps the density is their blend: neither step's own.
    let (a, b) = (fresh(3.0), fresh(3.1));
    let half = fresh(3.05);
    assert!(
        half.iter()
            .zip(a.iter().zip(&b))
            .all(|(h, (x, y))| (h - 0.5 * (x + y)).abs() < 1e-5)
    );
    assert_ne!(a, b);
    // Played frame by frame, each step's counts written over a dropped step's: every frame
    // as a fresh run shows it.
    let mut playing = Player::new(&settings, Sources::fixed(parcels.clone()));
    for frame in 0..40 {
        let time = frame as f32 * 0.05;
        let shown = playing.density(time).0.values;
        if frame % 13 == 12 {
            assert_eq!(shown, fresh(time), "frame {frame}");
        }
    }
    // A far jump catches up over calls, never more than a bounded number of steps at once.
    let mut far = Player::new(&settings, Sources::fixed(parcels));
    let (_, behind) = far.density(100.0);
    assert!(behind, "1,000 steps take more than one call");
}

#[test]
fn scrubbing_snapshots_stay_within_their_byte_cap_and_still_give_the_fresh_run() {
    let (settings, parcels) = parcel_settings();
    let fresh = |time: f32| {
        Player::new(&settings, Sources::fixed(parcels.clone()))
            .density(time)
            .0
            .values
    };
    let one = Simulation::new(&settings, &parcels).state().bytes();
    let cap = 5 * one;
    let mut player =
        Player::new(&settings, Sources::fixed(parcels.clone())).with_snapshot_bytes(cap);
    // 40 s at 10 steps a second: 400 steps, a snapshot every 32 (12 of them uncapped).
    let mut t = 0.0;
    while t < 40.0 {
        t += 10.0;
        while player.density(t).1 {}
    }
    assert!(
        player.snapshot_bytes() <= cap,
        "{} bytes of snapshots, cap {cap}",
        player.snapshot_bytes()
    );
    assert!(player.snapshot_bytes() >= 2 * one);
    // Scrubbing back still lands on what a fresh run shows.
    assert_eq!(player.density(13.0).0.values, fresh(13.0));
    // An uncapped player keeps more.
    let mut uncapped = Player::new(&settings, Sources::fixed(parcels.clone()));
    while uncapped.density(40.0).1 {}
    assert!(uncapped.snapshot_bytes() > cap);
}

#[test]
fn a_step_shared_among_threads_is_the_one_thread_step_to_the_bit() {
    // Big enough to be shared out (at least 2^14 words), with parcels, wind and every rule.
    let settings = Settings {
        cells: [128, 32, 256],
        origin: [0.0, 0.0, 0.0],
        cell_size: 1.0,
        wind: [0.0, 1.5],
        ..Settings::default()
    };
    let parcels = vec![Parcel {
        center: Vec3::new(60.0, 12.0, 120.0),
        radii: Vec3::new(50.0, 10.0, 90.0),
        rotation: Quat::IDENTITY,
    }];
    let mut one = Simulation::new(&settings, &parcels);
    one.automaton.set_threads(Some(1));
    let mut many = Simulation::new(&settings, &parcels);
    many.automaton.set_threads(Some(4));
    one.advance(25);
    many.advance(25);
    assert!(one.automaton().cloud_cells() > 1000, "no clouds formed");
    assert_eq!(one.automaton().cld, many.automaton().cld);
    assert_eq!(one.automaton().hum, many.automaton().hum);
    assert_eq!(one.automaton().act, many.automaton().act);
}

#[test]
fn smoothed_counts_equal_a_brute_force_count_on_ragged_grids() {
    // Each cell's cloud cells within r along each axis, cells past the edges empty, brought
    // into a byte as the smoothing keeps them (halved for r = 3, quartered for r = 4, rounded).
    let brute = |a: &Automaton, r: i64| -> Vec<u8> {
        let [nx, ny, nz] = a.dims.map(|d| d as i64);
        let down = [0, 0, 0, 1, 2][r as usize];
        let mut out = Vec::new();
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let mut n = 0u32;
                    for k in (z - r).max(0)..=(z + r).min(nz - 1) {
                        for j in (y - r).max(0)..=(y + r).min(ny - 1) {
                            for i in (x - r).max(0)..=(x + r).min(nx - 1) {
                                n += a.get(&a.cld, i as usize, j as usize, k as usize) as u32;
                            }
                        }
                    }
                    out.push(((n + ((1 << down) >> 1)) >> down) as u8);
                }
            }
        }
        out
    };
    // Rows of one to three words with a partial last one, and rows of exactly one word.
    for (dims, seed) in [
        ([70, 5, 6], 1),
        ([130, 9, 11], 2),
        ([64, 3, 4], 3),
        ([5, 4, 4], 4),
    ] {
        let a = random_automaton(dims, seed);
        assert!(a.cloud_cells() > 0);
        // Each radius written over the last one's counts (as the player reuses a step's
        // memory), the first over a bigger buffer of stale values.
        let mut old = vec![0xA5; 200_000];
        for r in 0..=4 {
            let s = smoothing::smooth(&a, r, old);
            assert_eq!(s.counts, brute(&a, r as i64), "{dims:?}, radius {r}");
            let divisor = [1.0, 1.0, 1.0, 2.0, 4.0][r];
            assert_eq!(s.scale, divisor / ((2 * r + 1) as f32).powi(3));
            old = s.counts;
        }
    }
    // Big enough to be shared out among threads (2^18 cells and more), slabs of uneven depth.
    let a = random_automaton([130, 40, 61], 5);
    for r in [1, 2] {
        assert_eq!(
            smoothing::smooth(&a, r, Vec::new()).counts,
            brute(&a, r as i64),
            "big, radius {r}"
        );
    }
}

#[test]
fn moving_parcels_steer_the_run_and_a_scrubbed_frame_equals_it_played_from_step_0() {
    use crate::scene::{Preset, Scene};
    // The simulated preset's parcels, carried by its wind, one swelling and one drying out,
    // over a coarser grid of the same extent.
    let scene = Scene::preset(Preset::Simulated);
    let settings = Settings {
        cells: [64, 16, 64],
        cell_size: 0.5,
        origin: [-16.0, -1.0, -16.0],
        ..Settings::default()
    };
    let sources = Sources::of(&scene);
    assert!(sources.moves());
    assert_ne!(sources.at(10.0), sources.at(0.0), "they move");
    // Its time does not change the sources (a new time is no new run).
    assert_eq!(Sources::of(&scene.posed_at(30.0)), sources);
    // Played one step at a time from step 0 to 101.
    let mut played = Simulation::steered(&settings, sources.clone());
    for _ in 0..101 {
        played.advance(1);
    }
    // A player taken to step 200, then scrubbed back to step 100 (it blends 100 and 101).
    let mut player = Player::new(&settings, sources.clone());
    let time = |n: u64| n as f32 / settings.rate;
    while player.density(time(200)).1 {}
    let taken = player.steps_taken();
    assert!(!player.density(time(100)).1);
    assert_eq!(player.run.step(), 101);
    assert_eq!(
        player.run.smoothed(),
        played.smoothed(),
        "scrubbed = played"
    );
    assert!(
        player.steps_taken() - taken <= SNAPSHOT_EVERY + 1,
        "the scrub back took {} steps",
        player.steps_taken() - taken
    );
    // The baseline: parcels held where they start give another cloud.
    let mut still = Simulation::new(&settings, &sources.at(0.0));
    still.advance(101);
    assert_ne!(
        still.smoothed(),
        played.smoothed(),
        "the moving parcels steered it"
    );
}

#[test]
fn fast_parcels_are_posed_every_step_and_slow_ones_every_interval() {
    use crate::scene::{Preset, Scene};
    let settings = Settings {
        cells: [64, 16, 64],
        cell_size: 0.5,
        origin: [-16.0, -1.0, -16.0],
        ..Settings::default()
    };
    // The preset's own breeze and turbulence move its parcels about 1.2 cells of its own
    // grid in 8 steps: posed every 4; on this grid of cells twice as large, 0.6 cells in 8
    // steps: every 8.
    let slow = Scene::preset(Preset::Simulated);
    let every =
        |grid: &Settings, sources: Sources| Simulation::steered(grid, sources).posing_every();
    assert_eq!(every(&Settings::default(), Sources::of(&slow)), 4);
    assert_eq!(every(&settings, Sources::of(&slow)), SOURCE_EVERY);
    let gale = |speed: f32| {
        let mut fast = slow.clone();
        fast.wind_field.velocity = [speed, 0.0];
        fast.wind_field.turbulence = 0.0;
        Sources::of(&fast)
    };
    // 2 units a second is 0.4 cells a step at 10 steps a second: posed every 2 steps, so a
    // parcel moves 0.8 cells between posings, not 3.2.
    assert_eq!(every(&settings, gale(2.0)), 2);
    // 12 units a second (2.4 cells a step): posed every step.
    let sources = gale(12.0);
    let mut run = Simulation::steered(&settings, sources.clone());
    assert_eq!(run.posing_every(), 1);
    // The brute-force reference: the parcels posed where they stand before every step.
    let mut reference = Simulation::steered(&settings, Sources::fixed(sources.at(0.0)));
    for step in 0..48u64 {
        steer(
            &mut reference.automaton,
            &settings,
            &sources.at(step as f32 / settings.rate),
        );
        reference.automaton.advance();
    }
    run.advance(48);
    assert_eq!(run.smoothed(), reference.smoothed(), "posed at every step");
    // The baseline: posed every 8 steps, the gale's parcels jump 19 cells at a time, and the
    // cloud differs.
    let mut coarse = Simulation::steered(&settings, sources);
    coarse.posing_every = SOURCE_EVERY;
    coarse.advance(48);
    assert_ne!(coarse.smoothed(), reference.smoothed());
}

#[test]
fn a_checkpoint_resumes_the_run_in_a_fresh_player_and_refuses_another_runs() {
    let (settings, parcels) = parcel_settings();
    let mut played = Player::new(&settings, Sources::fixed(parcels.clone()));
    while played.density(13.0).1 {} // 130 steps: snapshots to step 128
    let (step, bytes) = played.checkpoint();
    assert_eq!(step, 128);
    let mut fresh = Player::new(&settings, Sources::fixed(parcels.clone()));
    assert!(
        fresh.resume(&bytes, 100).is_err(),
        "a checkpoint past the step asked for"
    );
    assert_eq!(fresh.resume(&bytes, 130), Ok(128));
    let mut shown = fresh.density(13.0);
    while shown.1 {
        shown = fresh.density(13.0);
    }
    assert_eq!(shown.0.values, played.density(13.0).0.values);
    assert!(
        fresh.steps_taken() <= 3,
        "took {} steps",
        fresh.steps_taken()
    );
    // Another run (a parcel moved), a damaged file: refused, nothing taken.
    let mut moved = parcels.clone();
    moved[0].center.x += 1.0;
    let mut other = Player::new(&settings, Sources::fixed(moved));
    let err = other.resume(&bytes, 130).unwrap_err();
    assert!(err.contains("another scene"), "{err}");
    let err = fresh.resume(&bytes[..bytes.len() - 1], 130).unwrap_err();
    assert!(err.contains("bytes"), "{err}");
    assert!(fresh.resume(b"not a checkpoint", 130).is_err());
}

#[test]
fn levels_set_in_spans_are_the_levels_set_cell_by_cell() {
    // A row of 70 cells (a whole word and a part of one); inside each row's span the levels
    // vary, outside it they are one level: both ways of setting them run the same steps.
    let dims = [70, 5, 6];
    let span = |y: usize, z: usize| (!(y + z).is_multiple_of(3)).then_some((3 * z + y, 40 + 5 * z));
    let inside = |x: usize, y: usize, z: usize| ((x * 7 + y * 3 + z) % LEVELS.len()) as u8;
    let level = |x: usize, y: usize, z: usize| match span(y, z) {
        Some((from, to)) if (from..to).contains(&x) => inside(x, y, z),
        _ => 5,
    };
    let mut cell_by_cell = Automaton::new(dims, 9);
    let mut spans = Automaton::new(dims, 9);
    for kind in [Kind::Hum, Kind::Act, Kind::Ext] {
        cell_by_cell.set_levels(kind, level);
        spans.set_levels_in_spans(kind, 5, span, inside);
    }
    for _ in 0..12 {
        cell_by_cell.advance();
        spans.advance();
    }
    assert_eq!(cell_by_cell.state(), spans.state());
    assert!(
        cell_by_cell.state() != Automaton::new(dims, 9).state(),
        "the steps changed nothing"
    );
}
