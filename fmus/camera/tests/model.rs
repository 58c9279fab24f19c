//! Camera behaviour: depth geometry against known surfaces, the noise and invalid-band
//! formulas, colour and labels of fruit, determinism, and the FMI model's messages.

use agrisim_fmi::{Model, Quiet, Store, Value};
use agrisim_fmu_camera::crop::{FruitLook, STUB_RADIUS};
use agrisim_fmu_camera::lighting::Lighting;
use agrisim_fmu_camera::optics::{CameraPose, Intrinsics, Mount};
use agrisim_fmu_camera::ports::*;
use agrisim_fmu_camera::render::{self, invalid_band_width, DepthModel, DepthNoise, Shot};
use agrisim_fmu_camera::scene::Scene;
use agrisim_fmu_camera::{image, Camera};
use agrisim_math::Rng;
use agrisim_msgs::sensor_msgs::{CameraInfo, Image};
use agrisim_msgs::Message;
use agrisim_scene::{generate, GreenhouseConfig, Kind, Object, Placement, Shape};

const MOUNT: Mount = Mount { translation: [0.6, 0.0, 1.2], roll: 0.0, pitch: 0.0, yaw: 0.0 };

/// A large wall (box) facing the camera, its front face `z` metres ahead of the optical centre
/// of a camera on a base at the origin looking along +x.
fn wall_scene(z: f64) -> Scene {
    let face = MOUNT.translation[0] + z;
    Scene::from_objects(&[Object {
        id: 0,
        name: "wall".into(),
        kind: Kind::Obstacle,
        shape: Shape::Box { half: [0.5, 100.0, 100.0] },
        placement: Placement::at(face + 0.5, 0.0, 0.0),
    }])
}

fn model(noise: DepthNoise, band: bool, edge: f64) -> DepthModel {
    DepthModel { range: (0.105, 10.0), noise, baseline: 0.05, invalid_band: band, edge_ratio: edge }
}

fn light() -> Lighting {
    Lighting::new(180.0, 30.0, 0.35)
}

/// A frame of `scene` alone (no robot objects), noise seeded with `seed`, on 2 threads.
fn shoot(
    scene: &Scene,
    k: &Intrinsics,
    pose: &CameraPose,
    light: &Lighting,
    depth: DepthModel,
    seed: u64,
) -> render::Frame {
    render::render(&Shot { scene, dynamic: &[], k, pose, light, columns: &[], depth: &depth }, &mut Rng::new(seed), 2)
}

#[test]
fn depth_reprojects_onto_the_wall() {
    let k = Intrinsics::from_fov(320, 180, 87.0, 58.0);
    let pose = CameraPose::new(&MOUNT, 0.0, 0.0, 0.0);
    for z in [0.5, 2.0, 7.5] {
        let scene = wall_scene(z);
        // Noise-free: every pixel reprojects exactly onto the wall's face.
        let f = shoot(&scene, &k, &pose, &light(), model(DepthNoise::None, false, 0.05), 1);
        assert_eq!(f.valid, 320 * 180);
        for v in (0..180).step_by(7) {
            for u in (0..320).step_by(5) {
                let d = f.depth[v * 320 + u] as f64;
                let p = pose.to_map(k.reproject(u as f64, v as f64, d));
                assert!((p[0] - (0.6 + z)).abs() < 1e-5 * z, "z {z} pixel ({u}, {v}) -> {p:?}");
                assert_eq!(f.labels[v * 320 + u], 1);
            }
        }
        // With the stereo model: within 5 sigma of the surface.
        let f = shoot(&scene, &k, &pose, &light(), model(DepthNoise::Stereo { subpixel: 0.08 }, true, 0.05), 2);
        let sigma = z * z * 0.08 / (k.fx * 0.05);
        let mut checked = 0;
        for (i, &d) in f.depth.iter().enumerate() {
            if d > 0.0 {
                let p = pose.to_map(k.reproject((i % 320) as f64, (i / 320) as f64, d as f64));
                assert!((p[0] - (0.6 + z)).abs() < 5.5 * sigma, "{p:?} sigma {sigma}");
                checked += 1;
            }
        }
        assert!(checked > 300 * 180, "{checked}");
    }
}

