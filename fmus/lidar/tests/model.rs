//! The Lidar model through its Rust API and the generic FMI 3 layer: frame size, ranges to a
//! wall at a known distance, coverage growing with integration time, motion, the robot's own
//! box, intensities, determinism, and the PointCloud2 layout.

use agrisim_fmi::{fmi3, Model, Quiet, Status, Store, Value};
use agrisim_fmu_lidar::cloud::{self, Point};
use agrisim_fmu_lidar::ports::*;
use agrisim_fmu_lidar::Lidar;
use agrisim_msgs::sensor_msgs::{PointCloud2, PointField};
use agrisim_msgs::Message;
use std::f64::consts::PI;

const H: f64 = 0.02;

/// A closed 20 x 12 x 4 m hall (every ray returns within 40 m); its one plant row lies at
/// x = 14..18, behind the robot's back in the tests below.
const HALL: &str = "length = 20.0\nwidth = 12.0\nheight = 4.0\nrows = 1\nactive_rows = 1\nheadland = 14.0\nrow_length = 4.0\ngutter_height = 3.0";

fn start(scene: &str, pose: [f64; 3], setup: impl FnOnce(&mut Store)) -> (Lidar, Store) {
    let mut io = Store::new(Lidar::VARIABLES);
    *io.value_mut(SCENE) = Value::String(scene.into());
    io.set_f64(BASE_X, pose[0]);
    io.set_f64(BASE_Y, pose[1]);
    io.set_f64(BASE_YAW, pose[2]);
    setup(&mut io);
    let mut m = Lidar::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    (m, io)
}

/// Steps `steps` x 0.02 s from step `from`; returns the clouds published on the way.
fn run(m: &mut Lidar, io: &mut Store, from: usize, steps: usize) -> Vec<PointCloud2> {
    let mut out = vec![];
    for k in from..from + steps {
        let seq = io.i64(POINTS_SEQ);
        m.do_step(io, k as f64 * H, H, &mut Quiet).unwrap();
        if io.i64(POINTS_SEQ) != seq {
            out.push(PointCloud2::from_cdr(agrisim_fmi::port::latest(io, POINTS)).unwrap());
        }
    }
    out
}

fn points(c: &PointCloud2) -> Vec<Point> {
    cloud::read(c).unwrap()
}

fn norm(p: &Point) -> f64 {
    p.xyz.iter().map(|v| (*v as f64).powi(2)).sum::<f64>().sqrt()
}

#[test]
fn default_frame_has_20000_points_and_a_valid_layout() {
    let (mut m, mut io) = start("", [2.0, 27.5, 0.0], |_| {});
    let clouds = run(&mut m, &mut io, 0, 10);
    assert_eq!(clouds.len(), 2, "10 Hz on 0.02 s steps");
    assert_eq!(io.i32(POINTS_IN_FRAME), 20_000);
    let c = &clouds[1];
    assert_eq!((c.height, c.width, c.point_step, c.row_step), (1, 20_000, 20, 400_000));
    assert_eq!(c.data.len(), 400_000);
    assert!(!c.is_bigendian && c.is_dense);
    let fields: Vec<_> = c.fields.iter().map(|f| (f.name.as_str(), f.offset, f.datatype, f.count)).collect();
    let f32_ = PointField::FLOAT32;
    assert_eq!(
        fields,
        [("x", 0, f32_, 1), ("y", 4, f32_, 1), ("z", 8, f32_, 1), ("intensity", 12, f32_, 1), ("t", 16, f32_, 1)]
    );
    assert_eq!(c.header.frame_id, "lidar_link");
    // Sensor convention: stamp = first point of the frame (0.1 .. 0.2 s), t in [0, 0.1).
    assert_eq!(c.header.stamp.to_nanos(), 100_000_000);
    let pts = points(c);
    assert!(pts.iter().all(|p| (0.0..0.1).contains(&p.t)));
    assert!(pts.windows(2).all(|w| w[0].t <= w[1].t), "points in time order");
    let returns = pts.iter().filter(|p| norm(p) > 0.0).count();
    assert_eq!(returns as i32, io.i32(RETURNS_IN_FRAME));
    assert!(returns > 15_000, "{returns} returns");
    assert!(pts.iter().all(|p| norm(p) == 0.0 || (0.05..41.0).contains(&norm(p))));
}

