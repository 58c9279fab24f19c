//! Crop presets (`crop = "..."`) and scenario families (`[greenhouse.family]`).

use agrisim_scene::{generate, Greenhouse, GreenhouseConfig, Kind, Shape};

/// FNV-1a over the scene's objects (ids, names, kinds, shapes and placements, f64s by their
/// bits): any change to the generated greenhouse changes it.
fn scene_hash(gh: &Greenhouse) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= b as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for o in &gh.objects {
        eat(&o.id.to_le_bytes());
        eat(o.name.as_bytes());
        eat(format!("{:?}", o.kind).as_bytes());
        let shape: Vec<f64> = match o.shape {
            Shape::Sphere { radius } => vec![radius],
            Shape::Box { half } => half.to_vec(),
            Shape::Cylinder { radius, half_height } => vec![radius, half_height],
        };
        for v in shape.iter().chain(&o.placement.translation).chain(&o.placement.rotation) {
            eat(&v.to_bits().to_le_bytes());
        }
    }
    h
}

fn cfg(s: &str) -> GreenhouseConfig {
    GreenhouseConfig::from_toml_str(s).unwrap()
}

fn fruit_radii(gh: &Greenhouse) -> Vec<f64> {
    gh.objects
        .iter()
        .filter_map(|o| match (o.kind, o.shape) {
            (Kind::Fruit { .. }, Shape::Sphere { radius }) => Some(radius),
            _ => None,
        })
        .collect()
}

/// The default greenhouse (and `crop = "loose_round"`, its preset) generates exactly the
/// scene it generated before crop presets existed: hash and counts recorded from that code.
#[test]
fn default_greenhouse_is_unchanged_by_crop_presets() {
    for text in ["", "crop = \"loose_round\"", "active_rows = 6\naisle_width = 2.0\nseed = 1"] {
        let c = cfg(text);
        assert_eq!(c, GreenhouseConfig::default(), "{text:?}");
        let gh = generate(&c, c.seed);
        assert_eq!(gh.objects.len(), 35712, "{text:?}");
        assert_eq!(fruit_radii(&gh).len(), 7200, "{text:?}");
        assert_eq!(scene_hash(&gh), 0x86a3_91b1_3a7c_e6bb, "{text:?}");
    }
}

#[test]
fn a_preset_sets_the_crop_fields_and_explicit_keys_override_it() {
    let t = cfg("crop = \"truss\"");
    assert_eq!((t.fruit_per_truss, t.fruit_radius, t.leaf_density), (7, 0.0288, 10));
    assert_eq!(t.leaf_size, [0.4, 0.25]);
    let c = cfg("crop = \"cherry\"");
    assert_eq!((c.fruit_per_truss, c.fruit_radius, c.trusses_per_plant), (16, 0.015, 4));
    let o = cfg("crop = \"cherry\"\nfruit_per_truss = 12\nleaf_size = [0.2, 0.1]");
    assert_eq!((o.fruit_per_truss, o.fruit_radius, o.leaf_size), (12, 0.015, [0.2, 0.1]));
    // Keys a preset does not set keep their defaults.
    assert_eq!((o.aisle_width, o.fruit_height), (2.0, [0.5, 1.8]));
}

#[test]
fn an_unknown_crop_is_an_error_naming_the_key_and_the_crops() {
    let e = GreenhouseConfig::from_toml_str("crop = \"beefsteak\"").unwrap_err();
    assert!(e.contains("greenhouse.crop") && e.contains("beefsteak") && e.contains("cherry"), "{e}");
}

#[test]
fn cherry_fruit_are_25_to_35_mm_across_16_to_a_truss() {
    let c = cfg("crop = \"cherry\"\nrows = 2\nactive_rows = 2\nrow_length = 10.0");
    let gh = generate(&c, c.seed);
    let r = fruit_radii(&gh);
    assert_eq!(r.len(), 2 * 20 * 4 * 16);
    for &v in &r {
        assert!((0.0125 - 1e-12..=0.0175 + 1e-12).contains(&v), "fruit radius {v} m");
    }
    let mean = r.iter().sum::<f64>() / r.len() as f64;
    assert!((mean - 0.015).abs() < 0.0005, "mean radius {mean}");
    // The limits are reached (the spread is not so small that they never matter).
    assert!(r.iter().any(|&v| v > 0.0170) && r.iter().any(|&v| v < 0.0130));
    // Every pedicel still joins its fruit's top to the truss.
    let pedicels = gh.objects.iter().filter(|o| o.name.contains("/pedicel")).count();
    assert_eq!(pedicels, r.len());
}

