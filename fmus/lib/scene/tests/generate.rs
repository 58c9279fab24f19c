//! Determinism, naming, and the layout's promises (free aisles, headland, start pose).

use agrisim_scene::generate::{compound_leaf, LeafPart};
use agrisim_scene::occupancy::OccupancyMap;
use agrisim_scene::{generate, GreenhouseConfig, Kind, Object, Placement, Shape};

fn cfg(s: &str) -> GreenhouseConfig {
    GreenhouseConfig::from_toml_str(s).unwrap()
}

/// The robot's navigation height band [m].
const NAV_BAND: (f64, f64) = (0.02, 2.0);

#[test]
fn same_config_and_seed_give_identical_scene() {
    let c = cfg("random_obstacles = 4");
    let a = generate(&c, 5);
    let b = generate(&c, 5);
    assert_eq!(a, b);
}

#[test]
fn different_seed_changes_random_parts_only() {
    let c = cfg("random_obstacles = 4");
    let a = generate(&c, 5);
    let b = generate(&c, 6);
    assert_eq!(a.objects.len(), b.objects.len());
    assert_eq!(a.layout, b.layout);
    let fruit_moved = a
        .objects
        .iter()
        .zip(&b.objects)
        .filter(|(x, y)| matches!(x.kind, Kind::Fruit { .. }) && x.placement != y.placement)
        .count();
    assert!(fruit_moved > 1000, "only {fruit_moved} fruit moved");
    let ripeness_changed = a
        .objects
        .iter()
        .zip(&b.objects)
        .filter(|(x, y)| matches!(x.kind, Kind::Fruit { .. }) && x.kind != y.kind)
        .count();
    assert!(ripeness_changed > 500);
    let obst = |g: &agrisim_scene::Greenhouse| -> Vec<[f64; 3]> {
        g.objects.iter().filter(|o| o.kind == Kind::Obstacle).map(|o| o.placement.translation).collect()
    };
    assert_ne!(obst(&a), obst(&b));
    // Structure does not depend on the seed.
    for (x, y) in a.objects.iter().zip(&b.objects) {
        if matches!(x.kind, Kind::Post | Kind::Gutter | Kind::HeatingPipe | Kind::Wall | Kind::Floor | Kind::Roof) {
            assert_eq!(x, y);
        }
    }
}

#[test]
fn ids_dense_names_unique_and_conventional() {
    let g = generate(&cfg("random_obstacles = 3\nblock_aisles = [2]"), 1);
    for (i, o) in g.objects.iter().enumerate() {
        assert_eq!(o.id as usize, i);
    }
    let mut names: Vec<&str> = g.objects.iter().map(|o| o.name.as_str()).collect();
    names.sort();
    let n = names.len();
    names.dedup();
    assert_eq!(names.len(), n, "duplicate names");
    let fruit = g.objects.iter().find(|o| o.name == "row2/plant7/fruit1_3").expect("fruit name");
    assert!(matches!(fruit.kind, Kind::Fruit { ripeness: 1..=6 }));
    assert!(g.objects.iter().any(|o| o.name == "block2"));
}

#[test]
fn default_scene_counts_and_fruit_heights() {
    let c = GreenhouseConfig::default();
    let g = generate(&c, c.seed);
    let plants = 6 * 60;
    let count = |k: fn(&Kind) -> bool| g.objects.iter().filter(|o| k(&o.kind)).count();
    assert_eq!(count(|k| *k == Kind::Stem), plants);
    assert_eq!(count(|k| matches!(k, Kind::Fruit { .. })), plants * 4 * 5);
    // Compound leaves: per leaf a rachis (named leaf{k}) and 7 or 9 leaflets (leaf{k}_{j}).
    let rachises = g.objects.iter().filter(|o| o.kind == Kind::Leaf && !o.name.contains('_')).count();
    assert_eq!(rachises, plants * 6);
    let leaflets = count(|k| *k == Kind::Leaf) - rachises;
    assert_eq!(leaflets, plants * 6 / 2 * (7 + 9));
    // A pedicel per fruit, from the top of its collider up to its truss.
    let pedicels: Vec<&Object> = g.objects.iter().filter(|o| o.name.contains("/pedicel")).collect();
    assert_eq!(pedicels.len(), plants * 4 * 5);
    assert_eq!(count(|k| *k == Kind::Truss), plants * 4 * 6);
    let mut stages = [0usize; 6];
    for o in &g.objects {
        if let Kind::Fruit { ripeness } = o.kind {
            stages[ripeness as usize - 1] += 1;
            let z = o.placement.translation[2];
            assert!((0.5..=1.8).contains(&z), "{} at z = {z}", o.name);
        }
    }
    // Sampled stage frequencies follow the configured weights.
    let total: usize = stages.iter().sum();
    for (s, w) in stages.iter().zip(c.ripeness) {
        let f = *s as f64 / total as f64;
        assert!((f - w / c.ripeness.iter().sum::<f64>()).abs() < 0.03, "{stages:?}");
    }
}