#[test]
fn ranges_to_a_wall_at_a_known_distance_are_within_the_noise() {
    // Facing the hall's x = 0 wall from x = 5: the plane is x = 5 m ahead of lidar_link.
    for (noise, tol_mean, want_std) in [(0.02, 0.002, Some(0.02)), (0.0, 1e-5, None)] {
        let (mut m, mut io) = start(HALL, [5.0, 6.0, PI], |io| io.set_f64(RANGE_NOISE, noise));
        let clouds = run(&mut m, &mut io, 0, 50);
        let mut res = vec![];
        for c in &clouds {
            for p in points(c) {
                let r = norm(&p);
                let dx = p.xyz[0] as f64 / r;
                let z = p.xyz[2] as f64;
                if r > 0.0 && dx > 0.75 && (-0.9..2.9).contains(&z) && (p.xyz[0] as f64 - 5.0).abs() < 0.2 {
                    res.push(r - 5.0 / dx);
                }
            }
        }
        let n = res.len() as f64;
        let mean = res.iter().sum::<f64>() / n;
        let std = (res.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / n).sqrt();
        eprintln!("noise {noise}: {n} wall points, mean {mean:.5} m, std {std:.5} m");
        assert!(n > 5_000.0, "{n} wall points");
        assert!(mean.abs() < tol_mean, "mean residual {mean}");
        match want_std {
            Some(s) => assert!((std / s - 1.0).abs() < 0.1, "std {std}"),
            None => assert!(std < 1e-5, "std {std}"),
        }
    }
}

/// Fraction of 1 deg x 1 deg (azimuth, elevation) cells of the field with a return.
fn coverage(clouds: &[PointCloud2]) -> f64 {
    let rows = 59;
    let mut hit = vec![false; 360 * rows];
    for c in clouds {
        for p in points(c) {
            let r = norm(&p);
            if r == 0.0 {
                continue;
            }
            let az = (p.xyz[1] as f64).atan2(p.xyz[0] as f64).to_degrees().rem_euclid(360.0);
            let el = (p.xyz[2] as f64 / r).asin().to_degrees();
            let (a, e) = ((az as usize).min(359), ((el + 7.0).max(0.0) as usize).min(rows - 1));
            hit[e * 360 + a] = true;
        }
    }
    hit.iter().filter(|h| **h).count() as f64 / hit.len() as f64
}

#[test]
fn coverage_after_one_second_is_far_above_one_frame() {
    let (mut m, mut io) = start(HALL, [5.0, 6.0, 0.3], |io| io.set_f64(RANGE_NOISE, 0.0));
    let clouds = run(&mut m, &mut io, 0, 50);
    assert_eq!(clouds.len(), 10);
    assert!(clouds.iter().all(|c| points(c).iter().all(|p| norm(p) > 0.0)), "closed hall: every ray returns");
    let (one, ten) = (coverage(&clouds[..1]), coverage(&clouds));
    eprintln!("coverage of 1 x 1 deg cells: 0.1 s {one:.3}, 1 s {ten:.3}");
    assert!(one > 0.3 && ten > 0.95 && ten - one > 0.3, "{one} {ten}");
}

#[test]
fn points_are_measured_along_the_motion_unless_deskewed() {
    // Backing away from the x = 0 wall at 1 m/s (facing it): the wall recedes during a frame.
    for deskewed in [false, true] {
        let (mut m, mut io) = start(HALL, [3.0, 6.0, PI], |io| {
            io.set_f64(RANGE_NOISE, 0.0);
            io.set_bool(DESKEWED, deskewed);
        });
        let mut clouds = vec![];
        for k in 0..15 {
            let t = k as f64 * H;
            io.set_f64(BASE_X, 3.0 + t);
            clouds.extend(run(&mut m, &mut io, k, 1));
        }
        let c = clouds.last().unwrap(); // frame (0.2, 0.3]
        let stamp = c.header.stamp.to_nanos() as f64 * 1e-9;
        let mut worst: f64 = 0.0;
        for p in points(c) {
            let r = norm(&p);
            if r == 0.0 || (p.xyz[0] as f64) / r < 0.9 || (p.xyz[0] as f64) < 2.0 {
                continue;
            }
            let s = stamp + p.t as f64;
            // Pose is interpolated between inputs, held after the last one (t = 0.28 s).
            let x_base = if deskewed { 3.28 } else { 3.0 + s.min(0.28) };
            worst = worst.max((p.xyz[0] as f64 - x_base).abs());
        }
        assert!(worst < 1e-4, "deskewed {deskewed}: worst {worst}");
        let want_stamp = if deskewed { 0.3 } else { 0.2 };
        assert!((stamp - want_stamp).abs() < 1e-9, "{stamp}");
    }
}

