//! Images under sun and weather: darker at dusk and under cloud, shadows opposite the sun's
//! azimuth, geometry (depth, labels) untouched by light and weather, fog removing far depth
//! only, render quality changing colours only, and frames independent of the number of
//! render threads.

use agrisim_fmi::{Model, Quiet, Store, Value};
use agrisim_fmu_camera::lighting::Lighting;
use agrisim_fmu_camera::optics::{CameraPose, Intrinsics, Mount};
use agrisim_fmu_camera::ports::*;
use agrisim_fmu_camera::render::{self, DepthModel, DepthNoise};
use agrisim_fmu_camera::scene::Scene;
use agrisim_fmu_camera::{image, Camera};
use agrisim_math::Rng;
use agrisim_msgs::sensor_msgs::Image;
use agrisim_msgs::Message;
use agrisim_scene::{generate, GreenhouseConfig, Kind, Object, Placement, Shape};
use agrisim_sky::environment::Environment;
use agrisim_sky::weather::Conditions;

const NOON: &str = "date = \"2025-06-21\"\ntime = \"13:40\"";
const DUSK: &str = "date = \"2025-06-21\"\ntime = \"21:15\"";

struct Shot {
    rgb: Vec<u8>,
    depth: Vec<u8>,
    labels: Vec<u8>,
}

/// One frame of the FMU in the middle of an aisle of the default greenhouse, looking at a row.
fn shot(environment: &str, threads: i32) -> Shot {
    shot_with(environment, threads, |_| ())
}

/// [`shot`] with more of the camera's parameters set by `set`.
fn shot_with(environment: &str, threads: i32, set: impl FnOnce(&mut Store)) -> Shot {
    let cfg = GreenhouseConfig::from_toml_str("").unwrap();
    let gh = generate(&cfg, cfg.seed);
    let a = &gh.layout.aisles[1];
    let mut io = Store::new(Camera::VARIABLES);
    *io.value_mut(WIDTH) = Value::Int32(160);
    *io.value_mut(HEIGHT) = Value::Int32(90);
    *io.value_mut(NOISE_SEED) = Value::Int32(7);
    *io.value_mut(ENVIRONMENT) = Value::String(environment.into());
    *io.value_mut(RENDER_THREADS) = Value::Int32(threads);
    io.set_f64(BASE_X, 0.5 * (a.x_start + a.x_end));
    io.set_f64(BASE_Y, a.y);
    io.set_f64(BASE_YAW, 0.3);
    set(&mut io);
    let mut m = Camera::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    m.do_step(&mut io, 0.0, 0.02, &mut Quiet).unwrap();
    let img = |i| Image::from_cdr(agrisim_fmi::port::latest(&io, i)).unwrap().data;
    Shot { rgb: img(IMAGE), depth: img(DEPTH), labels: img(LABELS_IMAGE) }
}

/// Mean Rec. 709 luma of an rgb8 image (on the sRGB codes).
fn luma(rgb: &[u8]) -> f64 {
    let n = rgb.len() / 3;
    rgb.chunks_exact(3).map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64).sum::<f64>()
        / n as f64
}

#[test]
fn darker_at_dusk_and_under_cloud_with_the_same_geometry() {
    let noon = shot(NOON, 2);
    let dusk = shot(DUSK, 2);
    let overcast = shot(&format!("{NOON}\nweather = \"overcast\""), 2);
    let rain = shot(&format!("{NOON}\nweather = \"rain\""), 2);
    // Surfaces only: pixels seeing the sky through the glass are left out (an overcast sky is
    // brighter than a clear blue one, while the light it sends down is much weaker).
    let cfg = GreenhouseConfig::from_toml_str("").unwrap();
    let kinds: Vec<Kind> = generate(&cfg, cfg.seed).objects.iter().map(|o| o.kind).collect();
    let ids: Vec<i32> = noon.labels.chunks_exact(4).map(|c| i32::from_le_bytes(c.try_into().unwrap())).collect();
    let surface: Vec<bool> =
        ids.iter().map(|&l| l > 0 && !matches!(kinds.get(l as usize - 1), Some(Kind::Wall | Kind::Roof))).collect();
    assert!(surface.iter().filter(|&&b| b).count() > 160 * 90 / 2);
    let luma = |rgb: &[u8]| {
        let px: Vec<u8> = rgb.chunks_exact(3).zip(&surface).filter(|(_, &s)| s).flat_map(|(p, _)| p.to_vec()).collect();
        luma(&px)
    };
    let (ln, ld, lo, lr) = (luma(&noon.rgb), luma(&dusk.rgb), luma(&overcast.rgb), luma(&rain.rgb));
    println!("mean luma of surfaces: noon {ln:.1}, dusk {ld:.1}, overcast {lo:.1}, rain {lr:.1}");
    assert!(ld < 0.6 * ln, "dusk {ld} noon {ln}");
    assert!(lo < 0.8 * ln && lr < lo, "overcast {lo} rain {lr} noon {ln}");
    assert!(ld > 1.0, "dusk is dark, not black: {ld}");
    // Light and weather never touch geometry: depth (noise included) and labels byte for byte.
    for other in [&dusk, &overcast, &rain] {
        assert_eq!(other.depth, noon.depth);
        assert_eq!(other.labels, noon.labels);
        assert_ne!(other.rgb, noon.rgb);
    }
    // ... and the fixed-sun camera without an environment sees the same geometry too.
    let fixed = shot("", 2);
    assert_eq!(fixed.depth, noon.depth);
}