/// Every object except obstacles stays out of every aisle and the headland in the nav band,
/// and the start footprint (1.2 x 0.9 m) is free.
fn check_layout(c: &GreenhouseConfig, seed: u64) {
    let g = generate(c, seed);
    let l = &g.layout;
    assert_eq!(l.rows.len(), c.rows);
    assert_eq!(l.rows.iter().filter(|r| r.active).count(), c.active_rows);
    assert_eq!(l.aisles.len(), c.active_rows.saturating_sub(1));
    let overlaps_open = |o: &Object, r: [f64; 4]| {
        let (mn, mx) = o.aabb();
        let e = 1e-9;
        mx[2] > NAV_BAND.0
            && mn[2] < NAV_BAND.1
            && mn[0] < r[2] - e
            && mx[0] > r[0] + e
            && mn[1] < r[3] - e
            && mx[1] > r[1] + e
    };
    for a in &l.aisles {
        let r = [a.x_start, a.y - 0.5 * a.width, a.x_end, a.y + 0.5 * a.width];
        assert!(a.width >= 2.0 - 1e-12);
        for o in g.objects.iter().filter(|o| o.kind != Kind::Obstacle) {
            assert!(!overlaps_open(o, r), "{} intrudes aisle {}", o.name, a.index);
        }
    }
    for o in g.objects.iter().filter(|o| o.kind != Kind::Obstacle) {
        assert!(!overlaps_open(o, l.headland), "{} intrudes the headland", o.name);
    }
    // Start pose: inside the headland, facing +x, footprint free.
    let [x, y, yaw] = l.start_pose;
    assert_eq!(yaw, 0.0);
    let foot = [x - 0.6, y - 0.45, x + 0.6, y + 0.45];
    assert!(
        foot[0] >= l.headland[0] && foot[2] <= l.headland[2] && foot[1] >= l.headland[1] && foot[3] <= l.headland[3]
    );
    for o in &g.objects {
        assert!(!overlaps_open(o, foot), "{} on the start footprint", o.name);
    }
    // Same through the occupancy map the navigation stack uses.
    let map = OccupancyMap::from_objects(&g.objects, 0.05, NAV_BAND, l.bounds);
    let mut k = 0.0;
    while k <= 1.0 {
        let (px, py) =
            (foot[0] + 0.01 + k * (foot[2] - foot[0] - 0.02), foot[1] + 0.01 + k * (foot[3] - foot[1] - 0.02));
        assert!(!map.is_occupied_at(px, y) && !map.is_occupied_at(x, py));
        k += 0.05;
    }
}

#[test]
fn layout_default() {
    check_layout(&GreenhouseConfig::default(), 1);
}

#[test]
fn layout_with_inactive_rows_and_shifted_block() {
    check_layout(&cfg("rows = 12\nactive_rows = 5\nfirst_active_row = 4\nrow_length = 12.0"), 3);
}