#[test]
fn the_robots_own_box_is_hit_and_moves_with_it() {
    // Mounted low behind the base box, looking forward: the box's rear face is 0.4 m ahead.
    let (mut m, mut io) = start(HALL, [5.0, 6.0, 0.0], |io| {
        io.set_f64(RANGE_NOISE, 0.0);
        io.set_f64(MOUNT_X, -1.0);
        io.set_f64(MOUNT_Z, 0.1);
        *io.value_mut(ROBOT_LINKS) = Value::Boolean(false);
    });
    let mut clouds = run(&mut m, &mut io, 0, 10);
    // Then driving and turning: the box keeps its place in front of the sensor.
    for k in 10..20 {
        io.set_f64(BASE_X, 5.0 + 0.05 * (k - 10) as f64);
        io.set_f64(BASE_YAW, 0.02 * (k - 10) as f64);
        clouds.extend(run(&mut m, &mut io, k, 1));
    }
    let box_points: Vec<Point> = [&clouds[1], &clouds[3]]
        .into_iter()
        .flat_map(points)
        .filter(|p| {
            let r = norm(p);
            r > 0.0 && (p.xyz[0] as f64) / r > 0.95 && (p.xyz[2] as f64) > -0.04 && (p.xyz[2] as f64) < 0.5
        })
        .collect();
    assert!(!box_points.is_empty());
    for p in &box_points {
        assert!((p.xyz[0] as f64 - 0.4).abs() < 1e-5, "{p:?}");
        // Robot reflectivity 0.3 at near-normal incidence.
        assert!((p.intensity - 45.0).abs() < 45.0 * 0.06, "{}", p.intensity);
    }
}

/// Points of the first three clouds above the chassis (lidar frame z > -0.3) and within 1.2 m
/// of the sensor (the hall's walls are metres away): the robot's lift, post and arms.
fn self_points(links: bool, setup: impl FnOnce(&mut Store)) -> Vec<Point> {
    let (mut m, mut io) = start(HALL, [5.0, 6.0, 0.0], |io| {
        io.set_f64(RANGE_NOISE, 0.0);
        *io.value_mut(ROBOT_LINKS) = Value::Boolean(links);
        setup(io);
    });
    let clouds = run(&mut m, &mut io, 0, 16);
    assert_eq!(clouds.len(), 3);
    clouds.iter().flat_map(points).filter(|p| norm(p) > 0.0 && norm(p) < 1.2 && p.xyz[2] > -0.3).collect()
}

#[test]
fn the_robots_links_are_hit_where_the_joints_put_them() {
    assert!(self_points(false, |_| {}).is_empty());
    // The arms in their ready pose, folded in front of the lift, within the footprint.
    let ready = self_points(true, |_| {});
    assert!(ready.len() > 150, "{}", ready.len());
    assert!(ready.iter().all(|p| p.xyz[0].abs() < 0.75 && p.xyz[1].abs() < 0.55), "{ready:?}");
    // Joint 1 swings the left arm out to the left (+y), beyond the base.
    let swung = self_points(true, |io| io.set_f64(LEFT_Q1, 1.6));
    let left = |ps: &[Point]| ps.iter().filter(|p| p.xyz[1] > 0.55).count();
    println!(
        "robot points in 3 frames: ready {}, arm swung out {} ({} beside the base)",
        ready.len(),
        swung.len(),
        left(&swung)
    );
    assert!(left(&ready) == 0 && left(&swung) > 10, "{} {}", left(&ready), left(&swung));
    // Robot points come back with the robot's reflectivity (0.3): intensity 45 at normal incidence or below.
    assert!(swung.iter().all(|p| p.intensity <= 45.0 * 1.06));
}

#[test]
fn floor_intensity_follows_reflectivity_and_incidence() {
    let (mut m, mut io) = start(HALL, [5.0, 6.0, 0.0], |io| io.set_f64(RANGE_NOISE, 0.0));
    let clouds = run(&mut m, &mut io, 0, 5);
    let mut n = 0;
    for p in points(&clouds[0]) {
        let r = norm(&p);
        // Floor: 1 m below lidar_link.
        if r > 0.0 && ((p.xyz[2] as f64) + 1.0).abs() < 1e-4 {
            let cos = 1.0 / r; // the ray's component along the floor normal
            assert!((p.intensity as f64 - 150.0 * 0.25 * cos).abs() < 1e-3, "{p:?}");
            n += 1;
        }
    }
    assert!(n > 100, "{n} floor points");
}