#[test]
fn fog_removes_far_depth_only_and_fades_colour() {
    let clear = shot(NOON, 2);
    let fog = shot(&format!("{NOON}\nweather = \"fog\"\nvisibility = 8.0"), 2);
    assert_eq!(fog.labels, clear.labels);
    let exact = shot_with(NOON, 2, |io| *io.value_mut(DEPTH_NOISE_MODEL) = Value::Int32(0));
    let k = Intrinsics::from_fov(160, 90, 87.0, 58.0);
    let limit = 10f64.ln() / (3.912 / 8.0);
    let z = |b: &[u8], i: usize| f32::from_le_bytes(b[4 * i..4 * i + 4].try_into().unwrap()) as f64;
    let (mut kept, mut lost) = (0, 0);
    for i in 0..160 * 90 {
        let (zc, zf) = (z(&clear.depth, i), z(&fog.depth, i));
        // The true range along the ray: the noise-free image's depth.
        let range = z(&exact.depth, i) / k.ray((i % 160) as f64, (i / 160) as f64)[2];
        if zf > 0.0 {
            assert_eq!(zf, zc, "pixel {i}: fog keeps depth where it keeps any");
            assert!(range <= limit, "pixel {i} at {range} m kept (limit {limit})");
            kept += 1;
        } else if zc > 0.0 {
            // Lost pixels are beyond the fog's depth range.
            assert!(range > limit, "pixel {i} at {range} m lost (limit {limit})");
            lost += 1;
        }
    }
    println!("fog (visibility 8 m, depth limit {limit:.2} m): kept {kept}, lost {lost}");
    assert!(kept > 1000 && lost > 200, "kept {kept} lost {lost}");
    // Colour contrast falls: the image's spread of luma shrinks.
    let spread = |rgb: &[u8]| {
        let l: Vec<f64> = rgb.chunks_exact(3).map(|p| p[0] as f64 + p[1] as f64 + p[2] as f64).collect();
        let m = l.iter().sum::<f64>() / l.len() as f64;
        (l.iter().map(|v| (v - m).powi(2)).sum::<f64>() / l.len() as f64).sqrt()
    };
    assert!(spread(&fog.rgb) < 0.7 * spread(&clear.rgb));
}

#[test]
fn frames_do_not_depend_on_the_thread_count() {
    let env = format!("{NOON}\nrender_quality = \"high\"");
    let one = shot(&env, 1);
    let two = shot(&env, 2);
    let three = shot(&env, 3);
    assert!(one.rgb == two.rgb && one.depth == two.depth && one.labels == two.labels);
    assert!(one.rgb == three.rgb && one.depth == three.depth);
    let d = image::read_32fc1(&Image {
        encoding: "32FC1".into(),
        width: 160,
        height: 90,
        step: 640,
        data: one.depth.clone(),
        ..Default::default()
    })
    .unwrap();
    assert!(d.iter().filter(|&&z| z > 0.0).count() > 160 * 90 / 3);
}

/// Render quality (no shadows, hard, soft) changes colours only: depth (noise included) and
/// labels stay byte for byte.
#[test]
fn render_quality_changes_the_image_not_depth_or_labels() {
    let [low, medium, high] = ["low", "medium", "high"].map(|q| shot(&format!("{NOON}\nrender_quality = \"{q}\""), 2));
    for other in [&medium, &high] {
        assert_eq!(other.depth, low.depth);
        assert_eq!(other.labels, low.labels);
    }
    assert_ne!(medium.rgb, low.rgb, "shadows change the image");
    assert_ne!(high.rgb, medium.rgb, "soft shadows change the image");
}