#[test]
fn out_of_range_is_zero() {
    let k = Intrinsics::from_fov(64, 36, 87.0, 58.0);
    let pose = CameraPose::new(&MOUNT, 0.0, 0.0, 0.0);
    for z in [0.05, 12.0] {
        let f = shoot(&wall_scene(z), &k, &pose, &light(), model(DepthNoise::None, false, 0.0), 1);
        assert_eq!(f.valid, 0, "z {z}");
        assert!(f.depth.iter().all(|&d| d == 0.0));
        assert!(f.labels.iter().all(|&l| l == 1), "still seen in colour and labels");
    }
}

fn measured_sigma(noise: DepthNoise, z: f64, k: &Intrinsics) -> f64 {
    let pose = CameraPose::new(&MOUNT, 0.0, 0.0, 0.0);
    let f = shoot(&wall_scene(z), k, &pose, &light(), model(noise, false, 0.0), 99);
    let errs: Vec<f64> =
        f.depth.iter().zip(&f.true_depth).filter(|(d, _)| **d > 0.0).map(|(d, t)| *d as f64 - *t as f64).collect();
    assert!(errs.len() > 200_000);
    let n = errs.len() as f64;
    let mean = errs.iter().sum::<f64>() / n;
    assert!(mean.abs() < 0.05 * noise.sigma(z, k.fx, 0.05) + 1e-6, "bias {mean}");
    (errs.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / n).sqrt()
}

#[test]
fn noise_matches_the_stereo_formula_and_the_fixed_sigma() {
    let k = Intrinsics::from_fov(640, 480, 87.0, 58.0);
    for z in [1.0, 2.5, 4.0] {
        let want = z * z * 0.08 / (k.fx * 0.05);
        let got = measured_sigma(DepthNoise::Stereo { subpixel: 0.08 }, z, &k);
        println!("stereo z = {z} m: sigma {got:.5} m, formula {want:.5} m");
        // ~300,000 pixels: the standard error of sigma is ~0.13 %.
        assert!((got / want - 1.0).abs() < 0.02, "z {z}: {got} vs {want}");
    }
    let got = measured_sigma(DepthNoise::Fixed { sigma: 0.015 }, 2.0, &k);
    assert!((got / 0.015 - 1.0).abs() < 0.02, "{got}");
}

#[test]
fn left_invalid_band_matches_the_formula() {
    let k = Intrinsics::from_fov(640, 360, 87.0, 58.0);
    let pose = CameraPose::new(&MOUNT, 0.0, 0.0, 0.0);
    for z in [0.5, 1.0, 3.0] {
        let f = shoot(&wall_scene(z), &k, &pose, &light(), model(DepthNoise::None, true, 0.05), 1);
        let want = invalid_band_width(k.fx, 0.05, z);
        for v in [0, 100, 359] {
            let row = &f.depth[v * 640..(v + 1) * 640];
            let band = row.iter().take_while(|&&d| d == 0.0).count();
            assert_eq!(band, want.ceil() as usize, "z {z} row {v}: band {band} px, formula {want:.2} px");
            assert!(row[band..].iter().all(|&d| d > 0.0));
        }
    }
}

#[test]
fn depth_discontinuities_are_invalid() {
    // A post 1 m ahead in front of a wall 3 m ahead: background pixels next to it drop out.
    let mut objects = vec![Object {
        id: 0,
        name: "wall".into(),
        kind: Kind::Obstacle,
        shape: Shape::Box { half: [0.5, 100.0, 100.0] },
        placement: Placement::at(0.6 + 3.0 + 0.5, 0.0, 0.0),
    }];
    objects.push(Object {
        id: 1,
        name: "post".into(),
        kind: Kind::Post,
        shape: Shape::Box { half: [0.05, 0.1, 5.0] },
        placement: Placement::at(0.6 + 1.05, 0.0, 0.0),
    });
    let scene = Scene::from_objects(&objects);
    let k = Intrinsics::from_fov(320, 180, 87.0, 58.0);
    let pose = CameraPose::new(&MOUNT, 0.0, 0.0, 0.0);
    let f = shoot(&scene, &k, &pose, &light(), model(DepthNoise::None, false, 0.05), 1);
    let row = 90 * 320;
    let post: Vec<usize> = (0..320).filter(|&u| f.labels[row + u] == 2).collect();
    let (first, last) = (post[0], *post.last().unwrap());
    assert!(f.depth[row + first] > 0.0 && f.depth[row + last] > 0.0, "the near side stays");
    assert_eq!(f.depth[row + first - 1], 0.0);
    assert_eq!(f.depth[row + last + 1], 0.0);
    assert!(f.depth[row + first - 3] > 2.9);
}