fn bytes(noise_seed: i32) -> Vec<Vec<u8>> {
    let (mut m, mut io) = start(HALL, [5.0, 6.0, 0.0], |io| io.set_i32(NOISE_SEED, noise_seed));
    run(&mut m, &mut io, 0, 15).into_iter().map(|c| c.to_cdr()).collect()
}

#[test]
fn same_seed_same_bytes_other_seed_differs() {
    let a = bytes(3);
    assert_eq!(a.len(), 3);
    assert_eq!(a, bytes(3));
    assert_ne!(a, bytes(4));
}

/// The frames cast on 1, 2, 3 and 7 threads, in the default greenhouse while the base drives
/// (points measured along the motion, the robot's links seen).
#[test]
fn clouds_do_not_depend_on_the_cast_threads() {
    let clouds = |threads: i32| {
        let (mut m, mut io) = start("", [2.0, 27.5, 0.3], |io| io.set_i32(CAST_THREADS, threads));
        let mut out = vec![];
        for k in 0..15 {
            io.set_f64(BASE_X, 2.0 + 0.01 * k as f64);
            out.extend(run(&mut m, &mut io, k, 1).into_iter().map(|c| c.to_cdr()));
        }
        out
    };
    let one = clouds(1);
    assert_eq!(one.len(), 3);
    for threads in [2, 3, 7] {
        assert!(clouds(threads) == one, "{threads} threads");
    }
    let mut io = Store::new(Lidar::VARIABLES);
    io.set_i32(CAST_THREADS, 0);
    let err = Lidar::new().initialize(&mut io, 0.0, &mut Quiet).unwrap_err();
    assert!(err.contains("cast_threads"), "{err}");
}

#[test]
fn drop_no_return_leaves_only_returns() {
    let (mut m, mut io) = start("", [2.0, 27.5, 0.0], |io| io.set_bool(DROP_NO_RETURN, true));
    let clouds = run(&mut m, &mut io, 0, 5);
    let pts = points(&clouds[0]);
    assert_eq!(pts.len() as i32, io.i32(RETURNS_IN_FRAME));
    assert_eq!(io.i32(POINTS_IN_FRAME), io.i32(RETURNS_IN_FRAME));
    assert!(pts.iter().all(|p| norm(p) > 0.05));
}

#[test]
fn bad_scene_text_is_refused_with_the_key() {
    let mut io = Store::new(Lidar::VARIABLES);
    *io.value_mut(SCENE) = Value::String("rowz = 3".into());
    let err = Lidar::new().initialize(&mut io, 0.0, &mut Quiet).unwrap_err();
    assert!(err.contains("scene") && err.contains("rowz"), "{err}");
}