/// Floor and a tall post at the origin; the camera 8 m above it looking straight down.
fn post_scene() -> (Scene, Intrinsics, CameraPose) {
    let objects = vec![
        Object {
            id: 0,
            name: "floor".into(),
            kind: Kind::Floor,
            shape: Shape::Box { half: [50.0, 50.0, 0.05] },
            placement: Placement::at(0.0, 0.0, -0.05),
        },
        Object {
            id: 1,
            name: "post".into(),
            kind: Kind::Obstacle,
            shape: Shape::Box { half: [0.1, 0.1, 1.0] },
            placement: Placement::at(0.0, 0.0, 1.0),
        },
    ];
    let k = Intrinsics::from_fov(200, 200, 90.0, 90.0);
    let mount = Mount { translation: [0.0, 0.0, 8.0], roll: 0.0, pitch: std::f64::consts::FRAC_PI_2, yaw: 0.0 };
    (Scene::from_objects(&objects), k, CameraPose::new(&mount, 0.0, 0.0, 0.0))
}

/// Centroid (map x, y) of the floor pixels in shadow.
fn shadow_centroid(environment: &str) -> ([f64; 2], f64) {
    let (scene, k, pose) = post_scene();
    let c = Conditions::of(&Environment::from_toml_str(environment).unwrap());
    let light = Lighting::from_conditions(&c);
    let model = DepthModel {
        range: (0.1, 20.0),
        noise: DepthNoise::None,
        baseline: 0.05,
        invalid_band: false,
        edge_ratio: 0.0,
    };
    let f = render::render(
        &render::Shot { scene: &scene, dynamic: &[], k: &k, pose: &pose, light: &light, columns: &[], depth: &model },
        &mut Rng::new(1),
        2,
    );
    // Sunlit floor is far brighter than the floor lit by the sky alone.
    let floor: Vec<usize> = (0..f.labels.len()).filter(|&i| f.labels[i] == 1).collect();
    let max = floor.iter().map(|&i| f.rgb[3 * i] as u32).max().unwrap();
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
    for &i in &floor {
        if (f.rgb[3 * i] as u32) < max / 2 {
            let (u, v) = ((i % 200) as f64, (i / 200) as f64);
            let p = pose.to_map(k.reproject(u, v, f.true_depth[i] as f64));
            sx += p[0];
            sy += p[1];
            n += 1.0;
        }
    }
    assert!(n > 20.0, "{environment}: a shadow is seen ({n} px)");
    ([sx / n, sy / n], c.sun_map_azimuth)
}

#[test]
fn shadows_point_away_from_the_sun() {
    // Morning (sun in the east-south-east) and afternoon (west-south-west) in the Netherlands.
    let mut directions = vec![];
    for time in ["09:00", "17:30"] {
        let ([x, y], sun_az) = shadow_centroid(&format!("date = \"2025-06-21\"\ntime = \"{time}\""));
        let shadow_az = y.atan2(x).to_degrees();
        let off = (shadow_az - (sun_az + 180.0)).rem_euclid(360.0);
        let off = off.min(360.0 - off);
        println!("{time}: sun at map azimuth {sun_az:.1} deg, shadow centroid ({x:.2}, {y:.2}) at {shadow_az:.1} deg, {off:.1} deg from opposite the sun");
        assert!(off < 10.0, "{time}: shadow {shadow_az} sun {sun_az}");
        directions.push(shadow_az);
    }
    let turn = (directions[1] - directions[0]).rem_euclid(360.0);
    assert!(turn > 90.0 && turn < 270.0, "the shadow swings with the sun: {directions:?}");
    // No shadows at low quality.
    let (scene, k, pose) = post_scene();
    let c = Conditions::of(
        &Environment::from_toml_str("date = \"2025-06-21\"\ntime = \"09:00\"\nrender_quality = \"low\"").unwrap(),
    );
    let model = DepthModel {
        range: (0.1, 20.0),
        noise: DepthNoise::None,
        baseline: 0.05,
        invalid_band: false,
        edge_ratio: 0.0,
    };
    let f = render::render(
        &render::Shot {
            scene: &scene,
            dynamic: &[],
            k: &k,
            pose: &pose,
            light: &Lighting::from_conditions(&c),
            columns: &[],
            depth: &model,
        },
        &mut Rng::new(1),
        1,
    );
    let floor: Vec<u8> = (0..f.labels.len()).filter(|&i| f.labels[i] == 1).map(|i| f.rgb[3 * i]).collect();
    assert_eq!(floor.iter().min(), floor.iter().max(), "flat floor, one colour");
}