fn greenhouse() -> (Vec<Object>, [f64; 3]) {
    let cfg = GreenhouseConfig::from_toml_str("").unwrap();
    let gh = generate(&cfg, cfg.seed);
    let a = &gh.layout.aisles[0];
    (gh.objects.clone(), [0.5 * (a.x_start + a.x_end), a.y, std::f64::consts::FRAC_PI_2])
}

#[test]
fn labels_name_fruit_and_ripe_fruit_is_red() {
    let (objects, [x, y, yaw]) = greenhouse();
    let scene = Scene::from_objects(&objects);
    let k = Intrinsics::from_fov(320, 240, 87.0, 58.0);
    let mut fruit_px = 0;
    let mut ripe = [0.0f64; 3];
    let mut ripe_n = 0;
    let mut green = [0.0f64; 3];
    let mut green_n = 0;
    for side in [yaw, -yaw] {
        let pose = CameraPose::new(&MOUNT, x, y, side);
        let f = shoot(&scene, &k, &pose, &Lighting::new(0.0, 90.0, 0.35), model(DepthNoise::None, false, 0.0), 1);
        for (i, &l) in f.labels.iter().enumerate() {
            if l <= 0 {
                continue;
            }
            let o = &objects[(l - 1) as usize];
            assert_eq!(o.id as i32 + 1, l);
            if let (Kind::Fruit { ripeness }, Shape::Sphere { radius }) = (o.kind, o.shape) {
                fruit_px += 1;
                // The pixel's depth (when in range) reprojects onto this very fruit.
                if f.depth[i] == 0.0 {
                    continue;
                }
                let p = pose.to_map(k.reproject((i % 320) as f64, (i / 320) as f64, f.depth[i] as f64));
                let c = o.placement.translation;
                // On the rendered fruit inside the collider: the oblate spheroid, or the calyx
                // stub on top.
                let k = FruitLook::of(o.id, ripeness).shape_index;
                let q = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
                let e = (q[0] * q[0] + q[1] * q[1] + (q[2] / k).powi(2)).sqrt();
                let stub = q[2] >= k * radius - 1e-3 && q[0].hypot(q[1]) <= STUB_RADIUS + 1e-4;
                assert!((e - radius).abs() < 1e-4 || stub, "{} at {q:?} from its centre, radius {radius}", o.name);
                let px = &f.rgb[3 * i..3 * i + 3];
                let acc = |a: &mut [f64; 3]| (0..3).for_each(|j| a[j] += px[j] as f64);
                if ripeness == 6 {
                    acc(&mut ripe);
                    ripe_n += 1;
                } else if ripeness == 1 {
                    acc(&mut green);
                    green_n += 1;
                }
            }
        }
    }
    assert!(fruit_px > 100 && ripe_n > 10 && green_n > 10, "{fruit_px} {ripe_n} {green_n}");
    let ripe = ripe.map(|c| c / ripe_n as f64);
    let green = green.map(|c| c / green_n as f64);
    println!("mean colour of ripe (stage 6) fruit pixels {ripe:?}, green (stage 1) {green:?}");
    assert!(ripe[0] > 2.0 * ripe[1] && ripe[0] > 2.0 * ripe[2], "ripe {ripe:?}");
    assert!(green[1] > green[0] && green[1] > green[2], "green {green:?}");
}

#[test]
fn shadows_follow_the_sun() {
    // A floor and a block on it; with the sun low in +x the floor behind the block (-x side)
    // is darker than in front of it.
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
            name: "block".into(),
            kind: Kind::Obstacle,
            shape: Shape::Box { half: [0.2, 0.2, 0.5] },
            placement: Placement::at(3.0, 0.0, 0.5),
        },
    ];
    let scene = Scene::from_objects(&objects);
    let k = Intrinsics::from_fov(320, 240, 87.0, 58.0);
    let mount = Mount { translation: [0.0, 0.0, 6.0], roll: 0.0, pitch: std::f64::consts::FRAC_PI_2, yaw: 0.0 };
    let pose = CameraPose::new(&mount, 3.0, 0.0, 0.0); // straight down onto the block
    let px = |az: f64, p: [f64; 3]| {
        let f = shoot(&scene, &k, &pose, &Lighting::new(az, 30.0, 0.35), model(DepthNoise::None, false, 0.0), 1);
        // Project the floor point into the image.
        let rel = [p[0] - pose.origin[0], p[1] - pose.origin[1], p[2] - pose.origin[2]];
        let r = pose.rotation;
        let o = [0, 1, 2].map(|j| r[0][j] * rel[0] + r[1][j] * rel[1] + r[2][j] * rel[2]);
        let (u, v) = ((k.fx * o[0] / o[2] + k.cx).round() as usize, (k.fy * o[1] / o[2] + k.cy).round() as usize);
        f.rgb[3 * (v * 320 + u)]
    };
    let behind = [3.0 - 1.0, 0.0, 0.0];
    let front = [3.0 + 1.0, 0.0, 0.0];
    assert!(px(0.0, behind) < px(0.0, front), "sun in +x: shadow toward -x");
    assert!(px(180.0, behind) > px(180.0, front), "sun in -x: shadow toward +x");
}