const FAMILY: &str = "[family]
aisle_width = [1.6, 2.2]
fruit_per_truss = [3, 8]
leaf_density = [4, 14]
fruit_radius = [0.020, 0.040]
fruit_height_low = [0.4, 0.6]
fruit_height_high = [1.5, 1.8]
";

#[test]
fn family_draws_stay_in_their_ranges_and_depend_only_on_the_seed() {
    let mut fpt = std::collections::BTreeSet::new();
    let mut leaves = std::collections::BTreeSet::new();
    let (mut aisle, mut radius) = ([f64::MAX, f64::MIN], [f64::MAX, f64::MIN]);
    for k in 0..100u64 {
        let text = format!("seed = {}\n{FAMILY}", 7 + k);
        let c = cfg(&text);
        assert_eq!(c, cfg(&text), "draw {k} is not deterministic");
        assert!((1.6..=2.2).contains(&c.aisle_width), "draw {k}: aisle {}", c.aisle_width);
        assert!((3..=8).contains(&c.fruit_per_truss), "draw {k}: {}", c.fruit_per_truss);
        assert!((4..=14).contains(&c.leaf_density), "draw {k}: {}", c.leaf_density);
        assert!((0.020..=0.040).contains(&c.fruit_radius), "draw {k}: {}", c.fruit_radius);
        assert!((0.4..=0.6).contains(&c.fruit_height[0]) && (1.5..=1.8).contains(&c.fruit_height[1]));
        fpt.insert(c.fruit_per_truss);
        leaves.insert(c.leaf_density);
        aisle = [aisle[0].min(c.aisle_width), aisle[1].max(c.aisle_width)];
        radius = [radius[0].min(c.fruit_radius), radius[1].max(c.fruit_radius)];
    }
    // 100 draws cover the ranges: every count, and most of each interval.
    assert_eq!(fpt.len(), 6, "{fpt:?}");
    assert_eq!(leaves.len(), 11, "{leaves:?}");
    assert!(aisle[0] < 1.7 && aisle[1] > 2.1, "{aisle:?}");
    assert!(radius[0] < 0.022 && radius[1] > 0.038, "{radius:?}");
    // The generated scene follows the draw.
    let c = cfg(&format!("seed = 9\nrows = 2\nactive_rows = 2\nrow_length = 5.0\n{FAMILY}"));
    let gh = generate(&c, c.seed);
    assert_eq!(fruit_radii(&gh).len(), 2 * 10 * c.trusses_per_plant * c.fruit_per_truss);
    assert!((gh.layout.aisles[0].width - c.aisle_width).abs() < 1e-12);
}

#[test]
fn a_key_both_drawn_and_given_is_an_error_naming_both() {
    let e = GreenhouseConfig::from_toml_str(&format!("aisle_width = 2.0\n{FAMILY}")).unwrap_err();
    assert!(e.contains("greenhouse.family.aisle_width") && e.contains("greenhouse.aisle_width"), "{e}");
    let e = GreenhouseConfig::from_toml_str("[family]\nfruit_per_truss = [8, 3]").unwrap_err();
    assert!(e.contains("greenhouse.family.fruit_per_truss"), "{e}");
    let e = GreenhouseConfig::from_toml_str("[family]\nfruit_per_trus = [3, 8]").unwrap_err();
    assert!(e.contains("fruit_per_trus"), "{e}");
}

#[test]
fn a_family_draws_over_its_crop_preset() {
    let c = cfg("crop = \"cherry\"\n[family]\nfruit_radius = [0.012, 0.018]");
    assert!((0.012..=0.018).contains(&c.fruit_radius));
    assert_eq!((c.fruit_per_truss, c.fruit_radius_spread), (16, 0.07));
}

#[test]
fn loose_round_is_the_default_greenhouse() {
    let named = GreenhouseConfig::from_toml_str("crop = \"loose_round\"").unwrap();
    assert_eq!(named, GreenhouseConfig::default());
    assert_eq!(GreenhouseConfig::from_toml_str("").unwrap(), GreenhouseConfig::default());
}