#[test]
fn random_obstacles_never_close_an_aisle() {
    let c = cfg("random_obstacles = 25\nrow_length = 30.0");
    for seed in 0..20 {
        let g = generate(&c, seed);
        let obs: Vec<&Object> = g.objects.iter().filter(|o| o.kind == Kind::Obstacle).collect();
        assert!(obs.len() >= 20, "seed {seed}: only {} obstacles placed", obs.len());
        for a in &g.layout.aisles {
            // Sweep along the aisle: the free width at each x stays >= min_passage.
            let mut x = a.x_start;
            while x < a.x_end {
                let mut blocked = 0.0;
                for o in &obs {
                    let (mn, mx) = o.aabb();
                    if mn[0] <= x && mx[0] >= x && mx[1] > a.y - 0.5 * a.width && mn[1] < a.y + 0.5 * a.width {
                        blocked += mx[1].min(a.y + 0.5 * a.width) - mn[1].max(a.y - 0.5 * a.width);
                    }
                }
                assert!(a.width - blocked >= c.min_passage - 1e-9, "seed {seed} aisle {} x {x}", a.index);
                x += 0.05;
            }
        }
    }
}

#[test]
fn block_aisles_close_exactly_those_aisles() {
    let c = cfg("block_aisles = [1, 3]");
    let g = generate(&c, 1);
    let map = OccupancyMap::from_objects(&g.objects, 0.05, NAV_BAND, g.layout.bounds);
    for a in &g.layout.aisles {
        let xm = 0.5 * (a.x_start + a.x_end);
        // Walk across the aisle at its middle: a wall spans it iff blocked.
        let mut y = a.y - 0.5 * a.width + 0.01;
        let mut all = true;
        let mut any = false;
        while y < a.y + 0.5 * a.width {
            let occ = map.is_occupied_at(xm, y);
            all &= occ;
            any |= occ;
            y += 0.05;
        }
        if c.block_aisles.contains(&a.index) {
            assert!(all, "aisle {} not closed", a.index);
        } else {
            assert!(!any, "aisle {} obstructed", a.index);
        }
    }
}

#[test]
fn placed_obstacles_are_where_asked() {
    let g = generate(&cfg("[[obstacles]]\nx = 12.0\ny = 20.0\nsize_x = 0.4\nsize_y = 0.6\nheight = 0.7"), 1);
    let o = g.objects.iter().find(|o| o.name == "obstacle0").unwrap();
    assert_eq!(o.placement.translation, [12.0, 20.0, 0.35]);
    assert_eq!(o.shape, Shape::Box { half: [0.2, 0.3, 0.35] });
}

#[test]
fn rows_160_generate() {
    let c = cfg("rows = 160\nwidth = 420.0\nfirst_active_row = 77");
    let g = generate(&c, 1);
    assert_eq!(g.layout.rows.len(), 160);
    assert_eq!(g.layout.aisles.len(), 5);
    assert!(g.objects.len() > 250_000, "{}", g.objects.len());
    assert!(g.objects.iter().all(|o| {
        let (mn, mx) = o.aabb();
        mn[1] >= -0.5 && mx[1] <= 420.5 && mn[0] >= -0.5 && mx[0] <= 70.5
    }));
}

#[test]
fn fruit_of_a_plant_do_not_interpenetrate() {
    let c = GreenhouseConfig::default();
    let g = generate(&c, c.seed);
    let mut by_plant: std::collections::BTreeMap<String, Vec<([f64; 3], f64)>> = Default::default();
    for o in &g.objects {
        if let (Kind::Fruit { .. }, agrisim_scene::Shape::Sphere { radius }) = (o.kind, o.shape) {
            let plant = o.name.rsplit_once('/').unwrap().0.to_string();
            by_plant.entry(plant).or_default().push((o.placement.translation, radius));
        }
    }
    let (mut pairs, mut overlapping) = (0, 0);
    for fruit in by_plant.values() {
        for (i, (a, ra)) in fruit.iter().enumerate() {
            for (b, rb) in &fruit[i + 1..] {
                pairs += 1;
                let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
                overlapping += (d < ra + rb - 1e-9) as usize;
            }
        }
    }
    // A handful may keep their place when neither hanging lower nor higher fits the band.
    assert!(overlapping * 1000 < pairs, "{overlapping} of {pairs} fruit pairs interpenetrate");
    eprintln!("{overlapping} of {pairs} same-plant fruit pairs interpenetrate");
}