#[test]
fn solar_outputs_and_bad_environment() {
    let mut io = Store::new(Camera::VARIABLES);
    *io.value_mut(WIDTH) = Value::Int32(8);
    *io.value_mut(HEIGHT) = Value::Int32(8);
    *io.value_mut(ENVIRONMENT) = Value::String("date = \"2003-10-17\"\ntime = \"12:30:30\"\nutc_offset = -7.0\nlatitude = 39.742476\nlongitude = -105.1786\nelevation = 1830.14\npressure = 820.0\ntemperature = 11.0".into());
    Camera::new().initialize(&mut io, 0.0, &mut Quiet).unwrap();
    // The SPA paper's example (Delta T here is the Espenak-Meeus estimate, 64.6 s, not 67 s).
    assert!((io.f64(SOLAR_ZENITH) - 50.11162).abs() < 1e-3 && (io.f64(SOLAR_AZIMUTH) - 194.34024).abs() < 1e-3);
    *io.value_mut(ENVIRONMENT) = Value::String("weather = \"hail\"".into());
    let e = Camera::new().initialize(&mut io, 0.0, &mut Quiet).unwrap_err();
    assert!(e.contains("environment") && e.contains("weather"), "{e}");
}

/// The shadow grids ([`render::sun_columns`]) only skip work: frames with them equal frames
/// without, pixel for pixel, with hard shadows (packets) and with soft shadows and
/// supersampled colour (single rays), with the robot's base among the movers.
#[test]
fn sun_columns_change_no_pixel() {
    let cfg = GreenhouseConfig::from_toml_str("").unwrap();
    let gh = generate(&cfg, cfg.seed);
    let scene = Scene::from_objects(&gh.objects);
    let a = &gh.layout.aisles[1];
    let (x, y) = (0.5 * (a.x_start + a.x_end), a.y);
    let base = Object {
        id: gh.objects.len() as u32,
        name: "base".into(),
        kind: Kind::Robot,
        shape: Shape::Box { half: [0.6, 0.45, 0.3] },
        placement: Placement::yawed([x + 1.5, y, 0.35], 0.2),
    };
    let model = DepthModel {
        range: (0.1, 10.0),
        noise: DepthNoise::None,
        baseline: 0.05,
        invalid_band: false,
        edge_ratio: 0.0,
    };
    for (quality, w, h) in [("medium", 320, 180), ("high", 96, 54)] {
        let c =
            Conditions::of(&Environment::from_toml_str(&format!("{NOON}\nrender_quality = \"{quality}\"")).unwrap());
        let light = Lighting::from_conditions(&c);
        let columns = render::sun_columns(&scene, &light);
        assert_eq!(columns.len(), light.sun_samples().unwrap() as usize, "{quality}: a grid per sun sample");
        let k = Intrinsics::from_fov(w, h, 87.0, 58.0);
        for yaw in [0.3, 1.9] {
            let mount = Mount { translation: [0.0, 0.0, 1.2], roll: 0.0, pitch: 0.2, yaw: 0.0 };
            let pose = CameraPose::new(&mount, x, y, yaw);
            let frame = |columns: &[_]| {
                render::render(
                    &render::Shot {
                        scene: &scene,
                        dynamic: std::slice::from_ref(&base),
                        k: &k,
                        pose: &pose,
                        light: &light,
                        columns,
                        depth: &model,
                    },
                    &mut Rng::new(1),
                    2,
                )
            };
            let (with, without) = (frame(&columns), frame(&[]));
            assert!(
                with.rgb == without.rgb && with.depth == without.depth && with.labels == without.labels,
                "{quality}, yaw {yaw}"
            );
            // A grid for another sun is not used.
            let other = render::sun_columns(
                &scene,
                &Lighting::from_conditions(&Conditions::of(
                    &Environment::from_toml_str(
                        &format!("{DUSK}\nrender_quality = \"{quality}\"").replace("21:15", "16:00"),
                    )
                    .unwrap(),
                )),
            );
            assert!(frame(&other).rgb == without.rgb, "{quality}, yaw {yaw}: another sun's grid");
        }
    }
}