fn store(w: i32, h: i32, seed: i32) -> Store {
    let mut io = Store::new(Camera::VARIABLES);
    *io.value_mut(WIDTH) = Value::Int32(w);
    *io.value_mut(HEIGHT) = Value::Int32(h);
    *io.value_mut(NOISE_SEED) = Value::Int32(seed);
    let (_, [x, y, yaw]) = greenhouse();
    io.set_f64(BASE_X, x);
    io.set_f64(BASE_Y, y);
    io.set_f64(BASE_YAW, yaw);
    io
}

fn run(io: &mut Store, steps: usize) -> Camera {
    let mut m = Camera::new();
    m.initialize(io, 0.0, &mut Quiet).unwrap();
    for k in 0..steps {
        m.do_step(io, k as f64 * 0.02, 0.02, &mut Quiet).unwrap();
    }
    m
}

#[test]
fn fmu_publishes_decodable_messages_at_10_hz() {
    let mut io = store(160, 120, 3);
    let mut m = Camera::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    let mut seqs = vec![];
    for k in 0..11 {
        m.do_step(&mut io, k as f64 * 0.02, 0.02, &mut Quiet).unwrap();
        seqs.push(io.i64(IMAGE_SEQ));
    }
    // Frames at 0, 0.1, 0.2 s, each published by the step that reaches its instant.
    assert_eq!(seqs, [1, 1, 1, 1, 2, 2, 2, 2, 2, 3, 3]);
    let info = CameraInfo::from_cdr(agrisim_fmi::port::latest(&io, CAMERA_INFO)).unwrap();
    let k = Intrinsics::from_fov(160, 120, 87.0, 58.0);
    assert_eq!(info.k, k.k());
    assert_eq!(
        (info.width, info.height, info.distortion_model.as_str(), info.d.clone()),
        (160, 120, "plumb_bob", vec![0.0; 5])
    );
    assert_eq!(info.header.stamp.sec * 1_000_000_000 + info.header.stamp.nanosec as i32, 200_000_000);
    assert_eq!(info.header.frame_id, "camera_color_optical_frame");
    let rgb = Image::from_cdr(agrisim_fmi::port::latest(&io, IMAGE)).unwrap();
    assert_eq!(
        (rgb.encoding.as_str(), rgb.width, rgb.height, rgb.step, rgb.data.len()),
        ("rgb8", 160, 120, 480, 160 * 120 * 3)
    );
    let depth = image::read_32fc1(&Image::from_cdr(agrisim_fmi::port::latest(&io, DEPTH)).unwrap()).unwrap();
    assert_eq!(depth.len(), 160 * 120);
    assert_eq!(depth.iter().filter(|&&d| d > 0.0).count(), io.i32(VALID_DEPTH) as usize);
    println!("valid depth pixels {} of {}", io.i32(VALID_DEPTH), 160 * 120);
    assert!(io.i32(VALID_DEPTH) > 160 * 120 / 3);
    // In range up to the noise (sigma at 10 m is 1.9 m at this low resolution: fx = 84 px).
    let sigma_max = 100.0 * 0.08 / (k.fx * 0.05);
    assert!(depth.iter().all(|&d| d == 0.0 || (d > 0.0 && (d as f64) < 10.0 + 6.0 * sigma_max)));
    let labels = image::read_32sc1(&Image::from_cdr(agrisim_fmi::port::latest(&io, LABELS_IMAGE)).unwrap()).unwrap();
    assert_eq!(labels.len(), 160 * 120);
    assert_eq!(io.i64(LABELS_SEQ), 3);
    assert!(labels.iter().any(|&l| l > 0));
    for (s, d) in [(IMAGE_SEQ, DEPTH_SEQ), (IMAGE_SEQ, CAMERA_INFO_SEQ)] {
        assert_eq!(io.i64(s), io.i64(d));
    }
}