#[test]
fn through_the_fmi3_layer() {
    let token = std::ffi::CString::new(Lidar::TOKEN).unwrap();
    let scene = std::ffi::CString::new(HALL).unwrap();
    let vr = |i: usize| i as u32 + 1;
    unsafe {
        let p = fmi3::instantiate_co_simulation::<Lidar>(
            c"lidar".as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            0,
            0,
            0,
            0,
            std::ptr::null(),
            0,
            std::ptr::null_mut(),
            None,
            None,
        );
        assert!(!p.is_null());
        assert_eq!(fmi3::set_string::<Lidar>(p, &vr(SCENE), 1, &scene.as_ptr(), 1), Status::Ok);
        assert_eq!(fmi3::set_float64::<Lidar>(p, &vr(FRAME_RATE), 1, &20.0, 1), Status::Ok);
        assert_eq!(fmi3::enter_initialization_mode::<Lidar>(p, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
        assert_eq!(fmi3::set_float64::<Lidar>(p, &vr(BASE_X), 1, &5.0, 1), Status::Ok);
        assert_eq!(fmi3::set_float64::<Lidar>(p, &vr(BASE_Y), 1, &6.0, 1), Status::Ok);
        assert_eq!(fmi3::exit_initialization_mode::<Lidar>(p), Status::Ok);
        let (mut a, mut b, mut c, mut last) = (0u8, 0u8, 0u8, 0.0);
        for k in 0..5 {
            assert_eq!(fmi3::do_step::<Lidar>(p, k as f64 * H, H, 0, &mut a, &mut b, &mut c, &mut last), Status::Ok);
        }
        let (mut seq, mut n) = (0i64, 0i32);
        assert_eq!(fmi3::get_int64::<Lidar>(p, &vr(POINTS_SEQ), 1, &mut seq, 1), Status::Ok);
        assert_eq!(fmi3::get_int32::<Lidar>(p, &vr(POINTS_IN_FRAME), 1, &mut n, 1), Status::Ok);
        assert_eq!((seq, n), (2, 10_000), "20 Hz: two frames of 10,000 points in 0.1 s");
        let (mut size, mut data) = (0usize, std::ptr::null::<u8>());
        assert_eq!(fmi3::get_binary::<Lidar>(p, &vr(POINTS), 1, &mut size, &mut data, 1), Status::Ok);
        let frames = agrisim_frames::decode(std::slice::from_raw_parts(data, size)).unwrap();
        assert_eq!(frames.iter().map(|f| f.seq).collect::<Vec<_>>(), [1, 2], "both frames of the last 0.1 s");
        let cloud = PointCloud2::from_cdr(frames[1].payload).unwrap();
        assert_eq!(cloud.width, 10_000);
        assert_eq!(cloud.header.stamp.to_nanos(), 50_000_000);
        assert_eq!(frames[1].stamp_ns, 50_000_000);
        // A malformed scene is refused at initialization and named in the log.
        assert_eq!(fmi3::reset::<Lidar>(p), Status::Ok);
        let bad = std::ffi::CString::new("rows = -1").unwrap();
        assert_eq!(fmi3::set_string::<Lidar>(p, &vr(SCENE), 1, &bad.as_ptr(), 1), Status::Ok);
        assert_eq!(fmi3::enter_initialization_mode::<Lidar>(p, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
        assert_eq!(fmi3::exit_initialization_mode::<Lidar>(p), Status::Error);
        fmi3::free_instance::<Lidar>(p);
    }
}

/// A scene object the world reports moved (`moved_objects`: here a main stem carried upright
/// to 1.2 m in front of the robot) is where the returns come from, and no longer where it
/// grew; the same frame without the input is the grown scene's.
#[test]
fn moved_objects_are_seen_where_the_world_has_them() {
    use agrisim_msgs::geometry_msgs::{Point as P, Pose, Quaternion};
    let cfg = agrisim_scene::GreenhouseConfig::from_toml_str(HALL).unwrap();
    let objects = agrisim_scene::generate(&cfg, cfg.seed).objects;
    let stem = objects.iter().find(|o| o.kind == agrisim_scene::Kind::Stem).expect("a stem");
    let near = |c: &PointCloud2| {
        points(c).iter().filter(|p| (0.8..1.6).contains(&norm(p)) && p.xyz[0] > 0.0 && p.xyz[1].abs() < 0.3).count()
    };
    let frame = |moved: bool| {
        let (mut m, mut io) = start(HALL, [5.0, 6.0, 0.0], |_| {});
        if moved {
            let g = stem.placement.translation;
            let msg = agrisim_msgs::agrisim::MovedObjects {
                header: Default::default(),
                ids: vec![stem.id],
                poses: vec![Pose {
                    position: P { x: 6.5, y: 6.0, z: g[2] },
                    orientation: Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 },
                }],
            };
            *io.value_mut(MOVED_OBJECTS) = Value::Binary(msg.to_cdr());
            io.set_i64(MOVED_OBJECTS_SEQ, 1);
        }
        run(&mut m, &mut io, 0, 10).pop().unwrap()
    };
    let (grown, moved) = (frame(false), frame(true));
    assert_eq!(near(&grown), 0, "nothing stands 1.2 m ahead in the grown scene");
    assert!(near(&moved) > 20, "the moved stem returns {} points", near(&moved));
}

/// A malformed `moved_objects` (an id beyond the scene) is an error naming the input.
#[test]
fn a_bad_moved_objects_message_is_an_error_naming_the_input() {
    let (mut m, mut io) = start(HALL, [5.0, 6.0, 0.0], |_| {});
    let msg = agrisim_msgs::agrisim::MovedObjects {
        header: Default::default(),
        ids: vec![u32::MAX - 1],
        poses: vec![Default::default()],
    };
    *io.value_mut(MOVED_OBJECTS) = Value::Binary(msg.to_cdr());
    io.set_i64(MOVED_OBJECTS_SEQ, 1);
    let e = m.do_step(&mut io, 0.0, H, &mut Quiet).unwrap_err();
    assert!(e.contains("moved_objects") && e.contains("4294967294"), "{e}");
}