#[test]
fn compound_leaves_have_7_to_9_leaflets_inside_the_leaf() {
    for (seed, pairs) in [(1, 3), (2, 4), (3, 3), (4, 4)] {
        let half = [0.14, 0.09, 0.005];
        let mut rng = agrisim_math::Rng::new(seed);
        let parts = compound_leaf(half, pairs, &mut rng);
        let leaflets = parts.iter().filter(|p| p.0 == LeafPart::Leaflet).count();
        assert_eq!(leaflets, 2 * pairs + 1);
        assert!((7..=9).contains(&leaflets));
        assert_eq!(parts.iter().filter(|p| p.0 == LeafPart::Rachis).count(), 1);
        let mut lateral = 0;
        for (part, shape, pl) in &parts {
            let o = Object { id: 0, name: String::new(), kind: Kind::Leaf, shape: *shape, placement: *pl };
            let (lo, hi) = o.aabb();
            for i in 0..3 {
                assert!(lo[i] >= -half[i] - 1e-12 && hi[i] <= half[i] + 1e-12, "{part:?} {lo:?} {hi:?}");
            }
            if let (LeafPart::Leaflet, Shape::Box { half: h }) = (part, shape) {
                // Longer than wide, at most 0.3 of the leaf.
                assert!(h[0] > h[1] && 2.0 * h[0] <= 0.3 * 2.0 * half[0] + 1e-12);
                if pl.translation[1].abs() > 1e-9 {
                    lateral += 1;
                    // Pointing out from the rachis and toward the tip, 40-60 deg off it.
                    let tip = o.placement.transform_point([h[0], 0.0, 0.0]);
                    let dir = [tip[0] - pl.translation[0], tip[1] - pl.translation[1]];
                    let angle = (dir[1].abs()).atan2(dir[0]).to_degrees();
                    assert!((40.0..=60.0).contains(&angle), "{angle}");
                    assert!(dir[1] * pl.translation[1] > 0.0);
                }
            }
        }
        assert_eq!(lateral, 2 * pairs);
    }
}

#[test]
fn pedicels_rise_from_the_fruit_top_to_the_truss() {
    let c = cfg("rows = 2\nactive_rows = 2\nwidth = 12.0\nlength = 20.0\nrow_length = 4.0");
    let g = generate(&c, 3);
    let mut n = 0;
    for f in g.objects.iter().filter(|o| matches!(o.kind, Kind::Fruit { .. })) {
        let Shape::Sphere { radius } = f.shape else { panic!("fruit {} is no sphere", f.name) };
        let name = f.name.replace("/fruit", "/pedicel");
        let p = g.objects.iter().find(|o| o.name == name).expect("a pedicel per fruit");
        let Shape::Cylinder { half_height, .. } = p.shape else { panic!() };
        let ends = [-half_height, half_height].map(|z| p.placement.transform_point([0.0, 0.0, z]));
        let (low, high) = if ends[0][2] < ends[1][2] { (ends[0], ends[1]) } else { (ends[1], ends[0]) };
        let c = f.placement.translation;
        let top = [c[0], c[1], c[2] + radius];
        assert!((0..3).all(|i| (low[i] - top[i]).abs() < 1e-9), "{} starts at {low:?}, top {top:?}", p.name);
        assert!(high[2] > top[2]);
        // The upper end lies on the truss's axis (or just above a fruit touching it).
        let truss_name = f.name.split("/fruit").next().unwrap().to_string()
            + "/truss"
            + f.name.rsplit("/fruit").next().unwrap().split('_').next().unwrap();
        let truss = g.objects.iter().find(|o| o.name == truss_name).expect("truss");
        let local = Placement { translation: truss.placement.translation, rotation: truss.placement.rotation };
        let m = local.matrix();
        let d = [0, 1, 2].map(|i| high[i] - local.translation[i]);
        let off_axis = [0, 1].map(|j| (0..3).map(|i| m[i][j] * d[i]).sum::<f64>());
        assert!(off_axis[0].hypot(off_axis[1]) < 1e-9 || high[2] - top[2] < 0.0041, "{}", p.name);
        n += 1;
    }
    assert!(n > 100);
}