#[test]
fn square_pixels_when_fov_horizontal_is_zero() {
    let mut io = store(640, 480, 0);
    *io.value_mut(FOV_H) = Value::Float64(0.0);
    let m = run(&mut io, 1);
    let k = m.config().unwrap().intrinsics;
    assert!((k.fx - k.fy).abs() < 1e-9 && (k.fy - 240.0 / 29f64.to_radians().tan()).abs() < 1e-9, "{k:?}");
    let info = CameraInfo::from_cdr(agrisim_fmi::port::latest(&io, CAMERA_INFO)).unwrap();
    assert_eq!(info.k, k.k());
}

#[test]
fn labels_off_leaves_the_port_empty() {
    let mut io = store(32, 24, 0);
    *io.value_mut(LABELS) = Value::Boolean(false);
    run(&mut io, 3);
    assert_eq!(io.i64(IMAGE_SEQ), 1);
    assert!(agrisim_fmi::port::messages(&io, LABELS_IMAGE).is_empty() && io.i64(LABELS_SEQ) == 0);
}

#[test]
fn deterministic_per_seed() {
    let outputs = |seed| {
        let mut io = store(96, 64, seed);
        run(&mut io, 11);
        (io.binary(IMAGE).to_vec(), io.binary(DEPTH).to_vec(), io.binary(LABELS_IMAGE).to_vec())
    };
    let a = outputs(5);
    assert_eq!(a, outputs(5));
    let b = outputs(6);
    assert_eq!(a.0, b.0, "colour has no noise");
    assert_eq!(a.2, b.2);
    assert_ne!(a.1, b.1, "depth noise follows the seed");
}

#[test]
fn bad_parameters_fail_initialization() {
    for (i, v) in [
        (WIDTH, Value::Int32(0)),
        (HEIGHT, Value::Int32(5000)),
        (DEPTH_NOISE_MODEL, Value::Int32(3)),
        (FOV_H, Value::Float64(180.0)),
        (RANGE_MAX, Value::Float64(0.01)),
    ] {
        let mut io = Store::new(Camera::VARIABLES);
        *io.value_mut(i) = v;
        assert!(Camera::new().initialize(&mut io, 0.0, &mut Quiet).is_err(), "{}", VARIABLES[i].name);
    }
}

#[test]
fn keyed_pixel_noise_is_uncorrelated_and_new_every_frame() {
    // Noise is drawn per pixel from (frame key, pixel index): neighbours must not be
    // correlated, and the next frame (next key) must draw new noise.
    let k = Intrinsics::from_fov(640, 480, 87.0, 58.0);
    let pose = CameraPose::new(&MOUNT, 0.0, 0.0, 0.0);
    let scene = wall_scene(3.0);
    let m = model(DepthNoise::Stereo { subpixel: 0.08 }, false, 0.0);
    let mut rng = Rng::new(5);
    let f1 = render::render(
        &Shot { scene: &scene, dynamic: &[], k: &k, pose: &pose, light: &light(), columns: &[], depth: &m },
        &mut rng,
        2,
    );
    let f2 = render::render(
        &Shot { scene: &scene, dynamic: &[], k: &k, pose: &pose, light: &light(), columns: &[], depth: &m },
        &mut rng,
        2,
    );
    let err = |f: &render::Frame| -> Vec<f64> {
        f.depth.iter().zip(&f.true_depth).map(|(d, t)| *d as f64 - *t as f64).collect()
    };
    let (e1, e2) = (err(&f1), err(&f2));
    let corr = |a: &[f64], b: &[f64]| {
        let n = a.len() as f64;
        let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
        let cov = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum::<f64>() / n;
        let va = a.iter().map(|x| (x - ma).powi(2)).sum::<f64>() / n;
        let vb = b.iter().map(|y| (y - mb).powi(2)).sum::<f64>() / n;
        cov / (va * vb).sqrt()
    };
    let horizontal = corr(&e1[..e1.len() - 1], &e1[1..]);
    let vertical = corr(&e1[..e1.len() - 640], &e1[640..]);
    let frames = corr(&e1, &e2);
    println!("noise correlation: horizontal {horizontal:.4}, vertical {vertical:.4}, frame to frame {frames:.4}");
    // 307,200 samples: the standard error of a correlation is ~0.002.
    for c in [horizontal, vertical, frames] {
        assert!(c.abs() < 0.01, "{c}");
    }
}

/// Pixels per robot label (scene ids end at `first`; labels are id + 1) of a frame from the
/// camera where the robot carries it (the default mount: camera_link on the lift carriage,
/// as agrisim_robot.urdf's camera_joint).
fn robot_pixels(links: bool, setup: impl FnOnce(&mut Store)) -> std::collections::BTreeMap<i32, usize> {
    let mut io = store(320, 240, 0);
    *io.value_mut(ROBOT_LINKS) = Value::Boolean(links);
    setup(&mut io);
    let m = run(&mut io, 1);
    let first = m.config().unwrap().scene.object_count() as i32;
    let labels = image::read_32sc1(&Image::from_cdr(agrisim_fmi::port::latest(&io, LABELS_IMAGE)).unwrap()).unwrap();
    let mut out = std::collections::BTreeMap::new();
    for &l in labels.iter().filter(|&&l| l > first) {
        *out.entry(l).or_insert(0) += 1;
    }
    out
}

/// Both arms reaching forward and down (hands 0.9 m ahead, 0.76 m high, 0.25 m to each side):
/// in the view of the camera on the lift.
const WORKING: [f64; 7] = [0.0, 0.6, 0.0, -1.6, 0.0, 2.2, 0.785];

fn set_arms(io: &mut Store, q: [f64; 7], q1: [f64; 2]) {
    for (i, v) in q.into_iter().enumerate() {
        io.set_f64(LEFT_Q1 + i, if i == 0 { q1[0] } else { v });
        io.set_f64(RIGHT_Q1 + i, if i == 0 { q1[1] } else { v });
    }
}

#[test]
fn the_camera_sees_the_arms_where_the_joints_put_them() {
    // Without links the camera on the lift at lift 0 is inside the base box parameters (the
    // navigation envelope, up to 0.65 m): it sees nothing but the box.
    assert_eq!(robot_pixels(false, |_| {}).values().sum::<usize>(), 320 * 240);
    // With links: the chassis (0.42 m high) is below the view, the ready arms above it
    // (folded over the lift); arms reaching forward are in it, and both are seen.
    assert!(robot_pixels(true, |_| {}).is_empty());
    let working = robot_pixels(true, |io| set_arms(io, WORKING, [0.0, 0.0]));
    let seen: usize = working.values().sum();
    assert!(working.len() >= 6 && seen > 320 * 240 / 50, "{working:?}");
    // Swinging them out to the sides (joint 1) takes them out of the view; raising the lift
    // (camera and arms together) keeps them where they were in the image.
    let out = robot_pixels(true, |io| set_arms(io, WORKING, [1.6, -1.6]));
    assert!(out.values().sum::<usize>() < seen / 4, "{out:?} vs {working:?}");
    let raised = robot_pixels(true, |io| {
        set_arms(io, WORKING, [0.0, 0.0]);
        io.set_f64(LIFT_POSITION, 0.3);
    });
    let diff: usize = working
        .keys()
        .chain(raised.keys())
        .map(|k| working.get(k).unwrap_or(&0).abs_diff(*raised.get(k).unwrap_or(&0)))
        .sum();
    assert!(diff < seen / 20, "{raised:?} vs {working:?}");
}

/// The world's `moved_objects` as the engine writes an input: one bare message, counter 1.
fn set_moved(io: &mut Store, moves: &[(u32, Placement)]) {
    use agrisim_msgs::geometry_msgs::{Point, Pose, Quaternion};
    let msg = agrisim_msgs::agrisim::MovedObjects {
        header: agrisim_msgs::std_msgs::Header::default(),
        ids: moves.iter().map(|m| m.0).collect(),
        poses: moves
            .iter()
            .map(|(_, p)| {
                let [x, y, z] = p.translation;
                let [qx, qy, qz, qw] = p.rotation;
                Pose { position: Point { x, y, z }, orientation: Quaternion { x: qx, y: qy, z: qz, w: qw } }
            })
            .collect(),
    };
    *io.value_mut(MOVED_OBJECTS) = Value::Binary(msg.to_cdr());
    io.set_i64(MOVED_OBJECTS_SEQ, io.i64(MOVED_OBJECTS_SEQ) + 1);
}

/// A pushed leaf and a picked fruit, as the world reports them on `moved_objects`: the
/// camera's frame is exactly the frame of a scene generated with them where they are now
/// (colour, depth and labels), and nothing is left where they grew.
#[test]
fn moved_objects_are_rendered_where_the_world_has_them() {
    let (objects, [x, y, yaw]) = greenhouse();
    let mut io = store(320, 240, 5);
    let before = run(&mut io, 1);
    let labels = image::read_32sc1(&Image::from_cdr(agrisim_fmi::port::latest(&io, LABELS_IMAGE)).unwrap()).unwrap();
    // The fruit and the leaf part most in view.
    let most = |f: &dyn Fn(Kind) -> bool| {
        let mut n = std::collections::BTreeMap::new();
        for &l in labels.iter().filter(|&&l| l > 0 && (l as usize) <= objects.len()) {
            if f(objects[l as usize - 1].kind) {
                *n.entry(l - 1).or_insert(0usize) += 1;
            }
        }
        n.into_iter().max_by_key(|e| (e.1, std::cmp::Reverse(e.0))).unwrap()
    };
    let (fruit, fruit_px) = most(&|k| matches!(k, Kind::Fruit { .. }));
    let (leaf, _) = most(&|k| k == Kind::Leaf);
    drop(before);
    // The fruit 12 cm to the side and turned; the leaf part 30 cm up.
    let f = &objects[fruit as usize];
    let l = &objects[leaf as usize];
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let t = |o: &Object, d: [f64; 3]| {
        let p = o.placement.translation;
        [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
    };
    let mut moves = vec![
        (fruit as u32, Placement { translation: t(f, [0.12, 0.0, 0.0]), rotation: [0.0, h, 0.0, h] }),
        (leaf as u32, Placement { translation: t(l, [0.0, 0.0, 0.3]), rotation: l.placement.rotation }),
    ];
    moves.sort_by_key(|m| m.0);
    let mut io = store(320, 240, 5);
    set_moved(&mut io, &moves);
    let cam = run(&mut io, 1);
    let got = (
        Image::from_cdr(agrisim_fmi::port::latest(&io, IMAGE)).unwrap().data,
        image::read_32fc1(&Image::from_cdr(agrisim_fmi::port::latest(&io, DEPTH)).unwrap()).unwrap(),
        image::read_32sc1(&Image::from_cdr(agrisim_fmi::port::latest(&io, LABELS_IMAGE)).unwrap()).unwrap(),
    );
    // The reference: a scene built with the objects at their new placements.
    let mut moved = objects.clone();
    for &(id, p) in &moves {
        moved[id as usize].placement = p;
    }
    let scene = Scene::from_objects(&moved);
    let c = cam.config().unwrap();
    // The robot where the inputs put it (the camera rides on the lift, the links in view).
    let mut coords = agrisim_sensor_ports::robot::Coords { lift: io.f64(LIFT_POSITION), ..Default::default() };
    for i in 0..7 {
        (coords.arms[0][i], coords.arms[1][i]) = (io.f64(LEFT_Q1 + i), io.f64(RIGHT_Q1 + i));
    }
    coords.widths = [io.f64(LEFT_FINGER_WIDTH), io.f64(RIGHT_FINGER_WIDTH)];
    let robot = c.robot.objects(c.robot_links.then_some(&coords), x, y, yaw);
    let pose = c.camera_pose(&coords, x, y, yaw);
    let columns = render::sun_columns(&scene, &c.light);
    let shot = Shot {
        scene: &scene,
        dynamic: &robot,
        k: &c.intrinsics,
        pose: &pose,
        light: &c.light,
        columns: &columns,
        depth: &c.depth,
    };
    let mut want = render::Frame::default();
    render::render_into(&mut want, &shot, &mut Rng::new(5), 1);
    assert!(got.2 == want.labels, "labels differ from the moved scene's");
    assert!(got.1 == want.depth, "depth differs from the moved scene's");
    assert!(got.0 == want.rgb, "colour differs from the moved scene's");
    // And it is another frame than the grown scene's: the fruit moved across the image.
    let now = got.2.iter().filter(|&&v| v == fruit + 1).count();
    assert_ne!(got.2, labels, "the moved objects changed the frame");
    println!("fruit {fruit}: {fruit_px} px where it grew, {now} px moved; leaf part {leaf}");
}
